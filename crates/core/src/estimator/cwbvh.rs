//! Traversal of the compressed wide BVH (Ylitie, Karras and Laine, "Efficient Incoherent Ray
//! Traversal on GPUs Through Compressed Wide BVHs", HPG 2017), as `cwbvh.wgsl` does it.
//!
//! A node's hit mask packs the children the ray enters: inner children as bits 24..31, ranked so
//! that the highest bit is the child nearest the ray's origin octant (obvhs orders each node's
//! slots by octant: slot ^ octant code = rank), and leaf triangles as bits 0..23 (offsets from the
//! node's `primitive_base`). Traversal keeps one "group" of inner children still to visit (child
//! base, ranks, and the node's inner-slot mask to turn a rank into a node index) and a stack of
//! such groups. Triangles of entered leaves are tested before descending, so the nearest hit found
//! so far culls the boxes below. That is `traverse`, the kernel's twin, which the CPU runs for
//! any-hit queries; its nearest-hit queries visit children nearest first instead
//! (`traverse_nearest_first`: the same nearest distance, found sooner on large meshes).

/// The WGSL twin of this module, `cwbvh.wgsl` beside it (composed into the kernels by
/// `rt_gpu::shaders`).
pub const WGSL: &str = include_str!("cwbvh.wgsl");

use glam::{BVec3, Vec3};

use super::hit::{miss, test_triangles};
use crate::gpu_scene::GpuScene;
use crate::gpu_types::{Hit, WideBvhNode};
use crate::math::intersect::PreparedRay;
use crate::math::intersect_lanes::permuted_origin;

/// Bits of `WideBvhNode::exponents_imask` and of a group's mask that hold the inner-slot mask.
const IMASK: u32 = 0xff;
/// Bits of a hit mask (and a group's mask) that rank inner children.
const INNER_BITS: u32 = 0xff00_0000;

/// The power-of-two cell size of a node's quantisation grid on each axis.
fn cell_size(node: &WideBvhNode) -> Vec3 {
    let e = |shift: u32| f32::from_bits(((node.exponents_imask >> shift) & 0xff) << 23);
    Vec3::new(e(0), e(8), e(16))
}

/// The hit mask of `node`'s children that the ray enters before `t_max` (see the module doc).
/// `oct_inv4` is the ray's octant code (4 if x ≥ 0, + 2 if y ≥ 0, + 1 if z ≥ 0) in every byte.
/// (The kernel's test with its branch per child turned into a mask: the tests check the two
/// bit for bit. Computing the eight children's slabs lane-wise over arrays measured slower.)
#[inline(always)]
fn child_hits(
    node: &WideBvhNode,
    ray: &PreparedRay,
    oct_inv4: u32,
    neg: BVec3,
    t_max: f32,
    near_out: &mut [f32; 8],
) -> u32 {
    // t = (origin + q · cell − o) / d = q · (cell / d) + (origin − o) / d, per plane byte q.
    let scaled_inv = cell_size(node) * ray.inv_direction;
    let shifted_origin = (Vec3::from(node.origin) - ray.origin) * ray.inv_direction;
    // Which of a box's planes the ray enters by follows its direction's sign, the same for every
    // child: picked once per node, not per child (a branch per child lane that mispredicted).
    let planes = |neg: bool, lo: [u32; 2], hi: [u32; 2]| if neg { [hi, lo] } else { [lo, hi] };
    let [near_x, far_x] = planes(neg.x, node.lo_x, node.hi_x);
    let [near_y, far_y] = planes(neg.y, node.lo_y, node.hi_y);
    let [near_z, far_z] = planes(neg.z, node.lo_z, node.hi_z);
    let mut hits = 0;
    for word in 0..2 {
        let slot_bytes = node.slots[word];
        // Inner slots' bytes are 0b001_11xxx: the only bytes with bits 3 and 4 set. Their rank is
        // the slot's octant-flipped index (biased by 24, so it shifts into the inner bits); a
        // leaf's shift is its triangle offset and its bits the unary triangle count.
        let inner = (slot_bytes & (slot_bytes << 1)) & 0x1010_1010;
        let shift = (slot_bytes ^ (oct_inv4 & ((inner >> 4) * 0xff))) & 0x1f1f_1f1f;
        let bits = (slot_bytes >> 5) & 0x0707_0707;
        for lane in 0..4 {
            let byte = |w: [u32; 2]| ((w[word] >> (lane * 8)) & 0xff) as f32;
            let near = Vec3::new(byte(near_x), byte(near_y), byte(near_z));
            let far = Vec3::new(byte(far_x), byte(far_y), byte(far_z));
            let t_near = near * scaled_inv + shifted_origin;
            let t_far = far * scaled_inv + shifted_origin;
            let near = t_near.max_element().max(0.0);
            near_out[word * 4 + lane] = near;
            // Widened as `intersect_box` does, for the rounding of the t values.
            let far = t_far.min_element() * 1.000_000_4;
            // A mask, not a branch: whether the ray enters a child is as good as random.
            let enters = u32::from((near <= far) & (near < t_max));
            hits |= (((bits >> (lane * 8)) & 0xff) << ((shift >> (lane * 8)) & 0xff)) * enters;
        }
    }
    hits
}

/// Nearest hit through the wide BVH in `scene.wide_nodes` whose root is node `root`, or with
/// `any_hit` the first found. Compiled twice, for the baseline x86-64 and for CPUs with AVX2, FMA, BMI and LZCNT (`multiversion` picks one at run
/// time), the latter testing a node's eight children in one register (`avx2::child_hits`): the
/// same operations either way, so the same hits bit for bit (the tests compare both over 10⁶
/// rays); docs/performance-log.md has what each step gained.
#[multiversion::multiversion(targets("x86_64+avx2+fma+bmi1+bmi2+lzcnt+popcnt"))]
#[allow(unsafe_code)] // calling the AVX2 node test; see SAFETY below
pub(super) fn trace_wide(
    scene: &GpuScene,
    root: u32,
    origin: Vec3,
    direction: Vec3,
    t_max: f32,
    any_hit: bool,
) -> Hit {
    let (o, d) = (origin, direction);
    multiversion::target::match_target! {
        // SAFETY: this version of the function runs only on CPUs with AVX2.
        "x86_64+avx2" => {
            let test = |node: &WideBvhNode, ray: &PreparedRay, oct, neg, t, near: &mut [f32; 8]| {
                unsafe { avx2::child_hits(node, ray, oct, neg, t, near) }
            };
            if any_hit {
                traverse(scene, root, o, d, t_max, true, test)
            } else {
                traverse_nearest_first(scene, root, o, d, t_max, test)
            }
        }
        _ => if any_hit {
            traverse(scene, root, o, d, t_max, true, portable_child_hits)
        } else {
            traverse_nearest_first(scene, root, o, d, t_max, portable_child_hits)
        },
    }
}

/// `child_hits` with the octant code in one byte, as `traverse` passes it.
#[inline(always)]
fn portable_child_hits(
    node: &WideBvhNode,
    ray: &PreparedRay,
    oct_inv: u32,
    neg: BVec3,
    t_max: f32,
    near: &mut [f32; 8],
) -> u32 {
    child_hits(node, ray, oct_inv * 0x0101_0101, neg, t_max, near)
}

/// `trace_wide` as the baseline x86-64 runs it, for the tests.
#[cfg(test)]
fn trace_wide_baseline(
    scene: &GpuScene,
    root: u32,
    origin: Vec3,
    direction: Vec3,
    t_max: f32,
    any_hit: bool,
) -> Hit {
    if any_hit {
        traverse(
            scene,
            root,
            origin,
            direction,
            t_max,
            true,
            portable_child_hits,
        )
    } else {
        traverse_nearest_first(scene, root, origin, direction, t_max, portable_child_hits)
    }
}

/// What both traversals derive from a ray once: the prepared ray, its origin permuted for the
/// triangle test, its octant code (4 if x ≥ 0, + 2 if y ≥ 0, + 1 if z ≥ 0) and its negative axes.
#[inline(always)]
fn set_up(origin: Vec3, direction: Vec3) -> (PreparedRay, [f32; 3], u32, BVec3) {
    let ray = PreparedRay::new(origin, direction);
    let permuted = permuted_origin(&ray);
    let oct_inv = (u32::from(direction.x >= 0.0) << 2)
        | (u32::from(direction.y >= 0.0) << 1)
        | u32::from(direction.z >= 0.0);
    (ray, permuted, oct_inv, direction.cmplt(Vec3::ZERO))
}

/// Pending children the nearest-first traversal can hold: seven per level of the deepest tree.
const NEAREST_FIRST_STACK: usize = 7 * crate::bvh::MAX_WIDE_BVH_DEPTH;

/// The CPU's nearest-hit traversal: a node's entered inner children are visited nearest first by
/// their entry distance, the others kept with it and skipped when popped beyond the nearest hit
/// found since (as Embree does). The kernel's traversal (`traverse`, `cwbvh.wgsl`) follows the
/// ray's octant order and keeps no distances, which costs a GPU no registers; both find the same
/// nearest distance bit for bit (the same triangle tests; a box is skipped only beyond a hit
/// already found), and where two triangles are hit at exactly that distance either may be
/// reported. Any-hit queries keep the octant order (sorting only costs them).
#[inline(always)]
#[allow(unsafe_code)] // reading stack entries below `sp`, all written
fn traverse_nearest_first(
    scene: &GpuScene,
    root: u32,
    origin: Vec3,
    direction: Vec3,
    t_max: f32,
    child_hits: impl Fn(&WideBvhNode, &PreparedRay, u32, BVec3, f32, &mut [f32; 8]) -> u32,
) -> Hit {
    let (ray, permuted, oct_inv, neg) = set_up(origin, direction);
    let mut hit = miss(t_max);
    // Left uninitialised: zeroing 1.8 kB a ray measured slower than the traversal it served.
    let mut stack = [std::mem::MaybeUninit::<(u32, f32)>::uninit(); NEAREST_FIRST_STACK];
    let mut sp = 0;
    let mut near = [0.0f32; 8];
    let mut node_index = root;
    loop {
        let node = &scene.wide_nodes[node_index as usize];
        let hits = child_hits(node, &ray, oct_inv, neg, hit.t, &mut near);
        let triangles = hits & !INNER_BITS;
        if triangles != 0 {
            test_triangles(
                scene,
                &ray,
                permuted,
                (node.primitive_base, triangles),
                &mut hit,
                false,
            );
        }
        // The entered inner children nearer than the nearest hit, farthest first.
        let imask = node.exponents_imask >> 24;
        let mut inner = hits & INNER_BITS;
        let mut children = [(0u32, 0.0f32); 8];
        let mut count = 0;
        while inner != 0 {
            let rank_bit = 31 - inner.leading_zeros();
            inner &= !(1 << rank_bit);
            let slot = (rank_bit - 24) ^ oct_inv;
            let t = near[slot as usize];
            if t < hit.t {
                let child = node.child_base + (imask & ((1 << slot) - 1)).count_ones();
                let mut i = count;
                while i > 0 && children[i - 1].1 < t {
                    children[i] = children[i - 1];
                    i -= 1;
                }
                children[i] = (child, t);
                count += 1;
            }
        }
        if count > 0 {
            for &child in &children[..count - 1] {
                stack[sp].write(child);
                sp += 1;
            }
            node_index = children[count - 1].0;
            continue;
        }
        loop {
            if sp == 0 {
                return hit;
            }
            sp -= 1;
            // SAFETY: every entry below `sp` was written by the pushes above.
            let (child, t) = unsafe { stack[sp].assume_init() };
            if t < hit.t {
                node_index = child;
                break;
            }
        }
    }
}

/// The kernel's traversal (`cwbvh.wgsl`), inlined into each of `trace_wide`'s versions with the
/// node and leaf tests (so that they too are compiled for its instructions): the CPU's any-hit
/// queries, and the reference the nearest-first traversal is tested against. `child_hits` is a
/// node's test (`child_hits`' arguments, the octant code in one byte).
#[inline(always)]
fn traverse(
    scene: &GpuScene,
    root: u32,
    origin: Vec3,
    direction: Vec3,
    t_max: f32,
    any_hit: bool,
    child_hits: impl Fn(&WideBvhNode, &PreparedRay, u32, BVec3, f32, &mut [f32; 8]) -> u32,
) -> Hit {
    let (ray, permuted, oct_inv, neg) = set_up(origin, direction);
    let mut hit = miss(t_max);
    // A fixed stack, as the kernel's (the builder keeps the BVH within it; a push past it is
    // dropped in both twins): no allocation per ray.
    let mut stack = [(0u32, 0u32); crate::bvh::MAX_WIDE_BVH_DEPTH];
    let mut sp = 0;
    // The root is the one inner child (rank 7, no inner slots before it) of a virtual node whose
    // children begin at `root`.
    let mut group = (root, 0x8000_0000u32);
    let mut triangles = (0u32, 0u32);
    loop {
        if triangles.1 != 0 && test_triangles(scene, &ray, permuted, triangles, &mut hit, any_hit) {
            return hit;
        }
        if group.1 & INNER_BITS == 0 {
            if sp == 0 {
                break;
            }
            sp -= 1;
            group = stack[sp];
        }
        let rank_bit = 31 - group.1.leading_zeros();
        group.1 &= !(1 << rank_bit);
        let slot = (rank_bit - 24) ^ oct_inv;
        let child = group.0 + (group.1 & IMASK & ((1 << slot) - 1)).count_ones();
        if group.1 & INNER_BITS != 0 && sp < stack.len() {
            stack[sp] = group;
            sp += 1;
        }
        let node = &scene.wide_nodes[child as usize];
        let hits = child_hits(node, &ray, oct_inv, neg, hit.t, &mut [0.0; 8]);
        group = (
            node.child_base,
            (hits & INNER_BITS) | (node.exponents_imask >> 24),
        );
        triangles = (node.primitive_base, hits & !INNER_BITS);
    }
    hit
}

#[cfg(target_arch = "x86_64")]
mod avx2;
#[cfg(test)]
mod tests;
