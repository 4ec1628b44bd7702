//! Progressive rendering: each `render_batch` adds samples to every pixel through one or more short
//! dispatches, so a render can be stopped, cancelled or read back after any batch.

use std::time::{Duration, Instant};

use rt_core::gpu_types::Frame;
use rt_core::{GpuScene, Scene};
use wgpu::util::DeviceExt;

use crate::buffers::{read_buffer, storage_buffer};
use crate::context::GpuContext;
use crate::error::{GpuError, Result};
use crate::pipelines::{PipelineKey, trace_pipeline};
use crate::wavefront::{MAX_WAVE_PATHS, Wavefront};

/// The most invocations a work group of the tracing kernel may have: each holds a 64-entry BVH
/// traversal stack in work-group memory (`shaders/shared/bvh.wgsl`), 16 KiB in all.
pub const MAX_WORKGROUP_INVOCATIONS: u32 = 64;

/// Dispatch sizing: each dispatch should take about `target_dispatch`, well under the ~100 ms at
/// which operating systems start to suspect a hung GPU.
#[derive(Clone, Copy, Debug)]
pub struct RenderOptions {
    pub target_dispatch: Duration,
    /// Count rays in the kernel (benchmarks); compiled out otherwise.
    pub count_rays: bool,
    /// Upper bound on samples per pixel in one dispatch; `None` derives it from the loop budget.
    pub max_samples_per_dispatch: Option<u32>,
    /// Firefly clamp: scale each contribution of bounced light down so its largest channel is at
    /// most this (directly seen emitters stay exact). Biased (it removes energy); `None` (the
    /// default) leaves samples alone.
    /// `Renderer::for_scene` takes it from the scene's settings when unset here.
    pub clamp: Option<f32>,
    /// Compile every optional feature in, as if the scene used them all (benchmarks compare this
    /// generic kernel with the specialised one).
    pub generic_kernel: bool,
    /// The megakernel's work-group width and height (benchmarks); 8 x 8 by default, at most
    /// `MAX_WORKGROUP_INVOCATIONS` invocations (the BVH traversal stacks live in work-group
    /// memory). The wavefront kernels run 64 x 1.
    pub workgroup: [u32; 2],
    /// Also accumulate each pixel's first-hit albedo and normal (for `rt_core::denoise`; read them
    /// with `Renderer::read_aovs`).
    pub aovs: bool,
    /// Leave wgpu's injected bounds checks and loop guards out of the kernel when
    /// `GpuScene::check_kernel_indices` proves the scene's indices in range (otherwise they stay).
    /// Off by default: on lavapipe it measured no faster (docs/performance.md); the images are
    /// identical either way. Megakernel only: it selects the megakernel.
    pub unchecked: bool,
    /// Rebuild the tracing pipeline(s) once the kernels have run this long (not counting the first
    /// batch after a build), when `Some`. Mesa 22.3's lavapipe keeps host memory for every path the
    /// compiled megakernel traces (60-75 MB/s on the Cornell box here) until the pipeline is
    /// destroyed; the wavefront kernels do not grow (`tests/memory.rs`). `None` leaves it to
    /// `rebuild_on_cpu`. A rebuild changes no sample (`tests/extremes.rs`).
    pub pipeline_lifetime: Option<Duration>,
    /// With `pipeline_lifetime` `None`: on CPU adapters and with the megakernel, rebuild after
    /// `CPU_PIPELINE_LIFETIME` or `REBUILD_AMORTISATION` times the last build's first batch (which
    /// holds lavapipe's JIT compile, seconds), whichever is longer (`RT_PIPELINE_LIFETIME_S` in the
    /// environment sets the lifetime exactly); never on GPUs or with the wavefront kernels. Off by
    /// default, for renderers that share a device with others (the tests): a CI run of the test
    /// suite with it on stalled for over 10 minutes inside lavapipe (not reproduced by three
    /// threads rebuilding at once). `rt-cli render` and `converge` turn it on.
    pub rebuild_on_cpu: bool,
    /// Traversal reads triangle vertices from a structure-of-arrays copy instead of the 48-byte
    /// records (a layout experiment: `rt-cli bench --soa`; docs/performance.md).
    pub soa_triangles: bool,
    /// Trace with the wavefront kernels (one per path stage, over queues in storage buffers)
    /// rather than the megakernel (one invocation runs whole paths); docs/performance.md compares
    /// them. The same samples either way (bit for bit without delta lights). `unchecked` and
    /// `soa_triangles`, megakernel experiments, select the megakernel.
    pub wavefront: bool,
}

/// `RenderOptions::pipeline_lifetime` on CPU adapters by default (the compile-time amortisation
/// usually decides: see docs/performance.md for the memory and time this gives).
pub const CPU_PIPELINE_LIFETIME: Duration = Duration::from_secs(5);

/// Between rebuilds the kernel runs at least this many times as long as the last (re)build's first
/// batch took, which holds the JIT compile: rebuilds cost under 1/this of the render time.
pub const REBUILD_AMORTISATION: u32 = 10;

impl Default for RenderOptions {
    fn default() -> Self {
        RenderOptions {
            target_dispatch: Duration::from_millis(40),
            count_rays: false,
            max_samples_per_dispatch: None,
            clamp: None,
            generic_kernel: false,
            workgroup: [8, 8],
            aovs: false,
            unchecked: false,
            pipeline_lifetime: None,
            rebuild_on_cpu: false,
            soa_triangles: false,
            wavefront: true,
        }
    }
}

/// Mesa's lavapipe runs at most 65,535 loop iterations per invocation, over all loops, and then
/// silently cuts every loop short. Keep the estimated iterations of one dispatch well under it.
const LOOP_BUDGET: u32 = 16_384;

/// A rendered image: per pixel, the mean radiance (rgb) and mean squared luminance (a).
#[derive(Clone, Debug)]
pub struct Image {
    pub width: u32,
    pub height: u32,
    pub samples_per_pixel: u32,
    pub pixels: Vec<[f32; 4]>,
}

impl Image {
    pub fn rgb(&self) -> Vec<[f32; 3]> {
        self.pixels.iter().map(|p| [p[0], p[1], p[2]]).collect()
    }

    /// Mean of each channel over the image.
    pub fn channel_means(&self) -> [f64; 3] {
        let mut sum = [0.0f64; 3];
        for p in &self.pixels {
            for c in 0..3 {
                sum[c] += f64::from(p[c]);
            }
        }
        sum.map(|s| s / self.pixels.len().max(1) as f64)
    }
}

/// Per-pixel auxiliary outputs for the denoiser, means over the samples like the image.
#[derive(Clone, Debug, Default)]
pub struct Aovs {
    /// The first hit's albedo (texture, metal colour, glass tint; an emitter's normalised colour).
    pub albedo: Vec<[f32; 3]>,
    /// The first hit's geometric normal, facing the camera.
    pub normal: Vec<[f32; 3]>,
    /// Light seen directly: emitters and sky at the first segment.
    pub emission: Vec<[f32; 3]>,
}

/// What one batch did.
#[derive(Clone, Copy, Debug, Default)]
pub struct BatchStats {
    pub samples: u32,
    pub dispatches: u32,
    pub longest_dispatch: Duration,
    /// With the wavefront kernels, path depths run over all of the batch's waves (each wave
    /// stops at its first empty queue); 0 with the megakernel.
    pub wave_depths: u32,
}

/// What traces the paths.
enum Engine {
    /// trace.wgsl: one invocation per pixel runs whole paths.
    Megakernel {
        pipeline: wgpu::ComputePipeline,
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
    /// (binding, buffer) of every bind-group entry, to bind them to a rebuilt pipeline.
    bound: Vec<(u32, wgpu::Buffer)>,
    frame_buffer: wgpu::Buffer,
    accum: wgpu::Buffer,
    aovs: wgpu::Buffer,
    counters: wgpu::Buffer,
    frame: Frame,
    options: RenderOptions,
    samples_done: u32,
    samples_per_dispatch: u32,
    rows_per_dispatch: u32,
    /// A batch that failed part-way: the first row it had not rendered, and its samples per pixel.
    /// The rows before already hold its samples, so the next batch finishes this one.
    unfinished: Option<(u32, u32)>,
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
        let options = RenderOptions {
            clamp: options.clamp.or(scene.settings.clamp),
            ..options
        };
        Self::new(ctx, gpu_scene, frame, options)
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
        let accum_size = pixels * 16;
        ctx.check_buffer("accumulation (width x height x 16 bytes)", accum_size)?;
        // Albedo and normal, or a placeholder the kernel never touches.
        let aov_size = if options.aovs { pixels * 48 } else { 48 };
        ctx.check_buffer(
            "albedo, normal, emission (width x height x 48 bytes)",
            aov_size,
        )?;
        let [wx, wy] = options.workgroup;
        if wx == 0 || wy == 0 || wx * wy > MAX_WORKGROUP_INVOCATIONS {
            return Err(GpuError::Wgpu(format!(
                "work group {wx}x{wy}: it must have 1 to {MAX_WORKGROUP_INVOCATIONS} invocations \
                 (their BVH traversal stacks share the work group's 16 KiB of memory)"
            )));
        }
        if frame.emitter_count as usize > scene.emitters.len() {
            return Err(GpuError::Wgpu(format!(
                "the frame samples {} emitters of {}",
                frame.emitter_count,
                scene.emitters.len()
            )));
        }
        // The megakernel-only experiments select the megakernel.
        let wavefront = options.wavefront && !options.unchecked && !options.soa_triangles;
        let trusted = options.unchecked
            && match scene.check_kernel_indices() {
                Ok(()) => true,
                Err(e) => {
                    log::error!("kernel runs with bounds checks: the scene's {e}");
                    false
                }
            };
        let mut features = scene.features;
        features.thin_lens = frame.lens_radius > 0.0;
        features.nee = frame.emitter_count > 0;
        if options.generic_kernel {
            // Every branch compiled in; each still checks its data at run time. (NEE stays as the
            // scene needs: the emitter table must not be empty.)
            features.textures = true;
            features.metal = true;
            features.dielectric = true;
            features.thin_lens = true;
            features.delta_lights = true;
        }
        let pipeline_key = PipelineKey {
            features,
            layout: scene.layout,
            count_rays: options.count_rays,
            clamp_bits: options
                .clamp
                .filter(|c| c.is_finite() && *c > 0.0)
                .map_or(0, f32::to_bits),
            workgroup: options.workgroup.map(|w| w.max(1)),
            sobol: frame.sampler == 1,
            aovs: options.aovs,
            trusted,
            soa_triangles: options.soa_triangles,
        };
        let pipeline = if wavefront {
            None
        } else {
            Some(trace_pipeline(ctx, pipeline_key)?)
        };
        let buffers = [
            storage_buffer(
                ctx,
                "triangles",
                &scene.triangles,
                wgpu::BufferUsages::empty(),
            )?,
            storage_buffer(ctx, "shading", &scene.shading, wgpu::BufferUsages::empty())?,
            storage_buffer(
                ctx,
                "materials",
                &scene.materials,
                wgpu::BufferUsages::empty(),
            )?,
            storage_buffer(
                ctx,
                "bvh nodes",
                scene.node_bytes(),
                wgpu::BufferUsages::empty(),
            )?,
            storage_buffer(ctx, "texels", &scene.texels, wgpu::BufferUsages::empty())?,
            storage_buffer(
                ctx,
                "emitters",
                &scene.emitters,
                wgpu::BufferUsages::empty(),
            )?,
            storage_buffer(
                ctx,
                "delta lights",
                &scene.delta_lights,
                wgpu::BufferUsages::empty(),
            )?,
            storage_buffer(
                ctx,
                "triangle vertices (structure of arrays)",
                &if options.soa_triangles {
                    scene.triangle_soa()
                } else {
                    Vec::new()
                },
                wgpu::BufferUsages::empty(),
            )?,
        ];
        let (frame_buffer, accum, aovs, counters, bound) = ctx.scoped(|| {
            let frame_buffer = ctx
                .device
                .create_buffer_init(&wgpu::util::BufferInitDescriptor {
                    label: Some("frame"),
                    contents: bytemuck::bytes_of(&frame),
                    usage: wgpu::BufferUsages::UNIFORM | wgpu::BufferUsages::COPY_DST,
                });
            let accum = ctx.device.create_buffer(&wgpu::BufferDescriptor {
                label: Some("accumulation"),
                size: accum_size,
                usage: wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_SRC,
                mapped_at_creation: false,
            });
            let aovs = ctx.device.create_buffer(&wgpu::BufferDescriptor {
                label: Some("albedo and normal"),
                size: aov_size,
                usage: wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_SRC,
                mapped_at_creation: false,
            });
            let counters = ctx.device.create_buffer(&wgpu::BufferDescriptor {
                label: Some("counters"),
                size: 8,
                usage: wgpu::BufferUsages::STORAGE
                    | wgpu::BufferUsages::COPY_SRC
                    | wgpu::BufferUsages::COPY_DST,
                mapped_at_creation: false,
            });
            // 0: frame; 1-5: scene buffers; 6: accumulation; 7: counters; 8: emitters;
            // 9: delta lights.
            let [
                triangles,
                shading,
                materials,
                nodes,
                texels,
                emitters,
                delta_lights,
                triangle_soa,
            ] = &buffers;
            let bound = [
                (0, &frame_buffer),
                (1, triangles),
                (2, shading),
                (3, materials),
                (4, nodes),
                (5, texels),
                (6, &accum),
                (7, &counters),
                (8, emitters),
                (9, delta_lights),
                (10, &aovs),
                (11, triangle_soa),
            ];
            let bound: Vec<(u32, wgpu::Buffer)> =
                bound.into_iter().map(|(b, buf)| (b, buf.clone())).collect();
            (frame_buffer, accum, aovs, counters, bound)
        })?;
        // Each path segment traces one ray, a shadow ray for NEE and one per delta light.
        let rays_per_segment = 2 + scene.delta_lights.len() as u32;
        // Loop iterations per ray: BVH2 visits ~2 nodes a level; the wide BVH visits fewer nodes but
        // each may test up to 24 triangles in its inner loop, so count it more generously.
        let depth = scene.bvh_depth as u32;
        let steps_per_ray = match scene.layout {
            rt_core::bvh::BvhLayout::Bvh2 => 2 * depth + 8,
            rt_core::bvh::BvhLayout::Cwbvh => 4 * depth + 24,
        };
        let mut steps_per_segment = steps_per_ray * rays_per_segment;
        if frame.sampler == 1 {
            // Sobol's second dimension loops over the sample index's bits: up to 20 (a million
            // samples) for each of the ~4 such draws of a segment.
            steps_per_segment += 80;
        }
        let loop_cap = (LOOP_BUDGET / (frame.max_depth.max(1) * steps_per_segment)).clamp(1, 64);
        let loop_cap = options
            .max_samples_per_dispatch
            .map_or(loop_cap, |m| m.max(1));
        let engine = match pipeline {
            Some(pipeline) => Engine::Megakernel {
                bind_group: ctx.scoped(|| bind_buffers(ctx, &pipeline, &bound))?,
                pipeline,
            },
            None => {
                // Room for the whole tile at the most samples a wave may take, within the cap (but
                // always a row).
                let capacity = pixels
                    .saturating_mul(u64::from(loop_cap))
                    .min(u64::from(MAX_WAVE_PATHS))
                    .max(u64::from(frame.width)) as u32;
                Engine::Wavefront(Wavefront::new(ctx, pipeline_key, &bound, capacity)?)
            }
        };
        // RT_PIPELINE_LIFETIME_S (seconds) overrides the CPU default.
        let from_env = std::env::var("RT_PIPELINE_LIFETIME_S")
            .ok()
            .and_then(|v| v.trim().parse::<f64>().ok())
            .filter(|s| s.is_finite() && *s >= 0.0)
            .map(Duration::from_secs_f64);
        // Only the megakernel's pipelines grow (tests/memory.rs).
        let auto =
            options.rebuild_on_cpu && !wavefront && ctx.info.device_type == wgpu::DeviceType::Cpu;
        let explicit = options.pipeline_lifetime.or(from_env.filter(|_| auto));
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
            frame,
            options,
            samples_done: 0,
            samples_per_dispatch: 1,
            // Start with a band of about 16k pixels to measure the cost safely, then grow.
            rows_per_dispatch: (16_384 / frame.width)
                .clamp(1, frame.tile_row_end - frame.tile_row_begin),
            unfinished: None,
            loop_cap,
            rays: 0,
            dropped_samples: 0,
            longest_dispatch: Duration::ZERO,
            first_dispatch: Duration::ZERO,
            triangles: scene.triangles.len(),
        })
    }

    /// Whether the wavefront kernels trace (else the megakernel: see `RenderOptions::wavefront`).
    pub fn wavefront(&self) -> bool {
        matches!(self.engine, Engine::Wavefront(_))
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
            wave.rebuild(self.ctx, self.pipeline_key, &self.bound)?;
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
        self.ctx
            .pipelines
            .lock()
            .unwrap_or_else(|e| e.into_inner())
            .remove(&self.pipeline_key);
        let pipeline = trace_pipeline(self.ctx, self.pipeline_key)?;
        let bind_group = self
            .ctx
            .scoped(|| bind_buffers(self.ctx, &pipeline, &self.bound))?;
        self.engine = Engine::Megakernel {
            pipeline,
            bind_group,
        };
        Ok(())
    }

    /// Adds up to `max_samples` samples to every pixel; returns what was done. After an error
    /// part-way through a batch (some bands of rows already hold its samples), the next call
    /// finishes that batch, with its sample count, instead of starting a new one.
    pub fn render_batch(&mut self, max_samples: u32) -> Result<BatchStats> {
        if let (Some(life), Some(first)) = (self.pipeline_lifetime, self.pipeline_first_batch)
            && self.pipeline_ran >= life.max(first * self.rebuild_amortisation)
        {
            self.rebuild_pipeline()?;
        }
        let started = Instant::now();
        // On lavapipe the first batch after a pipeline is built holds its JIT compile (seconds).
        let first_after_build = self.pipeline_first_batch.is_none();
        let (mut row, samples) = self.unfinished.take().unwrap_or((
            self.frame.tile_row_begin,
            max_samples.min(self.samples_per_dispatch).max(1),
        ));
        let mut stats = BatchStats {
            samples,
            ..Default::default()
        };
        let mut slowest_rate = 0.0f64; // seconds per (sample x row)
        while row < self.frame.tile_row_end {
            let rows = self.rows_per_dispatch.min(self.frame.tile_row_end - row);
            let (elapsed, depths) = match self.dispatch(row, rows, samples) {
                Ok(done) => done,
                Err(e) => {
                    self.unfinished = Some((row, samples));
                    return Err(e);
                }
            };
            stats.dispatches += 1;
            stats.wave_depths += depths;
            stats.longest_dispatch = stats.longest_dispatch.max(elapsed);
            slowest_rate = slowest_rate.max(elapsed.as_secs_f64() / f64::from(samples * rows));
            row += rows;
        }
        self.samples_done += samples;
        self.read_counters()?;
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

    /// Chooses rows and samples per dispatch so one dispatch takes about the target time.
    fn adapt(&mut self, seconds_per_sample_row: f64) {
        if seconds_per_sample_row <= 0.0 {
            return;
        }
        let budget = self.options.target_dispatch.as_secs_f64() / seconds_per_sample_row;
        let tile_rows = self.frame.tile_row_end - self.frame.tile_row_begin;
        let height = f64::from(tile_rows);
        if budget >= height {
            self.rows_per_dispatch = tile_rows;
            self.samples_per_dispatch = ((budget / height) as u32).clamp(1, self.loop_cap);
        } else {
            self.samples_per_dispatch = 1;
            self.rows_per_dispatch = (budget as u32).clamp(1, tile_rows);
        }
        if let Engine::Wavefront(wave) = &self.engine {
            // A wave's paths must fit its queues.
            let row_paths = self.frame.width.max(1);
            let rows = (wave.capacity / row_paths).max(1);
            self.rows_per_dispatch = self.rows_per_dispatch.min(rows);
            let band = self.rows_per_dispatch * row_paths;
            self.samples_per_dispatch =
                self.samples_per_dispatch.min((wave.capacity / band).max(1));
        }
    }

    /// Runs one dispatch (megakernel) or wave (wavefront); returns its longest submission's time
    /// and, for a wave, the path depths it ran.
    fn dispatch(&mut self, row_begin: u32, rows: u32, samples: u32) -> Result<(Duration, u32)> {
        self.ctx.alive()?;
        let frame = Frame {
            sample_base: self.samples_done,
            samples_this_dispatch: samples,
            row_begin,
            row_end: row_begin + rows,
            ..self.frame
        };
        let (pipeline, bind_group) = match &self.engine {
            Engine::Megakernel {
                pipeline,
                bind_group,
            } => (pipeline, bind_group),
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
                let [wx, wy] = self.options.workgroup.map(|w| w.max(1));
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

    /// Renders until every pixel has `spp` samples, calling `progress(samples_done)` after each batch;
    /// `progress` returning false stops early (the image so far stays readable).
    pub fn render(&mut self, spp: u32, mut progress: impl FnMut(u32) -> bool) -> Result<()> {
        while self.samples_done < spp {
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
        let rows = self.frame.tile_row_end - self.frame.tile_row_begin;
        let size = u64::from(self.frame.width) * u64::from(rows) * 16;
        let bytes = read_buffer(self.ctx, &self.accum, size)?;
        let pixels: Vec<[f32; 4]> = bytemuck::pod_collect_to_vec(&bytes);
        let pixels = if self.samples_done == 0 {
            vec![[0.0; 4]; pixels.len()]
        } else {
            pixels
        };
        Ok(Image {
            width: self.frame.width,
            height: rows,
            samples_per_pixel: self.samples_done,
            pixels,
        })
    }
}

/// A bind group of `bound` for `pipeline`'s (derived) layout.
fn bind_buffers(
    ctx: &GpuContext,
    pipeline: &wgpu::ComputePipeline,
    bound: &[(u32, wgpu::Buffer)],
) -> wgpu::BindGroup {
    let entries: Vec<wgpu::BindGroupEntry> = bound
        .iter()
        .map(|(binding, buffer)| wgpu::BindGroupEntry {
            binding: *binding,
            resource: buffer.as_entire_binding(),
        })
        .collect();
    ctx.device.create_bind_group(&wgpu::BindGroupDescriptor {
        label: Some("trace"),
        layout: &pipeline.get_bind_group_layout(0),
        entries: &entries,
    })
}

/// Rows per tile so that a tile's accumulation buffer (16 bytes per pixel) fits in `max_bytes`.
pub fn tile_rows(width: u32, height: u32, max_bytes: u64) -> u32 {
    let row_bytes = u64::from(width.max(1)) * 16;
    ((max_bytes / row_bytes).max(1) as u32).min(height.max(1))
}

/// Renders `spp` samples per pixel of an image too large for one accumulation buffer, tile by
/// tile (bands of whole rows), and stitches the tiles. Each pixel's samples are the same as in an
/// untiled render (random numbers are keyed by the pixel's number in the whole image), so the result
/// is bit-identical. `max_tile_bytes` defaults to the adapter's largest storage binding;
/// `progress(fraction)` returning false stops after the current batch (the unrendered rest is black).
pub fn render_tiled(
    ctx: &GpuContext,
    gpu_scene: &GpuScene,
    frame: Frame,
    options: RenderOptions,
    spp: u32,
    max_tile_bytes: Option<u64>,
    mut progress: impl FnMut(f64) -> bool,
) -> Result<Image> {
    let limits = ctx.device.limits();
    let max_bytes = max_tile_bytes.unwrap_or(
        limits
            .max_storage_buffer_binding_size
            .min(limits.max_buffer_size),
    );
    let rows_per_tile = tile_rows(frame.width, frame.height, max_bytes);
    let mut pixels = vec![[0.0f32; 4]; frame.width as usize * frame.height as usize];
    let mut done_samples = spp;
    let mut begin = 0;
    let mut keep_going = true;
    while begin < frame.height && keep_going {
        let end = (begin + rows_per_tile).min(frame.height);
        let tile_frame = Frame {
            tile_row_begin: begin,
            tile_row_end: end,
            ..frame
        };
        let mut renderer = Renderer::new(ctx, gpu_scene, tile_frame, options)?;
        while renderer.samples_done() < spp {
            renderer.render_batch(spp - renderer.samples_done())?;
            let fraction = (f64::from(begin)
                + f64::from(end - begin) * f64::from(renderer.samples_done()) / f64::from(spp))
                / f64::from(frame.height);
            if !progress(fraction) {
                keep_going = false;
                break;
            }
        }
        done_samples = done_samples.min(renderer.samples_done());
        let tile = renderer.read_image()?;
        let start = begin as usize * frame.width as usize;
        pixels[start..start + tile.pixels.len()].copy_from_slice(&tile.pixels);
        begin = end;
    }
    Ok(Image {
        width: frame.width,
        height: frame.height,
        samples_per_pixel: done_samples,
        pixels,
    })
}
