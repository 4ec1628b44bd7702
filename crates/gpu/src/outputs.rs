//! A renderer's output buffers: the frame's uniform, the exact sums of every pixel of the tile
//! (`rt_core::accumulation`), the denoiser's guides (AOVs) and the counters. Their sizes, checked
//! against the adapter's limits, and what is read back from them.

use rt_core::accumulation::{self, CHANNEL_SUM_BYTES, PixelSums};
use rt_core::gpu_types::Frame;
use wgpu::util::DeviceExt;

use crate::bindings::{self, Binding};
use crate::buffers::{output_buffer, read_buffer};
use crate::context::GpuContext;
use crate::error::Result;
use crate::image::{Aovs, Image};

/// Bytes per pixel of the denoiser's guides (albedo, normal and directly seen light) and of what
/// shadow catchers caught, a `vec4` each, all in one binding (path.wgsl `AovMeans`).
pub const AOV_BYTES_PER_PIXEL: u64 = 64;

/// The exact sums of a tile of `pixels`: red, green, blue, squared luminance, a buffer each.
fn accumulation_bytes(pixels: u64) -> u64 {
    pixels * CHANNEL_SUM_BYTES
}

/// Albedo and normal, or a placeholder the kernel never touches.
fn aov_bytes(pixels: u64, aovs: bool) -> u64 {
    if aovs {
        pixels * AOV_BYTES_PER_PIXEL
    } else {
        AOV_BYTES_PER_PIXEL
    }
}

/// Checks the accumulation and AOV buffers of a tile of `pixels` against the adapter's limits.
pub(crate) fn check_sizes(ctx: &GpuContext, pixels: u64, aovs: bool) -> Result<()> {
    ctx.check_buffer(
        "accumulation (width x height x 16 bytes, one per channel)",
        accumulation_bytes(pixels),
    )?;
    ctx.check_buffer(
        "albedo, normal, emission, shadow catchers (width x height x 64 bytes)",
        aov_bytes(pixels, aovs),
    )
}

pub(crate) struct Outputs {
    /// The frame's uniform (each dispatch writes its own).
    pub frame: wgpu::Buffer,
    /// The exact sums: red, green, blue, squared luminance.
    pub accum: [wgpu::Buffer; 4],
    pub aovs: wgpu::Buffer,
    /// Rays traced and samples dropped.
    pub counters: wgpu::Buffer,
}

impl Outputs {
    /// The buffers for a tile of `pixels` of `frame`, with room for the AOVs when `aovs`. Call
    /// inside `GpuContext::scoped`.
    pub fn new(ctx: &GpuContext, frame: &Frame, pixels: u64, aovs: bool) -> Self {
        let frame = ctx
            .device
            .create_buffer_init(&wgpu::util::BufferInitDescriptor {
                label: Some("frame"),
                contents: bytemuck::bytes_of(frame),
                usage: wgpu::BufferUsages::UNIFORM | wgpu::BufferUsages::COPY_DST,
            });
        let output = |label: &str, size: u64| output_buffer(ctx, label, size);
        let accum = ["red", "green", "blue", "squared luminance"]
            .map(|c| output(&format!("accumulation: {c}"), accumulation_bytes(pixels)));
        Outputs {
            frame,
            accum,
            aovs: output("albedo and normal", aov_bytes(pixels, aovs)),
            counters: output("counters", 8),
        }
    }

    /// (binding, buffer) of each, for the kernels' bind groups.
    pub fn bound(&self) -> impl Iterator<Item = (Binding, wgpu::Buffer)> {
        [
            (bindings::FRAME, self.frame.clone()),
            (bindings::COUNTERS, self.counters.clone()),
            (bindings::AOVS, self.aovs.clone()),
        ]
        .into_iter()
        .chain(bindings::ACCUM.into_iter().zip(self.accum.iter().cloned()))
    }

    /// Zeroes the sums, the AOVs and the counters (a restart).
    pub fn clear(&self, ctx: &GpuContext) -> Result<()> {
        ctx.scoped(|| {
            let mut encoder = ctx.device.create_command_encoder(&Default::default());
            for buffer in self.accum.iter().chain([&self.aovs, &self.counters]) {
                encoder.clear_buffer(buffer, 0, None);
            }
            ctx.queue.submit([encoder.finish()]);
        })
    }

    /// The counters since the last call (rays traced, samples dropped), cleared for the next.
    pub fn take_counters(&self, ctx: &GpuContext) -> Result<[u32; 2]> {
        let bytes = read_buffer(ctx, &self.counters, 8)?;
        let counts: [u32; 2] = bytemuck::pod_read_unaligned(&bytes);
        let mut encoder = ctx.device.create_command_encoder(&Default::default());
        encoder.clear_buffer(&self.counters, 0, None);
        ctx.queue.submit([encoder.finish()]);
        Ok(counts)
    }

    /// The accumulation buffer as it is: per pixel of the `width` x `rows` tile, the exact sums
    /// of radiance and squared luminance (`rt_core::accumulation`).
    pub fn read_accumulation(
        &self,
        ctx: &GpuContext,
        width: u32,
        rows: u32,
    ) -> Result<Vec<PixelSums>> {
        let size = u64::from(width) * u64::from(rows) * CHANNEL_SUM_BYTES;
        let mut sums = vec![PixelSums::default(); width as usize * rows as usize];
        for (c, buffer) in self.accum.iter().enumerate() {
            let words: Vec<[u32; 4]> =
                bytemuck::pod_collect_to_vec(&read_buffer(ctx, buffer, size)?);
            for (s, w) in sums.iter_mut().zip(words) {
                s[c] = w;
            }
        }
        Ok(sums)
    }

    /// The mean first-hit albedo, normal and directly seen light of each pixel of the `width` x
    /// `rows` tile (the buffer must have been made with room for them).
    pub fn read_aovs(&self, ctx: &GpuContext, width: u32, rows: u32) -> Result<Aovs> {
        let size = u64::from(width) * u64::from(rows) * AOV_BYTES_PER_PIXEL;
        let bytes = read_buffer(ctx, &self.aovs, size)?;
        let values: Vec<[f32; 4]> = bytemuck::pod_collect_to_vec(&bytes);
        const VECS: usize = (AOV_BYTES_PER_PIXEL / 16) as usize;
        let xyz = |k: usize| {
            values
                .iter()
                .skip(k)
                .step_by(VECS)
                .map(|v| [v[0], v[1], v[2]])
        };
        let take = |k: usize| xyz(k).collect();
        // The w channels: coverage, distance × coverage, the first sample's object + 1
        // (path.wgsl `aov_sample_values`).
        let w = |k: usize| values.iter().skip(k).step_by(VECS).map(|v| v[3]);
        Ok(Aovs {
            albedo: take(0),
            normal: take(1),
            emission: take(2),
            hits: rt_core::first_hits::FirstHits {
                coverage: w(0).collect(),
                depth_weighted: w(1).collect(),
                object: w(2).map(|o| o as u32).collect(),
                caught: xyz(3).collect(),
            },
        })
    }
}

/// The image of a `width` x `rows` tile's `sums`: each pixel's mean over its own count where the
/// counts differ (`sample_counts`), else over `samples`.
pub(crate) fn mean_image(
    width: u32,
    rows: u32,
    samples: u32,
    sums: Vec<PixelSums>,
    sample_counts: Option<Vec<u32>>,
) -> Image {
    let pixels = match &sample_counts {
        Some(counts) => sums
            .iter()
            .zip(counts)
            .map(|(s, &n)| accumulation::pixel_mean(s, n))
            .collect(),
        None => sums
            .iter()
            .map(|s| accumulation::pixel_mean(s, samples))
            .collect(),
    };
    Image {
        width,
        height: rows,
        samples_per_pixel: samples,
        sample_counts,
        pixels,
        sums,
    }
}
