//! The `Pbr` material's base BSDF (glTF 2.0 metallic-roughness, Appendix B, with exact dielectric
//! Fresnel, real refraction and `KHR_materials_specular`), mirrored one-to-one in `bsdf.wgsl`
//! beside it. The layers above it (clear coat, sheen) are `math::layers`. Directions are in the
//! shading frame (normal +z) and point away from the surface; `wo.z > 0`.
//!
//! f = m · F_schlick(c, ωo·h) · k_ms · f_spec                      (metal)
//!   + (1 − m) · [F(ωo·h) · f_spec + (1 − t)(1 − F(ωo·h)) · c/π]   (dielectric over diffuse)
//!   + (1 − m) · t · c · f_walter                                  (rough refraction, ωi below)
//!   + (1 − m)(1 − t) d (1 − F(cosθo)) c_d/π                       (diffuse transmission, ωi below)
//!
//! where the diffuse lobe above keeps 1 − d of its weight: `KHR_materials_diffuse_transmission`
//! sends the share d of the diffuse lobe through to the other side, cosine-distributed, with its
//! own colour c_d in place of the base colour (its 1 − F at the view direction, as no half vector
//! joins the two sides).
//!
//! F is the dielectric's Fresnel as `KHR_materials_specular` shapes it, in Cycles' generalised form
//! that keeps total internal reflection: with F_η the exact unpolarised Fresnel of relative index
//! η and R0 = ((η − 1)/(η + 1))² its value at normal incidence,
//!   F = F0′ + (F90′ − F0′) · (F_η − R0)/(1 − R0),  F0′ = min(R0 · specular_color, 1) · specular,
//!   F90′ = specular,
//! an RGB reflectance that is exactly F_η for the defaults (specular 1, white); the same F splits
//! reflection from diffuse and transmission per channel. A thin film (`KHR_materials_iridescence`,
//! weight i) replaces F by mix(F, F_film, i) on the outside of a dielectric, and the conductor's
//! Schlick term likewise, F_film being `math::iridescence`'s reflectance of the film over that
//! base.
//!
//! A thin-walled surface (a sheet without a volume behind it: glTF's transmission without
//! `KHR_materials_volume`) lets light through without bending it: the slab's total reflectance
//! R' = 2R/(1 + R) (R the single interface's Fresnel, summing the inter-reflections inside the
//! sheet) replaces F for the transmitted part's reflection, and its transmission is the GGX
//! reflection lobe mirrored to the other side, (1 − R') D G2 / (4 cosθo) with ωi's z flipped.
//!
//! with f_spec = D G2 / (4 cosθo cosθi) (GGX, height-correlated Smith), f_walter Walter et al.
//! 2007's BTDF (its own 1 − F, and 1/η² for radiance), and k_ms = 1 + c (1/E(μo) − 1) Turquin
//! 2019's multiple-scattering compensation of the conductor, E the white conductor's directional
//! albedo (`microfacet::energy_table`). The transmissive part (its reflection and its
//! transmission) is scaled likewise by k_glass = 1/E_glass(μo, roughness, η), rough glass's own
//! albedo (`math::glass_energy`; a thin sheet's is the white conductor's E).
//!
//! Sampling is one-sample MIS over three strategies picked with probabilities that depend on ωo
//! only (so the pdf of any ωi can be evaluated for MIS with light sampling), F̄ the mean of F's
//! channels:
//!   q_r = m + (1 − m)(1 − t) F̄(cosθo)  visible-normal reflection,
//!   q_g = (1 − m) t                    visible normal, then reflect with F̄(ωo·m) or refract,
//!   q_d = (1 − m)(1 − t)(1 − F̄(cosθo)) cosine-weighted diffuse, above with 1 − d, below with d,
//! and the weight is f cosθi / Σ q_k p_k(ωi) (these sum to 1).

/// The WGSL twin of this module, `bsdf.wgsl` beside it (composed into the kernels by
/// `rt_gpu::shaders`).
pub const WGSL: &str = include_str!("bsdf.wgsl");

use glam::{Vec2, Vec3};

use super::iridescence::thin_film_fresnel;
use super::microfacet::*;
use super::sampling::{fresnel_dielectric, refract};

/// A `Pbr` surface at one shading point, as seen from one `wo`.
#[derive(Clone, Copy, Debug)]
pub struct Pbr {
    pub base: Vec3,
    pub metallic: f32,
    /// The GGX widths (α_x, α_y) along the shading frame's x and y (`microfacet`).
    pub alpha: Vec2,
    /// Relative index of refraction across the surface from wo's side: n_behind / n_in_front.
    pub eta: f32,
    pub transmission: f32,
    /// Turquin's factor k_ms for the conductor lobe.
    pub ms: Vec3,
    /// The dielectric's reflectance at normal incidence, F0′ (`KHR_materials_specular`).
    pub f0: Vec3,
    /// The dielectric's reflectance at grazing incidence, F90′.
    pub f90: f32,
    /// The transmissive part's multiple-scattering compensation k_glass (1: none).
    pub k_glass: f32,
    /// The diffuse lobe's transmitted share d and its colour c_d.
    pub diffuse_transmission: f32,
    pub diffuse_transmission_color: Vec3,
    /// The thin film's weight, index and thickness (nm).
    pub iridescence: f32,
    pub film_ior: f32,
    pub film_thickness: f32,
    pub q_reflect: f32,
    pub q_glass: f32,
    /// Thin-walled transmission (see above).
    pub thin: bool,
}

/// R0 = ((η − 1)/(η + 1))², the exact Fresnel at normal incidence (the same from either side).
pub fn normal_reflectance(eta: f32) -> f32 {
    let r = (eta - 1.0) / (eta + 1.0);
    r * r
}

/// F of the module doc: the exact Fresnel remapped from [R0, 1] onto [F0′, F90′].
pub fn fresnel_specular(cos: f32, eta: f32, f0: Vec3, f90: f32) -> Vec3 {
    let r0 = normal_reflectance(eta);
    let x = if r0 < 1.0 {
        ((fresnel_dielectric(cos, eta) - r0) / (1.0 - r0)).clamp(0.0, 1.0)
    } else {
        1.0
    };
    f0 + (Vec3::splat(f90) - f0) * x
}

fn mean(v: Vec3) -> f32 {
    (v.x + v.y + v.z) * (1.0 / 3.0)
}

/// The Fresnel reflectance the transmissive part uses: the interface's, or a thin sheet's 2R/(1+R).
fn glass_fresnel(f: Vec3, thin: bool) -> Vec3 {
    if thin { 2.0 * f / (Vec3::ONE + f) } else { f }
}

/// A direction drawn from the BSDF, with f cosθi / pdf and the pdf (solid angle).
#[derive(Clone, Copy, Debug)]
pub struct BsdfSample {
    pub wi: Vec3,
    pub weight: Vec3,
    pub pdf: f32,
}

impl Pbr {
    /// `energy` is the white conductor's albedo E(cosθo, roughness).
    pub fn new(
        base: Vec3,
        metallic: f32,
        roughness: f32,
        eta: f32,
        transmission: f32,
        cos_o: f32,
        energy: f32,
    ) -> Self {
        Pbr {
            base,
            metallic,
            alpha: Vec2::splat(alpha_of_roughness(roughness)),
            eta,
            transmission,
            ms: Vec3::ONE + base * (1.0 / energy.max(1e-3) - 1.0),
            f0: Vec3::splat(normal_reflectance(eta)),
            f90: 1.0,
            k_glass: 1.0,
            diffuse_transmission: 0.0,
            diffuse_transmission_color: Vec3::ONE,
            iridescence: 0.0,
            film_ior: 1.0,
            film_thickness: 0.0,
            q_reflect: 0.0,
            q_glass: 0.0,
            thin: false,
        }
        .with_specular(Vec3::ONE, 1.0, cos_o)
    }

    /// This surface with `KHR_materials_specular`'s colour and strength (see above).
    pub fn with_specular(self, color: Vec3, specular: f32, cos_o: f32) -> Self {
        let (m, t) = (self.metallic, self.transmission);
        let f0 = (normal_reflectance(self.eta) * color).min(Vec3::ONE) * specular;
        let fs = mean(fresnel_specular(cos_o, self.eta, f0, specular));
        Pbr {
            f0,
            f90: specular,
            q_reflect: m + (1.0 - m) * (1.0 - t) * fs,
            q_glass: (1.0 - m) * t,
            ..self
        }
    }

    /// This surface with anisotropic widths (α_x, α_y) (`microfacet::anisotropic_alpha`), the
    /// shading frame's x being the direction of anisotropy.
    pub fn anisotropic(self, alpha: Vec2) -> Self {
        Pbr { alpha, ..self }
    }

    /// This surface, thin-walled.
    pub fn thin_walled(self, thin: bool) -> Self {
        Pbr { thin, ..self }
    }

    /// This surface with `KHR_materials_diffuse_transmission`'s share and colour (see above).
    pub fn with_diffuse_transmission(self, share: f32, color: Vec3) -> Self {
        Pbr {
            diffuse_transmission: share,
            diffuse_transmission_color: color,
            ..self
        }
    }

    /// This surface under `KHR_materials_iridescence`'s thin film (weight, index, thickness in nm).
    pub fn with_iridescence(self, weight: f32, film_ior: f32, thickness: f32) -> Self {
        Pbr {
            iridescence: weight,
            film_ior,
            film_thickness: thickness,
            ..self
        }
    }

    /// The conductor's Fresnel at `cos`, under the film if there is one.
    fn metal_fresnel(&self, cos: f32) -> Vec3 {
        let f = fresnel_schlick(self.base, cos);
        if self.iridescence > 0.0 {
            let film = thin_film_fresnel(cos, self.film_ior, self.film_thickness, self.base);
            f.lerp(film, self.iridescence)
        } else {
            f
        }
    }

    /// This surface with its transmissive part compensated for multiple scattering, `albedo` being
    /// that part's single-scattering directional albedo at ωo (see above).
    pub fn with_glass_energy(self, albedo: f32) -> Self {
        Pbr {
            k_glass: 1.0 / albedo.max(0.1),
            ..self
        }
    }

    fn q_diffuse(&self) -> f32 {
        (1.0 - self.q_reflect - self.q_glass).max(0.0)
    }

    fn fresnel(&self, cos: f32) -> Vec3 {
        let f = fresnel_specular(cos, self.eta, self.f0, self.f90);
        // The film lies on the outside (a thin sheet has two outsides).
        if self.iridescence > 0.0 && self.eta >= 1.0 {
            let film = thin_film_fresnel(cos, self.film_ior, self.film_thickness, self.f0);
            f.lerp(film, self.iridescence)
        } else {
            f
        }
    }

    /// f · |cosθi| and the pdf of `sample` at `wi`.
    pub fn eval(&self, wo: Vec3, wi: Vec3) -> (Vec3, f32) {
        let (m, t, a) = (self.metallic, self.transmission, self.alpha);
        if wo.z <= 0.0 {
            return (Vec3::ZERO, 0.0);
        }
        if wi.z > 0.0 {
            let h = (wo + wi).normalize_or_zero();
            let woh = wo.dot(h);
            if woh <= 0.0 {
                return (Vec3::ZERO, 0.0);
            }
            let d = ggx_d(h, a);
            let spec_cos = d * ggx_g2(wo, wi, a) / (4.0 * wo.z);
            let pdf_reflect = ggx_g1(wo, a) * d / (4.0 * wo.z);
            let f_metal = self.metal_fresnel(woh) * self.ms;
            let f_d = self.fresnel(woh);
            let f_g = glass_fresnel(f_d, self.thin);
            let diffuse = self.base * (wi.z * std::f32::consts::FRAC_1_PI);
            let layer = (1.0 - t) * f_d + (t * self.k_glass) * f_g;
            let kept = 1.0 - self.diffuse_transmission;
            let f = f_metal * (m * spec_cos)
                + (layer * spec_cos + diffuse * ((1.0 - t) * kept) * (Vec3::ONE - f_d)) * (1.0 - m);
            let pdf = self.q_reflect * pdf_reflect
                + self.q_glass * pdf_reflect * mean(f_g)
                + self.q_diffuse() * kept * wi.z * std::f32::consts::FRAC_1_PI;
            return (f, pdf);
        }
        if wi.z == 0.0 {
            return (Vec3::ZERO, 0.0);
        }
        let (f, pdf) = self.eval_glass(wo, wi);
        let d = self.diffuse_transmission;
        if d <= 0.0 {
            return (f, pdf);
        }
        let c = -wi.z * std::f32::consts::FRAC_1_PI;
        let through = self.diffuse_transmission_color
            * (Vec3::ONE - self.fresnel(wo.z))
            * ((1.0 - m) * (1.0 - t) * d * c);
        (f + through, pdf + self.q_diffuse() * d * c)
    }

    /// The transmissive part's f · |cosθi| and pdf for `wi` below the surface.
    fn eval_glass(&self, wo: Vec3, wi: Vec3) -> (Vec3, f32) {
        let (m, t, a) = (self.metallic, self.transmission, self.alpha);
        if self.q_glass <= 0.0 {
            return (Vec3::ZERO, 0.0);
        }
        if self.thin {
            let mirrored = Vec3::new(wi.x, wi.y, -wi.z);
            let h = (wo + mirrored).normalize_or_zero();
            let woh = wo.dot(h);
            if woh <= 0.0 {
                return (Vec3::ZERO, 0.0);
            }
            let d = ggx_d(h, a);
            let t_g = Vec3::ONE - glass_fresnel(self.fresnel(woh), true);
            let spec_cos = d * ggx_g2(wo, mirrored, a) / (4.0 * wo.z);
            let pdf = self.q_glass * ggx_g1(wo, a) * d / (4.0 * wo.z) * mean(t_g);
            return (
                self.base * t_g * ((1.0 - m) * t * self.k_glass * spec_cos),
                pdf,
            );
        }
        let mut h = (wo + wi * self.eta).normalize_or_zero();
        if h.z < 0.0 {
            h = -h;
        }
        let (woh, wih) = (wo.dot(h), wi.dot(h));
        if !(woh > 0.0 && wih < 0.0) {
            return (Vec3::ZERO, 0.0);
        }
        let t_d = Vec3::ONE - self.fresnel(woh);
        let sqrt_denom = wih + woh / self.eta;
        let denom = sqrt_denom * sqrt_denom;
        let d = ggx_d(h, a);
        let ft_cos =
            d * ggx_g2(wo, wi, a) * (wih * woh).abs() / (wo.z * denom * self.eta * self.eta);
        let pdf = self.q_glass * vndf_pdf(wo, h, a) * mean(t_d) * wih.abs() / denom;
        (
            self.base * t_d * ((1.0 - m) * t * self.k_glass * ft_cos),
            pdf,
        )
    }

    /// The direction `sample` draws for three uniform numbers, or `None` where it draws none.
    pub fn sample_direction(&self, wo: Vec3, u_lobe: f32, u1: f32, u2: f32) -> Option<Vec3> {
        // A reflection below the horizon or a refraction above it is no sample (`eval` would read
        // it as the other event, whose density it does not have).
        if u_lobe < self.q_reflect + self.q_glass {
            let m = sample_vndf(wo, self.alpha, u1, u2);
            let reflects = u_lobe < self.q_reflect
                || (u_lobe - self.q_reflect)
                    < mean(glass_fresnel(self.fresnel(wo.dot(m)), self.thin)) * self.q_glass;
            if reflects || self.thin {
                let wi = 2.0 * wo.dot(m) * m - wo;
                if wi.z <= 0.0 {
                    return None;
                }
                return Some(if reflects {
                    wi
                } else {
                    Vec3::new(wi.x, wi.y, -wi.z)
                });
            }
            let wi = refract(-wo, m, self.eta);
            return (wi.z < 0.0).then_some(wi);
        }
        let r = u1.sqrt();
        let phi = std::f32::consts::TAU * u2;
        let z = (1.0 - u1).max(0.0).sqrt();
        // The diffuse lobe's transmitted share goes below, with what is left of u_lobe.
        let u = (u_lobe - self.q_reflect - self.q_glass) / self.q_diffuse();
        let below = u >= 1.0 - self.diffuse_transmission;
        Some(Vec3::new(
            r * phi.cos(),
            r * phi.sin(),
            if below { -z } else { z },
        ))
    }

    /// A direction for three uniform numbers, or `None` where the sample carries nothing.
    pub fn sample(&self, wo: Vec3, u_lobe: f32, u1: f32, u2: f32) -> Option<BsdfSample> {
        let wi = self.sample_direction(wo, u_lobe, u1, u2)?;
        let (f, pdf) = self.eval(wo, wi);
        let weight = f / pdf;
        (pdf > 0.0 && weight.is_finite()).then_some(BsdfSample { wi, weight, pdf })
    }
}

#[cfg(test)]
mod tests;
