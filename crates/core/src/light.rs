//! Point, spot and directional lights: delta lights, which no ray can hit, so the kernel samples
//! them only by next-event estimation (always, whatever the NEE setting: it is their only estimator).
//!
//! Units, with `power = color × intensity`:
//! - **Point**: radiant intensity I = power in W/sr. A Lambertian surface at distance d whose normal
//!   makes angle θ with the light receives irradiance E = I cosθ / d² and reflects radiance
//!   L = (albedo/π) E.
//! - **Spot**: a point light whose intensity is I inside `inner_angle_deg` of its direction, falls
//!   smoothly (smoothstep in cos, or glTF's squared linear ramp in cos for lights from glTF files)
//!   to zero at `outer_angle_deg`, and is zero beyond.
//! - **Directional** (sun): parallel light travelling along `direction`; irradiance on a surface
//!   facing it is E = power in W/m², times cosθ otherwise.

use glam::Vec3;
use serde::{Deserialize, Serialize};

pub use crate::light_kind::LightKind;
use crate::light_kind::LightTag;
use crate::material::Rgb;

/// How a spot light fades between its inner and outer cones.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum SpotFalloff {
    /// smoothstep(t), t the position between the cones' cosines.
    #[default]
    Smoothstep,
    /// t², as `KHR_lights_punctual` specifies (its `lightAngleScale`/`lightAngleOffset`).
    Gltf,
}

#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Light {
    pub name: String,
    pub kind: LightKind,
    /// Where a point or spot light is (unused by directional lights).
    #[serde(default)]
    pub position: [f32; 3],
    /// Where a spot light points, or which way a directional light's light travels.
    #[serde(default = "down")]
    pub direction: [f32; 3],
    pub color: Rgb,
    /// W/sr for point and spot lights, W/m² for directional lights (times `color`).
    pub intensity: f32,
    #[serde(default = "default_inner")]
    pub inner_angle_deg: f32,
    #[serde(default = "default_outer")]
    pub outer_angle_deg: f32,
    #[serde(default)]
    pub falloff: SpotFalloff,
    /// The node of the scene's animation that carries the light (`crate::animation`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub animation_node: Option<u32>,
}

fn down() -> [f32; 3] {
    [0.0, -1.0, 0.0]
}

fn default_inner() -> f32 {
    20.0
}

fn default_outer() -> f32 {
    30.0
}

impl Light {
    pub fn new(kind: LightKind, name: &str) -> Self {
        Light {
            name: name.into(),
            kind,
            position: [0.0; 3],
            direction: down(),
            color: [1.0; 3],
            intensity: 1.0,
            inner_angle_deg: default_inner(),
            outer_angle_deg: default_outer(),
            falloff: SpotFalloff::Smoothstep,
            animation_node: None,
        }
    }

    /// Checks that the numbers are finite and in range; names the light in the message.
    pub fn validate(&self) -> Result<(), String> {
        let what = format!("light '{}'", self.name);
        let finite = |v: &[f32]| v.iter().all(|x| x.is_finite());
        if !(finite(&self.position) && finite(&self.direction) && finite(&self.color)) {
            return Err(format!(
                "{what}: position, direction and colour must be finite"
            ));
        }
        if !(self.intensity.is_finite() && self.intensity >= 0.0)
            || self.color.iter().any(|c| *c < 0.0)
        {
            return Err(format!("{what}: colour and intensity must be >= 0"));
        }
        if self.kind.has_direction() && Vec3::from(self.direction).length_squared() == 0.0 {
            return Err(format!("{what}: the direction must not be zero"));
        }
        if self.kind == LightKind::Spot
            && !(0.0 <= self.inner_angle_deg
                && self.inner_angle_deg <= self.outer_angle_deg
                && self.outer_angle_deg <= 180.0)
        {
            return Err(format!(
                "{what}: spot angles must satisfy 0 <= inner ({}) <= outer ({}) <= 180",
                self.inner_angle_deg, self.outer_angle_deg
            ));
        }
        Ok(())
    }

    /// The GPU record.
    pub fn gpu(&self) -> crate::gpu_types::DeltaLight {
        let power = Vec3::from(self.color) * self.intensity;
        let direction = Vec3::from(self.direction).normalize_or(Vec3::NEG_Y);
        crate::gpu_types::DeltaLight {
            position: self.position,
            kind: self.tag().tag(),
            direction: direction.to_array(),
            cos_inner: self.inner_angle_deg.to_radians().cos(),
            power: power.to_array(),
            cos_outer: self.outer_angle_deg.to_radians().cos(),
        }
    }
}

impl Light {
    /// The tag of its path-tracer record.
    pub fn tag(&self) -> LightTag {
        match self.kind {
            LightKind::Point => LightTag::Point,
            LightKind::Spot if self.falloff == SpotFalloff::Gltf => LightTag::SpotGltf,
            LightKind::Spot => LightTag::Spot,
            LightKind::Directional => LightTag::Directional,
        }
    }
}

/// The spot falloff: 1 inside the inner cone, 0 outside the outer one, smoothstep in cosine
/// between. `cos_angle` is the cosine between the spot's direction and the direction to the point.
pub fn spot_falloff(cos_angle: f32, cos_inner: f32, cos_outer: f32) -> f32 {
    let t = ((cos_angle - cos_outer) / (cos_inner - cos_outer).max(1e-6)).clamp(0.0, 1.0);
    t * t * (3.0 - 2.0 * t)
}

/// glTF's spot falloff: t², t = clamp((cos − cos_outer) / max(0.001, cos_inner − cos_outer), 0, 1).
pub fn spot_falloff_gltf(cos_angle: f32, cos_inner: f32, cos_outer: f32) -> f32 {
    let t = ((cos_angle - cos_outer) / (cos_inner - cos_outer).max(1e-3)).clamp(0.0, 1.0);
    t * t
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_kind_has_a_tag_the_path_tracer_and_the_preview_know() {
        for kind in LightKind::ALL {
            for falloff in [SpotFalloff::Smoothstep, SpotFalloff::Gltf] {
                let mut light = Light::new(kind, "l");
                light.falloff = falloff;
                let tag = light.tag();
                assert!(tag.in_path_tracer() && tag != LightTag::None, "{kind:?}");
                assert_eq!(tag.in_light_tree(), kind.has_position(), "{kind:?}");
                assert_eq!(light.gpu().kind, tag.tag());
            }
        }
    }
}
