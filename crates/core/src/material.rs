//! Surface materials of the scene model. Each variant documents the BSDF the kernel implements.

use serde::{Deserialize, Serialize};

/// Linear RGB, each channel usually in [0, 1] for reflectances.
pub type Rgb = [f32; 3];

/// How a surface scatters or emits light.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(tag = "type", rename_all = "snake_case")]
pub enum Material {
    /// Ideal diffuse reflection: f = albedo / π, sampled with a cosine-weighted hemisphere so the
    /// estimator weight f·cosθ/pdf is exactly `albedo`. A texture, when present, replaces `albedo`.
    Lambertian { albedo: Rgb, texture: Option<usize> },
    /// Shirley-style metal: mirror reflection about the shading normal, perturbed by a random point in
    /// the unit ball scaled by `fuzz` ∈ [0, 1]; weight `albedo`. Fuzz 0 is a perfect tinted mirror.
    Metal { albedo: Rgb, fuzz: f32 },
    /// Smooth dielectric with exact unpolarised Fresnel reflectance
    /// F = ½(r∥² + r⊥²), r∥ = (η cosθi − cosθt)/(η cosθi + cosθt), r⊥ = (cosθi − η cosθt)/(cosθi + η cosθt),
    /// reflection chosen with probability F (weight 1), refraction with 1 − F (weight `tint`/η²,
    /// the radiance scaling across the interface). Total internal reflection when sin²θt ≥ 1.
    Dielectric { ior: f32, tint: Rgb },
    /// Area emitter radiating `color × intensity` from its front face only (counter-clockwise winding);
    /// it reflects nothing.
    Emissive { color: Rgb, intensity: f32 },
}

impl Material {
    pub fn lambertian(albedo: Rgb) -> Self {
        Material::Lambertian {
            albedo,
            texture: None,
        }
    }

    /// A short name of the model, for listings.
    pub fn kind_name(&self) -> &'static str {
        match self {
            Material::Lambertian {
                texture: Some(_), ..
            } => "lambertian (textured)",
            Material::Lambertian { .. } => "lambertian",
            Material::Metal { .. } => "metal",
            Material::Dielectric { .. } => "dielectric",
            Material::Emissive { .. } => "emissive",
        }
    }

    /// Checks parameters are finite and in range; `what` names the owner for the message.
    pub fn validate(&self, what: &str) -> Result<(), String> {
        let finite = |c: &Rgb| c.iter().all(|v| v.is_finite() && *v >= 0.0);
        let ok = match self {
            Material::Lambertian { albedo, .. } => finite(albedo),
            Material::Metal { albedo, fuzz } => finite(albedo) && (0.0..=1.0).contains(fuzz),
            Material::Dielectric { ior, tint } => finite(tint) && ior.is_finite() && *ior > 0.0,
            Material::Emissive { color, intensity } => {
                finite(color) && intensity.is_finite() && *intensity >= 0.0
            }
        };
        if ok {
            Ok(())
        } else {
            Err(format!(
                "{what}: material parameters out of range: {self:?}"
            ))
        }
    }
}
