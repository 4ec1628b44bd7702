//! Progressive rendering: each `render_batch` adds samples to every pixel through one or more short
//! dispatches, so a render can be stopped, cancelled or read back after any batch.

use std::sync::Arc;
use std::time::{Duration, Instant};

use rt_core::accumulation::{self, CHANNEL_SUM_BYTES, PixelSums};
use rt_core::gpu_types::Frame;
use rt_core::{GpuScene, Scene};
use wgpu::util::DeviceExt;

use crate::accel::{self, SceneAccel};
use crate::adaptive::AdaptiveState;
use crate::bindings::{self, Binding};
use crate::buffers::{output_buffer, read_buffer, storage_buffer};
use crate::context::GpuContext;
use crate::error::{GpuError, Result};
use crate::image::{Aovs, Image};
use crate::options::{CPU_PIPELINE_LIFETIME, Kernel, REBUILD_AMORTISATION, RenderOptions, Trace};
use crate::pipelines::{KernelPipelines, PipelineKey, forget, kernel_pipelines};
use crate::sizing;
use crate::wavefront::{MAX_WAVE_PATHS, Wavefront};

/// What one batch did.
#[derive(Clone, Copy, Debug, Default)]
pub struct BatchStats {
    pub samples: u32,
    pub dispatches: u32,
    pub longest_dispatch: Duration,
    /// With the wavefront kernels, path depths run over all of the batch's waves (each wave
    /// stops at its first empty queue); 0 with the megakernel.
    pub wave_depths: u32,
    /// Whether the batch finished (`Renderer::render_slice` may stop one part-way).
    pub complete: bool,
    /// Wall time of the last dispatch (the slice clock's prediction of the next).
    pub last_dispatch: Duration,
}

/// What one dispatch (or wave) covers.
#[derive(Clone, Copy, Debug)]
enum DispatchRange {
    /// Image rows `begin..begin + count` (inside the tile).
    Rows { begin: u32, count: u32 },
    /// Entries `begin..begin + count` of the list of pixels still sampling (adaptive sampling on
    /// the wavefront kernels).
    Active { begin: u32, count: u32 },
}

/// What traces the paths.
enum Engine {
    /// trace.wgsl: one invocation per pixel runs whole paths.
    Megakernel {
        pipelines: Arc<KernelPipelines>,
        bind_group: wgpu::BindGroup,
    },
    /// wavefront.wgsl: a kernel per path stage.
    Wavefront(Wavefront),
}

pub struct Renderer<'a> {
    ctx: &'a GpuContext,
    engine: Engine,
    pipeline_key: PipelineKey,
    /// Kernel time since `pipeline` was built, not counting its first batch (see
    /// `RenderOptions::pipeline_lifetime`), and that first batch's time (its compile).
    pipeline_ran: Duration,
    pipeline_first_batch: Option<Duration>,
    pipeline_lifetime: Option<Duration>,
    /// Scale `pipeline_first_batch` by this for the least kernel time between rebuilds.
    rebuild_amortisation: u32,
    pipeline_rebuilds: u32,
    /// The scene's buffers and the outputs, to bind them to a rebuilt pipeline.
    bound: Vec<(Binding, wgpu::Buffer)>,
    /// The driver's acceleration structure, when tracing with ray queries.
    accel: Option<SceneAccel>,
    frame_buffer: wgpu::Buffer,
    /// The exact sums: red, green, blue, squared luminance.
    accum: [wgpu::Buffer; 4],
    aovs: wgpu::Buffer,
    counters: wgpu::Buffer,
    /// Adaptive sampling's stop marks and pixels still sampling.
    adaptive: AdaptiveState,
    frame: Frame,
    options: RenderOptions,
    samples_done: u32,
    samples_per_dispatch: u32,
    rows_per_dispatch: u32,
    /// A batch that failed part-way: the first row it had not rendered, and its samples per pixel.
    /// The rows before already hold its samples, so the next batch finishes this one.
    unfinished: Option<(u32, u32)>,
    /// The slowest rate (seconds per sample and row) the unfinished batch's dispatches so far ran
    /// at, so a batch split over slices sizes the next as a whole one would.
    unfinished_rate: f64,
    /// Pixels the output buffers hold: `restart` may render any frame up to this size.
    capacity_pixels: u64,
    /// The last measured cost of one sample of one pixel, to size a restarted frame's dispatches.
    seconds_per_sample_pixel: Option<f64>,
    loop_cap: u32,
    rays: u64,
    dropped_samples: u64,
    longest_dispatch: Duration,
    /// The longest dispatch of the first batch (see `longest_dispatch`).
    first_dispatch: Duration,
    pub triangles: usize,
}

impl<'a> Renderer<'a> {
    /// Prepares a render of `scene` (camera and settings from the scene).
    pub fn for_scene(
        ctx: &'a GpuContext,
        scene: &Scene,
        gpu_scene: &GpuScene,
        options: RenderOptions,
    ) -> Result<Self> {
        let frame = rt_core::frame::frame_for(scene, gpu_scene)?;
        Self::new(
            ctx,
            gpu_scene,
            frame,
            options.with_scene_settings(&scene.settings),
        )
    }

    pub fn new(
        ctx: &'a GpuContext,
        scene: &GpuScene,
        frame: Frame,
        options: RenderOptions,
    ) -> Result<Self> {
        if !(frame.tile_row_begin < frame.tile_row_end && frame.tile_row_end <= frame.height) {
            return Err(GpuError::Wgpu(format!(
                "tile rows {}..{} are not inside the image's {} rows",
                frame.tile_row_begin, frame.tile_row_end, frame.height
            )));
        }
        let pixels = u64::from(frame.width) * u64::from(frame.tile_row_end - frame.tile_row_begin);
        let accum_size = pixels * CHANNEL_SUM_BYTES;
        ctx.check_buffer(
            "accumulation (width x height x 16 bytes, one per channel)",
            accum_size,
        )?;
        // Albedo and normal, or a placeholder the kernel never touches.
        let aov_size = if options.aovs { pixels * 48 } else { 48 };
        ctx.check_buffer(
            "albedo, normal, emission (width x height x 48 bytes)",
            aov_size,
        )?;
        options.validate()?;
        if frame.emitter_count as usize > scene.emitters.len() {
            return Err(GpuError::Wgpu(format!(
                "the frame samples {} emitters of {}",
                frame.emitter_count,
                scene.emitters.len()
            )));
        }
        let mut features = scene.features;
        features.thin_lens = frame.lens_radius > 0.0;
        features.nee = frame.emitter_count > 0;
        if options.experiments.generic_kernel {
            // Every branch compiled in; each still checks its data at run time. (NEE stays as the
            // scene needs: the emitter table must not be empty.)
            features.textures = true;
            features.metal = true;
            features.dielectric = true;
            features.thin_lens = true;
            features.delta_lights = true;
            features.pbr = true;
            features.environment = true;
            features.normal_maps = true;
            features.alpha = true;
        }
        let ray_query = ctx.resolve_trace(options.trace, scene) == Trace::Hardware;
        let accel = if ray_query {
            Some(accel::build(ctx, scene)?)
        } else {
            None
        };
        let pipeline_key = PipelineKey {
            kernel: options.kernel,
            features,
            layout: scene.layout,
            ray_query,
            count_rays: options.count_rays,
            clamp_bits: options
                .clamp
                .filter(|c| c.is_finite() && *c > 0.0)
                .map_or(0, f32::to_bits),
            workgroup: options.experiments.workgroup,
            sobol: frame.sampler == 1,
            aovs: options.aovs,
            adaptive: options.adaptive.is_some(),
        };
        let megakernel = match options.kernel {
            Kernel::Megakernel => Some(kernel_pipelines(ctx, pipeline_key)?),
            Kernel::Wavefront => None,
        };
        let scene_buffers = [
            (
                bindings::TRIANGLES,
                storage_buffer(
                    ctx,
                    "triangles",
                    &scene.triangles,
                    wgpu::BufferUsages::empty(),
                )?,
            ),
            (
                bindings::SHADING,
                storage_buffer(ctx, "shading", &scene.shading, wgpu::BufferUsages::empty())?,
            ),
            (
                bindings::MATERIALS,
                storage_buffer(
                    ctx,
                    "materials",
                    &scene.materials,
                    wgpu::BufferUsages::empty(),
                )?,
            ),
            (
                bindings::NODES,
                storage_buffer(
                    ctx,
                    "bvh nodes",
                    scene.node_bytes(),
                    wgpu::BufferUsages::empty(),
                )?,
            ),
            (
                bindings::TEXELS,
                storage_buffer(ctx, "texels", &scene.texels, wgpu::BufferUsages::empty())?,
            ),
            (
                bindings::EMITTERS,
                storage_buffer(
                    ctx,
                    "emitters",
                    &scene.emitters,
                    wgpu::BufferUsages::empty(),
                )?,
            ),
            (
                bindings::DELTA_LIGHTS,
                storage_buffer(
                    ctx,
                    "delta lights",
                    &scene.delta_lights,
                    wgpu::BufferUsages::empty(),
                )?,
            ),
            (
                bindings::ENVIRONMENT,
                storage_buffer(
                    ctx,
                    "environment",
                    &scene.env_texels,
                    wgpu::BufferUsages::empty(),
                )?,
            ),
            (
                bindings::GGX_ENERGY,
                storage_buffer(
                    ctx,
                    "ggx energy",
                    &scene.ggx_energy,
                    wgpu::BufferUsages::empty(),
                )?,
            ),
            (
                bindings::TANGENTS,
                storage_buffer(
                    ctx,
                    "tangents",
                    &scene.tangents,
                    wgpu::BufferUsages::empty(),
                )?,
            ),
        ];
        ctx.check_buffer(
            "adaptive sampling stops (width x height x 4 bytes)",
            AdaptiveState::buffer_bytes(options.adaptive, pixels),
        )?;
        let rows_in_tile = frame.tile_row_end - frame.tile_row_begin;
        let (frame_buffer, accum, aovs, counters, adaptive) = ctx.scoped(|| {
            let frame_buffer = ctx
                .device
                .create_buffer_init(&wgpu::util::BufferInitDescriptor {
                    label: Some("frame"),
                    contents: bytemuck::bytes_of(&frame),
                    usage: wgpu::BufferUsages::UNIFORM | wgpu::BufferUsages::COPY_DST,
                });
            let output = |label: &str, size: u64| output_buffer(ctx, label, size);
            (
                frame_buffer,
                ["red", "green", "blue", "squared luminance"]
                    .map(|c| output(&format!("accumulation: {c}"), accum_size)),
                output("albedo and normal", aov_size),
                output("counters", 8),
                AdaptiveState::new(ctx, options.adaptive, frame.width, rows_in_tile),
            )
        })?;
        let bound: Vec<(Binding, wgpu::Buffer)> = [
            (bindings::FRAME, frame_buffer.clone()),
            (bindings::COUNTERS, counters.clone()),
            (bindings::AOVS, aovs.clone()),
        ]
        .into_iter()
        .chain(bindings::ACCUM.into_iter().zip(accum.iter().cloned()))
        .chain(adaptive.bound())
        .chain(scene_buffers)
        .collect();
        let loop_cap = sizing::loop_cap(scene, &frame);
        let loop_cap = options
            .max_samples_per_dispatch
            .map_or(loop_cap, |m| m.max(1));
        let engine = match megakernel {
            Some(pipelines) => Engine::Megakernel {
                bind_group: ctx
                    .scoped(|| megakernel_bind_group(ctx, &pipelines, &bound, tlas(&accel)))?,
                pipelines,
            },
            None => {
                // Room for the whole tile at the most samples a wave may take, within the cap (but
                // always a row).
                let capacity = pixels
                    .saturating_mul(u64::from(loop_cap))
                    .min(u64::from(MAX_WAVE_PATHS))
                    .max(u64::from(frame.width)) as u32;
                Engine::Wavefront(Wavefront::new(
                    ctx,
                    pipeline_key,
                    &bound,
                    tlas(&accel),
                    capacity,
                )?)
            }
        };
        // RT_PIPELINE_LIFETIME_S (seconds) overrides the CPU default.
        let from_env = std::env::var("RT_PIPELINE_LIFETIME_S")
            .ok()
            .and_then(|v| v.trim().parse::<f64>().ok())
            .filter(|s| s.is_finite() && *s >= 0.0)
            .map(Duration::from_secs_f64);
        // Only the megakernel's pipelines grow (tests/memory.rs).
        // Mesa 25.0's megakernel stays flat (performance-log.md); other CPU drivers may not.
        let auto = options.rebuild_on_cpu
            && options.kernel == Kernel::Megakernel
            && ctx.info.device_type == wgpu::DeviceType::Cpu
            && ctx.mesa_version().is_none_or(|v| v < (25, 0));
        let explicit = options
            .experiments
            .pipeline_lifetime
            .or(from_env.filter(|_| auto));
        let pipeline_lifetime = explicit.or(auto.then_some(CPU_PIPELINE_LIFETIME));
        let rebuild_amortisation = if explicit.is_some() {
            0
        } else {
            REBUILD_AMORTISATION
        };
        Ok(Renderer {
            ctx,
            engine,
            pipeline_key,
            accel,
            pipeline_ran: Duration::ZERO,
            pipeline_first_batch: None,
            pipeline_lifetime,
            rebuild_amortisation,
            pipeline_rebuilds: 0,
            bound,
            frame_buffer,
            accum,
            aovs,
            counters,
            adaptive,
            frame,
            options,
            samples_done: 0,
            samples_per_dispatch: 1,
            rows_per_dispatch: first_band_rows(&frame),
            unfinished: None,
            unfinished_rate: 0.0,
            capacity_pixels: pixels,
            seconds_per_sample_pixel: None,
            loop_cap,
            rays: 0,
            dropped_samples: 0,
            longest_dispatch: Duration::ZERO,
            first_dispatch: Duration::ZERO,
            triangles: scene.triangles.len(),
        })
    }

    /// What traces the paths.
    pub fn kernel(&self) -> Kernel {
        self.options.kernel
    }

    /// What finds the nearest hits: `Trace::Bvh` or `Trace::Hardware` (`Auto` resolved).
    pub fn trace(&self) -> Trace {
        if self.accel.is_some() {
            Trace::Hardware
        } else {
            Trace::Bvh
        }
    }

    pub fn samples_done(&self) -> u32 {
        self.samples_done
    }

    /// Rays traced so far (only counted with `RenderOptions::count_rays`).
    pub fn rays_traced(&self) -> u64 {
        self.rays
    }

    /// Samples that came out NaN or infinite and were dropped (counted as black).
    pub fn dropped_samples(&self) -> u64 {
        self.dropped_samples
    }

    /// The longest dispatch (for the wavefront kernels: the longest submission, one path depth of
    /// a wave) after the render's first batch, whose time on CPU adapters is mostly the JIT compile
    /// (that one when there was no other).
    pub fn longest_dispatch(&self) -> Duration {
        if self.longest_dispatch.is_zero() {
            self.first_dispatch
        } else {
            self.longest_dispatch
        }
    }

    /// How often the pipeline was rebuilt (see `RenderOptions::pipeline_lifetime`).
    pub fn pipeline_rebuilds(&self) -> u32 {
        self.pipeline_rebuilds
    }

    /// Replaces the pipeline with a freshly built one (dropping this renderer's and the context's
    /// handles to the old one, so the driver can free what it holds for it) and rebinds the buffers.
    fn rebuild_pipeline(&mut self) -> Result<()> {
        if let Engine::Wavefront(wave) = &mut self.engine {
            wave.rebuild(self.ctx, self.pipeline_key, &self.bound, tlas(&self.accel))?;
        } else {
            self.rebuild_megakernel()?;
        }
        self.pipeline_ran = Duration::ZERO;
        self.pipeline_first_batch = None;
        self.pipeline_rebuilds += 1;
        log::debug!(
            "rebuilt the trace pipeline ({} so far)",
            self.pipeline_rebuilds
        );
        Ok(())
    }

    fn rebuild_megakernel(&mut self) -> Result<()> {
        if let Engine::Megakernel { pipelines, .. } = &self.engine {
            forget(self.ctx, pipelines);
        }
        let pipelines = kernel_pipelines(self.ctx, self.pipeline_key)?;
        let bind_group = self.ctx.scoped(|| {
            megakernel_bind_group(self.ctx, &pipelines, &self.bound, tlas(&self.accel))
        })?;
        self.engine = Engine::Megakernel {
            pipelines,
            bind_group,
        };
        Ok(())
    }

    /// Adds up to `max_samples` samples to every pixel still sampling (none once adaptive
    /// sampling has stopped them all); returns what was done. After an error
    /// part-way through a batch (some bands of rows already hold its samples), the next call
    /// finishes that batch, with its sample count, instead of starting a new one.
    pub fn render_batch(&mut self, max_samples: u32) -> Result<BatchStats> {
        self.render_slice(max_samples, |_| true)
    }

    /// As `render_batch`, but after each dispatch asks `another(time of that dispatch)` whether
    /// one more fits (the interactive viewport's frame budget, or a cancel); when it says no, the
    /// batch stops there and the next call goes on where it stopped (`BatchStats::complete` tells
    /// which happened). The pixels a stopped batch reached already hold its samples
    /// (`read_image` counts them).
    pub fn render_slice(
        &mut self,
        max_samples: u32,
        mut another: impl FnMut(Duration) -> bool,
    ) -> Result<BatchStats> {
        if self.active_pixels() == 0 {
            // Adaptive sampling has stopped every pixel: nothing is left to sample.
            return Ok(BatchStats::default());
        }
        if let (Some(life), Some(first)) = (self.pipeline_lifetime, self.pipeline_first_batch)
            && self.pipeline_ran >= life.max(first * self.rebuild_amortisation)
        {
            self.rebuild_pipeline()?;
        }
        let started = Instant::now();
        // On lavapipe the first batch after a pipeline is built holds its JIT compile (seconds).
        let first_after_build = self.pipeline_first_batch.is_none();
        // A batch walks the tile's rows, or with adaptive sampling on the wavefront kernels the
        // list of pixels still sampling (in pixels): waves then hold only paths that count.
        let compact = self.compacts();
        let width = self.frame.width.max(1);
        let (start, end, per_dispatch) = if compact {
            (
                0,
                self.active_pixels() as u32,
                self.rows_per_dispatch * width,
            )
        } else {
            (
                self.frame.tile_row_begin,
                self.frame.tile_row_end,
                self.rows_per_dispatch,
            )
        };
        let (mut at, samples) = self
            .unfinished
            .take()
            .unwrap_or((start, max_samples.min(self.samples_per_dispatch).max(1)));
        let mut stats = BatchStats {
            samples,
            ..Default::default()
        };
        // Seconds per (sample x row), over the slices of this batch.
        let mut slowest_rate = std::mem::take(&mut self.unfinished_rate);
        while at < end {
            let count = per_dispatch.min(end - at);
            let range = if compact {
                DispatchRange::Active { begin: at, count }
            } else {
                DispatchRange::Rows { begin: at, count }
            };
            let dispatch_started = Instant::now();
            let (elapsed, depths) = match self.dispatch(range, samples) {
                Ok(done) => done,
                Err(e) => {
                    self.unfinished = Some((at, samples));
                    return Err(e);
                }
            };
            let wall = dispatch_started.elapsed();
            stats.last_dispatch = wall;
            stats.dispatches += 1;
            stats.wave_depths += depths;
            stats.longest_dispatch = stats.longest_dispatch.max(elapsed);
            let rows = if compact {
                f64::from(count) / f64::from(width)
            } else {
                f64::from(count)
            };
            slowest_rate = slowest_rate.max(elapsed.as_secs_f64() / (f64::from(samples) * rows));
            at += count;
            if at < end && !another(wall) {
                self.unfinished = Some((at, samples));
                self.unfinished_rate = slowest_rate;
                return Ok(stats);
            }
        }
        stats.complete = true;
        self.samples_done += samples;
        self.read_counters()?;
        let (ctx, accum) = (self.ctx, &self.accum);
        let (width, rows) = (self.frame.width, tile_rows(&self.frame));
        let samples_done = self.samples_done;
        self.adaptive.update(ctx, samples_done, || {
            // Only pixels still sampling are judged, and they all hold `samples_done` samples.
            let sums = read_accumulation(ctx, accum, width, rows)?;
            Ok(sums
                .iter()
                .map(|s| accumulation::pixel_mean(s, samples_done))
                .collect())
        })?;
        if first_after_build && self.samples_done > samples {
            // A rebuild's first batch: not a measure of the kernel's speed or dispatch length.
        } else if first_after_build {
            // The render's first: it sizes the next batch, but its time is the compile's.
            self.first_dispatch = stats.longest_dispatch;
            self.adapt(slowest_rate);
        } else {
            self.longest_dispatch = self.longest_dispatch.max(stats.longest_dispatch);
            self.adapt(slowest_rate);
        }
        match self.pipeline_first_batch {
            None => {
                self.pipeline_first_batch = Some(started.elapsed());
                log::debug!("first batch of this pipeline: {:.2?}", started.elapsed());
            }
            Some(_) => self.pipeline_ran += started.elapsed(),
        }
        Ok(stats)
    }

    /// Whether batches walk the list of pixels still sampling instead of the tile's rows.
    fn compacts(&self) -> bool {
        self.adaptive.enabled() && matches!(self.engine, Engine::Wavefront(_))
    }

    /// Starts over on `frame` (another camera or image size of the same scene: the interactive
    /// viewport's restarts), keeping the scene's buffers and the pipeline. Refused (the caller then
    /// makes a new renderer) when the frame needs another pipeline (lens, light sampling,
    /// sampler), more pixels than the buffers hold, or adaptive sampling is on.
    pub fn restart(&mut self, scene: &GpuScene, frame: Frame) -> Result<()> {
        let pixels = u64::from(frame.width) * u64::from(tile_rows(&frame));
        let same_pipeline = (frame.lens_radius > 0.0) == (self.frame.lens_radius > 0.0)
            && (frame.emitter_count > 0) == (self.frame.emitter_count > 0)
            && frame.emitter_count as usize <= scene.emitters.len()
            && frame.sampler == self.frame.sampler;
        if !same_pipeline || pixels > self.capacity_pixels || self.adaptive.enabled() {
            return Err(GpuError::Options(
                "this frame needs a new renderer (another pipeline, more pixels or adaptive \
                 sampling)"
                    .into(),
            ));
        }
        if !(frame.tile_row_begin < frame.tile_row_end && frame.tile_row_end <= frame.height) {
            return Err(GpuError::Wgpu(
                "restart: the tile is not inside the image".into(),
            ));
        }
        self.ctx.scoped(|| {
            let mut encoder = self.ctx.device.create_command_encoder(&Default::default());
            for buffer in self.accum.iter().chain([&self.aovs, &self.counters]) {
                encoder.clear_buffer(buffer, 0, None);
            }
            self.ctx.queue.submit([encoder.finish()]);
        })?;
        self.frame = frame;
        self.loop_cap = self
            .options
            .max_samples_per_dispatch
            .map_or_else(|| sizing::loop_cap(scene, &frame), |m| m.max(1));
        self.samples_done = 0;
        self.unfinished = None;
        self.unfinished_rate = 0.0;
        self.samples_per_dispatch = 1;
        self.rows_per_dispatch = first_band_rows(&frame);
        if let Some(rate) = self.seconds_per_sample_pixel {
            self.adapt(rate * f64::from(frame.width));
        }
        Ok(())
    }

    /// Pixels (of this renderer's tile) still taking samples: all of them without adaptive
    /// sampling; once none is, further batches add nothing.
    pub fn active_pixels(&self) -> usize {
        self.adaptive.active().len()
    }

    /// Chooses rows and samples per dispatch so one dispatch takes about the target time.
    fn adapt(&mut self, seconds_per_sample_row: f64) {
        if seconds_per_sample_row.is_finite() && seconds_per_sample_row > 0.0 {
            self.seconds_per_sample_pixel =
                Some(seconds_per_sample_row / f64::from(self.frame.width.max(1)));
        }
        let wave_capacity = match &self.engine {
            Engine::Wavefront(wave) => Some(wave.capacity),
            Engine::Megakernel { .. } => None,
        };
        // In rows, or in rows' worth of the pixels still sampling.
        let rows = if self.compacts() {
            (self.active_pixels() as u32)
                .div_ceil(self.frame.width.max(1))
                .max(1)
        } else {
            self.frame.tile_row_end - self.frame.tile_row_begin
        };
        if let Some(shape) = sizing::dispatch_shape(
            seconds_per_sample_row,
            self.options.target_dispatch,
            self.frame.width,
            rows,
            self.loop_cap,
            wave_capacity,
        ) {
            (self.rows_per_dispatch, self.samples_per_dispatch) = shape;
        }
    }

    /// Runs one dispatch (megakernel) or wave (wavefront); returns its longest submission's time
    /// and, for a wave, the path depths it ran.
    fn dispatch(&mut self, range: DispatchRange, samples: u32) -> Result<(Duration, u32)> {
        self.ctx.alive()?;
        let frame = Frame {
            sample_base: self.samples_done,
            sample_offset: self.options.first_sample,
            samples_this_dispatch: samples,
            ..self.frame
        };
        let (frame, rows) = match range {
            DispatchRange::Rows { begin, count } => (
                Frame {
                    row_begin: begin,
                    row_end: begin + count,
                    ..frame
                },
                count,
            ),
            DispatchRange::Active { begin, count } => (
                Frame {
                    active_begin: begin,
                    active_count: count,
                    ..frame
                },
                0,
            ),
        };
        let (pipeline, bind_group) = match &self.engine {
            Engine::Megakernel {
                pipelines,
                bind_group,
            } => (pipelines.stage("main"), bind_group),
            // A wave is a submission per path depth; the longest one's time bounds each dispatch's.
            Engine::Wavefront(wave) => {
                let run = wave.run(self.ctx, &self.frame_buffer, &frame)?;
                return Ok((run.longest, run.depths));
            }
        };
        let started = Instant::now();
        self.ctx.scoped(|| {
            self.ctx
                .queue
                .write_buffer(&self.frame_buffer, 0, bytemuck::bytes_of(&frame));
            let mut encoder = self.ctx.device.create_command_encoder(&Default::default());
            {
                let mut pass = encoder.begin_compute_pass(&Default::default());
                pass.set_pipeline(pipeline);
                pass.set_bind_group(0, bind_group, &[]);
                let [wx, wy] = self.options.experiments.workgroup;
                pass.dispatch_workgroups(self.frame.width.div_ceil(wx), rows.div_ceil(wy), 1);
            }
            self.ctx.queue.submit([encoder.finish()]);
        })?;
        self.ctx
            .device
            .poll(wgpu::PollType::wait_indefinitely())
            .map_err(|e| GpuError::Wgpu(e.to_string()))?;
        Ok((started.elapsed(), 0))
    }

    fn read_counters(&mut self) -> Result<()> {
        let bytes = read_buffer(self.ctx, &self.counters, 8)?;
        let counts: [u32; 2] = bytemuck::pod_read_unaligned(&bytes);
        self.rays += u64::from(counts[0]);
        self.dropped_samples += u64::from(counts[1]);
        let mut encoder = self.ctx.device.create_command_encoder(&Default::default());
        encoder.clear_buffer(&self.counters, 0, None);
        self.ctx.queue.submit([encoder.finish()]);
        Ok(())
    }

    /// Renders until every pixel has `spp` samples (or adaptive sampling has stopped every pixel),
    /// calling `progress(samples_done)` after each batch;
    /// `progress` returning false stops early (the image so far stays readable).
    pub fn render(&mut self, spp: u32, mut progress: impl FnMut(u32) -> bool) -> Result<()> {
        while self.samples_done < spp && self.active_pixels() > 0 {
            self.render_batch(spp - self.samples_done)?;
            if !progress(self.samples_done) {
                break;
            }
        }
        Ok(())
    }

    /// The mean first-hit albedo, normal and directly seen light of each pixel (of this
    /// renderer's tile), when the renderer was made with `RenderOptions::aovs`.
    pub fn read_aovs(&self) -> Result<Option<Aovs>> {
        if !self.options.aovs {
            return Ok(None);
        }
        let rows = self.frame.tile_row_end - self.frame.tile_row_begin;
        let size = u64::from(self.frame.width) * u64::from(rows) * 48;
        let bytes = read_buffer(self.ctx, &self.aovs, size)?;
        let values: Vec<[f32; 4]> = bytemuck::pod_collect_to_vec(&bytes);
        let take = |k: usize| {
            values
                .iter()
                .skip(k)
                .step_by(3)
                .map(|v| [v[0], v[1], v[2]])
                .collect()
        };
        Ok(Some(Aovs {
            albedo: take(0),
            normal: take(1),
            emission: take(2),
        }))
    }

    /// The accumulated image so far (of this renderer's tile: `height` is the tile's rows). After a
    /// batch failed part-way, its finished rows hold one batch more than `samples_per_pixel` says
    /// until the next batch completes it (keep the last image read before the failure to save).
    pub fn read_image(&self) -> Result<Image> {
        let sums = if self.samples_done == 0 && self.unfinished.is_none() {
            vec![PixelSums::default(); tile_pixels(&self.frame)]
        } else {
            self.read_accumulation()?
        };
        let sample_counts = self.sample_counts();
        let pixels = match &sample_counts {
            Some(counts) => sums
                .iter()
                .zip(counts)
                .map(|(s, &n)| accumulation::pixel_mean(s, n))
                .collect(),
            None => sums
                .iter()
                .map(|s| accumulation::pixel_mean(s, self.samples_done))
                .collect(),
        };
        Ok(Image {
            width: self.frame.width,
            height: tile_rows(&self.frame),
            samples_per_pixel: self.samples_done,
            sample_counts,
            pixels,
            sums,
        })
    }

    /// Each pixel's count where they differ: with adaptive sampling, or after a batch failed
    /// part-way (the pixels it reached hold its samples too).
    fn sample_counts(&self) -> Option<Vec<u32>> {
        let counts = self.adaptive.counts(self.samples_done);
        let Some((at, extra)) = self.unfinished else {
            return counts;
        };
        let mut counts =
            counts.unwrap_or_else(|| vec![self.samples_done; tile_pixels(&self.frame)]);
        if self.compacts() {
            for &slot in &self.adaptive.active()[..at as usize] {
                counts[slot as usize] += extra;
            }
        } else {
            let width = self.frame.width as usize;
            let reached = (at - self.frame.tile_row_begin) as usize * width;
            for c in &mut counts[..reached] {
                *c += extra;
            }
        }
        Some(counts)
    }

    fn read_accumulation(&self) -> Result<Vec<PixelSums>> {
        read_accumulation(
            self.ctx,
            &self.accum,
            self.frame.width,
            tile_rows(&self.frame),
        )
    }
}

/// A first dispatch's rows: a band of about 16k pixels, to measure the cost safely, then grow.
fn first_band_rows(frame: &Frame) -> u32 {
    (16_384 / frame.width.max(1)).clamp(1, tile_rows(frame))
}

fn tile_rows(frame: &Frame) -> u32 {
    frame.tile_row_end - frame.tile_row_begin
}

fn tile_pixels(frame: &Frame) -> usize {
    frame.width as usize * tile_rows(frame) as usize
}

/// The accumulation buffer as it is: per pixel of the tile, the exact sums of radiance and squared
/// luminance (`rt_core::accumulation`).
fn read_accumulation(
    ctx: &GpuContext,
    accum: &[wgpu::Buffer; 4],
    width: u32,
    rows: u32,
) -> Result<Vec<PixelSums>> {
    let size = u64::from(width) * u64::from(rows) * CHANNEL_SUM_BYTES;
    let mut sums = vec![PixelSums::default(); width as usize * rows as usize];
    for (c, buffer) in accum.iter().enumerate() {
        let words: Vec<[u32; 4]> = bytemuck::pod_collect_to_vec(&read_buffer(ctx, buffer, size)?);
        for (s, w) in sums.iter_mut().zip(words) {
            s[c] = w;
        }
    }
    Ok(sums)
}

/// The megakernel's bind group over `bound`.
fn megakernel_bind_group(
    ctx: &GpuContext,
    pipelines: &KernelPipelines,
    bound: &[(Binding, wgpu::Buffer)],
    tlas: Option<&wgpu::Tlas>,
) -> wgpu::BindGroup {
    let buffers: Vec<(Binding, &wgpu::Buffer)> = bound.iter().map(|(b, buf)| (*b, buf)).collect();
    bindings::bind_group(ctx, Kernel::Megakernel, &pipelines.layout, &buffers, tlas)
}

fn tlas(accel: &Option<SceneAccel>) -> Option<&wgpu::Tlas> {
    accel.as_ref().map(|a| &a.tlas)
}
