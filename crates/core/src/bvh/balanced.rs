//! The BVH that holds for any triangle soup: splits at the median triangle (by centroid along the
//! widest axis, or anywhere when the centroids coincide), one triangle per leaf. Its depth is
//! ⌈log₂ n⌉ + 1 by construction (33 levels for 2³² triangles), within both traversal stacks
//! (`MAX_BVH_DEPTH`, and a third of it for the wide tree collapsed from it), where the
//! surface-area builder can make a chain of hundreds of levels out of coincident or degenerate
//! triangles (a fan over a polygon that repeats its corners). Slower to trace than the
//! surface-area tree, so it is the fallback when that one is too deep.

use glam::Vec3A;
use obvhs::Boundable;
use obvhs::aabb::Aabb;
use obvhs::bvh2::Bvh2;
use obvhs::bvh2::node::Bvh2Node;

use super::TriangleBox;

/// A median-split BVH2 over `triangles` in obvhs' layout (children of an inner node side by side
/// at `first_index`), one triangle per leaf.
pub fn median_split_bvh2(triangles: &[TriangleBox]) -> Bvh2 {
    let bounds: Vec<Aabb> = triangles.iter().map(Boundable::aabb).collect();
    let centroids: Vec<Vec3A> = bounds.iter().map(Aabb::center).collect();
    let mut order: Vec<u32> = (0..triangles.len() as u32).collect();
    let mut nodes = vec![Bvh2Node::default()];
    // (node, first, end) over `order`
    let mut stack = vec![(0usize, 0usize, triangles.len())];
    while let Some((node, first, end)) = stack.pop() {
        let aabb = order[first..end]
            .iter()
            .fold(Aabb::empty(), |b, &i| b.union(&bounds[i as usize]));
        if end - first <= 1 {
            nodes[node] = leaf(aabb, first);
            continue;
        }
        let centre_bounds = order[first..end].iter().fold(Aabb::empty(), |mut b, &i| {
            b.extend(centroids[i as usize]);
            b
        });
        let axis = centre_bounds.largest_axis();
        let middle = first + (end - first) / 2;
        order[first..end].select_nth_unstable_by(middle - first, |&a, &b| {
            centroids[a as usize][axis].total_cmp(&centroids[b as usize][axis])
        });
        let left = nodes.len();
        nodes.extend([Bvh2Node::default(); 2]);
        nodes[node] = Bvh2Node::new(aabb, 0, left as u32);
        stack.push((left, first, middle));
        stack.push((left + 1, middle, end));
    }
    Bvh2 {
        nodes,
        primitive_indices: order,
        ..Default::default()
    }
}

fn leaf(aabb: Aabb, first: usize) -> Bvh2Node {
    Bvh2Node::new(aabb, 1, first as u32)
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::Vec3;

    /// Depth of an obvhs BVH2 (levels on its longest root-to-leaf path).
    fn depth(bvh: &Bvh2, node: usize) -> usize {
        let n = &bvh.nodes[node];
        if n.prim_count > 0 {
            1
        } else {
            let first = n.first_index as usize;
            1 + depth(bvh, first).max(depth(bvh, first + 1))
        }
    }

    #[test]
    fn coincident_triangles_make_a_balanced_tree_holding_each_once() {
        let one = TriangleBox::of([Vec3::ZERO, Vec3::X, Vec3::Y]);
        for n in [1usize, 2, 3, 7, 1000, 4097] {
            let bvh = median_split_bvh2(&vec![one; n]);
            let bound = (n as f64).log2().ceil() as usize + 1;
            assert!(
                depth(&bvh, 0) <= bound,
                "{n}: depth {} > {bound}",
                depth(&bvh, 0)
            );
            let mut seen = bvh.primitive_indices.clone();
            seen.sort_unstable();
            assert_eq!(seen, (0..n as u32).collect::<Vec<_>>());
        }
    }

    #[test]
    fn every_leaf_lies_in_its_ancestors_boxes() {
        let triangles: Vec<TriangleBox> = (0..500)
            .map(|i| {
                let p = Vec3::new((i % 7) as f32, (i % 13) as f32 * 0.5, (i / 50) as f32);
                TriangleBox::of([p, p + Vec3::X, p + Vec3::Z * 0.25])
            })
            .collect();
        let bvh = median_split_bvh2(&triangles);
        let mut stack = vec![(0usize, Aabb::LARGEST)];
        let mut leaves = 0;
        while let Some((node, parent)) = stack.pop() {
            let n = &bvh.nodes[node];
            assert!(n.aabb().min.cmpge(parent.min).all() && n.aabb().max.cmple(parent.max).all());
            if n.prim_count > 0 {
                let t = &triangles[bvh.primitive_indices[n.first_index as usize] as usize];
                assert_eq!(Boundable::aabb(t).union(n.aabb()), *n.aabb());
                leaves += 1;
            } else {
                stack.push((n.first_index as usize, *n.aabb()));
                stack.push((n.first_index as usize + 1, *n.aabb()));
            }
        }
        assert_eq!(leaves, triangles.len());
    }
}
