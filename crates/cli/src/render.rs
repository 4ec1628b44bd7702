//! `rt-cli render`: a progressive render with a progress bar, saved when done (or when stopped).

use std::path::PathBuf;
use std::time::Instant;

use anyhow::{Context, Result};
use clap::Args;
use indicatif::{ProgressBar, ProgressStyle};
use rt_core::GpuScene;
use rt_gpu::{GpuContext, Renderer};

use crate::options::{EngineArgs, EstimatorArgs};
use crate::scene_args::SceneArgs;
use crate::shard::ShardArgs;

#[derive(Args, Debug)]
pub struct RenderArgs {
    #[command(flatten)]
    scene: SceneArgs,
    /// Output image: .png, .jpg, .ppm (sRGB, clamped) or .exr (linear float).
    #[arg(short, long, default_value = "render.png")]
    output: PathBuf,
    /// Samples per pixel (default 64; with --time-limit or --noise-target, the most to take).
    #[arg(long)]
    spp: Option<u32>,
    /// Stop after this many seconds (after the batch running then) and write the image.
    #[arg(long, value_name = "SECONDS")]
    time_limit: Option<f64>,
    /// Stop once the estimated noise (the square root of the image's expected relMSE against its
    /// converged version, from per-pixel sample variance) is at most this, e.g. 0.05.
    #[arg(long, value_name = "X")]
    noise_target: Option<f64>,
    /// Exposure in stops for 8-bit outputs (EXR is always linear).
    #[arg(long, default_value_t = 0.0, allow_hyphen_values = true)]
    exposure: f32,
    /// View transform for 8-bit outputs: `standard` clamps each channel at 1; `neutral` is the
    /// Khronos PBR Neutral tone mapper (highlights roll off instead of clipping). EXR stays linear.
    #[arg(long, value_enum, default_value = "standard")]
    view: ViewArg,
    /// Also write a denoised copy beside the output (NAME.denoised.EXT) guided by albedo and
    /// normals: `--denoise` or `--denoise=auto` uses Open Image Denoise where it is installed
    /// (scripts/ensure-oidn) and rt's À-Trous filter otherwise; `=oidn` requires OIDN; `=atrous`.
    /// The output itself stays raw.
    #[arg(long, value_enum, num_args = 0..=1, require_equals = true, default_missing_value = "auto", value_name = "DENOISER")]
    denoise: Option<crate::options::DenoiseArg>,
    /// Give every pixel every sample even with --noise-target (which otherwise turns adaptive
    /// sampling on, with the target as each pixel's threshold).
    #[arg(long, conflicts_with = "adaptive")]
    no_adaptive: bool,
    #[command(flatten)]
    shard: ShardArgs,
    #[command(flatten)]
    estimator: EstimatorArgs,
    #[command(flatten)]
    engine: EngineArgs,
}

/// `--view` values.
#[derive(clap::ValueEnum, Clone, Copy, Debug)]
pub enum ViewArg {
    Standard,
    #[value(alias = "khronos-pbr-neutral")]
    Neutral,
}

impl ViewArg {
    pub fn with_exposure(self, exposure_stops: f32) -> rt_core::output::View {
        use rt_core::output::ViewTransform;
        rt_core::output::View {
            transform: match self {
                ViewArg::Standard => ViewTransform::Standard,
                ViewArg::Neutral => ViewTransform::KhronosPbrNeutral,
            },
            exposure_stops,
        }
    }
}

impl RenderArgs {
    fn view(&self) -> rt_core::output::View {
        self.view.with_exposure(self.exposure)
    }
}

pub fn run(args: RenderArgs, verbose: bool) -> Result<()> {
    rt_core::output::ImageFormat::from_path(&args.output)?;
    let mut scene = args.scene.load()?;
    args.estimator.apply(&mut scene.settings);
    let settings = &mut scene.settings;
    let open_ended = args.time_limit.is_some() || args.noise_target.is_some();
    settings.samples_per_pixel = args.spp.unwrap_or(if open_ended {
        1 << 20
    } else {
        settings.samples_per_pixel
    });
    if let Some(t) = args.time_limit.filter(|t| !(t.is_finite() && *t > 0.0)) {
        anyhow::bail!("--time-limit must be a positive number of seconds, got {t}");
    }
    if let Some(x) = args.noise_target.filter(|x| !(x.is_finite() && *x > 0.0)) {
        anyhow::bail!("--noise-target must be a positive number, got {x}");
    }
    if args.no_adaptive {
        settings.adaptive_threshold = None;
    } else if settings.adaptive_threshold.is_none() {
        settings.adaptive_threshold = args.noise_target.map(|x| x as f32);
    }
    let range = args.shard.range(settings.samples_per_pixel)?;
    if range.is_some() {
        crate::shard::check_options(&args.output, open_ended, args.denoise.is_some())?;
    }
    // Check the camera and settings before opening the GPU, so mistakes are reported at once.
    rt_core::frame::validate(&scene)?;

    let ctx = GpuContext::new(&args.engine.adapter)?;
    let gpu_scene = GpuScene::build(&scene)?;
    let max_buffer = max_accumulation_bytes(&ctx);
    let accum_bytes = u64::from(scene.settings.width)
        * u64::from(scene.settings.height)
        * rt_core::accumulation::CHANNEL_SUM_BYTES;
    if accum_bytes > max_buffer {
        if open_ended {
            anyhow::bail!(
                "a {}x{} image needs {accum_bytes} bytes of accumulation, more than this adapter's \
                 {max_buffer} per buffer: it renders in tiles, one after another, which needs a \
                 fixed --spp rather than --time-limit or --noise-target",
                scene.settings.width,
                scene.settings.height
            );
        }
        return render_in_tiles(&args, &scene, &ctx, &gpu_scene, max_buffer, range);
    }
    let options = shard_options(&args, range);
    let mut renderer = Renderer::for_scene(&ctx, &scene, &gpu_scene, options)?;

    // A shard's own samples; the frame's otherwise.
    let spp = range.map_or(scene.settings.samples_per_pixel, |[a, b]| b - a);
    let bar = if open_ended {
        ProgressBar::new_spinner()
    } else {
        ProgressBar::new(u64::from(spp))
    };
    let template = if open_ended {
        "{spinner} [{elapsed_precise}] {pos} spp  {msg}"
    } else {
        "{spinner} [{elapsed_precise}] {bar:40} {pos}/{len} spp  {msg} (eta {eta})"
    };
    bar.set_style(
        ProgressStyle::with_template(template).unwrap_or_else(|_| ProgressStyle::default_bar()),
    );
    let started = Instant::now();
    let pixels = u64::from(scene.settings.width) * u64::from(scene.settings.height);
    let mut noise = f64::INFINITY;
    let mut last_estimate: Option<Instant> = None;
    let mut stopped_by = "samples per pixel";
    // The image as last read back: if the GPU fails mid-render, this is what can still be saved.
    let mut last_image: Option<rt_gpu::Image> = None;
    // Fault injection for the tests: lose the device after this many batches.
    let lose_device_after: Option<u32> = std::env::var("RT_FAULT_LOSE_DEVICE_AFTER_BATCHES")
        .ok()
        .and_then(|v| v.parse().ok());
    // And run out of memory (the next GPU operation fails) after this many.
    let out_of_memory_after: Option<u32> = std::env::var("RT_FAULT_OUT_OF_MEMORY_AFTER_BATCHES")
        .ok()
        .and_then(|v| v.parse().ok());
    let mut batches = 0u32;
    while renderer.samples_done() < spp && renderer.active_pixels() > 0 {
        let done = renderer.samples_done();
        // With a noise target, grow batches geometrically so the stop overshoots by at most 1/8.
        let batch = if args.noise_target.is_some() {
            (done / 8).max(1)
        } else {
            spp - done
        };
        if lose_device_after == Some(batches) {
            ctx.device.destroy();
        }
        if out_of_memory_after == Some(batches) {
            ctx.inject_out_of_memory(1);
        }
        batches += 1;
        let step = renderer
            .render_batch(batch.min(spp - done))
            .map(|_| ())
            .and_then(|()| {
                // Read back (for the noise estimate, and as a checkpoint) when the noise decides
                // the stop, else about once a second.
                let due = args.noise_target.is_some()
                    || last_estimate.is_none_or(|t| t.elapsed().as_secs_f64() >= 1.0);
                if due {
                    let image = renderer.read_image()?;
                    noise = image.estimated_noise();
                    last_estimate = Some(Instant::now());
                    last_image = Some(image);
                }
                Ok(())
            });
        if let Err(e) = step {
            bar.finish_and_clear();
            if range.is_some() {
                return Err(anyhow::Error::from(e)
                    .context("the shard's render failed; no part was written (render it again)"));
            }
            return Err(save_after_failure(&args, last_image, e.into()));
        }
        let done = renderer.samples_done();
        let secs = started.elapsed().as_secs_f64().max(1e-9);
        bar.set_position(u64::from(done));
        bar.set_message(format!(
            "{:.2} Mpaths/s  noise ≈ {noise:.4}",
            pixels as f64 * f64::from(done) / secs / 1e6
        ));
        if args.noise_target.is_some_and(|target| noise <= target) {
            stopped_by = "noise target";
            break;
        }
        if args.time_limit.is_some_and(|limit| secs >= limit) {
            stopped_by = "time limit";
            break;
        }
    }
    if renderer.active_pixels() == 0 {
        stopped_by = "adaptive sampling: every pixel converged";
    }
    bar.finish_and_clear();
    let render_time = started.elapsed();
    let image = renderer.read_image()?;
    let noise = image.estimated_noise();
    match range {
        Some(range) => {
            let aovs = renderer.read_aovs()?;
            let note = shard_note(range, &ctx, renderer.kernel());
            let scenes = (&scene, &gpu_scene);
            crate::shard::save(&args.output, range, scenes, &image, aovs.as_ref(), note)?;
        }
        None => save(&args, &image)?,
    }

    let secs = render_time.as_secs_f64().max(1e-9);
    let paths = pixels as f64 * image.mean_samples();
    print_scene_summary(&ctx, renderer.kernel(), renderer.trace(), &gpu_scene);
    eprintln!(
        "image:          {}x{}, {} spp, {}",
        image.width,
        image.height,
        image.samples_per_pixel,
        estimator_summary(&scene.settings, &gpu_scene)
    );
    if let (Some(threshold), Some(counts)) =
        (scene.settings.adaptive_threshold, &image.sample_counts)
    {
        let stopped = counts
            .iter()
            .filter(|&&c| c < image.samples_per_pixel)
            .count();
        eprintln!(
            "adaptive:       threshold {threshold}, mean {:.1} spp, {:.1}% of pixels stopped before the last batch",
            image.mean_samples(),
            100.0 * stopped as f64 / counts.len().max(1) as f64
        );
    }
    if let Some([a, b]) = range {
        eprintln!(
            "shard:          samples {a}..{b} of {}, saved as a part for `rt-cli merge`",
            scene.settings.samples_per_pixel
        );
    }
    eprintln!("render time:    {render_time:.2?} (stopped by {stopped_by})");
    eprintln!("noise:          {noise:.5} (estimated sqrt(relMSE) against the converged image)");
    eprintln!(
        "samples/s:      {:.1} spp/s",
        f64::from(image.samples_per_pixel) / secs
    );
    eprintln!("paths/s:        {:.3} M", paths / secs / 1e6);
    if renderer.dropped_samples() > 0 {
        eprintln!(
            "dropped:        {} NaN/Inf samples (counted as black)",
            renderer.dropped_samples()
        );
    }
    if verbose {
        eprintln!("longest dispatch: {:.2?}", renderer.longest_dispatch());
        let m = image.channel_means();
        eprintln!("channel means:  {:.6} {:.6} {:.6}", m[0], m[1], m[2]);
    }
    if args.denoise.is_some() {
        let aovs = renderer.read_aovs()?;
        save_denoised(&args, &image, aovs.as_ref())?;
    }
    eprintln!("saved:          {}", args.output.display());
    Ok(())
}

/// The adapter, kernel, tracing, triangles and BVH build, as both render paths print them.
fn print_scene_summary(
    ctx: &GpuContext,
    kernel: rt_gpu::Kernel,
    trace: rt_gpu::Trace,
    gpu_scene: &GpuScene,
) {
    eprintln!("adapter:        {}", ctx.adapter_label());
    eprintln!(
        "kernel:         {}, tracing {}",
        kernel.name(),
        trace_name(trace)
    );
    eprintln!("triangles:      {}", gpu_scene.triangles.len());
    eprintln!(
        "BVH build:      {:.2?} (depth {})",
        gpu_scene.bvh_build_time, gpu_scene.bvh_depth
    );
}

fn trace_name(trace: rt_gpu::Trace) -> &'static str {
    match trace {
        rt_gpu::Trace::Hardware => "with ray queries",
        rt_gpu::Trace::Bvh | rt_gpu::Trace::Auto => "rt's BVH",
    }
}

/// "max depth D, next-event estimation on|off, S sampler".
fn estimator_summary(settings: &rt_core::RenderSettings, gpu_scene: &GpuScene) -> String {
    format!(
        "max depth {}, next-event estimation {}, {} sampler",
        settings.max_depth,
        if gpu_scene.features.nee { "on" } else { "off" },
        match settings.sampler {
            rt_core::math::rng::SamplerKind::Sobol => "Sobol",
            rt_core::math::rng::SamplerKind::Independent => "independent",
        }
    )
}

/// The largest accumulation buffer this adapter allows: the adapter's limit, or less when
/// `RT_MAX_ACCUMULATION_BYTES` says so (tests use it to render small images in tiles).
fn max_accumulation_bytes(ctx: &GpuContext) -> u64 {
    let limits = ctx.device.limits();
    let limit = limits
        .max_storage_buffer_binding_size
        .min(limits.max_buffer_size);
    std::env::var("RT_MAX_ACCUMULATION_BYTES")
        .ok()
        .and_then(|v| v.trim().parse::<u64>().ok())
        .map_or(limit, |cap| cap.clamp(16, limit))
}

/// Renders an image too large for one accumulation buffer in bands of rows (see
/// `rt_gpu::render_tiled`), with the same options; the result is the same as an untiled render.
fn render_in_tiles(
    args: &RenderArgs,
    scene: &rt_core::Scene,
    ctx: &GpuContext,
    gpu_scene: &GpuScene,
    max_buffer: u64,
    range: Option<[u32; 2]>,
) -> Result<()> {
    let settings = &scene.settings;
    let rows = rt_gpu::tile_rows(settings.width, settings.height, max_buffer);
    let tiles = settings.height.div_ceil(rows);
    let bar = ProgressBar::new(1000);
    bar.set_style(
        ProgressStyle::with_template(
            "{spinner} [{elapsed_precise}] {bar:40} {percent}%  {msg} (eta {eta})",
        )
        .unwrap_or_else(|_| ProgressStyle::default_bar()),
    );
    bar.set_message(format!("{tiles} tiles of {rows} rows"));
    let started = Instant::now();
    let frame = rt_core::frame::frame_for(scene, gpu_scene)?;
    let rt_gpu::TiledRender { image, aovs } = rt_gpu::render_tiled(
        ctx,
        gpu_scene,
        frame,
        shard_options(args, range).with_scene_settings(settings),
        range.map_or(settings.samples_per_pixel, |[a, b]| b - a),
        Some(max_buffer),
        |fraction| {
            bar.set_position((fraction * 1000.0) as u64);
            true
        },
    )?;
    bar.finish_and_clear();
    let render_time = started.elapsed();
    match range {
        Some(range) => {
            let note = shard_note(range, ctx, args.engine.kernel());
            let scenes = (scene, gpu_scene);
            crate::shard::save(&args.output, range, scenes, &image, aovs.as_ref(), note)?;
        }
        None => save(args, &image)?,
    }
    let trace = ctx.resolve_trace(args.engine.trace.into(), gpu_scene);
    print_scene_summary(ctx, args.engine.kernel(), trace, gpu_scene);
    eprintln!(
        "image:          {}x{}, {} spp, {}, in {tiles} tiles of {rows} rows (the accumulation \
         buffer would exceed the adapter's {max_buffer} bytes)",
        image.width,
        image.height,
        image.samples_per_pixel,
        estimator_summary(settings, gpu_scene)
    );
    eprintln!("render time:    {render_time:.2?}");
    if args.denoise.is_some() {
        save_denoised(args, &image, aovs.as_ref())?;
    }
    eprintln!("saved:          {}", args.output.display());
    Ok(())
}

/// The render options, with a shard's first sample, and the denoiser's guides a part keeps.
fn shard_options(args: &RenderArgs, range: Option<[u32; 2]>) -> rt_gpu::RenderOptions {
    rt_gpu::RenderOptions {
        first_sample: range.map_or(0, |r| r[0]),
        ..args
            .engine
            .render_options(args.denoise.is_some() || range.is_some())
    }
}

/// Where a shard's samples were rendered (kept in the part's notes).
fn shard_note(range: [u32; 2], ctx: &GpuContext, kernel: rt_gpu::Kernel) -> String {
    format!(
        "samples {}..{}: {}, {} kernel",
        range[0],
        range[1],
        ctx.adapter_label(),
        kernel.name()
    )
}

/// After the GPU failed mid-render: saves the samples last read back (if any) and returns the
/// error, saying what was saved.
fn save_after_failure(
    args: &RenderArgs,
    last_image: Option<rt_gpu::Image>,
    error: anyhow::Error,
) -> anyhow::Error {
    let Some(image) = last_image.filter(|i| i.samples_per_pixel > 0) else {
        return error.context("the render failed before any samples were read back");
    };
    match save(args, &image) {
        Ok(()) => error.context(format!(
            "the render failed; the {} spp read back before the failure were saved to {}",
            image.samples_per_pixel,
            args.output.display()
        )),
        Err(save_error) => error.context(format!(
            "the render failed, and saving the samples read back before it failed too: {save_error:#}"
        )),
    }
}

/// Saves `image` as the output (atomically, in the format its name says).
fn save(args: &RenderArgs, image: &rt_gpu::Image) -> Result<()> {
    rt_core::output::save_render(
        &args.output,
        image.width,
        image.height,
        &image.pixels,
        image.counts(),
        args.view(),
    )
    .with_context(|| format!("saving {}", args.output.display()))
}

/// `out.png` -> `out.denoised.png`.
fn denoised_path(output: &std::path::Path) -> PathBuf {
    let stem = output
        .file_stem()
        .map(|s| s.to_string_lossy().into_owned())
        .unwrap_or_else(|| "render".into());
    let extension = output
        .extension()
        .map(|e| e.to_string_lossy().into_owned())
        .unwrap_or_else(|| "png".into());
    output.with_file_name(format!("{stem}.denoised.{extension}"))
}

/// Denoises `image` with its AOVs and saves it beside the output (`denoised_path`).
fn save_denoised(
    args: &RenderArgs,
    image: &rt_gpu::Image,
    aovs: Option<&rt_gpu::Aovs>,
) -> Result<()> {
    let aovs = aovs.context("the renderer did not keep albedo and normals")?;
    let denoiser = args.denoise.unwrap_or_default();
    save_denoised_image(&args.output, image, aovs, args.view(), denoiser)
}

/// Denoises `image` guided by `aovs` and saves it beside `output` (`denoised_path`).
pub fn save_denoised_image(
    output: &std::path::Path,
    image: &rt_gpu::Image,
    aovs: &rt_gpu::Aovs,
    view: rt_core::output::View,
    denoiser: crate::options::DenoiseArg,
) -> Result<()> {
    let started = Instant::now();
    let path = denoised_path(output);
    let denoised = image
        .denoised(aovs, denoiser.choice())
        .map_err(anyhow::Error::msg)?;
    if let Some(why) = &denoised.fallback {
        eprintln!("denoiser:       À-Trous, since {why}");
    }
    rt_core::output::save_image(&path, image.width, image.height, &denoised.pixels, view)
        .with_context(|| format!("saving {}", path.display()))?;
    eprintln!(
        "denoised:       {} ({}, {:.2?}; biased: a preview of the converged image, not a \
         measurement)",
        path.display(),
        denoised.denoiser.name(),
        started.elapsed()
    );
    Ok(())
}
