//! Adaptive sampling (`RenderOptions::adaptive`, the rule and its two streams in
//! `rt_core::adaptive`): pixels stop taking samples once both streams' noise estimates, and
//! their neighbours', are below the threshold. What it must keep: the image's expectation (each
//! stream decides only for the other), counts per pixel, the same stops and values on both
//! kernels and, sample for sample, on the CPU backend.

mod common;

use std::sync::atomic::AtomicBool;

use common::*;
use rt_core::GpuScene;
use rt_gpu::{Adaptive, Kernel, RenderOptions, Renderer};

const SPP: u32 = 48;

/// The image mean's luminance and its variance from the pixels' own estimates (mean squared
/// luminance in the fourth channel).
fn mean_and_variance(pixels: &[[f32; 4]], counts: &[u32]) -> (f64, f64) {
    let n = pixels.len() as f64;
    let (mut mean, mut variance) = (0.0, 0.0);
    for (p, &count) in pixels.iter().zip(counts) {
        let y = rt_core::math::sampling::luminance(glam::Vec3::new(p[0], p[1], p[2])) as f64;
        mean += y / n;
        variance += (f64::from(p[3]) - y * y).max(0.0) / f64::from(count.max(1)) / (n * n);
    }
    (mean, variance)
}

/// One sample per batch, so that the streams alternate sample by sample as on the CPU backend:
/// both kernels stop the same pixels with the same values bit for bit, the CPU backend stops
/// (nearly all) the same ones with the same values up to the twins' rounding, every pixel takes
/// the minimum, some stop early while others go on, and the image mean agrees with a render
/// without adaptive sampling (a Z-test).
#[test]
fn both_kernels_and_the_cpu_backend_stop_alike_and_keep_the_mean() {
    let Some(ctx) = gpu() else { return };
    let mut scene = rt_io::assets::cornell_box().unwrap();
    scene.settings.width = 24;
    scene.settings.height = 24;
    scene.ambient = [0.5; 3];
    let gpu_scene = GpuScene::build(&scene).unwrap();
    let adaptive = Adaptive {
        threshold: 0.12,
        min_samples: 8,
    };
    let mut plain_scene = scene.clone();
    (
        scene.settings.adaptive_threshold,
        scene.settings.adaptive_min_samples,
    ) = (Some(0.12), 8);
    assert_eq!(Adaptive::of_settings(&scene.settings), Some(adaptive));
    let mut images = Vec::new();
    for kernel in [Kernel::Wavefront, Kernel::Megakernel] {
        let options = RenderOptions {
            kernel,
            max_samples_per_dispatch: Some(1),
            ..Default::default()
        };
        let mut renderer = Renderer::for_scene(ctx, &scene, &gpu_scene, options).unwrap();
        renderer.render(SPP, |_| true).unwrap();
        let image = renderer.read_image().unwrap();
        let counts = image.sample_counts.clone().expect("per-pixel counts");
        let stopped = counts.iter().filter(|&&c| c < SPP).count();
        assert!(
            stopped * 10 >= counts.len() && renderer.active_pixels() > 0,
            "{kernel:?}: {stopped} of {} pixels stopped early, {} still sampling: the test \
             needs some of each",
            counts.len(),
            renderer.active_pixels()
        );
        assert!(
            counts.iter().all(|&c| c >= adaptive.min_samples),
            "{kernel:?}: a pixel under the minimum"
        );
        images.push(image);
    }
    assert!(
        images[0].pixels == images[1].pixels && images[0].sample_counts == images[1].sample_counts,
        "the kernels stop different pixels or give them other values"
    );
    // The CPU backend, a sample a batch: even samples in one stream, odd in the other.
    let frame = rt_core::frame::frame_for(&scene, &gpu_scene).unwrap();
    let mut cpu = rt_core::cpu_render::CpuAccumulation::new(&frame, 0, Some(adaptive), false);
    let go = AtomicBool::new(false);
    while cpu.samples < SPP && cpu.active_pixels() > 0 {
        assert!(cpu.add_batch(&gpu_scene, &frame, 1, &go));
    }
    let (gpu_counts, cpu_counts) = (images[0].sample_counts.as_ref().unwrap(), cpu.counts());
    let same: Vec<usize> = (0..cpu_counts.len())
        .filter(|&i| cpu_counts[i] == gpu_counts[i])
        .collect();
    assert!(
        same.len() * 20 >= cpu_counts.len() * 19,
        "the CPU backend stops other pixels: {} of {} alike",
        same.len(),
        cpu_counts.len()
    );
    let cpu_pixels = cpu.pixels();
    for &i in &same {
        for (a, b) in cpu_pixels[i].iter().zip(&images[0].pixels[i]).take(3) {
            assert!(
                (a - b).abs() <= 1e-4 * a.abs().max(1.0),
                "pixel {i}: CPU {a}, GPU {b}"
            );
        }
    }
    // In expectation the image is the plain render's.
    let options = RenderOptions {
        max_samples_per_dispatch: Some(1),
        ..Default::default()
    };
    plain_scene.settings.adaptive_threshold = None;
    let mut plain = Renderer::for_scene(ctx, &plain_scene, &gpu_scene, options).unwrap();
    plain.render(SPP, |_| true).unwrap();
    let plain = plain.read_image().unwrap();
    let (m_plain, v_plain) = mean_and_variance(&plain.pixels, &vec![SPP; plain.pixels.len()]);
    let (m, v) = mean_and_variance(&images[0].pixels, gpu_counts);
    let z = (m - m_plain) / (v + v_plain).sqrt();
    assert!(
        z.abs() < 4.0,
        "adaptive mean {m}, plain {m_plain}: z = {z:.2}"
    );
}

/// A threshold every pixel meets at once stops the whole image after the minimum: the render
/// ends early (no sample is spent on a stopped pixel), tiled renders too.
#[test]
fn a_loose_threshold_stops_every_pixel_after_the_minimum() {
    let Some(ctx) = gpu() else { return };
    let mut scene = rt_io::assets::cornell_box().unwrap();
    scene.settings.width = 16;
    scene.settings.height = 12;
    scene.settings.samples_per_pixel = 1000;
    scene.settings.adaptive_threshold = Some(1e6);
    let gpu_scene = GpuScene::build(&scene).unwrap();
    // One sample a batch: pixels are checked after each, so all stop at exactly the minimum.
    let options = RenderOptions {
        max_samples_per_dispatch: Some(1),
        ..Default::default()
    };
    let mut renderer = Renderer::for_scene(ctx, &scene, &gpu_scene, options).unwrap();
    renderer.render(1000, |_| true).unwrap();
    assert_eq!(renderer.active_pixels(), 0);
    let min = rt_core::scene::ADAPTIVE_MIN_SAMPLES;
    assert_eq!(renderer.samples_done(), min);
    let image = renderer.read_image().unwrap();
    assert!(image.sample_counts.unwrap().iter().all(|&c| c == min));
    let tiled = rt_gpu::render_tiled(
        ctx,
        (&scene, &gpu_scene),
        options,
        1000,
        Some(16 * 16 * 5),
        |_| true,
    )
    .unwrap();
    assert!(tiled.image.sample_counts.unwrap().iter().all(|&c| c == min));
    assert!(
        tiled.image.pixels == image.pixels,
        "tiles differ from the whole image"
    );
}

/// A threshold that is not a positive number, or a minimum under two samples, is a clear error.
#[test]
fn a_bad_threshold_is_a_clear_error() {
    let Some(ctx) = gpu() else { return };
    let mut scene = rt_io::assets::cornell_box().unwrap();
    for bad in [0.0, -1.0, f32::NAN] {
        scene.settings.adaptive_threshold = Some(bad);
        let error = rt_core::frame::validate(&scene).unwrap_err().to_string();
        assert!(error.contains("adaptive sampling threshold"), "{error}");
        let gpu_scene = GpuScene::build(&scene).unwrap();
        assert!(Renderer::for_scene(ctx, &scene, &gpu_scene, RenderOptions::default()).is_err());
    }
    // Fewer than two samples before stopping leaves a stream without one.
    scene.settings.adaptive_threshold = Some(0.1);
    scene.settings.adaptive_min_samples = 1;
    let error = rt_core::frame::validate(&scene).unwrap_err().to_string();
    assert!(error.contains("at least 2 samples"), "{error}");
}
