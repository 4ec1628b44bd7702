//! Ray–triangle and ray–box tests and the self-intersection offset, mirrored in
//! `intersect.wgsl` beside it.

/// The WGSL twin of this module, `intersect.wgsl` beside it (composed into the kernels by
/// `rt_gpu::shaders`).
pub const WGSL: &str = include_str!("intersect.wgsl");

use glam::Vec3;

/// A ray prepared for the watertight triangle test of Woop, Benthin and Wald (JCGT 2013): the axis
/// of largest |d| becomes z, and the shear maps the ray onto +z.
#[derive(Clone, Copy, Debug)]
pub struct PreparedRay {
    pub origin: Vec3,
    pub direction: Vec3,
    pub inv_direction: Vec3,
    pub k: [usize; 3],
    pub shear: Vec3,
}

impl PreparedRay {
    pub fn new(origin: Vec3, direction: Vec3) -> Self {
        let a = direction.abs();
        let kz = if a.x > a.y {
            if a.x > a.z { 0 } else { 2 }
        } else if a.y > a.z {
            1
        } else {
            2
        };
        let mut kx = (kz + 1) % 3;
        let mut ky = (kx + 1) % 3;
        if direction[kz] < 0.0 {
            std::mem::swap(&mut kx, &mut ky);
        }
        let dz = direction[kz];
        // As in the kernel: a zero component would make 0 · ∞ = NaN in the slab test for a ray in
        // a box's face plane.
        let safe = Vec3::select(direction.cmpeq(Vec3::ZERO), Vec3::splat(1e-30), direction);
        PreparedRay {
            origin,
            direction,
            inv_direction: safe.recip(),
            k: [kx, ky, kz],
            shear: Vec3::new(direction[kx] / dz, direction[ky] / dz, 1.0 / dz),
        }
    }
}

/// Distance and barycentrics (of v1, v2) of a hit strictly inside (0, t_max), watertight: rays through
/// shared edges and vertices hit at least one of the triangles.
pub fn intersect_triangle(
    ray: &PreparedRay,
    v0: Vec3,
    v1: Vec3,
    v2: Vec3,
    t_max: f32,
) -> Option<(f32, f32, f32)> {
    // The vertices relative to the origin, their axes permuted to (kx, ky, kz): indexing an array
    // (masked into range) rather than a `Vec3`, whose index is a match the CPU mispredicts.
    let [kx, ky, kz] = ray.k.map(|k| k & 3);
    let permuted = |p: Vec3| {
        let d = (p - ray.origin).extend(0.0).to_array();
        (d[kx], d[ky], d[kz])
    };
    let (a, b, c) = (permuted(v0), permuted(v1), permuted(v2));
    let s = ray.shear;
    let ax = a.0 - s.x * a.2;
    let ay = a.1 - s.y * a.2;
    let bx = b.0 - s.x * b.2;
    let by = b.1 - s.y * b.2;
    let cx = c.0 - s.x * c.2;
    let cy = c.1 - s.y * c.2;
    let u = cx * by - cy * bx;
    let v = ax * cy - ay * cx;
    let w = bx * ay - by * ax;
    // Non-short-circuit `|` and `&`: the same test with fewer branches to mispredict.
    if ((u < 0.0) | (v < 0.0) | (w < 0.0)) & ((u > 0.0) | (v > 0.0) | (w > 0.0)) {
        return None;
    }
    let det = u + v + w;
    if det == 0.0 {
        return None;
    }
    let t_scaled = u * (s.z * a.2) + v * (s.z * b.2) + w * (s.z * c.2);
    let t = t_scaled / det;
    if !(t > 0.0 && t < t_max) {
        return None;
    }
    Some((t, v / det, w / det))
}

/// Slab test; the far distance is widened by 1 + 2γ₃ (pbrt's bound) so rounding never loses a hit.
pub fn intersect_box(ray: &PreparedRay, min: Vec3, max: Vec3, t_max: f32) -> Option<f32> {
    let t0 = (min - ray.origin) * ray.inv_direction;
    let t1 = (max - ray.origin) * ray.inv_direction;
    let near = t0.min(t1).max_element().max(0.0);
    let far = t0.max(t1).min_element() * 1.000_000_4;
    (near <= far && near < t_max).then_some(near)
}

/// Moves a surface point off its surface along `n` by a few ULPs of its own magnitude (Wächter and
/// Binder, Ray Tracing Gems ch. 6), so the offset scales with the coordinates, not a fixed epsilon.
/// Near the origin, where ULPs vanish, it moves by a fixed distance relative to `scale` (the scene's
/// extent, at most 1: `Frame::offset_scale`), so tiny scenes are not offset by a visible amount.
pub fn offset_ray_origin(p: Vec3, n: Vec3, scale: f32) -> Vec3 {
    let origin = scale / 32.0;
    let float_scale = scale / 65536.0;
    const INT_SCALE: f32 = 256.0;
    let mut out = p;
    for i in 0..3 {
        if p[i].abs() < origin {
            out[i] = p[i] + float_scale * n[i];
        } else {
            let of = (INT_SCALE * n[i]) as i32;
            let of = if p[i] < 0.0 { -of } else { of };
            out[i] = f32::from_bits((p[i].to_bits() as i32).wrapping_add(of) as u32);
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn shared_edge_is_hit_by_one_of_two_triangles() {
        let (a, b, c, d) = (
            Vec3::new(0., 0., 0.),
            Vec3::new(1., 0., 0.),
            Vec3::new(1., 1., 0.),
            Vec3::new(0., 1., 0.),
        );
        for i in 0..1000 {
            let x = i as f32 / 1000.0;
            let ray = PreparedRay::new(Vec3::new(x, x, 1.0), Vec3::new(0.0, 0.0, -1.0));
            let h1 = intersect_triangle(&ray, a, b, c, f32::MAX);
            let h2 = intersect_triangle(&ray, a, c, d, f32::MAX);
            assert!(
                h1.is_some() || h2.is_some(),
                "ray along the diagonal at {x} fell through"
            );
        }
    }

    #[test]
    fn offset_moves_off_the_surface_at_every_scale() {
        // Points away from and near the origin (where the fixed-distance branch applies), in scenes
        // from a millionth of a unit to a million units wide.
        for scale in [1e-6f32, 1e-4, 1.0, 1e4, 1e6] {
            for p in [Vec3::new(0.3, 0.7, 0.5), Vec3::new(0.3, 0.7, 0.0)] {
                let p = p * scale;
                let q = offset_ray_origin(p, Vec3::Z, scale.min(1.0));
                assert!(
                    q.z > p.z && (q.z - p.z) / scale < 1e-3,
                    "scale {scale}: {p} -> {q}"
                );
            }
        }
    }
}
