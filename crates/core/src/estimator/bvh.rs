//! The BVH2 traversal, the twin of `bvh.wgsl` beside it (the wide BVH's, of `cwbvh.wgsl`, is in
//! `cwbvh.rs`). `trace` in `mod.rs` picks the scene's layout; the leaf test both traversals share
//! is in `hit.rs`, below both.

/// The WGSL twin of this module, `bvh.wgsl` beside it (composed into the kernels by
/// `rt_gpu::shaders`).
pub const WGSL: &str = include_str!("bvh.wgsl");

use glam::Vec3;

use super::hit::{miss, test_triangle};
use crate::gpu_scene::GpuScene;
use crate::gpu_types::{BvhNode, Hit};
use crate::math::intersect::{PreparedRay, intersect_box};

/// Nearest hit through the BVH2 whose root is node `root`, or with `any_hit` the first found, as
/// `intersect_scene` in `bvh.wgsl` computes it.
pub(super) fn trace_bvh2(
    scene: &GpuScene,
    root: u32,
    origin: Vec3,
    direction: Vec3,
    t_max: f32,
    any_hit: bool,
) -> Hit {
    let ray = PreparedRay::new(origin, direction);
    let mut hit = miss(t_max);
    walk_bvh2(&scene.nodes, root, &ray, &mut hit, |first, count, hit| {
        (first..first + count).any(|i| test_triangle(scene, &ray, i, hit) && any_hit)
    });
    hit
}

/// Visits the leaves of the BVH2 in `nodes` under `root` that `ray` enters before `hit.t`, near
/// first: `leaf(first, count, hit)` tests one (narrowing `hit`) and returns whether to stop. The
/// scene's triangle BVHs and its top level over instances (`instances.rs`) share it.
#[inline(always)]
pub(super) fn walk_bvh2(
    nodes: &[BvhNode],
    root: u32,
    ray: &PreparedRay,
    hit: &mut Hit,
    mut leaf: impl FnMut(u32, u32, &mut Hit) -> bool,
) {
    // A fixed stack, as the kernel's (the builder keeps the BVH within it; a push past it is
    // dropped in both twins): no allocation per ray.
    let mut stack = [0usize; crate::bvh::MAX_BVH_DEPTH];
    let mut sp = 0;
    let mut index = root as usize;
    loop {
        let node = &nodes[index];
        let children = [
            (node.left_min, node.left_max, node.left, node.left_count),
            (node.right_min, node.right_max, node.right, node.right_count),
        ];
        // Leaves are tested right away; inner children are visited near first.
        let mut inner = [None, None];
        for (slot, (lo, hi, first, count)) in children.into_iter().enumerate() {
            let Some(t) = intersect_box(ray, lo.into(), hi.into(), hit.t) else {
                continue;
            };
            if count == 0 {
                // Child 0 is no child (see bvh.wgsl): an empty scene's root has two.
                if first != 0 {
                    inner[slot] = Some((t, first as usize));
                }
                continue;
            }
            if leaf(first, count, hit) {
                return;
            }
        }
        let [l, r] = inner.map(|c| c.filter(|(t, _)| *t < hit.t));
        match (l, r) {
            (Some((tl, il)), Some((tr, ir))) => {
                let (near, far) = if tl <= tr { (il, ir) } else { (ir, il) };
                if sp < stack.len() {
                    stack[sp] = far;
                    sp += 1;
                }
                index = near;
            }
            (Some((_, i)), None) | (None, Some((_, i))) => index = i,
            (None, None) if sp > 0 => {
                sp -= 1;
                index = stack[sp];
            }
            (None, None) => break,
        }
    }
}
