// A hit's shading attributes: vertex colours and the tangent frame normal maps and anisotropy
// turn in. Mirrors crates/core/src/estimator/shading.rs one-to-one.

// The barycentric blend of a triangle's (sRGB-encoded) corner colours, in linear RGB.
fn vertex_color(sh: Shading, b: vec3<f32>) -> vec3<f32> {
    return srgb_to_linear(unpack4x8unorm(sh.c0).rgb) * b.x + srgb_to_linear(unpack4x8unorm(sh.c1).rgb) * b.y
        + srgb_to_linear(unpack4x8unorm(sh.c2).rgb) * b.z;
}

// The shading normal a tangent-space normal map gives (shading.rs `normal_mapped`).
fn normal_mapped(n: vec3<f32>, t0: vec4<f32>, t1: vec4<f32>, t2: vec4<f32>, b: vec3<f32>, t: vec3<f32>, scale: f32) -> vec3<f32> {
    let frame = tangent_frame(n, t0, t1, t2, b);
    if (all(frame.t == vec3(0.0))) {
        return n;
    }
    let m = t * 2.0 - vec3(1.0);
    let mapped = frame.t * (m.x * scale) + frame.b * (m.y * scale) + n * m.z;
    let l = length(mapped);
    return select(n, mapped / l, l > 0.0);
}

// The direction of anisotropy d (tangent frame) in world space about n (shading.rs
// `anisotropy_tangent`); zero where the corners' tangents vanish.
fn anisotropy_tangent(n: vec3<f32>, t0: vec4<f32>, t1: vec4<f32>, t2: vec4<f32>, b: vec3<f32>, d: vec3<f32>) -> vec3<f32> {
    let frame = tangent_frame(n, t0, t1, t2, b);
    return frame.t * d.x + frame.b * d.y;
}

// The tangent frame about n at barycentrics b (shading.rs `tangent_frame`); both axes zero where the
// corners' blended tangent vanishes.
fn tangent_frame(n: vec3<f32>, t0: vec4<f32>, t1: vec4<f32>, t2: vec4<f32>, b: vec3<f32>) -> Basis {
    let blended = t0.xyz * b.x + t1.xyz * b.y + t2.xyz * b.z;
    let ortho = blended - n * dot(n, blended);
    let len2 = dot(ortho, ortho);
    if (!(len2 > 0.0)) {
        return Basis(vec3(0.0), vec3(0.0));
    }
    let tangent = ortho * inverseSqrt(len2);
    return Basis(tangent, cross(n, tangent) * t0.w);
}
