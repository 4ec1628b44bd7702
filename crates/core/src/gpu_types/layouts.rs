//! The layout of every GPU struct as Rust sees it (name, size, alignment, member offsets), which
//! `tests/shaders.rs` compares with what naga reads from the WGSL. Each struct is defined once,
//! through `gpu_struct!`, which also derives its layout from that definition.

/// A Rust struct's layout as the layout test compares it with WGSL.
pub struct StructLayout {
    pub name: &'static str,
    pub size: usize,
    pub align: usize,
    /// (member name, byte offset) in declaration order.
    pub fields: Vec<(&'static str, usize)>,
}

/// A struct uploaded byte for byte to the kernels, whose layout the WGSL must share.
pub trait GpuStruct {
    fn layout() -> StructLayout;
}

/// Defines a GPU struct (attributes, docs and fields as written) and its `GpuStruct::layout`,
/// taken from the same definition: the member names and offsets the layout test checks are the
/// struct's own, not a copy kept by hand.
macro_rules! gpu_struct {
    (
        $(#[$meta:meta])*
        $vis:vis struct $name:ident {
            $( $(#[$field_meta:meta])* $field_vis:vis $field:ident : $ty:ty ),* $(,)?
        }
    ) => {
        $(#[$meta])*
        $vis struct $name {
            $( $(#[$field_meta])* $field_vis $field: $ty ),*
        }

        impl $crate::gpu_types::GpuStruct for $name {
            fn layout() -> $crate::gpu_types::StructLayout {
                $crate::gpu_types::StructLayout {
                    name: stringify!($name),
                    size: ::std::mem::size_of::<$name>(),
                    align: ::std::mem::align_of::<$name>(),
                    fields: vec![$((stringify!($field), ::std::mem::offset_of!($name, $field))),*],
                }
            }
        }
    };
}
pub(crate) use gpu_struct;

use super::*;

/// Name, size, alignment and member offsets of every GPU struct, for the layout test.
pub fn layouts() -> Vec<StructLayout> {
    vec![
        Triangle::layout(),
        Shading::layout(),
        TextureSlot::layout(),
        Material::layout(),
        Medium::layout(),
        MetalLobe::layout(),
        DielectricLobe::layout(),
        PbrLobe::layout(),
        EnvTexel::layout(),
        BvhNode::layout(),
        WideBvhNode::layout(),
        Emitter::layout(),
        LightNode::layout(),
        DeltaLight::layout(),
        Ray::layout(),
        Hit::layout(),
        crate::instances::Instance::layout(),
        Frame::layout(),
    ]
}
