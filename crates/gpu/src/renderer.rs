//! Progressive rendering: each `render_batch` adds samples to every pixel through one or more short
//! dispatches, so a render can be stopped, cancelled or read back after any batch.
//!
//! What it is made of lives beside it: the scene's buffers (`buffers::scene_buffers`), the output
//! buffers and their read-back (`outputs`), what traces the paths (`engine`) and when its pipeline
//! is rebuilt (`pipeline_lifetime`).

use std::time::{Duration, Instant};

use rt_core::accumulation::PixelSums;
use rt_core::gpu_types::Frame;
use rt_core::{GpuScene, Scene};

use crate::accel::{self, SceneAccel};
use crate::adaptive::AdaptiveState;
use crate::bindings::Binding;
use crate::buffers::scene_buffers;
use crate::context::GpuContext;
use crate::engine::{self, Engine, tlas};
use crate::error::{GpuError, Result};
use crate::image::{Aovs, Image};
use crate::options::{Kernel, RenderOptions, Trace};
use crate::outputs::{self, Outputs};
use crate::pipeline_cache::PipelineKey;
use crate::pipeline_lifetime::PipelineLifetime;
use crate::sizing;
use crate::wavefront::Wavefront;

pub use crate::outputs::AOV_BYTES_PER_PIXEL;

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

pub struct Renderer<'a> {
    ctx: &'a GpuContext,
    engine: Engine,
    pipeline_key: PipelineKey,
    /// When the pipeline is due for a rebuild (see `Tuning::pipeline_rebuilds`).
    lifetime: PipelineLifetime,
    /// The scene's buffers and the outputs, to bind them to a rebuilt pipeline.
    bound: Vec<(Binding, wgpu::Buffer)>,
    /// The driver's acceleration structure, when tracing with ray queries.
    accel: Option<SceneAccel>,
    /// The frame's uniform, the exact sums, the AOVs and the counters.
    outputs: Outputs,
    /// Adaptive sampling's stop marks and pixels still sampling.
    adaptive: AdaptiveState,
    frame: Frame,
    options: RenderOptions,
    samples_done: u32,
    /// The index (from `options.first_sample`) of the next batch's first sample: `samples_done`
    /// unless `seek` moved it.
    next_sample: u32,
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
    /// Prepares a render of `scene` (camera and settings, adaptive sampling included, from the
    /// scene).
    pub fn for_scene(
        ctx: &'a GpuContext,
        scene: &Scene,
        gpu_scene: &GpuScene,
        options: RenderOptions,
    ) -> Result<Self> {
        if scene.settings.integrator == rt_core::Integrator::Bdpt {
            return Err(crate::GpuError::Options(
                "bidirectional path tracing (integrator bdpt) renders on the CPU backend only: \
                 render with --device cpu, or with the path integrator on a GPU"
                    .into(),
            ));
        }
        let frame = rt_core::frame::frame_for(scene, gpu_scene)?;
        let adaptive = rt_core::adaptive::Adaptive::of_settings(&scene.settings);
        Self::new(ctx, gpu_scene, (frame, adaptive), options)
    }

    /// A render of `frame` of `scene` with adaptive sampling's rule `adaptive` (the scene's
    /// settings', as `for_scene` and `render_tiled` read them).
    pub(crate) fn new(
        ctx: &'a GpuContext,
        scene: &GpuScene,
        (frame, adaptive_rule): (Frame, Option<rt_core::adaptive::Adaptive>),
        options: RenderOptions,
    ) -> Result<Self> {
        validate_frame(ctx, scene, &frame, &options)?;
        let pixels = u64::from(frame.width) * u64::from(tile_rows(&frame));
        let ray_query = ctx.resolve_trace(options.trace, scene) == Trace::Hardware;
        let accel = if ray_query {
            Some(accel::build(ctx, scene)?)
        } else {
            None
        };
        let pipeline_key =
            engine::pipeline_key(scene, &frame, &options, ray_query, adaptive_rule.is_some());
        let megakernel = engine::megakernel_pipelines(ctx, pipeline_key)?;
        let scene_buffers = scene_buffers(ctx, scene)?;
        ctx.check_buffer(
            "adaptive sampling stops (width x height x 4 bytes)",
            AdaptiveState::buffer_bytes(adaptive_rule, pixels),
        )?;
        let (outputs, adaptive) = ctx.scoped(|| {
            (
                Outputs::new(ctx, &frame, pixels, options.aovs),
                AdaptiveState::new(ctx, adaptive_rule, frame.width, tile_rows(&frame)),
            )
        })?;
        let bound: Vec<(Binding, wgpu::Buffer)> = outputs
            .bound()
            .chain(adaptive.bound())
            .chain(scene_buffers)
            .collect();
        let loop_cap = loop_cap(scene, &frame, &options);
        let engine = match megakernel {
            Some(pipelines) => Engine::megakernel(ctx, pipelines, &bound, tlas(&accel))?,
            None => Engine::Wavefront(Wavefront::new(
                ctx,
                pipeline_key,
                &bound,
                tlas(&accel),
                engine::wave_capacity(pixels, loop_cap, frame.width),
            )?),
        };
        Ok(Renderer {
            ctx,
            engine,
            pipeline_key,
            accel,
            lifetime: PipelineLifetime::new(ctx, &options),
            bound,
            outputs,
            adaptive,
            frame,
            options,
            samples_done: 0,
            next_sample: 0,
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

    /// Whether a batch that stopped part-way (a failure, or `render_slice`'s budget) waits for the
    /// next call to finish it. With adaptive sampling, `read_image` shows whole batches only, so
    /// this is how a caller tells.
    pub fn batch_unfinished(&self) -> bool {
        self.unfinished.is_some()
    }

    /// Makes the next batch take samples from index `sample` on (counted from the options'
    /// `first_sample`) instead of after the last batch's: how `--device all` hands the GPU the
    /// ranges of a frame's samples it draws. Ranges must not overlap (the sums would count a
    /// sample twice). Not while a batch is unfinished (it keeps its samples).
    pub fn seek(&mut self, sample: u32) {
        if self.unfinished.is_none() {
            self.next_sample = sample;
        }
    }

    /// Samples a batch takes at most now (the dispatch sizing's current choice).
    pub fn batch_samples(&self) -> u32 {
        self.samples_per_dispatch
    }

    /// Rays traced so far (only counted with `Tuning::count_rays`).
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

    /// How often the pipeline was rebuilt (see `Tuning::pipeline_rebuilds`); for tests.
    #[cfg(feature = "testing")]
    pub fn pipeline_rebuilds(&self) -> u32 {
        self.lifetime.rebuilds()
    }

    /// Replaces the pipeline with a freshly built one (dropping this renderer's and the context's
    /// handles to the old one, so the driver can free what it holds for it) and rebinds the buffers.
    fn rebuild_pipeline(&mut self) -> Result<()> {
        self.engine
            .rebuild(self.ctx, self.pipeline_key, &self.bound, tlas(&self.accel))?;
        self.lifetime.rebuilt();
        log::debug!(
            "rebuilt the trace pipeline ({} so far)",
            self.lifetime.rebuilds()
        );
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
        if self.lifetime.due() {
            self.rebuild_pipeline()?;
        }
        let started = Instant::now();
        // On lavapipe the first batch after a pipeline is built holds its JIT compile (seconds).
        let first_after_build = self.lifetime.fresh();
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
        self.next_sample += samples;
        self.read_counters()?;
        let (ctx, outputs) = (self.ctx, &self.outputs);
        let (width, rows) = (self.frame.width, tile_rows(&self.frame));
        let samples_done = self.samples_done;
        self.adaptive.update(ctx, samples_done, || {
            outputs.read_accumulation(ctx, width, rows)
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
        self.lifetime.batch_done(started);
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
            && frame.sampler == self.frame.sampler
            && frame.light_sampler == self.frame.light_sampler
            // Fog compiles the media in (`HAS_MEDIA`).
            && rt_core::math::medium::is_vacuum(&frame.fog)
                == rt_core::math::medium::is_vacuum(&self.frame.fog);
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
        self.outputs.clear(self.ctx)?;
        self.frame = frame;
        self.loop_cap = loop_cap(scene, &frame, &self.options);
        self.samples_done = 0;
        self.next_sample = 0;
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
        let wave_capacity = self.engine.wave_capacity();
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
            sample_base: self.next_sample,
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
        self.engine.run(
            self.ctx,
            &self.outputs.frame,
            &frame,
            rows,
            self.options.tuning.workgroup,
        )
    }

    fn read_counters(&mut self) -> Result<()> {
        let [rays, dropped] = self.outputs.take_counters(self.ctx)?;
        self.rays += u64::from(rays);
        self.dropped_samples += u64::from(dropped);
        Ok(())
    }

    /// Renders until every pixel has `spp` samples (or adaptive sampling has stopped every pixel),
    /// calling `progress(samples_done)` after each batch;
    /// `progress` returning false stops early (the image so far stays readable).
    pub fn render(&mut self, spp: u32, mut progress: impl FnMut(u32) -> bool) -> Result<()> {
        use crate::render_loop::{AfterBatch, render_to};
        let never = std::sync::atomic::AtomicBool::new(false);
        let after_batch = |r: &Self| {
            Ok(match progress(r.samples_done) {
                true => AfterBatch::Continue,
                false => AfterBatch::Stop("the caller's progress"),
            })
        };
        render_to(self, spp, &never, |done| spp - done, after_batch)?;
        Ok(())
    }

    /// The mean first-hit albedo, normal and directly seen light of each pixel (of this
    /// renderer's tile), when the renderer was made with `RenderOptions::aovs`.
    pub fn read_aovs(&self) -> Result<Option<Aovs>> {
        if !self.options.aovs {
            return Ok(None);
        }
        let aovs = self
            .outputs
            .read_aovs(self.ctx, self.frame.width, tile_rows(&self.frame))?;
        Ok(Some(aovs))
    }

    /// The accumulated image so far (of this renderer's tile: `height` is the tile's rows). After a
    /// batch failed part-way, its finished rows hold one batch more than `samples_per_pixel` says
    /// until the next batch completes it (keep the last image read before the failure to save).
    pub fn read_image(&self) -> Result<Image> {
        let (width, rows) = (self.frame.width, tile_rows(&self.frame));
        if let Some((sums, counts)) = self.adaptive.sums_and_counts() {
            // What the two streams keep (`rt_core::adaptive`), of whole batches only.
            return Ok(outputs::mean_image(
                width,
                rows,
                self.samples_done,
                sums,
                Some(counts),
            ));
        }
        let sums = if self.samples_done == 0 && self.unfinished.is_none() {
            vec![PixelSums::default(); tile_pixels(&self.frame)]
        } else {
            self.outputs.read_accumulation(self.ctx, width, rows)?
        };
        let counts = self.sample_counts();
        Ok(outputs::mean_image(
            width,
            rows,
            self.samples_done,
            sums,
            counts,
        ))
    }

    /// Each pixel's count where they differ (without adaptive sampling): after a batch failed
    /// part-way, the pixels it reached hold its samples too.
    fn sample_counts(&self) -> Option<Vec<u32>> {
        let (at, extra) = self.unfinished?;
        let mut counts = vec![self.samples_done; tile_pixels(&self.frame)];
        let width = self.frame.width as usize;
        let reached = (at - self.frame.tile_row_begin) as usize * width;
        for c in &mut counts[..reached] {
            *c += extra;
        }
        Some(counts)
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

/// Checks `frame`'s tile, the output buffers' sizes for it, `options` and the emitters `frame`
/// samples (in that order: the first problem is the one reported).
fn validate_frame(
    ctx: &GpuContext,
    scene: &GpuScene,
    frame: &Frame,
    options: &RenderOptions,
) -> Result<()> {
    if !(frame.tile_row_begin < frame.tile_row_end && frame.tile_row_end <= frame.height) {
        return Err(GpuError::Wgpu(format!(
            "tile rows {}..{} are not inside the image's {} rows",
            frame.tile_row_begin, frame.tile_row_end, frame.height
        )));
    }
    let pixels = u64::from(frame.width) * u64::from(tile_rows(frame));
    outputs::check_sizes(ctx, pixels, options.aovs)?;
    options.validate()?;
    if frame.emitter_count as usize > scene.emitters.len() {
        return Err(GpuError::Wgpu(format!(
            "the frame samples {} emitters of {}",
            frame.emitter_count,
            scene.emitters.len()
        )));
    }
    Ok(())
}

/// The most samples one dispatch may take: `sizing::loop_cap`, or the options' cap.
fn loop_cap(scene: &GpuScene, frame: &Frame, options: &RenderOptions) -> u32 {
    options
        .max_samples_per_dispatch
        .map_or_else(|| sizing::loop_cap(scene, frame), |m| m.max(1))
}

/// A GPU batch is a few short dispatches: `cancel` is looked at between batches.
impl crate::render_loop::Batches for Renderer<'_> {
    fn samples_done(&self) -> u32 {
        Renderer::samples_done(self)
    }

    fn active_pixels(&self) -> usize {
        Renderer::active_pixels(self)
    }

    fn take_batch(&mut self, samples: u32, _cancel: &std::sync::atomic::AtomicBool) -> Result<()> {
        self.render_batch(samples).map(|_| ())
    }
}
