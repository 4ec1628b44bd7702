//! The native CPU backend: the Rust twin of the estimator (`reference`, function for function the
//! kernels' WGSL) run over the image on every core with rayon. Each pixel draws the same sample
//! streams as on the GPU and keeps the same fixed-point sums (`accumulation`), so a CPU image
//! equals a GPU one up to the twins' float rounding, and a CPU render part merges with GPU parts
//! of the same frame (`rt-cli merge`).
//!
//! Work is split into batches of samples over the whole image; a batch is split by rows across
//! threads, and checks for cancellation before each row. A cancelled batch adds nothing, so the
//! sums always hold whole batches: every pixel the same samples.

use std::sync::atomic::{AtomicBool, Ordering};

use rayon::prelude::*;

use crate::accumulation::{PixelSums, add_pixels, add_sample};
use crate::gpu_scene::GpuScene;
use crate::gpu_types::Frame;
use crate::reference::radiance;

/// The threads a batch is spread over (rayon's pool: one per core unless `RAYON_NUM_THREADS` says
/// otherwise).
pub fn threads() -> usize {
    rayon::current_num_threads()
}

/// A frame's samples accumulated on the CPU.
#[derive(Clone, Debug)]
pub struct CpuAccumulation {
    pub width: u32,
    pub height: u32,
    /// The index of the first sample taken (a render part's range start).
    pub first_sample: u32,
    /// Samples taken of every pixel so far (samples `first_sample..first_sample + samples`).
    pub samples: u32,
    /// Per pixel, row-major: the sums of its samples' radiance and squared luminance.
    pub sums: Vec<PixelSums>,
}

impl CpuAccumulation {
    /// No samples yet of a `frame.width × frame.height` image, starting at sample `first_sample`.
    pub fn new(frame: &Frame, first_sample: u32) -> Self {
        CpuAccumulation {
            width: frame.width,
            height: frame.height,
            first_sample,
            samples: 0,
            sums: vec![PixelSums::default(); (frame.width * frame.height) as usize],
        }
    }

    /// Takes the next `count` samples of every pixel. Returns false, having added nothing, when
    /// `cancel` is set before the batch ends.
    pub fn add_batch(
        &mut self,
        scene: &GpuScene,
        frame: &Frame,
        count: u32,
        cancel: &AtomicBool,
    ) -> bool {
        let width = self.width as usize;
        let first = self.first_sample + self.samples;
        let rows: Vec<Option<Vec<PixelSums>>> = (0..self.height)
            .into_par_iter()
            .map(|y| {
                if cancel.load(Ordering::Relaxed) {
                    return None;
                }
                let mut row = vec![PixelSums::default(); width];
                for (x, sums) in row.iter_mut().enumerate() {
                    for s in first..first + count {
                        // A sample that is not finite (or absurdly large) is dropped, as the
                        // kernels drop it: it adds zero and still counts.
                        add_sample(sums, radiance(scene, frame, x as u32, y, s).to_array());
                    }
                }
                Some(row)
            })
            .collect();
        if rows.iter().any(Option::is_none) {
            return false;
        }
        for (y, row) in rows.into_iter().flatten().enumerate() {
            let line = &mut self.sums[y * width..(y + 1) * width];
            for (sums, add) in line.iter_mut().zip(&row) {
                *sums = add_pixels(sums, add);
            }
        }
        self.samples += count;
        true
    }

    /// Each pixel's mean radiance (rgb) and mean squared luminance (a).
    pub fn pixels(&self) -> Vec<[f32; 4]> {
        self.sums
            .iter()
            .map(|s| crate::accumulation::pixel_mean(s, self.samples))
            .collect()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn cornell(width: u32, height: u32) -> (GpuScene, Frame) {
        let mut scene = crate::assets::cornell_box().unwrap();
        scene.settings.width = width;
        scene.settings.height = height;
        let gpu = GpuScene::build(&scene).unwrap();
        let frame = crate::frame::frame_for(&scene, &gpu).unwrap();
        (gpu, frame)
    }

    /// The sums do not depend on how samples are batched (exact fixed-point addition), a
    /// cancelled batch adds nothing, and the means are the reference renderer's.
    #[test]
    fn batches_sum_exactly_and_a_cancelled_batch_adds_nothing() {
        let (scene, frame) = cornell(12, 9);
        let go = AtomicBool::new(false);
        let mut one_by_one = CpuAccumulation::new(&frame, 3);
        assert!(one_by_one.add_batch(&scene, &frame, 1, &go));
        assert!(one_by_one.add_batch(&scene, &frame, 2, &go));
        let mut at_once = CpuAccumulation::new(&frame, 3);
        assert!(at_once.add_batch(&scene, &frame, 3, &go));
        assert_eq!(one_by_one.sums, at_once.sums);
        assert_eq!(one_by_one.samples, 3);
        let before = at_once.clone();
        let stop = AtomicBool::new(true);
        assert!(!at_once.add_batch(&scene, &frame, 1, &stop));
        assert_eq!(
            (&at_once.sums, at_once.samples),
            (&before.sums, before.samples)
        );
        // Samples 3..6 of every pixel, as `reference::radiance` gives them.
        let expected = |x: u32, y: u32| {
            (3..6).fold(glam::Vec3::ZERO, |s, i| {
                s + radiance(&scene, &frame, x, y, i)
            }) / 3.0
        };
        for (i, p) in before.pixels().iter().enumerate() {
            let e = expected(i as u32 % 12, i as u32 / 12);
            for c in 0..3 {
                assert!(
                    (p[c] - e[c]).abs() <= 1e-5 * e[c].abs().max(1.0),
                    "pixel {i}"
                );
            }
        }
        assert!(before.pixels().iter().any(|p| p[0] > 0.0), "all black");
    }
}
