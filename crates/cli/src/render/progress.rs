//! `rt-cli render` around rt's one progressive loop (`rt_gpu::render_loop::render_to`), on either
//! backend (`Progressive`: the GPU's `Renderer` or the native CPU backend): a progress bar, the
//! checkpoint image read back for the noise estimate and for saving after a failure, and the stop
//! rules (noise target, time limit).

use std::sync::atomic::AtomicBool;
use std::time::Instant;

use indicatif::{ProgressBar, ProgressStyle};
use rt_core::Scene;
use rt_gpu::GpuError;
use rt_gpu::progressive::Progressive;
use rt_gpu::render_loop::{AfterBatch, Ended, render_to};

use super::RenderArgs;
use crate::summary::Finish;

/// Renders `scene`'s samples (a shard's own, `range`, or the frame's) on `run`. `before_batch`
/// is called with the number of batches so far before each (the GPU's fault injection in test
/// builds). If a batch fails, returns the error with the image last read back (`Failed`, for
/// `render_failed` to save).
pub fn render_progressively(
    args: &RenderArgs,
    run: &mut Progressive,
    scene: &Scene,
    range: Option<[u32; 2]>,
    mut before_batch: impl FnMut(u32),
) -> Result<Finish, Box<Failed>> {
    let spp = range.map_or(scene.settings.samples_per_pixel, |[a, b]| b - a);
    let bar = progress_bar(args.open_ended(), spp);
    let started = Instant::now();
    let pixels = u64::from(scene.settings.width) * u64::from(scene.settings.height);
    let mut checkpoint = Checkpoint::default();
    // The CLI renders to the end or to a stop rule; nothing cancels a batch part-way.
    let never = AtomicBool::new(false);
    let mut batches = 0u32;
    // With a noise target, batches grow geometrically so the stop overshoots by at most 1/8; the
    // backend sizes batches to its time otherwise.
    let batch = |done: u32| {
        before_batch(batches);
        batches += 1;
        match args.noise_target {
            Some(_) => (done / 8).max(1),
            None => spp - done,
        }
    };
    let after_batch = |run: &Progressive| {
        checkpoint.update(run, args.noise_target.is_some())?;
        let done = run.samples_done();
        let secs = started.elapsed().as_secs_f64().max(1e-9);
        bar.set_position(u64::from(done));
        bar.set_message(format!(
            "{:.2} Mpaths/s  noise ≈ {:.4}",
            pixels as f64 * f64::from(done) / secs / 1e6,
            checkpoint.noise
        ));
        Ok(stop_rule(args, checkpoint.noise, secs).map_or(AfterBatch::Continue, AfterBatch::Stop))
    };
    let ended = render_to(run, spp, &never, batch, after_batch);
    bar.finish_and_clear();
    let stopped_by = match ended {
        Err(error) => {
            return Err(Box::new(Failed {
                error,
                last_image: checkpoint.image,
            }));
        }
        _ if run.active_pixels() == 0 => "adaptive sampling: every pixel converged",
        Ok(Ended::Stopped(rule)) => rule,
        Ok(_) => "samples per pixel",
    };
    Ok(Finish {
        render_time: started.elapsed(),
        stopped_by,
    })
}

/// A render that failed part-way: why, and the image last read back before it.
pub struct Failed {
    pub error: GpuError,
    pub last_image: Option<rt_gpu::Image>,
}

/// A bar of `spp` samples, or a spinner when the render is open-ended.
fn progress_bar(open_ended: bool, spp: u32) -> ProgressBar {
    let bar = if open_ended {
        ProgressBar::new_spinner()
    } else {
        ProgressBar::new(u64::from(spp))
    };
    let template = if open_ended {
        "{spinner} [{elapsed_precise}] {pos} spp  {msg}"
    } else {
        "{spinner} [{elapsed_precise}] {bar:40} {pos}/{len} spp  {msg} (eta {eta})"
    };
    bar.set_style(
        ProgressStyle::with_template(template).unwrap_or_else(|_| ProgressStyle::default_bar()),
    );
    bar
}

/// Which rule stops the render after a batch, if one does: the noise target, then the time limit
/// (`secs` into the render).
fn stop_rule(args: &RenderArgs, noise: f64, secs: f64) -> Option<&'static str> {
    if args.noise_target.is_some_and(|target| noise <= target) {
        Some("noise target")
    } else if args.time_limit.is_some_and(|limit| secs >= limit) {
        Some("time limit")
    } else {
        None
    }
}

/// The image as last read back, and its estimated noise.
struct Checkpoint {
    noise: f64,
    at: Option<Instant>,
    /// If the GPU fails mid-render, this is what can still be saved.
    image: Option<rt_gpu::Image>,
}

impl Default for Checkpoint {
    fn default() -> Self {
        Checkpoint {
            noise: f64::INFINITY,
            at: None,
            image: None,
        }
    }
}

impl Checkpoint {
    /// Reads back (for the noise estimate, and as a checkpoint) when the noise decides the stop,
    /// else about once a second.
    fn update(&mut self, run: &Progressive, noise_decides: bool) -> rt_gpu::Result<()> {
        let due = noise_decides || self.at.is_none_or(|t| t.elapsed().as_secs_f64() >= 1.0);
        if due {
            let image = run.read_image()?;
            self.noise = image.estimated_noise();
            self.at = Some(Instant::now());
            self.image = Some(image);
        }
        Ok(())
    }
}
