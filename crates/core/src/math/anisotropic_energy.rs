//! Multiple-scattering compensation of anisotropic conductors (`KHR_materials_anisotropy`): the
//! directional albedo E(μ, φ, r, s) of a white GGX conductor of roughness r stretched by strength
//! s (widths `microfacet::anisotropic_alpha`), seen from cosine μ and azimuth φ from the direction
//! of anisotropy, tabulated once and read by a four-way linear lookup, beside its WGSL twin
//! `anisotropic_energy.wgsl`. Turquin's factor 1 + F0 (1/E − 1) then restores what single
//! scattering loses, as the isotropic table does for isotropic metals: a lobe a hundred times
//! wider one way than the other loses up to half the light, which the isotropic table at the mean
//! width does not see.
//!
//! E(μ, φ, r, s) = E_{m ~ D_ωo}[G2(ωo, ωi) / G1(ωo)] over the reflected visible normals, by a
//! 610-point Fibonacci lattice over the visible-normal warp (the whole square: a stretched lobe is
//! not symmetric about the plane of ωo). A square midpoint grid aliases with the horizon's cut,
//! which near normal incidence follows its rows: measured at μ = 1, roughness 0.4, 24² to 64²
//! points swing by ±1%, the lattice stays within 0.01% from 377 to 1597 points. Its symmetries E(φ) = E(−φ) = E(π − φ) fold φ into [0, π/2].
//! Axes: cosines from `MU_MIN` to 1 and φ from 0 to π/2 evenly (ends included), roughnesses and
//! strengths from 0 to 1 evenly; entry ((s · ANISO_ROUGHNESS + r) · ANISO_PHI + φ) · ANISO_MU + μ.

/// The WGSL twin of this module, `anisotropic_energy.wgsl` beside it (composed into the kernels
/// by `rt_gpu::shaders`).
pub const WGSL: &str = include_str!("anisotropic_energy.wgsl");

use glam::Vec3;

use super::glass_energy::MU_MIN;
use super::microfacet::{anisotropic_alpha, ggx_g1, ggx_g2, sample_vndf};

pub const ANISO_MU: usize = 16;
pub const ANISO_PHI: usize = 6;
pub const ANISO_ROUGHNESS: usize = 16;
pub const ANISO_STRENGTH: usize = 8;
/// Entries of the table.
pub const ANISOTROPIC_TABLE: usize = ANISO_MU * ANISO_PHI * ANISO_ROUGHNESS * ANISO_STRENGTH;

/// E(μ, φ, r, s) by the module's quadrature.
fn albedo(mu: f32, phi: f32, roughness: f32, strength: f32) -> f32 {
    // The Fibonacci lattice of F_15 = 610 points, the second coordinate stepping by F_14 = 377.
    const N: usize = 610;
    const STEP: usize = 377;
    let alpha = anisotropic_alpha(roughness, strength);
    let s = (1.0 - mu * mu).max(0.0).sqrt();
    let wo = Vec3::new(s * phi.cos(), s * phi.sin(), mu);
    let g1 = ggx_g1(wo, alpha);
    let mut sum = 0.0f64;
    for i in 0..N {
        let u1 = (i as f32 + 0.5) / N as f32;
        let u2 = ((i * STEP) % N) as f32 / N as f32 + 0.5 / N as f32;
        let m = sample_vndf(wo, alpha, u1, u2);
        let wi = 2.0 * wo.dot(m) * m - wo;
        if wi.z > 0.0 {
            sum += f64::from(ggx_g2(wo, wi, alpha) / g1);
        }
    }
    (sum / N as f64) as f32
}

/// The table (layout in the module doc), built once on first use.
pub fn anisotropic_table() -> &'static [f32] {
    static TABLE: std::sync::OnceLock<Vec<f32>> = std::sync::OnceLock::new();
    TABLE.get_or_init(|| {
        use rayon::prelude::*;
        (0..ANISOTROPIC_TABLE)
            .into_par_iter()
            .map(|e| {
                let m = e % ANISO_MU;
                let p = (e / ANISO_MU) % ANISO_PHI;
                let r = (e / (ANISO_MU * ANISO_PHI)) % ANISO_ROUGHNESS;
                let s = e / (ANISO_MU * ANISO_PHI * ANISO_ROUGHNESS);
                albedo(
                    MU_MIN + (1.0 - MU_MIN) * m as f32 / (ANISO_MU - 1) as f32,
                    std::f32::consts::FRAC_PI_2 * p as f32 / (ANISO_PHI - 1) as f32,
                    r as f32 / (ANISO_ROUGHNESS - 1) as f32,
                    s as f32 / (ANISO_STRENGTH - 1) as f32,
                )
            })
            .collect()
    })
}

/// A grid coordinate: the lower index (at most size − 2) and the fraction, clamped at the edges.
fn grid(v: f32, size: usize) -> (usize, f32) {
    let v = v.clamp(0.0, (size - 1) as f32);
    let lo = v.floor().min((size - 2) as f32);
    (lo as usize, v - lo)
}

/// E seen from `wo` (shading frame, x the direction of anisotropy) for roughness and strength,
/// by linear interpolation along each of the table's four axes.
pub fn anisotropic_energy(table: &[f32], wo: Vec3, roughness: f32, strength: f32) -> f32 {
    let phi = wo.y.abs().atan2(wo.x.abs());
    let (m, fm) = grid(
        (wo.z - MU_MIN) / (1.0 - MU_MIN) * (ANISO_MU - 1) as f32,
        ANISO_MU,
    );
    let (p, fp) = grid(
        phi / std::f32::consts::FRAC_PI_2 * (ANISO_PHI - 1) as f32,
        ANISO_PHI,
    );
    let (r, fr) = grid(roughness * (ANISO_ROUGHNESS - 1) as f32, ANISO_ROUGHNESS);
    let (s, fs) = grid(strength * (ANISO_STRENGTH - 1) as f32, ANISO_STRENGTH);
    let at = |s: usize, r: usize, p: usize, m: usize| {
        table[((s * ANISO_ROUGHNESS + r) * ANISO_PHI + p) * ANISO_MU + m]
    };
    let mut out = 0.0;
    for (ds, ws) in [(0, 1.0 - fs), (1, fs)] {
        for (dr, wr) in [(0, 1.0 - fr), (1, fr)] {
            let (s, r) = (s + ds, r + dr);
            let lo = at(s, r, p, m) + (at(s, r, p, m + 1) - at(s, r, p, m)) * fm;
            let hi = at(s, r, p + 1, m) + (at(s, r, p + 1, m + 1) - at(s, r, p + 1, m)) * fm;
            out += ws * wr * (lo + (hi - lo) * fp);
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::math::microfacet::{energy_lookup, energy_table};

    /// At strength 0 the table is the isotropic conductor's, whatever the azimuth, within 1% (its
    /// grid is coarser: 16 cosines and roughnesses against 64, measured worst 0.65% at grazing
    /// incidence over roughness 0.1); stretched lobes lose more.
    #[test]
    fn strength_zero_is_the_isotropic_albedo() {
        let table = anisotropic_table();
        for r in [0.1f32, 0.4, 0.8, 1.0] {
            for mu in [0.1f32, 0.5, 0.9] {
                let iso = energy_lookup(energy_table(), mu, r);
                for phi in [0.0f32, 0.7, 1.5] {
                    let s = (1.0 - mu * mu).sqrt();
                    let wo = Vec3::new(s * phi.cos(), s * phi.sin(), mu);
                    let e = anisotropic_energy(table, wo, r, 0.0);
                    assert!((e - iso).abs() < 1e-2, "r {r} μ {mu} φ {phi}: {e} vs {iso}");
                    assert!(anisotropic_energy(table, wo, r, 1.0) <= e + 1e-3);
                }
            }
        }
    }
}
