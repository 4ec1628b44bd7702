// The PBR material's layer stack: a clear coat over a sheen over the base (PbrBsdf), each passing
// down what it does not reflect; mirrors crates/core/src/math/layers.rs (equations there).

// Which table of albedo_tables a lookup reads (core::math::layers::TABLE_*).
const TABLE_CONDUCTOR: u32 = 0u;
const TABLE_COAT: u32 = 1u;
const TABLE_SHEEN: u32 = 2u;
const TABLE_GLASS: u32 = 3u;

struct Layered {
    base: PbrBsdf,
    sheen: vec3<f32>,
    coat: f32,
    coat_alpha: f32,
    sheen_alpha: f32,
    below_coat: f32,
    below_sheen: f32,
    q_coat: f32,
    q_sheen: f32,
    // Whether the coat has a frame of its own, and the matrix taking the base's frame to it.
    coat_own_frame: bool,
    coat_frame: mat3x3<f32>,
}

// A direction of the base's frame in the coat's.
fn in_coat_frame(l: Layered, w: vec3<f32>) -> vec3<f32> {
    return select(w, l.coat_frame * w, l.coat_own_frame);
}

// base under a coat (weight, roughness, frame) and a sheen (colour, roughness), seen from wo (in
// the base's frame).
fn layered_bsdf(base: PbrBsdf, clearcoat: f32, clearcoat_roughness: f32, sheen_color: vec3<f32>,
                sheen_roughness: f32, wo: vec3<f32>, coat_own_frame: bool,
                coat_frame: mat3x3<f32>) -> Layered {
    let cos_o = wo.z;
    var l: Layered;
    l.coat_own_frame = coat_own_frame;
    l.coat_frame = coat_frame;
    l.base = base;
    l.coat = clearcoat;
    l.coat_alpha = alpha_of_roughness(clearcoat_roughness);
    l.sheen = sheen_color;
    l.sheen_alpha = sheen_alpha(sheen_roughness);
    l.below_coat = 1.0;
    l.below_sheen = 1.0;
    l.q_coat = 0.0;
    l.q_sheen = 0.0;
    if (l.coat > 0.0) {
        let cos_coat = max(in_coat_frame(l, wo).z, 0.0);
        l.q_coat = l.coat * albedo_lookup(TABLE_COAT, cos_coat, clearcoat_roughness);
        l.below_coat = 1.0 - l.q_coat;
    }
    let s = max(max(sheen_color.x, sheen_color.y), sheen_color.z);
    if (s > 0.0) {
        let e = s * albedo_lookup(TABLE_SHEEN, cos_o, sheen_roughness);
        l.below_sheen = 1.0 - e;
        l.q_sheen = l.below_coat * e;
    }
    return l;
}

// f |cos θi| in xyz and the sampling pdf in w.
fn layered_eval(l: Layered, wo: vec3<f32>, wi: vec3<f32>) -> vec4<f32> {
    let e = pbr_eval(l.base, wo, wi);
    var f = e.xyz * (l.below_coat * l.below_sheen);
    var pdf = max(1.0 - l.q_coat - l.q_sheen, 0.0) * e.w;
    if (l.coat > 0.0) {
        let c = coat_eval(in_coat_frame(l, wo), in_coat_frame(l, wi), l.coat_alpha);
        f += vec3(l.coat * c.x);
        pdf += l.q_coat * c.y;
    }
    if (l.q_sheen > 0.0 && wi.z > 0.0) {
        f += l.sheen * (l.below_coat * sheen_eval(wo, wi, l.sheen_alpha));
        pdf += l.q_sheen * (0.5 / PI);
    }
    return vec4(f, pdf);
}

fn layered_sample(l: Layered, wo: vec3<f32>, u_lobe: f32, u1: f32, u2: f32) -> BsdfSample {
    var out: BsdfSample;
    out.valid = false;
    var d: vec4<f32>;
    if (u_lobe < l.q_coat) {
        d = sample_coat(in_coat_frame(l, wo), l.coat_alpha, u1, u2);
        // Back to the base's frame: the rotation's inverse is its transpose.
        d = vec4(select(d.xyz, transpose(l.coat_frame) * d.xyz, l.coat_own_frame), d.w);
    } else if (u_lobe < l.q_coat + l.q_sheen) {
        d = vec4(sample_sheen(u1, u2), 1.0);
    } else {
        // The base's own lobe choice, from what is left of u_lobe.
        let q_base = max(1.0 - l.q_coat - l.q_sheen, 0.0);
        let u = min((u_lobe - l.q_coat - l.q_sheen) / q_base, 0.99999988);
        d = pbr_sample_direction(l.base, wo, u, u1, u2);
    }
    if (d.w == 0.0) {
        return out;
    }
    let e = layered_eval(l, wo, d.xyz);
    let weight = e.xyz / e.w;
    if (!(e.w > 0.0) || !is_finite3(weight)) {
        return out;
    }
    return BsdfSample(d.xyz, e.w, weight, true);
}
