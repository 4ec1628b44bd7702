//! The watertight ray–triangle test (`intersect::intersect_triangle`) on four triangles at once,
//! for the CPU backend's leaves: the same operations in the same order lane by lane, so each
//! lane's distance and barycentrics equal the scalar test's bit for bit (tested over 10⁶ random
//! cases), computed without a branch per triangle. The scalar test stays the reference, the
//! kernels' twin and the BVH2 path's test.
//!
//! Why: a leaf's triangle tests mostly fail, each on a branch the CPU cannot predict; four tests
//! as one straight run of arithmetic (which the compiler puts in SIMD registers) trade those
//! mispredictions for a few wasted lanes. Whether a lane's hit is kept is left to the caller,
//! triangle by triangle in the scalar order (the nearest so far shrinks `t_max` as it goes).

use glam::Vec3;

use super::intersect::PreparedRay;

/// How many triangles one call tests.
pub const LANES: usize = 4;

/// Each lane's candidate hit: whether the ray crosses the triangle in front of its origin (the
/// scalar test's sign, determinant and `t > 0` checks), and its distance and barycentrics (of v1,
/// v2), as `intersect_triangle` computes them. The scalar test's `t < t_max` is the caller's.
#[derive(Clone, Copy, Debug, Default)]
pub struct LaneHits {
    pub crosses: [bool; LANES],
    pub t: [f32; LANES],
    pub b1: [f32; LANES],
    pub b2: [f32; LANES],
}

/// The ray's origin with its axes permuted as the test wants them (kx, ky, kz), once per ray.
pub fn permuted_origin(ray: &PreparedRay) -> [f32; 3] {
    let o = ray.origin.to_array();
    ray.k.map(|k| o[k.min(2)])
}

/// Tests the triangles `vertices[lane] = [v0, v1, v2]`; lanes past the caller's count may hold
/// any finite copies (their results are ignored).
#[inline(always)]
pub fn intersect_triangles(
    ray: &PreparedRay,
    origin: [f32; 3],
    vertices: &[[Vec3; 3]; LANES],
) -> LaneHits {
    let [kx, ky, kz] = ray.k.map(|k| k.min(2));
    // Vertex coordinates relative to the origin, permuted, lane by lane: the subtraction per
    // component is the scalar test's `(p - origin)[k]`.
    let relative = |vertex: usize, k: usize, axis: usize| -> [f32; LANES] {
        std::array::from_fn(|lane| vertices[lane][vertex][k] - origin[axis])
    };
    let (a0, a1, a2) = (relative(0, kx, 0), relative(0, ky, 1), relative(0, kz, 2));
    let (b0, b1, b2) = (relative(1, kx, 0), relative(1, ky, 1), relative(1, kz, 2));
    let (c0, c1, c2) = (relative(2, kx, 0), relative(2, ky, 1), relative(2, kz, 2));
    let s = ray.shear;
    let mut hits = LaneHits::default();
    for lane in 0..LANES {
        let ax = a0[lane] - s.x * a2[lane];
        let ay = a1[lane] - s.y * a2[lane];
        let bx = b0[lane] - s.x * b2[lane];
        let by = b1[lane] - s.y * b2[lane];
        let cx = c0[lane] - s.x * c2[lane];
        let cy = c1[lane] - s.y * c2[lane];
        let u = cx * by - cy * bx;
        let v = ax * cy - ay * cx;
        let w = bx * ay - by * ax;
        let mixed = ((u < 0.0) | (v < 0.0) | (w < 0.0)) & ((u > 0.0) | (v > 0.0) | (w > 0.0));
        let det = u + v + w;
        let t_scaled = u * (s.z * a2[lane]) + v * (s.z * b2[lane]) + w * (s.z * c2[lane]);
        let t = t_scaled / det;
        hits.crosses[lane] = !mixed & (det != 0.0) & (t > 0.0);
        hits.t[lane] = t;
        hits.b1[lane] = v / det;
        hits.b2[lane] = w / det;
    }
    hits
}

#[cfg(test)]
mod tests;
