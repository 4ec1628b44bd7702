// The clear coat (KHR_materials_clearcoat): a GGX dielectric of index 1.5 over the whole material;
// mirrors crates/core/src/math/coat.rs (equations there).

const COAT_IOR: f32 = 1.5;

// f cos θi of the coat (weight 1) towards wi in x, the pdf of sample_coat there in y.
fn coat_eval(wo: vec3<f32>, wi: vec3<f32>, alpha: f32) -> vec2<f32> {
    if (wo.z <= 0.0 || wi.z <= 0.0) {
        return vec2(0.0);
    }
    let hs = wo + wi;
    let len2 = dot(hs, hs);
    if (len2 <= 0.0) {
        return vec2(0.0);
    }
    let h = hs * inverseSqrt(len2);
    let woh = dot(wo, h);
    if (woh <= 0.0) {
        return vec2(0.0);
    }
    let a = vec2(alpha);
    let d = ggx_d(h, a);
    let f = fresnel_dielectric(woh, COAT_IOR) * d * ggx_g2(wo, wi, a) / (4.0 * wo.z);
    return vec2(f, ggx_g1(wo, a) * d / (4.0 * wo.z));
}

// A reflected visible normal in xyz; w = 0 below the horizon (no sample).
fn sample_coat(wo: vec3<f32>, alpha: f32, u1: f32, u2: f32) -> vec4<f32> {
    let m = sample_vndf(wo, vec2(alpha), u1, u2);
    let wi = 2.0 * dot(wo, m) * m - wo;
    return vec4(wi, select(0.0, 1.0, wi.z > 0.0));
}
