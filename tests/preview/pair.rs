//! The preview and the path tracer's image of one scene, and per-object means over them.

use std::sync::atomic::AtomicBool;

use glam::Vec3;
use rt_core::Scene;

use crate::common::pixel_hits;

pub fn luminance(c: [f32; 3]) -> f64 {
    f64::from(0.2126 * c[0] + 0.7152 * c[1] + 0.0722 * c[2])
}

/// The preview and the path-traced render of `scene` (saved as `name`-preview.png and
/// `name`-render.png for a failing test to point at), and which object each pixel shows.
pub struct Pair {
    pub preview: Vec<[f32; 3]>,
    pub render: Vec<[f32; 3]>,
    pub hits: Vec<Option<(usize, Vec3)>>,
}

/// The path tracer's image of `scene` at its settings, on the CPU backend (the GPU kernels' image,
/// sample for sample, in less time on these test machines).
pub fn path_traced(scene: &Scene) -> Vec<[f32; 3]> {
    let gpu_scene = rt_core::GpuScene::build(scene).expect("the scene builds");
    let frame = rt_core::frame::frame_for(scene, &gpu_scene).expect("a frame");
    let mut image = rt_core::cpu_render::CpuAccumulation::new(&frame, 0, None, false);
    let spp = scene.settings.samples_per_pixel;
    assert!(image.add_batch(&gpu_scene, &frame, spp, &AtomicBool::new(false)));
    image.pixels().iter().map(|p| [p[0], p[1], p[2]]).collect()
}

pub fn preview_and_render(ctx: &rt_gpu::GpuContext, scene: &Scene, name: &str) -> Pair {
    let (width, height) = (scene.settings.width, scene.settings.height);
    let mut frame =
        rt_preview::build_frame(scene, &scene.camera, scene.bounds(), None, [width, height]);
    // The editor's grid is a viewport aid, not part of the scene (`rt-cli preview` leaves it out).
    frame.grid.clear();
    let preview = rt_preview::render_image(ctx, &frame).expect("the preview renders");
    let render = path_traced(scene);
    let dir = std::path::Path::new(env!("CARGO_TARGET_TMPDIR"));
    for (kind, image) in [("preview", &preview), ("render", &render)] {
        let path = dir.join(format!("{name}-{kind}.png"));
        rt_core::output::save_image(&path, width, height, image, 0.0).expect("saved");
        eprintln!("{kind}: {}", path.display());
    }
    assert!(preview.iter().flatten().all(|c| c.is_finite() && *c >= 0.0));
    Pair {
        preview,
        render,
        hits: interior(pixel_hits(scene, width, height), width as usize),
    }
}

/// The hits of pixels whose four neighbours show the same object: an edge pixel's samples see
/// the objects beside it too (a ceiling's pixels at the lamp's edge glow with the lamp in the
/// render, not in the preview, which takes one sample a pixel).
fn interior(hits: Vec<Option<(usize, Vec3)>>, width: usize) -> Vec<Option<(usize, Vec3)>> {
    let object = |i: usize| hits[i].map(|(o, _)| o);
    (0..hits.len())
        .map(|i| {
            let (x, y) = (i % width, i / width);
            let inside = x > 0
                && x + 1 < width
                && y > 0
                && (i + width) < hits.len()
                && [i - 1, i + 1, i - width, i + width]
                    .iter()
                    .all(|&j| object(j) == object(i));
            if inside { hits[i] } else { None }
        })
        .collect()
}

impl Pair {
    /// The mean colour of `image` over the pixels whose hit `keep` takes.
    pub fn mean(&self, image: &[[f32; 3]], keep: &dyn Fn(usize, Vec3) -> bool) -> [f32; 3] {
        let (mut sum, mut n) = ([0.0f64; 3], 0usize);
        for (pixel, hit) in image.iter().zip(&self.hits) {
            if let Some((object, p)) = *hit
                && keep(object, p)
            {
                for c in 0..3 {
                    sum[c] += f64::from(pixel[c]);
                }
                n += 1;
            }
        }
        assert!(n > 20, "{n} pixels");
        sum.map(|s| (s / n as f64) as f32)
    }

    /// Each object's mean luminance in the preview over the render's (objects with few pixels in
    /// view left out), printed.
    pub fn object_ratios(&self, scene: &Scene) -> Vec<(String, f64)> {
        let mut ratios = Vec::new();
        for (i, o) in scene.objects.iter().enumerate() {
            if self
                .hits
                .iter()
                .filter(|h| h.is_some_and(|(k, _)| k == i))
                .count()
                <= 20
            {
                continue;
            }
            let ours = self.mean(&self.preview, &|object, _| object == i);
            let theirs = self.mean(&self.render, &|object, _| object == i);
            let ratio = luminance(ours) / luminance(theirs);
            eprintln!(
                "{:12} preview {:.3?} render {:.3?}: {:+.1}%",
                o.name,
                ours,
                theirs,
                100.0 * (ratio - 1.0)
            );
            ratios.push((o.name.clone(), ratio));
        }
        ratios
    }
}
