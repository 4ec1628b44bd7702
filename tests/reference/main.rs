//! The GPU kernel against the scalar CPU reference of the same estimator, the BVH traversal against
//! brute force, determinism, and the loop-budget sentinel.
//!
//! `cpu_backend.rs` holds the native CPU backend against the GPU, `cpu_reference.rs` the Z-tests and lockstep against the CPU reference, `traversal.rs` the
//! BVH against brute force, `determinism.rs` seeds and the loop-budget sentinel,
//! `sampling_strategies.rs` NEE, MIS and BSDF sampling against each other.

#[path = "../common/mod.rs"]
mod common;
mod cpu_backend;
mod cpu_reference;
mod determinism;
mod sampling_strategies;
mod traversal;

use common::*;
use glam::Vec3;
use rt_core::reference;
use rt_core::shapes::quad;
use rt_core::{GpuScene, Material, Scene};
use rt_gpu::RenderOptions;

fn cornell_with_metal_and_glass(size: u32) -> Scene {
    let mut scene = rt_core::assets::cornell_box().unwrap();
    for o in &mut scene.objects {
        match o.name.as_str() {
            "tall_block" => {
                o.material = Material::Metal {
                    albedo: [0.9, 0.8, 0.6],
                    fuzz: 0.2,
                }
            }
            "short_block" => {
                o.material = Material::Dielectric {
                    ior: 1.5,
                    tint: [0.9, 1.0, 0.9],
                }
            }
            _ => {}
        }
    }
    // Ambient light through the open front keeps the per-pixel variance low enough for the test to
    // have power (with only the small ceiling light, a 3% BSDF bias went undetected).
    scene.ambient = [1.0; 3];
    scene.settings = settings(size, size, 1, 6);
    scene
}
