//! The preview's shadow maps: which lights get one (the strongest first, within
//! `MAX_SHADOW_LAYERS`), the view of each layer, and a key that changes only when a map must be
//! drawn again (an object, a mesh or a light moved), so that orbiting the camera redraws none.
//!
//! - a sun: one orthographic map over the scene's bounding sphere, looking along its light;
//! - a spot: one perspective map spanning its outer cone;
//! - a point light or an emitter (drawn as a light at its centre): a cube of six 90° maps, in the
//!   order +x, −x, +y, −y, +z, −z (`shadow_layer` in `preview.wgsl`). An emitter's own object is
//!   left out of its maps: the light lies on or inside it.

use std::hash::{Hash, Hasher};

use glam::{Mat4, Vec3};
use rt_core::Scene;

use super::types::{CUBE_SIDES, PreviewLight, light_kind};

/// Side of every shadow-map layer, in texels.
pub const SHADOW_SIZE: u32 = 1024;
/// Layers drawn at most: a sun, a spot and two point lights' cubes.
pub const MAX_SHADOW_LAYERS: usize = 14;

/// The layers of a frame's shadow maps.
#[derive(Clone, Debug, Default)]
pub struct ShadowPlan {
    /// Each layer's light view and projection (world to clip).
    pub matrices: Vec<[[f32; 4]; 4]>,
    /// Each layer's object left out (its emitter), as index + 1; 0 leaves none out.
    pub skip: Vec<u32>,
    /// Changes whenever the maps' content would.
    pub key: u64,
}

/// A view from `eye` along `forward` (any up that is not parallel to it).
fn look(eye: Vec3, forward: Vec3) -> Mat4 {
    let up = if forward.y.abs() > 0.9 {
        Vec3::Z
    } else {
        Vec3::Y
    };
    glam::camera::rh::view::look_to_mat4(eye, forward, up)
}

/// The cube's six views from `eye`, each 90° wide, reaching `far`.
fn cube(eye: Vec3, near: f32, far: f32) -> [Mat4; 6] {
    let projection =
        glam::camera::rh::proj::directx::perspective(std::f32::consts::FRAC_PI_2, 1.0, near, far);
    CUBE_SIDES.map(|forward| projection * look(eye, forward))
}

/// Gives the strongest of `lights` (sorted strongest first) shadow maps within the layer budget,
/// filling in their `shadow` layers and texel sizes, and returns the layers' views.
pub fn plan_shadows(
    lights: &mut [PreviewLight],
    scene: &Scene,
    center: Vec3,
    radius: f32,
) -> ShadowPlan {
    let mut plan = ShadowPlan::default();
    let texel = 2.0 / SHADOW_SIZE as f32;
    for light in lights.iter_mut() {
        let kind = light.shadow[0];
        let layers = if matches!(kind, light_kind::POINT | light_kind::EMITTER) {
            6
        } else {
            1
        };
        if plan.matrices.len() + layers > MAX_SHADOW_LAYERS {
            continue;
        }
        let position = Vec3::from_slice(&light.position[..3]);
        let axis = Vec3::from_slice(&light.direction[..3]).normalize_or(Vec3::NEG_Y);
        // Depth range: from just off the light to the far side of the scene.
        let reach = (position - center).length() + radius * 1.01;
        let near = (radius * 1e-3).max(reach * 1e-5);
        let (views, texel_size): (Vec<Mat4>, f32) = match kind {
            light_kind::DIRECTIONAL => {
                let eye = center - axis * (2.0 * radius);
                let projection = glam::camera::rh::proj::directx::orthographic(
                    -radius,
                    radius,
                    -radius,
                    radius,
                    0.0,
                    4.0 * radius,
                );
                (vec![projection * look(eye, axis)], radius * texel)
            }
            light_kind::SPOT => {
                let half = light.direction[3].clamp(-1.0, 1.0).acos().clamp(0.01, 1.45);
                let projection =
                    glam::camera::rh::proj::directx::perspective(2.0 * half, 1.0, near, reach);
                (vec![projection * look(position, axis)], half.tan() * texel)
            }
            _ => (cube(position, near, reach).to_vec(), texel),
        };
        light.shadow[1] = plan.matrices.len() as u32;
        light.shadow[2] = views.len() as u32;
        light.cone[2] = texel_size;
        for view in views {
            plan.matrices.push(view.to_cols_array_2d());
            plan.skip.push(light.shadow[3]);
        }
    }
    let mut hasher = std::collections::hash_map::DefaultHasher::new();
    for m in &plan.matrices {
        m.map(|c| c.map(f32::to_bits)).hash(&mut hasher);
    }
    plan.skip.hash(&mut hasher);
    super::surfaces::hash_placements(scene, &mut hasher);
    plan.key = hasher.finish();
    plan
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::types::NO_SHADOW;

    fn light(kind: u32, position: Vec3, direction: Vec3, cos_outer: f32) -> PreviewLight {
        PreviewLight {
            position: position.extend(1.0).to_array(),
            color: [1.0; 4],
            direction: direction.extend(cos_outer).to_array(),
            cone: [1.0, 0.0, 0.0, 0.0],
            shadow: [kind, NO_SHADOW, 0, 0],
        }
    }

    /// Each light's layers see the scene's centre inside their depth range, a point light's six
    /// faces cover every direction once, and lights past the budget get none.
    #[test]
    fn shadow_views_cover_the_scene_within_the_budget() {
        let scene = rt_core::Scene::default();
        let (center, radius) = (Vec3::new(1.0, 2.0, 3.0), 5.0);
        let mut lights = vec![
            light(
                light_kind::DIRECTIONAL,
                Vec3::ZERO,
                Vec3::new(0.3, -1.0, 0.2),
                -1.0,
            ),
            light(light_kind::SPOT, center + Vec3::Y * 8.0, Vec3::NEG_Y, 0.8),
            light(light_kind::POINT, center + Vec3::X * 3.0, Vec3::ZERO, -1.0),
            light(light_kind::POINT, center - Vec3::X * 3.0, Vec3::ZERO, -1.0),
            light(light_kind::POINT, center + Vec3::Z * 3.0, Vec3::ZERO, -1.0),
        ];
        let plan = plan_shadows(&mut lights, &scene, center, radius);
        assert_eq!(plan.matrices.len(), 1 + 1 + 6 + 6);
        assert_eq!(lights[4].shadow[1], NO_SHADOW, "past the budget");
        for l in &lights[..4] {
            let first = l.shadow[1] as usize;
            let inside = (0..l.shadow[2] as usize).any(|k| {
                let p = Mat4::from_cols_array_2d(&plan.matrices[first + k]) * center.extend(1.0);
                let ndc = p.truncate() / p.w;
                p.w > 0.0
                    && ndc.x.abs() <= 1.0
                    && ndc.y.abs() <= 1.0
                    && (0.0..=1.0).contains(&ndc.z)
            });
            assert!(inside, "light kind {} does not see the centre", l.shadow[0]);
        }
        // Directions around a point light land in exactly one face of its cube.
        let first = lights[2].shadow[1] as usize;
        let eye = Vec3::from_slice(&lights[2].position[..3]);
        for d in [
            Vec3::X,
            Vec3::new(-1.0, 0.5, 0.2),
            Vec3::new(0.1, 0.9, -0.3),
            Vec3::NEG_Z,
        ] {
            let p = eye + d.normalize() * 2.0;
            let hits = (0..6)
                .filter(|k| {
                    let c = Mat4::from_cols_array_2d(&plan.matrices[first + k]) * p.extend(1.0);
                    let ndc = c.truncate() / c.w;
                    c.w > 0.0 && ndc.x.abs() < 1.0 && ndc.y.abs() < 1.0
                })
                .count();
            assert_eq!(hits, 1, "{d}");
        }
    }
}
