//! The layout of every GPU struct as Rust sees it (name, size, alignment, member offsets), which
//! `tests/shaders.rs` compares with what naga reads from the WGSL.

use std::mem::{align_of, offset_of, size_of};

use super::*;

/// A Rust struct's layout as the layout test compares it with WGSL.
pub struct StructLayout {
    pub name: &'static str,
    pub size: usize,
    pub align: usize,
    /// (member name, byte offset) in declaration order.
    pub fields: Vec<(&'static str, usize)>,
}

macro_rules! layout {
    ($name:literal, $ty:ty, [$($field:ident),*]) => {
        StructLayout {
            name: $name,
            size: size_of::<$ty>(),
            align: align_of::<$ty>(),
            fields: vec![$((stringify!($field), offset_of!($ty, $field))),*],
        }
    };
}

/// Name, size, alignment and member offsets of every GPU struct, for the layout test.
pub fn layouts() -> Vec<StructLayout> {
    let mut all = material_layouts();
    all.extend(scene_layouts());
    all.push(frame_layout());
    all
}

/// The triangles' and materials' records.
fn material_layouts() -> Vec<StructLayout> {
    vec![
        layout!(
            "Triangle",
            Triangle,
            [v0, material, v1, has_normals, v2, has_uvs]
        ),
        layout!(
            "Shading",
            Shading,
            [n0, c0, n1, c1, n2, c2, uv0, uv1, uv2, _pad3]
        ),
        layout!("TextureSlot", TextureSlot, [offset, width, height]),
        layout!(
            "Material",
            Material,
            [
                color,
                kind,
                emission,
                flags,
                lobe,
                alpha,
                alpha_cutoff,
                samplers,
                textures,
                _pad,
                medium
            ]
        ),
        layout!("Medium", Medium, [sigma_t, anisotropy, sigma_s, _pad]),
        layout!("MetalLobe", MetalLobe, [fuzz]),
        layout!("DielectricLobe", DielectricLobe, [ior]),
        layout!(
            "PbrLobe",
            PbrLobe,
            [
                metallic,
                roughness,
                transmission,
                ior,
                _pad0,
                normal_scale,
                specular_color,
                specular,
                sheen_color,
                sheen_roughness,
                clearcoat,
                clearcoat_roughness,
                clearcoat_normal_scale,
                diffuse_transmission,
                diffuse_transmission_color,
                iridescence,
                iridescence_ior,
                iridescence_thickness_min,
                iridescence_thickness_max,
                anisotropy,
                anisotropy_rotation,
                dispersion,
                _pad
            ]
        ),
    ]
}

/// The environment, the BVHs, the lights and the test kernels' rays.
fn scene_layouts() -> Vec<StructLayout> {
    vec![
        layout!(
            "EnvTexel",
            EnvTexel,
            [radiance, pdf, alias_index, threshold, _pad]
        ),
        layout!(
            "BvhNode",
            BvhNode,
            [
                left_min,
                left,
                left_max,
                left_count,
                right_min,
                right,
                right_max,
                right_count
            ]
        ),
        layout!(
            "WideBvhNode",
            WideBvhNode,
            [
                origin,
                exponents_imask,
                child_base,
                primitive_base,
                slots,
                lo_x,
                hi_x,
                lo_y,
                hi_y,
                lo_z,
                hi_z
            ]
        ),
        layout!("Emitter", Emitter, [triangle, alias_index, threshold, leaf]),
        layout!(
            "LightNode",
            LightNode,
            [
                centre_x,
                centre_y,
                centre_z,
                axis_x,
                axis_y,
                axis_z,
                power,
                cos_theta_o,
                sin_theta_o,
                cos_theta_e,
                radius,
                child,
                leaves,
                parent,
                _pad
            ]
        ),
        layout!(
            "DeltaLight",
            DeltaLight,
            [position, kind, direction, cos_inner, power, cos_outer]
        ),
        layout!("Ray", Ray, [origin, t_max, direction, _pad]),
        layout!("Hit", Hit, [t, triangle, b1, b2, instance]),
        layout!(
            "Instance",
            crate::instances::Instance,
            [to_object, to_world, root, material, mirrored, _pad]
        ),
    ]
}

/// The per-render kernel parameters.
fn frame_layout() -> StructLayout {
    layout!(
        "Frame",
        Frame,
        [
            cam_origin,
            lens_radius,
            cam_u,
            focus_distance,
            cam_v,
            tan_half_vfov,
            cam_w,
            aspect,
            ambient,
            max_depth,
            width,
            height,
            seed,
            sample_base,
            samples_this_dispatch,
            row_begin,
            row_end,
            emitter_count,
            emitter_power_inv,
            roulette_from_depth,
            tile_row_begin,
            tile_row_end,
            sampler,
            nee_only,
            offset_scale,
            active_begin,
            active_count,
            env_width,
            env_height,
            env_rotation,
            env_pick,
            sample_offset,
            clamp_max,
            light_sampler,
            fog,
            camera_media,
            projection,
            projection_scale,
            film_x,
            film_y,
            film_width,
            film_height,
            transparent
        ]
    )
}
