// Sampling and shading formulas; mirrors crates/core/src/math/sampling.rs.

const PI: f32 = 3.14159265358979;
const TAU: f32 = 6.28318530717959;

struct Basis { t: vec3<f32>, b: vec3<f32> }

// Duff et al. 2017.
fn onb(n: vec3<f32>) -> Basis {
    let sign = select(-1.0, 1.0, n.z >= 0.0);
    let a = -1.0 / (sign + n.z);
    let b = n.x * n.y * a;
    return Basis(vec3(1.0 + sign * n.x * n.x * a, sign * b, -sign * n.x), vec3(b, sign + n.y * n.y * a, -n.y));
}

// pdf = cos(theta) / pi, so the Lambertian weight f cos / pdf is the albedo.
fn sample_cosine_hemisphere(n: vec3<f32>, rng: ptr<function, Sampler>) -> vec3<f32> {
    let u1 = rng_next(rng);
    let u2 = rng_next(rng);
    let r = sqrt(u1);
    let phi = TAU * u2;
    let basis = onb(n);
    return normalize(basis.t * (r * cos(phi)) + basis.b * (r * sin(phi)) + n * sqrt(max(1.0 - u1, 0.0)));
}

fn sample_unit_ball(rng: ptr<function, Sampler>) -> vec3<f32> {
    let z = 1.0 - 2.0 * rng_next(rng);
    let phi = TAU * rng_next(rng);
    let radius = pow(rng_next(rng), 1.0 / 3.0);
    let s = sqrt(max(1.0 - z * z, 0.0));
    return vec3(s * cos(phi), s * sin(phi), z) * radius;
}

fn sample_disk(rng: ptr<function, Sampler>) -> vec2<f32> {
    let r = sqrt(rng_next(rng));
    let phi = TAU * rng_next(rng);
    return vec2(r * cos(phi), r * sin(phi));
}

// Barycentrics of a point uniform over a triangle's area.
fn sample_triangle(u_a: f32, u_b: f32) -> vec3<f32> {
    let su = sqrt(u_a);
    return vec3(1.0 - su, u_b * su, (1.0 - u_b) * su);
}

// Exact unpolarised Fresnel reflectance; eta = n_transmitted / n_incident. 1 under total internal reflection.
fn fresnel_dielectric(cos_in: f32, eta: f32) -> f32 {
    let cos_i = clamp(cos_in, 0.0, 1.0);
    let sin2_t = (1.0 - cos_i * cos_i) / (eta * eta);
    if (sin2_t >= 1.0) {
        return 1.0;
    }
    let cos_t = sqrt(max(1.0 - sin2_t, 0.0));
    let r_parallel = (eta * cos_i - cos_t) / (eta * cos_i + cos_t);
    let r_perpendicular = (cos_i - eta * cos_t) / (cos_i + eta * cos_t);
    return 0.5 * (r_parallel * r_parallel + r_perpendicular * r_perpendicular);
}

fn refract_dir(d: vec3<f32>, n: vec3<f32>, eta: f32) -> vec3<f32> {
    let cos_i = -dot(d, n);
    let sin2_t = max(1.0 - cos_i * cos_i, 0.0) / (eta * eta);
    let cos_t = sqrt(max(1.0 - sin2_t, 0.0));
    return normalize(d / eta + n * (cos_i / eta - cos_t));
}

fn reflect_dir(d: vec3<f32>, n: vec3<f32>) -> vec3<f32> {
    return d - 2.0 * dot(d, n) * n;
}

// Fuzzy metal: the mirror direction plus `fuzz` times a uniform point in the unit ball, normalised
// (sampling.rs's `sample_metal` states its pdf).
fn sample_metal(d: vec3<f32>, n: vec3<f32>, fuzz: f32, rng: ptr<function, Sampler>) -> vec3<f32> {
    let ball = sample_unit_ball(rng) * fuzz;
    return normalize(reflect_dir(d, n) + ball);
}

struct DielectricSample {
    direction: vec3<f32>,
    refracted: bool,
}

// Smooth dielectric: reflection with probability F (exact Fresnel), else refraction; eta =
// n_transmitted / n_incident, and n faces -d.
fn sample_dielectric(d: vec3<f32>, n: vec3<f32>, eta: f32, rng: ptr<function, Sampler>) -> DielectricSample {
    let f = fresnel_dielectric(-dot(d, n), eta);
    if (rng_next(rng) < f) {
        return DielectricSample(reflect_dir(d, n), false);
    }
    return DielectricSample(refract_dir(d, n, eta), true);
}

fn srgb_to_linear(c: vec3<f32>) -> vec3<f32> {
    return select(pow((c + 0.055) / 1.055, vec3(2.4)), c / 12.92, c <= vec3(0.04045));
}

fn luminance(c: vec3<f32>) -> f32 {
    return dot(c, vec3(0.2126, 0.7152, 0.0722));
}
