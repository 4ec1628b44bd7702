//! Degenerate geometry and extreme settings render without NaN/Inf (checked by `render_gpu`) and
//! with the expected result, or fail with a clear error (part of issue 5's suite).
//!
//! `geometry.rs` holds degenerate geometry and extreme camera settings, `energy.rs` materials and
//! light at their limits, `renderer.rs` cancelling, accumulation, tiles, kernels and pipelines,
//! `device_faults.rs` lost devices and out-of-memory errors mid-render.

#[path = "../common/mod.rs"]
mod common;
mod device_faults;
mod energy;
mod geometry;
mod renderer;

use common::*;
use glam::Vec3;
use rt_core::shapes::{cuboid, quad};
use rt_core::{GpuScene, Material};
use rt_gpu::{Kernel, RenderOptions, Renderer};
use std::time::Duration;

fn lit_room() -> Vec<rt_core::Object> {
    vec![
        object(
            "room",
            cuboid(Vec3::splat(-2.0), Vec3::splat(2.0), true),
            Material::lambertian([0.6; 3]),
        ),
        object(
            "light",
            quad(Vec3::new(0.0, 1.99, 0.0), -Vec3::Y, 1.0),
            Material::Emissive {
                color: [8.0; 3],
                intensity: 1.0,
            },
        ),
    ]
}

fn mean(image: &rt_gpu::Image) -> f64 {
    image.channel_means().iter().sum::<f64>() / 3.0
}

/// Replicated image means (seeds 1..=k) and their standard error.
fn mean_and_error(ctx: &rt_gpu::GpuContext, scene: &rt_core::Scene, k: u32) -> (f64, f64) {
    let mut scene = scene.clone();
    let replicas: Vec<f64> = (1..=k)
        .map(|seed| {
            scene.settings.seed = seed;
            mean(&render(ctx, &scene))
        })
        .collect();
    let m = replicas.iter().sum::<f64>() / f64::from(k);
    let var = replicas.iter().map(|r| (r - m).powi(2)).sum::<f64>() / f64::from(k - 1);
    (m, (var / f64::from(k)).sqrt())
}
