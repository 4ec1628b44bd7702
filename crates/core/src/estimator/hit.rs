//! What both BVH traversals (`bvh.rs`, `cwbvh.rs`) share, below both: the miss value (`MISS` of
//! `gpu_types.wgsl`) and the leaf-triangle test (`intersect_triangle_at` of `gpu_scene.wgsl`,
//! alpha included), and brute force over every triangle, which checks them.

use glam::Vec3;

use crate::gpu_scene::GpuScene;
use crate::gpu_types::{Hit, NO_INSTANCE};
use crate::math::intersect::{PreparedRay, intersect_triangle};
use crate::math::intersect_lanes::{LANES, intersect_triangles};

/// The `triangle` of a hit that found none.
pub(crate) const MISS: u32 = u32::MAX;

/// No hit closer than `t_max` (yet).
pub(super) fn miss(t_max: f32) -> Hit {
    Hit {
        t: t_max,
        triangle: MISS,
        b1: 0.0,
        b2: 0.0,
        instance: NO_INSTANCE,
    }
}

/// Tests triangle `i`, keeping its hit in `hit` when nearer (both traversals' leaf test); whether
/// it did.
pub(super) fn test_triangle(scene: &GpuScene, ray: &PreparedRay, i: u32, hit: &mut Hit) -> bool {
    let tri = &scene.triangles[i as usize];
    if let Some((t, b1, b2)) =
        intersect_triangle(ray, tri.v0.into(), tri.v1.into(), tri.v2.into(), hit.t)
        && (!scene.features.alpha || super::texture::stops_ray(scene, ray, tri, i, b1, b2))
    {
        *hit = Hit {
            t,
            triangle: i,
            b1,
            b2,
            instance: NO_INSTANCE,
        };
        return true;
    }
    false
}

/// `test_triangle` on triangles `base + bit` for each set bit of `mask`, ascending, four at a time
/// (`intersect_lanes`: the same hits bit for bit, fewer mispredicted branches); with `any_hit`,
/// stops at the first kept and returns true. `origin` is the ray's, permuted
/// (`intersect_lanes::permuted_origin`).
#[inline(always)]
pub(super) fn test_triangles(
    scene: &GpuScene,
    ray: &PreparedRay,
    origin: [f32; 3],
    (base, mut mask): (u32, u32),
    hit: &mut Hit,
    any_hit: bool,
) -> bool {
    while mask != 0 {
        let mut index = [0u32; LANES];
        let mut count = 0;
        while mask != 0 && count < LANES {
            index[count] = base + mask.trailing_zeros();
            mask &= mask - 1;
            count += 1;
        }
        // Lanes past `count` repeat the last triangle (finite, and ignored).
        let vertices = std::array::from_fn(|lane| {
            let tri = &scene.triangles[index[lane.min(count - 1)] as usize];
            [tri.v0.into(), tri.v1.into(), tri.v2.into()]
        });
        let lanes = intersect_triangles(ray, origin, &vertices);
        for (lane, &i) in index.iter().enumerate().take(count) {
            let (t, b1, b2) = (lanes.t[lane], lanes.b1[lane], lanes.b2[lane]);
            if !(lanes.crosses[lane] && t < hit.t) {
                continue;
            }
            let tri = &scene.triangles[i as usize];
            if !scene.features.alpha || super::texture::stops_ray(scene, ray, tri, i, b1, b2) {
                *hit = Hit {
                    t,
                    triangle: i,
                    b1,
                    b2,
                    instance: NO_INSTANCE,
                };
                if any_hit {
                    return true;
                }
            }
        }
    }
    false
}

/// Nearest hit by testing every triangle (for checking `trace`).
pub fn trace_brute_force(scene: &GpuScene, origin: Vec3, direction: Vec3, t_max: f32) -> Hit {
    let ray = PreparedRay::new(origin, direction);
    let mut hit = miss(t_max);
    for i in 0..scene.triangles.len() as u32 {
        test_triangle(scene, &ray, i, &mut hit);
    }
    hit
}
