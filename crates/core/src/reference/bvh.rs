//! Nearest-hit and shadow queries through the scene's BVH, as the kernels run them: the BVH2
//! traversal is the twin of `shaders/shared/bvh.wgsl` (the wide BVH's, of `cwbvh.wgsl`, is in
//! `cwbvh.rs`), and brute force checks both.

use glam::Vec3;

use crate::bvh::BvhLayout;
use crate::gpu_scene::GpuScene;
use crate::gpu_types::Hit;
use crate::math::intersect::{PreparedRay, intersect_box, intersect_triangle};

pub(super) const MISS: u32 = u32::MAX;

/// No hit closer than `t_max` (yet).
pub(super) fn miss(t_max: f32) -> Hit {
    Hit {
        t: t_max,
        triangle: MISS,
        b1: 0.0,
        b2: 0.0,
    }
}

/// Tests triangle `i`, keeping its hit in `hit` when nearer (both traversals' leaf test).
pub(super) fn test_triangle(scene: &GpuScene, ray: &PreparedRay, i: u32, hit: &mut Hit) {
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
        };
    }
}

/// Nearest hit through the scene's BVH, as `intersect_scene` computes it in the kernel.
pub fn trace(scene: &GpuScene, origin: Vec3, direction: Vec3, t_max: f32) -> Hit {
    match scene.layout {
        BvhLayout::Bvh2 => trace_bvh2(scene, origin, direction, t_max),
        BvhLayout::Cwbvh => super::cwbvh::trace_wide(scene, origin, direction, t_max),
    }
}

/// Nearest hit through the BVH2, as `intersect_scene` in `bvh.wgsl` computes it.
fn trace_bvh2(scene: &GpuScene, origin: Vec3, direction: Vec3, t_max: f32) -> Hit {
    let ray = PreparedRay::new(origin, direction);
    let mut hit = miss(t_max);
    let mut stack = Vec::with_capacity(64);
    let mut index = 0usize;
    loop {
        let node = &scene.nodes[index];
        let children = [
            (node.left_min, node.left_max, node.left, node.left_count),
            (node.right_min, node.right_max, node.right, node.right_count),
        ];
        // Leaves are tested right away; inner children are visited near first.
        let mut inner = [None, None];
        for (slot, (lo, hi, first, count)) in children.into_iter().enumerate() {
            let Some(t) = intersect_box(&ray, lo.into(), hi.into(), hit.t) else {
                continue;
            };
            if count == 0 {
                // Child 0 is no child (see bvh.wgsl): an empty scene's root has two.
                if first != 0 {
                    inner[slot] = Some((t, first as usize));
                }
                continue;
            }
            for i in first..first + count {
                test_triangle(scene, &ray, i, &mut hit);
            }
        }
        let [l, r] = inner.map(|c| c.filter(|(t, _)| *t < hit.t));
        match (l, r) {
            (Some((tl, il)), Some((tr, ir))) => {
                let (near, far) = if tl <= tr { (il, ir) } else { (ir, il) };
                stack.push(far);
                index = near;
            }
            (Some((_, i)), None) | (None, Some((_, i))) => index = i,
            (None, None) => match stack.pop() {
                Some(next) => index = next,
                None => break,
            },
        }
    }
    hit
}

/// Whether anything lies on the segment from `origin` along unit `direction` up to `distance`.
pub fn occluded(scene: &GpuScene, origin: Vec3, direction: Vec3, distance: f32) -> bool {
    trace(scene, origin, direction, distance).triangle != MISS
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
