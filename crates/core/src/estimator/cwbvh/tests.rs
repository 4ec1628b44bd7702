use super::*;

/// The kernel's test (`cwbvh.wgsl`'s child loop), child by child with a branch: the reference
/// `child_hits`, which masks instead, must equal.
fn child_hits_per_child(
    node: &WideBvhNode,
    ray: &PreparedRay,
    oct_inv4: u32,
    neg: BVec3,
    t_max: f32,
) -> u32 {
    let scaled_inv = cell_size(node) * ray.inv_direction;
    let shifted_origin = (Vec3::from(node.origin) - ray.origin) * ray.inv_direction;
    let planes = |neg: bool, lo: [u32; 2], hi: [u32; 2]| if neg { [hi, lo] } else { [lo, hi] };
    let [near_x, far_x] = planes(neg.x, node.lo_x, node.hi_x);
    let [near_y, far_y] = planes(neg.y, node.lo_y, node.hi_y);
    let [near_z, far_z] = planes(neg.z, node.lo_z, node.hi_z);
    let mut hits = 0;
    for word in 0..2 {
        let slot_bytes = node.slots[word];
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
            let far = t_far.min_element() * 1.000_000_4;
            if near <= far && near < t_max {
                hits |= ((bits >> (lane * 8)) & 0xff) << ((shift >> (lane * 8)) & 0xff);
            }
        }
    }
    hits
}

struct Random(u64);

impl Random {
    fn next(&mut self) -> u32 {
        self.0 = self
            .0
            .wrapping_mul(6_364_136_223_846_793_005)
            .wrapping_add(1_442_695_040_888_963_407);
        (self.0 >> 32) as u32
    }

    fn float(&mut self) -> f32 {
        let u = (self.next() >> 8) as f32 / 16_777_216.0 * 2.0 - 1.0;
        match self.next() % 8 {
            0 => 0.0,
            1 => u * 1e15,
            2 => u * 1e-15,
            3 => (u * 4.0).round(),
            _ => u * 10.0,
        }
    }

    fn vector(&mut self) -> Vec3 {
        Vec3::new(self.float(), self.float(), self.float())
    }
}

/// The masked node test, and on CPUs with AVX2 the eight-lane one (`avx2::child_hits`), equal the
/// branching one bit for bit over 10⁶ random nodes and rays: directions with zero components,
/// huge and tiny coordinates and cell sizes (infinite ones too, whose slabs make NaNs), children
/// inner, leaf and empty, random distances.
#[test]
#[allow(unsafe_code)] // calling the AVX2 test where the CPU has AVX2
fn the_masked_and_wide_tests_equal_the_branching_one_over_random_nodes() {
    let mut random = Random(0xb0c5);
    let mut entered = 0;
    for _ in 0..1_000_000 {
        // Three cases in four ordinary (cells about 1, the ray starting among the children with
        // no limit), the fourth wild (any exponent, origin and limit).
        let wild = random.next().is_multiple_of(4);
        let exponent = |r: &mut Random| {
            if wild {
                r.next() % 256
            } else {
                125 + r.next() % 4
            }
        };
        // Per axis, the children's low and high plane bytes, ordered (a child's box).
        let axis = |r: &mut Random| {
            let (a, b) = ([r.next(), r.next()], [r.next(), r.next()]);
            let pick = |low: bool| -> [u32; 2] {
                std::array::from_fn(|word| {
                    (0..4).fold(0, |acc, lane| {
                        let x = (a[word] >> (lane * 8)) & 0xff;
                        let y = (b[word] >> (lane * 8)) & 0xff;
                        acc | (if low { x.min(y) } else { x.max(y) } << (lane * 8))
                    })
                })
            };
            (pick(true), pick(false))
        };
        let ((lo_x, hi_x), (lo_y, hi_y), (lo_z, hi_z)) =
            (axis(&mut random), axis(&mut random), axis(&mut random));
        let node = WideBvhNode {
            origin: random.vector().to_array(),
            exponents_imask: exponent(&mut random)
                | (exponent(&mut random) << 8)
                | (exponent(&mut random) << 16)
                | (random.next() & 0xff00_0000),
            child_base: 0,
            primitive_base: 0,
            slots: [random.next(), random.next()],
            lo_x,
            hi_x,
            lo_y,
            hi_y,
            lo_z,
            hi_z,
        };
        let direction = loop {
            let d = random.vector();
            if d != Vec3::ZERO {
                break d;
            }
        };
        // Rays from about the node's cells half of the time.
        let unit = |r: &mut Random| (r.next() >> 8) as f32 / 16_777_216.0;
        let origin = if wild {
            random.vector()
        } else {
            Vec3::from(node.origin)
                + Vec3::new(unit(&mut random), unit(&mut random), unit(&mut random)) * 255.0
        };
        let ray = PreparedRay::new(origin, direction);
        let oct_inv = (u32::from(direction.x >= 0.0) << 2)
            | (u32::from(direction.y >= 0.0) << 1)
            | u32::from(direction.z >= 0.0);
        let neg = direction.cmplt(Vec3::ZERO);
        let t_max = match random.next() % 3 {
            _ if !wild => f32::INFINITY,
            0 => f32::INFINITY,
            1 => f32::MAX,
            _ => random.float().abs() * 100.0,
        };
        let mut near = [0.0; 8];
        let masked = child_hits(&node, &ray, oct_inv * 0x0101_0101, neg, t_max, &mut near);
        let reference = child_hits_per_child(&node, &ray, oct_inv * 0x0101_0101, neg, t_max);
        assert_eq!(
            masked, reference,
            "node {node:?}, ray {ray:?}, t_max {t_max}"
        );
        #[cfg(target_arch = "x86_64")]
        if std::arch::is_x86_feature_detected!("avx2") {
            // SAFETY: the CPU has AVX2.
            let mut wide_near = [0.0; 8];
            let wide = unsafe {
                super::avx2::child_hits(&node, &ray, oct_inv, neg, t_max, &mut wide_near)
            };
            assert_eq!(
                wide, reference,
                "AVX2: node {node:?}, ray {ray:?}, t_max {t_max}"
            );
            // The entry distances the nearest-first traversal sorts by, for every child entered.
            for slot in 0..8 {
                if near[slot] <= t_max {
                    assert_eq!(
                        near[slot].to_bits(),
                        wide_near[slot].to_bits(),
                        "slot {slot}"
                    );
                }
            }
        }
        entered += usize::from(reference != 0);
    }
    assert!(
        entered > 100_000,
        "only {entered} nodes entered: the test needs many"
    );
}

/// A closed box (shared edges and vertices), a sphere inside it and a soup of small triangles.
fn test_scene() -> GpuScene {
    use crate::scene::{Mesh, Object, Scene};
    let object = |name: &str, mesh: Mesh| Object {
        shadow_catcher: false,
        animation_node: None,
        name: name.into(),
        mesh: std::sync::Arc::new(mesh),
        material: crate::Material::Lambertian {
            albedo: [0.5; 3],
            texture: None,
        },
        transform: Default::default(),
    };
    let mut random = Random(0x50f7);
    let mut unit = move || (random.next() >> 8) as f32 / 16_777_216.0;
    let positions: Vec<Vec3> = (0..3000)
        .flat_map(|_| {
            let c = Vec3::new(unit(), unit(), unit()) * 4.0 - 2.0;
            let size = 0.02 + unit() * unit();
            [(); 3].map(|_| c + (Vec3::new(unit(), unit(), unit()) - 0.5) * size)
        })
        .collect();
    let soup = Mesh {
        indices: (0..positions.len() as u32 / 3)
            .map(|i| [3 * i, 3 * i + 1, 3 * i + 2])
            .collect(),
        positions,
        normals: None,
        uvs: None,
        colors: None,
    };
    let scene = Scene {
        objects: vec![
            object(
                "room",
                crate::shapes::cuboid(Vec3::splat(-3.0), Vec3::splat(3.0), true),
            ),
            object("ball", crate::shapes::uv_sphere(1.0, 24, 48)),
            object("soup", soup),
        ],
        ..Default::default()
    };
    GpuScene::build(&scene).unwrap()
}

/// Ray `i` of the traversal tests: from mostly inside the test scene's room (±3), some outside
/// it, in a random unit direction; every fourth with a short random limit.
fn random_ray(random: &mut Random, i: u32) -> (Vec3, Vec3, f32) {
    let mut coordinate = || (random.next() >> 8) as f32 / 16_777_216.0 * 8.0 - 4.0;
    let origin = Vec3::new(coordinate(), coordinate(), coordinate());
    let direction = loop {
        let d = random.vector();
        if d != Vec3::ZERO && d.is_finite() {
            break d.normalize_or(Vec3::X);
        }
    };
    let t_max = if i.is_multiple_of(4) {
        random.float().abs() * 4.0
    } else {
        f32::MAX
    };
    (origin, direction, t_max)
}

/// The version `multiversion` dispatches to on this CPU finds the same hits as the baseline
/// x86-64 one, bit for bit (distance, triangle, barycentrics), nearest and any-hit, over 10⁶ rays
/// from inside and outside the scene. (On a CPU without the newer instructions both are the
/// baseline and this holds trivially; the machines here have them.)
#[test]
fn the_dispatched_traversal_equals_the_baseline_bit_for_bit() {
    let scene = test_scene();
    let mut random = Random(0xd15b);
    let mut hits = 0;
    for i in 0..1_000_000 {
        let (origin, direction, t_max) = random_ray(&mut random, i);
        let any_hit = i % 3 == 0;
        let bits = |h: Hit| (h.t.to_bits(), h.triangle, h.b1.to_bits(), h.b2.to_bits());
        let dispatched = trace_wide(&scene, 0, origin, direction, t_max, any_hit);
        let baseline = trace_wide_baseline(&scene, 0, origin, direction, t_max, any_hit);
        assert_eq!(
            bits(dispatched),
            bits(baseline),
            "ray {origin} → {direction}, t_max {t_max}, any_hit {any_hit}"
        );
        hits += usize::from(baseline.triangle != super::super::hit::MISS);
    }
    assert!(hits > 500_000, "only {hits} rays hit: the test needs many");
}

/// The CPU's nearest-first traversal finds the nearest distance of the kernel's octant-order one
/// bit for bit, and the same triangle and barycentrics wherever no other triangle is hit at
/// exactly that distance (a shared edge or vertex), over 10⁶ rays from inside and outside the test
/// scene (any-hit queries take the kernel's order itself).
#[test]
fn nearest_first_finds_the_kernel_orders_nearest_hits() {
    let scene = test_scene();
    let mut random = Random(0x5e1f);
    let (mut hits, mut ties) = (0, 0);
    for i in 0..1_000_000 {
        let (origin, direction, t_max) = random_ray(&mut random, i);
        let ours = trace_wide(&scene, 0, origin, direction, t_max, false);
        let kernel = traverse(
            &scene,
            0,
            origin,
            direction,
            t_max,
            false,
            portable_child_hits,
        );
        let context = format!("ray {origin} → {direction}, t_max {t_max}");
        assert_eq!(ours.t.to_bits(), kernel.t.to_bits(), "{context}");
        if kernel.triangle == super::super::hit::MISS {
            assert_eq!(ours.triangle, kernel.triangle, "{context}");
            continue;
        }
        hits += 1;
        if ours.triangle != kernel.triangle {
            ties += 1;
        } else {
            assert_eq!(
                (ours.b1.to_bits(), ours.b2.to_bits()),
                (kernel.b1.to_bits(), kernel.b2.to_bits()),
                "{context}"
            );
        }
    }
    assert!(
        hits > 300_000,
        "only {hits} nearest hits: the test needs many"
    );
    assert!(
        ties < hits / 10_000,
        "{ties} of {hits} hits on another triangle"
    );
}
