//! The emitter table for next-event estimation: every triangle with non-zero emission, picked in
//! proportion to its power (area × luminance of its emission) through Vose's alias method.
//!
//! With that choice the pdf of a uniformly sampled point on the chosen triangle, per unit area, is
//!   p_A = (A_i L_i / Σ_j A_j L_j) · (1 / A_i) = L_i / Σ_j A_j L_j,
//! which depends only on the emission's luminance L_i: the kernel needs no per-triangle table to
//! evaluate it when a BSDF-sampled ray hits an emitter (for the MIS weight).

use glam::Vec3;

use crate::gpu_types::{Emitter, Material, Triangle};
use crate::math::sampling::luminance;

/// The alias table and the total power Σ A·L (0 when nothing emits).
pub fn build_emitters(triangles: &[Triangle], materials: &[Material]) -> (Vec<Emitter>, f32) {
    let mut indices = Vec::new();
    let mut weights = Vec::new();
    for (i, t) in triangles.iter().enumerate() {
        let emission = luminance(Vec3::from(materials[t.material as usize].emission));
        if emission <= 0.0 {
            continue;
        }
        let (v0, v1, v2) = (Vec3::from(t.v0), Vec3::from(t.v1), Vec3::from(t.v2));
        let area = 0.5 * (v1 - v0).cross(v2 - v0).length();
        if area > 0.0 && area.is_finite() {
            indices.push(i as u32);
            weights.push(f64::from(area) * f64::from(emission));
        }
    }
    let total: f64 = weights.iter().sum();
    if indices.is_empty() || !(total > 0.0 && total.is_finite()) {
        return (Vec::new(), 0.0);
    }
    let (thresholds, aliases) = alias_table(&weights);
    let emitters = indices
        .iter()
        .zip(thresholds.iter().zip(&aliases))
        .map(|(&triangle, (&threshold, &alias))| Emitter {
            triangle,
            alias_index: alias,
            threshold,
            leaf: 0,
        })
        .collect();
    (emitters, total as f32)
}

/// The emitter triangle for two uniform numbers: slot ⌊u_pick·n⌋ of the alias table, then its own
/// triangle with probability `threshold`, else its alias's. Mirrors `shaders/trace.wgsl`.
pub fn pick_emitter(emitters: &[Emitter], u_pick: f32, u_alias: f32) -> u32 {
    let n = emitters.len() as u32;
    let slot = &emitters[((u_pick * n as f32) as u32).min(n - 1) as usize];
    if u_alias < slot.threshold {
        slot.triangle
    } else {
        emitters[slot.alias_index as usize].triangle
    }
}

/// Vose's alias method: entry i is kept with probability `threshold[i]`, else `alias[i]` is taken.
pub fn alias_table(weights: &[f64]) -> (Vec<f32>, Vec<u32>) {
    let n = weights.len();
    let total: f64 = weights.iter().sum();
    let mut scaled: Vec<f64> = weights.iter().map(|w| w / total * n as f64).collect();
    let mut threshold = vec![1.0f32; n];
    let mut alias: Vec<u32> = (0..n as u32).collect();
    let (mut small, mut large): (Vec<usize>, Vec<usize>) = (0..n).partition(|&i| scaled[i] < 1.0);
    while let (Some(s), Some(&l)) = (small.pop(), large.last()) {
        threshold[s] = scaled[s] as f32;
        alias[s] = l as u32;
        scaled[l] -= 1.0 - scaled[s];
        if scaled[l] < 1.0 {
            large.pop();
            small.push(l);
        }
    }
    // Whatever is left holds probability 1 up to rounding.
    (threshold, alias)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Emitter sampling picks each triangle in proportion to its power (area × luminance): a
    /// chi-square test over triangles of different sizes and emissions, non-emitters and a
    /// zero-area emitter included (those must never be picked).
    #[test]
    fn emitters_are_picked_in_proportion_to_their_power() {
        use crate::material_kind::MaterialKind;
        use crate::math::rng::Rng;
        let material = |emission: [f32; 3]| Material {
            color: [0.5; 3],
            kind: MaterialKind::Emissive.tag(),
            emission,
            ..Default::default()
        };
        let materials = [
            material([0.0; 3]),
            material([1.0, 1.0, 1.0]),
            material([5.0, 0.5, 0.1]),
            material([0.1, 0.1, 3.0]),
        ];
        let triangle = |size: f32, m: u32| Triangle {
            v0: [0.0, 0.0, 0.0],
            material: m,
            v1: [size, 0.0, 0.0],
            has_normals: 0,
            v2: [0.0, size, 0.0],
            has_uvs: 0,
        };
        let triangles = [
            triangle(1.0, 1),
            triangle(2.0, 0),
            triangle(0.5, 2),
            triangle(3.0, 3),
            triangle(0.0, 1),
            triangle(1.5, 1),
            triangle(0.1, 2),
        ];
        let (emitters, total) = build_emitters(&triangles, &materials);
        let power = |i: usize| {
            let t = &triangles[i];
            let area = 0.5 * Vec3::from(t.v1).cross(Vec3::from(t.v2)).length();
            f64::from(area)
                * f64::from(luminance(Vec3::from(
                    materials[t.material as usize].emission,
                )))
        };
        let expected_total: f64 = (0..triangles.len()).map(power).sum();
        assert!((f64::from(total) - expected_total).abs() < 1e-4 * expected_total);
        let samples = 200_000;
        let mut counts = vec![0usize; triangles.len()];
        for i in 0..samples {
            let mut rng = Rng::new(i, 3, 5);
            let (u_pick, u_alias) = (rng.next_f32(), rng.next_f32());
            counts[pick_emitter(&emitters, u_pick, u_alias) as usize] += 1;
        }
        assert_eq!(
            counts[1] + counts[4],
            0,
            "no light, or no area: never picked"
        );
        let mut chi2 = 0.0;
        let mut bins = 0;
        for (i, &c) in counts.iter().enumerate() {
            let e = power(i) / expected_total * f64::from(samples);
            if e > 0.0 {
                chi2 += (c as f64 - e).powi(2) / e;
                bins += 1;
            }
        }
        // The 0.999 quantile of chi-square with bins − 1 = 4 degrees of freedom is 18.47.
        assert_eq!(bins, 5);
        assert!(chi2 < 18.47, "chi-square {chi2:.2}: {counts:?}");
    }

    #[test]
    fn alias_table_reproduces_the_weights() {
        let weights = [1.0, 0.0, 3.0, 0.5, 10.0, 2.5];
        let (threshold, alias) = alias_table(&weights);
        let n = weights.len() as f64;
        let mut p = vec![0.0f64; weights.len()];
        for i in 0..weights.len() {
            p[i] += f64::from(threshold[i]) / n;
            p[alias[i] as usize] += (1.0 - f64::from(threshold[i])) / n;
        }
        let total: f64 = weights.iter().sum();
        for (i, w) in weights.iter().enumerate() {
            assert!(
                (p[i] - w / total).abs() < 1e-6,
                "entry {i}: {} vs {}",
                p[i],
                w / total
            );
        }
    }
}
