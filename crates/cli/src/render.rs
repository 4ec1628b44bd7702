//! `rt-cli render`: a progressive render with a progress bar, saved when done (or when stopped).

use std::path::PathBuf;
use std::time::Instant;

use anyhow::{Context, Result};
use clap::Args;
use indicatif::{ProgressBar, ProgressStyle};
use rt_core::output::ViewTransform;
use rt_core::{GpuScene, Scene};
use rt_gpu::both_devices::BothDevices;
use rt_gpu::progressive::Progressive;
use rt_gpu::{GpuContext, GpuError, Renderer};

use crate::options::{EngineArgs, EstimatorArgs, open_device};
use crate::scene_args::SceneArgs;
use crate::shard::ShardArgs;
use crate::summary::{
    estimator_summary, print_image_summary, print_render_summary, print_scene_summary,
};

mod progress;

#[derive(Args, Debug, Clone)]
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
    #[command(flatten)]
    display: ViewArgs,
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
    /// Render only this window of the image, X0,Y0 to X1,Y1 in pixels (X1 and Y1 excluded): its
    /// pixels take the samples the whole render takes there. Written alone, or with --into
    /// pasted into an earlier render of the whole image.
    #[arg(long, value_name = "X0,Y0,X1,Y1", value_parser = crate::region::parse_region)]
    region: Option<[u32; 4]>,
    /// With --region: paste the window into this render of the whole image and save the result
    /// as the output (which may be this file); with --transparent its alpha too.
    #[arg(
        long,
        value_name = "FILE",
        requires = "region",
        conflicts_with = "sample_range"
    )]
    into: Option<PathBuf>,
    /// A transparent background (Cycles' Film ▸ Transparent): the background seen directly adds
    /// nothing and alpha is the share of each pixel's camera rays that met a surface (glass
    /// counts as met); the background still lights the scene. PNG (straight alpha) or EXR
    /// (premultiplied).
    #[arg(long)]
    transparent: bool,
    /// Render passes written as layers of the EXR beside the beauty: any of depth, normal,
    /// albedo, position, object, material (e.g. --aov depth,normal).
    #[arg(long, value_name = "LIST", value_parser = crate::layers::parse_pass_list)]
    aov: Option<crate::layers::PassList>,
    #[command(flatten)]
    animation: crate::animation::AnimationArgs,
    #[command(flatten)]
    shard: ShardArgs,
    #[command(flatten)]
    estimator: EstimatorArgs,
    #[command(flatten)]
    engine: EngineArgs,
}

/// How 8-bit outputs show radiance: `--exposure`, `--view`, `--white-balance` (render, preview,
/// merge).
#[derive(clap::Args, Debug, Clone)]
pub struct ViewArgs {
    /// Exposure in stops for 8-bit outputs (EXR is always linear).
    #[arg(long, default_value_t = 0.0, allow_hyphen_values = true)]
    exposure: f32,
    /// View transform for 8-bit outputs: `standard` clamps each channel at 1; `neutral` is the
    /// Khronos PBR Neutral tone mapper (highlights roll off instead of clipping); `agx` is
    /// Blender's default since 4.0 (a wide latitude, highlights desaturating towards white). EXR
    /// stays linear.
    #[arg(long, value_enum, default_value = "standard")]
    view: ViewArg,
    /// White balance for 8-bit outputs: the colour temperature, in kelvin (1667–25000), of the
    /// light that should look white (3200 for tungsten; 6500 about nothing), as Blender's White
    /// Balance with its default tint.
    #[arg(long, value_name = "KELVIN", value_parser = parse_kelvin)]
    white_balance: Option<f32>,
}

fn parse_kelvin(s: &str) -> Result<f32, String> {
    let k: f32 = s
        .parse()
        .map_err(|_| format!("'{s}' is not a temperature in kelvin"))?;
    rt_core::display::white_balance_matrix(k)
        .map(|_| k)
        .ok_or_else(|| format!("{s} K is outside 1667–25000 K"))
}

impl ViewArgs {
    pub fn view(&self) -> rt_core::output::View {
        rt_core::output::View {
            transform: match self.view {
                ViewArg::Standard => ViewTransform::Standard,
                ViewArg::Neutral => ViewTransform::KhronosPbrNeutral,
                ViewArg::Agx => ViewTransform::Agx,
            },
            exposure_stops: self.exposure,
            white_balance_k: self.white_balance,
        }
    }
}

/// `--view` values.
#[derive(clap::ValueEnum, Clone, Copy, Debug)]
pub enum ViewArg {
    Standard,
    #[value(alias = "khronos-pbr-neutral")]
    Neutral,
    Agx,
}

impl RenderArgs {
    fn view(&self) -> rt_core::output::View {
        self.display.view()
    }

    /// With --time-limit or --noise-target, the samples per pixel are only the most to take.
    /// The render passes `--aov` asks for.
    fn passes(&self) -> Option<&[rt_core::passes::Pass]> {
        self.aov.as_ref().map(|list| list.0.as_slice())
    }

    /// Alpha or passes asked for, here or by the scene's settings (a project saved transparent):
    /// the render keeps its first hits.
    fn wants_layers(&self, settings: &rt_core::RenderSettings) -> bool {
        self.transparent || settings.transparent || self.aov.is_some()
    }

    fn open_ended(&self) -> bool {
        self.time_limit.is_some() || self.noise_target.is_some()
    }
}

/// Renders the image, or with `--frames`/`--turntable` each frame in turn to OUT.NNNN.EXT.
pub fn run(args: RenderArgs, verbose: bool) -> Result<()> {
    let Some(frames) = args.animation.frames()? else {
        return render_image(args, verbose);
    };
    for frame in frames {
        let mut one = args.clone();
        one.output = crate::animation::numbered(&args.output, frame.number);
        one.scene.animation_time = Some(frame.time);
        one.scene.turntable_turns = frame.turns;
        eprintln!("frame:          {} (t = {:.3} s)", frame.number, frame.time);
        render_image(one, verbose).with_context(|| format!("frame {}", frame.number))?;
    }
    Ok(())
}

fn render_image(args: RenderArgs, verbose: bool) -> Result<()> {
    let (scene, range) = prepare_scene(&args)?;
    let both = args.engine.device == crate::options::DeviceArg::All;
    let (on_cpu, why) = match both {
        true if scene.settings.integrator == rt_core::Integrator::Bdpt => {
            args.engine.on_cpu_for(&scene.settings)?
        }
        true => (false, "--device all".to_string()),
        false => args.engine.on_cpu_for(&scene.settings)?,
    };
    let ctx = match on_cpu {
        true => None,
        false => Some(open_device(&args.engine.adapter)?),
    };
    let gpu_scene = GpuScene::build(&scene)?;
    let guides = args.denoise.is_some() || range.is_some() || args.wants_layers(&scene.settings);
    let mut run = match &ctx {
        None => {
            let first = range.map_or(0, |r| r[0]);
            Progressive::cpu(&scene, &gpu_scene, first, guides)?
        }
        Some(ctx) => {
            let max_buffer = max_accumulation_bytes(ctx);
            let options = shard_options(&args, &scene.settings, range);
            let (width, height) = (scene.settings.width, scene.settings.height);
            let bytes = rt_gpu::whole_image_binding_bytes(width, height, &options);
            if bytes > max_buffer {
                if both {
                    anyhow::bail!(
                        "a {width}x{height} image needs a {bytes}-byte buffer, more than this \
                         adapter's {max_buffer} per buffer: it renders in tiles, which --device \
                         all does not; render it with --device gpu or cpu"
                    );
                }
                if args.open_ended() {
                    anyhow::bail!(
                        "a {width}x{height} image needs a {bytes}-byte buffer (accumulation or \
                         denoiser guides), more than this adapter's {max_buffer} per buffer: it \
                         renders in tiles, one after another, which needs a fixed --spp rather \
                         than --time-limit or --noise-target"
                    );
                }
                return render_in_tiles(&args, &scene, ctx, &gpu_scene, max_buffer, range);
            }
            let renderer = Renderer::for_scene(ctx, &scene, &gpu_scene, options)?;
            if both {
                let first = range.map_or(0, |r| r[0]);
                let shared = BothDevices::new(renderer, &scene, &gpu_scene, first, guides)?;
                Progressive::Both(Box::new(shared))
            } else {
                Progressive::Gpu(Box::new(renderer))
            }
        }
    };
    let faults = rt_gpu::faults::Faults::from_test_env();
    let inject = |batches| {
        if let Some(ctx) = &ctx {
            faults.before_batch(ctx, batches);
        }
    };
    let finish = progress::render_progressively(&args, &mut run, &scene, range, inject)
        .map_err(|f| render_failed(&args, range, f.last_image, f.error))?;
    let image = run.read_image()?;
    let aovs = if guides { run.read_aovs()? } else { None };
    let scenes = (&scene, &gpu_scene);
    let rendered_by = match (&run, &ctx) {
        (Progressive::Gpu(renderer), Some(ctx)) => gpu_rendered_by(ctx, renderer.kernel()),
        (Progressive::Both(both), Some(ctx)) => format!(
            "{} and {}",
            gpu_rendered_by(ctx, both.gpu().kernel()),
            rt_gpu::progressive::cpu_label()
        ),
        _ => rt_gpu::progressive::cpu_label(),
    };
    save_output(&args, range, &rendered_by, scenes, &image, aovs.as_ref())?;
    match (&run, &ctx) {
        (Progressive::Gpu(renderer), Some(ctx)) => {
            eprintln!("device:         GPU ({why})");
            print_render_summary(ctx, renderer, scenes, &image, range, &finish, verbose);
        }
        _ => {
            let device = match (&run, &ctx) {
                (Progressive::Both(both), Some(ctx)) => {
                    let (cpu, gpu) = both.shares();
                    format!(
                        "GPU {} and {} ({why}; samples per pixel: GPU {gpu}, CPU {cpu})",
                        ctx.adapter_label(),
                        rt_gpu::progressive::cpu_label()
                    )
                }
                _ => format!("{} ({why})", rt_gpu::progressive::cpu_label()),
            };
            eprintln!("device:         {device}");
            eprintln!(
                "triangles:      {}",
                crate::summary::triangles_line(&gpu_scene)
            );
            let estimator = estimator_summary(&scene.settings, &gpu_scene);
            eprintln!("estimator:      {estimator}");
            print_image_summary(scenes, &image, range, &finish);
        }
    }
    if args.denoise.is_some() {
        save_denoised(&args, &image, aovs.as_ref())?;
    }
    eprintln!("saved:          {}", args.output.display());
    Ok(())
}

/// Saves `image` as the output, or for a shard (`range`) as a part for `rt-cli merge`, with its
/// `aovs` and a note of where its samples were rendered (`rendered_by`).
fn save_output(
    args: &RenderArgs,
    range: Option<[u32; 2]>,
    rendered_by: &str,
    scenes: (&Scene, &GpuScene),
    image: &rt_gpu::Image,
    aovs: Option<&rt_gpu::Aovs>,
) -> Result<()> {
    match range {
        Some([first, end]) => {
            let note = format!("samples {first}..{end}: {rendered_by}");
            let layers = part_layers(args, scenes.0);
            crate::shard::save(
                &args.output,
                [first, end],
                scenes,
                (image, aovs),
                layers,
                note,
            )
        }
        None if args.wants_layers(&scenes.0.settings) => {
            let aovs = aovs.context("the render kept no first hits")?;
            if let (Some(into), Some(window)) = (&args.into, scenes.0.settings.film_window) {
                let size = [image.width, image.height];
                let alpha = aovs.hits.alphas();
                let layers = (&image.pixels[..], &alpha[..]);
                return crate::region::compose_into_with_alpha(
                    into,
                    &args.output,
                    window,
                    size,
                    layers,
                    args.view(),
                );
            }
            let passes = args.passes();
            crate::layers::save(&args.output, image, aovs, scenes, passes, args.view())
        }
        None => save(args, image, scenes.0.settings.film_window),
    }
}

/// What a part carries for the merge to write the alpha and passes asked for.
fn part_layers(args: &RenderArgs, scene: &Scene) -> rt_core::part::Layers {
    use rt_core::passes::{Pass, material_ids};
    let passes = args.passes().unwrap_or(&[]);
    rt_core::part::Layers {
        transparent: scene.settings.transparent,
        passes: passes.iter().map(|p| p.name().to_string()).collect(),
        material_ids: if passes.contains(&Pass::Material) {
            material_ids(scene)
        } else {
            Vec::new()
        },
    }
}

/// The adapter and kernel a GPU render ran on, as a part's notes keep it.
fn gpu_rendered_by(ctx: &GpuContext, kernel: rt_gpu::Kernel) -> String {
    format!("{}, {} kernel", ctx.adapter_label(), kernel.name())
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
    // A shadow catcher shows the background through it: only a transparent film has one.
    settings.transparent |= args.transparent || !args.scene.shadow_catcher.is_empty();
    crate::layers::check(&args.output, settings.transparent, args.passes())?;
    if let Some(region) = args.region {
        crate::region::apply(settings, region)?;
    }
    let range = args.shard.range(settings.samples_per_pixel)?;
    if args.passes().is_some() && args.into.is_some() {
        anyhow::bail!("--into pastes colour and alpha only: leave out --aov");
    }
    if range.is_some() && args.into.is_some() {
        anyhow::bail!("--into pastes a finished image: render the shards, merge them, then paste");
    }
    if range.is_some() {
        crate::shard::check_options(&args.output, open_ended, args.denoise.is_some())?;
        if args
            .passes()
            .is_some_and(|p| p.contains(&rt_core::passes::Pass::Cryptomatte))
        {
            anyhow::bail!(
                "--aov cryptomatte traces the scene again when the image is saved, which a \
                 render part does not: render it without --shard (it takes only camera rays)"
            );
        }
    }
    // Check the camera and settings before opening the GPU, so mistakes are reported at once.
    rt_core::frame::validate(&scene)?;
    Ok((scene, range))
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
    let options = shard_options(args, settings, range);
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
    let rt_gpu::TiledRender { image, aovs } = rt_gpu::render_tiled(
        ctx,
        (scene, gpu_scene),
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
    let rendered_by = gpu_rendered_by(ctx, kernel);
    save_output(args, range, &rendered_by, scenes, &image, aovs.as_ref())?;
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
fn shard_options(
    args: &RenderArgs,
    settings: &rt_core::RenderSettings,
    range: Option<[u32; 2]>,
) -> rt_gpu::RenderOptions {
    let guides = args.denoise.is_some() || range.is_some() || args.wants_layers(settings);
    rt_gpu::RenderOptions {
        first_sample: range.map_or(0, |r| r[0]),
        ..args.engine.render_options(guides)
    }
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
    if args.into.is_some() {
        // A half-rendered window is not pasted over a finished image.
        return error.context("the render failed; nothing was pasted --into the image");
    }
    match save(args, &image, None) {
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
fn save(
    args: &RenderArgs,
    image: &rt_gpu::Image,
    window: Option<rt_core::scene::FilmWindow>,
) -> Result<()> {
    if let (Some(into), Some(window)) = (&args.into, window) {
        let size = [image.width, image.height];
        return crate::region::compose_into(
            into,
            &args.output,
            window,
            size,
            &image.pixels,
            args.view(),
        );
    }
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
