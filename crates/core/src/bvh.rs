//! Builds the BVH the kernel traverses, with obvhs (PLOC + reinsertion + leaf collapse): a binary
//! BVH2 of uncompressed boxes, or obvhs' compressed wide BVH8 (CWBVH) collapsed from it. Where
//! that tree is deeper than a traversal stack (coincident or degenerate triangles can chain it),
//! the median-split tree of [`balanced`] replaces it, so any triangle soup builds. Large meshes
//! are built in spatial runs ([`chunked`]).

mod balanced;
mod chunked;
mod wide;

use std::time::{Duration, Instant};

use glam::{Vec3, Vec3A};
use obvhs::BvhBuildParams;
use obvhs::aabb::Aabb;
use obvhs::bvh2::reinsertion::ReinsertionOptimizer;

use crate::gpu_types::{BvhNode, WideBvhNode};

/// Deepest tree the kernel's traversal stack can hold (`BVH_STACK_SIZE` in `bvh.wgsl`).
pub const MAX_BVH_DEPTH: usize = 64;

/// Deepest wide tree the kernel's traversal stack can hold (`BVH_STACK_SIZE` in `cwbvh.wgsl`).
pub const MAX_WIDE_BVH_DEPTH: usize = 32;

/// Largest vertex coordinate magnitude for which the wide BVH is built (see `build_wide_bvh`).
pub const MAX_WIDE_BVH_COORDINATE: f32 = 1e15;

/// Which tree the kernel traverses; the pipeline is specialised for one.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub enum BvhLayout {
    /// Two children per node, 64 bytes, boxes in f32 (`bvh.wgsl`).
    Bvh2,
    /// Eight children per node, 80 bytes, boxes quantised to bytes (`cwbvh.wgsl`).
    #[default]
    Cwbvh,
}

/// Build-quality presets, from obvhs' fastest to its very slow builds. `Fast` is the default: on
/// the bench scenes (Cornell box, glass caustics, a many-lights room, bunny, dragons) its trees
/// traverse as fast as `Medium`'s on the CPU backend and lavapipe, and build 10–15% sooner
/// (docs/performance-log.md, session 25).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum BvhQuality {
    Fastest,
    #[default]
    Fast,
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
        // Spatial pre-splits (the slow presets) would list a triangle in several leaves; the scene
        // stores each triangle once, in leaf order.
        params.pre_split = false;
        params
    }
}

/// A built BVH: inner nodes (root first) and the order in which triangles must be stored so that a
/// leaf's `first..first + count` indexes them directly.
pub struct BuiltBvh {
    pub nodes: Vec<BvhNode>,
    pub triangle_order: Vec<u32>,
    /// Levels of inner nodes on the longest root-to-leaf path (what the traversal stack must hold).
    pub depth: usize,
    pub build_time: Duration,
}

/// A triangle's bounding box: all the builders read of a triangle (24 bytes, where obvhs'
/// `Triangle` holds the corners in 48; the scene's build keeps one per triangle while PLOC runs).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct TriangleBox {
    min: [f32; 3],
    max: [f32; 3],
}

impl TriangleBox {
    /// The box of a triangle's corners (as obvhs bounds its `Triangle`).
    pub fn of(corners: [Vec3; 3]) -> Self {
        let aabb = Aabb::from_points(&corners.map(Vec3A::from));
        Self::from_aabb(aabb)
    }

    /// The box spanning `lo` and `hi` (an instance's world box in the top-level tree).
    pub fn span(lo: Vec3, hi: Vec3) -> Self {
        Self::of([lo, hi, lo])
    }

    fn from_aabb(aabb: Aabb) -> Self {
        TriangleBox {
            min: aabb.min.to_array(),
            max: aabb.max.to_array(),
        }
    }

    /// The largest coordinate magnitude of its corners.
    fn largest_coordinate(&self) -> f32 {
        self.min
            .iter()
            .chain(&self.max)
            .fold(0.0f32, |m, c| m.max(c.abs()))
    }
}

impl obvhs::Boundable for TriangleBox {
    fn aabb(&self) -> Aabb {
        Aabb::new(self.min.into(), self.max.into())
    }
}

const EMPTY_MIN: [f32; 3] = [f32::INFINITY; 3];
const EMPTY_MAX: [f32; 3] = [f32::NEG_INFINITY; 3];

/// Builds over world-space triangles. An empty input gives one node with two empty children: child
/// index 0 with no triangles, which traversals read as no child (the root is nobody's child).
pub fn build_bvh(triangles: &[[Vec3; 3]], quality: BvhQuality) -> Result<BuiltBvh, String> {
    build_bvh_over(&triangle_boxes(triangles), quality)
}

/// [`build_bvh`] over the triangles' boxes (what `GpuScene` writes them into directly, so that no
/// copy of the corners is held during the build).
pub fn build_bvh_over(tris: &[TriangleBox], quality: BvhQuality) -> Result<BuiltBvh, String> {
    let start = Instant::now();
    let empty_root = BvhNode {
        left_min: EMPTY_MIN,
        left_max: EMPTY_MAX,
        right_min: EMPTY_MIN,
        right_max: EMPTY_MAX,
        ..Default::default()
    };
    if tris.is_empty() {
        return Ok(BuiltBvh {
            nodes: vec![empty_root],
            triangle_order: Vec::new(),
            depth: 1,
            build_time: start.elapsed(),
        });
    }
    // obvhs' `build_bvh2_from_tris` without spatial splits, over boxes.
    let params = quality.params();
    let mut reinsertion = ReinsertionOptimizer::default();
    let mut bvh = surface_area_bvh2(tris, &params, &mut reinsertion);
    obvhs::bvh2::leaf_collapser::collapse(
        &mut bvh,
        params.max_prims_per_leaf.clamp(1, 255),
        params.collapse_traversal_cost,
    );
    reinsertion.run(
        &mut bvh,
        params.reinsertion_batch_ratio * params.post_collapse_reinsertion_batch_ratio_multiplier,
        None,
    );
    let (mut nodes, mut triangle_order, mut depth) = kernel_nodes(&bvh, empty_root);
    if depth > MAX_BVH_DEPTH {
        log::warn!(
            "the surface-area BVH is {depth} levels deep (coincident or degenerate triangles); \
             using a median-split BVH"
        );
        (nodes, triangle_order, depth) =
            kernel_nodes(&balanced::median_split_bvh2(tris), empty_root);
    }
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

/// obvhs' BVH2 as the kernel's nodes (root first, leaves inlined into their parents), the
/// triangle order its leaves index, and its depth.
fn kernel_nodes(bvh: &obvhs::bvh2::Bvh2, empty_root: BvhNode) -> (Vec<BvhNode>, Vec<u32>, usize) {
    let mut nodes = vec![empty_root];
    let mut triangle_order = Vec::with_capacity(bvh.primitive_indices.len());
    let mut depth = 1;
    let root = &bvh.nodes[0];
    if root.prim_count > 0 {
        // A single leaf: the root's left child, the right one empty.
        let (first, count) = append_leaf(bvh, root, &mut triangle_order);
        nodes[0].left_min = root.aabb().min.to_array();
        nodes[0].left_max = root.aabb().max.to_array();
        nodes[0].left = first;
        nodes[0].left_count = count;
    } else {
        // (obvhs inner node, output node, level)
        let mut stack = vec![(0usize, 0usize, 1usize)];
        while let Some((src, dst, level)) = stack.pop() {
            depth = depth.max(level);
            let first_child = bvh.nodes[src].first_index as usize;
            for (side, child_index) in [first_child, first_child + 1].into_iter().enumerate() {
                let child = &bvh.nodes[child_index];
                let (index, count) = if child.prim_count > 0 {
                    append_leaf(bvh, child, &mut triangle_order)
                } else {
                    nodes.push(BvhNode::default());
                    stack.push((child_index, nodes.len() - 1, level + 1));
                    ((nodes.len() - 1) as u32, 0)
                };
                let (lo, hi) = (child.aabb().min.to_array(), child.aabb().max.to_array());
                let node = &mut nodes[dst];
                if side == 0 {
                    (node.left_min, node.left_max, node.left, node.left_count) =
                        (lo, hi, index, count);
                } else {
                    (node.right_min, node.right_max, node.right, node.right_count) =
                        (lo, hi, index, count);
                }
            }
        }
    }
    (nodes, triangle_order, depth)
}

/// The triangles' boxes.
pub fn triangle_boxes(triangles: &[[Vec3; 3]]) -> Vec<TriangleBox> {
    triangles.iter().map(|&t| TriangleBox::of(t)).collect()
}

/// PLOC's binary tree over the boxes, one triangle a leaf (large meshes in runs: `chunked`),
/// improved by reinsertion (the first steps of obvhs' builders).
fn surface_area_bvh2(
    tris: &[TriangleBox],
    params: &BvhBuildParams,
    reinsertion: &mut ReinsertionOptimizer,
) -> obvhs::bvh2::Bvh2 {
    let mut bvh2 = chunked::ploc_bvh2(tris, params, chunked::CHUNK_TRIANGLES);
    reinsertion.run(&mut bvh2, params.reinsertion_batch_ratio, None);
    bvh2
}

/// Appends a leaf's triangles to the order and returns (first, count).
fn append_leaf(
    bvh: &obvhs::bvh2::Bvh2,
    leaf: &obvhs::bvh2::node::Bvh2Node,
    order: &mut Vec<u32>,
) -> (u32, u32) {
    let first = order.len() as u32;
    let start = leaf.first_index as usize;
    order.extend_from_slice(&bvh.primitive_indices[start..start + leaf.prim_count as usize]);
    (first, leaf.prim_count)
}

/// A built wide BVH: nodes (root first) and the triangle order its leaves index, as `BuiltBvh`.
pub struct BuiltWideBvh {
    pub nodes: Vec<WideBvhNode>,
    pub triangle_order: Vec<u32>,
    pub depth: usize,
    pub build_time: Duration,
}

/// Builds a CWBVH over world-space triangles with obvhs (leaves of at most 3 triangles, children
/// ordered per ray octant). An empty input gives one node without children. Fails for geometry the
/// builder cannot handle; `GpuScene` then falls back to the BVH2.
pub fn build_wide_bvh(
    triangles: &[[Vec3; 3]],
    quality: BvhQuality,
) -> Result<BuiltWideBvh, String> {
    build_wide_bvh_over(&triangle_boxes(triangles), quality)
}

/// [`build_wide_bvh`] over the triangles' boxes.
pub fn build_wide_bvh_over(
    tris: &[TriangleBox],
    quality: BvhQuality,
) -> Result<BuiltWideBvh, String> {
    let start = Instant::now();
    if tris.is_empty() {
        return Ok(BuiltWideBvh {
            nodes: vec![WideBvhNode::default()],
            triangle_order: Vec::new(),
            depth: 1,
            build_time: start.elapsed(),
        });
    }
    // obvhs' collapse to 8-wide nodes sums surface-area costs in f32: with coordinates near f32's
    // range they overflow, and its node decisions come out invalid (a debug assertion found by the
    // project fuzzer). Such scenes take the BVH2, whose builder copes.
    let largest = tris
        .iter()
        .map(TriangleBox::largest_coordinate)
        .fold(0.0f32, f32::max);
    if largest > MAX_WIDE_BVH_COORDINATE {
        return Err(format!(
            "a vertex coordinate of magnitude {largest:e} is beyond the wide BVH's {MAX_WIDE_BVH_COORDINATE:e}"
        ));
    }
    // obvhs' `build_cwbvh_from_tris` without spatial splits, but collapsed to the wide tree on
    // every core (`wide`), a large mesh run by run (`chunked`). A panic in obvhs or a tree too
    // deep for the kernel's stack takes the median-split tree.
    let params = quality.params();
    let surface_area = std::panic::catch_unwind(|| {
        chunked::ploc_cwbvh(tris, &params, chunked::CHUNK_TRIANGLES, 3)
    });
    let surface_area = match surface_area {
        Ok(Ok(wide)) => Some(wide_kernel_nodes(wide, tris.len())?),
        _ => None,
    };
    let (nodes, triangle_order, depth) = match surface_area {
        Some(built) if built.2 <= MAX_WIDE_BVH_DEPTH => built,
        _ => {
            log::warn!(
                "the surface-area wide BVH is too deep (coincident or degenerate triangles); \
                 using one collapsed from a median-split BVH"
            );
            let balanced = balanced::median_split_bvh2(tris);
            wide_kernel_nodes(wide::bvh2_to_cwbvh(&balanced, 3)?, tris.len())?
        }
    };
    if depth > MAX_WIDE_BVH_DEPTH {
        return Err(format!(
            "wide BVH depth {depth} exceeds the kernel's traversal stack ({MAX_WIDE_BVH_DEPTH})"
        ));
    }
    Ok(BuiltWideBvh {
        nodes,
        triangle_order,
        depth,
        build_time: start.elapsed(),
    })
}

/// obvhs' CWBVH as the kernel's nodes, the triangle order its leaves index, and its depth.
fn wide_kernel_nodes(
    (nodes, primitive_indices): (Vec<obvhs::cwbvh::node::CwBvhNode>, Vec<u32>),
    triangles: usize,
) -> Result<(Vec<WideBvhNode>, Vec<u32>, usize), String> {
    if primitive_indices.len() != triangles {
        return Err(format!(
            "wide BVH lists {} triangles, the scene has {triangles}",
            primitive_indices.len()
        ));
    }
    let nodes: Vec<WideBvhNode> = nodes.iter().map(|n| bytemuck::cast(*n)).collect();
    let depth = wide_depth(&nodes);
    Ok((nodes, primitive_indices, depth))
}

/// Levels on the longest root-to-leaf path of a wide tree whose inner children come after their
/// parent (`GpuScene::check_kernel_indices` checks that), so one forward pass finds every level.
fn wide_depth(nodes: &[WideBvhNode]) -> usize {
    let mut level = vec![0usize; nodes.len()];
    if let Some(root) = level.first_mut() {
        *root = 1;
    }
    for (i, node) in nodes.iter().enumerate() {
        let inner = (node.exponents_imask >> 24).count_ones() as usize;
        for child in node.child_base as usize..node.child_base as usize + inner {
            if child > i && child < nodes.len() {
                level[child] = level[child].max(level[i] + 1);
            }
        }
    }
    level.into_iter().max().unwrap_or(0)
}
