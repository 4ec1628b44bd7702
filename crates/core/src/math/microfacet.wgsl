// The anisotropic GGX microfacet distribution; mirrors crates/core/src/math/microfacet.rs (equations there).
// Directions in the shading frame (normal +z).

const MIN_ALPHA: f32 = 1.0e-3;
const ENERGY_SIDE: u32 = 64u;

fn alpha_of_roughness(roughness: f32) -> f32 {
    let r = clamp(roughness, 0.0, 1.0);
    return max(r * r, MIN_ALPHA);
}

// (α_x, α_y) under KHR_materials_anisotropy's strength (microfacet.rs `anisotropic_alpha`).
fn anisotropic_alpha(roughness: f32, strength: f32) -> vec2<f32> {
    let a = alpha_of_roughness(roughness);
    let s = clamp(strength, 0.0, 1.0);
    return vec2(a + (1.0 - a) * s * s, a);
}

// The isotropic roughness whose albedo tables stand for an anisotropic surface's: that of the
// mean width (microfacet.rs `equivalent_roughness`).
fn equivalent_roughness(alpha: vec2<f32>) -> f32 {
    return sqrt(sqrt(alpha.x * alpha.y));
}

fn ggx_d(m: vec3<f32>, alpha: vec2<f32>) -> f32 {
    if (m.z <= 0.0) {
        return 0.0;
    }
    let x = m.x / alpha.x;
    let y = m.y / alpha.y;
    let d = x * x + y * y + m.z * m.z;
    return 1.0 / (PI * alpha.x * alpha.y * d * d);
}

fn ggx_lambda(w: vec3<f32>, alpha: vec2<f32>) -> f32 {
    let c2 = w.z * w.z;
    if (c2 <= 0.0) {
        return 3.0e38;
    }
    let x = alpha.x * w.x;
    let y = alpha.y * w.y;
    let t2 = (x * x + y * y) / c2;
    return 0.5 * (sqrt(1.0 + t2) - 1.0);
}

fn ggx_g1(w: vec3<f32>, alpha: vec2<f32>) -> f32 {
    return 1.0 / (1.0 + ggx_lambda(w, alpha));
}

fn ggx_g2(wo: vec3<f32>, wi: vec3<f32>, alpha: vec2<f32>) -> f32 {
    return 1.0 / (1.0 + ggx_lambda(wo, alpha) + ggx_lambda(wi, alpha));
}

// Heitz 2018.
fn sample_vndf(wo: vec3<f32>, alpha: vec2<f32>, u1: f32, u2: f32) -> vec3<f32> {
    let vh = normalize(vec3(alpha.x * wo.x, alpha.y * wo.y, wo.z));
    let lensq = vh.x * vh.x + vh.y * vh.y;
    var t1 = vec3(1.0, 0.0, 0.0);
    if (lensq > 0.0) {
        t1 = vec3(-vh.y, vh.x, 0.0) / sqrt(lensq);
    }
    let t2 = cross(vh, t1);
    let r = sqrt(u1);
    let phi = TAU * u2;
    let p1 = r * cos(phi);
    let s = 0.5 * (1.0 + vh.z);
    let p2 = (1.0 - s) * sqrt(max(1.0 - p1 * p1, 0.0)) + s * r * sin(phi);
    let nh = t1 * p1 + t2 * p2 + vh * sqrt(max(1.0 - p1 * p1 - p2 * p2, 0.0));
    return normalize(vec3(alpha.x * nh.x, alpha.y * nh.y, max(nh.z, 0.0)));
}

fn vndf_pdf(wo: vec3<f32>, m: vec3<f32>, alpha: vec2<f32>) -> f32 {
    let c = dot(wo, m);
    if (c <= 0.0 || wo.z <= 0.0) {
        return 0.0;
    }
    return ggx_g1(wo, alpha) * c * ggx_d(m, alpha) / wo.z;
}

fn fresnel_schlick(f0: vec3<f32>, cos_in: f32) -> vec3<f32> {
    let x = 1.0 - clamp(cos_in, 0.0, 1.0);
    let x2 = x * x;
    return f0 + (vec3(1.0) - f0) * (x2 * x2 * x);
}

// Bilinear lookup of table `table` of albedo_tables (core::math::layers::albedo_tables).
fn albedo_lookup(table: u32, mu: f32, roughness: f32) -> f32 {
    let n = f32(ENERGY_SIDE);
    let x = clamp(mu * n - 0.5, 0.0, n - 1.0);
    let y = clamp(roughness * (n - 1.0), 0.0, n - 1.0);
    let x0 = min(floor(x), n - 2.0);
    let y0 = min(floor(y), n - 2.0);
    let fx = x - x0;
    let fy = y - y0;
    let i = table * ENERGY_SIDE * ENERGY_SIDE + u32(y0) * ENERGY_SIDE + u32(x0);
    let a = albedo_tables[i];
    let b = albedo_tables[i + 1u];
    let c = albedo_tables[i + ENERGY_SIDE];
    let d = albedo_tables[i + ENERGY_SIDE + 1u];
    let lo = a + (b - a) * fx;
    let hi = c + (d - c) * fx;
    return lo + (hi - lo) * fy;
}

// The white GGX conductor's albedo E(μ, roughness) (the first table).
fn energy_lookup(mu: f32, roughness: f32) -> f32 {
    return albedo_lookup(0u, mu, roughness);
}
