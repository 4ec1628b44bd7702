// Copies the offscreen image into egui's pass. The offscreen image holds sRGB-encoded values; a
// target that encodes sRGB itself gets them decoded first.
override TARGET_IS_SRGB: bool = false;

@group(0) @binding(0) var blit_source: texture_2d<f32>;
@group(0) @binding(1) var blit_sampler: sampler;

struct BlitVarying {
    @builtin(position) clip: vec4<f32>,
    @location(0) uv: vec2<f32>,
}

@vertex
fn vs_blit(@builtin(vertex_index) index: u32) -> BlitVarying {
    // One triangle that covers the viewport.
    let x = f32((index << 1u) & 2u);
    let y = f32(index & 2u);
    var out: BlitVarying;
    out.clip = vec4<f32>(x * 2.0 - 1.0, 1.0 - y * 2.0, 0.0, 1.0);
    out.uv = vec2<f32>(x, y);
    return out;
}

fn srgb_decode(c: vec3<f32>) -> vec3<f32> {
    let lo = c / 12.92;
    let hi = pow((c + 0.055) / 1.055, vec3<f32>(2.4));
    return select(hi, lo, c <= vec3<f32>(0.04045));
}

@fragment
fn fs_blit(in: BlitVarying) -> @location(0) vec4<f32> {
    let c = textureSample(blit_source, blit_sampler, in.uv);
    if TARGET_IS_SRGB {
        return vec4<f32>(srgb_decode(c.rgb), 1.0);
    }
    return vec4<f32>(c.rgb, 1.0);
}
