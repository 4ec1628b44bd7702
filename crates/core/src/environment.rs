//! Environment lighting: an equirectangular (latitude–longitude) HDR image around the scene,
//! importance-sampled. The twin of `environment.wgsl` beside it.
//!
//! Mapping (Mitsuba 3's `envmap`, y up): a direction d, turned by −rotation about +y, has
//! u = atan2(d.x, −d.z) / 2π (wrapped to [0, 1)) and v = acos(d.y) / π, v = 0 the top row.
//! Radiance is the nearest texel's (so it is exactly piecewise constant, like its pdf).
//!
//! Sampling: texel i is picked in proportion to w_i = luminance(L_i) · sin θ_i (θ_i its centre's)
//! through an alias table, then a point uniform in (u, v) inside it. Since dω = 2π² sin θ du dv, the
//! solid-angle density is p(d) = P_i · W H / (2π² sin θ(d)), P_i = w_i / Σ w; each texel record
//! stores P_i · W H / (2π²).

/// The WGSL twin of this module, `environment.wgsl` beside it (composed into the kernels by
/// `rt_gpu::shaders`).
pub const WGSL: &str = include_str!("environment.wgsl");

use std::path::Path;
use std::sync::Arc;

use glam::Vec3;
use serde::{Deserialize, Serialize};

use crate::error::{Error, Result};
use crate::gpu_types::EnvTexel;
use crate::math::sampling::luminance;

/// Environments wider or taller than this are box-filtered down to it on load: 2048 × 1024 texels
/// are 64 MiB on the GPU (32 bytes each: radiance, pdf, alias entry), within every adapter's
/// storage-binding limit, and lighting needs no more.
pub const MAX_ENV_WIDTH: u32 = 2048;
pub const MAX_ENV_HEIGHT: u32 = 1024;
/// Largest side of a file rt decodes (about 1.5 GiB of f32 RGB for 16384 × 8192).
pub const MAX_ENV_FILE_SIDE: u32 = 16384;

/// Linear RGB radiance texels, row-major from the top row.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct EnvironmentMap {
    pub width: u32,
    pub height: u32,
    pub texels: Vec<[f32; 3]>,
}

/// A scene's environment: an image file, turned about the up axis and scaled.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Environment {
    /// Where it came from (for messages; projects store the texels themselves).
    pub source: String,
    /// Rotation about +y in degrees.
    #[serde(default)]
    pub rotation_deg: f32,
    /// Radiance scale (1 leaves the file's values).
    #[serde(default = "one")]
    pub strength: f32,
    #[serde(skip)]
    pub map: Arc<EnvironmentMap>,
}

fn one() -> f32 {
    1.0
}

impl Environment {
    pub fn new(source: impl Into<String>, map: EnvironmentMap) -> Self {
        Environment {
            source: source.into(),
            rotation_deg: 0.0,
            strength: 1.0,
            map: Arc::new(map),
        }
    }

    pub fn validate(&self) -> std::result::Result<(), String> {
        if !(self.strength.is_finite() && self.strength >= 0.0) {
            return Err(format!(
                "environment '{}': strength must be finite and >= 0, got {}",
                self.source, self.strength
            ));
        }
        if !self.rotation_deg.is_finite() {
            return Err(format!(
                "environment '{}': rotation must be finite, got {}",
                self.source, self.rotation_deg
            ));
        }
        let m = &self.map;
        if m.width == 0 || m.height == 0 || m.texels.len() != (m.width * m.height) as usize {
            return Err(format!(
                "environment '{}' has no texels (was it loaded?)",
                self.source
            ));
        }
        Ok(())
    }
}

impl EnvironmentMap {
    /// A constant environment (one texel).
    pub fn uniform(radiance: [f32; 3]) -> Self {
        Self::from_texels(1, 1, vec![radiance]).0
    }

    /// Replaces texels that are negative, NaN or infinite by 0 and box-filters the image down to at
    /// most `MAX_ENV_WIDTH` × `MAX_ENV_HEIGHT`; returns the map and how many values were replaced
    /// (not counting negatives above −1e-4, which lossy codecs leave around black).
    pub fn from_texels(width: u32, height: u32, mut texels: Vec<[f32; 3]>) -> (Self, usize) {
        let mut replaced = 0;
        for t in &mut texels {
            for c in t.iter_mut() {
                if !(c.is_finite() && *c >= 0.0) {
                    // Lossy EXR codecs leave values like −5e-7 around black: rounding, not damage.
                    if !(c.is_finite() && *c > -1e-4) {
                        replaced += 1;
                    }
                    *c = 0.0;
                }
            }
        }
        let map = EnvironmentMap {
            width,
            height,
            texels,
        };
        (map.fit(MAX_ENV_WIDTH, MAX_ENV_HEIGHT), replaced)
    }

    /// Box-filters by the smallest integer factor per axis that brings the image within
    /// `max_w` × `max_h` (a partial last block averages what it has).
    pub fn fit(self, max_w: u32, max_h: u32) -> Self {
        let fx = self.width.div_ceil(max_w).max(1);
        let fy = self.height.div_ceil(max_h).max(1);
        if fx == 1 && fy == 1 {
            return self;
        }
        let (w, h) = (self.width.div_ceil(fx), self.height.div_ceil(fy));
        let mut texels = vec![[0.0f32; 3]; (w * h) as usize];
        for y in 0..h {
            for x in 0..w {
                let mut sum = [0.0f64; 3];
                let mut n = 0.0f64;
                for sy in y * fy..((y + 1) * fy).min(self.height) {
                    for sx in x * fx..((x + 1) * fx).min(self.width) {
                        let t = self.texels[(sy * self.width + sx) as usize];
                        for c in 0..3 {
                            sum[c] += f64::from(t[c]);
                        }
                        n += 1.0;
                    }
                }
                texels[(y * w + x) as usize] = sum.map(|s| (s / n) as f32);
            }
        }
        EnvironmentMap {
            width: w,
            height: h,
            texels,
        }
    }
}

/// Reads an equirectangular environment from a Radiance .hdr, OpenEXR or any image `image` decodes
/// (8-bit images are taken as sRGB). Negative, NaN and infinite texels become 0 (with a warning).
pub fn load_environment(path: &Path) -> Result<EnvironmentMap> {
    if path.is_dir() {
        return Err(Error::File {
            path: path.to_path_buf(),
            message: "is a directory, not an image".into(),
        });
    }
    let bytes = std::fs::read(path).map_err(|source| Error::Io {
        path: path.to_path_buf(),
        source,
    })?;
    decode_environment(&bytes, path)
}

/// `load_environment` from the file's bytes; `path` names it in messages.
pub fn decode_environment(bytes: &[u8], path: &Path) -> Result<EnvironmentMap> {
    let file_error = |message: String| Error::File {
        path: path.to_path_buf(),
        message,
    };
    let reader = || {
        image::ImageReader::new(std::io::Cursor::new(bytes))
            .with_guessed_format()
            .map_err(|source| Error::Io {
                path: path.to_path_buf(),
                source,
            })
    };
    let (width, height) = reader()?
        .into_dimensions()
        .map_err(|e| file_error(format!("unreadable environment image: {e}")))?;
    if width > MAX_ENV_FILE_SIDE || height > MAX_ENV_FILE_SIDE {
        return Err(file_error(format!(
            "environment is {width}x{height}; the limit is {MAX_ENV_FILE_SIDE} per side"
        )));
    }
    let mut decoder = reader()?;
    decoder.no_limits();
    let image = decoder
        .decode()
        .map_err(|e| file_error(format!("unreadable environment image: {e}")))?;
    // Taken over without copies where possible: a 16k x 8k map is 1.5 GiB of f32 RGB
    // (tests/big_environment.rs measures the peak).
    let rgb = image.into_rgb32f();
    let (w, h) = rgb.dimensions();
    let texels: Vec<[f32; 3]> = bytemuck::allocation::try_cast_vec(rgb.into_raw())
        .unwrap_or_else(|(_, raw)| raw.chunks_exact(3).map(|c| [c[0], c[1], c[2]]).collect());
    let (map, replaced) = EnvironmentMap::from_texels(w, h, texels);
    if replaced > 0 {
        log::warn!(
            "{}: {replaced} negative, NaN or infinite channel values set to 0",
            path.display()
        );
    }
    if (map.width, map.height) != (w, h) {
        log::info!(
            "{}: {w}x{h} environment filtered down to {}x{}",
            path.display(),
            map.width,
            map.height
        );
    }
    Ok(map)
}

/// The GPU records of `map` scaled by `strength`, or `None` when it emits nothing.
pub fn build_env_texels(map: &EnvironmentMap, strength: f32) -> Option<Vec<EnvTexel>> {
    let (w, h) = (map.width, map.height);
    let mut weights = Vec::with_capacity(map.texels.len());
    for y in 0..h {
        let sin_theta = (std::f64::consts::PI * (f64::from(y) + 0.5) / f64::from(h)).sin();
        for x in 0..w {
            let l = luminance(Vec3::from(map.texels[(y * w + x) as usize]) * strength);
            weights.push(f64::from(l) * sin_theta);
        }
    }
    let total: f64 = weights.iter().sum();
    if !(total > 0.0 && total.is_finite()) {
        return None;
    }
    let (thresholds, aliases) = crate::emitters::alias_table(&weights);
    let scale = f64::from(w) * f64::from(h) / (2.0 * std::f64::consts::PI.powi(2));
    Some(
        map.texels
            .iter()
            .zip(&weights)
            .zip(thresholds.iter().zip(&aliases))
            .map(|((t, wt), (&threshold, &alias))| EnvTexel {
                radiance: t.map(|c| c * strength),
                pdf: (wt / total * scale) as f32,
                alias_index: alias,
                threshold,
                _pad: [0; 2],
            })
            .collect(),
    )
}

/// The texture coordinates of world direction `d` for an environment turned by `rotation` turns.
pub fn env_uv(d: Vec3, rotation: f32) -> (f32, f32) {
    let u = d.x.atan2(-d.z) * (0.5 * std::f32::consts::FRAC_1_PI) - rotation;
    let u = u - u.floor();
    let v = d.y.clamp(-1.0, 1.0).acos() * std::f32::consts::FRAC_1_PI;
    (u, v)
}

/// The world direction at texture coordinates (u, v).
pub fn env_direction(u: f32, v: f32, rotation: f32) -> Vec3 {
    let phi = std::f32::consts::TAU * (u + rotation);
    let theta = std::f32::consts::PI * v;
    let s = theta.sin();
    Vec3::new(s * phi.sin(), theta.cos(), -s * phi.cos())
}

/// The texel index holding (u, v).
pub fn env_texel_index(u: f32, v: f32, w: u32, h: u32) -> u32 {
    let x = ((u * w as f32) as u32).min(w - 1);
    let y = ((v * h as f32) as u32).min(h - 1);
    y * w + x
}

/// Radiance arriving along −`d` (seen looking along `d`) and the density of `sample_env` at `d`.
pub fn env_lookup(texels: &[EnvTexel], w: u32, h: u32, rotation: f32, d: Vec3) -> (Vec3, f32) {
    let (u, v) = env_uv(d, rotation);
    let t = &texels[env_texel_index(u, v, w, h) as usize];
    let sin_theta = (1.0 - d.y * d.y).max(0.0).sqrt();
    let pdf = if sin_theta > 0.0 {
        t.pdf / sin_theta
    } else {
        0.0
    };
    (Vec3::from(t.radiance), pdf)
}

/// A direction towards the environment for four uniform numbers: (direction, radiance, pdf).
pub fn sample_env(
    texels: &[EnvTexel],
    w: u32,
    h: u32,
    rotation: f32,
    u: [f32; 4],
) -> (Vec3, Vec3, f32) {
    let n = texels.len() as u32;
    let slot = ((u[0] * n as f32) as u32).min(n - 1);
    let i = if u[1] < texels[slot as usize].threshold {
        slot
    } else {
        texels[slot as usize].alias_index
    };
    let t = &texels[i as usize];
    let (x, y) = (i % w, i / w);
    let tu = (x as f32 + u[2]) / w as f32;
    let tv = (y as f32 + u[3]) / h as f32;
    let d = env_direction(tu, tv, rotation);
    let sin_theta = (std::f32::consts::PI * tv).sin();
    let pdf = if sin_theta > 0.0 {
        t.pdf / sin_theta
    } else {
        0.0
    };
    (d, Vec3::from(t.radiance), pdf)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::math::rng::Rng;
    use crate::math::stats::{chi2_limit, pearson};

    /// A small environment with a bright spot, a dark band and a black texel.
    fn test_map() -> EnvironmentMap {
        let (w, h) = (8u32, 4u32);
        let mut texels = Vec::new();
        for y in 0..h {
            for x in 0..w {
                let v = 0.2 + (x as f32 * 0.37 + y as f32 * 0.91).sin().abs();
                texels.push(if (x, y) == (5, 1) {
                    [40.0, 30.0, 20.0]
                } else if (x, y) == (2, 3) {
                    [0.0; 3]
                } else {
                    [v, v * 0.5, 0.1]
                });
            }
        }
        EnvironmentMap::from_texels(w, h, texels).0
    }

    /// Sampled directions land in texels (and in each texel's quarters) in proportion to the
    /// records' probabilities, the black texel never; chi-square over 128 bins.
    #[test]
    fn environment_samples_follow_luminance_times_sine() {
        let map = test_map();
        let texels = build_env_texels(&map, 2.0).unwrap();
        let (w, h) = (map.width, map.height);
        let rotation = 0.15;
        let n = 200_000;
        let mut counts = vec![0.0f64; (w * h * 4) as usize];
        let mut rng = Rng::new(0, 0, 5);
        for _ in 0..n {
            let u = [
                rng.next_f32(),
                rng.next_f32(),
                rng.next_f32(),
                rng.next_f32(),
            ];
            let (d, _, pdf) = sample_env(&texels, w, h, rotation, u);
            assert!(pdf > 0.0);
            let (tu, tv) = env_uv(d, rotation);
            let (x, y) = (tu * 2.0 * w as f32, tv * 2.0 * h as f32);
            let (x, y) = ((x as u32).min(2 * w - 1), (y as u32).min(2 * h - 1));
            counts[(y * 2 * w + x) as usize] += 1.0;
        }
        let scale = f64::from(w * h) / (2.0 * std::f64::consts::PI.powi(2));
        let mut expected = Vec::new();
        for y in 0..2 * h {
            for x in 0..2 * w {
                let t = &texels[((y / 2) * w + x / 2) as usize];
                // Uniform in (u, v) inside the texel: each quarter holds a quarter.
                expected.push(f64::from(t.pdf) / scale * 0.25 * n as f64);
            }
        }
        let (x, dof) = pearson(&counts, &expected);
        let limit = chi2_limit(dof, 1, 1e-3);
        assert!(
            x < limit,
            "chi-square {x:.1} over {dof} dof exceeds {limit:.1}"
        );
        assert_eq!(counts[((3 * 2) * 2 * w + 2 * 2) as usize], 0.0);
    }

    /// The pdf `env_lookup` reports is the one `sample_env` sampled with, and it integrates to 1
    /// over the sphere; the radiance is the texel's times the strength.
    #[test]
    fn environment_lookup_agrees_with_sampling() {
        let map = test_map();
        let texels = build_env_texels(&map, 2.0).unwrap();
        let (w, h, rotation) = (map.width, map.height, 0.3);
        let mut rng = Rng::new(1, 0, 5);
        for _ in 0..2000 {
            let u = [
                rng.next_f32(),
                rng.next_f32(),
                rng.next_f32(),
                rng.next_f32(),
            ];
            let (d, le, pdf) = sample_env(&texels, w, h, rotation, u);
            let (le2, pdf2) = env_lookup(&texels, w, h, rotation, d);
            // Directions on a texel border may round into the neighbour, and at the poles sin θ
            // rounds to 0 in f32.
            if le == le2 && d.y.abs() < 0.9999 {
                assert!(
                    (pdf - pdf2).abs() <= 1e-3 * pdf,
                    "pdf {pdf} vs lookup {pdf2}"
                );
            }
        }
        let (mut integral, k) = (0.0f64, 600);
        for i in 0..k {
            let c = -1.0 + 2.0 * (i as f64 + 0.5) / k as f64;
            let s = (1.0 - c * c).sqrt();
            for j in 0..2 * k {
                let phi = std::f64::consts::TAU * (j as f64 + 0.5) / (2 * k) as f64;
                let d = Vec3::new((s * phi.cos()) as f32, c as f32, (s * phi.sin()) as f32);
                let (_, pdf) = env_lookup(&texels, w, h, rotation, d);
                integral +=
                    f64::from(pdf) * (2.0 / k as f64) * (std::f64::consts::TAU / (2 * k) as f64);
            }
        }
        assert!(
            (integral - 1.0).abs() < 5e-3,
            "pdf integrates to {integral}"
        );
        let (le, _) = env_lookup(&texels, w, h, 0.0, env_direction(5.5 / 8.0, 1.5 / 4.0, 0.0));
        assert_eq!(le, Vec3::new(80.0, 60.0, 40.0));
    }

    #[test]
    fn bad_texels_become_zero_and_black_environments_emit_nothing() {
        let (map, replaced) = EnvironmentMap::from_texels(
            2,
            1,
            vec![[f32::NAN, -1.0, f32::INFINITY], [0.5, 0.5, 0.5]],
        );
        assert_eq!(replaced, 3);
        assert_eq!(map.texels[0], [0.0; 3]);
        assert!(build_env_texels(&EnvironmentMap::uniform([0.0; 3]), 1.0).is_none());
        let one = build_env_texels(&EnvironmentMap::uniform([1.0; 3]), 1.0).unwrap();
        // A 1×1 environment is the constant one: pdf 1/(4π) everywhere.
        let (le, pdf) = env_lookup(&one, 1, 1, 0.0, Vec3::new(0.3, 0.5, -0.8).normalize());
        assert_eq!(le, Vec3::ONE);
        let s = (1.0f32 - 0.5f32.powi(2) / (0.09 + 0.25 + 0.64)).sqrt();
        assert!((pdf * s - 1.0 / (2.0 * std::f32::consts::PI.powi(2))).abs() < 1e-6);
    }

    #[test]
    fn large_environments_are_filtered_down() {
        let texels = vec![[1.0, 2.0, 3.0]; 4100 * 2];
        let map = EnvironmentMap {
            width: 4100,
            height: 2,
            texels,
        }
        .fit(MAX_ENV_WIDTH, MAX_ENV_HEIGHT);
        assert_eq!((map.width, map.height), (1367, 2));
        assert!(map.texels.iter().all(|t| *t == [1.0, 2.0, 3.0]));
    }

    #[test]
    fn missing_and_corrupt_files_are_clear_errors() {
        let dir = std::env::temp_dir().join(format!("rt-env-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let missing = dir.join("missing.hdr");
        let e = load_environment(&missing).unwrap_err().to_string();
        assert!(e.contains("missing.hdr"), "{e}");
        let corrupt = dir.join("corrupt.exr");
        std::fs::write(&corrupt, b"not an exr at all").unwrap();
        let e = load_environment(&corrupt).unwrap_err().to_string();
        assert!(e.contains("corrupt.exr") && e.contains("unreadable"), "{e}");
        std::fs::remove_dir_all(&dir).ok();
    }
}
