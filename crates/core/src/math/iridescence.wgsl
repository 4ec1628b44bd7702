// Thin-film interference (KHR_materials_iridescence): Belcour and Barla 2017; mirrors
// crates/core/src/math/iridescence.rs (equations there).

fn film_r0(t: f32, i: f32) -> f32 {
    let r = (t - i) / (t + i);
    return r * r;
}

fn film_schlick(f0: f32, cos_in: f32) -> f32 {
    let x = 1.0 - clamp(cos_in, 0.0, 1.0);
    return f0 + (1.0 - f0) * (x * x * x * x * x);
}

// The colour matching functions' response to an optical path difference (nm) with phase shifts,
// in linear Rec. 709 RGB.
fn film_sensitivity(opd: f32, shift: vec3<f32>) -> vec3<f32> {
    let phase = TAU * opd * 1.0e-9;
    let val = vec3(5.4856e-13, 4.4201e-13, 5.2481e-13);
    let pos = vec3(1.6810e+06, 1.7953e+06, 2.2084e+06);
    let var_ = vec3(4.3278e+09, 9.3046e+09, 6.6121e+09);
    var xyz = val * sqrt(TAU * var_) * cos(pos * phase + shift) * exp(-(phase * phase) * var_);
    xyz.x += 9.7470e-14 * sqrt(TAU * 4.5282e+09) * cos(2.2399e+06 * phase + shift.x) * exp(-4.5282e+09 * phase * phase);
    xyz /= 1.0685e-7;
    let to_rgb = mat3x3(
        vec3(3.2404542, -0.969266, 0.0556434),
        vec3(-1.5371385, 1.8760108, -0.2040259),
        vec3(-0.4985314, 0.041556, 1.0572252));
    return to_rgb * xyz;
}

// The film's reflectance at cosine cos1 outside it (index 1), film index film_ior, thickness (nm),
// over a base whose reflectance at normal incidence is base_f0.
fn thin_film_fresnel(cos1: f32, film_ior: f32, thickness: f32, base_f0: vec3<f32>) -> vec3<f32> {
    let outside = 1.0;
    let t = clamp(thickness / 0.03, 0.0, 1.0);
    let n_f = outside + (film_ior - outside) * (t * t * (3.0 - 2.0 * t));
    let sin2 = (outside / n_f) * (outside / n_f) * (1.0 - cos1 * cos1);
    let cos2_sq = 1.0 - sin2;
    if (cos2_sq < 0.0) {
        return vec3(1.0);
    }
    let cos2 = sqrt(cos2_sq);
    let r12 = film_schlick(film_r0(n_f, outside), cos1);
    let t121 = 1.0 - r12;
    let phi12 = select(0.0, PI, n_f < outside);
    let phi21 = PI - phi12;
    let f0 = clamp(base_f0, vec3(0.0), vec3(0.9999));
    let s = sqrt(f0);
    let base_ior = (vec3(1.0) + s) / (vec3(1.0) - s);
    let r23 = vec3(film_schlick(film_r0(base_ior.x, n_f), cos2),
                   film_schlick(film_r0(base_ior.y, n_f), cos2),
                   film_schlick(film_r0(base_ior.z, n_f), cos2));
    let phi23 = select(vec3(0.0), vec3(PI), base_ior < vec3(n_f));
    let opd = 2.0 * n_f * thickness * cos2;
    let phi = vec3(phi21) + phi23;
    let r123 = clamp(r12 * r23, vec3(1e-5), vec3(0.9999));
    let root = sqrt(r123);
    let rs = t121 * t121 * r23 / (vec3(1.0) - r123);
    var i = vec3(r12) + rs;
    var cm = rs - vec3(t121);
    for (var m = 1u; m <= 2u; m++) {
        cm *= root;
        i += cm * 2.0 * film_sensitivity(f32(m) * opd, f32(m) * phi);
    }
    return clamp(i, vec3(0.0), vec3(1.0));
}
