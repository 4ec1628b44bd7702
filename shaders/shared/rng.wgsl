// Counter-based random numbers; mirrors crates/core/src/reference/rng.rs.

fn pcg_hash(input: u32) -> u32 {
    let state = input * 747796405u + 2891336453u;
    let word = ((state >> ((state >> 28u) + 4u)) ^ state) * 277803737u;
    return (word >> 22u) ^ word;
}

// One stream per (pixel, sample, seed): a sample does not depend on how samples are batched.
fn rng_init(pixel: u32, sample: u32, seed: u32) -> u32 {
    return pcg_hash(pixel + pcg_hash(sample + pcg_hash(seed)));
}

// Uniform in [0, 1) with 24 bits.
fn rng_next(state: ptr<function, u32>) -> f32 {
    *state = *state * 747796405u + 2891336453u;
    let s = *state;
    let word = ((s >> ((s >> 28u) + 4u)) ^ s) * 277803737u;
    return f32(((word >> 22u) ^ word) >> 8u) * (1.0 / 16777216.0);
}
