//! `rt-cli render`: a progressive render with a progress bar, saved when done (or when stopped).

use std::path::PathBuf;
use std::time::Instant;

use anyhow::{Context, Result};
use clap::Args;
use indicatif::{ProgressBar, ProgressStyle};
use rt_core::GpuScene;
use rt_gpu::{AdapterChoice, GpuContext, RenderOptions, Renderer};

use crate::scene_args::SceneArgs;

#[derive(Args, Debug)]
pub struct RenderArgs {
    #[command(flatten)]
    scene: SceneArgs,
    /// Output image: .png, .jpg, .ppm (sRGB, clamped) or .exr (linear float).
    #[arg(short, long, default_value = "render.png")]
    output: PathBuf,
    #[arg(long)]
    width: Option<u32>,
    #[arg(long)]
    height: Option<u32>,
    /// Samples per pixel.
    #[arg(long, default_value_t = 64)]
    spp: u32,
    /// Ray segments per path (1: emitters only, 2: direct light, ...).
    #[arg(long)]
    max_depth: Option<u32>,
    /// Exposure in stops for 8-bit outputs (EXR is always linear).
    #[arg(long, default_value_t = 0.0, allow_hyphen_values = true)]
    exposure: f32,
    /// Turn off next-event estimation (sample only the BSDF; noisier, for comparisons).
    #[arg(long)]
    no_nee: bool,
    /// Turn off Russian roulette (every path runs to max depth unless it is absorbed or escapes).
    #[arg(long)]
    no_roulette: bool,
    /// GPU adapter: auto, cpu (lavapipe), or part of an adapter's name.
    #[arg(long, default_value = "auto")]
    adapter: AdapterChoice,
}

pub fn run(args: RenderArgs, verbose: bool) -> Result<()> {
    rt_core::output::ImageFormat::from_path(&args.output)?;
    let mut scene = args.scene.load()?;
    let settings = &mut scene.settings;
    settings.width = args.width.unwrap_or(settings.width);
    settings.height = args.height.unwrap_or(settings.height);
    settings.samples_per_pixel = args.spp;
    settings.max_depth = args.max_depth.unwrap_or(settings.max_depth);
    settings.next_event_estimation = !args.no_nee;
    settings.russian_roulette = !args.no_roulette;
    // Check the camera and settings before opening the GPU, so mistakes are reported at once.
    rt_core::frame::validate(&scene)?;

    let ctx = GpuContext::new(&args.adapter)?;
    let gpu_scene = GpuScene::build(&scene)?;
    let mut renderer = Renderer::for_scene(&ctx, &scene, &gpu_scene, RenderOptions::default())?;

    let bar = ProgressBar::new(u64::from(args.spp));
    bar.set_style(
        ProgressStyle::with_template(
            "{spinner} [{elapsed_precise}] {bar:40} {pos}/{len} spp  {msg} (eta {eta})",
        )
        .unwrap_or_else(|_| ProgressStyle::default_bar()),
    );
    let started = Instant::now();
    let pixels = u64::from(scene.settings.width) * u64::from(scene.settings.height);
    renderer.render(args.spp, |done| {
        let secs = started.elapsed().as_secs_f64().max(1e-9);
        bar.set_position(u64::from(done));
        bar.set_message(format!(
            "{:.2} Mpaths/s",
            pixels as f64 * f64::from(done) / secs / 1e6
        ));
        true
    })?;
    bar.finish_and_clear();
    let render_time = started.elapsed();
    let image = renderer.read_image()?;
    rt_core::output::save_image(
        &args.output,
        image.width,
        image.height,
        &image.rgb(),
        args.exposure,
    )
    .with_context(|| format!("saving {}", args.output.display()))?;

    let secs = render_time.as_secs_f64().max(1e-9);
    let paths = pixels as f64 * f64::from(image.samples_per_pixel);
    eprintln!("adapter:        {}", ctx.adapter_label());
    eprintln!("triangles:      {}", gpu_scene.triangles.len());
    eprintln!(
        "BVH build:      {:.2?} (depth {})",
        gpu_scene.bvh_build_time, gpu_scene.bvh_depth
    );
    eprintln!(
        "image:          {}x{}, {} spp, max depth {}, next-event estimation {}",
        image.width,
        image.height,
        image.samples_per_pixel,
        scene.settings.max_depth,
        if gpu_scene.features.nee { "on" } else { "off" }
    );
    eprintln!("render time:    {render_time:.2?}");
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
    eprintln!("saved:          {}", args.output.display());
    Ok(())
}
