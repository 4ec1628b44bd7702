//! Adaptive sampling's state on the CPU and the GPU: which pixels have stopped (and at which
//! count), and the list of those still sampling, which the wavefront's waves walk. The rule is
//! `rt_core::adaptive::Adaptive::settle`; `Renderer::render_batch` calls `update` after every batch.

use wgpu::util::DeviceExt;

use crate::bindings::{self, Binding};
use crate::buffers::output_buffer;
use crate::context::GpuContext;
use crate::error::Result;
use crate::options::Adaptive;

/// A tile's stop marks and pixels still sampling.
pub(crate) struct AdaptiveState {
    rule: Option<Adaptive>,
    width: usize,
    /// Per pixel of the tile: 0 while it takes samples, else the count it stopped at (mirrored in
    /// `pixel_done`, which the megakernel reads); empty without adaptive sampling.
    stopped: Vec<u32>,
    /// The tile slots of the pixels still sampling, ascending (mirrored in `active_slots`, which
    /// the wavefront kernels read); all of them without adaptive sampling.
    active: Vec<u32>,
    pixel_done: wgpu::Buffer,
    active_slots: wgpu::Buffer,
}

impl AdaptiveState {
    /// Every pixel of a `width` x `rows` tile sampling; with `rule` `None` the buffers are
    /// placeholders the kernels never read. Call inside `GpuContext::scoped`.
    pub fn new(ctx: &GpuContext, rule: Option<Adaptive>, width: u32, rows: u32) -> Self {
        let pixels = width as usize * rows as usize;
        let active: Vec<u32> = (0..pixels as u32).collect();
        let (stopped, marks, list): (Vec<u32>, u64, &[u8]) = match rule {
            Some(_) => (
                vec![0; pixels],
                pixels as u64 * 4,
                bytemuck::cast_slice(&active),
            ),
            None => (Vec::new(), 16, &[0; 16]),
        };
        let pixel_done = output_buffer(ctx, "adaptive sampling stops", marks.max(16));
        let active_slots = ctx
            .device
            .create_buffer_init(&wgpu::util::BufferInitDescriptor {
                label: Some("pixels still sampling"),
                contents: if list.is_empty() { &[0; 16] } else { list },
                usage: wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_DST,
            });
        AdaptiveState {
            rule,
            width: width as usize,
            stopped,
            active,
            pixel_done,
            active_slots,
        }
    }

    /// The bytes its buffers need, for the adapter's limits.
    pub fn buffer_bytes(rule: Option<Adaptive>, pixels: u64) -> u64 {
        if rule.is_some() { pixels * 4 } else { 16 }
    }

    /// (binding, buffer) of the stop marks and the list, for the kernels' bind groups.
    pub fn bound(&self) -> [(Binding, wgpu::Buffer); 2] {
        [
            (bindings::PIXEL_DONE, self.pixel_done.clone()),
            (bindings::ACTIVE_SLOTS, self.active_slots.clone()),
        ]
    }

    /// Whether adaptive sampling is on.
    pub fn enabled(&self) -> bool {
        self.rule.is_some()
    }

    /// The pixels still sampling (tile slots, ascending).
    pub fn active(&self) -> &[u32] {
        &self.active
    }

    /// Each pixel's sample count after `samples_done` batches' samples, with adaptive sampling.
    pub fn counts(&self, samples_done: u32) -> Option<Vec<u32>> {
        self.rule?;
        Some(
            self.stopped
                .iter()
                .map(|&s| if s == 0 { samples_done } else { s })
                .collect(),
        )
    }

    /// After a batch (`samples_done` samples in all, the tile's accumulation `pixels`): stops each
    /// pixel whose noise estimate is at most the threshold once it and its eight neighbours (those
    /// inside the tile) are there. The new marks are uploaded before they are kept, so after a
    /// failed upload the kernels and this state still agree.
    pub fn update(
        &mut self,
        ctx: &GpuContext,
        samples_done: u32,
        pixels: impl FnOnce() -> Result<Vec<[f32; 4]>>,
    ) -> Result<()> {
        let Some(rule) = self.rule else {
            return Ok(());
        };
        if samples_done < rule.min_samples || self.active.is_empty() {
            return Ok(());
        }
        let stopped = rule.settle(&pixels()?, &self.stopped, self.width, samples_done);
        if stopped == self.stopped {
            return Ok(());
        }
        let active: Vec<u32> = self
            .active
            .iter()
            .copied()
            .filter(|&slot| stopped[slot as usize] == 0)
            .collect();
        ctx.scoped(|| {
            ctx.queue
                .write_buffer(&self.pixel_done, 0, bytemuck::cast_slice(&stopped));
            if !active.is_empty() {
                ctx.queue
                    .write_buffer(&self.active_slots, 0, bytemuck::cast_slice(&active));
            }
        })?;
        self.active = active;
        self.stopped = stopped;
        Ok(())
    }
}
