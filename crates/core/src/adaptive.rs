//! Adaptive sampling, the rule and its state, shared by both backends (the GPU's
//! `rt_gpu::adaptive` feeds it each batch's sums read back; the CPU's `cpu_render` its own).
//!
//! **Why two streams.** A pixel that stops once its own samples look converged is biased where
//! rare bright paths decide its value (caustics): one that has not yet met such a path looks
//! converged and stops low, one that has keeps sampling and dilutes it (a 4% darker caustic scene,
//! docs/quality.md). So each pixel's samples are dealt into two independent streams, and each
//! stream decides only for the other:
//!
//! - stream s *fires* at pixel i when its own estimate is under the threshold at i and at the
//!   eight neighbours (or they have fired in s already); it then freezes the *other* stream's sums
//!   at that moment, which is what the image keeps of that stream;
//! - a pixel stops taking samples when both streams have fired;
//! - its value is the mean of the two streams' kept means: (S₀/n₀ + S₁/n₁) / 2, with n₀ the
//!   samples stream 0 held when stream 1 fired, and so on.
//!
//! When stream 1 fires depends on stream 1's samples (and its neighbours' stream 1) alone, never
//! on stream 0's, so n₀ is independent of the values it counts and E[S₀/n₀] is the pixel's
//! expectation (optional stopping by an independent clock); likewise for stream 1. The image is
//! unbiased; the price is the samples a stream takes after it was frozen (until the other
//! fires), spent on the decision only. A render stopped by its sample or time limit keeps what
//! each stream holds then.

/// The rule (as Cycles' noise threshold, decided per stream): after `min_samples` in all, a
/// stream fires once the square root of its estimated relMSE term for the pixel's final value
/// (`metrics::pixel_rel_mse` of the stream, halved: the value averages two streams) is at most
/// `threshold` at the pixel and at its eight neighbours.
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
            min_samples: settings.adaptive_min_samples,
        })
    }
}

use crate::accumulation::{FixedSum, PixelSums};

/// Sums of radiance (r, g, b) and squared luminance, and how many samples they hold.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct StreamSums {
    pub sums: [f64; 4],
    pub count: u32,
}

impl StreamSums {
    fn mean(&self) -> Option<[f64; 4]> {
        (self.count > 0).then(|| self.sums.map(|s| s / f64::from(self.count)))
    }
}

/// One pixel's two streams.
#[derive(Clone, Copy, Debug, Default)]
struct PixelStreams {
    running: [StreamSums; 2],
    /// `fired[s]`: stream s has met the rule (and frozen the other stream's `kept`).
    fired: [bool; 2],
    /// `kept[s]`: stream s's sums when the other stream fired.
    kept: [StreamSums; 2],
}

impl PixelStreams {
    /// What the image keeps of stream `s`: its frozen sums, or all it holds while the other
    /// stream has not fired.
    fn kept(&self, s: usize) -> StreamSums {
        if self.fired[1 - s] {
            self.kept[s]
        } else {
            self.running[s]
        }
    }
}

/// A tile's (or image's) adaptive sampling: each pixel's streams, and which pixels stopped.
#[derive(Clone, Debug)]
pub struct AdaptiveStreams {
    rule: Adaptive,
    width: usize,
    pixels: Vec<PixelStreams>,
    /// Per pixel: 0 while it takes samples, else the samples it had taken when it stopped.
    stopped: Vec<u32>,
    /// Samples every pixel still sampling holds, per stream.
    dealt: [u32; 2],
}

impl AdaptiveStreams {
    /// Every pixel of a `width`-wide image of `pixels` pixels sampling, no samples yet.
    pub fn new(rule: Adaptive, width: usize, pixels: usize) -> Self {
        AdaptiveStreams {
            rule,
            width: width.max(1),
            pixels: vec![PixelStreams::default(); pixels],
            stopped: vec![0; pixels],
            dealt: [0; 2],
        }
    }

    pub fn rule(&self) -> Adaptive {
        self.rule
    }

    /// The stream a batch dealt to one stream as a whole should go to: the one with fewer samples
    /// (a choice by the schedule alone, never by the samples' values).
    pub fn next_stream(&self) -> usize {
        usize::from(self.dealt[1] < self.dealt[0])
    }

    /// Adds a batch to every pixel still sampling: `samples[s]` samples to stream s, whose sums
    /// for pixel i are `added(i)[s]`.
    pub fn add(&mut self, samples: [u32; 2], added: impl Fn(usize) -> [[f64; 4]; 2]) {
        for (i, pixel) in self.pixels.iter_mut().enumerate() {
            if self.stopped[i] != 0 {
                continue;
            }
            let added = added(i);
            for s in 0..2 {
                let stream = &mut pixel.running[s];
                for (sum, a) in stream.sums.iter_mut().zip(added[s]) {
                    *sum += a;
                }
                stream.count += samples[s];
            }
        }
        self.dealt[0] += samples[0];
        self.dealt[1] += samples[1];
    }

    /// Applies the rule after a batch: streams that meet it fire, and pixels whose streams have
    /// both fired stop (at their count so far).
    pub fn settle(&mut self) {
        let samples_done = self.dealt[0] + self.dealt[1];
        if samples_done < self.rule.min_samples {
            return;
        }
        let limit = f64::from(self.rule.threshold).powi(2);
        let rows = self.pixels.len() / self.width;
        for s in 0..2 {
            // Stream s's view of the image alone: its own estimates, and where it fired.
            let converged: Vec<bool> = self
                .pixels
                .iter()
                .map(|p| {
                    p.fired[s]
                        || p.running[s].mean().is_some_and(|m| {
                            let m = m.map(|c| c as f32);
                            crate::metrics::pixel_rel_mse(m, p.running[s].count) / 2.0 <= limit
                        })
                })
                .collect();
            for y in 0..rows {
                for x in 0..self.width {
                    let i = y * self.width + x;
                    if self.pixels[i].fired[s] {
                        continue;
                    }
                    let settled = (y.saturating_sub(1)..(y + 2).min(rows)).all(|ny| {
                        (x.saturating_sub(1)..(x + 2).min(self.width))
                            .all(|nx| converged[ny * self.width + nx])
                    });
                    if settled {
                        let pixel = &mut self.pixels[i];
                        pixel.fired[s] = true;
                        pixel.kept[1 - s] = pixel.running[1 - s];
                    }
                }
            }
        }
        for (stop, pixel) in self.stopped.iter_mut().zip(&self.pixels) {
            if *stop == 0 && pixel.fired[0] && pixel.fired[1] {
                *stop = pixel.running[0].count + pixel.running[1].count;
            }
        }
    }

    /// Per pixel: 0 while it takes samples, else the samples it took.
    pub fn stopped(&self) -> &[u32] {
        &self.stopped
    }

    /// The pixels still taking samples.
    pub fn active(&self) -> usize {
        self.stopped.iter().filter(|&&s| s == 0).count()
    }

    /// The samples each pixel took.
    pub fn samples_taken(&self) -> Vec<u32> {
        self.pixels
            .iter()
            .map(|p| p.running[0].count + p.running[1].count)
            .collect()
    }

    /// Pixel i's value, (S₀/n₀ + S₁/n₁) / 2 over what each stream keeps (radiance and mean
    /// squared luminance), and the count of one stream of samples with the same variance,
    /// 4 / (1/n₀ + 1/n₁) (both streams' samples when they keep equally many): what the image's
    /// noise estimates read as the pixel's count.
    pub fn value(&self, i: usize) -> ([f64; 4], u32) {
        let pixel = &self.pixels[i];
        let kept = [pixel.kept(0), pixel.kept(1)];
        match (kept[0].mean(), kept[1].mean()) {
            (Some(a), Some(b)) => {
                let (n0, n1) = (f64::from(kept[0].count), f64::from(kept[1].count));
                let effective = (4.0 / (1.0 / n0 + 1.0 / n1)).round() as u32;
                ([0, 1, 2, 3].map(|c| (a[c] + b[c]) / 2.0), effective)
            }
            (Some(m), None) | (None, Some(m)) => (m, kept[0].count.max(kept[1].count)),
            (None, None) => ([0.0; 4], 0),
        }
    }

    /// The image as sums and counts (the form renders and parts keep): per pixel, its `value`
    /// times its count in fixed point, and that count.
    pub fn sums_and_counts(&self) -> (Vec<PixelSums>, Vec<u32>) {
        (0..self.pixels.len())
            .map(|i| {
                let (mean, count) = self.value(i);
                (mean.map(|m| f64_to_fixed(m * f64::from(count))), count)
            })
            .unzip()
    }
}

/// The fixed-point sums as `f64` (what a stream adds up).
pub fn sums_f64(sums: &PixelSums) -> [f64; 4] {
    sums.map(crate::accumulation::to_f64)
}

/// `v` in the accumulation's fixed point, rounded to its 2^-64 step (saturating far beyond what
/// a pixel's sums hold).
fn f64_to_fixed(v: f64) -> FixedSum {
    let magnitude = (v.abs() * 64f64.exp2()) as u128;
    let words = [0, 1, 2, 3].map(|k| (magnitude >> (32 * k)) as u32);
    if v < 0.0 {
        crate::accumulation::negate(words)
    } else {
        words
    }
}

#[cfg(test)]
mod tests;
