//! CPU mirrors of the preview shader's structs (`shaders/preview.wgsl`); a test checks them against
//! naga's layout.

use bytemuck::{Pod, Zeroable};

pub const MAX_PREVIEW_LIGHTS: usize = 8;

/// The six sides of a cube in the order the shader numbers them (`shadow_layer`, `ambient_cube` in
/// `preview.wgsl`): +x, −x, +y, −y, +z, −z; a point light's shadow cube and a probe's ambient cube.
pub const CUBE_SIDES: [glam::Vec3; 6] = [
    glam::Vec3::X,
    glam::Vec3::NEG_X,
    glam::Vec3::Y,
    glam::Vec3::NEG_Y,
    glam::Vec3::Z,
    glam::Vec3::NEG_Z,
];

/// `PreviewObject::flags[1]`: which images a material has (the `TEX_*` constants of the shader);
/// the slots of `MaterialTextures` in order.
pub mod image_slot {
    pub const BASE: u32 = 1;
    pub const METAL_ROUGH: u32 = 2;
    pub const NORMAL: u32 = 4;
    pub const EMISSION: u32 = 8;
}

/// `PreviewLight::shadow[1]` of a light without a shadow map.
pub const NO_SHADOW: u32 = u32::MAX;

/// What a preview light is (`PreviewLight::shadow[0]`, the `LIGHT_*` constants of the shader):
/// the tags of `rt_core::LightTag`, as constants to match on. A spot's falloff is in its cone, so
/// glTF's spots are `SPOT` here.
pub mod light_kind {
    use rt_core::LightTag;
    pub const POINT: u32 = LightTag::Point.tag();
    pub const SPOT: u32 = LightTag::Spot.tag();
    pub const DIRECTIONAL: u32 = LightTag::Directional.tag();
    /// An emissive object, drawn as a light at its centre whose intensity follows the object's
    /// projected area (`frame.rs`, `emitter_light`).
    pub const EMITTER: u32 = LightTag::Emitter.tag();
}

#[repr(C, align(16))]
#[derive(Clone, Copy, Debug, Default, PartialEq, Pod, Zeroable)]
pub struct PreviewLight {
    /// xyz: where the light is (a sun's is unused); w: an environment's sun's solid angle (sr;
    /// 0 for every other light, which glass does not show).
    pub position: [f32; 4],
    /// rgb: radiant intensity in W/sr (point, spot), irradiance in W/m² (sun) or an emitter's
    /// radiance; a: an emitter's isotropic part of its projected area, (A − |N|)/4.
    pub color: [f32; 4],
    /// xyz: a spot's axis or a sun's direction of travel (unit), or an emitter's area-weighted
    /// normal N; w: a spot's cos(outer angle).
    pub direction: [f32; 4],
    /// x: a spot's cos(inner angle); y: 1 for glTF's squared falloff, 0 for smoothstep; z: the
    /// world-space size of a shadow-map texel per unit of distance from the light (a sun's: in
    /// all), how far a lookup is pushed along the normal.
    pub cone: [f32; 4],
    /// x: `light_kind`; y: its first shadow-map layer (`NO_SHADOW`: none); z: its layer count
    /// (6 for a point light's cube, else 1); w: the emitting object's index + 1 (0: none), which
    /// its own shadow map leaves out.
    pub shadow: [u32; 4],
}

#[repr(C, align(16))]
#[derive(Clone, Copy, Debug, Pod, Zeroable)]
pub struct PreviewView {
    pub view_proj: [[f32; 4]; 4],
    /// The inverse of `view_proj` (the background's view directions).
    pub inverse_view_proj: [[f32; 4]; 4],
    /// xyz: the camera's position; w: the environment's rotation about +y in radians.
    pub eye: [f32; 4],
    /// rgb: the fog's glow (the radiance it scatters towards the eye where it is thick); a: its
    /// density (0: none).
    pub fog: [f32; 4],
    /// rgb: a constant environment's radiance (the ambient colour); a: 1 when the environment is
    /// constant, which the shader then reads here instead of from its images.
    pub ambient: [f32; 4],
    /// The irradiance volume's bounds (`bounce.rs`; xyz, w unused).
    pub probe_lo: [f32; 4],
    pub probe_hi: [f32; 4],
    pub light_count: u32,
    /// The render's `max_depth`: what the glass shows through it at that depth (`refracted`).
    pub max_depth: u32,
    pub _pad1: u32,
    pub _pad2: u32,
    pub lights: [PreviewLight; MAX_PREVIEW_LIGHTS],
}

#[repr(C, align(16))]
#[derive(Clone, Copy, Debug, Default, PartialEq, Pod, Zeroable)]
pub struct PreviewObject {
    pub model: [[f32; 4]; 4],
    pub normal_matrix: [[f32; 4]; 4],
    /// rgb: base colour; a: an alpha mask's threshold on the image's alpha (cutoff / alpha factor;
    /// 0 cuts nothing).
    pub base_color: [f32; 4],
    /// rgb: emitted radiance (black for non-emitters); a: the material's alpha (blended objects).
    pub emission: [f32; 4],
    /// metallic, roughness, transmission, specular reflectance at normal incidence of its
    /// dielectric layer (0 for a plain Lambertian).
    pub params: [f32; 4],
    /// x: the normal map's strength; y: the dielectric layer's reflectance at grazing angles (F90:
    /// glTF's `specular`, 0 for materials without a specular layer); z: the strength of
    /// anisotropy, w: its rotation in radians from the tangent (∂p/∂u).
    pub extra: [f32; 4],
    /// selected, its images (`image_slot` bits), has vertex normals, and the IOR (f32 bits) of
    /// solid glass, which the shader refracts through (0: none, or a thin sheet).
    pub flags: [u32; 4],
    /// x: the clear coat's weight, y: its roughness (`KHR_materials_clearcoat`); z: the sheen's
    /// roughness; w: unused.
    pub layers: [f32; 4],
    /// rgb: the sheen's colour (`KHR_materials_sheen`; black, none); a: unused.
    pub sheen: [f32; 4],
    /// Solid glass: rgb, its volume's attenuation per unit length (σ = −ln(attenuation colour) /
    /// distance, `KHR_materials_volume`; 0: clear); a: the radius of the object's bounding sphere
    /// (how far a view refracted into it travels). Zero for everything else.
    pub volume: [f32; 4],
}

/// Interleaved vertex: position, normal (zero when the mesh has none), UV, colour (white when the
/// mesh has none; it multiplies the base colour, as in the render).
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, Pod, Zeroable)]
pub struct MeshVertex {
    pub position: [f32; 3],
    pub normal: [f32; 3],
    pub uv: [f32; 2],
    pub color: [f32; 3],
}

#[repr(C)]
#[derive(Clone, Copy, Debug, Default, Pod, Zeroable)]
pub struct GridVertex {
    pub position: [f32; 3],
    /// sRGB-encoded colour; alpha: the fade.
    pub color: [f32; 4],
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::mem::{offset_of, size_of};

    fn wgsl_layout(name: &str) -> (usize, Vec<(String, usize)>) {
        let source = rt_gpu::shaders::PREVIEW.source();
        let module = naga::front::wgsl::parse_str(&source).expect("preview.wgsl parses");
        let ty = module
            .types
            .iter()
            .find(|(_, t)| t.name.as_deref() == Some(name))
            .map(|(_, t)| t)
            .expect("struct exists in WGSL");
        let naga::TypeInner::Struct { members, span } = &ty.inner else {
            panic!("{name} is not a struct")
        };
        (
            *span as usize,
            members
                .iter()
                .map(|m| (m.name.clone().unwrap_or_default(), m.offset as usize))
                .collect(),
        )
    }

    macro_rules! check {
        ($name:literal, $ty:ty, [$($field:ident),*]) => {{
            let (size, members) = wgsl_layout($name);
            assert_eq!(size, size_of::<$ty>(), "{}: size (WGSL vs Rust)", $name);
            let rust: Vec<(String, usize)> =
                vec![$((stringify!($field).to_string(), offset_of!($ty, $field))),*];
            assert_eq!(members, rust, "{}: member offsets (WGSL vs Rust)", $name);
        }};
    }

    #[test]
    fn preview_light_kinds_match_the_shader() {
        let source = rt_gpu::shaders::PREVIEW.source();
        let module = naga::front::wgsl::parse_str(&source).expect("preview.wgsl parses");
        let defines = |name: &str| {
            module
                .constants
                .iter()
                .any(|(_, c)| c.name.as_deref() == Some(name))
        };
        // The light tags the preview uses, from the one table (and no others).
        let tags = rt_core::LightTag::ALL.into_iter().filter(|t| {
            assert_eq!(defines(t.wgsl_constant()), t.in_preview(), "{t:?}");
            t.in_preview()
        });
        for (name, value) in tags
            .map(|t| (t.wgsl_constant(), t.tag()))
            .collect::<Vec<_>>()
            .into_iter()
            .chain([
                ("NO_SHADOW", NO_SHADOW),
                ("TEX_BASE", image_slot::BASE),
                ("TEX_METAL_ROUGH", image_slot::METAL_ROUGH),
                ("TEX_NORMAL", image_slot::NORMAL),
                ("TEX_EMISSION", image_slot::EMISSION),
                (
                    "MAX_SHADOW_LAYERS",
                    crate::shadows::MAX_SHADOW_LAYERS as u32,
                ),
                ("BANDS", crate::bounce::BANDS),
                ("AZIMUTHS", crate::bounce::AZIMUTHS),
            ])
        {
            assert!(
                matches!(
                    shader_constant(&module, name),
                    naga::Expression::Literal(naga::Literal::U32(v)) if *v == value
                ),
                "{name}"
            );
        }
    }

    /// The expression `name` is defined as in the preview's shader.
    fn shader_constant<'m>(module: &'m naga::Module, name: &str) -> &'m naga::Expression {
        let (_, c) = module
            .constants
            .iter()
            .find(|(_, c)| c.name.as_deref() == Some(name))
            .unwrap_or_else(|| panic!("preview.wgsl has no {name}"));
        &module.global_expressions[c.init]
    }

    #[test]
    fn the_float_constants_match_the_shader() {
        let source = rt_gpu::shaders::PREVIEW.source();
        let module = naga::front::wgsl::parse_str(&source).expect("preview.wgsl parses");
        for (name, value) in [
            ("PROBE_LOOKUP_LIFT", crate::bounce::PROBE_LOOKUP_LIFT),
            ("SHARP_ROUGHNESS", crate::behind::SHARP_ROUGHNESS),
        ] {
            assert!(
                matches!(
                    shader_constant(&module, name),
                    naga::Expression::Literal(naga::Literal::F32(v)) if *v == value
                ),
                "{name}"
            );
        }
    }

    #[test]
    fn preview_structs_match_the_shader() {
        check!(
            "PreviewLight",
            PreviewLight,
            [position, color, direction, cone, shadow]
        );
        check!(
            "PreviewView",
            PreviewView,
            [
                view_proj,
                inverse_view_proj,
                eye,
                fog,
                ambient,
                probe_lo,
                probe_hi,
                light_count,
                max_depth,
                _pad1,
                _pad2,
                lights
            ]
        );
        check!(
            "PreviewObject",
            PreviewObject,
            [
                model,
                normal_matrix,
                base_color,
                emission,
                params,
                extra,
                flags,
                layers,
                sheen,
                volume
            ]
        );
    }
}
