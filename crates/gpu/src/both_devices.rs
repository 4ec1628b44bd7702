//! `--device all`: the GPU and the native CPU backend render one frame together. Each batch's
//! samples are dealt out by a shared counter: each device takes the next range of sample indices
//! its own batch size asks for, renders it into its own exact sums, and comes back for more until
//! the batch is dealt, so the faster device takes more and neither waits for the other longer
//! than one of its batches. The sums are fixed-point integers (`rt_core::accumulation`), so the
//! frame is the sum of the two devices' sums whichever took which sample: the same image as one
//! device rendering every sample, up to the twins' float rounding per sample.

use std::sync::atomic::{AtomicBool, AtomicU32, Ordering};
use std::time::Instant;

use rt_core::accumulation::add_pixels;
use rt_core::cpu_render::{BATCH_DURATION, CpuAccumulation};
use rt_core::gpu_types::Frame;
use rt_core::{GpuScene, Scene};

use crate::error::{GpuError, Result};
use crate::image::{Aovs, Image};
use crate::renderer::Renderer;

/// A frame rendered by both devices.
pub struct BothDevices<'a> {
    gpu: Renderer<'a>,
    scene: &'a GpuScene,
    frame: Frame,
    cpu: CpuAccumulation,
    /// The CPU's next range size, grown while its ranges take under half of `BATCH_DURATION`.
    cpu_batch: u32,
    /// Samples of every pixel, on both devices together.
    samples: u32,
}

impl<'a> BothDevices<'a> {
    /// Both devices on `scene` (sample indices from `first_sample`, which `gpu` was made with
    /// too), keeping the CPU's denoiser guides when `guides` asks. Adaptive sampling decides per
    /// pixel on one device's sums, so it is refused here.
    pub fn new(
        gpu: Renderer<'a>,
        scene: &Scene,
        gpu_scene: &'a GpuScene,
        first_sample: u32,
        guides: bool,
    ) -> Result<Self> {
        if scene.settings.adaptive_threshold.is_some() {
            return Err(GpuError::Options(
                "--device all renders every sample of every pixel: adaptive sampling (or a noise \
                 target's per-pixel stops) needs one device; render with --no-adaptive or on \
                 one device"
                    .into(),
            ));
        }
        let frame = rt_core::frame::frame_for(scene, gpu_scene)
            .map_err(|e| GpuError::Options(e.to_string()))?;
        Ok(BothDevices {
            gpu,
            scene: gpu_scene,
            cpu: CpuAccumulation::new(&frame, first_sample, None, guides),
            frame,
            cpu_batch: 1,
            samples: 0,
        })
    }

    pub fn samples_done(&self) -> u32 {
        self.samples
    }

    /// The samples each device has taken, (CPU, GPU).
    pub fn shares(&self) -> (u32, u32) {
        (self.cpu.samples, self.gpu.samples_done())
    }

    pub fn gpu(&self) -> &Renderer<'a> {
        &self.gpu
    }

    /// Rays traced by both devices (the GPU's only with `Tuning::count_rays`).
    pub fn rays_traced(&self) -> u64 {
        self.gpu.rays_traced() + self.cpu.rays
    }

    /// `samples` more samples of every pixel, dealt to both devices (the CPU on a thread of its
    /// own, the GPU on this one). When `cancel` is set, or the GPU fails, the CPU takes no new
    /// range; a cancelled or failed batch leaves the frame unusable (parts of it are in the sums).
    pub fn render_batch(&mut self, samples: u32, cancel: &AtomicBool) -> Result<()> {
        let (start, end) = (self.samples, self.samples + samples);
        let next = AtomicU32::new(start);
        let gpu_failed = AtomicBool::new(false);
        let stop = || cancel.load(Ordering::Relaxed) || gpu_failed.load(Ordering::Relaxed);
        // Takes the next range of up to `want` samples, if any is left.
        let take = |want: u32| {
            let first = next.fetch_add(want, Ordering::Relaxed);
            (first < end).then(|| (first, want.min(end - first)))
        };
        let (scene, frame, first_sample) = (self.scene, self.frame, self.cpu.first_sample);
        let (cpu, cpu_batch, gpu) = (&mut self.cpu, &mut self.cpu_batch, &mut self.gpu);
        let cpu_finished = std::thread::scope(|scope| {
            let cpu_thread = scope.spawn(|| {
                while !stop() {
                    let Some((first, count)) = take(*cpu_batch) else {
                        return true;
                    };
                    let started = Instant::now();
                    // (It counts them in `cpu.samples`: the CPU's share.)
                    if !cpu.add_samples(scene, &frame, first_sample + first, count, &stop) {
                        return false;
                    }
                    if started.elapsed() < BATCH_DURATION / 2 {
                        *cpu_batch = cpu_batch.saturating_mul(2);
                    }
                }
                false
            });
            let gpu_result = (|| -> Result<()> {
                while let Some((first, count)) = take(gpu.batch_samples().max(1)) {
                    let mut done = 0;
                    while done < count {
                        gpu.seek(first + done);
                        let stats = gpu.render_batch(count - done)?;
                        done += stats.samples;
                    }
                    if cancel.load(Ordering::Relaxed) {
                        break;
                    }
                }
                Ok(())
            })();
            if gpu_result.is_err() {
                gpu_failed.store(true, Ordering::Relaxed);
            }
            let cpu_finished = cpu_thread.join().unwrap_or(false);
            gpu_result.map(|()| cpu_finished)
        })?;
        if !cpu_finished && !cancel.load(Ordering::Relaxed) {
            return Err(GpuError::Wgpu(
                "the CPU's share of --device all stopped before its samples were taken".into(),
            ));
        }
        self.samples = end;
        Ok(())
    }

    /// The frame: the two devices' sums added, every pixel with `samples_done` samples.
    pub fn read_image(&self) -> Result<Image> {
        let gpu = self.gpu.read_image()?;
        let sums = gpu
            .sums
            .iter()
            .zip(&self.cpu.sums)
            .map(|(g, c)| add_pixels(g, c))
            .collect();
        Ok(crate::outputs::mean_image(
            self.frame.width,
            self.frame.height,
            self.samples,
            sums,
            None,
        ))
    }

    /// The denoiser's guides: the GPU's, else the CPU's (each device's first hits estimate the
    /// same means).
    pub fn read_aovs(&self) -> Result<Option<Aovs>> {
        Ok(match self.gpu.read_aovs()? {
            Some(aovs) => Some(aovs),
            None => Aovs::of_cpu(&self.cpu),
        })
    }
}
