//! Adaptive sampling's rule, the one both backends apply between batches (the GPU's
//! `rt_gpu::adaptive`, the CPU's `cpu_render`).

/// Adaptive sampling (as Cycles' noise threshold): after `min_samples`, a pixel stops taking
/// samples once the square root of its estimated relMSE term (`metrics::pixel_rel_mse`) is at
/// most `threshold` and its eight neighbours' are too (so a pixel dark by chance among noisy ones
/// goes on). Each pixel's mean stays the running mean of its own samples, and its count is kept.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Adaptive {
    pub threshold: f32,
    pub min_samples: u32,
}

impl Adaptive {
    /// The rule a scene's settings ask for (`RenderSettings::adaptive_threshold`), if any.
    pub fn of_settings(settings: &crate::RenderSettings) -> Option<Adaptive> {
        settings.adaptive_threshold.map(|threshold| Adaptive {
            threshold,
            min_samples: crate::scene::ADAPTIVE_MIN_SAMPLES,
        })
    }

    /// The stop marks after a batch: `stopped` holds, per pixel of a `width`-wide image or tile,
    /// 0 while it samples, else the count it stopped at; `pixels` are the means after
    /// `samples_done` samples of every pixel still sampling. Returns the new marks (pixels that
    /// stop now get `samples_done`).
    pub fn settle(
        &self,
        pixels: &[[f32; 4]],
        stopped: &[u32],
        width: usize,
        samples_done: u32,
    ) -> Vec<u32> {
        if samples_done < self.min_samples {
            return stopped.to_vec();
        }
        let limit = f64::from(self.threshold).powi(2);
        let converged: Vec<bool> = pixels
            .iter()
            .zip(stopped)
            .map(|(p, &s)| s != 0 || crate::metrics::pixel_rel_mse(*p, samples_done) <= limit)
            .collect();
        let width = width.max(1);
        let rows = pixels.len() / width;
        let mut out = stopped.to_vec();
        for y in 0..rows {
            for x in 0..width {
                let settled = (y.saturating_sub(1)..(y + 2).min(rows)).all(|ny| {
                    (x.saturating_sub(1)..(x + 2).min(width)).all(|nx| converged[ny * width + nx])
                });
                if out[y * width + x] == 0 && settled {
                    out[y * width + x] = samples_done;
                }
            }
        }
        out
    }
}
