//! A hit's shading attributes: the vertex colours' blend and the tangent frame that normal maps
//! and anisotropy turn in. Mirrored one-to-one in `shading.wgsl` beside it.

use glam::Vec3;

use crate::math::sampling::srgb_to_linear;

/// The WGSL twin of this module, `shading.wgsl` beside it (composed into the kernels by
/// `rt_gpu::shaders`).
pub const WGSL: &str = include_str!("shading.wgsl");

/// The barycentric blend of a triangle's (sRGB-encoded) corner colours, in linear RGB.
pub fn vertex_color(shading: &crate::gpu_types::Shading, b: [f32; 3]) -> Vec3 {
    let decode = |c: u32| {
        let p = c.to_le_bytes();
        Vec3::new(
            srgb_to_linear(p[0] as f32 / 255.0),
            srgb_to_linear(p[1] as f32 / 255.0),
            srgb_to_linear(p[2] as f32 / 255.0),
        )
    };
    decode(shading.c0) * b[0] + decode(shading.c1) * b[1] + decode(shading.c2) * b[2]
}

/// The shading normal a tangent-space normal map gives: texel t ∈ [0, 1]³ read as
/// n_t = (2t − 1) with x, y scaled, in the frame (T, B = w·N×T, N) of the interpolated normal N and
/// the barycentric blend of the corner tangents (T made orthogonal to N).
pub fn normal_mapped(n: Vec3, corners: [[f32; 4]; 3], b: [f32; 3], t: Vec3, scale: f32) -> Vec3 {
    let Some((tangent, bitangent)) = tangent_frame(n, corners, b) else {
        return n;
    };
    let m = t * 2.0 - Vec3::ONE;
    let mapped = tangent * (m.x * scale) + bitangent * (m.y * scale) + n * m.z;
    let len = mapped.length();
    if len > 0.0 { mapped / len } else { n }
}

/// The direction of anisotropy `d` (in the tangent frame: x along the tangent, y the bitangent) in
/// world space, about the shading normal `n`, with the frame of `normal_mapped`; zero where the
/// corners' tangents vanish.
pub fn anisotropy_tangent(n: Vec3, corners: [[f32; 4]; 3], b: [f32; 3], d: Vec3) -> Vec3 {
    tangent_frame(n, corners, b).map_or(Vec3::ZERO, |(t, bt)| t * d.x + bt * d.y)
}

/// The tangent frame about `n` at barycentrics `b`: the blend of the corners' tangents made
/// orthogonal to `n`, and the bitangent w·n×T; `None` where the blend vanishes.
fn tangent_frame(n: Vec3, corners: [[f32; 4]; 3], b: [f32; 3]) -> Option<(Vec3, Vec3)> {
    let tangent = Vec3::from_slice(&corners[0]) * b[0]
        + Vec3::from_slice(&corners[1]) * b[1]
        + Vec3::from_slice(&corners[2]) * b[2];
    let tangent = (tangent - n * n.dot(tangent)).normalize_or_zero();
    (tangent != Vec3::ZERO).then(|| (tangent, n.cross(tangent) * corners[0][3]))
}
