//! The math the CPU side shares with the kernels, each file the twin of the WGSL file of its stem
//! beside it (exported as its `WGSL`): `rng.rs` of
//! `rng.wgsl` (PCG and Owen-scrambled Sobol samplers), `sampling.rs` of
//! `sampling.wgsl` (directions, Fresnel, colour), `intersect.rs` of `intersect.wgsl` (watertight
//! triangle and slab tests, ray offsets), `microfacet.rs` of `microfacet.wgsl` (GGX) and `bsdf.rs` of
//! `bsdf.wgsl` (the PBR material's base), `coat.rs`, `sheen.rs`, `layers.rs`, `glass_energy.rs` and
//! `iridescence.rs` of theirs (the clear coat, the sheen, the stack they form over the base, rough
//! glass's energy compensation, thin-film interference), `anisotropic_energy.rs` of its WGSL
//! (anisotropic metals' energy compensation), `dispersion.rs` of `dispersion.wgsl` (the
//! index by wavelength, the hero channel), `medium.rs` of `medium.wgsl` (participating media: the
//! phase function, free flight, transmittance). The CPU reference (`crate::reference`), emitters, the
//! denoiser and the loaders use them.

pub mod anisotropic_energy;
pub mod bsdf;
pub mod coat;
pub mod dispersion;
pub mod glass_energy;
pub mod intersect;
pub mod intersect_lanes;
pub mod iridescence;
pub mod layers;
pub mod medium;
pub mod microfacet;
pub mod rng;
pub mod sampling;
pub mod sheen;
#[cfg(test)]
pub(crate) mod stats;
