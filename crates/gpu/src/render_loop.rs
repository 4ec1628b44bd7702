//! rt's one progressive render loop (`render_to`), for every render that takes its samples batch
//! by batch (`Batches`): the GPU's `Renderer` (one tile of rows), and `Progressive` — either
//! backend or both — which `rt-cli render`, `converge`, `bench`, `interactive`'s references and
//! the editor's render windows drive. The callers differ only in how large a batch they ask for
//! and in what they do between batches (a progress bar, a preview, a stop rule).

use std::sync::atomic::{AtomicBool, Ordering};

use crate::error::Result;

/// A render that takes its samples batch by batch.
pub trait Batches {
    /// Samples taken of every pixel still sampling.
    fn samples_done(&self) -> u32;
    /// Pixels adaptive sampling has not stopped.
    fn active_pixels(&self) -> usize;
    /// Up to `samples` more samples of every pixel still sampling (a batch may take fewer: a GPU
    /// batch is sized to its dispatch time, a CPU batch to `BATCH_DURATION`; one that `cancel`
    /// stops part-way adds nothing).
    fn take_batch(&mut self, samples: u32, cancel: &AtomicBool) -> Result<()>;
}

/// What the caller of `render_to` decides after each batch.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum AfterBatch {
    Continue,
    /// Stop here, for the reason named (a noise target met, a time limit reached, nobody left
    /// to show the image to).
    Stop(&'static str),
}

/// Why a progressive render ended.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Ended {
    /// Every pixel has its samples.
    Samples,
    /// Adaptive sampling stopped every pixel before that.
    Converged,
    /// The cancel flag was set.
    Cancelled,
    /// The caller's `AfterBatch::Stop`.
    Stopped(&'static str),
}

/// Batch after batch until every pixel still sampling has `spp` samples, adaptive sampling has
/// stopped every pixel, `cancel` is set or `after_batch` says stop. `batch(samples done)` is how
/// many samples to ask of the next batch (at least one, at most what is left); `after_batch` sees
/// the render after each, to report progress, read the image or decide to stop.
pub fn render_to<B: Batches + ?Sized>(
    run: &mut B,
    spp: u32,
    cancel: &AtomicBool,
    mut batch: impl FnMut(u32) -> u32,
    mut after_batch: impl FnMut(&B) -> Result<AfterBatch>,
) -> Result<Ended> {
    loop {
        if cancel.load(Ordering::Relaxed) {
            return Ok(Ended::Cancelled);
        }
        if run.active_pixels() == 0 {
            return Ok(Ended::Converged);
        }
        let done = run.samples_done();
        if done >= spp {
            return Ok(Ended::Samples);
        }
        run.take_batch(batch(done).clamp(1, spp - done), cancel)?;
        if let AfterBatch::Stop(why) = after_batch(run)? {
            return Ok(Ended::Stopped(why));
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A render that takes at most three samples a batch and whose pixels all stop at
    /// `converges_at` samples; it records each batch's request.
    struct Fake {
        done: u32,
        converges_at: u32,
        asked: Vec<u32>,
    }

    impl Batches for Fake {
        fn samples_done(&self) -> u32 {
            self.done
        }

        fn active_pixels(&self) -> usize {
            usize::from(self.done < self.converges_at)
        }

        fn take_batch(&mut self, samples: u32, _cancel: &AtomicBool) -> Result<()> {
            self.asked.push(samples);
            self.done += samples.min(3);
            Ok(())
        }
    }

    fn fake(converges_at: u32) -> Fake {
        Fake {
            done: 0,
            converges_at,
            asked: Vec::new(),
        }
    }

    fn go(_: &Fake) -> Result<AfterBatch> {
        Ok(AfterBatch::Continue)
    }

    #[test]
    fn batches_go_on_until_the_samples_are_taken() {
        let never = AtomicBool::new(false);
        let mut run = fake(u32::MAX);
        let ended = render_to(&mut run, 10, &never, |done| 10 - done, go).unwrap();
        assert_eq!(ended, Ended::Samples);
        assert_eq!(run.done, 10);
        // Each request is what is left (the backend took three at most).
        assert_eq!(run.asked, [10, 7, 4, 1]);
    }

    #[test]
    fn requests_are_at_least_one_and_at_most_what_is_left() {
        let never = AtomicBool::new(false);
        let mut run = fake(u32::MAX);
        render_to(
            &mut run,
            5,
            &never,
            |done| [0, 100][(done % 2) as usize],
            go,
        )
        .unwrap();
        assert!(
            run.asked.iter().all(|&n| (1..=5).contains(&n)),
            "{:?}",
            run.asked
        );
        assert_eq!(run.done, 5);
    }

    #[test]
    fn adaptive_sampling_cancelling_and_the_caller_end_it() {
        let never = AtomicBool::new(false);
        let mut run = fake(4);
        let ended = render_to(&mut run, 100, &never, |_| 2, go).unwrap();
        assert_eq!((ended, run.done), (Ended::Converged, 4));

        let cancel = AtomicBool::new(true);
        let mut run = fake(u32::MAX);
        let ended = render_to(&mut run, 100, &cancel, |_| 2, go).unwrap();
        assert_eq!((ended, run.done), (Ended::Cancelled, 0));

        let mut run = fake(u32::MAX);
        let stop_at_six = |r: &Fake| {
            Ok(match r.done >= 6 {
                true => AfterBatch::Stop("six"),
                false => AfterBatch::Continue,
            })
        };
        let ended = render_to(&mut run, 100, &never, |_| 2, stop_at_six).unwrap();
        assert_eq!((ended, run.done), (Ended::Stopped("six"), 6));
    }
}
