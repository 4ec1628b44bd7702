//! `KHR_lights_punctual` onto rt's lights: photometric units to radiometric ones, spots with
//! glTF's own falloff.

use glam::{Mat4, Vec3};

use rt_core::light::{Light, LightKind, SpotFalloff};

/// Photometric glTF units to rt's radiometric ones at 683 lm/W (Blender's importer does the same).
pub const LUMENS_PER_WATT: f32 = 683.0;

pub(super) fn light_of(light: &gltf::khr_lights_punctual::Light, world: Mat4, name: &str) -> Light {
    use gltf::khr_lights_punctual::Kind;
    let (kind, inner, outer) = match light.kind() {
        Kind::Directional => (LightKind::Directional, 0.0, 0.0),
        Kind::Point => (LightKind::Point, 0.0, 0.0),
        Kind::Spot {
            inner_cone_angle,
            outer_cone_angle,
        } => (LightKind::Spot, inner_cone_angle, outer_cone_angle),
    };
    let mut out = Light::new(kind, light.name().unwrap_or(name));
    out.position = world.transform_point3(Vec3::ZERO).to_array();
    out.direction = world
        .transform_vector3(Vec3::NEG_Z)
        .normalize_or(Vec3::NEG_Y)
        .to_array();
    out.color = light
        .color()
        .map(|c| if c.is_finite() { c.max(0.0) } else { 0.0 });
    let intensity = light.intensity();
    out.intensity = if intensity.is_finite() && intensity >= 0.0 {
        intensity / LUMENS_PER_WATT
    } else {
        0.0
    };
    if kind == LightKind::Spot {
        let outer = outer.clamp(0.0, std::f32::consts::FRAC_PI_2);
        out.outer_angle_deg = outer.to_degrees();
        out.inner_angle_deg = inner.clamp(0.0, outer).to_degrees();
        out.falloff = SpotFalloff::Gltf;
    }
    out
}
