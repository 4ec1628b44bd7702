//! Packing a scene's materials for the GPU: each object's `gpu_types::Material`, its texture slots
//! resolved against the texel array, and the tangents a normal map needs.

use crate::error::{Error, Result};
use crate::gpu_types::{self, NO_TEXTURE, material_kind};
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
            material.texture_offset = texture_offsets[t];
            material.texture_width = texture.width;
            material.texture_height = texture.height;
            material.samplers |= texture.sampler.bits() << gpu_types::SLOT_BASE;
            features.textures = true;
        } else {
            log::warn!("{} has a texture but no UVs: rendering it white", label());
            material.albedo = [1.0; 3];
        }
    }
    let mut tangents = None;
    if let Material::Pbr(p) = &object.material {
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
        // (offset, width, height) of a slot, its sampler in `samplers` at `shift`.
        let mut bind = |t: usize, shift: u32, samplers: &mut u32| {
            let texture = &scene.textures[t];
            *samplers |= texture.sampler.bits() << shift;
            features.textures = true;
            (texture_offsets[t], texture.width, texture.height)
        };
        let mut samplers = material.samplers;
        if let Some(t) = slot(p.metallic_roughness_texture, "metallic-roughness texture")? {
            (
                material.mr_texture_offset,
                material.mr_texture_width,
                material.mr_texture_height,
            ) = bind(t, gpu_types::SLOT_METALLIC_ROUGHNESS, &mut samplers);
        }
        if let Some(t) = slot(p.emission_texture, "emission texture")? {
            (
                material.emission_texture_offset,
                material.emission_texture_width,
                material.emission_texture_height,
            ) = bind(t, gpu_types::SLOT_EMISSION, &mut samplers);
        }
        if let Some(t) = slot(p.normal_texture, "normal texture")? {
            match crate::tangents::mikktspace_tangents(mesh) {
                Some(t_corners) => {
                    (
                        material.normal_texture_offset,
                        material.normal_texture_width,
                        material.normal_texture_height,
                    ) = bind(t, gpu_types::SLOT_NORMAL, &mut samplers);
                    tangents = Some(t_corners);
                    features.normal_maps = true;
                }
                None => log::warn!(
                    "{}: no tangents (it needs normals and UVs): ignoring its normal map",
                    label()
                ),
            }
        }
        material.samplers = samplers;
        // Coverage comes from the factor and the base colour texture: without UVs only the factor.
        let cuts = match p.alpha_mode {
            AlphaMode::Opaque => false,
            AlphaMode::Mask => material.texture_offset != NO_TEXTURE || p.alpha < p.alpha_cutoff,
            AlphaMode::Blend => material.texture_offset != NO_TEXTURE || p.alpha < 1.0,
        };
        if cuts {
            material.flags |= match p.alpha_mode {
                AlphaMode::Mask => gpu_types::ALPHA_MASK,
                _ => gpu_types::ALPHA_BLEND,
            };
            features.alpha = true;
        }
    }
    features.metal |= material.kind == material_kind::METAL;
    features.dielectric |= material.kind == material_kind::DIELECTRIC;
    features.pbr |= material.kind == material_kind::PBR;
    Ok((material, tangents))
}

fn gpu_material(material: &Material) -> gpu_types::Material {
    let base = gpu_types::Material {
        texture_offset: NO_TEXTURE,
        mr_texture_offset: NO_TEXTURE,
        normal_texture_offset: NO_TEXTURE,
        emission_texture_offset: NO_TEXTURE,
        alpha: 1.0,
        ..Default::default()
    };
    match *material {
        Material::Lambertian { albedo, .. } => gpu_types::Material {
            albedo,
            kind: material_kind::LAMBERTIAN,
            ..base
        },
        Material::Metal { albedo, fuzz } => gpu_types::Material {
            albedo,
            kind: material_kind::METAL,
            param: fuzz,
            ..base
        },
        Material::Dielectric { ior, tint } => gpu_types::Material {
            albedo: tint,
            kind: material_kind::DIELECTRIC,
            param: ior,
            ..base
        },
        Material::Emissive { color, intensity } => gpu_types::Material {
            kind: material_kind::EMISSIVE,
            emission: color.map(|c| c * intensity),
            ..base
        },
        Material::Pbr(ref p) => gpu_types::Material {
            normal_scale: p.normal_scale,
            albedo: p.base_color,
            kind: material_kind::PBR,
            emission: p.emission.map(|c| c * p.emission_strength),
            param: p.ior,
            absorption: p.absorption(),
            metallic: p.metallic,
            roughness: p.roughness,
            transmission: p.transmission,
            alpha: p.alpha,
            alpha_cutoff: p.alpha_cutoff,
            flags: if p.thin_walled {
                gpu_types::THIN_WALLED
            } else {
                0
            },
            ..base
        },
    }
}
