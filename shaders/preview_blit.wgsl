// Shows the raster preview's image (linear radiance) in egui's pass as the path-traced view shows
// its own: the standard view at exposure 0 (each channel clamped to [0, 1]), sRGB-encoded unless
// the target encodes it.
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

fn srgb_encode(c: vec3<f32>) -> vec3<f32> {
    let lo = c * 12.92;
    let hi = 1.055 * pow(max(c, vec3<f32>(0.0)), vec3<f32>(1.0 / 2.4)) - 0.055;
    return select(hi, lo, c <= vec3<f32>(0.0031308));
}

@fragment
fn fs_blit(in: BlitVarying) -> @location(0) vec4<f32> {
    let c = clamp(textureSample(blit_source, blit_sampler, in.uv).rgb, vec3<f32>(0.0), vec3<f32>(1.0));
    if TARGET_IS_SRGB {
        return vec4<f32>(c, 1.0);
    }
    return vec4<f32>(srgb_encode(c), 1.0);
}

// The selection outline (crates/preview/src/outline.rs): `blit_source` is the selection's mask;
// a pixel outside it but within two pixels of it turns orange (linear radiance, blended over the
// preview's image); elsewhere nothing is drawn.
@fragment
fn fs_outline(in: BlitVarying) -> @location(0) vec4<f32> {
    let size = vec2<i32>(textureDimensions(blit_source));
    let p = vec2<i32>(in.clip.xy);
    if textureLoad(blit_source, p, 0).r > 0.5 {
        discard;
    }
    var near = 0.0;
    for (var dy = -2; dy <= 2; dy++) {
        for (var dx = -2; dx <= 2; dx++) {
            let q = clamp(p + vec2<i32>(dx, dy), vec2<i32>(0), size - vec2<i32>(1));
            near = max(near, textureLoad(blit_source, q, 0).r);
        }
    }
    if near < 0.5 {
        discard;
    }
    return vec4<f32>(1.0, 0.3, 0.02, 1.0);
}
