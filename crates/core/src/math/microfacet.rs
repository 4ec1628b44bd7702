//! The GGX (Trowbridge–Reitz) microfacet distribution, anisotropic, mirrored one-to-one in
//! `microfacet.wgsl` beside it. Directions are in the shading frame (normal = +z, x the direction
//! of anisotropy); α = (α_x, α_y) are the widths along x and y (glTF: roughness², and
//! `KHR_materials_anisotropy` widens α_x). Isotropic surfaces have α_x = α_y.
//!
//! - D(m) = 1 / (π α_x α_y ((m_x/α_x)² + (m_y/α_y)² + m_z²)²)
//! - Λ(ω) = (√(1 + (α_x² ω_x² + α_y² ω_y²)/ω_z²) − 1) / 2, G1(ω) = 1 / (1 + Λ(ω)), and the
//!   height-correlated G2(ωo, ωi) = 1 / (1 + Λ(ωo) + Λ(ωi)) (Heitz 2014).
//! - Visible normals D_ωo(m) = G1(ωo) max(0, ωo·m) D(m) / cosθ_o, sampled exactly by stretching
//!   ωo to the unit-width configuration and back (Heitz 2018).

/// The WGSL twin of this module, `microfacet.wgsl` beside it (composed into the kernels by
/// `rt_gpu::shaders`).
pub const WGSL: &str = include_str!("microfacet.wgsl");

use glam::{Vec2, Vec3};

/// Widths below this are treated as this (a mirror to f32 precision; D stays finite).
pub const MIN_ALPHA: f32 = 1.0e-3;

/// α of a glTF roughness in [0, 1].
pub fn alpha_of_roughness(roughness: f32) -> f32 {
    (roughness.clamp(0.0, 1.0) * roughness.clamp(0.0, 1.0)).max(MIN_ALPHA)
}

/// (α_x, α_y) of a glTF roughness under `KHR_materials_anisotropy`'s strength s ∈ [0, 1]:
/// α_x = mix(α, 1, s²) along the direction of anisotropy, α_y = α across it.
pub fn anisotropic_alpha(roughness: f32, strength: f32) -> Vec2 {
    let a = alpha_of_roughness(roughness);
    let s = strength.clamp(0.0, 1.0);
    Vec2::new(a + (1.0 - a) * s * s, a)
}

/// The isotropic roughness whose albedo tables stand for an anisotropic surface's where it has no
/// table of its own (rough glass; conductors have `math::anisotropic_energy`): that of the mean
/// width √(α_x α_y), as Cycles does. An approximation: strongly anisotropic glass loses more than
/// it restores, and at grazing angles along the narrow axis may gain a few per cent (measured in
/// `bsdf`'s tests).
pub fn equivalent_roughness(alpha: Vec2) -> f32 {
    (alpha.x * alpha.y).sqrt().sqrt()
}

pub fn ggx_d(m: Vec3, alpha: Vec2) -> f32 {
    if m.z <= 0.0 {
        return 0.0;
    }
    let (x, y) = (m.x / alpha.x, m.y / alpha.y);
    let d = x * x + y * y + m.z * m.z;
    1.0 / (std::f32::consts::PI * alpha.x * alpha.y * d * d)
}

pub fn ggx_lambda(w: Vec3, alpha: Vec2) -> f32 {
    let c2 = w.z * w.z;
    if c2 <= 0.0 {
        return f32::MAX;
    }
    let (x, y) = (alpha.x * w.x, alpha.y * w.y);
    let t2 = (x * x + y * y) / c2;
    0.5 * ((1.0 + t2).sqrt() - 1.0)
}

pub fn ggx_g1(w: Vec3, alpha: Vec2) -> f32 {
    1.0 / (1.0 + ggx_lambda(w, alpha))
}

pub fn ggx_g2(wo: Vec3, wi: Vec3, alpha: Vec2) -> f32 {
    1.0 / (1.0 + ggx_lambda(wo, alpha) + ggx_lambda(wi, alpha))
}

/// A visible normal for `wo` (wo.z > 0) from two uniform numbers (Heitz 2018, "Sampling the GGX
/// Distribution of Visible Normals").
pub fn sample_vndf(wo: Vec3, alpha: Vec2, u1: f32, u2: f32) -> Vec3 {
    let vh = Vec3::new(alpha.x * wo.x, alpha.y * wo.y, wo.z).normalize();
    let lensq = vh.x * vh.x + vh.y * vh.y;
    let t1 = if lensq > 0.0 {
        Vec3::new(-vh.y, vh.x, 0.0) / lensq.sqrt()
    } else {
        Vec3::X
    };
    let t2 = vh.cross(t1);
    let r = u1.sqrt();
    let phi = std::f32::consts::TAU * u2;
    let p1 = r * phi.cos();
    let s = 0.5 * (1.0 + vh.z);
    let p2 = (1.0 - s) * (1.0 - p1 * p1).max(0.0).sqrt() + s * r * phi.sin();
    let nh = t1 * p1 + t2 * p2 + vh * (1.0 - p1 * p1 - p2 * p2).max(0.0).sqrt();
    Vec3::new(alpha.x * nh.x, alpha.y * nh.y, nh.z.max(0.0)).normalize()
}

/// The density of `sample_vndf` at normal `m`.
pub fn vndf_pdf(wo: Vec3, m: Vec3, alpha: Vec2) -> f32 {
    let c = wo.dot(m);
    if c <= 0.0 || wo.z <= 0.0 {
        return 0.0;
    }
    ggx_g1(wo, alpha) * c * ggx_d(m, alpha) / wo.z
}

/// Schlick's Fresnel approximation, F0 + (1 − F0)(1 − cosθ)⁵ (glTF's conductor Fresnel).
pub fn fresnel_schlick(f0: Vec3, cos: f32) -> Vec3 {
    let x = 1.0 - cos.clamp(0.0, 1.0);
    let x2 = x * x;
    f0 + (Vec3::ONE - f0) * (x2 * x2 * x)
}

/// Side of the directional-albedo table: `ENERGY_SIDE` roughnesses × `ENERGY_SIDE` cosines.
pub const ENERGY_SIDE: usize = 64;

/// E(μ, roughness): the directional albedo of a white GGX conductor (F = 1) with single scattering,
/// ∫ D G2 / (4 cosθ_o) dω_i = E_{m ~ D_ωo}[G2 / G1], at cosines μ_j = (j + ½)/N and roughnesses
/// r_i = i/(N − 1), entry i·N + j. Computed once by a 64 × 64 midpoint rule over the visible-normal
/// warp (each entry's quadrature error is below 1e-3); the kernels read the same table.
pub fn energy_table() -> &'static [f32] {
    static TABLE: std::sync::OnceLock<Vec<f32>> = std::sync::OnceLock::new();
    TABLE.get_or_init(|| visible_normal_albedo(|_, _| 1.0))
}

/// A directional-albedo table laid out as `energy_table`: entry (roughness r_i, cosine μ_j) holds
/// `f(r_i, μ_j)`.
pub fn tabulate(f: impl Fn(f32, f32) -> f32 + Sync) -> Vec<f32> {
    use rayon::prelude::*;
    (0..ENERGY_SIDE * ENERGY_SIDE)
        .into_par_iter()
        .map(|k| {
            let roughness = (k / ENERGY_SIDE) as f32 / (ENERGY_SIDE - 1) as f32;
            f(
                roughness,
                ((k % ENERGY_SIDE) as f32 + 0.5) / ENERGY_SIDE as f32,
            )
        })
        .collect()
}

/// The single-scattering albedo of a GGX reflector whose Fresnel is `fresnel(ωo·m)`:
/// E_{m ~ D_ωo}[F(ωo·m) G2 / G1] by a 64 × 64 midpoint rule over the visible-normal warp, its
/// second coordinate (φ = 2π u2) over the half circle u2 ∈ [¼, ¾): the integrand is symmetric about
/// the plane of ωo, which the warp's φ → π − φ mirrors, so the other half repeats it exactly.
pub fn visible_normal_albedo(fresnel: impl Fn(f32, f32) -> f32 + Sync) -> Vec<f32> {
    const Q: usize = 64;
    tabulate(|roughness, mu| {
        let alpha = Vec2::splat(alpha_of_roughness(roughness));
        let wo = Vec3::new((1.0 - mu * mu).sqrt(), 0.0, mu);
        let mut sum = 0.0f64;
        for a in 0..Q {
            for b in Q / 4..3 * Q / 4 {
                let u1 = (a as f32 + 0.5) / Q as f32;
                let u2 = (b as f32 + 0.5) / Q as f32;
                let m = sample_vndf(wo, alpha, u1, u2);
                let wi = 2.0 * wo.dot(m) * m - wo;
                if wi.z > 0.0 {
                    sum += f64::from(
                        fresnel(wo.dot(m), roughness) * ggx_g2(wo, wi, alpha) / ggx_g1(wo, alpha),
                    );
                }
            }
        }
        (sum / (Q * Q / 2) as f64) as f32
    })
}

/// Bilinear lookup of `energy_table` (clamped at its edges).
pub fn energy_lookup(table: &[f32], mu: f32, roughness: f32) -> f32 {
    let n = ENERGY_SIDE as f32;
    let x = (mu * n - 0.5).clamp(0.0, n - 1.0);
    let y = (roughness * (n - 1.0)).clamp(0.0, n - 1.0);
    let (x0, y0) = (x.floor().min(n - 2.0), y.floor().min(n - 2.0));
    let (fx, fy) = (x - x0, y - y0);
    let at = |i: f32, j: f32| table[i as usize * ENERGY_SIDE + j as usize];
    let lo = at(y0, x0) + (at(y0, x0 + 1.0) - at(y0, x0)) * fx;
    let hi = at(y0 + 1.0, x0) + (at(y0 + 1.0, x0 + 1.0) - at(y0 + 1.0, x0)) * fx;
    lo + (hi - lo) * fy
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::math::stats::{check_sphere_sampling, estimate};

    /// The widths tested: isotropic, mildly and fully anisotropic (glTF strengths 0, 0.5, 1;
    /// narrower lobes than α 0.1 across outrun the chi-square's bin quadrature).
    fn widths() -> [Vec2; 4] {
        [
            anisotropic_alpha(0.5, 0.0),
            anisotropic_alpha(0.3, 0.5),
            anisotropic_alpha(0.35, 1.0),
            Vec2::new(0.1, 0.6),
        ]
    }

    /// With equal widths the anisotropic D and Λ are the isotropic formulas of the module doc.
    #[test]
    fn equal_widths_are_the_isotropic_distribution() {
        for a in [0.01f32, 0.2, 0.7, 1.0] {
            for k in 1..=20 {
                let c = k as f32 / 20.0;
                let s = (1.0 - c * c).sqrt();
                let m = Vec3::new(s * 0.6, s * 0.8, c);
                // The isotropic formulas in f64 (in f32, c²(α² − 1) + 1 cancels at small α).
                let (a64, c64, s64) = (f64::from(a), f64::from(c), f64::from(s));
                let den = c64 * c64 * (a64 * a64 - 1.0) + 1.0;
                let iso_d = (a64 * a64 / (std::f64::consts::PI * den * den)) as f32;
                let iso_lambda =
                    (0.5 * ((1.0 + a64 * a64 * s64 * s64 / (c64 * c64)).sqrt() - 1.0)) as f32;
                let d = ggx_d(m, Vec2::splat(a));
                let l = ggx_lambda(m, Vec2::splat(a));
                assert!(
                    (d - iso_d).abs() <= 1e-4 * iso_d,
                    "α {a} cos {c}: {d} vs {iso_d}"
                );
                assert!(
                    (l - iso_lambda).abs() <= 1e-5 + 1e-4 * iso_lambda,
                    "α {a} cos {c}: Λ {l} vs {iso_lambda}"
                );
            }
        }
        let a = alpha_of_roughness(0.4);
        assert_eq!(anisotropic_alpha(0.4, 0.0), Vec2::splat(a));
        assert_eq!(anisotropic_alpha(0.4, 1.0), Vec2::new(1.0, a));
        assert!((equivalent_roughness(Vec2::splat(0.16)) - 0.4).abs() < 1e-6);
    }

    /// D is a distribution of normals (∫ D(m) cosθ_m dω = 1), and G1 is the projected area it
    /// implies (∫ G1(ωo) max(0, ωo·m) D(m) dω = cosθo): uniform-hemisphere estimates within four
    /// standard errors, for each width and three views (one along each axis and one between).
    #[test]
    fn anisotropic_ggx_is_normalised() {
        let hemisphere = |u1: f32, u2: f32| {
            let z = u1;
            let r = (1.0 - z * z).max(0.0).sqrt();
            let phi = std::f32::consts::TAU * u2;
            Vec3::new(r * phi.cos(), r * phi.sin(), z)
        };
        for a in widths() {
            // Wide lobes are integrated well by uniform directions; narrow ones have most of
            // their mass in a sliver, so they get more samples.
            let n = if a.min_element() < 0.15 {
                4_000_000
            } else {
                400_000
            };
            let (total, se) = estimate(n, 11, |_, u1, u2| {
                let m = hemisphere(u1, u2);
                f64::from(ggx_d(m, a) * m.z) * std::f64::consts::TAU
            });
            assert!(
                (total - 1.0).abs() <= 4.0 * se + 1e-3,
                "α {a}: ∫D cos = {total} ± {se}"
            );
            for wo in [
                Vec3::new(0.6, 0.0, 0.8),
                Vec3::new(0.0, 0.8, 0.6),
                Vec3::new(0.5, 0.5, 0.5f32.sqrt()),
            ] {
                let (projected, se) = estimate(n, 12, |_, u1, u2| {
                    let m = hemisphere(u1, u2);
                    f64::from(ggx_g1(wo, a) * wo.dot(m).max(0.0) * ggx_d(m, a))
                        * std::f64::consts::TAU
                });
                assert!(
                    (projected - f64::from(wo.z)).abs() <= 4.0 * se + 1e-3,
                    "α {a}, ωo {wo}: {projected} ± {se} against cosθo {}",
                    wo.z
                );
            }
        }
    }

    /// The visible normals drawn follow `vndf_pdf`, anisotropic too: chi-square over the sphere of
    /// the directions they reflect ωo to above the horizon (density vndf_pdf / (4 ωo·h); the
    /// normals themselves crowd the pole more tightly than the sphere's bins resolve).
    #[test]
    fn visible_normals_follow_their_pdf() {
        let views = [
            Vec3::new(0.6, 0.0, 0.8),
            Vec3::new(-0.3, 0.9, 0.3).normalize(),
        ];
        let tests = widths().len() * views.len();
        let mut k = 0;
        for a in widths() {
            for wo in views {
                check_sphere_sampling(
                    &format!("visible normals, α {a}, ωo {wo}"),
                    300_000,
                    tests,
                    k,
                    |_, u1, u2| {
                        let m = sample_vndf(wo, a, u1, u2);
                        let wi = 2.0 * wo.dot(m) * m - wo;
                        (wi.z > 0.0).then_some(wi)
                    },
                    |wi| {
                        let h = (wo + wi).normalize_or_zero();
                        let c = wo.dot(h);
                        if c > 0.0 && wi.z > 0.0 {
                            vndf_pdf(wo, h, a) / (4.0 * c)
                        } else {
                            0.0
                        }
                    },
                );
                k += 1;
            }
        }
    }
}
