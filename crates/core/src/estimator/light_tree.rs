//! Sampling the light tree (`crate::light_tree` builds it), as `light_tree.wgsl` beside it (its
//! twin) does: from a shading point x with normal n, descend from the root, at each four-wide
//! node taking a slot with probability proportional to its importance
//!   I(x, n) = Φ · cos θ′ / d² · cos θ′_i,
//! where d is the distance from x to the centre of the slot's box, θ′ = max(0, θ_w − θ_o − θ_b)
//! the smallest angle between the emitters' normal cone and the direction to x (θ_w: to the
//! centre, θ_b: half the angle the box's bounding sphere subtends from x; zero when θ′ ≥ θ_e: no
//! emitter below faces x), and θ′_i = max(0, θ_i − θ_b) the smallest angle between n and a
//! direction into the sphere (zero at or past π/2: next-event estimation takes only lights above
//! the surface; cos θ′_i = 1 for n = 0, at a surface that point and spot lights reach through
//! from either side, `Surface::lit_through`); I = Φ / r² for x inside the sphere (radius r). Every bound is conservative, so an
//! emitter that can light x keeps a non-zero probability. The four slots' importances are
//! computed lane by lane. The emitter's pmf is the product of the choices; `tree_pmf` recomputes
//! it from the emitter's slot upwards for a BSDF-sampled ray that hits it (exact MIS).

/// The WGSL twin of this module, `light_tree.wgsl` beside it.
pub const WGSL: &str = include_str!("light_tree.wgsl");

use glam::{Vec3, Vec4};

use crate::gpu_types::LightNode;
use crate::light_tree::MAX_DEPTH;

/// The largest f32 below 1 (a remapped random number stays in [0, 1)).
const ONE_MINUS_EPSILON: f32 = 1.0 - f32::EPSILON / 2.0;

/// cos(max(0, a − b)) from the sines and cosines of a and b (angles in [0, π]), lane by lane.
fn cos_sub_clamped(sin_a: Vec4, cos_a: Vec4, sin_b: Vec4, cos_b: Vec4) -> Vec4 {
    Vec4::select(cos_a.cmpgt(cos_b), Vec4::ONE, cos_a * cos_b + sin_a * sin_b)
}

/// sin(max(0, a − b)), as `cos_sub_clamped`.
fn sin_sub_clamped(sin_a: Vec4, cos_a: Vec4, sin_b: Vec4, cos_b: Vec4) -> Vec4 {
    Vec4::select(
        cos_a.cmpgt(cos_b),
        Vec4::ZERO,
        sin_a * cos_b - cos_a * sin_b,
    )
}

/// √max(0, 1 − c²): the sine of an angle in [0, π] from its cosine.
fn sine(cos: Vec4) -> Vec4 {
    (Vec4::ONE - cos * cos).max(Vec4::ZERO).sqrt()
}

/// The importance I(x, n) of each of the node's four slots at `x` with normal `n` (the module's
/// equation; 0 for an empty slot).
pub fn slot_importances(node: &LightNode, x: Vec3, n: Vec3) -> Vec4 {
    let tx = Vec4::splat(x.x) - Vec4::from(node.centre_x);
    let ty = Vec4::splat(x.y) - Vec4::from(node.centre_y);
    let tz = Vec4::splat(x.z) - Vec4::from(node.centre_z);
    let d2 = tx * tx + ty * ty + tz * tz;
    let power = Vec4::from(node.power);
    let radius = Vec4::from(node.radius);
    let r2 = radius * radius;
    // x inside a bounding sphere: no angle bounds anything there.
    let inside = power / r2.max(Vec4::splat(f32::MIN_POSITIVE));
    let inv_d = d2.sqrt().recip();
    let (wx, wy, wz) = (tx * inv_d, ty * inv_d, tz * inv_d);
    let sin_b = (radius * inv_d).min(Vec4::ONE);
    let cos_b = sine(sin_b);
    // The receiver: the smallest angle between n and a direction into the sphere (none for
    // n = 0: lit from both sides).
    let cos_i = -(wx * n.x + wy * n.y + wz * n.z);
    let cos_pi = if n == Vec3::ZERO {
        Vec4::ONE
    } else {
        cos_sub_clamped(sine(cos_i), cos_i, sin_b, cos_b)
    };
    // The emitters: the smallest angle between their normals and the direction to x.
    let cos_w =
        wx * Vec4::from(node.axis_x) + wy * Vec4::from(node.axis_y) + wz * Vec4::from(node.axis_z);
    let sin_w = sine(cos_w);
    let (cos_o, sin_o) = (Vec4::from(node.cos_theta_o), Vec4::from(node.sin_theta_o));
    let cos_x = cos_sub_clamped(sin_w, cos_w, sin_o, cos_o);
    let sin_x = sin_sub_clamped(sin_w, cos_w, sin_o, cos_o);
    let cos_p = cos_sub_clamped(sin_x, cos_x, sin_b, cos_b);
    let lit = cos_p.cmpgt(Vec4::from(node.cos_theta_e)) & cos_pi.cmpgt(Vec4::ZERO);
    let outside = Vec4::select(lit, power * cos_p * cos_pi / d2, Vec4::ZERO);
    let value = Vec4::select(d2.cmple(r2), inside, outside);
    Vec4::select(power.cmpgt(Vec4::ZERO), value, Vec4::ZERO)
}

/// Whether a sum of importances, or a pmf, can weigh a choice: positive and finite (an overflow
/// or an underflow picks nothing rather than a sample of pdf NaN or 0).
fn usable(x: f32) -> bool {
    x > 0.0 && x <= f32::MAX
}

/// The sum of the four importances, in a fixed order (both twins add them alike).
fn total(importance: [f32; 4]) -> f32 {
    (importance[0] + importance[1]) + (importance[2] + importance[3])
}

/// The slot whose share of `total` holds `target` (in [0, total)), and the importances before it.
fn pick_slot(importance: [f32; 4], target: f32) -> (usize, f32) {
    let mut below = 0.0;
    let mut last = 0;
    for (slot, &i) in importance.iter().enumerate() {
        if i > 0.0 {
            if target < below + i {
                return (slot, below);
            }
            below += i;
            last = slot;
        }
    }
    // Rounding left `target` past the sum: the last slot that can be picked.
    (last, below - importance[last])
}

/// A light and its pmf for the uniform number `u`, descending from the root: an emitter triangle,
/// or `DELTA_LEAF` and a point or spot light's index; `None` where no light can light x.
pub fn sample_tree(nodes: &[LightNode], x: Vec3, n: Vec3, u: f32) -> Option<(u32, f32)> {
    let mut u = u;
    let mut index = 0usize;
    let mut pmf = 1.0f32;
    for _ in 0..MAX_DEPTH {
        let node = &nodes[index];
        let importance = slot_importances(node, x, n).to_array();
        let sum = total(importance);
        if !usable(sum) {
            return None;
        }
        let target = u * sum;
        let (slot, below) = pick_slot(importance, target);
        u = ((target - below) / importance[slot]).clamp(0.0, ONE_MINUS_EPSILON);
        pmf *= importance[slot] / sum;
        if node.leaves & (1 << slot) != 0 {
            return usable(pmf).then_some((node.child[slot], pmf));
        }
        index = node.child[slot] as usize;
    }
    None
}

/// The pmf with which `sample_tree` at (x, n) picks the emitter in slot `code` (4 × node + slot,
/// `Emitter::leaf`), from its node up to the root.
pub fn tree_pmf(nodes: &[LightNode], code: u32, x: Vec3, n: Vec3) -> f32 {
    let mut pmf = 1.0f32;
    let mut code = code;
    for _ in 0..MAX_DEPTH {
        let node = &nodes[(code / 4) as usize];
        let importance = slot_importances(node, x, n).to_array();
        let sum = total(importance);
        if !usable(sum) {
            return 0.0;
        }
        pmf *= importance[(code % 4) as usize] / sum;
        if code / 4 == 0 {
            return pmf;
        }
        code = node.parent;
    }
    0.0
}

/// Where emitter triangle `triangle` sits in the light tree (4 × node + slot): a binary search of
/// the emitters (in triangle order) for its entry.
pub fn leaf_of(emitters: &[crate::gpu_types::Emitter], triangle: u32) -> u32 {
    let (mut lo, mut hi) = (0usize, emitters.len());
    while hi - lo > 1 {
        let mid = (lo + hi) / 2;
        if emitters[mid].triangle <= triangle {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    emitters[lo].leaf
}

/// The packed tree normal of a vertex lit from both sides: `unpack_normal` gives n = 0. No
/// normal packs to it (`pack_normal`'s snorms stop at −32767).
pub const NO_NORMAL: u32 = 0x8000_8000;

/// The tree normal of a vertex with geometric normal `ng`, packed: `NO_NORMAL` where point and
/// spot lights reach the surface through it from its other side (`Surface::lit_through`), so
/// that the tree keeps those beyond it.
pub fn tree_normal_at(ng: Vec3, lit_through: bool) -> u32 {
    if lit_through {
        NO_NORMAL
    } else {
        pack_normal(ng)
    }
}

/// The normal the tree weighs lights with at a vertex, packed into 32 bits (octahedral, 16-bit
/// snorm) so the path carries it to the next hit: next-event estimation
/// and the MIS weight of an emitter that the BSDF sample hits both use its unpacked value, so the
/// two pmfs are the same.
pub fn pack_normal(n: Vec3) -> u32 {
    let l1 = n.x.abs() + n.y.abs() + n.z.abs();
    let (mut u, mut v) = (n.x / l1, n.y / l1);
    if n.z < 0.0 {
        (u, v) = (
            (1.0 - v.abs()) * sign_not_zero(u),
            (1.0 - u.abs()) * sign_not_zero(v),
        );
    }
    let snorm = |e: f32| ((0.5 + 32767.0 * e.clamp(-1.0, 1.0)).floor() as i32 as i16 as u16) as u32;
    snorm(u) | snorm(v) << 16
}

/// `pack_normal`'s unit normal (0 for `NO_NORMAL`).
pub fn unpack_normal(packed: u32) -> Vec3 {
    if packed == NO_NORMAL {
        return Vec3::ZERO;
    }
    let snorm = |bits: u32| (f32::from(bits as u16 as i16) / 32767.0).max(-1.0);
    let (u, v) = (snorm(packed & 0xffff), snorm(packed >> 16));
    let z = 1.0 - u.abs() - v.abs();
    let (x, y) = if z < 0.0 {
        (
            (1.0 - v.abs()) * sign_not_zero(u),
            (1.0 - u.abs()) * sign_not_zero(v),
        )
    } else {
        (u, v)
    };
    Vec3::new(x, y, z).normalize()
}

fn sign_not_zero(x: f32) -> f32 {
    if x >= 0.0 { 1.0 } else { -1.0 }
}
