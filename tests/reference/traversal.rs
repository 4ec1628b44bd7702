//! The GPU's BVH traversal against brute force.

use super::*;
use rt_core::bvh::{BvhLayout, BvhQuality};
use rt_core::estimator::trace_brute_force;
use rt_core::gpu_types::Ray;
use rt_gpu::GpuContext;

fn random_unit(state: &mut u32) -> Vec3 {
    let mut next = || {
        *state = rt_core::math::rng::pcg_hash(*state);
        *state as f32 / u32::MAX as f32
    };
    let z = 1.0 - 2.0 * next();
    let phi = std::f32::consts::TAU * next();
    let s = (1.0 - z * z).sqrt();
    Vec3::new(s * phi.cos(), s * phi.sin(), z)
}

/// The kernel's BVH traversals (BVH2 and compressed wide BVH) find the same nearest hit as testing
/// every triangle, for rays from all around a real mesh (the Stanford bunny, 3,674 triangles) aimed
/// into it and past it.
#[test]
fn gpu_bvh_traversal_matches_brute_force() {
    let Some(ctx) = gpu() else { return };
    let path =
        std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("assets/bunny/bunny-lowres-npm.obj");
    let scene = rt_io::obj::load_obj(&path, 0).unwrap();
    for layout in [BvhLayout::Bvh2, BvhLayout::Cwbvh] {
        let gpu_scene = GpuScene::build_with_layout(&scene, BvhQuality::default(), layout).unwrap();
        check_traversal_against_brute_force(ctx, &scene, &gpu_scene);
    }
}

fn check_traversal_against_brute_force(ctx: &GpuContext, scene: &Scene, gpu_scene: &GpuScene) {
    let layout = gpu_scene.layout;
    let (lo, hi) = scene.bounds().unwrap();
    let (center, radius) = ((lo + hi) * 0.5, (hi - lo).length() * 0.5);
    let mut state = 12345u32;
    let rays: Vec<Ray> = (0..4096)
        .map(|i| {
            let origin = center + random_unit(&mut state) * radius * 1.5;
            let target =
                center + random_unit(&mut state) * radius * if i % 4 == 0 { 1.2 } else { 0.4 };
            let t_max = if i % 8 == 0 { radius } else { f32::MAX };
            Ray {
                origin: origin.to_array(),
                t_max,
                direction: (target - origin).normalize().to_array(),
                _pad: 0.0,
            }
        })
        .collect();
    let hits = rt_gpu::trace_rays::trace_rays(ctx, gpu_scene, &rays, rt_gpu::Trace::Bvh).unwrap();
    let mut hit_count = 0;
    for (ray, gpu_hit) in rays.iter().zip(&hits) {
        let cpu = trace_brute_force(
            gpu_scene,
            ray.origin.into(),
            ray.direction.into(),
            ray.t_max,
        );
        let cpu_bvh = estimator::trace(
            gpu_scene,
            ray.origin.into(),
            ray.direction.into(),
            ray.t_max,
        );
        assert_eq!(
            cpu_bvh.triangle == u32::MAX,
            cpu.triangle == u32::MAX,
            "{layout:?}: CPU BVH vs brute force: {ray:?}"
        );
        assert_eq!(
            gpu_hit.triangle == u32::MAX,
            cpu.triangle == u32::MAX,
            "{layout:?}: hit/miss differs for {ray:?}: {gpu_hit:?} vs {cpu:?}"
        );
        if cpu.triangle != u32::MAX {
            hit_count += 1;
            // Same distance (a tie on a shared edge may pick either triangle).
            assert!(
                (gpu_hit.t - cpu.t).abs() <= 1e-5 * cpu.t.max(1.0),
                "{layout:?}: distance differs for {ray:?}: {gpu_hit:?} vs {cpu:?}"
            );
            assert!((cpu_bvh.t - cpu.t).abs() <= 1e-5 * cpu.t.max(1.0));
        }
    }
    assert!(
        hit_count > 2000,
        "{layout:?}: too few rays hit the mesh ({hit_count}) for the test to mean much"
    );
}
