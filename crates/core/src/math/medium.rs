//! Homogeneous participating media: the Henyey–Greenstein phase function, free-flight sampling and
//! transmittance. Mirrored one-to-one in `medium.wgsl` beside it.
//!
//! A medium (`gpu_types::Medium`) has an extinction σ_t = σ_a + σ_s and a scattering coefficient
//! σ_s per RGB channel (per scene unit), and a phase function p(θ) of the angle θ between the
//! direction light travels and the one it scatters into:
//!
//!   p_HG(cosθ) = (1 − g²) / (4π (1 + g² − 2g cosθ)^{3/2}),   ∫ p dω = 1,  E[cosθ] = g.
//!
//! Along a segment of length d the transmittance is T(d) = exp(−σ_t d) per channel. A path crossing
//! a medium samples where it next interacts (free flight) with one channel's density picked
//! uniformly — the one-sample spectral MIS of pbrt-v4 and Mitsuba's `volpath` — so the pdf of a
//! collision at t is the channels' mean p(t) = ⅓ Σ_c σ_t,c T_c(t), and that of passing the whole
//! segment of length t_max is ⅓ Σ_c T_c(t_max). The throughput is then multiplied by
//!
//!   scattered at t:  σ_s T(t) / p(t),      passed:  T(t_max) / ⅓ Σ_c T_c(t_max),
//!
//! unbiased for every channel at once. With a grey σ_t these are the albedo σ_s/σ_t and 1. A medium
//! that only absorbs (σ_s = 0) takes T(t_max) outright and draws nothing. A ray that leaves the
//! scene travels t_max = ∞ (`FAR`): in a medium that dims every channel it always scatters.
//!
//! Grid (heterogeneous) media fit the same interface: `free_flight` and `transmittance` would walk a
//! majorant grid with delta and ratio tracking; the path code calls only these two and the phase
//! function.

/// The WGSL twin of this module, `medium.wgsl` beside it (composed into the kernels by
/// `rt_gpu::shaders`).
pub const WGSL: &str = include_str!("medium.wgsl");

use glam::Vec3;

use crate::gpu_types::Medium;
use crate::math::rng::Rng;
use crate::math::sampling::onb;

/// The length of a ray that leaves the scene (`trace`'s `f32::MAX` stand-in in WGSL).
pub const FAR: f32 = 3.0e38;

/// Optical depths beyond this are taken as opaque (e^−80 ≈ 2·10⁻³⁵): exactly zero, so that a shadow
/// ray with no light left is not traced, and never a subnormal, which GPUs flush to zero and the
/// CPU does not.
const MAX_OPTICAL_DEPTH: f32 = 80.0;

/// The Henyey–Greenstein phase function at cosθ (θ from the direction of travel), per steradian.
pub fn hg_phase(cos_theta: f32, g: f32) -> f32 {
    let denom = 1.0 + g * g - 2.0 * g * cos_theta;
    (1.0 - g * g) / (4.0 * std::f32::consts::PI * denom * denom.max(1e-12).sqrt())
}

/// A direction scattered from one travelling along `direction` with density `hg_phase(cosθ, g)`
/// (inverting the CDF of cosθ; uniform on the sphere for |g| < 1e-3).
pub fn sample_hg(direction: Vec3, g: f32, u1: f32, u2: f32) -> Vec3 {
    let cos_theta = if g.abs() < 1e-3 {
        1.0 - 2.0 * u1
    } else {
        let s = (1.0 - g * g) / (1.0 - g + 2.0 * g * u1);
        ((1.0 + g * g - s * s) / (2.0 * g)).clamp(-1.0, 1.0)
    };
    let sin_theta = (1.0 - cos_theta * cos_theta).max(0.0).sqrt();
    let phi = 2.0 * std::f32::consts::PI * u2;
    let (t, b) = onb(direction);
    (t * (sin_theta * phi.cos()) + b * (sin_theta * phi.sin()) + direction * cos_theta).normalize()
}

/// exp(−σ_t d) per channel.
pub fn transmittance(sigma_t: Vec3, distance: f32) -> Vec3 {
    let depth = sigma_t * distance;
    Vec3::select(
        depth.cmpgt(Vec3::splat(MAX_OPTICAL_DEPTH)),
        Vec3::ZERO,
        (-depth).exp(),
    )
}

/// Whether a medium changes light at all (vacuum does not: nothing is sampled in it).
pub fn is_vacuum(m: &Medium) -> bool {
    Vec3::from(m.sigma_t) == Vec3::ZERO
}

/// The medium's single-scattering albedo σ_s/σ_t per channel (0 where it is vacuum).
pub fn scattering_albedo(m: &Medium) -> Vec3 {
    let (sigma_t, sigma_s) = (Vec3::from(m.sigma_t), Vec3::from(m.sigma_s));
    Vec3::select(sigma_t.cmpgt(Vec3::ZERO), sigma_s / sigma_t, Vec3::ZERO)
}

/// Where a path crossing a medium next interacts, within `t_max`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct FreeFlight {
    /// The distance to the scattering event, or `t_max` where the path passed.
    pub t: f32,
    /// What the throughput is multiplied by (see the module's equations).
    pub weight: Vec3,
    pub scattered: bool,
}

/// Free flight through `m` over a segment of length `t_max` (`FAR`: the ray left the scene). Draws
/// two numbers where the medium scatters, none otherwise.
pub fn free_flight(m: &Medium, t_max: f32, rng: &mut Rng) -> FreeFlight {
    let sigma_t = Vec3::from(m.sigma_t);
    let sigma_s = Vec3::from(m.sigma_s);
    if sigma_s == Vec3::ZERO {
        return FreeFlight {
            t: t_max,
            weight: transmittance(sigma_t, t_max),
            scattered: false,
        };
    }
    let u_channel = rng.next_f32();
    let u_distance = rng.next_f32();
    let sigma = sigma_t[(u_channel * 3.0).min(2.0) as usize];
    let t = if sigma > 0.0 {
        -(1.0 - u_distance).ln() / sigma
    } else {
        FAR
    };
    if t < t_max {
        let tr = transmittance(sigma_t, t);
        let pdf = (sigma_t * tr).dot(Vec3::ONE) / 3.0;
        let weight = if pdf > 0.0 {
            sigma_s * tr / pdf
        } else {
            Vec3::ZERO
        };
        return FreeFlight {
            t,
            weight,
            scattered: true,
        };
    }
    let tr = transmittance(sigma_t, t_max);
    let pdf = tr.dot(Vec3::ONE) / 3.0;
    FreeFlight {
        t: t_max,
        weight: if pdf > 0.0 { tr / pdf } else { Vec3::ZERO },
        scattered: false,
    }
}

/// (Host side only: materials are converted once, so this has no WGSL twin.) The single-scattering
/// albedo ρ of a medium whose multiple scattering looks like `c` (the albedo
/// of a semi-infinite slab of it): the inversion `KHR_materials_volume_scatter`'s `multiscatterColor`
/// and Cycles' random walk use (Chiang et al. 2016),
///   ρ = 1 − (4.09712 + 4.20863 c − √(9.59217 + 41.6808 c + 17.7126 c²))².
pub fn single_scatter_albedo(c: f32) -> f32 {
    // Exact at the ends (the fit gives ~6·10⁻⁶ at 0): black absorbs only, and then free flight
    // takes the transmittance outright.
    if c.is_nan() || c <= 0.0 {
        return 0.0;
    }
    if c >= 1.0 {
        return 1.0;
    }
    let s = 4.09712 + 4.20863 * c - (9.59217 + 41.6808 * c + 17.7126 * c * c).sqrt();
    (1.0 - s * s).clamp(0.0, 1.0)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::math::stats::{chi2_limit, pearson};

    fn medium(sigma_t: Vec3, sigma_s: Vec3, g: f32) -> Medium {
        Medium {
            sigma_t: sigma_t.into(),
            anisotropy: g,
            sigma_s: sigma_s.into(),
            _pad: 0.0,
        }
    }

    /// ∫ p dω = 1 and ∫ p cosθ dω = g, by quadrature over cosθ (p depends on θ alone).
    #[test]
    fn hg_integrates_to_one_with_mean_cosine_g() {
        for g in [-0.95, -0.5, 0.0, 0.3, 0.9, 0.99] {
            let n = 200_000;
            let (mut total, mut mean) = (0.0f64, 0.0f64);
            for i in 0..n {
                let mu = -1.0 + 2.0 * (i as f64 + 0.5) / n as f64;
                let p =
                    hg_phase(mu as f32, g) as f64 * 2.0 * std::f64::consts::PI * (2.0 / n as f64);
                total += p;
                mean += p * mu;
            }
            assert!((total - 1.0).abs() < 2e-3, "g {g}: ∫p = {total}");
            assert!((mean - g as f64).abs() < 2e-3, "g {g}: E[cos] = {mean}");
        }
    }

    /// Sampled directions follow `hg_phase` (chi-square over 40 bins of cosθ and 8 of φ, expected
    /// counts from the CDF), and the sample's cosθ is the one evaluated.
    #[test]
    fn hg_samples_follow_the_phase_function() {
        let direction = Vec3::new(0.3, -0.5, 0.8).normalize();
        let (t, b) = onb(direction);
        for g in [-0.7, 0.0, 0.5, 0.95] {
            let (bins_mu, bins_phi, n) = (40usize, 8usize, 400_000usize);
            let mut counts = vec![0.0f64; bins_mu * bins_phi];
            let mut rng = Rng::new(7, 0, 1);
            for _ in 0..n {
                let d = sample_hg(direction, g, rng.next_f32(), rng.next_f32());
                assert!((d.length() - 1.0).abs() < 1e-4);
                let mu = d.dot(direction).clamp(-1.0, 1.0);
                let phi = d.dot(b).atan2(d.dot(t)).rem_euclid(std::f32::consts::TAU);
                let i = (((mu + 1.0) * 0.5 * bins_mu as f32) as usize).min(bins_mu - 1);
                let j =
                    ((phi / std::f32::consts::TAU * bins_phi as f32) as usize).min(bins_phi - 1);
                counts[i * bins_phi + j] += 1.0;
            }
            // The CDF of cosθ, by quadrature of 2π p.
            let cdf = |mu: f64| {
                let steps = 4000;
                let h = (mu + 1.0) / steps as f64;
                (0..steps)
                    .map(|k| {
                        let m = -1.0 + (k as f64 + 0.5) * h;
                        hg_phase(m as f32, g) as f64 * 2.0 * std::f64::consts::PI * h
                    })
                    .sum::<f64>()
            };
            let mut expected = Vec::new();
            for i in 0..bins_mu {
                let lo = -1.0 + 2.0 * i as f64 / bins_mu as f64;
                let hi = -1.0 + 2.0 * (i + 1) as f64 / bins_mu as f64;
                let share = (cdf(hi) - cdf(lo)) / bins_phi as f64;
                expected.extend(std::iter::repeat_n(share * n as f64, bins_phi));
            }
            let (stat, dof) = pearson(&counts, &expected);
            assert!(
                stat < chi2_limit(dof, 4, 0.01),
                "g {g}: chi2 {stat} over {dof} dof"
            );
        }
    }

    /// A pure absorber's free flight is the slab's transmittance exp(−σ_t d), per channel, with no
    /// random numbers drawn.
    #[test]
    fn slab_transmittance_per_channel() {
        let m = medium(Vec3::new(0.5, 1.0, 2.0), Vec3::ZERO, 0.0);
        let mut rng = Rng::new(1, 0, 1);
        let mut before = rng;
        let f = free_flight(&m, 1.5, &mut rng);
        assert!(!f.scattered);
        let want = Vec3::new((-0.75f32).exp(), (-1.5f32).exp(), (-3.0f32).exp());
        assert!(
            (f.weight - want).abs().max_element() < 1e-6,
            "{:?}",
            f.weight
        );
        assert_eq!(rng.next_f32(), before.next_f32());
        assert_eq!(transmittance(Vec3::splat(1.0), FAR), Vec3::ZERO);
        assert_eq!(transmittance(Vec3::ZERO, FAR), Vec3::ONE);
    }

    /// The free-flight estimator is unbiased per channel, chromatic σ_t included: the expected
    /// weight of passing a slab is T(d), and the expected σ_s-weighted collision density over [0, d)
    /// integrates to what the medium scatters, ∫ σ_s T(t) dt = σ_s/σ_t (1 − T(d)).
    #[test]
    fn free_flight_is_unbiased_per_channel() {
        let sigma_t = Vec3::new(0.2, 1.0, 3.0);
        let sigma_s = Vec3::new(0.1, 0.8, 2.4);
        let m = medium(sigma_t, sigma_s, 0.0);
        let d = 1.3;
        let n = 400_000;
        let mut rng = Rng::new(3, 0, 1);
        let (mut pass, mut scatter) = (Vec3::ZERO, Vec3::ZERO);
        let (mut pass2, mut scatter2) = (Vec3::ZERO, Vec3::ZERO);
        for _ in 0..n {
            let f = free_flight(&m, d, &mut rng);
            if f.scattered {
                scatter += f.weight;
                scatter2 += f.weight * f.weight;
            } else {
                pass += f.weight;
                pass2 += f.weight * f.weight;
            }
        }
        let nf = n as f32;
        let check = |sum: Vec3, sum2: Vec3, want: Vec3, what: &str| {
            let mean = sum / nf;
            let se = ((sum2 / nf - mean * mean) / nf)
                .max(Vec3::splat(1e-12))
                .sqrt();
            let z = ((mean - want) / se).abs().max_element();
            assert!(z < 4.5, "{what}: mean {mean:?} want {want:?} (z {z})");
        };
        check(pass, pass2, transmittance(sigma_t, d), "passing");
        let scattered = sigma_s / sigma_t * (Vec3::ONE - transmittance(sigma_t, d));
        check(scatter, scatter2, scattered, "scattering");
    }

    /// The albedo inversion: 0 ↦ 0, 1 ↦ 1, increasing, and above c (each scattering absorbs a little,
    /// so to look c after many a medium must keep more than c at one).
    #[test]
    fn single_scatter_albedo_inverts_the_multiple_scattering_colour() {
        assert_eq!(single_scatter_albedo(0.0), 0.0);
        assert_eq!(single_scatter_albedo(1.0), 1.0);
        assert!(single_scatter_albedo(1e-3) < 0.05);
        let mut last = 0.0;
        for i in 1..100 {
            let c = i as f32 / 100.0;
            let a = single_scatter_albedo(c);
            assert!(a >= last && a >= c - 1e-6, "c {c}: {a}");
            last = a;
        }
    }
}
