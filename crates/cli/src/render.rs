//! `rt-cli render`: a progressive render with a progress bar, saved when done (or when stopped).

use std::path::PathBuf;
use std::time::Instant;

use anyhow::{Context, Result};
use clap::Args;
use indicatif::{ProgressBar, ProgressStyle};
use rt_core::{GpuScene, Scene};
use rt_gpu::{GpuContext, GpuError, Renderer};

use crate::options::{EngineArgs, EstimatorArgs, open_device};
use crate::scene_args::SceneArgs;
use crate::shard::ShardArgs;
use crate::summary::{Finish, estimator_summary, print_render_summary, print_scene_summary};

mod cpu;

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

    /// With --time-limit or --noise-target, the samples per pixel are only the most to take.
    fn open_ended(&self) -> bool {
        self.time_limit.is_some() || self.noise_target.is_some()
    }
}

pub fn run(args: RenderArgs, verbose: bool) -> Result<()> {
    let (scene, range) = prepare_scene(&args)?;
    let (on_cpu, why) = args.engine.on_cpu()?;
    if on_cpu {
        return cpu::run(&args, &scene, range, &why);
    }
    let ctx = open_device(&args.engine.adapter)?;
    let gpu_scene = GpuScene::build(&scene)?;
    let max_buffer = max_accumulation_bytes(&ctx);
    let options = shard_options(&args, range);
    let (width, height) = (scene.settings.width, scene.settings.height);
    let bytes = rt_gpu::whole_image_binding_bytes(width, height, &options);
    if bytes > max_buffer {
        if args.open_ended() {
            anyhow::bail!(
                "a {width}x{height} image needs a {bytes}-byte buffer (accumulation or denoiser \
                 guides), more than this adapter's {max_buffer} per buffer: it renders in tiles, \
                 one after another, which needs a fixed --spp rather than --time-limit or \
                 --noise-target"
            );
        }
        return render_in_tiles(&args, &scene, &ctx, &gpu_scene, max_buffer, range);
    }
    let mut renderer = Renderer::for_scene(&ctx, &scene, &gpu_scene, options)?;
    let finish = render_progressively(&args, &ctx, &mut renderer, &scene, range)?;
    let image = renderer.read_image()?;
    let aovs = match range {
        Some(_) => renderer.read_aovs()?,
        None => None,
    };
    let (kernel, scenes) = (renderer.kernel(), (&scene, &gpu_scene));
    save_output(&args, range, &ctx, kernel, scenes, &image, aovs.as_ref())?;
    eprintln!("device:         GPU ({why})");
    print_render_summary(&ctx, &renderer, scenes, &image, range, &finish, verbose);
    if args.denoise.is_some() {
        let aovs = renderer.read_aovs()?;
        save_denoised(&args, &image, aovs.as_ref())?;
    }
    eprintln!("saved:          {}", args.output.display());
    Ok(())
}

/// Loads the scene and applies the arguments to its settings (samples per pixel, adaptive
/// sampling), checking them, the shard's options and the camera before the GPU is opened, so
/// mistakes are reported at once. Returns the scene and the shard's samples (`--shard`).
fn prepare_scene(args: &RenderArgs) -> Result<(Scene, Option<[u32; 2]>)> {
    rt_core::output::ImageFormat::from_path(&args.output)?;
    let mut scene = args.scene.load()?;
    args.estimator.apply(&mut scene.settings);
    let settings = &mut scene.settings;
    let open_ended = args.open_ended();
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
    Ok((scene, range))
}

/// Renders batch after batch, with a progress bar, until every pixel has its samples (a shard's
/// own, or the frame's), the noise target or the time limit is met, or adaptive sampling has
/// stopped every pixel. If the GPU fails, saves what was last read back (not for a shard) and
/// returns the error.
fn render_progressively(
    args: &RenderArgs,
    ctx: &GpuContext,
    renderer: &mut Renderer,
    scene: &Scene,
    range: Option<[u32; 2]>,
) -> Result<Finish> {
    // A shard's own samples; the frame's otherwise.
    let spp = range.map_or(scene.settings.samples_per_pixel, |[a, b]| b - a);
    let bar = progress_bar(args.open_ended(), spp);
    let started = Instant::now();
    let pixels = u64::from(scene.settings.width) * u64::from(scene.settings.height);
    let mut checkpoint = Checkpoint::default();
    let mut stopped_by = "samples per pixel";
    let faults = rt_gpu::faults::Faults::from_test_env();
    let mut batches = 0u32;
    while renderer.samples_done() < spp && renderer.active_pixels() > 0 {
        let done = renderer.samples_done();
        // With a noise target, grow batches geometrically so the stop overshoots by at most 1/8.
        let batch = if args.noise_target.is_some() {
            (done / 8).max(1)
        } else {
            spp - done
        };
        faults.before_batch(ctx, batches);
        batches += 1;
        let step = renderer
            .render_batch(batch.min(spp - done))
            .map(|_| ())
            .and_then(|()| checkpoint.update(renderer, args.noise_target.is_some()));
        if let Err(e) = step {
            bar.finish_and_clear();
            return Err(render_failed(args, range, checkpoint.image, e));
        }
        let done = renderer.samples_done();
        let secs = started.elapsed().as_secs_f64().max(1e-9);
        bar.set_position(u64::from(done));
        bar.set_message(format!(
            "{:.2} Mpaths/s  noise ≈ {:.4}",
            pixels as f64 * f64::from(done) / secs / 1e6,
            checkpoint.noise
        ));
        if let Some(rule) = stop_rule(args, checkpoint.noise, secs) {
            stopped_by = rule;
            break;
        }
    }
    if renderer.active_pixels() == 0 {
        stopped_by = "adaptive sampling: every pixel converged";
    }
    bar.finish_and_clear();
    Ok(Finish {
        render_time: started.elapsed(),
        stopped_by,
    })
}

/// A bar of `spp` samples, or a spinner when the render is open-ended.
fn progress_bar(open_ended: bool, spp: u32) -> ProgressBar {
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
    bar
}

/// Which rule stops the render after a batch, if one does: the noise target, then the time limit
/// (`secs` into the render).
fn stop_rule(args: &RenderArgs, noise: f64, secs: f64) -> Option<&'static str> {
    if args.noise_target.is_some_and(|target| noise <= target) {
        Some("noise target")
    } else if args.time_limit.is_some_and(|limit| secs >= limit) {
        Some("time limit")
    } else {
        None
    }
}

/// The image as last read back, and its estimated noise.
struct Checkpoint {
    noise: f64,
    at: Option<Instant>,
    /// If the GPU fails mid-render, this is what can still be saved.
    image: Option<rt_gpu::Image>,
}

impl Default for Checkpoint {
    fn default() -> Self {
        Checkpoint {
            noise: f64::INFINITY,
            at: None,
            image: None,
        }
    }
}

impl Checkpoint {
    /// Reads back (for the noise estimate, and as a checkpoint) when the noise decides the stop,
    /// else about once a second.
    fn update(&mut self, renderer: &Renderer, noise_decides: bool) -> rt_gpu::Result<()> {
        let due = noise_decides || self.at.is_none_or(|t| t.elapsed().as_secs_f64() >= 1.0);
        if due {
            let image = renderer.read_image()?;
            self.noise = image.estimated_noise();
            self.at = Some(Instant::now());
            self.image = Some(image);
        }
        Ok(())
    }
}

/// The error of a render that failed mid-way: a shard writes nothing; a frame saves the image
/// last read back, if any (`save_after_failure`).
fn render_failed(
    args: &RenderArgs,
    range: Option<[u32; 2]>,
    last_image: Option<rt_gpu::Image>,
    error: GpuError,
) -> anyhow::Error {
    if range.is_some() {
        return anyhow::Error::from(error)
            .context("the shard's render failed; no part was written (render it again)");
    }
    save_after_failure(args, last_image, error.into())
}

/// The largest accumulation buffer this adapter allows: the adapter's limit, or less where a test
/// asks (`rt_gpu::faults::max_accumulation_bytes`).
fn max_accumulation_bytes(ctx: &GpuContext) -> u64 {
    let limits = ctx.device.limits();
    let limit = limits
        .max_storage_buffer_binding_size
        .min(limits.max_buffer_size);
    rt_gpu::faults::max_accumulation_bytes().map_or(limit, |cap| cap.clamp(16, limit))
}

/// Renders an image too large for one accumulation buffer in bands of rows (see
/// `rt_gpu::render_tiled`), with the same options; the result is the same as an untiled render.
fn render_in_tiles(
    args: &RenderArgs,
    scene: &Scene,
    ctx: &GpuContext,
    gpu_scene: &GpuScene,
    max_buffer: u64,
    range: Option<[u32; 2]>,
) -> Result<()> {
    let settings = &scene.settings;
    let options = shard_options(args, range).with_scene_settings(settings);
    let pixel_bytes = rt_gpu::pixel_binding_bytes(&options);
    let rows = rt_gpu::tile_rows(settings.width, settings.height, pixel_bytes, max_buffer);
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
        options,
        range.map_or(settings.samples_per_pixel, |[a, b]| b - a),
        Some(max_buffer),
        |fraction| {
            bar.set_position((fraction * 1000.0) as u64);
            true
        },
    )?;
    bar.finish_and_clear();
    let render_time = started.elapsed();
    let (kernel, scenes) = (args.engine.kernel(), (scene, gpu_scene));
    save_output(args, range, ctx, kernel, scenes, &image, aovs.as_ref())?;
    let trace = ctx.resolve_trace(args.engine.trace.into(), gpu_scene);
    print_scene_summary(ctx, kernel, trace, gpu_scene);
    eprintln!(
        "image:          {}x{}, {} spp, {}, in {tiles} tiles of {rows} rows (a whole-image \
         buffer of {pixel_bytes} bytes a pixel would exceed the adapter's {max_buffer} bytes)",
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

/// Saves `image` as the output, or for a shard (`range`) as a part for `rt-cli merge`, with its
/// `aovs` and a note of where its samples were rendered (by `kernel`).
fn save_output(
    args: &RenderArgs,
    range: Option<[u32; 2]>,
    ctx: &GpuContext,
    kernel: rt_gpu::Kernel,
    scenes: (&Scene, &GpuScene),
    image: &rt_gpu::Image,
    aovs: Option<&rt_gpu::Aovs>,
) -> Result<()> {
    match range {
        Some(range) => {
            let note = shard_note(range, ctx, kernel);
            crate::shard::save(&args.output, range, scenes, image, aovs, note)
        }
        None => save(args, image),
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
