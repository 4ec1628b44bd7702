//! Sampling and shading formulas, mirrored one-to-one in `sampling.wgsl` beside it.

/// The WGSL twin of this module, `sampling.wgsl` beside it (composed into the kernels by
/// `rt_gpu::shaders`).
pub const WGSL: &str = include_str!("sampling.wgsl");

use glam::Vec3;

use super::rng::Rng;

/// An orthonormal basis around unit `n` (Duff et al. 2017, "Building an Orthonormal Basis, Revisited").
pub fn onb(n: Vec3) -> (Vec3, Vec3) {
    let sign = 1.0f32.copysign(n.z);
    let a = -1.0 / (sign + n.z);
    let b = n.x * n.y * a;
    (
        Vec3::new(1.0 + sign * n.x * n.x * a, sign * b, -sign * n.x),
        Vec3::new(b, sign + n.y * n.y * a, -n.y),
    )
}

/// Cosine-weighted direction about `n`: pdf = cosθ/π (Malley's method).
pub fn sample_cosine_hemisphere(n: Vec3, rng: &mut Rng) -> Vec3 {
    let u1 = rng.next_f32();
    let u2 = rng.next_f32();
    let r = u1.sqrt();
    let phi = std::f32::consts::TAU * u2;
    let (t, b) = onb(n);
    (t * (r * phi.cos()) + b * (r * phi.sin()) + n * (1.0 - u1).max(0.0).sqrt()).normalize()
}

/// Uniform point in the unit ball (for metal fuzz): direction uniform on the sphere, radius ∛u.
pub fn sample_unit_ball(rng: &mut Rng) -> Vec3 {
    let z = 1.0 - 2.0 * rng.next_f32();
    let phi = std::f32::consts::TAU * rng.next_f32();
    let radius = rng.next_f32().cbrt();
    let s = (1.0 - z * z).max(0.0).sqrt();
    Vec3::new(s * phi.cos(), s * phi.sin(), z) * radius
}

/// Uniform point on the unit disk (thin lens), by polar mapping.
pub fn sample_disk(rng: &mut Rng) -> (f32, f32) {
    let r = rng.next_f32().sqrt();
    let phi = std::f32::consts::TAU * rng.next_f32();
    (r * phi.cos(), r * phi.sin())
}

/// Barycentrics of a point uniform over a triangle's area (the square-root warp).
pub fn sample_triangle(u_a: f32, u_b: f32) -> [f32; 3] {
    let su = u_a.sqrt();
    [1.0 - su, u_b * su, (1.0 - u_b) * su]
}

/// Exact unpolarised Fresnel reflectance of a smooth dielectric; `eta` = n_transmitted / n_incident,
/// `cos_i` the cosine on the incident side. Returns 1 under total internal reflection.
pub fn fresnel_dielectric(cos_i: f32, eta: f32) -> f32 {
    let cos_i = cos_i.clamp(0.0, 1.0);
    let sin2_t = (1.0 - cos_i * cos_i) / (eta * eta);
    if sin2_t >= 1.0 {
        return 1.0;
    }
    let cos_t = (1.0 - sin2_t).max(0.0).sqrt();
    let r_parallel = (eta * cos_i - cos_t) / (eta * cos_i + cos_t);
    let r_perpendicular = (cos_i - eta * cos_t) / (cos_i + eta * cos_t);
    0.5 * (r_parallel * r_parallel + r_perpendicular * r_perpendicular)
}

/// Refraction of unit `d` through a surface with unit normal `n` facing the incident side.
pub fn refract(d: Vec3, n: Vec3, eta: f32) -> Vec3 {
    let cos_i = -d.dot(n);
    let sin2_t = (1.0 - cos_i * cos_i).max(0.0) / (eta * eta);
    let cos_t = (1.0 - sin2_t).max(0.0).sqrt();
    (d / eta + n * (cos_i / eta - cos_t)).normalize()
}

pub fn reflect(d: Vec3, n: Vec3) -> Vec3 {
    d - 2.0 * d.dot(n) * n
}

/// Fuzzy metal: the mirror direction plus `fuzz` × a uniform point in the unit ball, normalised.
/// Its pdf about the mirror direction r, with c = ω·r, is (s₊³ − s₋³) / (4π fuzz³) where
/// s± = c ± √(c² − 1 + fuzz²) (s₋ clamped at 0) are where the ray from the origin along ω enters and
/// leaves the ball of radius fuzz around r; zero where c² < 1 − fuzz².
pub fn sample_metal(d: Vec3, n: Vec3, fuzz: f32, rng: &mut Rng) -> Vec3 {
    (reflect(d, n) + sample_unit_ball(rng) * fuzz).normalize()
}

/// Smooth dielectric: reflection with probability F (exact Fresnel), else refraction. Returns the
/// direction and whether it refracted. `eta` = n_transmitted / n_incident; `n` faces `−d`.
pub fn sample_dielectric(d: Vec3, n: Vec3, eta: f32, rng: &mut Rng) -> (Vec3, bool) {
    let f = fresnel_dielectric(-d.dot(n), eta);
    if rng.next_f32() < f {
        (reflect(d, n), false)
    } else {
        (refract(d, n, eta), true)
    }
}

/// sRGB transfer function, decoding an 8-bit value to linear.
pub fn srgb_to_linear(c: f32) -> f32 {
    if c <= 0.04045 {
        c / 12.92
    } else {
        ((c + 0.055) / 1.055).powf(2.4)
    }
}

pub fn luminance(c: Vec3) -> f32 {
    c.dot(Vec3::new(0.2126, 0.7152, 0.0722))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn fresnel_normal_incidence_is_four_percent_for_glass() {
        assert!((fresnel_dielectric(1.0, 1.5) - 0.04).abs() < 1e-6);
        assert!((fresnel_dielectric(1.0, 1.0 / 1.5) - 0.04).abs() < 1e-6);
        assert_eq!(
            fresnel_dielectric(0.1, 1.0 / 1.5),
            1.0,
            "total internal reflection"
        );
        assert!(
            fresnel_dielectric(0.5, 1.0).abs() < 1e-7,
            "index-matched interface reflects nothing"
        );
    }

    /// Points stay inside the triangle and are uniform over its area: each of the four sub-triangles
    /// cut by the edge midpoints receives a quarter of them (chi-square, 3 degrees of freedom).
    #[test]
    fn triangle_samples_are_uniform_and_inside() {
        let n = 40_000;
        let mut counts = [0usize; 4];
        let mut rng = Rng::new(1, 2, 3);
        for _ in 0..n {
            let b = sample_triangle(rng.next_f32(), rng.next_f32());
            assert!(
                b.iter().all(|&x| (0.0..=1.0).contains(&x))
                    && (b.iter().sum::<f32>() - 1.0).abs() < 1e-5,
                "{b:?}"
            );
            // The corner sub-triangle with barycentric > 1/2, else the middle one.
            counts[b.iter().position(|&x| x > 0.5).unwrap_or(3)] += 1;
        }
        let expected = n as f64 / 4.0;
        let chi2: f64 = counts
            .iter()
            .map(|&c| (c as f64 - expected).powi(2) / expected)
            .sum();
        assert!(
            chi2 < 16.27,
            "chi-square {chi2} over 3 dof exceeds the 0.001 quantile: {counts:?}"
        );
    }

    /// Cosine-weighted directions against their pdf cosθ/π: with u = sin²θ and φ, equal-probability
    /// bins are a uniform grid, so a chi-square test over 10 × 10 bins (99 degrees of freedom).
    #[test]
    fn cosine_hemisphere_samples_follow_their_pdf() {
        let n = Vec3::new(0.3, -0.5, 0.8).normalize();
        let (t, b) = onb(n);
        let mut counts = [[0usize; 10]; 10];
        let samples = 100_000;
        for i in 0..samples {
            let mut rng = Rng::new(i, 0, 9);
            let d = sample_cosine_hemisphere(n, &mut rng);
            let cos = d.dot(n);
            assert!(cos >= 0.0 && (d.length() - 1.0).abs() < 1e-5);
            let u = (1.0 - cos * cos).clamp(0.0, 0.999_999);
            let phi = d.dot(b).atan2(d.dot(t)).rem_euclid(std::f32::consts::TAU);
            let j = ((phi / std::f32::consts::TAU) * 10.0).min(9.0) as usize;
            counts[(u * 10.0) as usize][j] += 1;
        }
        let expected = samples as f64 / 100.0;
        let chi2: f64 = counts
            .iter()
            .flatten()
            .map(|&c| (c as f64 - expected).powi(2) / expected)
            .sum();
        // The 0.999 quantile of chi-square with 99 degrees of freedom is about 148.2.
        assert!(
            chi2 < 148.2,
            "chi-square {chi2} with 99 dof: cosine sampling does not match cos/π"
        );
    }

    /// The 0.999 quantile of chi-square with `dof` degrees of freedom (Wilson–Hilferty).
    fn chi2_quantile_999(dof: usize) -> f64 {
        let k = dof as f64;
        let z = 3.090_2;
        k * (1.0 - 2.0 / (9.0 * k) + z * (2.0 / (9.0 * k)).sqrt()).powi(3)
    }

    fn chi2(counts: &[usize], expected: &[f64]) -> f64 {
        counts
            .iter()
            .zip(expected)
            .map(|(&c, &e)| (c as f64 - e).powi(2) / e)
            .sum()
    }

    /// The fuzzy-metal pdf over directions as a function of c = ω·r (see `sample_metal`).
    fn metal_pdf(c: f64, fuzz: f64) -> f64 {
        let disc = c * c - 1.0 + fuzz * fuzz;
        if disc < 0.0 {
            return 0.0;
        }
        let s_hi = c + disc.sqrt();
        if s_hi <= 0.0 {
            return 0.0;
        }
        let s_lo = (c - disc.sqrt()).max(0.0);
        (s_hi.powi(3) - s_lo.powi(3)) / (4.0 * std::f64::consts::PI * fuzz.powi(3))
    }

    /// ∫ pdf dω over the band c ∈ [a, b] (all azimuths), by Simpson's rule.
    fn metal_band_probability(a: f64, b: f64, fuzz: f64) -> f64 {
        let steps = 400;
        let h = (b - a) / steps as f64;
        let mut sum = metal_pdf(a, fuzz) + metal_pdf(b, fuzz);
        for i in 1..steps {
            let w = if i % 2 == 1 { 4.0 } else { 2.0 };
            sum += w * metal_pdf(a + i as f64 * h, fuzz);
        }
        std::f64::consts::TAU * sum * h / 3.0
    }

    /// Fuzzy metal directions against their analytic pdf: 20 bands of c = ω·r (over the cone the
    /// fuzz ball allows) × 8 azimuth bins, for fuzz 0.2, 0.6 and 1. The pdf integrates to 1 first.
    #[test]
    fn fuzzy_metal_samples_follow_their_pdf() {
        let n = Vec3::new(0.2, 0.9, -0.3).normalize();
        let d = Vec3::new(0.5, -0.6, 0.4).normalize();
        let r = reflect(d, n);
        let (t, b) = onb(r);
        for fuzz in [0.2f32, 0.6, 1.0] {
            let f = f64::from(fuzz);
            let c_min = if f < 1.0 { (1.0 - f * f).sqrt() } else { 0.0 };
            let total = metal_band_probability(c_min, 1.0, f);
            assert!((total - 1.0).abs() < 1e-3, "pdf integrates to {total}");
            let (bands, sectors) = (20, 8);
            let samples = 160_000;
            let mut counts = vec![0usize; bands * sectors];
            for i in 0..samples {
                let mut rng = Rng::new(i, 7, (fuzz * 100.0) as u32);
                let w = sample_metal(d, n, fuzz, &mut rng);
                let c = f64::from(w.dot(r)).min(1.0);
                let band =
                    (((c - c_min) / (1.0 - c_min)) * bands as f64).clamp(0.0, bands as f64 - 1.0);
                let phi = w.dot(b).atan2(w.dot(t)).rem_euclid(std::f32::consts::TAU);
                let sector =
                    ((phi / std::f32::consts::TAU) * sectors as f32).min(sectors as f32 - 1.0);
                counts[band as usize * sectors + sector as usize] += 1;
            }
            let expected: Vec<f64> = (0..bands * sectors)
                .map(|k| {
                    let band = k / sectors;
                    let a = c_min + (1.0 - c_min) * band as f64 / bands as f64;
                    let b = c_min + (1.0 - c_min) * (band + 1) as f64 / bands as f64;
                    metal_band_probability(a, b, f) / sectors as f64 * samples as f64
                })
                .collect();
            // Pool the bins expected to get fewer than 5 samples (the rim of the fuzz = 1 cone).
            let (mut kept_c, mut kept_e) = (Vec::new(), Vec::new());
            let (mut pooled_c, mut pooled_e) = (0usize, 0.0f64);
            for (&c, &e) in counts.iter().zip(&expected) {
                if e >= 5.0 {
                    kept_c.push(c);
                    kept_e.push(e);
                } else {
                    pooled_c += c;
                    pooled_e += e;
                }
            }
            if pooled_e > 0.0 {
                kept_c.push(pooled_c);
                kept_e.push(pooled_e.max(1e-9));
            }
            assert!(kept_c.len() > 100);
            let x = chi2(&kept_c, &kept_e);
            let limit = chi2_quantile_999(kept_c.len() - 1);
            assert!(x < limit, "fuzz {fuzz}: chi-square {x:.1} > {limit:.1}");
        }
    }

    /// The dielectric picks reflection with probability F (chi-square over the two outcomes at
    /// several angles, entering and leaving), reflects about the normal, and refracts by Snell's law.
    #[test]
    fn dielectric_samples_follow_fresnel_and_snell() {
        let n = Vec3::Y;
        let mut x = 0.0;
        let mut dof = 0;
        for eta in [1.5f32, 1.0 / 1.5, 2.417] {
            for cos_i in [1.0f32, 0.8, 0.5, 0.2, 0.05] {
                let sin_i = (1.0 - cos_i * cos_i).sqrt();
                let d = Vec3::new(sin_i, -cos_i, 0.0);
                let f = fresnel_dielectric(cos_i, eta);
                let samples = 20_000;
                let mut refracted = 0usize;
                for i in 0..samples {
                    let mut rng = Rng::new(i, (eta * 1000.0) as u32, (cos_i * 1000.0) as u32);
                    let (w, through) = sample_dielectric(d, n, eta, &mut rng);
                    assert!((w.length() - 1.0).abs() < 1e-5);
                    if through {
                        refracted += 1;
                        // Snell: sinθt = sinθi / eta, on the far side, same plane of incidence.
                        assert!(w.y < 0.0 && w.z.abs() < 1e-6);
                        assert!((w.x - sin_i / eta).abs() < 1e-4, "{w} eta {eta}");
                    } else {
                        assert!((w - Vec3::new(sin_i, cos_i, 0.0)).length() < 1e-5);
                    }
                }
                if f > 0.0 && f < 1.0 {
                    let expected = [f as f64 * samples as f64, (1.0 - f as f64) * samples as f64];
                    if expected.iter().all(|&e| e >= 5.0) {
                        x += chi2(&[samples as usize - refracted, refracted], &expected);
                        dof += 1;
                    }
                } else {
                    assert_eq!(refracted == 0, f >= 1.0, "F = {f}");
                }
            }
        }
        assert!(dof >= 10);
        let limit = chi2_quantile_999(dof);
        assert!(x < limit, "chi-square {x:.1} over {dof} dof > {limit:.1}");
    }

    #[test]
    fn onb_is_orthonormal() {
        for n in [
            Vec3::Z,
            -Vec3::Z,
            Vec3::X,
            Vec3::new(1.0, 2.0, -3.0).normalize(),
        ] {
            let (t, b) = onb(n);
            assert!(t.dot(n).abs() < 1e-6 && b.dot(n).abs() < 1e-6 && t.dot(b).abs() < 1e-6);
            assert!((t.length() - 1.0).abs() < 1e-6 && (b.length() - 1.0).abs() < 1e-6);
        }
    }
}
