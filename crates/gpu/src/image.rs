//! What a render reads back: the image (per-pixel means) and the denoiser's guides, and the one
//! place they are denoised (the CLI, `converge` and the editor all call `Image::denoised`).

/// A rendered image: per pixel, the mean radiance (rgb) and mean squared luminance (a).
#[derive(Clone, Debug)]
pub struct Image {
    pub width: u32,
    pub height: u32,
    pub samples_per_pixel: u32,
    pub pixels: Vec<[f32; 4]>,
}

impl Image {
    pub fn rgb(&self) -> Vec<[f32; 3]> {
        self.pixels.iter().map(|p| [p[0], p[1], p[2]]).collect()
    }

    /// Mean of each channel over the image.
    pub fn channel_means(&self) -> [f64; 3] {
        let mut sum = [0.0f64; 3];
        for p in &self.pixels {
            for c in 0..3 {
                sum[c] += f64::from(p[c]);
            }
        }
        sum.map(|s| s / self.pixels.len().max(1) as f64)
    }
}

/// Per-pixel auxiliary outputs for the denoiser, means over the samples like the image.
#[derive(Clone, Debug, Default)]
pub struct Aovs {
    /// The first hit's albedo (texture, metal colour, glass tint; an emitter's normalised colour).
    pub albedo: Vec<[f32; 3]>,
    /// The first hit's geometric normal, facing the camera.
    pub normal: Vec<[f32; 3]>,
    /// Light seen directly: emitters and sky at the first segment.
    pub emission: Vec<[f32; 3]>,
}

impl Image {
    /// The image filtered by `rt_core::denoise` (edge-avoiding À-Trous) with `aovs` as guides and
    /// the per-pixel luminance variance; biased, for previews: the raw image stays the measurement.
    pub fn denoised(&self, aovs: &Aovs) -> Result<Vec<[f32; 3]>, String> {
        let color = self.rgb();
        let variance = rt_core::output::pixel_variance(&self.pixels, self.samples_per_pixel);
        rt_core::denoise::denoise(
            &rt_core::denoise::DenoiseInput {
                width: self.width,
                height: self.height,
                color: &color,
                emission: &aovs.emission,
                albedo: &aovs.albedo,
                normal: &aovs.normal,
                variance: &variance,
            },
            &rt_core::denoise::DenoiseParams::default(),
        )
    }
}
