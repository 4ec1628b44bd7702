//! The clear coat (`KHR_materials_clearcoat`): a GGX dielectric interface of index 1.5 over the
//! whole material, mirrored one-to-one in `coat.wgsl` beside it. Directions are in the shading
//! frame (normal +z), `wo.z > 0`.
//!
//! f_coat cosθi = F(ωo·h, 1.5) D(h) G2(ωo, ωi) / (4 cosθo),  α = clearcoat_roughness²,
//!
//! sampled by reflecting a visible normal (pdf G1(ωo) D(h) / (4 cosθo)). What the coat does not
//! reflect reaches the layers below: `math::layers` scales them by 1 − c E_coat(μo), with
//! E_coat(μ, r) = E_{m ~ D_ωo}[F(ωo·m) G2/G1] the coat's directional albedo (`coat_table`), so a
//! coat over a white furnace returns exactly what the layers below it would.

/// The WGSL twin of this module, `coat.wgsl` beside it (composed into the kernels by
/// `rt_gpu::shaders`).
pub const WGSL: &str = include_str!("coat.wgsl");

use glam::{Vec2, Vec3};

use super::microfacet::{ggx_d, ggx_g1, ggx_g2, sample_vndf, visible_normal_albedo};
use super::sampling::fresnel_dielectric;

/// The coat's index of refraction (glTF fixes it).
pub const COAT_IOR: f32 = 1.5;

/// f cosθi of the coat (weight 1) towards `wi`, and the pdf of `sample_coat` there.
pub fn coat_eval(wo: Vec3, wi: Vec3, alpha: f32) -> (f32, f32) {
    if wo.z <= 0.0 || wi.z <= 0.0 {
        return (0.0, 0.0);
    }
    let h = (wo + wi).normalize_or_zero();
    let woh = wo.dot(h);
    if woh <= 0.0 {
        return (0.0, 0.0);
    }
    let a = Vec2::splat(alpha);
    let d = ggx_d(h, a);
    let f = fresnel_dielectric(woh, COAT_IOR) * d * ggx_g2(wo, wi, a) / (4.0 * wo.z);
    (f, ggx_g1(wo, a) * d / (4.0 * wo.z))
}

/// A reflected visible normal for two uniform numbers, `None` below the horizon.
pub fn sample_coat(wo: Vec3, alpha: f32, u1: f32, u2: f32) -> Option<Vec3> {
    let m = sample_vndf(wo, Vec2::splat(alpha), u1, u2);
    let wi = 2.0 * wo.dot(m) * m - wo;
    (wi.z > 0.0).then_some(wi)
}

/// E_coat(μ, roughness), laid out as `microfacet::energy_table`.
pub fn coat_table() -> &'static [f32] {
    static TABLE: std::sync::OnceLock<Vec<f32>> = std::sync::OnceLock::new();
    TABLE.get_or_init(|| visible_normal_albedo(|cos, _| fresnel_dielectric(cos, COAT_IOR)))
}
