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
use rt_core::estimator;
use rt_core::shapes::quad;
use rt_core::{GpuScene, Material, Scene};
use rt_gpu::RenderOptions;

fn cornell_with_metal_and_glass(size: u32) -> Scene {
    let mut scene = rt_io::assets::cornell_box().unwrap();
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

/// The Cornell box in fog (σ_t 1/400 per unit: the room is ~1.4 mean free paths across, g 0.4) with
/// a point light beside the area light, the tall block glass (vacuum inside: its interior takes the
/// fog out of the rays through it) and the short block a scattering, absorbing volume (jade):
/// free flight in both media, phase-function and light sampling in both, shadow rays dimmed by
/// each, the medium stack entering and leaving.
fn cornell_in_fog(size: u32) -> Scene {
    let mut scene = cornell_with_metal_and_glass(size);
    for o in &mut scene.objects {
        match o.name.as_str() {
            "tall_block" => {
                o.material = Material::Dielectric {
                    ior: 1.5,
                    tint: [1.0; 3],
                }
            }
            "short_block" => {
                o.material = pbr(rt_core::material::Pbr {
                    base_color: [1.0; 3],
                    roughness: 0.2,
                    transmission: 1.0,
                    ior: 1.3,
                    attenuation_color: [0.5, 0.8, 0.6],
                    attenuation_distance: Some(60.0),
                    multiscatter_color: [0.6, 0.9, 0.7],
                    scatter_anisotropy: -0.3,
                    ..Default::default()
                })
            }
            _ => {}
        }
    }
    let mut bulb = rt_core::Light::new(rt_core::LightKind::Point, "bulb");
    bulb.position = [150.0, 400.0, 250.0];
    bulb.intensity = 40_000.0;
    scene.lights.push(bulb);
    scene.fog = rt_core::fog::Fog {
        density: 1.0 / 400.0,
        albedo: [0.9, 0.95, 1.0],
        anisotropy: 0.4,
    };
    scene.settings.max_depth = 8;
    scene
}
