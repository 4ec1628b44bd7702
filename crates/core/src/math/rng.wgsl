// Random numbers; mirrors crates/core/src/math/rng.rs. Two samplers, chosen per pipeline:
// - independent: a PCG stream per (pixel, sample, seed);
// - SOBOL: Owen-scrambled Sobol points (Burley 2020, "Practical hash-based Owen scrambling"),
//   consecutive dimensions taken in pairs from the (0,2)-sequence of Sobol's first two
//   dimensions, each pair's point index shuffled and its values scrambled by hashes of the pixel,
//   seed and pair, so pairs are independent and every estimate stays unbiased.
// Either way a sample depends only on (pixel, sample, seed), not on how samples are batched.

override SOBOL: bool = false;

fn pcg_hash(input: u32) -> u32 {
    let state = input * 747796405u + 2891336453u;
    let word = ((state >> ((state >> 28u) + 4u)) ^ state) * 277803737u;
    return (word >> 22u) ^ word;
}

struct Sampler {
    // PCG state (independent sampler).
    pcg: u32,
    // Sobol point index (the sample number) and the next dimension to draw.
    index: u32,
    dim: u32,
    // Per-pixel scrambling key.
    key: u32,
}

fn rng_init(pixel: u32, sample: u32, seed: u32) -> Sampler {
    return Sampler(
        pcg_hash(pixel + pcg_hash(sample + pcg_hash(seed))),
        sample,
        0u,
        pcg_hash(pixel ^ pcg_hash(seed ^ 0x5bd1e995u)),
    );
}

fn laine_karras_permutation(v: u32, seed: u32) -> u32 {
    var x = v + seed;
    x ^= x * 0x6c50b47cu;
    x ^= x * 0xb82f1e52u;
    x ^= x * 0xc7afe638u;
    x ^= x * 0x8d22f6e6u;
    return x;
}

fn nested_uniform_scramble(v: u32, seed: u32) -> u32 {
    return reverseBits(laine_karras_permutation(reverseBits(v), seed));
}

// Sobol's second dimension: bit k of i adds direction number v_k, v_0 = 2^31, v_k = v_(k-1) ^ (v_(k-1) >> 1).
fn sobol_dim1(i: u32) -> u32 {
    var v = 0x80000000u;
    var x = 0u;
    var bits = i;
    while (bits != 0u) {
        if ((bits & 1u) != 0u) {
            x ^= v;
        }
        bits >>= 1u;
        v ^= v >> 1u;
    }
    return x;
}

// Uniform in [0, 1) with 24 bits.
fn rng_next(s: ptr<function, Sampler>) -> f32 {
    var bits: u32;
    if (SOBOL) {
        let d = (*s).dim;
        (*s).dim = d + 1u;
        let pair_key = pcg_hash((*s).key ^ pcg_hash(d / 2u + 1u));
        let i = nested_uniform_scramble((*s).index, pair_key);
        var x = reverseBits(i);
        if ((d & 1u) != 0u) {
            x = sobol_dim1(i);
        }
        bits = nested_uniform_scramble(x, pcg_hash(pair_key + 1u + (d & 1u)));
    } else {
        (*s).pcg = (*s).pcg * 747796405u + 2891336453u;
        let p = (*s).pcg;
        let word = ((p >> ((p >> 28u) + 4u)) ^ p) * 277803737u;
        bits = (word >> 22u) ^ word;
    }
    return f32(bits >> 8u) * (1.0 / 16777216.0);
}
