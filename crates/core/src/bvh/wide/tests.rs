use glam::Vec3;
use obvhs::bvh2::reinsertion::ReinsertionOptimizer;

use super::*;
use crate::bvh::{BvhQuality, TriangleBox, balanced, surface_area_bvh2};

/// A linear congruential generator: the same soup on every run.
struct Random(u64);

impl Random {
    fn unit(&mut self) -> f32 {
        self.0 = self
            .0
            .wrapping_mul(6_364_136_223_846_793_005)
            .wrapping_add(1_442_695_040_888_963_407);
        (self.0 >> 40) as f32 / 16_777_216.0
    }

    fn point(&mut self, scale: f32) -> Vec3 {
        Vec3::new(self.unit(), self.unit(), self.unit()) * scale
    }
}

/// `count` small triangles scattered through a box, some in tight clusters, a few long slivers,
/// and some repeated exactly (equal boxes make cost ties); their boxes, as the builders read them.
fn soup(count: usize, seed: u64) -> Vec<TriangleBox> {
    let mut random = Random(seed);
    let mut triangles = Vec::with_capacity(count);
    for i in 0..count {
        let size = match i % 5 {
            0 => 5.0,
            1 => 0.001,
            _ => 0.05,
        };
        let v0 = random.point(10.0);
        let triangle = TriangleBox::of([v0, v0 + random.point(size), v0 + random.point(size)]);
        triangles.push(triangle);
        if i % 97 == 0 {
            triangles.push(triangle);
        }
    }
    triangles.truncate(count);
    triangles
}

/// The surface-area tree the scene's build collapses (PLOC and reinsertion, the `fast` preset).
fn ploc(triangles: &[TriangleBox]) -> Bvh2 {
    let params = BvhQuality::Fast.params();
    surface_area_bvh2(triangles, &params, &mut ReinsertionOptimizer::default())
}

/// The collapse equals obvhs' serial one byte for byte (nodes) and index for index (primitives).
fn assert_as_obvhs(bvh2: &Bvh2, max_prims_per_leaf: u32) {
    let ours = bvh2_to_cwbvh(bvh2, max_prims_per_leaf).expect("one primitive per leaf");
    let theirs = obvhs::cwbvh::bvh2_to_cwbvh::bvh2_to_cwbvh(bvh2, max_prims_per_leaf, true, false);
    assert_eq!(ours.1, theirs.primitive_indices, "primitive order");
    assert_eq!(ours.0.len(), theirs.nodes.len(), "node count");
    for (i, (a, b)) in ours.0.iter().zip(&theirs.nodes).enumerate() {
        assert_eq!(
            bytemuck::bytes_of(a),
            bytemuck::bytes_of(b),
            "wide node {i} of {}",
            ours.0.len()
        );
    }
}

#[test]
fn collapses_as_obvhs_does_on_surface_area_trees() {
    // Large enough that both passes fork (ten binary levels, three wide ones) and small ones that
    // stay on one thread, including a lone triangle (the root a leaf).
    for (count, seed) in [(1, 1), (2, 2), (9, 3), (300, 4), (40_000, 5)] {
        let triangles = soup(count, seed);
        for max_prims_per_leaf in [1, 3] {
            assert_as_obvhs(&ploc(&triangles), max_prims_per_leaf);
        }
    }
}

#[test]
fn collapses_as_obvhs_does_on_median_split_trees() {
    // The fallback tree for degenerate input: many coincident triangles.
    let mut triangles = soup(5_000, 6);
    triangles.extend(std::iter::repeat_n(triangles[0], 3_000));
    assert_as_obvhs(&balanced::median_split_bvh2(&triangles), 3);
}

#[test]
fn refuses_leaves_of_several_primitives() {
    let triangles = soup(64, 7);
    let params = BvhQuality::Fast.params();
    let mut bvh = ploc(&triangles);
    obvhs::bvh2::leaf_collapser::collapse(&mut bvh, params.max_prims_per_leaf, 1.0);
    assert!(
        bvh.nodes.iter().any(|n| n.prim_count > 1),
        "no leaf of several primitives"
    );
    match bvh2_to_cwbvh(&bvh, 3) {
        Err(error) => assert!(error.contains("leaves of one"), "{error}"),
        Ok(_) => panic!("collapsed a tree whose leaves hold several primitives"),
    }
}

/// A chain: each inner node's first child a leaf, its second the next inner node.
fn chain(leaves: u32) -> Bvh2 {
    use obvhs::aabb::Aabb;
    use obvhs::bvh2::node::Bvh2Node;
    let unit = Aabb::new(Vec3A::ZERO, Vec3A::ONE);
    let mut nodes = Vec::new();
    for i in 0..leaves - 1 {
        // Inner node 2i has children 2i + 1 (leaf i) and 2i + 2 (the next inner node).
        nodes.push(Bvh2Node::new(unit, 0, 2 * i + 1));
        nodes.push(Bvh2Node::new(unit, 1, i));
    }
    nodes.push(Bvh2Node::new(unit, 1, leaves - 1));
    Bvh2 {
        nodes,
        primitive_indices: (0..leaves).collect(),
        ..Default::default()
    }
}

#[test]
fn stops_on_trees_too_deep_for_the_kernels_stack() {
    // Deeper than any tree whose wide form fits the stack: refused (the builder then takes the
    // median-split tree) before the passes, which recurse, go deeper.
    let error = match bvh2_to_cwbvh(&chain(100_000), 3) {
        Err(error) => error,
        Ok(_) => panic!("collapsed a chain 100,000 levels deep"),
    };
    assert!(error.contains("deeper than"), "{error}");
    // Shallow enough: collapsed as obvhs does.
    assert_as_obvhs(&chain(150), 3);
}
