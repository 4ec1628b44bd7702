//! Dispersion (`KHR_materials_dispersion`): a transmissive volume's index of refraction varies
//! with the wavelength, so a prism splits white light. Mirrored one-to-one in `dispersion.wgsl`
//! beside it.
//!
//! The extension gives the index at wavelength λ (nm) from the index n_d at the Fraunhofer d line
//! (587.56 nm) and the Abbe number V_d = 20 / `dispersion` by Cauchy's two-term fit through the
//! F and C lines:
//!
//!   n(λ) = max(n_d + (n_d − 1)/V_d · (523655/λ² − 1.5168), 1).
//!
//! rt renders RGB, so a path that meets a dispersive surface picks one of the three channels
//! uniformly (a "hero channel", as spectral renderers pick a hero wavelength) and carries that
//! channel alone from then on, weighted by 3, refracting at the channel's wavelength: each
//! channel's expectation is unchanged (1/3 · 3), and the colours separate where the paths of the
//! channels part. The channels stand for the sRGB primaries' dominant wavelengths.

/// The WGSL twin of this module, `dispersion.wgsl` beside it (composed into the kernels by
/// `rt_gpu::shaders`).
pub const WGSL: &str = include_str!("dispersion.wgsl");

use glam::Vec3;

/// The wavelength (nm) each RGB channel stands for: the sRGB primaries' dominant wavelengths.
pub const CHANNEL_WAVELENGTHS: [f32; 3] = [612.0, 549.0, 465.0];

/// The index at wavelength `lambda` (nm) of a material of index `ior` (at the d line) and the
/// extension's `dispersion` (20 / V_d; 0: none).
pub fn ior_at(ior: f32, dispersion: f32, lambda: f32) -> f32 {
    if dispersion <= 0.0 {
        return ior;
    }
    let abbe = 20.0 / dispersion;
    (ior + (ior - 1.0) * (523_655.0 / (lambda * lambda) - 1.5168) / abbe).max(1.0)
}

/// The index for a path's hero channel (`channel` 1, 2, 3: red, green, blue; 0: none chosen).
pub fn channel_ior(ior: f32, dispersion: f32, channel: u32) -> f32 {
    if channel == 0 {
        ior
    } else {
        ior_at(
            ior,
            dispersion,
            CHANNEL_WAVELENGTHS[(channel - 1).min(2) as usize],
        )
    }
}

/// The hero channel (1, 2, 3) a uniform number picks, and the throughput's mask for it: that
/// channel alone, weighted by 3.
pub fn pick_channel(u: f32) -> (u32, Vec3) {
    let k = ((u * 3.0) as u32).min(2);
    let mut mask = Vec3::ZERO;
    mask[k as usize] = 3.0;
    (k + 1, mask)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The index is n_d at the d line, higher in the blue than in the red by (n_d − 1)/V_d between
    /// the F (486.13 nm) and C (656.27 nm) lines (the Abbe number's definition), never below 1, and
    /// unchanged without dispersion.
    #[test]
    fn the_index_follows_the_abbe_number() {
        let (ior, dispersion) = (1.5168, 20.0 / 64.17); // N-BK7
        assert!((ior_at(ior, dispersion, 587.56) - ior).abs() < 1e-4);
        let spread = ior_at(ior, dispersion, 486.13) - ior_at(ior, dispersion, 656.27);
        let expected = (ior - 1.0) / 64.17;
        assert!(
            (spread - expected).abs() < 0.02 * expected,
            "n_F − n_C = {spread}, (n_d − 1)/V_d = {expected}"
        );
        assert!(channel_ior(ior, dispersion, 3) > channel_ior(ior, dispersion, 1));
        assert_eq!(channel_ior(ior, dispersion, 0), ior);
        assert_eq!(ior_at(ior, 0.0, 400.0), ior);
        assert_eq!(ior_at(1.01, 50.0, 700.0), 1.0, "clamped at 1");
    }

    /// Picking a channel keeps each channel's expectation: E[mask] = (1, 1, 1).
    #[test]
    fn the_hero_channel_is_unbiased() {
        let n = 30_000;
        let mut sum = Vec3::ZERO;
        for i in 0..n {
            let (channel, mask) = pick_channel((i as f32 + 0.5) / n as f32);
            assert!((1..=3).contains(&channel) && mask[channel as usize - 1] == 3.0);
            sum += mask;
        }
        assert!((sum / n as f32 - Vec3::ONE).abs().max_element() < 1e-3);
    }
}
