// The PBR material's BSDF; mirrors crates/core/src/math/bsdf.rs (equations there).

struct PbrBsdf {
    base: vec3<f32>,
    metallic: f32,
    ms: vec3<f32>,
    alpha: f32,
    eta: f32,
    transmission: f32,
    q_reflect: f32,
    q_glass: f32,
    thin: bool,
}

// The transmissive part's Fresnel: the interface's, or a thin sheet's 2R/(1+R).
fn glass_fresnel(cos_in: f32, eta: f32, thin: bool) -> f32 {
    let r = fresnel_dielectric(cos_in, eta);
    return select(r, 2.0 * r / (1.0 + r), thin);
}

fn pbr_bsdf(base: vec3<f32>, metallic: f32, roughness: f32, eta: f32, transmission: f32, cos_o: f32, energy: f32) -> PbrBsdf {
    let fs = fresnel_dielectric(cos_o, eta);
    let m = metallic;
    let t = transmission;
    return PbrBsdf(base, m, vec3(1.0) + base * (1.0 / max(energy, 1e-3) - 1.0), alpha_of_roughness(roughness),
                   eta, t, m + (1.0 - m) * (1.0 - t) * fs, (1.0 - m) * t, false);
}

// f |cos θi| in xyz and the sampling pdf in w.
fn pbr_eval(b: PbrBsdf, wo: vec3<f32>, wi: vec3<f32>) -> vec4<f32> {
    let m = b.metallic;
    let t = b.transmission;
    let a = b.alpha;
    if (wo.z <= 0.0) {
        return vec4(0.0);
    }
    let q_diffuse = max(1.0 - b.q_reflect - b.q_glass, 0.0);
    if (wi.z > 0.0) {
        let hs = wo + wi;
        let len2 = dot(hs, hs);
        if (len2 <= 0.0) {
            return vec4(0.0);
        }
        let h = hs * inverseSqrt(len2);
        let woh = dot(wo, h);
        if (woh <= 0.0) {
            return vec4(0.0);
        }
        let d = ggx_d(h, a);
        let spec_cos = d * ggx_g2(wo, wi, a) / (4.0 * wo.z);
        let pdf_reflect = ggx_g1(wo, a) * d / (4.0 * wo.z);
        let f_metal = fresnel_schlick(b.base, woh) * b.ms;
        let f_d = fresnel_dielectric(woh, b.eta);
        let f_g = glass_fresnel(woh, b.eta, b.thin);
        let diffuse = b.base * (wi.z * (1.0 / PI));
        let layer = (1.0 - t) * f_d + t * f_g;
        let f = f_metal * (m * spec_cos) + (vec3(layer * spec_cos) + diffuse * ((1.0 - t) * (1.0 - f_d))) * (1.0 - m);
        let pdf = b.q_reflect * pdf_reflect + b.q_glass * pdf_reflect * f_g + q_diffuse * wi.z * (1.0 / PI);
        return vec4(f, pdf);
    }
    if (wi.z == 0.0 || b.q_glass <= 0.0) {
        return vec4(0.0);
    }
    if (b.thin) {
        let mirrored = vec3(wi.x, wi.y, -wi.z);
        let hs_t = wo + mirrored;
        let l2 = dot(hs_t, hs_t);
        if (l2 <= 0.0) {
            return vec4(0.0);
        }
        let h_t = hs_t * inverseSqrt(l2);
        let woh_t = dot(wo, h_t);
        if (woh_t <= 0.0) {
            return vec4(0.0);
        }
        let d_t = ggx_d(h_t, a);
        let t_g = 1.0 - glass_fresnel(woh_t, b.eta, true);
        let spec_t = d_t * ggx_g2(wo, mirrored, a) / (4.0 * wo.z);
        let pdf_t = b.q_glass * ggx_g1(wo, a) * d_t / (4.0 * wo.z) * t_g;
        return vec4(b.base * ((1.0 - m) * t * t_g * spec_t), pdf_t);
    }
    let hs = wo + wi * b.eta;
    let len2 = dot(hs, hs);
    if (len2 <= 0.0) {
        return vec4(0.0);
    }
    var h = hs * inverseSqrt(len2);
    if (h.z < 0.0) {
        h = -h;
    }
    let woh = dot(wo, h);
    let wih = dot(wi, h);
    if (!(woh > 0.0 && wih < 0.0)) {
        return vec4(0.0);
    }
    let f_d = fresnel_dielectric(woh, b.eta);
    let sqrt_denom = wih + woh / b.eta;
    let denom = sqrt_denom * sqrt_denom;
    let d = ggx_d(h, a);
    let ft_cos = d * ggx_g2(wo, wi, a) * (1.0 - f_d) * abs(wih * woh) / (wo.z * denom * b.eta * b.eta);
    let pdf = b.q_glass * vndf_pdf(wo, h, a) * (1.0 - f_d) * abs(wih) / denom;
    return vec4(b.base * ((1.0 - m) * t * ft_cos), pdf);
}

struct BsdfSample {
    wi: vec3<f32>,
    pdf: f32,
    weight: vec3<f32>,
    // false: no sample (the path ends).
    valid: bool,
}

fn pbr_sample(b: PbrBsdf, wo: vec3<f32>, u_lobe: f32, u1: f32, u2: f32) -> BsdfSample {
    var none: BsdfSample;
    none.valid = false;
    var wi: vec3<f32>;
    if (u_lobe < b.q_reflect + b.q_glass) {
        let m = sample_vndf(wo, b.alpha, u1, u2);
        var reflects = u_lobe < b.q_reflect;
        if (!reflects) {
            reflects = (u_lobe - b.q_reflect) < glass_fresnel(dot(wo, m), b.eta, b.thin) * b.q_glass;
        }
        if (reflects) {
            wi = 2.0 * dot(wo, m) * m - wo;
            if (wi.z <= 0.0) {
                return none;
            }
        } else if (b.thin) {
            wi = 2.0 * dot(wo, m) * m - wo;
            if (wi.z <= 0.0) {
                return none;
            }
            wi.z = -wi.z;
        } else {
            wi = refract_dir(-wo, m, b.eta);
            if (wi.z >= 0.0) {
                return none;
            }
        }
    } else {
        let r = sqrt(u1);
        let phi = TAU * u2;
        wi = vec3(r * cos(phi), r * sin(phi), sqrt(max(1.0 - u1, 0.0)));
    }
    let e = pbr_eval(b, wo, wi);
    let weight = e.xyz / e.w;
    if (!(e.w > 0.0) || !is_finite3(weight)) {
        return none;
    }
    return BsdfSample(wi, e.w, weight, true);
}
