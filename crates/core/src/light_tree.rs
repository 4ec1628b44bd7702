//! The light tree: a binary tree over the emitter triangles that next-event estimation descends to
//! pick an emitter by its importance at the shading point instead of by its power alone
//! (Conty Estevez & Kulla 2018, "Importance Sampling of Many Lights with Adaptive Tree Splitting";
//! as pbrt-v4's `BVHLightSampler` and Cycles' light tree). This file builds it; the descent and
//! the pmf of a given emitter are the estimator's (`reference::light_tree` and its WGSL twin).
//!
//! Each node bounds the emitters below it: a box (kept as its bounding sphere, all the importance
//! needs), a cone of normals (axis, θ_o), the angle past a normal they emit into (θ_e = π/2: rt's
//! emitters are one-sided diffuse) and their power Φ = Σ area × luminance(emission), the alias
//! table's weight. Point and spot lights are leaves too (as in pbrt-v4), with Φ = luminance of
//! their intensity, so that Φ/d² is the irradiance scale of either kind: a point emits over the
//! sphere (θ_o = π), a spot along its axis with θ_o its inner cone and θ_e the rest of its outer
//! one. Suns stay out: they are summed at every vertex (`reference::light::delta_lights_at`), as
//! pbrt keeps its infinite lights beside the tree. Splits minimise pbrt's cost over
//! 12 centroid buckets per axis,
//!   cost = Φ · M_Ω · A_box · K_r,  M_Ω = 2π(1 − cosθ_o) + π/2 (2θ_w sinθ_o − cos(θ_o − 2θ_w)
//!                                        − 2θ_o sinθ_o + cosθ_o),  θ_w = min(θ_o + θ_e, π),
//! with K_r the box's longest side over its side along the split axis (against thin slabs).
//! The binary tree is then collapsed into four-wide nodes (each node's slots are a binary node's
//! grandchildren), stored lane by lane so that a descent weighs four slots at once and goes half
//! as deep. Every node knows where it hangs in its parent, so the pmf of an emitter that a
//! BSDF-sampled ray hits is recomputed from its slot upwards (exact MIS).

use glam::{Quat, Vec3};

use crate::gpu_types::{DeltaLight, Emitter, LightNode, Material, Triangle, light_kind};
use crate::math::sampling::luminance;

/// Set in a leaf slot's `child` for a point or spot light: the rest is its index in the delta
/// lights (`DELTA_LEAF` in `light_tree.wgsl`); without it the slot names an emitter triangle.
pub const DELTA_LEAF: u32 = 1 << 31;

/// Whether the tree holds `light` (points and spots; suns are summed at each vertex).
pub fn in_tree(light: &DeltaLight) -> bool {
    matches!(
        light.kind,
        light_kind::POINT | light_kind::SPOT | light_kind::SPOT_GLTF
    )
}

/// Below this depth splits minimise the cost; deeper, they halve the emitters (so no tree is
/// deeper than this plus log2 of the emitter count; the descents stop at `MAX_DEPTH`).
const COST_SPLIT_DEPTH: usize = 48;

/// The most nodes a descent visits (the kernels' loop bound): the binary tree's depth is at most
/// `COST_SPLIT_DEPTH` + 32 halvings, and a four-wide node takes two of its levels.
pub const MAX_DEPTH: u32 = 41;

const BUCKETS: usize = 12;

/// A node's bounds while building (`LightNode` without its links).
#[derive(Clone, Copy, Debug)]
struct LightBounds {
    lo: Vec3,
    hi: Vec3,
    axis: Vec3,
    cos_theta_o: f32,
    cos_theta_e: f32,
    power: f32,
}

impl LightBounds {
    /// An emitter triangle: its box, its normal (one-sided, emitting over the hemisphere).
    fn of_triangle(t: &Triangle, power: f32) -> Self {
        let v = [t.v0, t.v1, t.v2].map(Vec3::from);
        LightBounds {
            lo: v[0].min(v[1]).min(v[2]),
            hi: v[0].max(v[1]).max(v[2]),
            axis: (v[1] - v[0]).cross(v[2] - v[0]).normalize(),
            cos_theta_o: 1.0,
            cos_theta_e: 0.0,
            power,
        }
    }

    /// A point or spot light: a point, emitting over the sphere (a point) or within its outer cone
    /// (a spot, at full strength within its inner one).
    fn of_delta(light: &DeltaLight) -> Self {
        let position = Vec3::from(light.position);
        let power = luminance(Vec3::from(light.power)).min(f32::MAX / 4.0);
        let (axis, cos_theta_o, cos_theta_e) = if light.kind == light_kind::POINT {
            (Vec3::Z, -1.0, 0.0)
        } else {
            let theta_outer = light.cos_outer.clamp(-1.0, 1.0).acos();
            let theta_o = light.cos_inner.clamp(-1.0, 1.0).acos().min(theta_outer);
            // Widened a little, so rounding never cuts the falloff's last sliver off, and its
            // cosine kept below 1: a hard-edged spot (inner = outer, as glTF importers make of
            // inner > outer) has θ_e = 0, and the importance's strict cos θ′ > cos θ_e would
            // never hold.
            let theta_e = (theta_outer - theta_o + 1e-3).min(std::f32::consts::PI);
            let axis = Vec3::from(light.direction).normalize_or(Vec3::Z);
            (axis, theta_o.cos(), theta_e.cos().min(1.0 - 1e-6))
        };
        LightBounds {
            lo: position,
            hi: position,
            axis,
            cos_theta_o,
            cos_theta_e,
            power,
        }
    }

    fn union(&self, b: &LightBounds) -> LightBounds {
        let (axis, cos_theta_o) =
            cone_union((self.axis, self.cos_theta_o), (b.axis, b.cos_theta_o));
        LightBounds {
            lo: self.lo.min(b.lo),
            hi: self.hi.max(b.hi),
            axis,
            cos_theta_o,
            cos_theta_e: self.cos_theta_e.min(b.cos_theta_e),
            // Kept finite: four slots' sum must be too.
            power: (self.power + b.power).min(f32::MAX / 4.0),
        }
    }

    fn centroid(&self) -> Vec3 {
        0.5 * (self.lo + self.hi)
    }

    /// pbrt's split cost of these bounds as a child of a box with diagonal `parent_diagonal`,
    /// split along `axis`.
    fn cost(&self, parent_diagonal: Vec3, axis: usize) -> f64 {
        use std::f64::consts::PI;
        let cos_o = f64::from(self.cos_theta_o.clamp(-1.0, 1.0));
        let theta_o = cos_o.acos();
        let theta_e = f64::from(self.cos_theta_e.clamp(-1.0, 1.0)).acos();
        let theta_w = (theta_o + theta_e).min(PI);
        let sin_o = (1.0 - cos_o * cos_o).max(0.0).sqrt();
        let m_omega = 2.0 * PI * (1.0 - cos_o)
            + PI / 2.0
                * (2.0 * theta_w * sin_o - (theta_o - 2.0 * theta_w).cos() - 2.0 * theta_o * sin_o
                    + cos_o);
        let d = (self.hi - self.lo).as_dvec3();
        let area = 2.0 * (d.x * d.y + d.y * d.z + d.z * d.x);
        let along = f64::from(parent_diagonal[axis]);
        let k_r = if along > 0.0 {
            f64::from(parent_diagonal.max_element()) / along
        } else {
            1.0
        };
        f64::from(self.power) * m_omega * k_r * area
    }
}

/// The smallest cone (axis, cosine of its half-angle) holding two cones (pbrt's
/// `DirectionCone::Union`).
fn cone_union(a: (Vec3, f32), b: (Vec3, f32)) -> (Vec3, f32) {
    use std::f32::consts::PI;
    let theta_a = a.1.clamp(-1.0, 1.0).acos();
    let theta_b = b.1.clamp(-1.0, 1.0).acos();
    let theta_d = a.0.angle_between(b.0);
    if (theta_d + theta_b).min(PI) <= theta_a {
        return a;
    }
    if (theta_d + theta_a).min(PI) <= theta_b {
        return b;
    }
    let theta_o = 0.5 * (theta_a + theta_d + theta_b);
    let rotation_axis = a.0.cross(b.0);
    if theta_o >= PI || rotation_axis.length_squared() == 0.0 {
        return (a.0, -1.0);
    }
    let axis = Quat::from_axis_angle(rotation_axis.normalize(), theta_o - theta_a) * a.0;
    (axis.normalize(), theta_o.cos())
}

/// The tree over `emitters` (the alias table's entries, in triangle order), whose `leaf` fields it
/// sets, and over the point and spot lights among `delta_lights` (`in_tree`). Empty without
/// either.
pub fn build_light_tree(
    emitters: &mut [Emitter],
    triangles: &[Triangle],
    materials: &[Material],
    delta_lights: &[DeltaLight],
) -> Vec<LightNode> {
    let mut items: Vec<(LightBounds, u32)> = emitters
        .iter()
        .map(|e| {
            let t = &triangles[e.triangle as usize];
            let v = [t.v0, t.v1, t.v2].map(Vec3::from);
            let area = 0.5 * (v[1] - v[0]).cross(v[2] - v[0]).length();
            let emission = luminance(Vec3::from(materials[t.material as usize].emission));
            // In f64 and clamped: a huge bright triangle keeps a finite power.
            let power = (f64::from(area) * f64::from(emission)).min(f64::from(f32::MAX / 4.0));
            (LightBounds::of_triangle(t, power as f32), e.triangle)
        })
        .collect();
    items.extend(
        delta_lights
            .iter()
            .enumerate()
            .filter(|(_, l)| in_tree(l))
            .map(|(i, l)| (LightBounds::of_delta(l), DELTA_LEAF | i as u32)),
    );
    if items.is_empty() {
        return Vec::new();
    }
    let mut binary = Vec::new();
    build_binary(&mut items, 0, &mut binary);
    let mut nodes = vec![LightNode::default()];
    let root = &binary[0];
    let slots = match root.children {
        // One emitter: a root with one leaf slot.
        None => vec![0],
        Some(_) => grandchildren(&binary, 0),
    };
    collapse(&binary, &slots, 0, 0, &mut nodes);
    for (code, node) in nodes
        .iter()
        .enumerate()
        .flat_map(|(i, node)| (0..4).map(move |slot| (4 * i + slot, node)))
    {
        let slot = code % 4;
        if node.leaves & (1 << slot) != 0 && node.child[slot] & DELTA_LEAF == 0 {
            let triangle = node.child[slot];
            let i = emitters.partition_point(|e| e.triangle < triangle);
            emitters[i].leaf = code as u32;
        }
    }
    nodes
}

/// A node of the binary tree the build makes first: its bounds, and its two children or its
/// light (an emitter triangle, or `DELTA_LEAF` and a delta light).
struct BinaryNode {
    bounds: LightBounds,
    children: Option<[usize; 2]>,
    triangle: u32,
}

/// Appends the binary tree over `items` to `out`; returns its root's index.
fn build_binary(
    items: &mut [(LightBounds, u32)],
    depth: usize,
    out: &mut Vec<BinaryNode>,
) -> usize {
    let index = out.len();
    if let [(bounds, triangle)] = items {
        out.push(BinaryNode {
            bounds: *bounds,
            children: None,
            triangle: *triangle,
        });
        return index;
    }
    out.push(BinaryNode {
        bounds: items[0].0,
        children: None,
        triangle: 0,
    });
    let mid = split(items, depth);
    let (left, right) = items.split_at_mut(mid);
    let a = build_binary(left, depth + 1, out);
    let b = build_binary(right, depth + 1, out);
    out[index].bounds = out[a].bounds.union(&out[b].bounds);
    out[index].children = Some([a, b]);
    index
}

/// The slots of the four-wide node standing for binary node `index`: its children, each replaced
/// by its own two where it has them (2 to 4 slots).
fn grandchildren(binary: &[BinaryNode], index: usize) -> Vec<usize> {
    let mut slots = Vec::with_capacity(4);
    for child in binary[index].children.into_iter().flatten() {
        match binary[child].children {
            Some(pair) => slots.extend(pair),
            None => slots.push(child),
        }
    }
    slots
}

/// Fills four-wide node `index` (at `parent_code` = 4 × parent + slot) with the binary nodes
/// `slots`, appending a node for each interior one.
fn collapse(
    binary: &[BinaryNode],
    slots: &[usize],
    index: usize,
    parent_code: u32,
    nodes: &mut Vec<LightNode>,
) {
    let mut node = LightNode {
        parent: parent_code,
        ..Default::default()
    };
    for (slot, &b) in slots.iter().enumerate() {
        let bounds = &binary[b].bounds;
        let centre = bounds.centroid();
        let cos_theta_o = bounds.cos_theta_o.clamp(-1.0, 1.0);
        node.centre_x[slot] = centre.x;
        node.centre_y[slot] = centre.y;
        node.centre_z[slot] = centre.z;
        node.axis_x[slot] = bounds.axis.x;
        node.axis_y[slot] = bounds.axis.y;
        node.axis_z[slot] = bounds.axis.z;
        node.power[slot] = bounds.power;
        node.cos_theta_o[slot] = cos_theta_o;
        node.sin_theta_o[slot] = (1.0 - cos_theta_o * cos_theta_o).max(0.0).sqrt();
        node.cos_theta_e[slot] = bounds.cos_theta_e;
        // Rounded up a little, so the sphere holds every corner however the sums round.
        node.radius[slot] = 0.5 * (bounds.hi - bounds.lo).length() * (1.0 + 1e-5);
        if binary[b].children.is_none() {
            node.leaves |= 1 << slot;
            node.child[slot] = binary[b].triangle;
        }
    }
    let interior: Vec<(usize, usize)> = slots
        .iter()
        .enumerate()
        .filter(|(_, b)| binary[**b].children.is_some())
        .map(|(slot, b)| (slot, *b))
        .collect();
    let first = nodes.len();
    for (k, (slot, _)) in interior.iter().enumerate() {
        node.child[*slot] = (first + k) as u32;
    }
    nodes[index] = node;
    nodes.extend(std::iter::repeat_n(LightNode::default(), interior.len()));
    for (k, (slot, b)) in interior.into_iter().enumerate() {
        let below = grandchildren(binary, b);
        collapse(binary, &below, first + k, (4 * index + slot) as u32, nodes);
    }
}

/// Reorders `items` and returns where the second child's begin (0 < mid < len): the cheapest of
/// the bucket splits, else (no two centroids apart, or too deep) half of them along the longest
/// axis of their centroids.
fn split(items: &mut [(LightBounds, u32)], depth: usize) -> usize {
    let (c_lo, c_hi) = items.iter().fold(
        (Vec3::splat(f32::MAX), Vec3::splat(f32::MIN)),
        |(lo, hi), (b, _)| (lo.min(b.centroid()), hi.max(b.centroid())),
    );
    let extent = c_hi - c_lo;
    if depth < COST_SPLIT_DEPTH {
        // The boxes alone: the cones' union would cost an acos and a rotation per item.
        let (lo, hi) = items.iter().fold(
            (Vec3::splat(f32::MAX), Vec3::splat(f32::MIN)),
            |(lo, hi), (b, _)| (lo.min(b.lo), hi.max(b.hi)),
        );
        let diagonal = hi - lo;
        let mut best: Option<(f64, usize, usize)> = None;
        for axis in 0..3 {
            if extent[axis].is_nan() || extent[axis] <= 0.0 {
                continue;
            }
            let bucket_of = |b: &LightBounds| {
                let t = (b.centroid()[axis] - c_lo[axis]) / extent[axis];
                ((t * BUCKETS as f32) as usize).min(BUCKETS - 1)
            };
            let mut buckets: [Option<LightBounds>; BUCKETS] = [None; BUCKETS];
            for (b, _) in items.iter() {
                let slot = &mut buckets[bucket_of(b)];
                *slot = Some(slot.map_or(*b, |s| s.union(b)));
            }
            let merge = |range: &[Option<LightBounds>]| {
                range.iter().flatten().fold(None::<LightBounds>, |acc, b| {
                    Some(acc.map_or(*b, |a| a.union(b)))
                })
            };
            for cut in 1..BUCKETS {
                let (Some(below), Some(above)) = (merge(&buckets[..cut]), merge(&buckets[cut..]))
                else {
                    continue;
                };
                let cost = below.cost(diagonal, axis) + above.cost(diagonal, axis);
                if best.is_none_or(|(c, _, _)| cost < c) {
                    best = Some((cost, axis, cut));
                }
            }
        }
        if let Some((_, axis, cut)) = best {
            let below = |b: &LightBounds| {
                let t = (b.centroid()[axis] - c_lo[axis]) / extent[axis];
                ((t * BUCKETS as f32) as usize).min(BUCKETS - 1) < cut
            };
            let mut mid = 0;
            for i in 0..items.len() {
                if below(&items[i].0) {
                    items.swap(i, mid);
                    mid += 1;
                }
            }
            if mid > 0 && mid < items.len() {
                return mid;
            }
        }
    }
    let axis = extent.max_position();
    let mid = items.len() / 2;
    items.select_nth_unstable_by(mid, |a, b| {
        a.0.centroid()[axis].total_cmp(&b.0.centroid()[axis])
    });
    mid
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::material_kind::MaterialKind;
    use crate::math::rng::Rng;
    use crate::reference::light_tree::{leaf_of, sample_tree, slot_importances, tree_pmf};

    /// `count` emitter triangles of random size, place, facing and emission (and a non-emitter
    /// among them), with their materials; `facing` makes every normal that direction.
    fn emitters(count: usize, facing: Option<Vec3>) -> (Vec<Triangle>, Vec<Material>) {
        let mut rng = Rng::new(3, 0, 0x7ee);
        let mut u = || rng.next_f32();
        let mut materials = vec![Material::default()];
        let mut triangles = Vec::new();
        for i in 0..count {
            let centre = Vec3::new(u(), u(), u()) * 10.0 - 5.0;
            let n = facing.unwrap_or_else(|| (Vec3::new(u(), u(), u()) * 2.0 - 1.0).normalize());
            let (t, b) = crate::math::sampling::onb(n);
            let size = 0.05 + 0.5 * u();
            let emission = 10f32.powf(3.0 * u() - 1.0);
            materials.push(Material {
                kind: MaterialKind::Emissive.tag(),
                emission: [emission, emission * u(), emission],
                ..Default::default()
            });
            triangles.push(Triangle {
                v0: (centre - t * size).to_array(),
                material: if i == count / 2 {
                    0
                } else {
                    materials.len() as u32 - 1
                },
                v1: (centre + t * size).to_array(),
                has_normals: 0,
                v2: (centre + b * size).to_array(),
                has_uvs: 0,
            });
        }
        (triangles, materials)
    }

    fn tree(count: usize, facing: Option<Vec3>) -> (Vec<Emitter>, Vec<LightNode>, f32) {
        let (triangles, materials) = emitters(count, facing);
        let (mut emitters, power) = crate::emitters::build_emitters(&triangles, &materials);
        let nodes = build_light_tree(&mut emitters, &triangles, &materials, &[]);
        (emitters, nodes, power)
    }

    /// The slot `code` (4 × node + slot) of `nodes`: its sphere (centre, radius) and power.
    fn slot(nodes: &[LightNode], code: u32) -> (Vec3, f32, f32) {
        let (n, k) = (&nodes[(code / 4) as usize], (code % 4) as usize);
        let centre = Vec3::new(n.centre_x[k], n.centre_y[k], n.centre_z[k]);
        (centre, n.radius[k], n.power[k])
    }

    /// The slots from an emitter's own up to the root's.
    fn ancestry(nodes: &[LightNode], leaf: u32) -> Vec<u32> {
        let mut codes = vec![leaf];
        while codes.last().unwrap() / 4 != 0 {
            codes.push(nodes[(codes.last().unwrap() / 4) as usize].parent);
        }
        codes
    }

    /// Every emitter has one leaf slot that names its triangle, every sphere on its way to the
    /// root holds it, each slot's power is the sum of its node's, and the tree is four-wide
    /// (depth about log4 of the emitter count).
    #[test]
    fn the_tree_holds_every_emitter_once_with_consistent_bounds() {
        let (emitters, nodes, power) = tree(500, None);
        assert_eq!(emitters.len(), 499, "the non-emitter is left out");
        let leaves: u32 = nodes.iter().map(|n| n.leaves.count_ones()).sum();
        assert_eq!(leaves as usize, emitters.len());
        let (triangles, _) = emitters_and_materials(500);
        let mut deepest = 0;
        for e in &emitters {
            let node = &nodes[(e.leaf / 4) as usize];
            assert!(node.leaves & (1 << (e.leaf % 4)) != 0);
            assert_eq!(node.child[(e.leaf % 4) as usize], e.triangle);
            assert_eq!(leaf_of(&emitters, e.triangle), e.leaf);
            let t = &triangles[e.triangle as usize];
            let codes = ancestry(&nodes, e.leaf);
            deepest = deepest.max(codes.len());
            for &code in &codes {
                let (centre, radius, _) = slot(&nodes, code);
                for v in [t.v0, t.v1, t.v2] {
                    let d = Vec3::from(v).distance(centre);
                    assert!(d <= radius, "slot {code}: {d} > {radius}");
                }
            }
        }
        assert!(deepest <= 12, "{deepest} levels for 499 emitters");
        let root: f32 = nodes[0].power.iter().sum();
        assert!((root - power).abs() <= 1e-4 * power);
        for (i, node) in nodes.iter().enumerate() {
            for k in 0..4 {
                if node.power[k] > 0.0 && node.leaves & (1 << k) == 0 {
                    let child = &nodes[node.child[k] as usize];
                    assert_eq!(child.parent, (4 * i + k) as u32);
                    let sum: f32 = child.power.iter().sum();
                    assert!((sum - node.power[k]).abs() <= 1e-5 * node.power[k]);
                }
            }
        }
    }

    /// The probability that a descent from node `index` (reached with probability `p`) ends at a
    /// node whose slots all have zero importance: no emitter there can light x.
    fn dead_end_mass(nodes: &[LightNode], index: usize, p: f64, x: Vec3, n: Vec3) -> f64 {
        let node = &nodes[index];
        let importance = slot_importances(node, x, n).to_array().map(f64::from);
        let sum: f64 = importance.iter().sum();
        if sum == 0.0 {
            return p;
        }
        (0..4)
            .filter(|&k| importance[k] > 0.0 && node.leaves & (1 << k) == 0)
            .map(|k| dead_end_mass(nodes, node.child[k] as usize, p * importance[k] / sum, x, n))
            .sum()
    }

    /// At random points and normals, the tree's pmfs over all emitters and the probability of
    /// ending where nothing can light the point sum to one (no emitter that can light it has a
    /// zero pmf: `importance_is_zero_only_where_nothing_below_can_light`), samples end there as
    /// often as that says, and the pmf a sample reports is the one `tree_pmf` recomputes from its
    /// slot, which MIS relies on.
    #[test]
    fn tree_pmfs_sum_to_one_and_samples_report_their_pmf() {
        let (emitters, nodes, _) = tree(300, None);
        let mut rng = Rng::new(9, 0, 0x51);
        let (mut lit, mut dead_expected, mut dead_seen) = (0, 0.0, 0);
        let draws = 50;
        for _ in 0..400 {
            let x = Vec3::new(rng.next_f32(), rng.next_f32(), rng.next_f32()) * 14.0 - 7.0;
            let n =
                (Vec3::new(rng.next_f32(), rng.next_f32(), rng.next_f32()) * 2.0 - 1.0).normalize();
            let sum: f64 = emitters
                .iter()
                .map(|e| f64::from(tree_pmf(&nodes, e.leaf, x, n)))
                .sum();
            let dead = dead_end_mass(&nodes, 0, 1.0, x, n);
            if dead < 1.0 {
                lit += 1;
                assert!(
                    (sum + dead - 1.0).abs() < 1e-4,
                    "Σ pmf {sum} + dead ends {dead}"
                );
            }
            for _ in 0..draws {
                match sample_tree(&nodes, x, n, rng.next_f32()) {
                    Some((triangle, pmf)) => {
                        let again = tree_pmf(&nodes, leaf_of(&emitters, triangle), x, n);
                        assert!(
                            pmf > 0.0 && (pmf - again).abs() <= 1e-5 * pmf,
                            "{pmf} vs {again}"
                        );
                    }
                    None => dead_seen += 1,
                }
            }
            dead_expected += dead * f64::from(draws);
        }
        assert!(lit > 300, "only {lit} of 400 points lit");
        // Binomial counts: within 4 standard deviations.
        let sd = dead_expected.sqrt().max(1.0);
        assert!(
            (f64::from(dead_seen) - dead_expected).abs() < 4.0 * sd,
            "dead ends: {dead_seen} seen, {dead_expected:.0} expected"
        );
    }

    /// Far away, the importance bounds stop telling emitters apart: a receiver ten thousand
    /// scene sizes above emitters that all face it picks them in proportion to their power
    /// (chi-square over 200,000 samples).
    #[test]
    fn a_distant_receiver_picks_emitters_by_power() {
        let (triangles, materials) = emitters(40, Some(Vec3::Y));
        let (mut emitters, power) = crate::emitters::build_emitters(&triangles, &materials);
        let nodes = build_light_tree(&mut emitters, &triangles, &materials, &[]);
        let x = Vec3::new(0.0, 1e5, 0.0);
        let mut counts = vec![0usize; triangles.len()];
        let samples = 200_000;
        for i in 0..samples {
            let u = Rng::new(i, 1, 2).next_f32();
            counts[sample_tree(&nodes, x, Vec3::NEG_Y, u).unwrap().0 as usize] += 1;
        }
        let mut chi2 = 0.0;
        for e in &emitters {
            let t = &triangles[e.triangle as usize];
            let v = [t.v0, t.v1, t.v2].map(Vec3::from);
            let area = 0.5 * (v[1] - v[0]).cross(v[2] - v[0]).length();
            let lum = luminance(Vec3::from(materials[t.material as usize].emission));
            let expected = f64::from(area * lum / power) * f64::from(samples);
            chi2 += (counts[e.triangle as usize] as f64 - expected).powi(2) / expected;
        }
        // The 0.999 quantile of chi-square with 38 degrees of freedom is 70.70.
        assert!(chi2 < 70.7, "chi-square {chi2:.1}");
    }

    /// The importance is a bound: where an emitter's front faces x from above x's horizon, every
    /// slot on its way to the root has a positive importance at x (so zero means that no emitter
    /// below can light x).
    #[test]
    fn importance_is_zero_only_where_nothing_below_can_light() {
        let (emitters, nodes, _) = tree(200, None);
        let (triangles, _) = emitters_and_materials(200);
        let mut rng = Rng::new(4, 0, 0x99);
        let mut checked = 0;
        while checked < 2000 {
            let x = Vec3::new(rng.next_f32(), rng.next_f32(), rng.next_f32()) * 14.0 - 7.0;
            let n =
                (Vec3::new(rng.next_f32(), rng.next_f32(), rng.next_f32()) * 2.0 - 1.0).normalize();
            let e = &emitters[(rng.next_f32() * emitters.len() as f32) as usize];
            let t = &triangles[e.triangle as usize];
            let v = [t.v0, t.v1, t.v2].map(Vec3::from);
            let (b1, b2) = (rng.next_f32(), rng.next_f32());
            let (b1, b2) = if b1 + b2 > 1.0 {
                (1.0 - b1, 1.0 - b2)
            } else {
                (b1, b2)
            };
            let y = v[0] + (v[1] - v[0]) * b1 + (v[2] - v[0]) * b2;
            let nl = (v[1] - v[0]).cross(v[2] - v[0]).normalize();
            let to_y = (y - x).normalize();
            // Only points the emitter's front faces, with the point above x's horizon.
            if !(to_y.dot(nl) < -1e-3 && to_y.dot(n) > 1e-3) {
                continue;
            }
            checked += 1;
            for code in ancestry(&nodes, e.leaf) {
                let importance = slot_importances(&nodes[(code / 4) as usize], x, n);
                assert!(
                    importance[(code % 4) as usize] > 0.0,
                    "slot {code} on the way to a light that reaches x"
                );
            }
        }
    }

    /// `count` point and spot lights (both falloffs) of random place, axis, cones and intensity,
    /// after a sun, which the tree leaves out.
    fn delta_lights(count: usize) -> Vec<DeltaLight> {
        let mut rng = Rng::new(5, 0, 0xde1);
        let mut u = || rng.next_f32();
        let mut lights = vec![DeltaLight {
            kind: light_kind::DIRECTIONAL,
            direction: [0.0, -1.0, 0.0],
            power: [3.0; 3],
            ..Default::default()
        }];
        for i in 0..count {
            let outer = 0.1 + 1.4 * u();
            // Hard-edged spots too (inner = outer), and inner past outer (the falloffs then end
            // at the outer cone).
            let inner = match i % 7 {
                0 => outer,
                3 => outer * (1.0 + 0.2 * u()),
                _ => outer * u(),
            };
            let strength = 10f32.powf(3.0 * u() - 1.0);
            lights.push(DeltaLight {
                position: (Vec3::new(u(), u(), u()) * 10.0 - 5.0).to_array(),
                kind: [light_kind::POINT, light_kind::SPOT, light_kind::SPOT_GLTF][i % 3],
                direction: (Vec3::new(u(), u(), u()) * 2.0 - 1.0)
                    .normalize()
                    .to_array(),
                cos_inner: inner.cos(),
                power: [strength, strength * u(), strength],
                cos_outer: outer.cos(),
            });
        }
        lights
    }

    /// Every leaf slot of the tree: its code (4 × node + slot) and what it holds.
    fn leaves(nodes: &[LightNode]) -> Vec<(u32, u32)> {
        (0..nodes.len() * 4)
            .filter(|code| nodes[code / 4].leaves & (1 << (code % 4)) != 0)
            .map(|code| (code as u32, nodes[code / 4].child[code % 4]))
            .collect()
    }

    /// Points and spots are leaves of the tree beside the emitters, once each (the sun is not):
    /// at random points, with normals and with none (n = 0, a surface lit from both sides), the
    /// pmfs of all leaves and the dead ends sum to one, a sample reports the pmf its slot
    /// recomputes, and wherever a point or spot light gives irradiance above the horizon every
    /// slot on its way to the root has a positive importance (a spot's cones bound its falloff).
    #[test]
    fn points_and_spots_join_the_tree_with_conservative_bounds() {
        use crate::reference::light::delta_light_incidence;
        let (triangles, materials) = emitters(120, None);
        let (mut emitters, _) = crate::emitters::build_emitters(&triangles, &materials);
        let lights = delta_lights(90);
        let nodes = build_light_tree(&mut emitters, &triangles, &materials, &lights);
        let leaves = leaves(&nodes);
        let delta_code = |index: usize| {
            let found: Vec<u32> = (leaves.iter())
                .filter(|(_, child)| *child == DELTA_LEAF | index as u32)
                .map(|(code, _)| *code)
                .collect();
            found
        };
        assert!(
            delta_code(0).is_empty(),
            "the sun is summed, not in the tree"
        );
        for i in 1..lights.len() {
            assert_eq!(delta_code(i).len(), 1, "light {i}");
        }
        assert_eq!(leaves.len(), emitters.len() + lights.len() - 1);
        let mut rng = Rng::new(12, 0, 0x3d);
        let (mut checked, mut lit) = (0, 0);
        for k in 0..600 {
            let x = Vec3::new(rng.next_f32(), rng.next_f32(), rng.next_f32()) * 14.0 - 7.0;
            let n = if k % 3 == 0 {
                Vec3::ZERO
            } else {
                (Vec3::new(rng.next_f32(), rng.next_f32(), rng.next_f32()) * 2.0 - 1.0).normalize()
            };
            let sum: f64 = (leaves.iter())
                .map(|(code, _)| f64::from(tree_pmf(&nodes, *code, x, n)))
                .sum();
            let dead = dead_end_mass(&nodes, 0, 1.0, x, n);
            if dead < 1.0 {
                lit += 1;
                assert!((sum + dead - 1.0).abs() < 1e-4, "Σ pmf {sum} + dead {dead}");
            }
            if let Some((light, pmf)) = sample_tree(&nodes, x, n, rng.next_f32()) {
                let code = if light & DELTA_LEAF != 0 {
                    delta_code((light & !DELTA_LEAF) as usize)[0]
                } else {
                    leaf_of(&emitters, light)
                };
                let again = tree_pmf(&nodes, code, x, n);
                assert!((pmf - again).abs() <= 1e-5 * pmf, "{pmf} vs {again}");
            }
            for (i, light) in lights.iter().enumerate().skip(1) {
                let (dir, _, irradiance) = delta_light_incidence(light, x);
                if irradiance.max_element() <= 0.0 || !(n == Vec3::ZERO || dir.dot(n) > 1e-3) {
                    continue;
                }
                checked += 1;
                for code in ancestry(&nodes, delta_code(i)[0]) {
                    let importance = slot_importances(&nodes[(code / 4) as usize], x, n);
                    assert!(
                        importance[(code % 4) as usize] > 0.0,
                        "slot {code} on the way to light {i} ({}), which lights x",
                        light.kind
                    );
                }
            }
        }
        assert!(
            lit > 500 && checked > 10_000,
            "{lit} points lit, {checked} lights checked"
        );
    }

    /// The descent picks each light as often as its pmf says, at points among the lights (where
    /// the importances, not the powers, decide): chi-square of 200,000 samples per point against
    /// `tree_pmf` over every leaf (emitters, points and spots; bins expecting under 5 pooled).
    #[test]
    fn samples_follow_the_tree_pmf_near_the_lights() {
        let (triangles, materials) = emitters(60, None);
        let (mut emitters, _) = crate::emitters::build_emitters(&triangles, &materials);
        let lights = delta_lights(30);
        let nodes = build_light_tree(&mut emitters, &triangles, &materials, &lights);
        let leaves = leaves(&nodes);
        let code_of = |light: u32| {
            if light & DELTA_LEAF != 0 {
                leaves.iter().find(|(_, child)| *child == light).unwrap().0
            } else {
                leaf_of(&emitters, light)
            }
        };
        let mut rng = Rng::new(21, 0, 0x2c);
        let mut all_dof = 0;
        for k in 0..4 {
            let x = Vec3::new(rng.next_f32(), rng.next_f32(), rng.next_f32()) * 8.0 - 4.0;
            let n = if k == 0 {
                Vec3::ZERO
            } else {
                (Vec3::new(rng.next_f32(), rng.next_f32(), rng.next_f32()) * 2.0 - 1.0).normalize()
            };
            let samples = 200_000u32;
            let mut counts = std::collections::HashMap::new();
            let mut dead = 0u32;
            for i in 0..samples {
                let u = Rng::new(i, k, 0x77).next_f32();
                match sample_tree(&nodes, x, n, u) {
                    Some((light, _)) => *counts.entry(code_of(light)).or_insert(0u32) += 1,
                    None => dead += 1,
                }
            }
            // Every leaf's count, and the dead ends' as one more outcome.
            let mut seen = vec![f64::from(dead)];
            let mut expected = vec![dead_end_mass(&nodes, 0, 1.0, x, n) * f64::from(samples)];
            for (code, _) in &leaves {
                let e = f64::from(tree_pmf(&nodes, *code, x, n)) * f64::from(samples);
                let c = f64::from(counts.get(code).copied().unwrap_or(0));
                assert!(e > 0.0 || c == 0.0, "slot {code} sampled with pmf 0");
                seen.push(c);
                expected.push(e);
            }
            let (chi2, dof) = crate::math::stats::pearson(&seen, &expected);
            let limit = crate::math::stats::chi2_limit(dof, 4, 1e-3);
            assert!(
                dof >= 4 && chi2 < limit,
                "point {k}: chi-square {chi2:.1} with {dof} degrees of freedom (limit {limit:.1})"
            );
            all_dof += dof;
        }
        assert!(
            all_dof > 60,
            "only {all_dof} degrees of freedom: the points see too few lights"
        );
    }

    fn emitters_and_materials(count: usize) -> (Vec<Triangle>, Vec<Material>) {
        emitters(count, None)
    }
}
