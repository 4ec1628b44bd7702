//! The scene's nearest hit with instances (`crate::instances`): the world-space triangles' BVH
//! (node 0), then the top-level BVH2 over the instances' world boxes, each instance entered by
//! carrying the ray into its mesh's space and tracing its mesh's BVH. The twin of
//! `instance_bvh.wgsl` beside it.

/// The WGSL twin of this module, `instance_bvh.wgsl` beside it (composed into the kernels by
/// `rt_gpu::shaders`).
pub const WGSL: &str = include_str!("instance_bvh.wgsl");

use glam::Vec3;

use super::bvh::walk_bvh2;
use super::hit::MISS;
use crate::bvh::BvhLayout;
use crate::gpu_scene::GpuScene;
use crate::gpu_types::Hit;
use crate::math::intersect::PreparedRay;

/// `intersect_scene` of the kernels: the nearest hit, or with `any_hit` the first found. The
/// instances' top level is walked after the world-space triangles, with what they gave as the
/// bound.
pub(super) fn intersect_scene(
    scene: &GpuScene,
    origin: Vec3,
    dir: Vec3,
    t_max: f32,
    any_hit: bool,
) -> Hit {
    let hit = trace_mesh(scene, 0, origin, dir, t_max, any_hit);
    if scene.instances.is_empty() || (any_hit && hit.triangle != MISS) {
        return hit;
    }
    trace_instances(scene, origin, dir, hit, any_hit)
}

/// Nearest hit (or with `any_hit` the first) through the triangle BVH whose root is node `root`
/// in the scene's layout: the world-space triangles' (0) or an instanced mesh's.
fn trace_mesh(
    scene: &GpuScene,
    root: u32,
    origin: Vec3,
    dir: Vec3,
    t_max: f32,
    any_hit: bool,
) -> Hit {
    match scene.layout {
        BvhLayout::Bvh2 => super::bvh::trace_bvh2(scene, root, origin, dir, t_max, any_hit),
        BvhLayout::Cwbvh => super::cwbvh::trace_wide(scene, root, origin, dir, t_max, any_hit),
    }
}

/// `hit` narrowed by the instances `origin` + t·`direction` meets before `hit.t` (with
/// `any_hit`, the first one found).
fn trace_instances(
    scene: &GpuScene,
    origin: Vec3,
    direction: Vec3,
    mut hit: Hit,
    any_hit: bool,
) -> Hit {
    let ray = PreparedRay::new(origin, direction);
    walk_bvh2(
        &scene.instance_nodes,
        0,
        &ray,
        &mut hit,
        |first, count, hit| {
            for k in first..first + count {
                let instance = &scene.instances[k as usize];
                let o = instance.point_to_object(origin);
                let d = instance.direction_to_object(direction);
                let found = trace_mesh(scene, instance.root, o, d, hit.t, any_hit);
                if found.triangle != MISS {
                    *hit = Hit {
                        instance: k,
                        ..found
                    };
                    if any_hit {
                        return true;
                    }
                }
            }
            false
        },
    );
    hit
}
