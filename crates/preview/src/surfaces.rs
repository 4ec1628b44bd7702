//! What the preview reads of a scene's objects, shared by the frame builder (`frame.rs`) and the
//! irradiance volume (`bounce.rs`): an object's area, centroid and area-weighted normal, and a
//! material's metallic-roughness parameters.

use glam::Vec3;
use rt_core::Material;
use rt_core::material::AlphaMode;

/// An emissive object's shape as a light: its area A, centroid and area-weighted normal N (front
/// faces, counter-clockwise). Its projected area towards a unit direction ω, Σ Aᵢ max(nᵢ·ω, 0), is
/// taken as max(N·ω, 0) + (A − |N|)/4: exact for a flat emitter and for a sphere.
pub fn emitter_shape(object: &rt_core::Object) -> (f32, Vec3, Vec3) {
    let m = object.transform.matrix();
    let mesh = &object.mesh;
    let mut area = 0.0;
    let mut weighted = Vec3::ZERO;
    let mut normal = Vec3::ZERO;
    for tri in &mesh.indices {
        let [a, b, c] = tri.map(|i| {
            mesh.positions
                .get(i as usize)
                .map_or(Vec3::ZERO, |p| m.transform_point3(*p))
        });
        let n = (b - a).cross(c - a) * 0.5;
        let tri_area = n.length();
        area += tri_area;
        weighted += (a + b + c) / 3.0 * tri_area;
        normal += n;
    }
    let center = if area > 0.0 {
        weighted / area
    } else {
        m.transform_point3(Vec3::ZERO)
    };
    (area, center, normal)
}

/// The shader's parameters of a material: (base colour, emission, [metallic, roughness,
/// transmission, F0], alpha, texture). Kinds other than PBR map onto the same model.
pub fn material_params(material: &Material) -> ([f32; 3], Vec3, [f32; 4], f32, Option<usize>) {
    match material {
        // A Lambertian's image replaces its colour (the PBR base colour multiplies its image).
        Material::Lambertian { albedo, texture } => (
            if texture.is_some() { [1.0; 3] } else { *albedo },
            Vec3::ZERO,
            [0.0, 1.0, 0.0, 0.0],
            1.0,
            *texture,
        ),
        Material::Metal { albedo, fuzz } => (
            *albedo,
            Vec3::ZERO,
            [1.0, fuzz.clamp(0.0, 1.0), 0.0, 0.0],
            1.0,
            None,
        ),
        Material::Dielectric { ior, tint } => {
            let f0 = ((ior - 1.0) / (ior + 1.0)).powi(2);
            (*tint, Vec3::ZERO, [0.0, 0.0, 1.0, f0], 1.0, None)
        }
        Material::Emissive { color, intensity } => (
            [0.0; 3],
            Vec3::from(*color) * *intensity,
            [0.0, 1.0, 0.0, 0.0],
            1.0,
            None,
        ),
        Material::Pbr(p) => {
            let f0 = ((p.ior - 1.0) / (p.ior + 1.0)).powi(2)
                * p.specular
                * Vec3::from(p.specular_color).max_element();
            let alpha = if p.alpha_mode == AlphaMode::Blend {
                p.alpha.clamp(0.0, 1.0)
            } else {
                1.0
            };
            (
                p.base_color,
                Vec3::from(p.emission) * p.emission_strength,
                [p.metallic, p.roughness, p.transmission, f0.clamp(0.0, 1.0)],
                alpha,
                p.texture,
            )
        }
    }
}

/// Hashes where each object of `scene` stands: its mesh (by address) and its transform (the
/// irradiance volume's and the shadow maps' keys).
pub fn hash_placements(scene: &rt_core::Scene, hasher: &mut impl std::hash::Hasher) {
    use std::hash::Hash;
    for object in &scene.objects {
        (std::sync::Arc::as_ptr(&object.mesh) as usize).hash(hasher);
        object
            .transform
            .matrix()
            .to_cols_array()
            .map(f32::to_bits)
            .hash(hasher);
    }
}

/// The mean of channel `channel` (0–3) of `texture` in [0, 1], decoded from sRGB when `srgb`, over
/// at most 4096 texels evenly strided (a factor's image stands in by its mean where the preview
/// does not sample it); 1 without an image.
fn image_mean(
    textures: &[rt_core::Texture],
    texture: Option<usize>,
    channel: usize,
    srgb: bool,
) -> f32 {
    let Some(t) = texture.and_then(|t| textures.get(t)) else {
        return 1.0;
    };
    let texels = t.rgba8.len() / 4;
    let stride = (texels / 4096).max(1);
    let (mut sum, mut count) = (0.0f32, 0u32);
    for texel in t.rgba8.chunks_exact(4).step_by(stride) {
        let v = f32::from(texel[channel]) / 255.0;
        sum += if srgb {
            rt_core::math::sampling::srgb_to_linear(v)
        } else {
            v
        };
        count += 1;
    }
    if count == 0 { 1.0 } else { sum / count as f32 }
}

/// The layers over a material's base as the preview draws them (`PreviewObject::layers`, its
/// sheen colour, and its anisotropy's strength and rotation): glTF's factors times their images'
/// means (the coat's red, its roughness's green, the sheen colour's sRGB, the sheen roughness's
/// alpha, the anisotropy's blue; the preview samples only the base colour, metallic-roughness,
/// normal and emission images per pixel).
pub fn layer_params(
    material: &Material,
    textures: &[rt_core::Texture],
) -> ([f32; 4], Vec3, [f32; 2]) {
    let Material::Pbr(p) = material else {
        return ([0.0; 4], Vec3::ZERO, [0.0; 2]);
    };
    let mean = |texture, channel, srgb| image_mean(textures, texture, channel, srgb);
    let sheen = Vec3::from(p.sheen_color)
        * Vec3::new(
            mean(p.sheen_color_texture, 0, true),
            mean(p.sheen_color_texture, 1, true),
            mean(p.sheen_color_texture, 2, true),
        );
    (
        [
            (p.clearcoat * mean(p.clearcoat_texture, 0, false)).clamp(0.0, 1.0),
            (p.clearcoat_roughness * mean(p.clearcoat_roughness_texture, 1, false)).clamp(0.0, 1.0),
            (p.sheen_roughness * mean(p.sheen_roughness_texture, 3, false)).clamp(0.0, 1.0),
            0.0,
        ],
        sheen.clamp(Vec3::ZERO, Vec3::ONE),
        [
            (p.anisotropy * mean(p.anisotropy_texture, 2, false)).clamp(0.0, 1.0),
            p.anisotropy_rotation,
        ],
    )
}
