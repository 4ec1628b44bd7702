//! What the viewport's render thread traces with: the GPU's `Renderer`, or the native CPU backend
//! (`rt_core::cpu_render`) where the device is the CPU: the same calls (restart on a new frame, a
//! slice of samples, read the image and the denoiser's guides), so the ladder, the slicing and the
//! denoise thread do not know which one runs.
//!
//! Not `progressive::Progressive`, which drives a final render: that borrows its scene for the
//! render's lifetime and sizes its CPU batches to about 250 ms, where the view keeps its renderer
//! beside the `Arc` of the scene it was built on (a restart may bring another) and cuts a batch
//! short on every change.

use std::sync::Arc;
use std::time::{Duration, Instant};

use rt_core::cpu_render::CpuAccumulation;
use rt_core::gpu_types::Frame;
use rt_core::{GpuScene, Scene};

use crate::image::{Aovs, Image};
use crate::{BatchStats, GpuContext, RenderOptions, Renderer};

/// The viewport's renderer on either backend.
pub(super) enum LiveRenderer<'a> {
    Gpu(Box<Renderer<'a>>),
    Cpu(Box<CpuLive>),
}

/// The CPU backend's state for one ladder step: the scene, the step's frame and its samples so far
/// (with the denoiser's guides).
pub(super) struct CpuLive {
    scene: Arc<GpuScene>,
    frame: Frame,
    accumulation: CpuAccumulation,
}

impl CpuLive {
    fn new(scene: Arc<GpuScene>, frame: Frame) -> Self {
        CpuLive {
            accumulation: CpuAccumulation::new(&frame, 0, None, true),
            scene,
            frame,
        }
    }
}

impl<'a> LiveRenderer<'a> {
    /// A renderer for `scene` on `ctx` (the GPU; `None`: the CPU backend), holding `full`'s
    /// pixels and started on `frame`.
    pub(super) fn new(
        ctx: Option<&'a GpuContext>,
        full: &Scene,
        scene: &Arc<GpuScene>,
        frame: Frame,
        options: RenderOptions,
    ) -> Result<Self, String> {
        let Some(ctx) = ctx else {
            return Ok(LiveRenderer::Cpu(Box::new(CpuLive::new(
                scene.clone(),
                frame,
            ))));
        };
        let mut r = Renderer::for_scene(ctx, full, scene, options).map_err(|e| e.to_string())?;
        r.restart(scene, frame).map_err(|e| e.to_string())?;
        Ok(LiveRenderer::Gpu(Box::new(r)))
    }

    /// Starts over on `frame` of `scene`; false where a new renderer is needed (another GPU
    /// pipeline or more pixels). The CPU backend restarts on any frame.
    pub(super) fn restart(&mut self, scene: &Arc<GpuScene>, frame: Frame) -> bool {
        match self {
            LiveRenderer::Gpu(r) => r.restart(scene, frame).is_ok(),
            LiveRenderer::Cpu(c) => {
                **c = CpuLive::new(scene.clone(), frame);
                true
            }
        }
    }

    /// Whether the CPU backend renders (the device, or standing in while the GPU's kernel compiles).
    pub(super) fn on_cpu(&self) -> bool {
        matches!(self, LiveRenderer::Cpu(_))
    }

    pub(super) fn samples_done(&self) -> u32 {
        match self {
            LiveRenderer::Gpu(r) => r.samples_done(),
            LiveRenderer::Cpu(c) => c.accumulation.samples,
        }
    }

    /// Up to `max_samples` more samples while `another` (asked after each dispatch or CPU batch
    /// with its duration) says one more fits; `stale` stops a CPU batch part-way (it then adds
    /// nothing and the slice is incomplete).
    pub(super) fn render_slice(
        &mut self,
        max_samples: u32,
        mut another: impl FnMut(Duration) -> bool,
        stale: &(dyn Fn() -> bool + Sync),
    ) -> Result<BatchStats, String> {
        let c = match self {
            LiveRenderer::Gpu(r) => {
                return r
                    .render_slice(max_samples, |last| another(last) && !stale())
                    .map_err(|e| e.to_string());
            }
            LiveRenderer::Cpu(c) => c,
        };
        let mut stats = BatchStats::default();
        // One sample of every pixel a batch: the accumulation holds whole batches, and a batch
        // is what a change can cut short (row by row).
        while stats.samples < max_samples {
            let started = Instant::now();
            if !c.accumulation.add_batch_until(&c.scene, &c.frame, 1, stale) {
                return Ok(stats);
            }
            stats.samples += 1;
            stats.dispatches += 1;
            stats.last_dispatch = started.elapsed();
            stats.longest_dispatch = stats.longest_dispatch.max(stats.last_dispatch);
            if !another(stats.last_dispatch) {
                break;
            }
        }
        stats.complete = true;
        Ok(stats)
    }

    pub(super) fn read_image(&self) -> Result<Image, String> {
        match self {
            LiveRenderer::Gpu(r) => r.read_image().map_err(|e| e.to_string()),
            LiveRenderer::Cpu(c) => Ok(crate::progressive::image_of(&c.accumulation)),
        }
    }

    pub(super) fn read_aovs(&self) -> Result<Option<Aovs>, String> {
        match self {
            LiveRenderer::Gpu(r) => r.read_aovs().map_err(|e| e.to_string()),
            LiveRenderer::Cpu(c) => Ok(Aovs::of_cpu(&c.accumulation)),
        }
    }
}
