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
    /// The glTF 2.0 metallic-roughness model (`math::bsdf` has its equation): a GGX conductor
    /// (`metallic`) over a dielectric with index `ior` whose base is diffuse or, with
    /// `transmission`, a rough refracting interface into a medium absorbing per unit length
    /// σ = −ln(attenuation_color) / attenuation_distance (Beer–Lambert; none without a distance).
    /// `texture` multiplies `base_color`; `emission × emission_strength` is added on top from the
    /// front face, times `emission_texture`. `alpha_mode` cuts holes by the base colour's alpha.
    /// Roughness, metallic, transmission and alpha must lie in [0, 1].
    Pbr(Box<Pbr>),
}

/// The parameters of `Material::Pbr` (boxed to keep `Material` small).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default)]
pub struct Pbr {
    pub base_color: Rgb,
    pub texture: Option<usize>,
    /// glTF's metallic-roughness image (linear): blue scales `metallic`, green `roughness`.
    pub metallic_roughness_texture: Option<usize>,
    /// A tangent-space normal map (linear, +Y up, glTF's convention); needs normals and UVs.
    pub normal_texture: Option<usize>,
    /// Scales the normal map's x and y.
    pub normal_scale: f32,
    pub metallic: f32,
    pub roughness: f32,
    pub ior: f32,
    pub transmission: f32,
    /// Transmission through a thin sheet (no volume behind the surface; light passes without
    /// bending), as glTF's transmission without `KHR_materials_volume`.
    pub thin_walled: bool,
    pub attenuation_color: Rgb,
    /// `None`: no absorption.
    pub attenuation_distance: Option<f32>,
    pub emission: Rgb,
    pub emission_strength: f32,
    /// An sRGB image multiplying `emission` (glTF's emissive texture).
    pub emission_texture: Option<usize>,
    /// How the coverage α = `alpha` × the base colour texture's alpha cuts the surface.
    pub alpha_mode: AlphaMode,
    /// The base colour factor's alpha, in [0, 1].
    pub alpha: f32,
    /// `AlphaMode::Mask`: coverage below this is a hole (glTF's default 0.5).
    pub alpha_cutoff: f32,
    /// `KHR_materials_specular`'s strength in [0, 1]: scales the dielectric reflectance at normal
    /// (F0) and grazing (F90) incidence; 1 keeps the exact Fresnel of `ior`.
    pub specular: f32,
    /// `KHR_materials_specular`'s colour: F0 becomes min(F0(ior) · colour, 1) · `specular`.
    pub specular_color: Rgb,
    /// `KHR_materials_clearcoat`'s weight in [0, 1]: a smooth-to-rough GGX dielectric coat (IOR 1.5)
    /// over the whole material (`math::coat`).
    pub clearcoat: f32,
    /// The coat's roughness in [0, 1] (α = roughness²).
    pub clearcoat_roughness: f32,
    /// `KHR_materials_sheen`'s colour, each channel in [0, 1]: a Charlie-distribution sheen layer
    /// between the coat and the base (`math::sheen`); black is no sheen.
    pub sheen_color: Rgb,
    /// The sheen's roughness in [0, 1] (α = roughness²).
    pub sheen_roughness: f32,
    /// An image whose red channel (linear) multiplies `clearcoat`.
    pub clearcoat_texture: Option<usize>,
    /// An image whose green channel (linear) multiplies `clearcoat_roughness`.
    pub clearcoat_roughness_texture: Option<usize>,
    /// An sRGB image multiplying `sheen_color`.
    pub sheen_color_texture: Option<usize>,
    /// An image whose alpha multiplies `sheen_roughness`.
    pub sheen_roughness_texture: Option<usize>,
    /// An image whose alpha multiplies `specular`.
    pub specular_texture: Option<usize>,
    /// An sRGB image multiplying `specular_color`.
    pub specular_color_texture: Option<usize>,
    /// The clear coat's own tangent-space normal map (as `normal_texture`); without one the coat
    /// follows the interpolated normal, not the base's normal map (glTF's rule).
    pub clearcoat_normal_texture: Option<usize>,
    /// Scales the coat's normal map's x and y.
    pub clearcoat_normal_scale: f32,
    /// `KHR_materials_diffuse_transmission`'s factor in [0, 1]: the share of the diffuse lobe that
    /// leaves through the other side, cosine-distributed (leaves, paper, lampshades).
    pub diffuse_transmission: f32,
    /// The colour of the diffusely transmitted light (each channel ≥ 0).
    pub diffuse_transmission_color: Rgb,
    /// `KHR_materials_iridescence`'s weight in [0, 1]: a thin film over the surface whose
    /// interference colours its reflection (soap bubbles, oil, anodised metal).
    pub iridescence: f32,
    /// The film's index of refraction (≥ 1; glTF's default 1.3).
    pub iridescence_ior: f32,
    /// The film's thickness range in nanometres (glTF's defaults 100 and 400); without an image
    /// the film is `iridescence_thickness_max` thick.
    pub iridescence_thickness_min: f32,
    pub iridescence_thickness_max: f32,
    /// `KHR_materials_anisotropy`'s strength in [0, 1]: the highlight stretches along the direction
    /// of anisotropy, its GGX width there growing from α to 1 as strength² (brushed metal).
    /// Needs the mesh's tangents (normals and UVs).
    pub anisotropy: f32,
    /// The direction of anisotropy in radians, counter-clockwise from the mesh's tangent.
    pub anisotropy_rotation: f32,
    /// An image whose red and green (linear) give the direction in the tangent frame (2c − 1, then
    /// rotated by `anisotropy_rotation`) and whose blue multiplies `anisotropy`.
    pub anisotropy_texture: Option<usize>,
    /// `KHR_materials_dispersion`: 20 / V_d (V_d the Abbe number; 0: none, glass ~0.3, diamond
    /// ~0.9): a transmissive volume's index varies with the wavelength (`math::dispersion`).
    pub dispersion: f32,
    /// An image whose alpha multiplies `diffuse_transmission`.
    pub diffuse_transmission_texture: Option<usize>,
    /// An sRGB image multiplying `diffuse_transmission_color`.
    pub diffuse_transmission_color_texture: Option<usize>,
    /// An image whose red multiplies `iridescence`.
    pub iridescence_texture: Option<usize>,
    /// An image whose green picks the film's thickness, from `iridescence_thickness_min` (0) to
    /// `iridescence_thickness_max` (1).
    pub iridescence_thickness_texture: Option<usize>,
    /// Scattering in the volume behind a transmissive, non-thin surface (the draft
    /// `KHR_materials_volume_scatter`'s `multiscatterColor`, each channel in [0, 1]): the colour a
    /// thick piece of it takes after scattering many times (milk, jade, wax). The attenuation
    /// gives the extinction σ_t; this gives the single-scattering albedo ρ by the inversion of
    /// `math::medium::single_scatter_albedo`, σ_s = ρ σ_t. Black: absorption only.
    pub multiscatter_color: Rgb,
    /// The Henyey–Greenstein anisotropy g of that scattering (and of `subsurface`'s), in (−1, 1):
    /// > 0 forward.
    pub scatter_anisotropy: f32,
    /// Subsurface scattering's weight in [0, 1] (Blender's Subsurface Weight): that share of the
    /// surface lets light through its dielectric boundary (`ior`, `roughness`) into a scattering
    /// volume whose colour after many scatterings is the base colour factor and whose mean free
    /// path is `subsurface_radius` (a random walk, as Cycles'). It takes the place of the volume
    /// the attenuation and `multiscatter_color` describe. The surface itself is then white where
    /// the weight is 1 (the colour comes from inside), the base colour where it is 0, mixed
    /// between; a base colour image tints the surface only. Needs a closed mesh.
    pub subsurface: f32,
    /// How far light travels inside between scatterings, per channel, in scene units (Blender's
    /// Radius × Scale; skin scatters red farthest), each > 0.
    pub subsurface_radius: Rgb,
}

/// glTF's alpha modes: how a surface's coverage α (base colour alpha) cuts it.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum AlphaMode {
    /// α is ignored.
    #[default]
    Opaque,
    /// A hole where α < `alpha_cutoff`, solid elsewhere (leaves, fences, decals).
    Mask,
    /// Partly transparent: a ray stops with probability α and passes straight through otherwise
    /// (stochastic transparency; it converges to α-blending the surface over what lies behind).
    Blend,
}

impl Default for Pbr {
    fn default() -> Self {
        Pbr {
            base_color: [0.8; 3],
            texture: None,
            metallic_roughness_texture: None,
            normal_texture: None,
            normal_scale: 1.0,
            metallic: 0.0,
            roughness: 0.5,
            ior: 1.5,
            transmission: 0.0,
            thin_walled: false,
            attenuation_color: [1.0; 3],
            attenuation_distance: None,
            emission: [0.0; 3],
            emission_strength: 1.0,
            emission_texture: None,
            alpha_mode: AlphaMode::Opaque,
            alpha: 1.0,
            alpha_cutoff: 0.5,
            specular: 1.0,
            specular_color: [1.0; 3],
            clearcoat: 0.0,
            clearcoat_roughness: 0.0,
            sheen_color: [0.0; 3],
            sheen_roughness: 0.0,
            clearcoat_texture: None,
            clearcoat_roughness_texture: None,
            sheen_color_texture: None,
            sheen_roughness_texture: None,
            specular_texture: None,
            specular_color_texture: None,
            clearcoat_normal_texture: None,
            clearcoat_normal_scale: 1.0,
            diffuse_transmission: 0.0,
            diffuse_transmission_color: [1.0; 3],
            iridescence: 0.0,
            iridescence_ior: 1.3,
            iridescence_thickness_min: 100.0,
            iridescence_thickness_max: 400.0,
            anisotropy: 0.0,
            anisotropy_rotation: 0.0,
            anisotropy_texture: None,
            dispersion: 0.0,
            diffuse_transmission_texture: None,
            diffuse_transmission_color_texture: None,
            iridescence_texture: None,
            iridescence_thickness_texture: None,
            multiscatter_color: [0.0; 3],
            scatter_anisotropy: 0.0,
            subsurface: 0.0,
            // Blender's default radius (1, 0.2, 0.1) × its default scale 0.05 (metres).
            subsurface_radius: [0.05, 0.01, 0.005],
        }
    }
}

impl Pbr {
    /// Every texture slot with its name, for index checks.
    pub fn textures(&self) -> [(&'static str, Option<usize>); 16] {
        [
            ("texture", self.texture),
            (
                "metallic_roughness_texture",
                self.metallic_roughness_texture,
            ),
            ("normal_texture", self.normal_texture),
            ("emission_texture", self.emission_texture),
            ("clearcoat_texture", self.clearcoat_texture),
            (
                "clearcoat_roughness_texture",
                self.clearcoat_roughness_texture,
            ),
            ("sheen_color_texture", self.sheen_color_texture),
            ("sheen_roughness_texture", self.sheen_roughness_texture),
            ("specular_texture", self.specular_texture),
            ("specular_color_texture", self.specular_color_texture),
            ("clearcoat_normal_texture", self.clearcoat_normal_texture),
            ("anisotropy_texture", self.anisotropy_texture),
            (
                "diffuse_transmission_texture",
                self.diffuse_transmission_texture,
            ),
            (
                "diffuse_transmission_color_texture",
                self.diffuse_transmission_color_texture,
            ),
            ("iridescence_texture", self.iridescence_texture),
            (
                "iridescence_thickness_texture",
                self.iridescence_thickness_texture,
            ),
        ]
    }

    /// The volume's extinction σ_t = −ln(c)/d per channel (0 without attenuation).
    pub fn extinction(&self) -> Rgb {
        match self.attenuation_distance {
            Some(d) if d > 0.0 => self
                .attenuation_color
                .map(|c| -(c.clamp(1e-6, 1.0)).ln() / d),
            _ => [0.0; 3],
        }
    }
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
            Material::Pbr(p) if p.transmission > 0.0 => "pbr (transmissive)",
            Material::Pbr(p) if p.metallic > 0.0 => "pbr (metallic)",
            Material::Pbr(_) => "pbr",
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
            Material::Pbr(p) => return p.validate(what),
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

impl Pbr {
    /// Names the first parameter out of range.
    pub fn validate(&self, what: &str) -> Result<(), String> {
        let unit = |name: &str, v: f32| {
            if (0.0..=1.0).contains(&v) {
                Ok(())
            } else {
                Err(format!("{what}: pbr {name} must lie in [0, 1], got {v}"))
            }
        };
        let colour = |name: &str, c: &Rgb| {
            if c.iter().all(|v| v.is_finite() && *v >= 0.0) {
                Ok(())
            } else {
                Err(format!(
                    "{what}: pbr {name} must be finite and >= 0, got {c:?}"
                ))
            }
        };
        unit("metallic", self.metallic)?;
        unit("roughness", self.roughness)?;
        unit("transmission", self.transmission)?;
        unit("alpha", self.alpha)?;
        unit("specular", self.specular)?;
        unit("clearcoat", self.clearcoat)?;
        unit("clearcoat_roughness", self.clearcoat_roughness)?;
        unit("sheen_roughness", self.sheen_roughness)?;
        unit("diffuse_transmission", self.diffuse_transmission)?;
        unit("iridescence", self.iridescence)?;
        unit("anisotropy", self.anisotropy)?;
        // `note` says what the number means.
        let nonnegative = |name: &str, v: f32, note: &str| {
            if v.is_finite() && v >= 0.0 {
                Ok(())
            } else {
                Err(format!(
                    "{what}: pbr {name} must be finite and >= 0{note}, got {v}"
                ))
            }
        };
        nonnegative("dispersion", self.dispersion, " (20 / Abbe number)")?;
        if !self.anisotropy_rotation.is_finite() {
            return Err(format!(
                "{what}: pbr anisotropy_rotation must be finite (radians), got {}",
                self.anisotropy_rotation
            ));
        }
        if !(self.iridescence_ior.is_finite() && self.iridescence_ior >= 1.0) {
            return Err(format!(
                "{what}: pbr iridescence_ior must be >= 1, got {}",
                self.iridescence_ior
            ));
        }
        for (name, d) in [
            ("iridescence_thickness_min", self.iridescence_thickness_min),
            ("iridescence_thickness_max", self.iridescence_thickness_max),
        ] {
            nonnegative(name, d, " (nanometres)")?;
        }
        for c in self.sheen_color {
            unit("sheen_color", c)?;
        }
        for c in self.multiscatter_color {
            unit("multiscatter_color", c)?;
        }
        unit("subsurface", self.subsurface)?;
        if !self
            .subsurface_radius
            .iter()
            .all(|r| r.is_finite() && *r > 0.0)
        {
            return Err(format!(
                "{what}: pbr subsurface_radius must be finite and > 0 per channel (scene units), \
                 got {:?}",
                self.subsurface_radius
            ));
        }
        if self.scatter_anisotropy.is_nan() || self.scatter_anisotropy.abs() >= 1.0 {
            return Err(format!(
                "{what}: pbr scatter_anisotropy must lie in (-1, 1), got {}",
                self.scatter_anisotropy
            ));
        }
        if !self.alpha_cutoff.is_finite() {
            return Err(format!(
                "{what}: pbr alpha_cutoff must be finite, got {}",
                self.alpha_cutoff
            ));
        }
        colour("base_color", &self.base_color)?;
        colour("attenuation_color", &self.attenuation_color)?;
        colour("emission", &self.emission)?;
        colour("specular_color", &self.specular_color)?;
        colour(
            "diffuse_transmission_color",
            &self.diffuse_transmission_color,
        )?;
        if !(self.ior.is_finite() && self.ior >= 1.0) {
            return Err(format!("{what}: pbr ior must be >= 1, got {}", self.ior));
        }
        if !self.clearcoat_normal_scale.is_finite() {
            return Err(format!(
                "{what}: pbr clearcoat_normal_scale must be finite, got {}",
                self.clearcoat_normal_scale
            ));
        }
        if !self.normal_scale.is_finite() {
            return Err(format!(
                "{what}: pbr normal_scale must be finite, got {}",
                self.normal_scale
            ));
        }
        nonnegative("emission_strength", self.emission_strength, "")?;
        if let Some(d) = self.attenuation_distance
            && !(d.is_finite() && d > 0.0)
        {
            return Err(format!(
                "{what}: pbr attenuation_distance must be positive, got {d}"
            ));
        }
        Ok(())
    }
}
