// The PBR material's base BSDF (with KHR_materials_specular); mirrors crates/core/src/math/bsdf.rs
// (equations there).

struct PbrBsdf {
    base: vec3<f32>,
    metallic: f32,
    ms: vec3<f32>,
    // The GGX widths along the shading frame's x (the direction of anisotropy) and y.
    alpha: vec2<f32>,
    // The dielectric's reflectance at normal incidence F0′ and at grazing incidence F90′.
    f0: vec3<f32>,
    f90: f32,
    eta: f32,
    transmission: f32,
    // The transmissive part's multiple-scattering compensation (1: none).
    k_glass: f32,
    // The diffuse lobe's transmitted share and its colour (KHR_materials_diffuse_transmission).
    diffuse_transmission: f32,
    diffuse_transmission_color: vec3<f32>,
    // The thin film's weight, index and thickness (nm; KHR_materials_iridescence).
    iridescence: f32,
    film_ior: f32,
    film_thickness: f32,
    q_reflect: f32,
    q_glass: f32,
    thin: bool,
}

// R0 = ((η − 1)/(η + 1))², the exact Fresnel at normal incidence.
fn normal_reflectance(eta: f32) -> f32 {
    let r = (eta - 1.0) / (eta + 1.0);
    return r * r;
}

// The exact Fresnel remapped from [R0, 1] onto [F0′, F90′] (KHR_materials_specular, Cycles' form).
fn fresnel_specular(cos_in: f32, eta: f32, f0: vec3<f32>, f90: f32) -> vec3<f32> {
    let r0 = normal_reflectance(eta);
    var x = 1.0;
    if (r0 < 1.0) {
        x = clamp((fresnel_dielectric(cos_in, eta) - r0) / (1.0 - r0), 0.0, 1.0);
    }
    return f0 + (vec3(f90) - f0) * x;
}

fn mean3(v: vec3<f32>) -> f32 {
    return (v.x + v.y + v.z) * (1.0 / 3.0);
}

// The transmissive part's Fresnel: the interface's, or a thin sheet's 2R/(1+R).
fn glass_fresnel(f: vec3<f32>, thin: bool) -> vec3<f32> {
    return select(f, 2.0 * f / (vec3(1.0) + f), thin);
}

fn pbr_bsdf(base: vec3<f32>, metallic: f32, roughness: f32, eta: f32, transmission: f32, cos_o: f32, energy: f32) -> PbrBsdf {
    var b: PbrBsdf;
    b.base = base;
    b.metallic = metallic;
    b.ms = vec3(1.0) + base * (1.0 / max(energy, 1e-3) - 1.0);
    b.alpha = vec2(alpha_of_roughness(roughness));
    b.eta = eta;
    b.transmission = transmission;
    b.thin = false;
    b.k_glass = 1.0;
    b.diffuse_transmission = 0.0;
    b.diffuse_transmission_color = vec3(1.0);
    b.iridescence = 0.0;
    b.film_ior = 1.0;
    b.film_thickness = 0.0;
    return pbr_with_specular(b, vec3(1.0), 1.0, cos_o);
}

// b with anisotropic widths (α_x, α_y) (anisotropic_alpha).
fn pbr_anisotropic(b_in: PbrBsdf, alpha: vec2<f32>) -> PbrBsdf {
    var b = b_in;
    b.alpha = alpha;
    return b;
}

// b under KHR_materials_iridescence's thin film (weight, index, thickness in nm).
fn pbr_with_iridescence(b_in: PbrBsdf, weight: f32, film_ior: f32, thickness: f32) -> PbrBsdf {
    var b = b_in;
    b.iridescence = weight;
    b.film_ior = film_ior;
    b.film_thickness = thickness;
    return b;
}

// The conductor's Fresnel at cos_in, under the film if there is one.
fn pbr_metal_fresnel(b: PbrBsdf, cos_in: f32) -> vec3<f32> {
    let f = fresnel_schlick(b.base, cos_in);
    if (b.iridescence > 0.0) {
        return mix(f, thin_film_fresnel(cos_in, b.film_ior, b.film_thickness, b.base), b.iridescence);
    }
    return f;
}

// The dielectric's Fresnel (bsdf.rs's F), under the film on the outside.
fn pbr_fresnel(b: PbrBsdf, cos_in: f32) -> vec3<f32> {
    let f = fresnel_specular(cos_in, b.eta, b.f0, b.f90);
    if (b.iridescence > 0.0 && b.eta >= 1.0) {
        return mix(f, thin_film_fresnel(cos_in, b.film_ior, b.film_thickness, b.f0), b.iridescence);
    }
    return f;
}

// b with KHR_materials_diffuse_transmission's share and colour.
fn pbr_with_diffuse_transmission(b_in: PbrBsdf, share: f32, color: vec3<f32>) -> PbrBsdf {
    var b = b_in;
    b.diffuse_transmission = share;
    b.diffuse_transmission_color = color;
    return b;
}

// b with its transmissive part compensated for multiple scattering (albedo: that part's
// single-scattering albedo at ωo).
fn pbr_with_glass_energy(b_in: PbrBsdf, albedo: f32) -> PbrBsdf {
    var b = b_in;
    b.k_glass = 1.0 / max(albedo, 0.1);
    return b;
}

// b with KHR_materials_specular's colour and strength.
fn pbr_with_specular(b_in: PbrBsdf, color: vec3<f32>, specular: f32, cos_o: f32) -> PbrBsdf {
    var b = b_in;
    let m = b.metallic;
    let t = b.transmission;
    b.f0 = min(normal_reflectance(b.eta) * color, vec3(1.0)) * specular;
    b.f90 = specular;
    let fs = mean3(fresnel_specular(cos_o, b.eta, b.f0, specular));
    b.q_reflect = m + (1.0 - m) * (1.0 - t) * fs;
    b.q_glass = (1.0 - m) * t;
    return b;
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
        let f_metal = pbr_metal_fresnel(b, woh) * b.ms;
        let f_d = pbr_fresnel(b, woh);
        let f_g = glass_fresnel(f_d, b.thin);
        let diffuse = b.base * (wi.z * (1.0 / PI));
        let layer = (1.0 - t) * f_d + (t * b.k_glass) * f_g;
        let kept = 1.0 - b.diffuse_transmission;
        let f = f_metal * (m * spec_cos) + (layer * spec_cos + diffuse * ((1.0 - t) * kept) * (vec3(1.0) - f_d)) * (1.0 - m);
        let pdf = b.q_reflect * pdf_reflect + b.q_glass * pdf_reflect * mean3(f_g) + q_diffuse * kept * wi.z * (1.0 / PI);
        return vec4(f, pdf);
    }
    if (wi.z == 0.0) {
        return vec4(0.0);
    }
    var e = pbr_eval_glass(b, wo, wi);
    let d = b.diffuse_transmission;
    if (d > 0.0) {
        let c = -wi.z * (1.0 / PI);
        let through = b.diffuse_transmission_color * (vec3(1.0) - pbr_fresnel(b, wo.z)) * ((1.0 - m) * (1.0 - t) * d * c);
        e += vec4(through, q_diffuse * d * c);
    }
    return e;
}

// The transmissive part's f |cos θi| and pdf for wi below the surface.
fn pbr_eval_glass(b: PbrBsdf, wo: vec3<f32>, wi: vec3<f32>) -> vec4<f32> {
    let m = b.metallic;
    let t = b.transmission;
    let a = b.alpha;
    if (b.q_glass <= 0.0) {
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
        let t_g = vec3(1.0) - glass_fresnel(pbr_fresnel(b, woh_t), true);
        let spec_t = d_t * ggx_g2(wo, mirrored, a) / (4.0 * wo.z);
        let pdf_t = b.q_glass * ggx_g1(wo, a) * d_t / (4.0 * wo.z) * mean3(t_g);
        return vec4(b.base * t_g * ((1.0 - m) * t * b.k_glass * spec_t), pdf_t);
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
    let t_d = vec3(1.0) - pbr_fresnel(b, woh);
    let sqrt_denom = wih + woh / b.eta;
    let denom = sqrt_denom * sqrt_denom;
    let d = ggx_d(h, a);
    let ft_cos = d * ggx_g2(wo, wi, a) * abs(wih * woh) / (wo.z * denom * b.eta * b.eta);
    let pdf = b.q_glass * vndf_pdf(wo, h, a) * mean3(t_d) * abs(wih) / denom;
    return vec4(b.base * t_d * ((1.0 - m) * t * b.k_glass * ft_cos), pdf);
}

struct BsdfSample {
    wi: vec3<f32>,
    pdf: f32,
    weight: vec3<f32>,
    // false: no sample (the path ends).
    valid: bool,
}

// The direction pbr_sample draws for three uniform numbers in xyz, w = 0 where it draws none.
fn pbr_sample_direction(b: PbrBsdf, wo: vec3<f32>, u_lobe: f32, u1: f32, u2: f32) -> vec4<f32> {
    if (u_lobe < b.q_reflect + b.q_glass) {
        let m = sample_vndf(wo, b.alpha, u1, u2);
        var reflects = u_lobe < b.q_reflect;
        if (!reflects) {
            let f = glass_fresnel(pbr_fresnel(b, dot(wo, m)), b.thin);
            reflects = (u_lobe - b.q_reflect) < mean3(f) * b.q_glass;
        }
        if (reflects || b.thin) {
            var wi = 2.0 * dot(wo, m) * m - wo;
            if (wi.z <= 0.0) {
                return vec4(0.0);
            }
            if (!reflects) {
                wi.z = -wi.z;
            }
            return vec4(wi, 1.0);
        }
        let wi = refract_dir(-wo, m, b.eta);
        return vec4(wi, select(0.0, 1.0, wi.z < 0.0));
    }
    let r = sqrt(u1);
    let phi = TAU * u2;
    let z = sqrt(max(1.0 - u1, 0.0));
    // The diffuse lobe's transmitted share goes below, with what is left of u_lobe.
    let u = (u_lobe - b.q_reflect - b.q_glass) / max(1.0 - b.q_reflect - b.q_glass, 0.0);
    let below = u >= 1.0 - b.diffuse_transmission;
    return vec4(r * cos(phi), r * sin(phi), select(z, -z, below), 1.0);
}

fn pbr_sample(b: PbrBsdf, wo: vec3<f32>, u_lobe: f32, u1: f32, u2: f32) -> BsdfSample {
    var out: BsdfSample;
    out.valid = false;
    let d = pbr_sample_direction(b, wo, u_lobe, u1, u2);
    if (d.w == 0.0) {
        return out;
    }
    let e = pbr_eval(b, wo, d.xyz);
    let weight = e.xyz / e.w;
    if (!(e.w > 0.0) || !is_finite3(weight)) {
        return out;
    }
    return BsdfSample(d.xyz, e.w, weight, true);
}
