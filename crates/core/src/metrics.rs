//! Image error metrics for comparing renders with a reference.
//!
//! relMSE = mean over pixels and channels of (img − ref)² / (ref² + 0.01), the definition used for
//! the shared Cornell box statistics (shared/README.md); RMSE = sqrt(mean (img − ref)²).

use crate::output::SampleCounts;

/// A linear RGB float image.
#[derive(Clone, Debug, PartialEq)]
pub struct RgbImage {
    pub width: u32,
    pub height: u32,
    pub pixels: Vec<[f32; 3]>,
}

impl RgbImage {
    /// Reads any format `image` decodes (EXR stays linear; 8-bit formats are decoded from sRGB).
    pub fn load(path: &std::path::Path) -> crate::Result<Self> {
        let img = image::open(path).map_err(|e| crate::Error::File {
            path: path.into(),
            message: e.to_string(),
        })?;
        let linear_8bit = !matches!(
            img,
            image::DynamicImage::ImageRgb32F(_) | image::DynamicImage::ImageRgba32F(_)
        );
        let rgb = img.to_rgb32f();
        let decode = |c: f32| {
            if linear_8bit {
                crate::math::sampling::srgb_to_linear(c)
            } else {
                c
            }
        };
        Ok(RgbImage {
            width: rgb.width(),
            height: rgb.height(),
            pixels: rgb.pixels().map(|p| p.0.map(decode)).collect(),
        })
    }

    /// Averages `factor`×`factor` blocks (a box filter, as pixels integrate over their area).
    pub fn downsample(&self, factor: u32) -> RgbImage {
        let (w, h) = (self.width / factor, self.height / factor);
        let mut pixels = vec![[0.0f32; 3]; (w * h) as usize];
        let scale = 1.0 / (factor * factor) as f32;
        for y in 0..h * factor {
            for x in 0..w * factor {
                let p = self.pixels[(y * self.width + x) as usize];
                let out = &mut pixels[((y / factor) * w + x / factor) as usize];
                for c in 0..3 {
                    out[c] += p[c] * scale;
                }
            }
        }
        RgbImage {
            width: w,
            height: h,
            pixels,
        }
    }
}

/// Errors of `image` against `reference`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ImageError {
    pub rel_mse: f64,
    pub rmse: f64,
    /// mean(image) / mean(reference) per channel.
    pub mean_ratio: [f64; 3],
}

/// Compares two images; the reference is box-downsampled when it is an integer multiple larger.
pub fn compare(image: &RgbImage, reference: &RgbImage) -> Result<ImageError, String> {
    let reference = if reference.width != image.width
        && image.width > 0
        && reference.width.is_multiple_of(image.width)
    {
        let factor = reference.width / image.width;
        if reference.height != image.height * factor {
            return Err("the images have different aspect ratios".into());
        }
        reference.downsample(factor)
    } else {
        reference.clone()
    };
    if (reference.width, reference.height) != (image.width, image.height) {
        return Err(format!(
            "image is {}x{} but the reference is {}x{} (not an integer multiple)",
            image.width, image.height, reference.width, reference.height
        ));
    }
    let (mut rel, mut sq) = (0.0f64, 0.0f64);
    let (mut sum_i, mut sum_r) = ([0.0f64; 3], [0.0f64; 3]);
    for (p, r) in image.pixels.iter().zip(&reference.pixels) {
        for c in 0..3 {
            let (a, b) = (f64::from(p[c]), f64::from(r[c]));
            rel += (a - b).powi(2) / (b * b + 0.01);
            sq += (a - b).powi(2);
            sum_i[c] += a;
            sum_r[c] += b;
        }
    }
    let n = (image.pixels.len() * 3).max(1) as f64;
    Ok(ImageError {
        rel_mse: rel / n,
        rmse: (sq / n).sqrt(),
        mean_ratio: [0, 1, 2].map(|c| {
            if sum_r[c] > 0.0 {
                sum_i[c] / sum_r[c]
            } else {
                f64::NAN
            }
        }),
    })
}

/// The relMSE this image is expected to have against its converged version, estimated from its
/// own samples: mean over pixels of (s²/n) / (m² + 0.01), with m the mean luminance and s² the
/// sample variance of luminance (from the mean of squares `mean_sq_lum`) over `n` samples. Its
/// square root is the "noise" that `--noise-target` compares. Needs n ≥ 2.
pub fn estimated_rel_mse(pixels: &[[f32; 4]], counts: SampleCounts) -> f64 {
    if pixels.is_empty() {
        return f64::INFINITY;
    }
    let total: f64 = (0..pixels.len())
        .map(|i| pixel_rel_mse(pixels[i], counts.at(i)))
        .sum();
    total / pixels.len() as f64
}

/// One pixel's term of `estimated_rel_mse`: (s²/n) / (m² + 0.01) for its luminance mean m and
/// sample variance s² over its n samples (infinite below two samples). Adaptive sampling stops a
/// pixel once the square root of this is below its threshold.
pub fn pixel_rel_mse(p: [f32; 4], samples: u32) -> f64 {
    if samples < 2 {
        return f64::INFINITY;
    }
    let n = f64::from(samples);
    let weights = [0.2126, 0.7152, 0.0722];
    let m: f64 = (0..3).map(|c| weights[c] * f64::from(p[c])).sum();
    let variance = (f64::from(p[3]) - m * m).max(0.0) * n / (n - 1.0);
    variance / n / (m * m + 0.01)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn estimated_rel_mse_of_known_samples() {
        // Samples 0 and 2 (grey): mean 1, mean square 2, sample variance 2 over n = 2.
        let pixels = [[1.0, 1.0, 1.0, 2.0]];
        let expected = 2.0 / 2.0 / 1.01;
        assert!((estimated_rel_mse(&pixels, SampleCounts::Uniform(2)) - expected).abs() < 1e-6);
        assert!(estimated_rel_mse(&pixels, SampleCounts::Uniform(1)).is_infinite());
        assert!((estimated_rel_mse(&pixels, SampleCounts::PerPixel(&[2])) - expected).abs() < 1e-6);
        assert_eq!(
            estimated_rel_mse(&[[0.5, 0.5, 0.5, 0.25]], SampleCounts::Uniform(10)),
            0.0,
            "constant samples: no noise"
        );
    }

    #[test]
    fn relmse_of_known_differences() {
        let reference = RgbImage {
            width: 2,
            height: 1,
            pixels: vec![[1.0; 3], [0.0; 3]],
        };
        let image = RgbImage {
            width: 2,
            height: 1,
            pixels: vec![[1.1; 3], [0.1; 3]],
        };
        let e = compare(&image, &reference).unwrap();
        let expected = (0.01 / 1.01 + 0.01 / 0.01) / 2.0;
        assert!((e.rel_mse - expected).abs() < 1e-6, "{}", e.rel_mse);
        assert!((e.rmse - 0.1).abs() < 1e-6);
        assert!((e.mean_ratio[0] - 1.2).abs() < 1e-6);
        let big = RgbImage {
            width: 4,
            height: 2,
            pixels: vec![[1.0; 3]; 8],
        };
        let small = RgbImage {
            width: 2,
            height: 1,
            pixels: vec![[1.0; 3]; 2],
        };
        assert_eq!(
            compare(&small, &big).unwrap().rel_mse,
            0.0,
            "downsampled reference"
        );
        assert!(
            compare(
                &RgbImage {
                    width: 3,
                    height: 1,
                    pixels: vec![[0.0; 3]; 3]
                },
                &big
            )
            .is_err()
        );
    }
}
