//! Adaptive sampling's state on the CPU and the GPU: its two streams (`rt_core::adaptive`: each
//! whole batch goes to one of them), which pixels have stopped, and the list of those still
//! sampling, which the wavefront's waves walk. `Renderer::render_batch` calls `update` after every
//! batch with the accumulation it read back; what a batch added is the difference of the sums.

use wgpu::util::DeviceExt;

use crate::bindings::{self, Binding};
use crate::buffers::output_buffer;
use crate::context::GpuContext;
use crate::error::Result;
use crate::options::Adaptive;
use rt_core::accumulation::PixelSums;
use rt_core::adaptive::{AdaptiveStreams, sums_f64};

/// A tile's stop marks and pixels still sampling.
pub(crate) struct AdaptiveState {
    /// The streams (their `stopped` marks are mirrored in `pixel_done`, which the megakernel
    /// reads); `None` without adaptive sampling.
    streams: Option<AdaptiveStreams>,
    /// The accumulation's sums after the last batch, per pixel of the tile (as `f64`).
    previous: Vec<[f64; 4]>,
    /// Samples of every pixel still sampling after the last batch.
    previous_samples: u32,
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
        let (marks, list): (u64, &[u8]) = match rule {
            Some(_) => (pixels as u64 * 4, bytemuck::cast_slice(&active)),
            None => (16, &[0; 16]),
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
            streams: rule.map(|rule| AdaptiveStreams::new(rule, width as usize, pixels)),
            previous: if rule.is_some() {
                vec![[0.0; 4]; pixels]
            } else {
                Vec::new()
            },
            previous_samples: 0,
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
        self.streams.is_some()
    }

    /// The pixels still sampling (tile slots, ascending).
    pub fn active(&self) -> &[u32] {
        &self.active
    }

    /// The image as its sums and counts (`AdaptiveStreams::sums_and_counts`), with adaptive
    /// sampling.
    pub fn sums_and_counts(&self) -> Option<(Vec<PixelSums>, Vec<u32>)> {
        Some(self.streams.as_ref()?.sums_and_counts())
    }

    /// After a batch (`samples_done` samples in all, the tile's accumulation `sums`): deals what
    /// the batch added to the pixels still sampling to one stream, then stops the pixels whose
    /// streams have both met the rule. The new marks are uploaded before they are kept, so after
    /// a failed upload the kernels and this state still agree.
    pub fn update(
        &mut self,
        ctx: &GpuContext,
        samples_done: u32,
        sums: impl FnOnce() -> Result<Vec<PixelSums>>,
    ) -> Result<()> {
        let Some(streams) = &self.streams else {
            return Ok(());
        };
        if self.active.is_empty() || samples_done == self.previous_samples {
            return Ok(());
        }
        let now: Vec<[f64; 4]> = sums()?.iter().map(sums_f64).collect();
        let mut streams = streams.clone();
        let added = samples_done - self.previous_samples;
        let mut dealt = [0; 2];
        let stream = streams.next_stream();
        dealt[stream] = added;
        streams.add(dealt, |i| {
            let mut both = [[0.0; 4]; 2];
            both[stream] = [0, 1, 2, 3].map(|c| now[i][c] - self.previous[i][c]);
            both
        });
        streams.settle();
        let stopped = streams.stopped().to_vec();
        let active: Vec<u32> = self
            .active
            .iter()
            .copied()
            .filter(|&slot| stopped[slot as usize] == 0)
            .collect();
        if active.len() != self.active.len() {
            ctx.scoped(|| {
                ctx.queue
                    .write_buffer(&self.pixel_done, 0, bytemuck::cast_slice(&stopped));
                if !active.is_empty() {
                    ctx.queue
                        .write_buffer(&self.active_slots, 0, bytemuck::cast_slice(&active));
                }
            })?;
        }
        self.active = active;
        self.streams = Some(streams);
        self.previous = now;
        self.previous_samples = samples_done;
        Ok(())
    }
}
