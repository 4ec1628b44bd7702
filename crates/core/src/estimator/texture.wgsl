// Texture lookups and alpha coverage; mirrors crates/core/src/estimator/texture.rs. Texels are RGBA8
// words in `texels` (R in the low byte); a slot is (offset, width, height) and its sampler's 5 bits
// (core::scene::TextureSampler::bits): wrap s, wrap t (0 repeat, 1 clamp, 2 mirror), nearest.

const WRAP_CLAMP: u32 = 1u;
const WRAP_MIRROR: u32 = 2u;
const FILTER_NEAREST: u32 = 16u;

// A texel index on an axis of n texels after the wrap mode.
fn wrap_index(i: i32, n: i32, mode: u32) -> u32 {
    if (mode == WRAP_CLAMP) {
        return u32(clamp(i, 0, n - 1));
    }
    if (mode == WRAP_MIRROR) {
        let period = 2 * n;
        let m = ((i % period) + period) % period;
        return u32(select(m, period - 1 - m, m >= n));
    }
    return u32(((i % n) + n) % n);
}

// One texel as RGBA in [0, 1]; `srgb` decodes the colour channels (alpha stays linear).
fn slot_texel(offset: u32, w: u32, h: u32, bits: u32, x: i32, y: i32, srgb: bool) -> vec4<f32> {
    let xi = wrap_index(x, i32(w), bits & 3u);
    let yi = wrap_index(y, i32(h), (bits >> 2u) & 3u);
    let p = unpack4x8unorm(texels[offset + yi * w + xi]);
    if (srgb) {
        return vec4(srgb_to_linear(p.rgb), p.a);
    }
    return p;
}

// A texture slot at `uv` (uv.y = 0 the image's bottom row, OBJ's convention): bilinear over decoded
// texels, or the nearest texel.
fn sample_slot(offset: u32, w: u32, h: u32, bits: u32, uv: vec2<f32>, srgb: bool) -> vec4<f32> {
    let x = uv.x * f32(w);
    let y = (1.0 - uv.y) * f32(h);
    if ((bits & FILTER_NEAREST) != 0u) {
        return slot_texel(offset, w, h, bits, i32(floor(x)), i32(floor(y)), srgb);
    }
    let x0 = floor(x - 0.5);
    let y0 = floor(y - 0.5);
    let fx = x - 0.5 - x0;
    let fy = y - 0.5 - y0;
    let xi = i32(x0);
    let yi = i32(y0);
    let top = mix(slot_texel(offset, w, h, bits, xi, yi, srgb), slot_texel(offset, w, h, bits, xi + 1, yi, srgb), fx);
    let bottom = mix(slot_texel(offset, w, h, bits, xi, yi + 1, srgb), slot_texel(offset, w, h, bits, xi + 1, yi + 1, srgb), fx);
    return mix(top, bottom, fy);
}

// Material m's texture slot `slot` (SLOT_*) at uv.
fn material_texture(m: Material, slot: u32, uv: vec2<f32>, srgb: bool) -> vec4<f32> {
    let t = m.textures[slot];
    return sample_slot(t.offset, t.width, t.height, sampler_bits(m, slot), uv, srgb);
}

// The base colour image (sRGB), multiplied by the factor for PBR (a Lambertian texture replaces it).
fn base_color_texture(m: Material, uv: vec2<f32>) -> vec3<f32> {
    let t = material_texture(m, SLOT_BASE, uv, true).rgb;
    return t * select(vec3(1.0), m.color, m.kind == MAT_PBR);
}

// The light a surface emits at the barycentrics (b1, b2) of triangle i towards a direction at
// cosine cos_out to its normal: the material's emission times its emission image, under a clear
// coat times 1 − c E_coat(cos_out) (texture.rs says why).
fn surface_emission(m: Material, tri: Triangle, i: u32, b1: f32, b2: f32, cos_out: f32) -> vec3<f32> {
    var e = m.emission;
    if (HAS_TEXTURES && m.textures[SLOT_EMISSION].offset != NO_TEXTURE && tri.has_uvs != 0u) {
        let uv = stored_uv(i, b1, b2);
        e *= material_texture(m, SLOT_EMISSION, uv, true).rgb;
    }
    if (HAS_PBR && m.kind == MAT_PBR) {
        let lobe = pbr_lobe(m);
        if (lobe.clearcoat > 0.0) {
            e *= 1.0 - lobe.clearcoat * albedo_lookup(TABLE_COAT, cos_out, lobe.clearcoat_roughness);
        }
    }
    return e;
}

// The coverage of triangle i's surface at (b1, b2): the alpha of the base colour factor times its
// image; with ALPHA_MASK, 1 at or above the cutoff and 0 below.
fn coverage(m: Material, tri: Triangle, i: u32, b1: f32, b2: f32) -> f32 {
    var a = m.alpha;
    if (m.textures[SLOT_BASE].offset != NO_TEXTURE && tri.has_uvs != 0u) {
        let uv = stored_uv(i, b1, b2);
        a *= material_texture(m, SLOT_BASE, uv, false).a;
    }
    if ((m.flags & ALPHA_MASK) != 0u) {
        return select(0.0, 1.0, a >= m.alpha_cutoff);
    }
    return a;
}

// A 32-bit integer hash (Wellons' lowbias32).
fn hash_u32(x: u32) -> u32 {
    var h = x;
    h ^= h >> 16u;
    h *= 0x7feb352du;
    h ^= h >> 15u;
    h *= 0x846ca68bu;
    h ^= h >> 16u;
    return h;
}

// A uniform number in [0, 1) for one ray meeting one triangle: stochastic transparency's coin. It
// hashes the ray's exact bits, so every sample's rays flip their own coins, even the camera rays
// of one pixel of a 4K image (dropping low bits to survive rounding would make those share a
// coin, and a pixel would then not converge to the blend).
fn alpha_coin(ray: PreparedRay, i: u32) -> f32 {
    let o = bitcast<vec3<u32>>(ray.origin);
    let d = bitcast<vec3<u32>>(ray.inv_direction);
    var h = hash_u32(i);
    h = hash_u32(h ^ o.x);
    h = hash_u32(h ^ o.y);
    h = hash_u32(h ^ o.z);
    h = hash_u32(h ^ d.x);
    h = hash_u32(h ^ d.y);
    h = hash_u32(h ^ d.z);
    return f32(h >> 8u) * (1.0 / 16777216.0);
}

// `stops_ray` for triangle i (the ray-query traversal's candidates).
fn stops_ray_at(ray: PreparedRay, i: u32, b1: f32, b2: f32) -> bool {
    return stops_ray(ray, triangles[i], i, b1, b2);
}

// Whether the hit of `ray` on triangle i at (b1, b2) stops it: always for opaque materials; for
// masked ones where the coverage is 1; for blended ones with probability equal to the coverage.
fn stops_ray(ray: PreparedRay, tri: Triangle, i: u32, b1: f32, b2: f32) -> bool {
    let m = materials[tri.material];
    if ((m.flags & (ALPHA_MASK | ALPHA_BLEND)) == 0u) {
        return true;
    }
    let a = coverage(m, tri, i, b1, b2);
    if ((m.flags & ALPHA_MASK) != 0u) {
        return a > 0.5;
    }
    return a > alpha_coin(ray, i);
}

// The PBR inputs at uv: the lobe's factors times their images (metallic-roughness: blue and green;
// clear coat: red; its roughness: green; sheen colour: sRGB; its roughness: alpha; specular: alpha;
// specular colour: sRGB), as glTF reads them.
fn textured_pbr_inputs(m: Material, uv: vec2<f32>) -> PbrInputs {
    var p = pbr_inputs_of_lobe(pbr_lobe(m));
    if (m.textures[SLOT_METALLIC_ROUGHNESS].offset != NO_TEXTURE) {
        let t = material_texture(m, SLOT_METALLIC_ROUGHNESS, uv, false);
        p.roughness *= t.y;
        p.metallic *= t.z;
    }
    if (m.textures[SLOT_CLEARCOAT].offset != NO_TEXTURE) {
        p.clearcoat *= material_texture(m, SLOT_CLEARCOAT, uv, false).x;
    }
    if (m.textures[SLOT_CLEARCOAT_ROUGHNESS].offset != NO_TEXTURE) {
        p.clearcoat_roughness *= material_texture(m, SLOT_CLEARCOAT_ROUGHNESS, uv, false).y;
    }
    if (m.textures[SLOT_SHEEN_COLOR].offset != NO_TEXTURE) {
        p.sheen_color *= material_texture(m, SLOT_SHEEN_COLOR, uv, true).rgb;
    }
    if (m.textures[SLOT_SHEEN_ROUGHNESS].offset != NO_TEXTURE) {
        p.sheen_roughness *= material_texture(m, SLOT_SHEEN_ROUGHNESS, uv, false).a;
    }
    if (m.textures[SLOT_SPECULAR].offset != NO_TEXTURE) {
        p.specular *= material_texture(m, SLOT_SPECULAR, uv, false).a;
    }
    if (m.textures[SLOT_SPECULAR_COLOR].offset != NO_TEXTURE) {
        p.specular_color *= material_texture(m, SLOT_SPECULAR_COLOR, uv, true).rgb;
    }
    if (m.textures[SLOT_DIFFUSE_TRANSMISSION].offset != NO_TEXTURE) {
        p.diffuse_transmission *= material_texture(m, SLOT_DIFFUSE_TRANSMISSION, uv, false).a;
    }
    if (m.textures[SLOT_DIFFUSE_TRANSMISSION_COLOR].offset != NO_TEXTURE) {
        p.diffuse_transmission_color *= material_texture(m, SLOT_DIFFUSE_TRANSMISSION_COLOR, uv, true).rgb;
    }
    if (m.textures[SLOT_IRIDESCENCE].offset != NO_TEXTURE) {
        p.iridescence *= material_texture(m, SLOT_IRIDESCENCE, uv, false).r;
    }
    if (m.textures[SLOT_IRIDESCENCE_THICKNESS].offset != NO_TEXTURE) {
        let l = pbr_lobe(m);
        let g = material_texture(m, SLOT_IRIDESCENCE_THICKNESS, uv, false).g;
        p.iridescence_thickness = l.iridescence_thickness_min + (l.iridescence_thickness_max - l.iridescence_thickness_min) * g;
    }
    if (m.textures[SLOT_ANISOTROPY].offset != NO_TEXTURE) {
        let t = material_texture(m, SLOT_ANISOTROPY, uv, false);
        p.anisotropy *= t.z;
        p.anisotropy_direction = rotate_direction(p.anisotropy_direction, t.x, t.y);
    }
    return p;
}

// The material's rotation (cos, sin) applied to an anisotropy image's direction (texture.rs
// `rotate_direction`); a zero-length image direction reads as (1, 0).
fn rotate_direction(rotated: vec3<f32>, r: f32, g: f32) -> vec3<f32> {
    var d = vec2(2.0 * r - 1.0, 2.0 * g - 1.0);
    let len2 = dot(d, d);
    d = select(vec2(1.0, 0.0), d * inverseSqrt(len2), len2 > 0.0);
    return vec3(rotated.x * d.x - rotated.y * d.y, rotated.y * d.x + rotated.x * d.y, 0.0);
}
