//! `child_hits` for CPUs with AVX2: the eight children's slab tests as eight lanes of one register
//! each, and their slot bytes turned into hit-mask bits lane-wise, where the portable version runs
//! child by child. The same operations in the same order per child, so the same mask bit for bit
//! (tested over 10⁶ random nodes and rays, NaN-making ones included).
//!
//! Why it pays where the compiler's own vectorisation of the portable loop did not
//! (docs/performance-log.md): the portable test widens each plane byte separately and ORs each
//! child's bits into the mask one at a time; here a node's 48 plane bytes widen in six
//! instructions and its mask comes out of one variable shift and a horizontal OR.

use std::arch::x86_64::*;

use glam::{BVec3, Vec3};

use super::cell_size;
use crate::gpu_types::WideBvhNode;
use crate::math::intersect::PreparedRay;

/// The eight plane bytes of one axis' side (`[u32; 2]`, child order) as eight floats.
#[inline]
#[target_feature(enable = "avx2")]
fn plane_bytes(words: &[u32; 2]) -> __m256 {
    let packed = (u64::from(words[1]) << 32) | u64::from(words[0]);
    _mm256_cvtepi32_ps(_mm256_cvtepu8_epi32(_mm_cvtsi64_si128(packed as i64)))
}

/// `child_hits` (see there) for the eight children at once.
///
/// The portable test's operations, lane by lane: `t = q · scaled_inv + shifted_origin` (a multiply
/// then an add, never fused, as Rust computes `Vec3` arithmetic); glam's `max_element` is
/// `max(x, max(y, z))` with `max(a, b) = if a > b { a } else { b }`, which is exactly
/// `_mm256_max_ps(a, b)` (NaN in either gives `b`), and `min_element` likewise `_mm256_min_ps`;
/// `near.max(0.0)` ignores a NaN `near` as `_mm256_max_ps(near, 0)` does; the comparisons are
/// ordered (false on NaN) as Rust's `<=` and `<` are.
#[inline]
#[target_feature(enable = "avx2")]
pub(super) fn child_hits(
    node: &WideBvhNode,
    ray: &PreparedRay,
    oct_inv: u32,
    neg: BVec3,
    t_max: f32,
    near_out: &mut [f32; 8],
) -> u32 {
    let scaled_inv = cell_size(node) * ray.inv_direction;
    let shifted_origin = (Vec3::from(node.origin) - ray.origin) * ray.inv_direction;
    let planes = |neg: bool, lo: &[u32; 2], hi: &[u32; 2]| {
        let (near, far) = if neg { (hi, lo) } else { (lo, hi) };
        (plane_bytes(near), plane_bytes(far))
    };
    let (near_x, far_x) = planes(neg.x, &node.lo_x, &node.hi_x);
    let (near_y, far_y) = planes(neg.y, &node.lo_y, &node.hi_y);
    let (near_z, far_z) = planes(neg.z, &node.lo_z, &node.hi_z);
    let t = |q: __m256, scale: f32, shift: f32| {
        _mm256_add_ps(
            _mm256_mul_ps(q, _mm256_set1_ps(scale)),
            _mm256_set1_ps(shift),
        )
    };
    let (s, o) = (scaled_inv, shifted_origin);
    let near = _mm256_max_ps(
        t(near_x, s.x, o.x),
        _mm256_max_ps(t(near_y, s.y, o.y), t(near_z, s.z, o.z)),
    );
    let near = _mm256_max_ps(near, _mm256_setzero_ps());
    *near_out = bytemuck::cast(near);
    let far = _mm256_min_ps(
        t(far_x, s.x, o.x),
        _mm256_min_ps(t(far_y, s.y, o.y), t(far_z, s.z, o.z)),
    );
    let far = _mm256_mul_ps(far, _mm256_set1_ps(1.000_000_4));
    let enters = _mm256_castps_si256(_mm256_and_ps(
        _mm256_cmp_ps::<_CMP_LE_OQ>(near, far),
        _mm256_cmp_ps::<_CMP_LT_OQ>(near, _mm256_set1_ps(t_max)),
    ));

    // Each child's bits and shift from its slot byte, as the portable test's word-wise masks.
    let packed = (u64::from(node.slots[1]) << 32) | u64::from(node.slots[0]);
    let slot = _mm256_cvtepu8_epi32(_mm_cvtsi64_si128(packed as i64));
    let sixteen = _mm256_set1_epi32(0x10);
    let inner = _mm256_cmpeq_epi32(
        _mm256_and_si256(
            _mm256_and_si256(slot, _mm256_slli_epi32::<1>(slot)),
            sixteen,
        ),
        sixteen,
    );
    let octant = _mm256_and_si256(_mm256_set1_epi32(oct_inv as i32), inner);
    let shift = _mm256_and_si256(_mm256_xor_si256(slot, octant), _mm256_set1_epi32(0x1f));
    let bits = _mm256_and_si256(_mm256_srli_epi32::<5>(slot), _mm256_set1_epi32(7));
    let lanes = _mm256_and_si256(_mm256_sllv_epi32(bits, shift), enters);
    let half = _mm_or_si128(
        _mm256_castsi256_si128(lanes),
        _mm256_extracti128_si256::<1>(lanes),
    );
    let quarter = _mm_or_si128(half, _mm_shuffle_epi32::<0b01_00_11_10>(half));
    let one = _mm_or_si128(quarter, _mm_shuffle_epi32::<0b10_11_00_01>(quarter));
    _mm_cvtsi128_si32(one) as u32
}
