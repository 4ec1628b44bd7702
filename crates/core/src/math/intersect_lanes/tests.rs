use super::*;
use crate::math::intersect::intersect_triangle;

/// A small generator of awkward floats: ordinary, huge, tiny, zero and shared values.
struct Cases(u64);

impl Cases {
    fn next_u32(&mut self) -> u32 {
        self.0 = self
            .0
            .wrapping_mul(6_364_136_223_846_793_005)
            .wrapping_add(1_442_695_040_888_963_407);
        (self.0 >> 32) as u32
    }

    fn unit(&mut self) -> f32 {
        (self.next_u32() >> 8) as f32 / 16_777_216.0
    }

    fn coordinate(&mut self) -> f32 {
        let u = self.unit() * 2.0 - 1.0;
        match self.next_u32() % 8 {
            0 => 0.0,
            1 => u * 1e18,
            2 => u * 1e-18,
            3 => (u * 4.0).round(),
            _ => u * 10.0,
        }
    }

    fn point(&mut self) -> Vec3 {
        Vec3::new(self.coordinate(), self.coordinate(), self.coordinate())
    }

    fn direction(&mut self) -> Vec3 {
        // Zero components often (rays in axis planes), never all three.
        loop {
            let d = Vec3::new(self.coordinate(), self.coordinate(), self.coordinate());
            if d != Vec3::ZERO && d.is_finite() {
                return d;
            }
        }
    }
}

/// Each lane equals the scalar test bit for bit over 10⁶ random rays and triangles: whether it
/// hits below `t_max`, and its distance and barycentrics when it does.
#[test]
fn lanes_equal_the_scalar_test_bit_for_bit() {
    let mut cases = Cases(0x5eed);
    let mut hits = 0;
    for _ in 0..250_000 {
        let ray = PreparedRay::new(cases.point(), cases.direction());
        let origin = permuted_origin(&ray);
        let vertices: [[Vec3; 3]; LANES] = std::array::from_fn(|_| {
            // Triangles about the ray's path half of the time, so that many are hit.
            if cases.next_u32().is_multiple_of(2) {
                let at = ray.origin + ray.direction * cases.unit() * 4.0;
                std::array::from_fn(|_| at + cases.point() * 0.1)
            } else {
                std::array::from_fn(|_| cases.point())
            }
        });
        let t_max = match cases.next_u32() % 3 {
            0 => f32::INFINITY,
            1 => f32::MAX,
            _ => cases.unit() * 8.0,
        };
        let lanes = intersect_triangles(&ray, origin, &vertices);
        for (lane, [v0, v1, v2]) in vertices.iter().enumerate() {
            let scalar = intersect_triangle(&ray, *v0, *v1, *v2, t_max);
            let kept = (lanes.crosses[lane] && lanes.t[lane] < t_max)
                .then(|| (lanes.t[lane], lanes.b1[lane], lanes.b2[lane]));
            let bits =
                |h: Option<(f32, f32, f32)>| h.map(|(t, b1, b2)| [t, b1, b2].map(f32::to_bits));
            assert_eq!(
                bits(kept),
                bits(scalar),
                "ray {ray:?}, triangle {:?}",
                [v0, v1, v2]
            );
            hits += usize::from(scalar.is_some());
        }
    }
    assert!(
        hits > 100_000,
        "only {hits} of 10⁶ cases hit: the test needs many"
    );
}
