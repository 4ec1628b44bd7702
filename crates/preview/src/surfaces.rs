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
