//! Multiple-scattering compensation of rough glass, mirrored one-to-one in `glass_energy.wgsl`
//! beside it. A single-scattering GGX dielectric loses the light that bounces more than once
//! among its microfacets (up to half of it at roughness 1 from inside); Turquin 2019 (as Cycles'
//! `ggx_glass_E` tables) scales the lobe by 1/E(μo, roughness, η), E being its directional albedo
//! (reflection plus transmission, radiance's 1/η² undone), so a white glass keeps its energy:
//!
//! E(μ, r, η) = E_{m ~ D_ωo}[F(ωo·m) G2(ωo, ωr)/G1(ωo) + (1 − F(ωo·m)) G2(ωo, ωt)/G1(ωo)],
//!
//! ωr and ωt the reflected and refracted directions (each counted on its own side only). Two
//! tables, entering (η > 1) and leaving (η < 1) the denser medium, over 32 cosines × 32
//! roughnesses × 16 indices z = ((n − 1)/(n + 1)) / ½ (n = η or 1/η, so n ∈ [1, 3]), read
//! trilinearly; a 24 × 24 midpoint rule over the visible-normal warp per entry. Measured against
//! the quadrature at off-grid points, the lookup is within 0.6% (worst at normal incidence from
//! inside, where total internal reflection moves with η); a white furnace of rough glass keeps
//! at least 99.3% (`bsdf`'s tests).

/// The WGSL twin of this module, `glass_energy.wgsl` beside it (composed into the kernels by
/// `rt_gpu::shaders`).
pub const WGSL: &str = include_str!("glass_energy.wgsl");

use glam::{Vec2, Vec3};

use super::microfacet::{alpha_of_roughness, ggx_g1, ggx_g2, sample_vndf};
use super::sampling::{fresnel_dielectric, refract};

/// Cosines, roughnesses and indices of each table.
pub const GLASS_MU: usize = 32;
pub const GLASS_ROUGHNESS: usize = 32;
pub const GLASS_IOR: usize = 16;
/// Entries of one table (entering or leaving).
pub const GLASS_TABLE: usize = GLASS_MU * GLASS_ROUGHNESS * GLASS_IOR;

/// The grazing end of the cosine axis (cosines run evenly from it to 1, both ends included).
pub const MU_MIN: f32 = 1.0 / 64.0;

/// η of index slot `k` of the entering table (its inverse for the leaving one).
fn eta_of(k: usize) -> f32 {
    let z = 0.5 * k as f32 / (GLASS_IOR - 1) as f32;
    (1.0 + z) / (1.0 - z)
}

/// E(μ, r, η) by the module's quadrature (its second coordinate over half the circle, as
/// `microfacet::visible_normal_albedo` says why).
fn albedo(mu: f32, roughness: f32, eta: f32) -> f32 {
    const Q: usize = 24;
    let alpha = Vec2::splat(alpha_of_roughness(roughness));
    let wo = Vec3::new((1.0 - mu * mu).max(0.0).sqrt(), 0.0, mu);
    let g1 = ggx_g1(wo, alpha);
    let mut sum = 0.0f64;
    for a in 0..Q {
        for b in Q / 4..3 * Q / 4 {
            let m = sample_vndf(
                wo,
                alpha,
                (a as f32 + 0.5) / Q as f32,
                (b as f32 + 0.5) / Q as f32,
            );
            let f = fresnel_dielectric(wo.dot(m), eta);
            let wr = 2.0 * wo.dot(m) * m - wo;
            if wr.z > 0.0 {
                sum += f64::from(f * ggx_g2(wo, wr, alpha) / g1);
            }
            if f < 1.0 {
                let wt = refract(-wo, m, eta);
                if wt.z < 0.0 {
                    sum += f64::from((1.0 - f) * ggx_g2(wo, wt, alpha) / g1);
                }
            }
        }
    }
    (sum / (Q * Q / 2) as f64) as f32
}

/// The entering table followed by the leaving one, entry ((k · GLASS_ROUGHNESS) + i) · GLASS_MU + j
/// for index k, roughness i/(GLASS_ROUGHNESS − 1) and cosine MU_MIN + (1 − MU_MIN) j/(GLASS_MU − 1)
/// (the ends included: E changes fastest at normal incidence from inside).
pub fn glass_table() -> &'static [f32] {
    static TABLE: std::sync::OnceLock<Vec<f32>> = std::sync::OnceLock::new();
    TABLE.get_or_init(|| {
        use rayon::prelude::*;
        (0..2 * GLASS_TABLE)
            .into_par_iter()
            .map(|e| {
                let (side, e) = (e / GLASS_TABLE, e % GLASS_TABLE);
                let (k, i, j) = (
                    e / (GLASS_ROUGHNESS * GLASS_MU),
                    (e / GLASS_MU) % GLASS_ROUGHNESS,
                    e % GLASS_MU,
                );
                let eta = if side == 0 {
                    eta_of(k)
                } else {
                    1.0 / eta_of(k)
                };
                let mu = MU_MIN + (1.0 - MU_MIN) * j as f32 / (GLASS_MU - 1) as f32;
                albedo(mu, i as f32 / (GLASS_ROUGHNESS - 1) as f32, eta)
            })
            .collect()
    })
}

/// Trilinear lookup of E(μ, roughness, η) in `table` (`glass_table`'s layout), clamped at its
/// edges.
pub fn glass_energy(table: &[f32], mu: f32, roughness: f32, eta: f32) -> f32 {
    let side = if eta >= 1.0 { 0 } else { GLASS_TABLE };
    let n = if eta >= 1.0 { eta } else { 1.0 / eta };
    let z = 2.0 * (n - 1.0) / (n + 1.0);
    let coordinate = |v: f32, size: usize| {
        let v = v.clamp(0.0, (size - 1) as f32);
        let lo = v.floor().min((size - 2) as f32);
        (lo as usize, v - lo)
    };
    let (j, fj) = coordinate(
        (mu - MU_MIN) / (1.0 - MU_MIN) * (GLASS_MU - 1) as f32,
        GLASS_MU,
    );
    let (i, fi) = coordinate(roughness * (GLASS_ROUGHNESS - 1) as f32, GLASS_ROUGHNESS);
    let (k, fk) = coordinate(z * (GLASS_IOR - 1) as f32, GLASS_IOR);
    let at = |k: usize, i: usize, j: usize| table[side + (k * GLASS_ROUGHNESS + i) * GLASS_MU + j];
    let plane = |k: usize| {
        let lo = at(k, i, j) + (at(k, i, j + 1) - at(k, i, j)) * fj;
        let hi = at(k, i + 1, j) + (at(k, i + 1, j + 1) - at(k, i + 1, j)) * fj;
        lo + (hi - lo) * fi
    };
    let (a, b) = (plane(k), plane(k + 1));
    a + (b - a) * fk
}
