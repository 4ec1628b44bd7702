//! Builds the BVH2 the kernel traverses, with obvhs (PLOC + reinsertion + leaf collapse).

use std::time::{Duration, Instant};

use glam::{Vec3, Vec3A};
use obvhs::BvhBuildParams;

use crate::gpu_types::BvhNode;

/// Deepest tree the kernel's traversal stack can hold (`BVH_STACK_SIZE` in `bvh.wgsl`).
pub const MAX_BVH_DEPTH: usize = 64;

/// Build-quality presets, from obvhs' fastest to its very slow builds.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum BvhQuality {
    Fastest,
    Fast,
    #[default]
    Medium,
    Slow,
}

impl BvhQuality {
    fn params(self) -> BvhBuildParams {
        let mut params = match self {
            BvhQuality::Fastest => BvhBuildParams::fastest_build(),
            BvhQuality::Fast => BvhBuildParams::fast_build(),
            BvhQuality::Medium => BvhBuildParams::medium_build(),
            BvhQuality::Slow => BvhBuildParams::slow_build(),
        };
        // Small leaves keep each traversal step short in the kernel.
        params.max_prims_per_leaf = params.max_prims_per_leaf.min(4);
        params
    }
}

/// A built BVH: nodes (root first) and the order in which triangles must be stored so that a leaf's
/// `first..first + count` indexes them directly.
pub struct BuiltBvh {
    pub nodes: Vec<BvhNode>,
    pub triangle_order: Vec<u32>,
    pub depth: usize,
    pub build_time: Duration,
}

/// Builds over world-space triangles. An empty input gives one empty leaf whose box no ray enters.
pub fn build_bvh(triangles: &[[Vec3; 3]], quality: BvhQuality) -> Result<BuiltBvh, String> {
    let start = Instant::now();
    if triangles.is_empty() {
        let empty = BvhNode {
            min: [f32::INFINITY; 3],
            first: 0,
            max: [f32::NEG_INFINITY; 3],
            count: 0,
        };
        return Ok(BuiltBvh {
            nodes: vec![empty],
            triangle_order: Vec::new(),
            depth: 1,
            build_time: start.elapsed(),
        });
    }
    let tris: Vec<obvhs::triangle::Triangle> = triangles
        .iter()
        .map(|t| obvhs::triangle::Triangle {
            v0: Vec3A::from(t[0]),
            v1: Vec3A::from(t[1]),
            v2: Vec3A::from(t[2]),
        })
        .collect();
    let mut core_time = Duration::ZERO;
    let bvh = obvhs::bvh2::builder::build_bvh2_from_tris(&tris, quality.params(), &mut core_time);

    let (nodes, triangle_order, depth) = layout_siblings(&bvh);
    if depth > MAX_BVH_DEPTH {
        return Err(format!(
            "BVH depth {depth} exceeds the kernel's traversal stack ({MAX_BVH_DEPTH})"
        ));
    }
    Ok(BuiltBvh {
        nodes,
        triangle_order,
        depth,
        build_time: start.elapsed(),
    })
}

/// Copies obvhs' tree into `BvhNode`s with both children of a node stored side by side, and leaf
/// triangles contiguous in the returned triangle order.
fn layout_siblings(bvh: &obvhs::bvh2::Bvh2) -> (Vec<BvhNode>, Vec<u32>, usize) {
    let to_node = |n: &obvhs::bvh2::node::Bvh2Node| BvhNode {
        min: n.aabb.min.to_array(),
        first: 0,
        max: n.aabb.max.to_array(),
        count: n.prim_count,
    };
    let mut nodes = vec![to_node(&bvh.nodes[0])];
    let mut triangle_order = Vec::new();
    let mut depth = 1;
    // (index in obvhs, index in output, level)
    let mut stack = vec![(0usize, 0usize, 1usize)];
    while let Some((src, dst, level)) = stack.pop() {
        depth = depth.max(level);
        let node = &bvh.nodes[src];
        if node.prim_count > 0 {
            nodes[dst].first = triangle_order.len() as u32;
            let first = node.first_index as usize;
            triangle_order
                .extend_from_slice(&bvh.primitive_indices[first..first + node.prim_count as usize]);
        } else {
            let left = node.first_index as usize;
            let out_left = nodes.len();
            nodes[dst].first = out_left as u32;
            nodes.push(to_node(&bvh.nodes[left]));
            nodes.push(to_node(&bvh.nodes[left + 1]));
            stack.push((left + 1, out_left + 1, level + 1));
            stack.push((left, out_left, level + 1));
        }
    }
    (nodes, triangle_order, depth)
}
