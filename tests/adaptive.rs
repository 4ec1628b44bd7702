//! Adaptive sampling (`RenderOptions::adaptive`): pixels stop taking samples once their noise
//! estimate, and their neighbours', is below the threshold. What it must keep: each pixel's mean
//! is exactly the running mean of its own first samples (the same random numbers as a render
//! without adaptive sampling), counts are kept per pixel, and a stopped pixel had met the
//! threshold.

mod common;

use common::*;
use rt_core::GpuScene;
use rt_gpu::{Adaptive, Kernel, RenderOptions, Renderer};

const SPP: u32 = 48;

/// One sample per batch, so that pixels stop at known counts, and every image of a render without
/// adaptive sampling is kept: a stopped pixel must hold, bit for bit, that render's value at its
/// count (both kernels, which also agree with each other).
#[test]
fn stopped_pixels_hold_the_mean_of_their_own_samples() {
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
    let mut images = Vec::new();
    for kernel in [Kernel::Wavefront, Kernel::Megakernel] {
        let options = RenderOptions {
            kernel,
            max_samples_per_dispatch: Some(1),
            ..Default::default()
        };
        // The render without adaptive sampling, image by image.
        let mut plain = Renderer::for_scene(ctx, &scene, &gpu_scene, options).unwrap();
        let mut steps = vec![plain.read_image().unwrap()];
        while plain.samples_done() < SPP {
            plain.render_batch(1).unwrap();
            steps.push(plain.read_image().unwrap());
        }
        let options = RenderOptions {
            adaptive: Some(adaptive),
            ..options
        };
        let mut renderer = Renderer::for_scene(ctx, &scene, &gpu_scene, options).unwrap();
        renderer.render(SPP, |_| true).unwrap();
        let image = renderer.read_image().unwrap();
        let counts = image.sample_counts.clone().expect("per-pixel counts");
        let stopped = counts
            .iter()
            .filter(|&&c| c < image.samples_per_pixel)
            .count();
        assert!(
            stopped * 10 >= counts.len() && renderer.active_pixels() > 0,
            "{kernel:?}: {stopped} of {} pixels stopped early, {} still sampling: the test \
             needs some of each",
            counts.len(),
            renderer.active_pixels()
        );
        for (i, (&count, pixel)) in counts.iter().zip(&image.pixels).enumerate() {
            assert!(
                count >= adaptive.min_samples,
                "{kernel:?}: pixel {i}: {count} samples"
            );
            assert!(
                *pixel == steps[count as usize].pixels[i],
                "{kernel:?}: pixel {i} after {count} samples differs from the plain render's"
            );
            if count < image.samples_per_pixel {
                let noise = rt_core::metrics::pixel_rel_mse(*pixel, count).sqrt();
                assert!(
                    noise <= f64::from(adaptive.threshold),
                    "{kernel:?}: pixel {i} stopped at noise {noise}"
                );
            }
        }
        images.push(image);
    }
    assert!(
        images[0].pixels == images[1].pixels && images[0].sample_counts == images[1].sample_counts,
        "the kernels stop different pixels or give them other values"
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
    let frame = rt_core::frame::frame_for(&scene, &gpu_scene).unwrap();
    let tiled = rt_gpu::render_tiled(
        ctx,
        &gpu_scene,
        frame,
        options.with_scene_settings(&scene.settings),
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

/// A threshold that is not a positive number is a clear error.
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
}
