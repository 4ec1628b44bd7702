//! The material gallery: every preset (`presets::PRESETS`) as a thumbnail rendered by rt itself,
//! on its CPU backend: a sphere on a grey floor under the built-in studio environment, seen from a
//! little above. The thumbnails are computed once per session on a background thread (cached in
//! memory; the Inspector shows each as it arrives), so opening the gallery never waits.

use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::{Arc, mpsc};

use glam::Vec3;
use rt_core::environment::{Environment, EnvironmentMap};
use rt_core::{Material, Object, Scene};

use crate::presets::PRESETS;

/// A thumbnail's side (pixels) and samples per pixel.
pub const THUMBNAIL_SIZE: u32 = 48;
const THUMBNAIL_SPP: u32 = 32;

/// The studio environment at a quarter of its resolution: the thumbnails are too small to tell,
/// and its sampling table builds 16× faster.
fn small_studio() -> Option<Environment> {
    let studio = rt_io::assets::default_environment().ok()?;
    let map = &studio.map;
    let (w, h) = (map.width / 4, map.height / 4);
    let mut texels = vec![[0.0f32; 3]; (w * h) as usize];
    for y in 0..h {
        for x in 0..w {
            let mut sum = [0.0f32; 3];
            for dy in 0..4 {
                for dx in 0..4 {
                    let t = map.texels[((4 * y + dy) * map.width + 4 * x + dx) as usize];
                    (0..3).for_each(|c| sum[c] += t[c] / 16.0);
                }
            }
            texels[(y * w + x) as usize] = sum;
        }
    }
    let map = EnvironmentMap {
        width: w,
        height: h,
        texels,
    };
    Some(Environment::new("studio (thumbnails)", map))
}

/// The thumbnail scene of `material`, `size` pixels square at `spp` samples.
pub fn thumbnail_scene(
    material: Material,
    environment: Option<Environment>,
    size: u32,
    spp: u32,
) -> Scene {
    let mut scene = Scene {
        environment,
        ..Scene::default()
    };
    scene.objects = vec![
        Object {
            shadow_catcher: false,
            animation_node: None,
            name: "sphere".into(),
            mesh: rt_core::shapes::uv_sphere(1.0, 16, 32).into(),
            material,
            transform: rt_core::Transform {
                translation: [0.0, 1.0, 0.0],
                ..Default::default()
            },
        },
        Object {
            shadow_catcher: false,
            animation_node: None,
            name: "floor".into(),
            mesh: rt_core::shapes::quad(Vec3::ZERO, Vec3::Y, 12.0).into(),
            material: Material::lambertian([0.35; 3]),
            transform: Default::default(),
        },
    ];
    scene.camera.from = [0.0, 2.2, 3.6];
    scene.camera.to = [0.0, 0.95, 0.0];
    scene.camera.up = [0.0, 1.0, 0.0];
    scene.camera.vfov_deg = 38.0;
    scene.settings.width = size;
    scene.settings.height = size;
    scene.settings.samples_per_pixel = spp;
    scene.settings.max_depth = 8;
    // The studio's softboxes, reflected by metal and focused by glass onto the floor, leave
    // fireflies that 32 samples cannot average away: a picture needs no unbiased estimate.
    scene.settings.clamp = Some(3.0);
    scene
}

/// Renders `scene` on the CPU backend and tone-maps it (Khronos PBR Neutral); `None` if
/// cancelled or the scene does not build.
pub fn render_thumbnail(scene: &Scene, cancel: &AtomicBool) -> Option<egui::ColorImage> {
    let gpu_scene = rt_core::GpuScene::build(scene).ok()?;
    let frame = rt_core::frame::frame_for(scene, &gpu_scene).ok()?;
    let mut accumulation = rt_core::cpu_render::CpuAccumulation::new(&frame, 0, None, false);
    if !accumulation.add_batch(&gpu_scene, &frame, scene.settings.samples_per_pixel, cancel) {
        return None;
    }
    let rgb: Vec<[f32; 3]> = accumulation
        .pixels()
        .iter()
        .map(|p| [p[0], p[1], p[2]])
        .collect();
    let view = rt_core::output::View {
        transform: rt_core::output::ViewTransform::KhronosPbrNeutral,
        exposure_stops: 0.0,
        white_balance_k: None,
    };
    let size = [
        scene.settings.width as usize,
        scene.settings.height as usize,
    ];
    Some(egui::ColorImage::from_rgba_unmultiplied(
        size,
        &view.to_rgba8(&rgb),
    ))
}

/// The thumbnails of the presets, as they arrive from their thread.
#[derive(Default)]
pub struct Gallery {
    textures: Vec<Option<egui::TextureHandle>>,
    receiver: Option<mpsc::Receiver<(usize, egui::ColorImage)>>,
    cancel: Arc<AtomicBool>,
}

impl Gallery {
    /// Starts rendering the thumbnails (once); `repaint` is woken as each arrives.
    pub fn start(&mut self, repaint: egui::Context) {
        if self.receiver.is_some() {
            return;
        }
        self.textures = vec![None; PRESETS.len()];
        let (send, receive) = mpsc::channel();
        self.receiver = Some(receive);
        let cancel = self.cancel.clone();
        std::thread::spawn(move || {
            let environment = small_studio();
            for (i, preset) in PRESETS.iter().enumerate() {
                let scene = thumbnail_scene(
                    (preset.material)(),
                    environment.clone(),
                    THUMBNAIL_SIZE,
                    THUMBNAIL_SPP,
                );
                let Some(image) = render_thumbnail(&scene, &cancel) else {
                    return;
                };
                if send.send((i, image)).is_err() {
                    return;
                }
                repaint.request_repaint();
            }
        });
    }

    /// Uploads the thumbnails that arrived.
    pub fn poll(&mut self, ctx: &egui::Context) {
        let Some(receiver) = &self.receiver else {
            return;
        };
        while let Ok((i, image)) = receiver.try_recv() {
            let name = format!("gallery {}", PRESETS[i].name);
            self.textures[i] = Some(ctx.load_texture(name, image, egui::TextureOptions::LINEAR));
        }
    }

    /// Preset `i`'s thumbnail, once rendered.
    pub fn thumbnail(&self, i: usize) -> Option<&egui::TextureHandle> {
        self.textures.get(i)?.as_ref()
    }

    /// How many thumbnails have arrived.
    pub fn ready(&self) -> usize {
        self.textures.iter().flatten().count()
    }
}

impl Drop for Gallery {
    fn drop(&mut self) {
        self.cancel.store(true, Ordering::Relaxed);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The mean colour of a thumbnail's middle (the sphere), 0–255.
    fn sphere_colour(name: &str) -> [f32; 3] {
        let preset = PRESETS.iter().find(|p| p.name == name).unwrap();
        let scene = thumbnail_scene((preset.material)(), small_studio(), 24, 8);
        let image = render_thumbnail(&scene, &AtomicBool::new(false)).expect("renders");
        let mut sum = [0.0f32; 3];
        let mut n = 0.0;
        for y in 8..16 {
            for x in 8..16 {
                let p = image.pixels[y * 24 + x];
                sum[0] += f32::from(p.r());
                sum[1] += f32::from(p.g());
                sum[2] += f32::from(p.b());
                n += 1.0;
            }
        }
        sum.map(|s| s / n)
    }

    /// rt renders the thumbnails, and they tell materials apart: gold is warm where chrome is
    /// neutral, rubber is dark where plastic is light, the car paint is red.
    #[test]
    fn thumbnails_show_each_materials_colour() {
        let gold = sphere_colour("Gold");
        let chrome = sphere_colour("Chrome");
        assert!(gold[0] > 1.3 * gold[2], "gold {gold:?}");
        assert!(chrome[0] < 1.15 * chrome[2], "chrome {chrome:?}");
        let rubber = sphere_colour("Rubber");
        let plastic = sphere_colour("Plastic");
        let luma = |c: [f32; 3]| c[0] + c[1] + c[2];
        assert!(
            luma(plastic) > 2.0 * luma(rubber),
            "plastic {plastic:?}, rubber {rubber:?}"
        );
        let paint = sphere_colour("Car paint");
        assert!(paint[0] > 1.5 * paint[1], "car paint {paint:?}");
    }
}
