//! Goodness-of-fit helpers for the sampling tests (test builds only).

/// The standard normal quantile (Acklam's rational approximation, relative error < 1.2e-9).
pub fn normal_quantile(p: f64) -> f64 {
    const A: [f64; 6] = [
        -3.969_683_028_665_376e1,
        2.209_460_984_245_205e2,
        -2.759_285_104_469_687e2,
        1.383_577_518_672_69e2,
        -3.066_479_806_614_716e1,
        2.506_628_277_459_239,
    ];
    const B: [f64; 5] = [
        -5.447_609_879_822_406e1,
        1.615_858_368_580_409e2,
        -1.556_989_798_598_866e2,
        6.680_131_188_771_972e1,
        -1.328_068_155_288_572e1,
    ];
    const C: [f64; 6] = [
        -7.784_894_002_430_293e-3,
        -3.223_964_580_411_365e-1,
        -2.400_758_277_161_838,
        -2.549_732_539_343_734,
        4.374_664_141_464_968,
        2.938_163_982_698_783,
    ];
    const D: [f64; 4] = [
        7.784_695_709_041_462e-3,
        3.224_671_290_700_398e-1,
        2.445_134_137_142_996,
        3.754_408_661_907_416,
    ];
    let tail = |q: f64| {
        (((((C[0] * q + C[1]) * q + C[2]) * q + C[3]) * q + C[4]) * q + C[5])
            / ((((D[0] * q + D[1]) * q + D[2]) * q + D[3]) * q + 1.0)
    };
    if p < 0.02425 {
        tail((-2.0 * p.ln()).sqrt())
    } else if p > 1.0 - 0.02425 {
        -tail((-2.0 * (1.0 - p).ln()).sqrt())
    } else {
        let q = p - 0.5;
        let r = q * q;
        (((((A[0] * r + A[1]) * r + A[2]) * r + A[3]) * r + A[4]) * r + A[5]) * q
            / (((((B[0] * r + B[1]) * r + B[2]) * r + B[3]) * r + B[4]) * r + 1.0)
    }
}

/// The chi-square value with `dof` degrees of freedom that one of `tests` independent tests
/// exceeds by chance with probability 1 − (1 − α)^(1/tests) (Šidák), so that all of them together
/// fail by chance with probability α (Wilson–Hilferty's approximation of the quantile).
pub fn chi2_limit(dof: usize, tests: usize, alpha: f64) -> f64 {
    let per_test = 1.0 - (1.0 - alpha).powf(1.0 / tests as f64);
    let z = normal_quantile(1.0 - per_test);
    let k = dof as f64;
    k * (1.0 - 2.0 / (9.0 * k) + z * (2.0 / (9.0 * k)).sqrt()).powi(3)
}

/// Pearson's statistic over bins, pooling bins expected to hold fewer than 5 (and their counts)
/// into one; returns (statistic, degrees of freedom).
pub fn pearson(counts: &[f64], expected: &[f64]) -> (f64, usize) {
    let (mut x, mut bins) = (0.0, 0usize);
    let (mut pooled_c, mut pooled_e) = (0.0, 0.0);
    for (&c, &e) in counts.iter().zip(expected) {
        if e < 5.0 {
            pooled_c += c;
            pooled_e += e;
        } else {
            x += (c - e).powi(2) / e;
            bins += 1;
        }
    }
    if pooled_e >= 5.0 {
        x += (pooled_c - pooled_e).powi(2) / pooled_e;
        bins += 1;
    } else if pooled_c > 0.0 && pooled_e <= 0.0 {
        // Samples where the pdf says none can land.
        return (f64::INFINITY, bins.max(1));
    }
    (x, bins.saturating_sub(1).max(1))
}

const THETA_BINS: usize = 20;
const PHI_BINS: usize = 24;

/// The (cosθ, φ) bin of a direction on the sphere: 20 × 24 bins of equal solid angle.
fn sphere_bin(w: glam::Vec3) -> usize {
    let c = ((w.z + 1.0) * 0.5 * THETA_BINS as f32).clamp(0.0, THETA_BINS as f32 - 1.0);
    let phi = w.y.atan2(w.x).rem_euclid(std::f32::consts::TAU);
    let p = (phi / std::f32::consts::TAU * PHI_BINS as f32).min(PHI_BINS as f32 - 1.0);
    c as usize * PHI_BINS + p as usize
}

/// Each sphere bin's probability under `pdf` (solid angle), by a 24 × 24 midpoint rule per bin.
fn sphere_masses(pdf: impl Fn(glam::Vec3) -> f32) -> Vec<f64> {
    const SUB: usize = 24;
    let mut masses = vec![0.0f64; THETA_BINS * PHI_BINS];
    let dc = 2.0 / (THETA_BINS * SUB) as f64;
    let dphi = std::f64::consts::TAU / (PHI_BINS * SUB) as f64;
    for i in 0..THETA_BINS * SUB {
        let c = -1.0 + (i as f64 + 0.5) * dc;
        let s = (1.0 - c * c).max(0.0).sqrt();
        for j in 0..PHI_BINS * SUB {
            let phi = (j as f64 + 0.5) * dphi;
            let wi = glam::Vec3::new((s * phi.cos()) as f32, (s * phi.sin()) as f32, c as f32);
            masses[(i / SUB) * PHI_BINS + j / SUB] += f64::from(pdf(wi)) * dc * dphi;
        }
    }
    masses
}

/// Checks that `n` directions drawn by `sample` (from three uniform numbers; `None`: no sample)
/// follow `pdf`, including the mass of the draws that produce nothing: chi-square over 480 sphere
/// bins plus that outcome, Šidák-corrected over `tests` such checks at α = 1e-3. Panics naming
/// `what`; also checks the pdf integrates to at most 1.
pub fn check_sphere_sampling(
    what: &str,
    n: usize,
    tests: usize,
    seed: u32,
    sample: impl Fn(f32, f32, f32) -> Option<glam::Vec3>,
    pdf: impl Fn(glam::Vec3) -> f32,
) {
    let mut counts = vec![0.0f64; THETA_BINS * PHI_BINS + 1];
    let mut rng = super::rng::Rng::new(seed, 0, 77);
    for _ in 0..n {
        let (a, u1, u2) = (rng.next_f32(), rng.next_f32(), rng.next_f32());
        match sample(a, u1, u2) {
            Some(wi) => counts[sphere_bin(wi)] += 1.0,
            None => counts[THETA_BINS * PHI_BINS] += 1.0,
        }
    }
    let masses = sphere_masses(pdf);
    let total: f64 = masses.iter().sum();
    assert!(
        total <= 1.0 + 5e-3,
        "{what}: the pdf integrates to {total} > 1"
    );
    let mut expected: Vec<f64> = masses.iter().map(|p| p * n as f64).collect();
    expected.push((1.0 - total).max(0.0) * n as f64);
    let (x, dof) = pearson(&counts, &expected);
    let limit = chi2_limit(dof, tests, 1e-3);
    assert!(
        x < limit,
        "{what}: chi-square {x:.1} over {dof} dof exceeds {limit:.1}"
    );
}

/// The mean of `f` over `n` triples of uniform numbers, and its standard error.
pub fn estimate(n: usize, seed: u32, f: impl Fn(f32, f32, f32) -> f64) -> (f64, f64) {
    let mut rng = super::rng::Rng::new(seed, 0, 11);
    let (mut sum, mut sum_sq) = (0.0f64, 0.0f64);
    for _ in 0..n {
        let w = f(rng.next_f32(), rng.next_f32(), rng.next_f32());
        sum += w;
        sum_sq += w * w;
    }
    let mean = sum / n as f64;
    let var = (sum_sq / n as f64 - mean * mean).max(0.0);
    (mean, (var / n as f64).sqrt())
}

#[cfg(test)]
mod tests {
    #[test]
    fn normal_quantiles_match_tables() {
        assert!((super::normal_quantile(0.975) - 1.959_964).abs() < 1e-5);
        assert!((super::normal_quantile(0.999) - 3.090_232).abs() < 1e-5);
        assert!((super::normal_quantile(0.5)).abs() < 1e-12);
    }
}
