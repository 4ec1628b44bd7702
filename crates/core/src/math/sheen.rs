//! The sheen layer (`KHR_materials_sheen`): Estevez and Kulla's "Charlie" microfibre distribution
//! with their fitted visibility, mirrored one-to-one in `sheen.wgsl` beside it. Directions are in
//! the shading frame (normal +z), `wo.z > 0`; α = max(sheen_roughness, 0.07)² (the Khronos sample
//! viewer squares the roughness; the floor, as three.js's, keeps D representable in f32).
//!
//! - D(h) = (2 + 1/α) (sin²θh)^(1/(2α)) / (2π)
//! - Λ(μ) = exp(l(μ)) for μ < ½, else exp(2 l(½) − l(1 − μ)), with l(x) = a/(1 + b x^c) + d x + e
//!   and (a…e) interpolated between the fits at α = 0 and α = 1 by (1 − α)²
//! - f_sheen cosθi = sheen_color · D(h) / ((1 + Λ(μo) + Λ(μi)) · 4 μo)
//!
//! sampled uniformly over the hemisphere (pdf 1/2π: the lobe lies towards grazing angles, where a
//! cosine-weighted sample would seldom go). `math::layers` scales what lies below the sheen by
//! 1 − max(sheen_color) E_sheen(μo), E_sheen (`sheen_table`) the white sheen's directional albedo.

/// The WGSL twin of this module, `sheen.wgsl` beside it (composed into the kernels by
/// `rt_gpu::shaders`).
pub const WGSL: &str = include_str!("sheen.wgsl");

use glam::Vec3;

use super::microfacet::tabulate;

/// The smallest sheen roughness the lobe uses.
pub const SHEEN_MIN_ROUGHNESS: f32 = 0.07;

/// α of a sheen roughness.
pub fn sheen_alpha(roughness: f32) -> f32 {
    let r = roughness.clamp(SHEEN_MIN_ROUGHNESS, 1.0);
    r * r
}

pub fn charlie_d(cos_h: f32, alpha: f32) -> f32 {
    let sin2 = (1.0 - cos_h * cos_h).max(0.0);
    (2.0 + 1.0 / alpha) * sin2.powf(0.5 / alpha) * (0.5 * std::f32::consts::FRAC_1_PI)
}

fn charlie_l(x: f32, alpha: f32) -> f32 {
    let t = (1.0 - alpha) * (1.0 - alpha);
    let mix = |at1: f32, at0: f32| at1 + (at0 - at1) * t;
    let a = mix(21.5473, 25.3245);
    let b = mix(3.82987, 3.32435);
    let c = mix(0.19823, 0.16801);
    let d = mix(-1.97760, -1.27393);
    let e = mix(-4.32054, -4.85967);
    a / (1.0 + b * x.powf(c)) + d * x + e
}

pub fn charlie_lambda(cos: f32, alpha: f32) -> f32 {
    if cos < 0.5 {
        charlie_l(cos, alpha).exp()
    } else {
        (2.0 * charlie_l(0.5, alpha) - charlie_l(1.0 - cos, alpha)).exp()
    }
}

/// f cosθi of a white sheen towards `wi` (zero below the horizon).
pub fn sheen_eval(wo: Vec3, wi: Vec3, alpha: f32) -> f32 {
    if wo.z <= 0.0 || wi.z <= 0.0 {
        return 0.0;
    }
    let h = (wo + wi).normalize();
    charlie_d(h.z, alpha)
        / ((1.0 + charlie_lambda(wo.z, alpha) + charlie_lambda(wi.z, alpha)) * 4.0 * wo.z)
}

/// A uniform direction on the upper hemisphere for two uniform numbers (pdf `1/2π`).
pub fn sample_sheen(u1: f32, u2: f32) -> Vec3 {
    let s = (1.0 - u1 * u1).max(0.0).sqrt();
    let phi = std::f32::consts::TAU * u2;
    Vec3::new(s * phi.cos(), s * phi.sin(), u1)
}

/// E_sheen(μ, roughness) = ∫ f_sheen cosθi dωi for a white sheen, laid out as
/// `microfacet::energy_table`: a 64 × 32 midpoint rule over (u, φ) with cosθi = u² (the lobe and
/// its visibility change fastest near the horizon) and φ over half the circle (the lobe is
/// symmetric about the plane of ωo); measured against a 2048 × 512 rule, within 4e-4.
pub fn sheen_table() -> &'static [f32] {
    static TABLE: std::sync::OnceLock<Vec<f32>> = std::sync::OnceLock::new();
    TABLE.get_or_init(|| {
        const QC: usize = 64;
        const QP: usize = 32;
        tabulate(|roughness, mu| {
            let alpha = sheen_alpha(roughness);
            let wo = Vec3::new((1.0 - mu * mu).sqrt(), 0.0, mu);
            let mut sum = 0.0f64;
            for a in 0..QC {
                let u = (a as f32 + 0.5) / QC as f32;
                for b in 0..QP {
                    let wi = sample_sheen(u * u, 0.5 * (b as f32 + 0.5) / QP as f32);
                    sum += f64::from(sheen_eval(wo, wi, alpha) * 2.0 * u);
                }
            }
            (sum * std::f64::consts::TAU / (QC * QP) as f64) as f32
        })
    })
}
