// The sheen layer (KHR_materials_sheen): the Charlie distribution and its fitted visibility;
// mirrors crates/core/src/math/sheen.rs (equations there).

const SHEEN_MIN_ROUGHNESS: f32 = 0.07;

fn sheen_alpha(roughness: f32) -> f32 {
    let r = clamp(roughness, SHEEN_MIN_ROUGHNESS, 1.0);
    return r * r;
}

fn charlie_d(cos_h: f32, alpha: f32) -> f32 {
    let sin2 = max(1.0 - cos_h * cos_h, 0.0);
    return (2.0 + 1.0 / alpha) * pow(sin2, 0.5 / alpha) * (0.5 / PI);
}

fn charlie_l(x: f32, alpha: f32) -> f32 {
    let t = (1.0 - alpha) * (1.0 - alpha);
    let a = mix(21.5473, 25.3245, t);
    let b = mix(3.82987, 3.32435, t);
    let c = mix(0.19823, 0.16801, t);
    let d = mix(-1.97760, -1.27393, t);
    let e = mix(-4.32054, -4.85967, t);
    return a / (1.0 + b * pow(x, c)) + d * x + e;
}

fn charlie_lambda(cos_in: f32, alpha: f32) -> f32 {
    if (cos_in < 0.5) {
        return exp(charlie_l(cos_in, alpha));
    }
    return exp(2.0 * charlie_l(0.5, alpha) - charlie_l(1.0 - cos_in, alpha));
}

// f cos θi of a white sheen towards wi (zero below the horizon).
fn sheen_eval(wo: vec3<f32>, wi: vec3<f32>, alpha: f32) -> f32 {
    if (wo.z <= 0.0 || wi.z <= 0.0) {
        return 0.0;
    }
    let h = normalize(wo + wi);
    return charlie_d(h.z, alpha)
        / ((1.0 + charlie_lambda(wo.z, alpha) + charlie_lambda(wi.z, alpha)) * 4.0 * wo.z);
}

// A uniform direction on the upper hemisphere (pdf 1/2π).
fn sample_sheen(u1: f32, u2: f32) -> vec3<f32> {
    let s = sqrt(max(1.0 - u1 * u1, 0.0));
    let phi = TAU * u2;
    return vec3(s * cos(phi), s * sin(phi), u1);
}
