//! What a render reads back: the image (per-pixel means) and the denoiser's guides, and the one
//! place they are denoised (the CLI, `converge` and the editor all call `Image::denoised`).

use rt_core::accumulation::PixelSums;
use rt_core::output::SampleCounts;

/// A rendered image: per pixel, the mean radiance (rgb) and mean squared luminance (a), and the
/// exact sums they are the means of (what a render shard keeps for `rt-cli merge`).
#[derive(Clone, Debug)]
pub struct Image {
    pub width: u32,
    pub height: u32,
    /// Samples of every pixel still sampling (all of them, without adaptive sampling).
    pub samples_per_pixel: u32,
    /// With adaptive sampling, each pixel's own count (at most `samples_per_pixel`).
    pub sample_counts: Option<Vec<u32>>,
    pub pixels: Vec<[f32; 4]>,
    /// Empty for an image that did not come from a render or a part (a plain EXR opened).
    pub sums: Vec<PixelSums>,
}

impl Image {
    /// A part's (or merged frame's) image, and its denoiser guides when it carries them.
    pub fn from_part(part: &rt_core::part::Part) -> (Image, Option<Aovs>) {
        let image = Image {
            width: part.header.width,
            height: part.header.height,
            samples_per_pixel: part.counts.iter().copied().max().unwrap_or(0),
            sample_counts: Some(part.counts.clone()),
            pixels: part.pixels(),
            sums: part.sums.clone(),
        };
        let g = &part.guides;
        let aovs = (g.albedo.len() == part.counts.len()).then(|| Aovs::from(g));
        (image, aovs)
    }

    /// An image of known colour only (one "sample" per pixel, no variance).
    pub fn from_rgb(width: u32, height: u32, rgb: &[[f32; 3]]) -> Image {
        let pixels = rgb
            .iter()
            .map(|&[r, g, b]| {
                let y = rt_core::math::sampling::luminance(glam::Vec3::new(r, g, b));
                [r, g, b, y * y]
            })
            .collect();
        Image {
            width,
            height,
            samples_per_pixel: 1,
            sample_counts: None,
            pixels,
            sums: Vec::new(),
        }
    }
}

impl Image {
    /// How many samples each pixel holds.
    pub fn counts(&self) -> SampleCounts<'_> {
        match &self.sample_counts {
            Some(counts) => SampleCounts::PerPixel(counts),
            None => SampleCounts::Uniform(self.samples_per_pixel),
        }
    }

    /// The square root of the relMSE this image is expected to have against its converged
    /// version (`rt_core::metrics::estimated_rel_mse`).
    pub fn estimated_noise(&self) -> f64 {
        rt_core::metrics::estimated_rel_mse(&self.pixels, self.counts()).sqrt()
    }

    /// The mean sample count over the pixels.
    pub fn mean_samples(&self) -> f64 {
        match &self.sample_counts {
            Some(counts) => {
                counts.iter().map(|&c| f64::from(c)).sum::<f64>() / counts.len().max(1) as f64
            }
            None => f64::from(self.samples_per_pixel),
        }
    }

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
    /// Coverage (alpha), depth and object ids; empty where they were not kept (render parts).
    pub hits: rt_core::first_hits::FirstHits,
}

impl From<&rt_core::part::Guides> for Aovs {
    /// Guides alone (a part's: parts keep no coverage, depth or ids).
    fn from(g: &rt_core::part::Guides) -> Self {
        Aovs {
            albedo: g.albedo.clone(),
            normal: g.normal.clone(),
            emission: g.emission.clone(),
            hits: Default::default(),
        }
    }
}

impl Aovs {
    /// The CPU backend's guides and first hits (`rt_core::cpu_render`), when it kept them.
    pub fn of_cpu(accumulation: &rt_core::cpu_render::CpuAccumulation) -> Option<Aovs> {
        let mut aovs = Aovs::from(accumulation.guides()?);
        aovs.hits = accumulation.first_hits().cloned().unwrap_or_default();
        Some(aovs)
    }
}

impl Image {
    /// The image denoised by `choice` (`rt_core::denoiser`: Open Image Denoise where it loads, or
    /// the edge-avoiding À-Trous filter) with `aovs` as guides and, for À-Trous, the per-pixel
    /// luminance variance; biased, for previews: the raw image stays the measurement.
    pub fn denoised(
        &self,
        aovs: &Aovs,
        choice: rt_core::denoiser::DenoiserChoice,
    ) -> Result<rt_core::denoiser::Denoised, String> {
        self.denoised_limited(aovs, choice, None, &|| true)
    }

    /// As `denoised`, with OIDN on at most `threads` threads, stopped once `keep_going` says no
    /// (`rt_core::denoiser::denoise_limited`).
    pub fn denoised_limited(
        &self,
        aovs: &Aovs,
        choice: rt_core::denoiser::DenoiserChoice,
        threads: Option<u32>,
        keep_going: &(dyn Fn() -> bool + Sync),
    ) -> Result<rt_core::denoiser::Denoised, String> {
        let color = self.rgb();
        let variance = rt_core::output::pixel_variance(&self.pixels, self.counts());
        rt_core::denoiser::denoise_limited(
            choice,
            &rt_core::denoise::DenoiseInput {
                width: self.width,
                height: self.height,
                color: &color,
                emission: &aovs.emission,
                albedo: &aovs.albedo,
                normal: &aovs.normal,
                variance: &variance,
            },
            threads,
            keep_going,
        )
    }
}
