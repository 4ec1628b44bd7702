//! The random numbers shared by the kernel (`rng.wgsl` beside it) and the CPU reference.
//! Two samplers:
//! - **independent**: one PCG stream per (pixel, sample, seed);
//! - **Sobol**: Owen-scrambled Sobol points (Burley 2020, "Practical Hash-based Owen Scrambling").
//!   Consecutive dimensions are taken in pairs from the (0,2)-sequence formed by Sobol's first two
//!   dimensions; each pair's point index is shuffled and its values Owen-scrambled by hashes of the
//!   pixel, the seed and the pair. The first 2^m samples of a pair are then a (0,m,2)-net (one point
//!   in every elementary interval of area 2^-m), pairs are independent of each other, and every
//!   sample is uniform: estimates stay unbiased, with less variance on smooth integrands.
//!
//! Either way any sample can be regenerated on its own, so the image does not depend on how samples
//! are split into dispatches.

/// The WGSL twin of this module, `rng.wgsl` beside it (composed into the kernels by
/// `rt_gpu::shaders`).
pub const WGSL: &str = include_str!("rng.wgsl");

/// PCG-RXS-M-XS hash of one 32-bit word (Jarzynski & Olano 2020).
#[inline(always)]
pub fn pcg_hash(input: u32) -> u32 {
    let state = input.wrapping_mul(747_796_405).wrapping_add(2_891_336_453);
    let word = ((state >> ((state >> 28) + 4)) ^ state).wrapping_mul(277_803_737);
    (word >> 22) ^ word
}

#[inline(always)]
fn laine_karras_permutation(v: u32, seed: u32) -> u32 {
    let mut x = v.wrapping_add(seed);
    x ^= x.wrapping_mul(0x6c50_b47c);
    x ^= x.wrapping_mul(0xb82f_1e52);
    x ^= x.wrapping_mul(0xc7af_e638);
    x ^= x.wrapping_mul(0x8d22_f6e6);
    x
}

/// A random permutation of [0, 2³²) that keeps aligned blocks of 2^k together (Owen scrambling
/// of the bits, as a hash).
pub fn nested_uniform_scramble(v: u32, seed: u32) -> u32 {
    laine_karras_permutation(v.reverse_bits(), seed).reverse_bits()
}

/// Sobol's second dimension: bit k of `i` adds direction number v_k, with v_0 = 2³¹ and
/// v_k = v_(k−1) ^ (v_(k−1) >> 1). (The WGSL loops over the bits; here a byte of `i` at a time
/// looks its XOR of direction numbers up: the same value, a quarter of the CPU backend's time in
/// random numbers otherwise.)
pub fn sobol_dim1(i: u32) -> u32 {
    xor_of_bytes(&SOBOL_DIM1_BYTES, i)
}

/// `sobol_dim1(i).reverse_bits()`, by tables of reversed direction numbers (a bit reversal is a
/// permutation of bits, so it distributes over XOR): the scramble reverses the value first.
#[inline(always)]
fn sobol_dim1_reversed(i: u32) -> u32 {
    xor_of_bytes(&SOBOL_DIM1_REVERSED_BYTES, i)
}

#[inline(always)]
fn xor_of_bytes(t: &[[u32; 256]; 4], i: u32) -> u32 {
    t[0][(i & 0xff) as usize]
        ^ t[1][((i >> 8) & 0xff) as usize]
        ^ t[2][((i >> 16) & 0xff) as usize]
        ^ t[3][(i >> 24) as usize]
}

/// `SOBOL_DIM1_BYTES[k][b]`: the XOR of the direction numbers of the set bits of byte `b` placed
/// at byte `k` of the index.
static SOBOL_DIM1_BYTES: [[u32; 256]; 4] = sobol_dim1_bytes();
static SOBOL_DIM1_REVERSED_BYTES: [[u32; 256]; 4] = reversed(sobol_dim1_bytes());

const fn reversed(mut table: [[u32; 256]; 4]) -> [[u32; 256]; 4] {
    let mut byte = 0;
    while byte < 4 {
        let mut b = 0;
        while b < 256 {
            table[byte][b] = table[byte][b].reverse_bits();
            b += 1;
        }
        byte += 1;
    }
    table
}

const fn sobol_dim1_bytes() -> [[u32; 256]; 4] {
    let mut directions = [0u32; 32];
    let mut v = 0x8000_0000u32;
    let mut k = 0;
    while k < 32 {
        directions[k] = v;
        v ^= v >> 1;
        k += 1;
    }
    let mut table = [[0u32; 256]; 4];
    let mut byte = 0;
    while byte < 4 {
        let mut b = 0;
        while b < 256 {
            let mut x = 0;
            let mut bit = 0;
            while bit < 8 {
                if b & (1 << bit) != 0 {
                    x ^= directions[8 * byte + bit];
                }
                bit += 1;
            }
            table[byte][b] = x;
            b += 1;
        }
        byte += 1;
    }
    table
}

/// The sampler of a render. Sobol is the default: at equal samples its error is 1.5–2× lower on
/// the Cornell box and it costs ~8% more time with the wavefront kernels (docs/quality.md), so it
/// is the better trade for every render; independent samples remain for tests whose statistics
/// need independent samples, and for comparison.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum SamplerKind {
    Independent,
    #[default]
    Sobol,
}

/// One sample's random numbers.
#[derive(Clone, Copy, Debug)]
pub struct Rng {
    state: u32,
    /// The sample's index, bit-reversed (the first step of every pair's index shuffle).
    reversed_index: u32,
    dim: u32,
    key: u32,
    sobol: bool,
    /// Sobol values of dimensions `block_start .. block_start + SOBOL_BLOCK`, computed together:
    /// each value is a chain of dependent multiplies, so one at a time the CPU waits on each;
    /// a block's independent chains overlap (the same values the WGSL draws one by one).
    block_start: u32,
    block: [u32; SOBOL_BLOCK],
}

/// Sobol dimensions computed at once (an even number: a block holds whole pairs; 16 measured
/// faster than 8 and level with 32, docs/performance-log.md).
const SOBOL_BLOCK: usize = 16;

impl Rng {
    /// The independent sampler.
    pub fn new(pixel: u32, sample: u32, seed: u32) -> Self {
        Self::with_sampler(pixel, sample, seed, SamplerKind::Independent)
    }

    pub fn with_sampler(pixel: u32, sample: u32, seed: u32, kind: SamplerKind) -> Self {
        Rng {
            state: pcg_hash(pixel.wrapping_add(pcg_hash(sample.wrapping_add(pcg_hash(seed))))),
            reversed_index: sample.reverse_bits(),
            dim: 0,
            key: pcg_hash(pixel ^ pcg_hash(seed ^ 0x5bd1_e995)),
            sobol: kind == SamplerKind::Sobol,
            // No block yet: `dim - block_start` is at least SOBOL_BLOCK for dimension 0.
            block_start: SOBOL_BLOCK as u32,
            block: [0; SOBOL_BLOCK],
        }
    }

    /// Uniform in [0, 1) with 24 bits, exactly representable in f32.
    pub fn next_f32(&mut self) -> f32 {
        let bits = if self.sobol {
            let d = self.dim;
            self.dim += 1;
            let offset = d.wrapping_sub(self.block_start);
            if offset as usize >= SOBOL_BLOCK {
                self.fill_block(d);
                self.block[0]
            } else {
                self.block[offset as usize]
            }
        } else {
            self.state = self
                .state
                .wrapping_mul(747_796_405)
                .wrapping_add(2_891_336_453);
            let s = self.state;
            let word = ((s >> ((s >> 28) + 4)) ^ s).wrapping_mul(277_803_737);
            (word >> 22) ^ word
        };
        (bits >> 8) as f32 * (1.0 / 16_777_216.0)
    }

    /// Fills the block with dimensions `first ..` (`first` even; dimensions are drawn in order).
    fn fill_block(&mut self, first: u32) {
        self.block = sobol_block(self.key, self.reversed_index, first / 2);
        self.block_start = first;
    }
}

/// The Sobol values of pairs `first_pair ..` of the sample whose index is `reversed_index`
/// reversed, in dimension order. Pair p shuffles the point index by
/// `nested_uniform_scramble(index, pair_key)` and scrambles its two values by their own keys.
/// Each step runs over all lanes at once (so AVX2 takes eight in a register where the CPU has it;
/// integer arithmetic, so the same bits either way).
#[multiversion::multiversion(targets("x86_64+avx2"))]
fn sobol_block(key: u32, reversed_index: u32, first_pair: u32) -> [u32; SOBOL_BLOCK] {
    const PAIRS: usize = SOBOL_BLOCK / 2;
    let mut pair_key = [0u32; PAIRS];
    for (p, k) in pair_key.iter_mut().enumerate() {
        *k = pcg_hash(key ^ pcg_hash(first_pair + p as u32 + 1));
    }
    // Lane p holds pair p's first value and lane PAIRS + p its second, each before its scramble
    // (bit-reversed: Sobol's dimension 0 of index i is i reversed) beside its key.
    let mut value = [0u32; SOBOL_BLOCK];
    let mut value_key = [0u32; SOBOL_BLOCK];
    for p in 0..PAIRS {
        // nested_uniform_scramble(index, pair_key), its first reversal done once.
        value[p] = laine_karras_permutation(reversed_index, pair_key[p]).reverse_bits();
        value_key[p] = pcg_hash(pair_key[p].wrapping_add(1));
        value_key[PAIRS + p] = pcg_hash(pair_key[p].wrapping_add(2));
    }
    for p in 0..PAIRS {
        value[PAIRS + p] = sobol_dim1_reversed(value[p]);
    }
    // nested_uniform_scramble(v.reverse_bits(), k), its first reversal undone.
    for (v, k) in value.iter_mut().zip(value_key) {
        *v = laine_karras_permutation(*v, k).reverse_bits();
    }
    let mut block = [0u32; SOBOL_BLOCK];
    for p in 0..PAIRS {
        block[2 * p] = value[p];
        block[2 * p + 1] = value[PAIRS + p];
    }
    block
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The first 256 Sobol samples of a pixel, for each pair of dimensions, put exactly one point
    /// in each cell of a 16 × 16 grid, of 256 × 1 strips and of 1 × 256 strips (a (0,8,2)-net);
    /// the independent sampler does not.
    #[test]
    fn sobol_dim1_tables_match_the_bit_loop() {
        // The WGSL's definition (rng.wgsl), bit by bit.
        let by_bits = |i: u32| {
            let (mut v, mut x, mut bits) = (0x8000_0000u32, 0u32, i);
            while bits != 0 {
                if bits & 1 != 0 {
                    x ^= v;
                }
                bits >>= 1;
                v ^= v >> 1;
            }
            x
        };
        let mut rng = Rng::new(1, 2, 3);
        for i in (0..4096).chain([u32::MAX, 1 << 31, 0x8000_0001]) {
            assert_eq!(sobol_dim1(i), by_bits(i), "{i}");
            let r = (rng.next_f32() * 16_777_216.0) as u32 * 256 + i % 256;
            assert_eq!(sobol_dim1(r), by_bits(r), "{r}");
            assert_eq!(sobol_dim1_reversed(r), by_bits(r).reverse_bits(), "{r}");
            assert_eq!(sobol_dim1_reversed(i), by_bits(i).reverse_bits(), "{i}");
        }
    }

    /// The CPU's blocks of Sobol values equal the definition the WGSL draws one value at a time:
    /// pair p's point index is `nested_uniform_scramble(sample, k)` with k = hash(key, p), its
    /// two values Sobol's dimensions 0 and 1 of that index, each scrambled by its own key.
    #[test]
    fn sobol_blocks_equal_values_drawn_one_at_a_time() {
        for (pixel, sample, seed) in [
            (0, 0, 0),
            (7, 3, 1),
            (123_456, 255, 9),
            (u32::MAX, u32::MAX, 4),
        ] {
            let key = pcg_hash(pixel ^ pcg_hash(seed ^ 0x5bd1_e995));
            let mut rng = Rng::with_sampler(pixel, sample, seed, SamplerKind::Sobol);
            for d in 0..61u32 {
                let k = pcg_hash(key ^ pcg_hash(d / 2 + 1));
                let i = nested_uniform_scramble(sample, k);
                let bits = if d % 2 == 0 {
                    nested_uniform_scramble(i.reverse_bits(), pcg_hash(k.wrapping_add(1)))
                } else {
                    nested_uniform_scramble(sobol_dim1(i), pcg_hash(k.wrapping_add(2)))
                };
                let expected = (bits >> 8) as f32 * (1.0 / 16_777_216.0);
                assert_eq!(
                    rng.next_f32().to_bits(),
                    expected.to_bits(),
                    "dimension {d}"
                );
            }
        }
    }

    #[test]
    fn sobol_pairs_are_nets_per_pixel() {
        for pixel in [0u32, 7, 123_456] {
            let samples: Vec<Vec<f32>> = (0..256)
                .map(|i| {
                    let mut r = Rng::with_sampler(pixel, i, 3, SamplerKind::Sobol);
                    (0..6).map(|_| r.next_f32()).collect()
                })
                .collect();
            for pair in 0..3 {
                for (nx, ny) in [(16usize, 16usize), (256, 1), (1, 256), (32, 8)] {
                    let mut cells = vec![0u32; nx * ny];
                    for s in &samples {
                        let x = ((s[2 * pair] * nx as f32) as usize).min(nx - 1);
                        let y = ((s[2 * pair + 1] * ny as f32) as usize).min(ny - 1);
                        cells[y * nx + x] += 1;
                    }
                    assert!(
                        cells.iter().all(|&c| c == 1),
                        "pixel {pixel}, pair {pair}, {nx}x{ny}: not one point per cell"
                    );
                }
            }
        }
        let mut cells = [0u32; 256];
        for i in 0..256 {
            let mut r = Rng::new(0, i, 3);
            let (x, y) = (r.next_f32(), r.next_f32());
            cells[((y * 16.0) as usize) * 16 + (x * 16.0) as usize] += 1;
        }
        assert!(
            cells.iter().any(|&c| c != 1),
            "independent samples are not a net"
        );
    }

    /// Across pixels (different scrambles), each Sobol dimension is uniform: chi-square over 16
    /// bins of the 5th sample's every dimension, over 16,384 pixels.
    #[test]
    fn sobol_values_are_uniform_across_pixels() {
        for dim in 0..6 {
            let mut bins = [0u32; 16];
            for pixel in 0..16_384 {
                let mut r = Rng::with_sampler(pixel, 5, 1, SamplerKind::Sobol);
                let v = (0..=dim).map(|_| r.next_f32()).last().unwrap_or(0.0);
                bins[((v * 16.0) as usize).min(15)] += 1;
            }
            let expected = 16_384.0 / 16.0;
            let chi2: f64 = bins
                .iter()
                .map(|&b| (f64::from(b) - expected).powi(2) / expected)
                .sum();
            // 0.999 quantile of chi-square with 15 degrees of freedom.
            assert!(
                chi2 < 37.7,
                "dimension {dim}: chi-square {chi2:.1}, {bins:?}"
            );
        }
    }
}
