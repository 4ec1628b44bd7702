//! Thin-film interference (`KHR_materials_iridescence`): Belcour and Barla 2017's Airy summation
//! of a film of index n_f and thickness d over a base, integrated against the CIE colour matching
//! functions in Fourier space (their Gaussian fits), as the glTF extension specifies it; mirrored
//! one-to-one in `iridescence.wgsl` beside it.
//!
//! With cosθ1 outside the film and cosθ2 inside it (Snell, n_f ← 1 as d → 0 so a vanishing film
//! vanishes), R12 = F_schlick(R0(n_f, 1), cosθ1), T121 = 1 − R12, R23 = F_schlick(R0(n_b, n_f),
//! cosθ2) per channel with the base's index n_b from its F0, phase shifts φ21 = π − φ12 (φ12 = π
//! where the film is less dense than the outside), φ23 = π where the base is less dense than the
//! film, the optical path difference OPD = 2 n_f d cosθ2, and R123 = R12 R23:
//!
//!   I = R12 + Rs + Σ_{m=1,2} 2 (Rs − T121) √R123^m S(m·OPD, m·(φ21 + φ23)),
//!   Rs = T121² R23 / (1 − R123),
//!
//! S the sensitivity's Fourier transform in linear Rec. 709 RGB. Total internal reflection into the
//! film reflects everything. The result is clamped to [0, 1] (the fits can leave the gamut).

/// The WGSL twin of this module, `iridescence.wgsl` beside it (composed into the kernels by
/// `rt_gpu::shaders`).
pub const WGSL: &str = include_str!("iridescence.wgsl");

use glam::{Mat3, Vec3};

/// R0 of an interface between indices `t` and `i`.
fn r0(t: f32, i: f32) -> f32 {
    let r = (t - i) / (t + i);
    r * r
}

fn schlick(f0: f32, cos: f32) -> f32 {
    let x = 1.0 - cos.clamp(0.0, 1.0);
    f0 + (1.0 - f0) * (x * x * x * x * x)
}

/// The colour matching functions' response to an optical path difference `opd` (nm) with phase
/// shifts `shift`, in linear Rec. 709 RGB.
fn sensitivity(opd: f32, shift: Vec3) -> Vec3 {
    let tau = std::f32::consts::TAU;
    let phase = tau * opd * 1.0e-9;
    let val = Vec3::new(5.4856e-13, 4.4201e-13, 5.2481e-13);
    let pos = Vec3::new(1.6810e+06, 1.7953e+06, 2.2084e+06);
    let var = Vec3::new(4.3278e+09, 9.3046e+09, 6.6121e+09);
    let cos = |v: Vec3| Vec3::new(v.x.cos(), v.y.cos(), v.z.cos());
    let exp = |v: Vec3| Vec3::new(v.x.exp(), v.y.exp(), v.z.exp());
    let sqrt = |v: Vec3| Vec3::new(v.x.sqrt(), v.y.sqrt(), v.z.sqrt());
    let mut xyz = val * sqrt(tau * var) * cos(pos * phase + shift) * exp(-(phase * phase) * var);
    xyz.x += 9.7470e-14
        * (tau * 4.5282e+09f32).sqrt()
        * (2.2399e+06 * phase + shift.x).cos()
        * (-4.5282e+09 * phase * phase).exp();
    xyz /= 1.0685e-7;
    // CIE XYZ to linear Rec. 709 (rows).
    let to_rgb = Mat3::from_cols(
        Vec3::new(3.240_454_2, -0.969_266, 0.055_643_4),
        Vec3::new(-1.537_138_5, 1.876_010_8, -0.204_025_9),
        Vec3::new(-0.498_531_4, 0.041_556, 1.057_225_2),
    );
    to_rgb * xyz
}

/// The film's reflectance at cosine `cos1` outside it (outside index 1), for a film of index
/// `film_ior` and thickness `thickness` (nm) over a base whose reflectance at normal incidence is
/// `base_f0`.
pub fn thin_film_fresnel(cos1: f32, film_ior: f32, thickness: f32, base_f0: Vec3) -> Vec3 {
    let outside = 1.0;
    let t = (thickness / 0.03).clamp(0.0, 1.0);
    let n_f = outside + (film_ior - outside) * (t * t * (3.0 - 2.0 * t));
    let sin2 = (outside / n_f) * (outside / n_f) * (1.0 - cos1 * cos1);
    let cos2_sq = 1.0 - sin2;
    if cos2_sq < 0.0 {
        return Vec3::ONE;
    }
    let cos2 = cos2_sq.sqrt();
    let r12 = schlick(r0(n_f, outside), cos1);
    let t121 = 1.0 - r12;
    let phi12 = if n_f < outside {
        std::f32::consts::PI
    } else {
        0.0
    };
    let phi21 = std::f32::consts::PI - phi12;
    let f0 = base_f0.clamp(Vec3::ZERO, Vec3::splat(0.9999));
    let s = Vec3::new(f0.x.sqrt(), f0.y.sqrt(), f0.z.sqrt());
    let base_ior = (Vec3::ONE + s) / (Vec3::ONE - s);
    let r23 = Vec3::new(
        schlick(r0(base_ior.x, n_f), cos2),
        schlick(r0(base_ior.y, n_f), cos2),
        schlick(r0(base_ior.z, n_f), cos2),
    );
    let phi23 = Vec3::select(
        base_ior.cmplt(Vec3::splat(n_f)),
        Vec3::splat(std::f32::consts::PI),
        Vec3::ZERO,
    );
    let opd = 2.0 * n_f * thickness * cos2;
    let phi = Vec3::splat(phi21) + phi23;
    let r123 = (r12 * r23).clamp(Vec3::splat(1e-5), Vec3::splat(0.9999));
    let root = Vec3::new(r123.x.sqrt(), r123.y.sqrt(), r123.z.sqrt());
    let rs = t121 * t121 * r23 / (Vec3::ONE - r123);
    let mut i = Vec3::splat(r12) + rs;
    let mut cm = rs - Vec3::splat(t121);
    for m in 1..=2 {
        cm *= root;
        i += cm * 2.0 * sensitivity(m as f32 * opd, m as f32 * phi);
    }
    i.clamp(Vec3::ZERO, Vec3::ONE)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A vanishing film leaves the base's reflectance at normal incidence (within the fits' 1%:
    /// the formula's Schlick terms keep a grazing reflection even without a film, as the
    /// extension's reference does); a film over glass colours the reflection with thickness and
    /// angle and never leaves [0, 1].
    #[test]
    fn a_thin_film_colours_and_a_vanishing_one_does_not() {
        let f0 = Vec3::new(0.04, 0.5, 0.9);
        let none = thin_film_fresnel(1.0, 1.3, 0.0, f0);
        assert!((none - f0).abs().max_element() < 1e-2, "{none} vs {f0}");
        let mut colours = Vec::new();
        for d in [100.0, 250.0, 400.0, 800.0] {
            for cos in [0.2, 0.6, 1.0] {
                let f = thin_film_fresnel(cos, 1.3, d, Vec3::splat(0.04));
                assert!(f.min_element() >= 0.0 && f.max_element() <= 1.0);
                colours.push(f);
            }
        }
        // Interference tints: the channels differ, and differently at different thicknesses.
        let spread = |f: &Vec3| f.max_element() - f.min_element();
        assert!(colours.iter().any(|f| spread(f) > 0.05), "{colours:?}");
        assert!(colours.iter().any(|f| f.x > f.z) && colours.iter().any(|f| f.z > f.x));
    }
}
