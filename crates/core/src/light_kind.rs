//! The one table of light kinds, as `material_kind.rs` is for materials. Two enumerations, because
//! a user and a kernel cut lights differently:
//! - [`LightKind`]: what a user places (point, spot, sun): the scene's `Light::kind`, projects,
//!   the editor's lists (labels, tooltips, default names) and glTF's `KHR_lights_punctual`.
//! - [`LightTag`]: what a light record is to the code that shades with it: the path tracer's
//!   `DeltaLight::kind` (a spot's two falloffs apart), the raster preview's `PreviewLight` (which
//!   also draws emissive objects as lights), the WGSL constants `LIGHT_*` of both
//!   (`gpu_types.wgsl`, `shaders/preview.wgsl`; checked by `tests/shaders.rs` and the preview's
//!   tests), and which records the light tree holds.
//!
//! A light's tag is `Light::tag` (`light.rs`). A new light type is a variant of each here, then
//! the files docs/architecture.md ("Adding a light type") lists.

use serde::{Deserialize, Serialize};

#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum LightKind {
    Point,
    Spot,
    Directional,
}

impl LightKind {
    /// Every kind, in the order the editor lists them.
    pub const ALL: [LightKind; 3] = [LightKind::Point, LightKind::Spot, LightKind::Directional];

    /// The name a user sees (the Inspector's type buttons).
    pub fn label(self) -> &'static str {
        match self {
            LightKind::Point => "Point",
            LightKind::Spot => "Spot",
            LightKind::Directional => "Sun",
        }
    }

    /// What it is, in a sentence (the editor's tooltips), with the unit of its intensity.
    pub fn summary(self) -> &'static str {
        match self {
            LightKind::Point => "Light from a point, in every direction (intensity in W/sr)",
            LightKind::Spot => "Light from a point, in a cone (intensity in W/sr)",
            LightKind::Directional => "Parallel light from far away (irradiance in W/m²)",
        }
    }

    /// What a new light of this kind is called, before its number ("point light 2").
    pub fn noun(self) -> &'static str {
        match self {
            LightKind::Point => "point light",
            LightKind::Spot => "spot light",
            LightKind::Directional => "sun",
        }
    }

    /// Whether it stands somewhere (a sun is everywhere at infinity): it has a position to move.
    pub fn has_position(self) -> bool {
        self != LightKind::Directional
    }

    /// Whether it points somewhere: it has a direction to turn.
    pub fn has_direction(self) -> bool {
        self != LightKind::Point
    }
}

/// The tag of a light record, the value both kernels and the preview dispatch on.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
#[repr(u32)]
pub enum LightTag {
    /// The padding record of a scene without delta lights: lights nothing.
    None = 0,
    Point = 1,
    /// A spot whose intensity falls off as smoothstep in cosine (`light::spot_falloff`).
    Spot = 2,
    Directional = 3,
    /// A spot with glTF's squared falloff (`light::spot_falloff_gltf`).
    SpotGltf = 4,
    /// An emissive object as the raster preview approximates it: a light at its centre. The path
    /// tracer samples emitters by triangle (`emitters.rs`, `light_tree.rs`) and has no such record.
    Emitter = 5,
}

impl LightTag {
    /// Every tag, in tag order.
    pub const ALL: [LightTag; 6] = [
        LightTag::None,
        LightTag::Point,
        LightTag::Spot,
        LightTag::Directional,
        LightTag::SpotGltf,
        LightTag::Emitter,
    ];

    pub const fn tag(self) -> u32 {
        self as u32
    }

    pub fn from_tag(tag: u32) -> Option<LightTag> {
        LightTag::ALL.get(tag as usize).copied()
    }

    /// The WGSL constant holding `tag`.
    pub fn wgsl_constant(self) -> &'static str {
        match self {
            LightTag::None => "LIGHT_NONE",
            LightTag::Point => "LIGHT_POINT",
            LightTag::Spot => "LIGHT_SPOT",
            LightTag::Directional => "LIGHT_DIRECTIONAL",
            LightTag::SpotGltf => "LIGHT_SPOT_GLTF",
            LightTag::Emitter => "LIGHT_EMITTER",
        }
    }

    /// Whether the path tracer's records (`gpu_types::DeltaLight`) use it; the preview's use the
    /// rest but `None` and `SpotGltf` (it reads a spot's falloff from its cone).
    pub fn in_path_tracer(self) -> bool {
        self != LightTag::Emitter
    }

    /// Whether the preview's records (`PreviewLight`) use it.
    pub fn in_preview(self) -> bool {
        !matches!(self, LightTag::None | LightTag::SpotGltf)
    }

    /// Whether the light tree holds such a record where it samples (points and spots, bounded in
    /// space); the rest (suns) are summed at every vertex. Twin: `in_light_tree` in
    /// `reference/light.wgsl`.
    pub fn in_light_tree(self) -> bool {
        matches!(self, LightTag::Point | LightTag::Spot | LightTag::SpotGltf)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn tags_are_the_variants_in_order() {
        for (i, tag) in LightTag::ALL.iter().enumerate() {
            assert_eq!(tag.tag(), i as u32);
            assert_eq!(LightTag::from_tag(i as u32), Some(*tag));
        }
        assert_eq!(LightTag::from_tag(LightTag::ALL.len() as u32), None);
    }
}
