//! When a renderer rebuilds its pipeline (`Tuning::pipeline_rebuilds`): some CPU drivers hold memory per compiled pipeline that grows
//! while it runs, and a fresh build lets them free it.

use std::time::{Duration, Instant};

use crate::context::GpuContext;
use crate::options::{
    CPU_PIPELINE_LIFETIME, Kernel, PipelineRebuilds, REBUILD_AMORTISATION, RenderOptions,
};

/// A renderer's pipeline's age, and when it is due for a rebuild.
pub(crate) struct PipelineLifetime {
    /// Kernel time since the pipeline was built, not counting its first batch (see
    /// `PipelineRebuilds::Every`), and that first batch's time (its compile).
    ran: Duration,
    first_batch: Option<Duration>,
    lifetime: Option<Duration>,
    /// Scale `first_batch` by this for the least kernel time between rebuilds.
    amortisation: u32,
    rebuilds: u32,
}

impl PipelineLifetime {
    /// The lifetime `options` ask for on `ctx`'s adapter; `None` never rebuilds.
    pub fn new(ctx: &GpuContext, options: &RenderOptions) -> Self {
        let (lifetime, amortisation) = match options.tuning.pipeline_rebuilds {
            PipelineRebuilds::Never => (None, 0),
            PipelineRebuilds::Every(lifetime) => (Some(lifetime), 0),
            PipelineRebuilds::OnGrowingCpuDrivers { lifetime } => {
                // Only the megakernel's pipelines grow (tests/memory.rs); Mesa 25.0's megakernel
                // stays flat (performance-log.md), other CPU drivers may not.
                let grows = options.kernel == Kernel::Megakernel
                    && ctx.info.device_type == wgpu::DeviceType::Cpu
                    && ctx.mesa_version().is_none_or(|v| v < (25, 0));
                match (grows, lifetime) {
                    (false, _) => (None, 0),
                    (true, Some(lifetime)) => (Some(lifetime), 0),
                    (true, None) => (Some(CPU_PIPELINE_LIFETIME), REBUILD_AMORTISATION),
                }
            }
        };
        PipelineLifetime {
            ran: Duration::ZERO,
            first_batch: None,
            lifetime,
            amortisation,
            rebuilds: 0,
        }
    }

    /// Whether the pipeline has run its lifetime (and enough longer than its compile took).
    pub fn due(&self) -> bool {
        matches!(
            (self.lifetime, self.first_batch),
            (Some(life), Some(first)) if self.ran >= life.max(first * self.amortisation)
        )
    }

    /// Whether the pipeline has not finished a batch yet (on lavapipe the first batch after a
    /// build holds its JIT compile).
    pub fn fresh(&self) -> bool {
        self.first_batch.is_none()
    }

    /// Counts a batch that began at `started`.
    pub fn batch_done(&mut self, started: Instant) {
        match self.first_batch {
            None => {
                self.first_batch = Some(started.elapsed());
                log::debug!("first batch of this pipeline: {:.2?}", started.elapsed());
            }
            Some(_) => self.ran += started.elapsed(),
        }
    }

    /// Starts over after a rebuild.
    pub fn rebuilt(&mut self) {
        self.ran = Duration::ZERO;
        self.first_batch = None;
        self.rebuilds += 1;
    }

    /// How often the pipeline was rebuilt.
    pub fn rebuilds(&self) -> u32 {
        self.rebuilds
    }
}
