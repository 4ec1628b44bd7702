//! The emitter table for next-event estimation: every triangle with non-zero emission, picked in
//! proportion to its power (area × luminance of its emission) through Vose's alias method.
//!
//! With that choice the pdf of a uniformly sampled point on the chosen triangle, per unit area, is
//!   p_A = (A_i L_i / Σ_j A_j L_j) · (1 / A_i) = L_i / Σ_j A_j L_j,
//! which depends only on the emission's luminance L_i: the kernel needs no per-triangle table to
//! evaluate it when a BSDF-sampled ray hits an emitter (for the MIS weight).

use glam::Vec3;

use crate::gpu_types::{Emitter, Material, Triangle};
use crate::reference::sampling::luminance;

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
            _pad: 0,
        })
        .collect();
    (emitters, total as f32)
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
