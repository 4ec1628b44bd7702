//! Unit tests of `light_tree`.

use super::*;
use crate::estimator::light_tree::{leaf_of, sample_tree, slot_importances, tree_pmf};
use crate::material_kind::MaterialKind;
use crate::math::rng::Rng;

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
        let n = (Vec3::new(rng.next_f32(), rng.next_f32(), rng.next_f32()) * 2.0 - 1.0).normalize();
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
        let n = (Vec3::new(rng.next_f32(), rng.next_f32(), rng.next_f32()) * 2.0 - 1.0).normalize();
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
        kind: LightTag::Directional.tag(),
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
            kind: [LightTag::Point, LightTag::Spot, LightTag::SpotGltf][i % 3].tag(),
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
    use crate::estimator::light::delta_light_incidence;
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
