//! The wavefront variant of the tracing kernel (the default, `Kernel::Wavefront`; measured
//! against the megakernel in docs/performance.md): the same estimator, split into one kernel per
//! stage over queues of paths in storage buffers (`shaders/wavefront.wgsl` describes the stages).
//! A wave is a band of rows times some samples per pixel, every path to its end: one submission
//! per path depth until the queue empties, then one for `finish`.

use std::sync::Arc;
use std::time::{Duration, Instant};

use rt_core::gpu_types::Frame;

use crate::bindings::{self, Binding};
use crate::buffers::output_buffer;
use crate::context::GpuContext;
use crate::error::{GpuError, Result};
use crate::options::Kernel;
use crate::outputs::AOV_BYTES_PER_PIXEL;
use crate::pipeline_cache::{KernelPipelines, PipelineKey};
use crate::pipelines::{forget, kernel_pipelines};

/// Invocations per work group of every wavefront kernel (`WAVE_GROUP` in the shader).
pub const WAVE_GROUP: u32 = 64;

/// The most paths one wave holds (buffers: `WAVE_PATH_BYTES + SHADOW_RAY_BYTES + 8` bytes each).
pub const MAX_WAVE_PATHS: u32 = 1 << 18;

/// Size of `WavePath` in `shaders/wavefront.wgsl` (checked against naga in tests/shaders.rs).
pub const WAVE_PATH_BYTES: u64 = 128;

/// Size of `ShadowRay` in `crates/core/src/estimator/path.wgsl` (checked against naga in tests/shaders.rs).
pub const SHADOW_RAY_BYTES: u64 = 48;

/// Mirror of `WaveQueues` in `shaders/wavefront.wgsl`; its first three words are the indirect
/// dispatch size of extend, shade and connect.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, bytemuck::Pod, bytemuck::Zeroable)]
pub struct WaveQueues {
    pub groups: [u32; 3],
    pub rays: u32,
    pub next_rays: u32,
    pub shadows: u32,
    pub parity: u32,
    pub _pad: u32,
}

/// Where the current queue's length sits in `WaveQueues` (read back after each depth).
const WAVE_QUEUES_RAYS_OFFSET: u64 = std::mem::offset_of!(WaveQueues, rays) as u64;

/// Field names and offsets of `WaveQueues`, for the layout test.
pub const WAVE_QUEUES_FIELDS: &[(&str, usize)] = &[
    ("groups_x", 0),
    ("groups_y", 4),
    ("groups_z", 8),
    ("rays", 12),
    ("next_rays", 16),
    ("shadows", 20),
    ("parity", 24),
    ("_pad", 28),
];

/// The wavefront's own buffers, in the order `Wavefront::own` holds them.
const OWN: [Binding; 5] = [
    bindings::PATHS,
    bindings::RAY_QUEUES,
    bindings::SHADOW_RAYS,
    bindings::QUEUES,
    bindings::PATH_AOVS,
];
/// Index of the queue lengths (`WaveQueues`) among the own buffers.
const QUEUE_LENGTHS: usize = 3;

/// The wavefront kernels of `key`'s feature set.
fn wave_pipelines(ctx: &GpuContext, key: PipelineKey) -> Result<Arc<KernelPipelines>> {
    let key = PipelineKey {
        kernel: Kernel::Wavefront,
        ..key
    };
    kernel_pipelines(ctx, key)
}

/// A renderer's wavefront state: its kernels, queues and the bind group over the scene's buffers.
pub(crate) struct Wavefront {
    pipelines: Arc<KernelPipelines>,
    bind_group: wgpu::BindGroup,
    /// Paths, ray queues, shadow rays, queue lengths and per-path AOVs (bindings `OWN`).
    own: [wgpu::Buffer; 5],
    /// The queues' first three words, copied after each advance: a buffer bound as storage cannot
    /// also hold a dispatch's indirect size.
    dispatch_size: wgpu::Buffer,
    /// Paths one wave may hold.
    pub capacity: u32,
    /// Adaptive sampling: a wave covers `frame.active_count` pixels of the list of those still
    /// sampling, not rows.
    adaptive: bool,
}

impl Wavefront {
    /// Queues for `capacity` paths; `bound` are the scene's buffers and the outputs (shared with
    /// the megakernel's bindings).
    pub fn new(
        ctx: &GpuContext,
        key: PipelineKey,
        bound: &[(Binding, wgpu::Buffer)],
        tlas: Option<&wgpu::Tlas>,
        capacity: u32,
    ) -> Result<Self> {
        let pipelines = wave_pipelines(ctx, key)?;
        let capacity = capacity.max(1);
        let sizes = [
            ("wavefront paths", u64::from(capacity) * WAVE_PATH_BYTES),
            ("wavefront ray queues", u64::from(capacity) * 8),
            (
                "wavefront shadow rays",
                u64::from(capacity) * SHADOW_RAY_BYTES,
            ),
            ("wavefront queue lengths", size_of::<WaveQueues>() as u64),
            (
                "wavefront path AOVs",
                if key.aovs {
                    u64::from(capacity) * AOV_BYTES_PER_PIXEL
                } else {
                    AOV_BYTES_PER_PIXEL
                },
            ),
        ];
        for (name, size) in sizes {
            ctx.check_buffer(name, size)?;
        }
        let (own, dispatch_size) = ctx.scoped(|| {
            let own = sizes.map(|(label, size)| output_buffer(ctx, label, size));
            let dispatch_size = ctx.device.create_buffer(&wgpu::BufferDescriptor {
                label: Some("wavefront dispatch size"),
                size: 12,
                usage: wgpu::BufferUsages::INDIRECT | wgpu::BufferUsages::COPY_DST,
                mapped_at_creation: false,
            });
            (own, dispatch_size)
        })?;
        let bind_group = bind(ctx, &pipelines, bound, tlas, &own)?;
        Ok(Wavefront {
            pipelines,
            bind_group,
            own,
            dispatch_size,
            capacity,
            adaptive: key.adaptive,
        })
    }

    /// Replaces the kernels with freshly built ones (see `Renderer::rebuild_pipeline`: lavapipe
    /// holds memory per compiled pipeline) over the same buffers.
    pub fn rebuild(
        &mut self,
        ctx: &GpuContext,
        key: PipelineKey,
        bound: &[(Binding, wgpu::Buffer)],
        tlas: Option<&wgpu::Tlas>,
    ) -> Result<()> {
        forget(ctx, &self.pipelines);
        let pipelines = wave_pipelines(ctx, key)?;
        self.bind_group = bind(ctx, &pipelines, bound, tlas, &self.own)?;
        self.pipelines = pipelines;
        Ok(())
    }

    /// Runs one wave: `frame.samples_this_dispatch` samples of rows `frame.row_begin..row_end`
    /// (whose paths must fit the capacity), written into `frame_buffer` first. Each depth is its
    /// own submission, waited for and timed (the renderer sizes waves by the longest, which bounds
    /// every dispatch's time). The accumulation changes only in the last submission.
    ///
    /// Each depth's submission also copies the next queue's length back, read when the wait ends
    /// (no extra synchronisation), and the wave stops at the first empty queue: with a max depth
    /// of 64 and paths that leave an open scene after a bounce or two, the other ~60 submissions
    /// would each cost a round trip for nothing.
    pub fn run(
        &self,
        ctx: &GpuContext,
        frame_buffer: &wgpu::Buffer,
        frame: &Frame,
    ) -> Result<WaveRun> {
        ctx.alive()?;
        let band = if self.adaptive {
            frame.active_count
        } else {
            (frame.row_end - frame.row_begin) * frame.width
        };
        let paths = band * frame.samples_this_dispatch;
        if paths > self.capacity {
            return Err(GpuError::Wgpu(format!(
                "a wave of {paths} paths exceeds the queues' {}",
                self.capacity
            )));
        }
        let queues = WaveQueues {
            // The dispatch size stays an upper bound: invocations past the queue's length return.
            groups: [paths.div_ceil(WAVE_GROUP), 1, 1],
            rays: paths,
            ..Default::default()
        };
        let p = &self.pipelines;
        // Made per wave, so a wave that failed mid-way leaves no mapping pending for the next.
        let length = ctx.scoped(|| {
            ctx.device.create_buffer(&wgpu::BufferDescriptor {
                label: Some("wavefront queue length readback"),
                size: 4,
                usage: wgpu::BufferUsages::MAP_READ | wgpu::BufferUsages::COPY_DST,
                mapped_at_creation: false,
            })
        })?;
        let depth_stages = [
            (p.stage("extend"), None),
            (p.stage("shade"), None),
            (p.stage("connect"), None),
            (p.stage("advance"), Some(1)),
        ];
        let mut run = WaveRun::default();
        for depth in 0..frame.max_depth.max(1) {
            let (elapsed, rays) = self.submit(
                ctx,
                &length,
                &|encoder| {
                    if depth == 0 {
                        ctx.queue
                            .write_buffer(frame_buffer, 0, bytemuck::bytes_of(frame));
                        ctx.queue.write_buffer(
                            &self.own[QUEUE_LENGTHS],
                            0,
                            bytemuck::bytes_of(&queues),
                        );
                        ctx.queue.write_buffer(
                            &self.dispatch_size,
                            0,
                            bytemuck::bytes_of(&queues.groups),
                        );
                        self.pass(
                            encoder,
                            &[(p.stage("generate"), Some(paths.div_ceil(WAVE_GROUP)))],
                        );
                    }
                    if frame.max_depth > 0 {
                        self.pass(encoder, &depth_stages);
                        encoder.copy_buffer_to_buffer(
                            &self.own[QUEUE_LENGTHS],
                            0,
                            &self.dispatch_size,
                            0,
                            12,
                        );
                    }
                },
                frame.max_depth > 0,
            )?;
            run.longest = run.longest.max(elapsed);
            run.depths += u32::from(frame.max_depth > 0);
            if rays == Some(0) {
                break;
            }
        }
        let (elapsed, _) = self.submit(
            ctx,
            &length,
            &|encoder| {
                self.pass(
                    encoder,
                    &[(p.stage("finish"), Some(band.div_ceil(WAVE_GROUP)))],
                );
            },
            false,
        )?;
        run.longest = run.longest.max(elapsed);
        Ok(run)
    }

    /// One submission: `record` fills its encoder's passes; with `read_length`, returns the
    /// length of the queue the submission left current (copied into `length`).
    fn submit(
        &self,
        ctx: &GpuContext,
        length: &wgpu::Buffer,
        record: &dyn Fn(&mut wgpu::CommandEncoder),
        read_length: bool,
    ) -> Result<(Duration, Option<u32>)> {
        let started = Instant::now();
        let (tx, rx) = std::sync::mpsc::channel();
        ctx.scoped(|| {
            let mut encoder = ctx.device.create_command_encoder(&Default::default());
            record(&mut encoder);
            if read_length {
                encoder.copy_buffer_to_buffer(
                    &self.own[QUEUE_LENGTHS],
                    WAVE_QUEUES_RAYS_OFFSET,
                    length,
                    0,
                    4,
                );
            }
            ctx.queue.submit([encoder.finish()]);
            if read_length {
                length.map_async(wgpu::MapMode::Read, .., move |r| {
                    let _ = tx.send(r);
                });
            }
        })?;
        ctx.device
            .poll(wgpu::PollType::wait_indefinitely())
            .map_err(|e| GpuError::Wgpu(e.to_string()))?;
        let elapsed = started.elapsed();
        if !read_length {
            return Ok((elapsed, None));
        }
        rx.recv()
            .map_err(|e| GpuError::Wgpu(e.to_string()))?
            .map_err(|e| GpuError::Wgpu(format!("reading back a queue length: {e}")))?;
        let rays = {
            let bytes = length
                .get_mapped_range(..)
                .map_err(|e| GpuError::Wgpu(e.to_string()))?;
            u32::from_le_bytes([bytes[0], bytes[1], bytes[2], bytes[3]])
        };
        length.unmap();
        Ok((elapsed, Some(rays)))
    }

    /// A compute pass of `stages`, each with its work-group count or (`None`) the count the
    /// queue lengths left in `dispatch_size`.
    fn pass(
        &self,
        encoder: &mut wgpu::CommandEncoder,
        stages: &[(&wgpu::ComputePipeline, Option<u32>)],
    ) {
        let mut pass = encoder.begin_compute_pass(&Default::default());
        pass.set_bind_group(0, &self.bind_group, &[]);
        for (pipeline, groups) in stages {
            pass.set_pipeline(pipeline);
            match groups {
                Some(groups) => pass.dispatch_workgroups(*groups, 1, 1),
                None => pass.dispatch_workgroups_indirect(&self.dispatch_size, 0),
            }
        }
    }
}

/// What one wave did.
#[derive(Clone, Copy, Debug, Default)]
pub struct WaveRun {
    /// The longest submission.
    pub longest: Duration,
    /// Path depths run (extend, shade, connect and advance each): fewer than the max depth when
    /// every path ended sooner.
    pub depths: u32,
}

/// The bind group of `pipelines` over the shared bindings of `bound` and the wavefront's own.
fn bind(
    ctx: &GpuContext,
    pipelines: &KernelPipelines,
    bound: &[(Binding, wgpu::Buffer)],
    tlas: Option<&wgpu::Tlas>,
    own: &[wgpu::Buffer; 5],
) -> Result<wgpu::BindGroup> {
    let buffers: Vec<(Binding, &wgpu::Buffer)> = bound
        .iter()
        .map(|(binding, buffer)| (*binding, buffer))
        .chain(OWN.into_iter().zip(own))
        .collect();
    ctx.scoped(|| bindings::bind_group(ctx, Kernel::Wavefront, &pipelines.layout, &buffers, tlas))
}
