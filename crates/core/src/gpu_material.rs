//! Packing a scene's materials for the GPU: each object's `gpu_types::Material`, its texture slots
//! resolved against the texel array, and the tangents a normal map needs.

use crate::error::{Error, Result};
use crate::gpu_types::{
    self, DielectricLobe, MetalLobe, PbrLobe, SLOT_ANISOTROPY, SLOT_BASE, SLOT_CLEARCOAT,
    SLOT_CLEARCOAT_NORMAL, SLOT_CLEARCOAT_ROUGHNESS, SLOT_DIFFUSE_TRANSMISSION,
    SLOT_DIFFUSE_TRANSMISSION_COLOR, SLOT_EMISSION, SLOT_IRIDESCENCE, SLOT_IRIDESCENCE_THICKNESS,
    SLOT_METALLIC_ROUGHNESS, SLOT_NORMAL, SLOT_SHEEN_COLOR, SLOT_SHEEN_ROUGHNESS, SLOT_SPECULAR,
    SLOT_SPECULAR_COLOR, TextureSlot,
};
use crate::material::{AlphaMode, Material};
use crate::scene::Scene;
use crate::scene_features::SceneFeatures;

/// An object's GPU material (texture slots resolved against `texture_offsets`) and, with a normal
/// map, its MikkTSpace tangents (three per triangle, in the mesh's order); notes the features it
/// uses in `features`.
pub(crate) fn object_material(
    scene: &Scene,
    object: &crate::Object,
    texture_offsets: &[u32],
    features: &mut SceneFeatures,
) -> Result<(gpu_types::Material, Option<Vec<[f32; 4]>>)> {
    let mesh = &object.mesh;
    let label = || format!("object '{}'", object.name);
    object.material.validate(&label()).map_err(Error::Scene)?;
    let mut material = gpu_material(&object.material);
    if object.shadow_catcher {
        material.flags |= gpu_types::SHADOW_CATCHER;
    }
    let texture = match &object.material {
        Material::Lambertian { texture, .. } => *texture,
        Material::Pbr(p) => p.texture,
        _ => None,
    };
    if let Some(t) = texture {
        let texture = scene.textures.get(t).ok_or_else(|| {
            Error::Scene(format!("{}: texture index {t} does not exist", label()))
        })?;
        if mesh.uvs.is_some() {
            material.textures[SLOT_BASE as usize] = TextureSlot {
                offset: texture_offsets[t],
                width: texture.width,
                height: texture.height,
            };
            material.set_sampler_bits(SLOT_BASE, texture.sampler.bits());
            features.textures = true;
        } else {
            log::warn!("{} has a texture but no UVs: rendering it white", label());
            material.color = [1.0; 3];
        }
    }
    let tangents = match &object.material {
        Material::Pbr(p) => {
            let tangents = pbr_slots(scene, object, p, texture_offsets, &mut material, features)?;
            pbr_coverage(p, &mut material, features);
            tangents
        }
        _ => None,
    };
    features.kinds.insert(object.material.kind());
    features.media |= !crate::math::medium::is_vacuum(&material.medium);
    Ok((material, tangents))
}

/// A PBR material's texture slots past the base colour (each resolved against
/// `texture_offsets`, ignored without UVs) and, where a normal map or anisotropy needs them, the
/// mesh's MikkTSpace tangents.
fn pbr_slots(
    scene: &Scene,
    object: &crate::Object,
    p: &crate::material::Pbr,
    texture_offsets: &[u32],
    material: &mut gpu_types::Material,
    features: &mut SceneFeatures,
) -> Result<Option<Vec<[f32; 4]>>> {
    let mesh = &object.mesh;
    let label = || format!("object '{}'", object.name);
    let mut tangents = None;
    let slot = |t: Option<usize>, name: &str| -> Result<Option<usize>> {
        match t {
            Some(t) if t >= scene.textures.len() => Err(Error::Scene(format!(
                "{}: {name} {t} does not exist",
                label()
            ))),
            Some(_) if mesh.uvs.is_none() => {
                log::warn!("{} has a {name} but no UVs: ignoring it", label());
                Ok(None)
            }
            other => Ok(other),
        }
    };
    // Puts texture `t` into `slot`, with its sampler.
    let mut bind = |t: usize, slot: u32, material: &mut gpu_types::Material| {
        let texture = &scene.textures[t];
        material.set_sampler_bits(slot, texture.sampler.bits());
        material.textures[slot as usize] = TextureSlot {
            offset: texture_offsets[t],
            width: texture.width,
            height: texture.height,
        };
        features.textures = true;
    };
    if let Some(t) = slot(p.metallic_roughness_texture, "metallic-roughness texture")? {
        bind(t, SLOT_METALLIC_ROUGHNESS, material);
    }
    for (t, name, gpu_slot) in [
        (p.emission_texture, "emission texture", SLOT_EMISSION),
        (p.clearcoat_texture, "clear coat texture", SLOT_CLEARCOAT),
        (
            p.clearcoat_roughness_texture,
            "clear coat roughness texture",
            SLOT_CLEARCOAT_ROUGHNESS,
        ),
        (
            p.sheen_color_texture,
            "sheen colour texture",
            SLOT_SHEEN_COLOR,
        ),
        (
            p.sheen_roughness_texture,
            "sheen roughness texture",
            SLOT_SHEEN_ROUGHNESS,
        ),
        (p.specular_texture, "specular texture", SLOT_SPECULAR),
        (
            p.specular_color_texture,
            "specular colour texture",
            SLOT_SPECULAR_COLOR,
        ),
        (p.anisotropy_texture, "anisotropy texture", SLOT_ANISOTROPY),
        (
            p.diffuse_transmission_texture,
            "diffuse transmission texture",
            SLOT_DIFFUSE_TRANSMISSION,
        ),
        (
            p.diffuse_transmission_color_texture,
            "diffuse transmission colour texture",
            SLOT_DIFFUSE_TRANSMISSION_COLOR,
        ),
        (
            p.iridescence_texture,
            "iridescence texture",
            SLOT_IRIDESCENCE,
        ),
        (
            p.iridescence_thickness_texture,
            "iridescence thickness texture",
            SLOT_IRIDESCENCE_THICKNESS,
        ),
    ] {
        if let Some(t) = slot(t, name)? {
            bind(t, gpu_slot, material);
        }
    }
    for (t, name, gpu_slot) in [
        (p.normal_texture, "normal texture", SLOT_NORMAL),
        (
            p.clearcoat_normal_texture,
            "clear coat normal texture",
            SLOT_CLEARCOAT_NORMAL,
        ),
    ] {
        let Some(t) = slot(t, name)? else { continue };
        if tangents.is_none() {
            tangents = crate::tangents::mikktspace_tangents(mesh);
        }
        if tangents.is_some() {
            bind(t, gpu_slot, material);
            features.normal_maps = true;
        } else {
            log::warn!(
                "{}: no tangents (it needs normals and UVs): ignoring its {name}",
                label()
            );
        }
    }
    // The direction of anisotropy is given in the tangent frame.
    if p.anisotropy > 0.0 && tangents.is_none() {
        tangents = crate::tangents::mikktspace_tangents(mesh);
        if tangents.is_none() {
            log::warn!(
                "{}: no tangents (it needs normals and UVs): its anisotropy follows an \
                     arbitrary direction",
                label()
            );
        }
    }
    if tangents.is_some() {
        material.flags |= gpu_types::TANGENTS;
        features.normal_maps = true;
    }
    Ok(tangents)
}

/// Whether a PBR material cuts holes (alpha mask or blend), in its flags.
fn pbr_coverage(
    p: &crate::material::Pbr,
    material: &mut gpu_types::Material,
    features: &mut SceneFeatures,
) {
    // Coverage comes from the factor and the base colour texture: without UVs only the factor.
    let base_textured = !material.texture(SLOT_BASE).is_empty();
    let cuts = match p.alpha_mode {
        AlphaMode::Opaque => false,
        AlphaMode::Mask => base_textured || p.alpha < p.alpha_cutoff,
        AlphaMode::Blend => base_textured || p.alpha < 1.0,
    };
    if cuts {
        material.flags |= match p.alpha_mode {
            AlphaMode::Mask => gpu_types::ALPHA_MASK,
            _ => gpu_types::ALPHA_BLEND,
        };
        features.alpha = true;
    }
}

fn gpu_material(material: &Material) -> gpu_types::Material {
    let mut gpu = gpu_types::Material {
        kind: material.kind().tag(),
        ..Default::default()
    };
    match *material {
        Material::Lambertian { albedo, .. } => gpu.color = albedo,
        Material::Metal { albedo, fuzz } => {
            gpu.color = albedo;
            gpu.set_lobe(MetalLobe { fuzz });
        }
        Material::Dielectric { ior, tint } => {
            gpu.color = tint;
            gpu.set_lobe(DielectricLobe { ior });
        }
        Material::Emissive { color, intensity } => gpu.emission = color.map(|c| c * intensity),
        Material::Pbr(ref p) => {
            gpu.color = p.base_color;
            let subsurface = if p.thin_walled { 0.0 } else { p.subsurface };
            if subsurface > 0.0 {
                // The colour moves from the surface into the volume (`Pbr::subsurface`).
                gpu.color = p.base_color.map(|c| c + (1.0 - c) * subsurface);
            }
            gpu.emission = p.emission.map(|c| c * p.emission_strength);
            gpu.alpha = p.alpha;
            gpu.alpha_cutoff = p.alpha_cutoff;
            if p.thin_walled {
                gpu.flags |= gpu_types::THIN_WALLED;
            }
            gpu.set_lobe(PbrLobe {
                metallic: p.metallic,
                roughness: p.roughness,
                transmission: p.transmission.max(subsurface),
                // At η = 1 exactly the BSDF's refraction half-vector vanishes (the light passes
                // unbent) and its samples were NaN: 1 + 10⁻⁴ passes it the same (F0 ~ 10⁻⁹).
                ior: p.ior.max(1.0 + 1e-4),
                _pad0: [0.0; 3],
                normal_scale: p.normal_scale,
                specular_color: p.specular_color,
                specular: p.specular,
                sheen_color: p.sheen_color,
                sheen_roughness: p.sheen_roughness,
                clearcoat: p.clearcoat,
                clearcoat_roughness: p.clearcoat_roughness,
                clearcoat_normal_scale: p.clearcoat_normal_scale,
                diffuse_transmission: p.diffuse_transmission,
                diffuse_transmission_color: p.diffuse_transmission_color,
                iridescence: p.iridescence,
                iridescence_ior: p.iridescence_ior,
                iridescence_thickness_min: p.iridescence_thickness_min,
                iridescence_thickness_max: p.iridescence_thickness_max,
                anisotropy: p.anisotropy,
                anisotropy_rotation: p.anisotropy_rotation,
                dispersion: p.dispersion,
                _pad: [0.0; 2],
            });
            if subsurface > 0.0 {
                gpu.medium = subsurface_medium(p);
            } else if !p.thin_walled {
                gpu.medium = interior_medium(p);
            }
        }
    }
    gpu
}

/// The densest medium a material packs into: a radius or distance near f32's smallest would make
/// σ_t infinite, and ρ·∞ NaN where a channel absorbs all (σ_s = 0·∞). Light crosses 10⁻³⁰ of a
/// unit before it meets such a medium: opaque at any scene scale.
const MAX_EXTINCTION: f32 = 1e30;

/// The medium inside a PBR volume: extinction from the attenuation, scattering from the
/// multiple-scattering colour (`Pbr::multiscatter_color`).
fn interior_medium(p: &crate::material::Pbr) -> gpu_types::Medium {
    scattering_medium(p.extinction(), p.multiscatter_color, p.scatter_anisotropy)
}

/// The volume under a subsurface-scattering surface: mean free path `subsurface_radius` (σ_t =
/// 1/radius per channel), looking like the base colour after many scatterings.
fn subsurface_medium(p: &crate::material::Pbr) -> gpu_types::Medium {
    scattering_medium(
        p.subsurface_radius.map(|r| 1.0 / r),
        p.base_color,
        p.scatter_anisotropy,
    )
}

/// A medium of extinction `sigma_t` (capped) that looks `colour` after many scatterings
/// (`math::medium::single_scatter_albedo`), with Henyey–Greenstein anisotropy `g`.
fn scattering_medium(sigma_t: [f32; 3], colour: [f32; 3], g: f32) -> gpu_types::Medium {
    let sigma_t = sigma_t.map(|s| s.min(MAX_EXTINCTION));
    let albedo = colour.map(crate::math::medium::single_scatter_albedo);
    gpu_types::Medium {
        sigma_t,
        anisotropy: g,
        sigma_s: std::array::from_fn(|c| albedo[c] * sigma_t[c]),
        _pad: 0.0,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::material::Pbr;

    /// A volume's medium from its attenuation and multiple-scattering colour, subsurface's from its
    /// radius and the base colour (which then leaves the surface), none behind a thin sheet.
    #[test]
    fn volumes_and_subsurface_become_media() {
        let volume = Pbr {
            transmission: 1.0,
            attenuation_color: [0.5, 0.25, 1.0],
            attenuation_distance: Some(2.0),
            multiscatter_color: [1.0, 0.0, 0.5],
            ..Pbr::default()
        };
        let m = gpu_material(&Material::Pbr(Box::new(volume.clone()))).medium;
        let ln2 = std::f32::consts::LN_2;
        assert_eq!(m.sigma_t, [ln2 / 2.0, ln2, 0.0]);
        assert_eq!(m.sigma_s[0], m.sigma_t[0], "white scatters all");
        assert_eq!(m.sigma_s[1], 0.0, "black absorbs only");
        let thin = Pbr {
            thin_walled: true,
            subsurface: 1.0,
            ..volume.clone()
        };
        assert_eq!(
            gpu_material(&Material::Pbr(Box::new(thin))).medium,
            gpu_types::Medium::default()
        );
        let skin = Pbr {
            base_color: [0.8, 0.5, 0.25],
            subsurface: 0.5,
            subsurface_radius: [0.5, 0.25, 0.125],
            ..volume
        };
        let g = gpu_material(&Material::Pbr(Box::new(skin)));
        assert_eq!(g.medium.sigma_t, [2.0, 4.0, 8.0]);
        let rho = crate::math::medium::single_scatter_albedo(0.8);
        assert!((g.medium.sigma_s[0] - 2.0 * rho).abs() < 1e-6);
        assert_eq!(g.color, [0.9, 0.75, 0.625]);
        assert_eq!(g.lobe_of::<PbrLobe>().transmission, 1.0);
        // A subnormal radius and a black channel: finite, not 0·∞.
        let extreme = Pbr {
            base_color: [0.0, 0.5, 1.0],
            subsurface: 1.0,
            subsurface_radius: [1e-40, 1.0, 1.0],
            ..Pbr::default()
        };
        let m = gpu_material(&Material::Pbr(Box::new(extreme))).medium;
        assert!(
            m.sigma_t.iter().chain(&m.sigma_s).all(|v| v.is_finite()),
            "{m:?}"
        );
        assert_eq!(m.sigma_s[0], 0.0);
    }
}
