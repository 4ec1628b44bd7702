//! PLOC in spatial runs, so that a large mesh's build never holds PLOC's working arrays for every
//! triangle at once, nor (for the wide tree) the whole mesh's binary tree (issue 43: bytes per
//! unique triangle).
//!
//! obvhs' PLOC over n triangles keeps, besides the 2n − 1 nodes of the tree it writes (64 bytes a
//! triangle), two cluster arrays of n nodes and n Morton codes: 96 more bytes a triangle
//! (docs/performance-log.md, session 29). So a large mesh is split at its median box centre along
//! its widest axis until each part (a run) holds at most [`CHUNK_TRIANGLES`], and each run is built
//! by PLOC on its own (its working arrays sized to the run, the runs spread over the cores). For the wide tree ([`ploc_cwbvh`]) each run is improved by
//! reinsertion and collapsed on its own, and a wide tree over the runs' roots joins them; for the
//! binary tree ([`ploc_bvh2`]) each run is written straight into its place in the one tree and a
//! PLOC over the runs' boxes joins them at the top. Only a run's edges see fewer merge candidates
//! than before. A mesh of up to two runs is built in one piece, as before.

use std::ops::Range;

use obvhs::BvhBuildParams;
use obvhs::aabb::Aabb;
use obvhs::bvh2::Bvh2;
use obvhs::bvh2::node::Bvh2Node;
use obvhs::bvh2::reinsertion::ReinsertionOptimizer;
use obvhs::cwbvh::node::CwBvhNode;
use obvhs::ploc::PlocBuilder;
use rayon::prelude::*;

use super::TriangleBox;
use super::wide::{self, Wide};

/// Triangles per run: PLOC's working arrays and tree for one run take about 10 MB.
pub const CHUNK_TRIANGLES: usize = 1 << 16;

/// PLOC's binary tree over `tris` (one triangle a leaf, leaves indexing `primitive_indices`), built
/// in runs of `chunk` triangles when there are more than two runs' worth.
pub fn ploc_bvh2(tris: &[TriangleBox], params: &BvhBuildParams, chunk: usize) -> Bvh2 {
    if tris.len() <= 2 * chunk {
        return ploc(tris, (0..tris.len() as u32).collect(), params);
    }
    let (order, ranges) = spatial_runs(tris, chunk);
    let runs: Vec<&[u32]> = ranges.iter().map(|r| &order[r.clone()]).collect();
    let run_boxes: Vec<TriangleBox> = runs
        .par_iter()
        .map(|run| {
            let aabb = run.iter().fold(Aabb::empty(), |b, &i| {
                b.union(&obvhs::Boundable::aabb(&tris[i as usize]))
            });
            TriangleBox::from_aabb(aabb)
        })
        .collect();
    let top = ploc(&run_boxes, (0..runs.len() as u32).collect(), params);
    // The top tree's leaves, one per run, are where the runs' roots go.
    let mut root_slot = vec![0usize; runs.len()];
    for (index, node) in top.nodes.iter().enumerate() {
        if node.prim_count > 0 {
            root_slot[top.primitive_indices[node.first_index as usize] as usize] = index;
        }
    }
    // Every run of m triangles brings 2m − 2 nodes below its root, placed after the top tree's.
    let mut nodes = vec![Bvh2Node::default(); 2 * tris.len() - 1];
    nodes[..top.nodes.len()].copy_from_slice(&top.nodes);
    let mut jobs = Vec::with_capacity(runs.len());
    let mut rest = &mut nodes[top.nodes.len()..];
    let mut offset = top.nodes.len();
    for (run, range) in runs.iter().zip(&ranges) {
        let (below, after) = rest.split_at_mut(2 * run.len() - 2);
        jobs.push(RunJob {
            run,
            below,
            offset,
            first_triangle: range.start,
        });
        offset += 2 * run.len() - 2;
        rest = after;
    }
    let group = runs.len().div_ceil(rayon::current_num_threads());
    let roots: Vec<Bvh2Node> = jobs
        .par_chunks_mut(group)
        .flat_map_iter(|group| {
            let mut workspace = Workspace::new(chunk);
            group
                .iter_mut()
                .map(|job| job.build(tris, params, &mut workspace))
                .collect::<Vec<_>>()
        })
        .collect();
    for (r, root) in roots.into_iter().enumerate() {
        nodes[root_slot[r]] = root;
    }
    Bvh2 {
        nodes,
        primitive_indices: order,
        ..Default::default()
    }
}

/// One run to build: its triangles, and where its nodes go in the whole tree.
struct RunJob<'a> {
    run: &'a [u32],
    /// The run's nodes below its root, from `offset` in the whole tree.
    below: &'a mut [Bvh2Node],
    offset: usize,
    /// Where the run's triangles start in the whole tree's order.
    first_triangle: usize,
}

impl RunJob<'_> {
    /// Builds the run with PLOC, writes its nodes below the root into place and returns its
    /// root (placed too).
    fn build(
        &mut self,
        tris: &[TriangleBox],
        params: &BvhBuildParams,
        workspace: &mut Workspace,
    ) -> Bvh2Node {
        let built = workspace.ploc(self.run, tris, params);
        let placed = |node: &Bvh2Node| placed(node, self.offset, self.first_triangle);
        for (slot, node) in self.below.iter_mut().zip(&built.nodes[1..]) {
            *slot = placed(node);
        }
        placed(&built.nodes[0])
    }
}

/// What one thread builds its runs with: allocated once for all of them (once a run, the holes
/// each left in the allocator's heaps cost more than the runs saved), as obvhs means its builder
/// to be kept.
struct Workspace {
    builder: PlocBuilder,
    bvh2: Bvh2,
    boxes: Vec<TriangleBox>,
    reinsertion: ReinsertionOptimizer,
}

impl Workspace {
    fn new(chunk: usize) -> Self {
        Workspace {
            builder: PlocBuilder::with_capacity(chunk),
            bvh2: Bvh2::default(),
            boxes: Vec::with_capacity(chunk),
            reinsertion: ReinsertionOptimizer::default(),
        }
    }

    /// PLOC's tree over a run's triangles (leaf i holds the run's triangle i).
    fn ploc(&mut self, run: &[u32], tris: &[TriangleBox], params: &BvhBuildParams) -> &mut Bvh2 {
        self.boxes.clear();
        self.boxes.extend(run.iter().map(|&i| tris[i as usize]));
        self.builder.build_with_bvh(
            &mut self.bvh2,
            params.ploc_search_distance,
            &self.boxes,
            (0..run.len() as u32).collect(),
            params.sort_precision,
            params.search_depth_threshold,
        );
        &mut self.bvh2
    }

    /// A run's wide tree (its leaves indexing the mesh's triangles), its root's cost as one wide
    /// child, and its box.
    fn collapse(
        &mut self,
        run: &[u32],
        tris: &[TriangleBox],
        params: &BvhBuildParams,
        max_prims_per_leaf: u32,
    ) -> Result<(Wide, f32, TriangleBox), String> {
        self.ploc(run, tris, params);
        self.reinsertion
            .run(&mut self.bvh2, params.reinsertion_batch_ratio, None);
        let (mut wide, cost) = wide::collapse(&self.bvh2, max_prims_per_leaf)?;
        for p in &mut wide.primitives {
            *p = run[*p as usize];
        }
        Ok((
            wide,
            cost,
            TriangleBox::from_aabb(*self.bvh2.nodes[0].aabb()),
        ))
    }
}

/// The wide tree over `tris`, collapsed from PLOC's binary tree improved by reinsertion (leaves of
/// at most `max_prims_per_leaf` triangles). Beyond two runs' worth of triangles each run is built,
/// improved and collapsed on its own, its binary tree freed before the next (the whole mesh's
/// binary tree, 64 bytes a triangle, is never held), and a wide tree over the runs' roots joins
/// them (`wide::collapse_over`). Returns the nodes, root first, and the triangle order.
pub fn ploc_cwbvh(
    tris: &[TriangleBox],
    params: &BvhBuildParams,
    chunk: usize,
    max_prims_per_leaf: u32,
) -> Result<(Vec<CwBvhNode>, Vec<u32>), String> {
    let mut reinsertion = ReinsertionOptimizer::default();
    if tris.len() <= 2 * chunk {
        let bvh2 = super::surface_area_bvh2(tris, params, &mut reinsertion);
        return wide::bvh2_to_cwbvh(&bvh2, max_prims_per_leaf);
    }
    let (order, ranges) = spatial_runs(tris, chunk);
    let runs: Vec<&[u32]> = ranges.iter().map(|r| &order[r.clone()]).collect();
    // The runs in one contiguous group per thread.
    let group = runs.len().div_ceil(rayon::current_num_threads());
    let built: Vec<Result<(Wide, f32, TriangleBox), String>> = runs
        .par_chunks(group)
        .flat_map_iter(|group| {
            let mut workspace = Workspace::new(chunk);
            group
                .iter()
                .map(|run| workspace.collapse(run, tris, params, max_prims_per_leaf))
                .collect::<Vec<_>>()
        })
        .collect();
    drop(order);
    let mut subtrees = Vec::with_capacity(built.len());
    let mut run_boxes = Vec::with_capacity(built.len());
    for run in built {
        let (wide, cost, aabb) = run?;
        subtrees.push((wide, cost));
        run_boxes.push(aabb);
    }
    let mut top = ploc(&run_boxes, (0..run_boxes.len() as u32).collect(), params);
    reinsertion.run(&mut top, params.reinsertion_batch_ratio, None);
    let whole = wide::collapse_over(&top, subtrees)?;
    Ok((whole.nodes, whole.primitives))
}

/// A run's node moved into the whole tree: its nodes below the root (from index 1) start at
/// `offset`, its triangles' positions in the order at `first_triangle`.
fn placed(node: &Bvh2Node, offset: usize, first_triangle: usize) -> Bvh2Node {
    let mut node = *node;
    node.first_index += if node.prim_count > 0 {
        first_triangle as u32
    } else {
        offset as u32 - 1
    };
    node
}

fn ploc<T: obvhs::Boundable>(boxes: &[T], indices: Vec<u32>, params: &BvhBuildParams) -> Bvh2 {
    PlocBuilder::with_capacity(boxes.len()).build(
        params.ploc_search_distance,
        boxes,
        indices,
        params.sort_precision,
        params.search_depth_threshold,
    )
}

/// The triangles' indices grouped into runs of at most `chunk`, and the runs: each part split at
/// its median box centre along the widest extent of its centres until it fits (a k-d tree's top
/// levels), so that the runs' boxes overlap little (consecutive stretches of the Morton order
/// would overlap their neighbours' wherever the curve turns, and the tree over the runs traced
/// 16% slower). Ties go by index, so the runs are the same on any number of cores.
fn spatial_runs(tris: &[TriangleBox], chunk: usize) -> (Vec<u32>, Vec<Range<usize>>) {
    let mut order: Vec<u32> = (0..tris.len() as u32).collect();
    let mut runs = Vec::new();
    split_into_runs(tris, &mut order, 0, chunk.max(1), &mut runs);
    (order, runs)
}

fn split_into_runs(
    tris: &[TriangleBox],
    part: &mut [u32],
    first: usize,
    chunk: usize,
    runs: &mut Vec<Range<usize>>,
) {
    if part.len() <= chunk {
        runs.push(first..first + part.len());
        return;
    }
    let centre = |i: u32| obvhs::Boundable::aabb(&tris[i as usize]).center();
    let bounds = part.iter().fold(Aabb::empty(), |mut b, &i| {
        b.extend(centre(i));
        b
    });
    let axis = bounds.largest_axis();
    let middle = part.len() / 2;
    part.select_nth_unstable_by(middle, |&a, &b| {
        centre(a)[axis].total_cmp(&centre(b)[axis]).then(a.cmp(&b))
    });
    let (left, right) = part.split_at_mut(middle);
    let (mut left_runs, mut right_runs) = (Vec::new(), Vec::new());
    rayon::join(
        || split_into_runs(tris, left, first, chunk, &mut left_runs),
        || split_into_runs(tris, right, first + middle, chunk, &mut right_runs),
    );
    runs.extend(left_runs);
    runs.extend(right_runs);
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::Vec3;

    fn boxes(n: usize) -> Vec<TriangleBox> {
        // A bumpy sheet with a few coincident triangles.
        (0..n)
            .map(|i| {
                let (x, z) = ((i % 97) as f32, (i / 97) as f32);
                let p = Vec3::new(x, (x * 0.3).sin() + (z * 0.7).cos(), z);
                let p = if i % 50 == 0 { Vec3::ZERO } else { p };
                TriangleBox::of([p, p + Vec3::X, p + Vec3::Z * 0.5])
            })
            .collect()
    }

    /// Every triangle in exactly one leaf, every node's box holding its children's, each inner
    /// node's children side by side and reached once.
    fn assert_well_formed(bvh: &Bvh2, tris: &[TriangleBox]) {
        let mut seen = vec![0u32; tris.len()];
        let mut reached = vec![0u32; bvh.nodes.len()];
        let mut stack = vec![0usize];
        while let Some(i) = stack.pop() {
            reached[i] += 1;
            let node = &bvh.nodes[i];
            let aabb = node.aabb();
            if node.prim_count > 0 {
                for k in 0..node.prim_count as usize {
                    let t = bvh.primitive_indices[node.first_index as usize + k] as usize;
                    seen[t] += 1;
                    let b = obvhs::Boundable::aabb(&tris[t]);
                    assert!(
                        aabb.union(&b) == *aabb,
                        "leaf {i} does not hold triangle {t}"
                    );
                }
            } else {
                for child in [node.first_index as usize, node.first_index as usize + 1] {
                    let b = *bvh.nodes[child].aabb();
                    assert!(
                        aabb.union(&b) == *aabb,
                        "node {i} does not hold child {child}"
                    );
                    stack.push(child);
                }
            }
        }
        assert!(
            seen.iter().all(|&s| s == 1),
            "a triangle not in exactly one leaf"
        );
        assert!(
            reached.iter().all(|&r| r == 1),
            "a node not reached exactly once"
        );
    }

    #[test]
    fn runs_make_one_tree_over_every_triangle() {
        let params = BvhBuildParams::fast_build();
        // Runs of 64: one of a single triangle at the end, and one tree without runs.
        for n in [1, 2, 100, 129, 64 * 7 + 1, 5000] {
            let tris = boxes(n);
            let bvh = ploc_bvh2(&tris, &params, 64);
            assert_eq!(bvh.nodes.len(), 2 * n - 1, "{n} triangles");
            assert_well_formed(&bvh, &tris);
        }
    }

    #[test]
    fn runs_collapse_into_one_valid_wide_tree() {
        let params = BvhBuildParams::fast_build();
        // Runs of 64, the last of one triangle in the second case; obvhs' validation checks
        // every node's quantised child boxes against the triangles below them, that every node
        // and every triangle is reached exactly once, and the depth.
        for n in [200, 64 * 7 + 1, 5000] {
            let tris = boxes(n);
            let (nodes, primitive_indices) = ploc_cwbvh(&tris, &params, 64, 3).expect("builds");
            let total_aabb = tris
                .iter()
                .fold(Aabb::empty(), |b, t| b.union(&obvhs::Boundable::aabb(t)));
            let cwbvh = obvhs::cwbvh::CwBvh {
                nodes,
                primitive_indices,
                total_aabb,
                exact_node_aabbs: None,
                uses_spatial_splits: false,
            };
            let result = cwbvh.validate(&tris, false);
            assert_eq!(result.prim_count, n, "{n} triangles");
        }
    }

    #[test]
    fn runs_are_a_permutation_split_at_medians() {
        let tris = boxes(4000);
        let (order, runs) = spatial_runs(&tris, 300);
        let mut sorted = order.clone();
        sorted.sort_unstable();
        assert!(sorted.iter().copied().eq(0..4000));
        // 4000 halved until at most 300: 16 runs of 250, one after another.
        assert_eq!(runs.len(), 16);
        assert!(runs.iter().all(|r| r.len() == 250));
        assert!(runs.windows(2).all(|w| w[0].end == w[1].start));
        // The first split: along the sheet's long side (x spans 97, z 41), every centre of the
        // first half at or before every one of the second.
        let x = |i: &u32| obvhs::Boundable::aabb(&tris[*i as usize]).center().x;
        let left = order[..2000].iter().map(x).fold(f32::MIN, f32::max);
        let right = order[2000..].iter().map(x).fold(f32::MAX, f32::min);
        assert!(left <= right, "halves overlap: {left} > {right}");
    }
}
