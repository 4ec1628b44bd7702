//! Scenes with known answers, rendered on the GPU: furnaces, a lens-filling emitter, a mirror and a
//! glass slab at normal incidence, and an empty scene.
//!
//! `cameras.rs` holds the projections, `closed_form.rs` the furnaces, emitters, mirror, slab and
//! empty scene, `film.rs` alpha and the depth pass, `lights.rs` the delta lights, the sun and sky and the Sobol sampler,
//! `materials.rs` PBR, normal maps, texture wrap modes and alpha, `media.rs` fog and volumes.

mod cameras;
mod closed_form;
#[path = "../common/mod.rs"]
mod common;
mod film;
mod lights;
mod materials;
mod media;

use common::*;
use glam::Vec3;
use rt_core::shapes::{quad, uv_sphere};
use rt_core::{GpuScene, Material};
use rt_gpu::RenderOptions;

/// The image's mean red value must be `expected` within four standard errors, taken from the
/// spread of the pixels (every pixel has the same expected value).
fn assert_mean(image: &rt_gpu::Image, expected: f64, what: &str) {
    let (mean, std_error) = pixel_mean_and_error(image);
    assert!(
        (mean - expected).abs() <= 4.0 * std_error + 1e-6,
        "{what}: mean {mean} vs {expected} (σ {std_error})"
    );
}

fn assert_all_pixels(image: &rt_gpu::Image, expected: [f32; 3], tolerance: f32, what: &str) {
    for (i, p) in image.pixels.iter().enumerate() {
        for c in 0..3 {
            assert!(
                (p[c] - expected[c]).abs() <= tolerance,
                "{what}: pixel {i} channel {c} is {} but should be {}",
                p[c],
                expected[c]
            );
        }
    }
}
