//! Image-based light for the preview, built on the CPU once per environment (the renderer caches it
//! by `PreviewEnvironment::key`), as the glTF Sample Viewer and Filament do on the GPU:
//! - `sharp`: the environment (times its strength) box-filtered to at most 512 × 256: the
//!   background and mirror reflections;
//! - `blur`: at 64 × 32, the environment prefiltered for GGX at roughness 0.25, 0.5, 0.75 and 1
//!   (Karis' split sum with n = v = r: texel j weighs D(r·h_j) (r·l_j) Δω_j), then its cosine
//!   convolution ∫ L (n·l)/π dω (irradiance over π, what a white Lambertian surface reflects);
//! - the split-sum table (A, B) over (μ, roughness), E = F0 A + B for Schlick's Fresnel, from
//!   rt-core's visible-normal quadrature: A + B is the render's GGX albedo table.
//!
//! A constant ambient is a one-texel environment: every layer is that radiance.

use std::f32::consts::PI;

use glam::Vec3;
use rt_core::environment::{EnvironmentMap, env_direction};

use super::frame::PreviewEnvironment;

/// Largest background / mirror layer.
pub const SHARP_WIDTH: u32 = 512;
pub const SHARP_HEIGHT: u32 = 256;
/// Size of the prefiltered layers.
pub const BLUR_WIDTH: u32 = 64;
pub const BLUR_HEIGHT: u32 = 32;
/// The roughness of each GGX layer (`preview.wgsl`'s `ENV_ROUGH_LAYERS`); the cosine layer follows.
pub const ROUGH_LEVELS: [f32; 4] = [0.25, 0.5, 0.75, 1.0];

/// An equirectangular image (row-major from the top row, the environment's own mapping).
#[derive(Clone, Debug, PartialEq)]
pub struct Layer {
    pub width: u32,
    pub height: u32,
    pub texels: Vec<[f32; 3]>,
}

/// The prefiltered environment.
#[derive(Clone, Debug)]
pub struct Prefiltered {
    pub sharp: Layer,
    /// `ROUGH_LEVELS`, then the cosine convolution; all the same size.
    pub blur: Vec<Layer>,
}

fn scaled(map: &EnvironmentMap, strength: f32, width: u32, height: u32) -> Layer {
    let fitted = map.clone().fit(width, height);
    let strength = if strength.is_finite() {
        strength.max(0.0)
    } else {
        0.0
    };
    Layer {
        width: fitted.width,
        height: fitted.height,
        texels: fitted
            .texels
            .iter()
            .map(|t| t.map(|c| c * strength))
            .collect(),
    }
}

/// Each texel's direction (unrotated: the shader turns the lookup) and solid angle.
fn directions(layer: &Layer) -> Vec<(Vec3, f32)> {
    let (w, h) = (layer.width, layer.height);
    let cell = 2.0 * PI * PI / (w * h) as f32;
    (0..w * h)
        .map(|i| {
            let (x, y) = (i % w, i / w);
            let (u, v) = ((x as f32 + 0.5) / w as f32, (y as f32 + 0.5) / h as f32);
            (env_direction(u, v, 0.0), cell * (PI * v).sin())
        })
        .collect()
}

/// `source` convolved with `weight(r, l)` at every texel direction r, normalised by the weights'
/// sum when `normalise`.
fn convolve(source: &Layer, weight: impl Fn(Vec3, Vec3) -> f32, normalise: bool) -> Layer {
    let dirs = directions(source);
    let texels = dirs
        .iter()
        .map(|&(r, _)| {
            let mut sum = Vec3::ZERO;
            let mut total = 0.0;
            for (&(l, solid_angle), t) in dirs.iter().zip(&source.texels) {
                let w = weight(r, l) * solid_angle;
                if w > 0.0 {
                    sum += Vec3::from(*t) * w;
                    total += w;
                }
            }
            let value = if normalise && total > 0.0 {
                sum / total
            } else {
                sum
            };
            value.to_array()
        })
        .collect();
    Layer {
        width: source.width,
        height: source.height,
        texels,
    }
}

/// The prefiltered copies of `environment`.
pub fn prefilter(environment: &PreviewEnvironment) -> Prefiltered {
    let uniform;
    let (map, strength) = match &environment.map {
        Some(map) => (map.as_ref(), environment.strength),
        None => {
            uniform = EnvironmentMap::uniform(environment.ambient);
            (&uniform, 1.0)
        }
    };
    let sharp = scaled(map, strength, SHARP_WIDTH, SHARP_HEIGHT);
    if sharp.texels.len() == 1 {
        // Constant: every convolution of it is itself (a quadrature over one texel is not).
        return Prefiltered {
            blur: vec![sharp.clone(); ROUGH_LEVELS.len() + 1],
            sharp,
        };
    }
    let source = scaled(map, strength, BLUR_WIDTH, BLUR_HEIGHT);
    let mut blur: Vec<Layer> = ROUGH_LEVELS
        .iter()
        .map(|&roughness| {
            let a2 = (roughness * roughness).powi(2).max(1e-6);
            convolve(
                &source,
                |r, l| {
                    let cos = r.dot(l);
                    if cos <= 0.0 {
                        return 0.0;
                    }
                    let n_h = r.dot((r + l).normalize());
                    let k = n_h * n_h * (a2 - 1.0) + 1.0;
                    a2 / (PI * k * k) * cos
                },
                true,
            )
        })
        .collect();
    blur.push(convolve(&source, |n, l| n.dot(l).max(0.0) / PI, false));
    Prefiltered { sharp, blur }
}

/// Side of the split-sum table: its entries are rt-core's GGX albedo table's (μ_j = (j + ½)/N,
/// roughness r_i = i/(N − 1)).
pub const BRDF_TABLE_SIDE: usize = rt_core::math::microfacet::ENERGY_SIDE;

/// (A, B) per (roughness row, μ column): E = F0 A + B for Schlick's Fresnel F0 + (1 − F0)(1 − c)⁵.
pub fn brdf_table() -> &'static [[f32; 2]] {
    use rt_core::math::microfacet::{energy_table, visible_normal_albedo};
    static TABLE: std::sync::OnceLock<Vec<[f32; 2]>> = std::sync::OnceLock::new();
    TABLE.get_or_init(|| {
        let bias = visible_normal_albedo(|c, _| (1.0 - c.clamp(0.0, 1.0)).powi(5));
        energy_table()
            .iter()
            .zip(&bias)
            .map(|(&e, &b)| [e - b, b])
            .collect()
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn ambient(radiance: [f32; 3]) -> PreviewEnvironment {
        PreviewEnvironment {
            map: None,
            strength: 1.0,
            ambient: radiance,
            key: 0,
        }
    }

    /// A constant environment prefilters to itself at every roughness, and its cosine convolution
    /// (irradiance over π) is the radiance again (to the quadrature's error).
    #[test]
    fn a_constant_environment_prefilters_to_itself() {
        let p = prefilter(&ambient([0.5, 1.0, 2.0]));
        for layer in std::iter::once(&p.sharp).chain(&p.blur) {
            for t in &layer.texels {
                for (c, want) in t.iter().zip([0.5, 1.0, 2.0]) {
                    assert!((c / want - 1.0).abs() < 1e-5, "{t:?}");
                }
            }
        }
        // The same through a larger map (the quadrature over 64 × 32 texels).
        let map = EnvironmentMap {
            width: 128,
            height: 64,
            texels: vec![[1.0; 3]; 128 * 64],
        };
        let env = PreviewEnvironment {
            map: Some(std::sync::Arc::new(map)),
            strength: 2.0,
            ambient: [0.0; 3],
            key: 1,
        };
        let p = prefilter(&env);
        for layer in &p.blur {
            for t in &layer.texels {
                assert!((t[0] - 2.0).abs() < 0.02, "{t:?}");
            }
        }
    }

    /// A sky bright above and dark below: the cosine layer gives a normal facing up all of it,
    /// one facing down none and one facing sideways half, and roughness spreads the sharp
    /// layer's step below the horizon.
    #[test]
    fn a_bright_upper_hemisphere_lights_upward_normals() {
        let (w, h) = (64u32, 32u32);
        let texels = (0..w * h)
            .map(|i| if i / w < h / 2 { [1.0; 3] } else { [0.0; 3] })
            .collect();
        let env = PreviewEnvironment {
            map: Some(std::sync::Arc::new(EnvironmentMap {
                width: w,
                height: h,
                texels,
            })),
            strength: 1.0,
            ambient: [0.0; 3],
            key: 2,
        };
        let p = prefilter(&env);
        let diffuse = p.blur.last().unwrap();
        let top = diffuse.texels[0][0];
        let bottom = diffuse.texels[(w * (h - 1)) as usize][0];
        let equator = diffuse.texels[(w * (h / 2)) as usize][0];
        // Facing up: all of the sky, 1; facing down: none; sideways: half.
        assert!((top - 1.0).abs() < 0.02, "{top}");
        assert!(bottom < 0.02, "{bottom}");
        assert!((equator - 0.5).abs() < 0.05, "{equator}");
        // Just below the horizon the mirror layer is dark; the roughest layer is not.
        let below = (w * (h / 2 + 1)) as usize;
        assert!(p.sharp.texels[(p.sharp.width * (p.sharp.height / 2 + 2)) as usize][0] == 0.0);
        assert!(
            p.blur[3].texels[below][0] > 0.2,
            "{}",
            p.blur[3].texels[below][0]
        );
    }

    /// The split-sum table: A + B is the render's GGX albedo, both within [0, 1], and B (the part
    /// Fresnel's grazing rise adds) grows towards grazing angles.
    #[test]
    fn the_split_sum_table_adds_up_to_the_ggx_albedo() {
        let table = brdf_table();
        let energy = rt_core::math::microfacet::energy_table();
        let n = BRDF_TABLE_SIDE;
        assert_eq!(table.len(), n * n);
        for (ab, e) in table.iter().zip(energy) {
            assert!((ab[0] + ab[1] - e).abs() < 1e-6);
            assert!(
                (0.0..=1.0).contains(&ab[0]) && (0.0..=1.0).contains(&ab[1]),
                "{ab:?}"
            );
        }
        let row = n * (n / 4);
        assert!(
            table[row][1] > table[row + n - 1][1] * 5.0,
            "grazing B > normal B"
        );
        // A smooth reflector at normal incidence: E = F0 (A ≈ 1, B ≈ 0).
        assert!(
            table[n - 1][0] > 0.99 && table[n - 1][1] < 1e-3,
            "{:?}",
            table[n - 1]
        );
    }
}
