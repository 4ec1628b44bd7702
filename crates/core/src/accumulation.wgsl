// Exact per-pixel sums of samples (crates/core/src/accumulation.rs is the CPU twin and documents
// the format): per pixel, red, green, blue and squared luminance, each a 128-bit two's-complement
// fixed-point number with 64 fraction bits in a vec4<u32>, least significant word first. Integer
// addition is associative, so a pixel's sums are the same bit for bit however its samples were
// batched, tiled or split across machines and merged (`rt-cli merge`).

// Per pixel of the tile, one channel's sum in each buffer: 16 bytes per pixel per binding, so an
// image as large fits in the adapter's binding limit as with float means (lavapipe: 128 MiB, about
// 8 megapixels).
@group(0) @binding(6) var<storage, read_write> accum_red: array<vec4<u32>>;
@group(0) @binding(23) var<storage, read_write> accum_green: array<vec4<u32>>;
@group(0) @binding(24) var<storage, read_write> accum_blue: array<vec4<u32>>;
@group(0) @binding(25) var<storage, read_write> accum_squared: array<vec4<u32>>;

// A channel at or above 2^44 drops the sample (as NaN and Inf do); squared luminance is clamped
// at 2^50 so a firefly cannot overflow its sum (accumulation.rs `MAX_SAMPLE`, `MAX_SQUARED`).
const MAX_SAMPLE: f32 = 0x1p44f;
const MAX_SQUARED: f32 = 0x1p50f;

struct PixelSums {
    r: vec4<u32>,
    g: vec4<u32>,
    b: vec4<u32>,
    squared: vec4<u32>,
}

// `v` in the fixed-point format, from its bits: |v| = m × 2^(e − 150) with the 24-bit mantissa m and
// biased exponent e, which is m × 2^(e − 86) steps of 2^-64, so m shifts into at most two words.
// Integer operations only, so any GPU gets the same words (and they are cheaper than float steps).
fn to_fixed(v: f32) -> vec4<u32> {
    let bits = bitcast<u32>(v);
    let biased = (bits >> 23u) & 0xffu;
    let m = (bits & 0x7fffffu) | 0x800000u;
    let shift = i32(biased) - 86;
    var words = vec4(0u);
    if (biased == 0u) {
        // Zero or subnormal: below the 2^-64 step.
    } else if (shift < 0) {
        // Below 2^-41: the bits under 2^-64 are truncated.
        words.x = select(0u, m >> u32(-shift), shift > -24);
    } else {
        let word = u32(shift) >> 5u;
        let bit = u32(shift) & 31u;
        let low = m << bit;
        let high = select(0u, m >> (32u - bit), bit != 0u);
        let k = vec4(0u, 1u, 2u, 3u);
        words = select(vec4(0u), vec4(low), k == vec4(word)) | select(vec4(0u), vec4(high), k == vec4(word + 1u));
    }
    return select(words, fixed_negate(words), v < 0.0);
}

fn fixed_add(a: vec4<u32>, b: vec4<u32>) -> vec4<u32> {
    let x = a.x + b.x;
    var carry = select(0u, 1u, x < a.x);
    let y = a.y + b.y + carry;
    carry = select(0u, 1u, y < a.y || (carry == 1u && y == a.y));
    let z = a.z + b.z + carry;
    carry = select(0u, 1u, z < a.z || (carry == 1u && z == a.z));
    let w = a.w + b.w + carry;
    return vec4(x, y, z, w);
}

fn fixed_negate(m: vec4<u32>) -> vec4<u32> {
    return fixed_add(~m, vec4(1u, 0u, 0u, 0u));
}

// Whether a sample counts: finite and below MAX_SAMPLE (a dropped one adds nothing but its count).
fn sample_is_kept(l: vec3<f32>) -> bool {
    return is_finite3(l) && all(abs(l) < vec3(MAX_SAMPLE));
}

fn add_sample(sums: ptr<function, PixelSums>, l: vec3<f32>) {
    let lum = luminance(l);
    (*sums).r = fixed_add((*sums).r, to_fixed(l.x));
    (*sums).g = fixed_add((*sums).g, to_fixed(l.y));
    (*sums).b = fixed_add((*sums).b, to_fixed(l.z));
    (*sums).squared = fixed_add((*sums).squared, to_fixed(min(lum * lum, MAX_SQUARED)));
}

// The pixel's sums so far (zero when this render's first batch starts).
fn load_pixel_sums(slot: u32) -> PixelSums {
    if (frame.sample_base == 0u) {
        return PixelSums(vec4(0u), vec4(0u), vec4(0u), vec4(0u));
    }
    return PixelSums(accum_red[slot], accum_green[slot], accum_blue[slot], accum_squared[slot]);
}

fn store_pixel_sums(slot: u32, sums: PixelSums) {
    accum_red[slot] = sums.r;
    accum_green[slot] = sums.g;
    accum_blue[slot] = sums.b;
    accum_squared[slot] = sums.squared;
}
