//! The counter-based random numbers shared by the kernel (`shaders/shared/rng.wgsl`) and the CPU
//! reference: one PCG stream per (pixel, sample, seed), so any sample can be regenerated on its own
//! and the image does not depend on how samples are split into dispatches.

/// PCG-RXS-M-XS hash of one 32-bit word (Jarzynski & Olano 2020).
pub fn pcg_hash(input: u32) -> u32 {
    let state = input.wrapping_mul(747_796_405).wrapping_add(2_891_336_453);
    let word = ((state >> ((state >> 28) + 4)) ^ state).wrapping_mul(277_803_737);
    (word >> 22) ^ word
}

/// A PCG32-style stream seeded from a pixel, a sample index and the user's seed.
#[derive(Clone, Copy, Debug)]
pub struct Rng {
    state: u32,
}

impl Rng {
    pub fn new(pixel: u32, sample: u32, seed: u32) -> Self {
        Rng {
            state: pcg_hash(pixel.wrapping_add(pcg_hash(sample.wrapping_add(pcg_hash(seed))))),
        }
    }

    /// Uniform in [0, 1) with 24 bits, exactly representable in f32.
    pub fn next_f32(&mut self) -> f32 {
        self.state = self
            .state
            .wrapping_mul(747_796_405)
            .wrapping_add(2_891_336_453);
        let s = self.state;
        let word = ((s >> ((s >> 28) + 4)) ^ s).wrapping_mul(277_803_737);
        (((word >> 22) ^ word) >> 8) as f32 * (1.0 / 16_777_216.0)
    }
}
