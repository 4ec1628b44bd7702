//! The light tree: a binary tree over the emitter triangles that next-event estimation descends to
//! pick an emitter by its importance at the shading point instead of by its power alone
//! (Conty Estevez & Kulla 2018, "Importance Sampling of Many Lights with Adaptive Tree Splitting";
//! as pbrt-v4's `BVHLightSampler` and Cycles' light tree). This file builds it; the descent and
//! the pmf of a given emitter are the estimator's (`estimator::light_tree` and its WGSL twin).
//!
//! Each node bounds the emitters below it: a box (kept as its bounding sphere, all the importance
//! needs), a cone of normals (axis, θ_o), the angle past a normal they emit into (θ_e = π/2: rt's
//! emitters are one-sided diffuse) and their power Φ = Σ area × luminance(emission), the alias
//! table's weight. Point and spot lights are leaves too (as in pbrt-v4), with Φ = luminance of
//! their intensity, so that Φ/d² is the irradiance scale of either kind: a point emits over the
//! sphere (θ_o = π), a spot along its axis with θ_o its inner cone and θ_e the rest of its outer
//! one. Suns stay out: they are summed at every vertex (`estimator::light::delta_lights_at`), as
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

use crate::gpu_types::{DeltaLight, Emitter, LightNode, Material, Triangle};
use crate::light_kind::LightTag;
use crate::math::sampling::luminance;

/// Set in a leaf slot's `child` for a point or spot light: the rest is its index in the delta
/// lights (`DELTA_LEAF` in `light_tree.wgsl`); without it the slot names an emitter triangle.
pub const DELTA_LEAF: u32 = 1 << 31;

/// Whether the tree holds `light` (points and spots; suns are summed at each vertex).
pub fn in_tree(light: &DeltaLight) -> bool {
    LightTag::from_tag(light.kind).is_some_and(LightTag::in_light_tree)
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
        let (axis, cos_theta_o, cos_theta_e) = if light.kind == LightTag::Point.tag() {
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
mod tests;
