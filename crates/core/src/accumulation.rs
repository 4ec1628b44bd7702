//! Exact per-pixel sums of samples, the CPU twin of `accumulation.wgsl` beside it.
//!
//! Each pixel accumulates four channels (red, green, blue and squared luminance), each a 128-bit
//! two's-complement fixed-point number with 64 fraction bits, stored as four `u32` words, least
//! significant first. Integer addition is associative, so a pixel's sum is the same bit for bit
//! however its samples were batched, tiled, split across machines and merged (`rt-cli merge`);
//! float running means are not. A sample converts exactly when it is at least 2^-41 (24
//! significant bits above the 2^-64 step), and smaller ones are truncated at 2^-64 ≈ 5.4e-20.
//! The sums hold up to 2^63 ≈ 9.2e18 per channel: with `MAX_SAMPLE` per sample that is 2^19
//! samples of the brightest value a sample may have, and far more of real ones.

/// The WGSL twin of this module, `accumulation.wgsl` beside it (composed into the kernels by
/// `rt_gpu::shaders`).
pub const WGSL: &str = include_str!("accumulation.wgsl");

/// One channel's sum: 128-bit two's complement, 64 fraction bits, least significant word first.
pub type FixedSum = [u32; 4];

/// A pixel's sums of red, green, blue and squared luminance.
pub type PixelSums = [FixedSum; 4];

/// Bytes of `PixelSums` (what the kernels' accumulation buffers hold per pixel).
pub const PIXEL_SUMS_BYTES: u64 = 64;

/// Bytes per pixel of each of the kernels' four accumulation buffers (one channel's sum each), the
/// size the adapter's binding limit applies to.
pub const CHANNEL_SUM_BYTES: u64 = 16;

/// A sample channel at or above this (2^44 ≈ 1.8e13) counts as dropped, like NaN and infinity;
/// the kernels do the same.
pub const MAX_SAMPLE: f32 = 17_592_186_044_416.0;

/// Squared luminance is clamped to this (2^50) so that a firefly cannot overflow its sum.
pub const MAX_SQUARED: f32 = 1_125_899_906_842_624.0;

/// `v` in the fixed-point format (exact for |v| ≥ 2^-41 and below 2^62; truncated towards zero
/// at 2^-64), from its bits as `to_fixed` in `accumulate.wgsl`: |v| = m × 2^(e − 150) is m shifted
/// by e − 86 steps of 2^-64.
pub fn to_fixed(v: f32) -> FixedSum {
    let bits = v.to_bits();
    let biased = (bits >> 23) & 0xff;
    let m = u128::from((bits & 0x7f_ffff) | 0x80_0000);
    let shift = biased as i32 - 86;
    let magnitude = match biased {
        0 => 0,
        _ if shift < 0 => m.checked_shr(shift.unsigned_abs()).unwrap_or(0),
        _ => m.checked_shl(shift as u32).unwrap_or(0),
    };
    let words = from_u128(magnitude);
    if v < 0.0 { negate(words) } else { words }
}

/// `a + b`, wrapping like the kernels' 128-bit addition.
pub fn add(a: FixedSum, b: FixedSum) -> FixedSum {
    let a = to_u128(a);
    let b = to_u128(b);
    from_u128(a.wrapping_add(b))
}

/// `-m` in two's complement.
pub fn negate(m: FixedSum) -> FixedSum {
    from_u128(to_u128(m).wrapping_neg())
}

/// The sum as a number (rounded to f64).
pub fn to_f64(m: FixedSum) -> f64 {
    let signed = to_u128(m) as i128;
    // i128 -> f64 rounds once; the scale is a power of two, exact.
    signed as f64 * (-64f64).exp2()
}

/// Adds one sample (radiance `rgb`) to a pixel, as the kernels do; false (and nothing added) when
/// the sample is dropped (a channel not finite or at least `MAX_SAMPLE`).
pub fn add_sample(sums: &mut PixelSums, rgb: [f32; 3]) -> bool {
    if !rgb.iter().all(|c| c.is_finite() && c.abs() < MAX_SAMPLE) {
        return false;
    }
    let lum = crate::math::sampling::luminance(glam::Vec3::from(rgb));
    let squared = (lum * lum).min(MAX_SQUARED);
    for (sum, v) in sums.iter_mut().zip([rgb[0], rgb[1], rgb[2], squared]) {
        *sum = add(*sum, to_fixed(v));
    }
    true
}

/// Adds light that lands in a pixel from elsewhere (bidirectional path tracing's light tracing) to
/// its radiance sums, not to its squared luminance: it is no sample of its own. A value that is
/// not finite or absurdly large is dropped, as `add_sample` drops it.
pub fn add_splat(sums: &mut PixelSums, rgb: [f32; 3]) -> bool {
    if !rgb.iter().all(|c| c.is_finite() && c.abs() < MAX_SAMPLE) {
        return false;
    }
    for (sum, v) in sums.iter_mut().zip(rgb) {
        *sum = add(*sum, to_fixed(v));
    }
    true
}

/// Adds two pixels' sums (the merge of two disjoint sets of samples).
pub fn add_pixels(a: &PixelSums, b: &PixelSums) -> PixelSums {
    [0, 1, 2, 3].map(|c| add(a[c], b[c]))
}

/// The mean radiance and mean squared luminance of `count` samples with these sums (zeros for
/// none): what the rest of rt calls a pixel.
pub fn pixel_mean(sums: &PixelSums, count: u32) -> [f32; 4] {
    if count == 0 {
        return [0.0; 4];
    }
    let n = f64::from(count);
    sums.map(|s| (to_f64(s) / n) as f32)
}

fn to_u128(m: FixedSum) -> u128 {
    m.iter()
        .rev()
        .fold(0u128, |acc, &w| (acc << 32) | u128::from(w))
}

fn from_u128(v: u128) -> FixedSum {
    [0, 1, 2, 3].map(|k| (v >> (32 * k)) as u32)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The exact value of `v` times 2^64, as an integer (for f32 that are multiples of 2^-64).
    fn exact(v: f32) -> i128 {
        let v = f64::from(v);
        (v * 64f64.exp2()) as i128
    }

    #[test]
    fn conversion_is_exact_across_the_range() {
        for e in -41..62 {
            for mantissa in [1.0f32, 1.5, 1.999_999_9, 1.234_567_8] {
                let v = mantissa * (e as f32).exp2();
                assert_eq!(to_u128(to_fixed(v)) as i128, exact(v), "{v:e}");
                assert_eq!(to_u128(to_fixed(-v)) as i128, -exact(v), "{v:e}");
                assert_eq!(to_f64(to_fixed(v)), f64::from(v));
            }
        }
        assert_eq!(to_fixed(0.0), [0; 4]);
        // Below 2^-64 nothing is left.
        assert_eq!(to_fixed(1e-21), [0; 4]);
    }

    #[test]
    fn sums_do_not_depend_on_grouping() {
        let mut state = 12345u64;
        let mut next = || {
            state = state
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            let x = (state >> 40) as f32 / (1u64 << 24) as f32;
            x.powi(8) * 1e4
        };
        let samples: Vec<[f32; 3]> = (0..1000).map(|_| [next(), next(), next()]).collect();
        let mut whole = PixelSums::default();
        for s in &samples {
            assert!(add_sample(&mut whole, *s));
        }
        let (mut a, mut b) = (PixelSums::default(), PixelSums::default());
        for s in &samples[..377] {
            add_sample(&mut a, *s);
        }
        for s in &samples[377..] {
            add_sample(&mut b, *s);
        }
        assert_eq!(add_pixels(&a, &b), whole);
        assert_eq!(add_pixels(&b, &a), whole);
        let mean = pixel_mean(&whole, 1000)[0] as f64;
        let direct = samples.iter().map(|s| f64::from(s[0])).sum::<f64>() / 1000.0;
        assert!((mean - direct).abs() <= 1e-6 * direct, "{mean} vs {direct}");
    }

    #[test]
    fn dropped_samples_add_nothing() {
        let mut sums = PixelSums::default();
        assert!(!add_sample(&mut sums, [f32::NAN, 0.0, 0.0]));
        assert!(!add_sample(&mut sums, [0.0, f32::INFINITY, 0.0]));
        assert!(!add_sample(&mut sums, [0.0, 0.0, MAX_SAMPLE]));
        assert_eq!(sums, PixelSums::default());
        assert!(add_sample(&mut sums, [1e12, 1e12, 1e12]));
        assert_eq!(to_f64(sums[3]), f64::from(MAX_SQUARED));
        // The sign bit is clear: the clamped square did not overflow its sum.
        assert_eq!(sums[3][3] & 0x8000_0000, 0);
    }
}
