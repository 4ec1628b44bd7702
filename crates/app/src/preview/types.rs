//! CPU mirrors of the preview shader's structs (`shaders/preview.wgsl`); a test checks them against
//! naga's layout.

use bytemuck::{Pod, Zeroable};

pub const MAX_PREVIEW_LIGHTS: usize = 8;

#[repr(C, align(16))]
#[derive(Clone, Copy, Debug, Default, Pod, Zeroable)]
pub struct PreviewLight {
    pub position: [f32; 4],
    /// rgb: radiant intensity over π; a: a spot's cos(inner angle).
    pub intensity: [f32; 4],
    /// xyz: a spot's axis (where it shines); w: cos(outer angle), or `NO_CONE` for the others.
    pub direction: [f32; 4],
}

/// `PreviewLight::direction`'s w for a light without a cone (below any cosine).
pub const NO_CONE: f32 = -2.0;

#[repr(C, align(16))]
#[derive(Clone, Copy, Debug, Pod, Zeroable)]
pub struct PreviewView {
    pub view_proj: [[f32; 4]; 4],
    pub eye: [f32; 4],
    pub ambient: [f32; 4],
    pub light_count: u32,
    /// The fog's glow (`preview.wgsl`): the radiance it scatters towards the eye where it is
    /// thick, per channel (its density is `ambient`'s w).
    pub fog_r: f32,
    pub fog_g: f32,
    pub fog_b: f32,
    pub lights: [PreviewLight; MAX_PREVIEW_LIGHTS],
}

/// How the preview shades an object (`PreviewObject::flags[3]`, the `LOOK_*` constants of
/// `shaders/preview.wgsl`): an approximation chosen per material, not the material's kind
/// (`rt_core::MaterialKind`); the preview's match over `Material` gives each material one.
pub mod look {
    pub const DIFFUSE: u32 = 0;
    pub const METAL: u32 = 1;
    pub const GLASS: u32 = 2;
    pub const EMITTER: u32 = 3;
}

#[repr(C, align(16))]
#[derive(Clone, Copy, Debug, Default, Pod, Zeroable)]
pub struct PreviewObject {
    pub model: [[f32; 4]; 4],
    pub normal_matrix: [[f32; 4]; 4],
    pub color: [f32; 4],
    pub emission: [f32; 4],
    /// selected, textured, has vertex normals, kind.
    pub flags: [u32; 4],
}

/// Interleaved vertex: position, normal (zero when the mesh has none), UV.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, Pod, Zeroable)]
pub struct MeshVertex {
    pub position: [f32; 3],
    pub normal: [f32; 3],
    pub uv: [f32; 2],
}

#[repr(C)]
#[derive(Clone, Copy, Debug, Default, Pod, Zeroable)]
pub struct GridVertex {
    pub position: [f32; 3],
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
    fn preview_looks_match_the_shader() {
        let source = rt_gpu::shaders::PREVIEW.source();
        let module = naga::front::wgsl::parse_str(&source).expect("preview.wgsl parses");
        for (name, value) in [
            ("LOOK_DIFFUSE", look::DIFFUSE),
            ("LOOK_METAL", look::METAL),
            ("LOOK_GLASS", look::GLASS),
            ("LOOK_EMITTER", look::EMITTER),
        ] {
            let (_, c) = module
                .constants
                .iter()
                .find(|(_, c)| c.name.as_deref() == Some(name))
                .unwrap_or_else(|| panic!("preview.wgsl has no {name}"));
            assert!(
                matches!(
                    module.global_expressions[c.init],
                    naga::Expression::Literal(naga::Literal::U32(v)) if v == value
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
            [position, intensity, direction]
        );
        check!(
            "PreviewView",
            PreviewView,
            [
                view_proj,
                eye,
                ambient,
                light_count,
                fog_r,
                fog_g,
                fog_b,
                lights
            ]
        );
        check!(
            "PreviewObject",
            PreviewObject,
            [model, normal_matrix, color, emission, flags]
        );
    }
}
