// Homogeneous participating media: the Henyey-Greenstein phase function, free flight and
// transmittance; mirrors crates/core/src/math/medium.rs (equations there).

const MEDIUM_FAR: f32 = 3.0e38;
const MAX_OPTICAL_DEPTH: f32 = 80.0;

fn hg_phase(cos_theta: f32, g: f32) -> f32 {
    let denom = 1.0 + g * g - 2.0 * g * cos_theta;
    return (1.0 - g * g) / (4.0 * PI * denom * sqrt(max(denom, 1e-12)));
}

fn sample_hg(direction: vec3<f32>, g: f32, u1: f32, u2: f32) -> vec3<f32> {
    var cos_theta = 1.0 - 2.0 * u1;
    if (abs(g) >= 1e-3) {
        let s = (1.0 - g * g) / (1.0 - g + 2.0 * g * u1);
        cos_theta = clamp((1.0 + g * g - s * s) / (2.0 * g), -1.0, 1.0);
    }
    let sin_theta = sqrt(max(1.0 - cos_theta * cos_theta, 0.0));
    let phi = 2.0 * PI * u2;
    let basis = onb(direction);
    return normalize(basis.t * (sin_theta * cos(phi)) + basis.b * (sin_theta * sin(phi)) + direction * cos_theta);
}

// Optical depths past MAX_OPTICAL_DEPTH are opaque: exactly zero, never a subnormal (medium.rs).
fn transmittance(sigma_t: vec3<f32>, distance: f32) -> vec3<f32> {
    let depth = sigma_t * distance;
    return select(exp(-min(depth, vec3(MAX_OPTICAL_DEPTH))), vec3(0.0), depth > vec3(MAX_OPTICAL_DEPTH));
}

fn is_vacuum(m: Medium) -> bool {
    return all(m.sigma_t == vec3(0.0));
}

fn scattering_albedo(m: Medium) -> vec3<f32> {
    return select(vec3(0.0), m.sigma_s / m.sigma_t, m.sigma_t > vec3(0.0));
}

struct FreeFlight {
    weight: vec3<f32>,
    t: f32,
    scattered: bool,
}

// Free flight through m over a segment of length t_max (MEDIUM_FAR: the ray left the scene). Draws
// two numbers where the medium scatters, none otherwise.
fn free_flight(m: Medium, t_max: f32, rng: ptr<function, Sampler>) -> FreeFlight {
    if (all(m.sigma_s == vec3(0.0))) {
        return FreeFlight(transmittance(m.sigma_t, t_max), t_max, false);
    }
    let u_channel = rng_next(rng);
    let u_distance = rng_next(rng);
    let sigma = m.sigma_t[u32(min(u_channel * 3.0, 2.0))];
    var t = MEDIUM_FAR;
    if (sigma > 0.0) {
        t = -log(1.0 - u_distance) / sigma;
    }
    if (t < t_max) {
        let tr = transmittance(m.sigma_t, t);
        let pdf = dot(m.sigma_t * tr, vec3(1.0)) / 3.0;
        return FreeFlight(select(vec3(0.0), m.sigma_s * tr / pdf, pdf > 0.0), t, true);
    }
    let tr = transmittance(m.sigma_t, t_max);
    let pdf = dot(tr, vec3(1.0)) / 3.0;
    return FreeFlight(select(vec3(0.0), tr / pdf, pdf > 0.0), t_max, false);
}
