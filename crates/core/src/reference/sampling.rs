//! Sampling and shading formulas, mirrored one-to-one in `shaders/shared/sampling.wgsl`.

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
