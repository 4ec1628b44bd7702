//! The GGX (Trowbridge–Reitz) microfacet distribution, mirrored one-to-one in
//! `microfacet.wgsl` beside it. Directions are in the shading frame (normal = +z), α is the
//! width (glTF: roughness²).
//!
//! - D(m) = α² / (π (cos²θ_m (α² − 1) + 1)²)
//! - Λ(ω) = (√(1 + α² tan²θ) − 1) / 2, G1(ω) = 1 / (1 + Λ(ω)), and the height-correlated
//!   G2(ωo, ωi) = 1 / (1 + Λ(ωo) + Λ(ωi)) (Heitz 2014).
//! - Visible normals D_ωo(m) = G1(ωo) max(0, ωo·m) D(m) / cosθ_o, sampled exactly (Heitz 2018).

/// The WGSL twin of this module, `microfacet.wgsl` beside it (composed into the kernels by
/// `rt_gpu::shaders`).
pub const WGSL: &str = include_str!("microfacet.wgsl");

use glam::Vec3;

/// Widths below this are treated as this (a mirror to f32 precision; D stays finite).
pub const MIN_ALPHA: f32 = 1.0e-3;

/// α of a glTF roughness in [0, 1].
pub fn alpha_of_roughness(roughness: f32) -> f32 {
    (roughness.clamp(0.0, 1.0) * roughness.clamp(0.0, 1.0)).max(MIN_ALPHA)
}

pub fn ggx_d(m: Vec3, alpha: f32) -> f32 {
    if m.z <= 0.0 {
        return 0.0;
    }
    let a2 = alpha * alpha;
    let c2 = m.z * m.z;
    let d = c2 * (a2 - 1.0) + 1.0;
    a2 / (std::f32::consts::PI * d * d)
}

pub fn ggx_lambda(w: Vec3, alpha: f32) -> f32 {
    let c2 = w.z * w.z;
    let s2 = (1.0 - c2).max(0.0);
    if c2 <= 0.0 {
        return f32::MAX;
    }
    let t2 = alpha * alpha * s2 / c2;
    0.5 * ((1.0 + t2).sqrt() - 1.0)
}

pub fn ggx_g1(w: Vec3, alpha: f32) -> f32 {
    1.0 / (1.0 + ggx_lambda(w, alpha))
}

pub fn ggx_g2(wo: Vec3, wi: Vec3, alpha: f32) -> f32 {
    1.0 / (1.0 + ggx_lambda(wo, alpha) + ggx_lambda(wi, alpha))
}

/// A visible normal for `wo` (wo.z > 0) from two uniform numbers (Heitz 2018, "Sampling the GGX
/// Distribution of Visible Normals").
pub fn sample_vndf(wo: Vec3, alpha: f32, u1: f32, u2: f32) -> Vec3 {
    let vh = Vec3::new(alpha * wo.x, alpha * wo.y, wo.z).normalize();
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
    Vec3::new(alpha * nh.x, alpha * nh.y, nh.z.max(0.0)).normalize()
}

/// The density of `sample_vndf` at normal `m`.
pub fn vndf_pdf(wo: Vec3, m: Vec3, alpha: f32) -> f32 {
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
        let alpha = alpha_of_roughness(roughness);
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
