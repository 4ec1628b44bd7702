//! `rt-cli converge`: renders at 1, 2, 4, … samples per pixel and measures each image against a
//! reference, so that the speed/accuracy trade of each setting can be plotted.
//!
//! Time is what a user waits for that image: BVH build plus GPU render time, without the readbacks
//! and comparisons the measurement itself adds.

use std::path::PathBuf;
use std::time::{Duration, Instant};

use anyhow::{Context, Result};
use clap::Args;
use rt_core::GpuScene;
use rt_core::metrics::{RgbImage, compare};
use rt_gpu::Renderer;

use crate::options::{BvhArgs, EngineArgs, EstimatorArgs, open_device};
use crate::plot;
use crate::scene_args::SceneArgs;
use crate::series::{Row, append_csv, read_csv};
use rt_gpu::progressive::Progressive;

#[derive(Args, Debug)]
pub struct ConvergeArgs {
    #[command(flatten)]
    scene: SceneArgs,
    /// Reference image (EXR); box-downsampled when it is an integer multiple of the render size.
    #[arg(long)]
    reference: PathBuf,
    /// Largest sample count (a power of two is reached exactly; steps double from 1).
    #[arg(long, default_value_t = 256)]
    max_spp: u32,
    #[command(flatten)]
    estimator: EstimatorArgs,
    /// Measure the denoised image at each step (the denoising time counts):
    /// `--denoise[=auto|oidn|atrous]`, as `render --denoise`.
    #[arg(long, value_enum, num_args = 0..=1, require_equals = true, default_missing_value = "auto", value_name = "DENOISER")]
    denoise: Option<crate::options::DenoiseArg>,
    #[command(flatten)]
    bvh: BvhArgs,
    #[command(flatten)]
    engine: EngineArgs,
    /// Name of this series in the CSV and the plot (default: from the settings).
    #[arg(long)]
    label: Option<String>,
    /// Append the rows to this CSV file (created with a header when missing).
    #[arg(long)]
    csv: Option<PathBuf>,
    /// Write an SVG plot of relMSE against time of every series in the CSV.
    #[arg(long)]
    plot: Option<PathBuf>,
}

pub fn run(args: ConvergeArgs) -> Result<()> {
    let mut scene = args.scene.load()?;
    args.estimator.apply(&mut scene.settings);
    scene.settings.samples_per_pixel = args.max_spp.max(1);
    rt_core::frame::validate(&scene)?;
    let reference = RgbImage::load(&args.reference)?;
    let label = args
        .label
        .clone()
        .unwrap_or_else(|| default_label(&args, &scene));

    let ctx = match args.engine.on_cpu_for(&scene.settings)?.0 {
        true => None,
        false => Some(open_device(&args.engine.adapter)?),
    };
    let start = Instant::now();
    let (quality, layout) = (args.bvh.bvh_quality.into(), args.bvh.bvh.into());
    let gpu_scene = GpuScene::build_with_layout(&scene, quality, layout)?;
    let bvh = start.elapsed();
    let guides = args.denoise.is_some();
    let (mut renderer, on) = match &ctx {
        Some(ctx) => {
            let options = args.engine.render_options(guides);
            // The first dispatch includes compiling the kernel; a warm-up sample keeps that out
            // of the curve (it is a one-off per feature set, cached afterwards).
            {
                let mut warm = Renderer::for_scene(ctx, &scene, &gpu_scene, options)?;
                warm.render_batch(1)?;
                warm.read_image()?;
            }
            let renderer = Renderer::for_scene(ctx, &scene, &gpu_scene, options)?;
            (Progressive::Gpu(Box::new(renderer)), ctx.adapter_label())
        }
        None => (
            Progressive::cpu(&scene, &gpu_scene, 0, guides)?,
            rt_gpu::progressive::cpu_label(),
        ),
    };
    eprintln!(
        "{label}: {}x{}, up to {} spp on {on}",
        scene.settings.width, scene.settings.height, args.max_spp,
    );
    println!(
        "{:>7} {:>10} {:>12} {:>12} {:>8}",
        "spp", "seconds", "relMSE", "RMSE", "mean"
    );
    let mut rows = Vec::new();
    let mut rendering = Duration::ZERO;
    let mut step = 1u32;
    loop {
        let step_start = Instant::now();
        // Adaptive sampling may stop every pixel before `step`.
        renderer.render(step)?;
        // render_batch waits for its dispatches, so this is GPU time as the user sees it.
        rendering += step_start.elapsed();
        let (measured, denoise_time) = read_measured(&renderer, args.denoise)?;
        let e = compare(&measured, &reference)
            .map_err(anyhow::Error::msg)
            .with_context(|| format!("comparing with {}", args.reference.display()))?;
        let row = Row {
            label: label.clone(),
            spp: step,
            seconds: (bvh + rendering + denoise_time).as_secs_f64(),
            rel_mse: e.rel_mse,
            rmse: e.rmse,
            mean_ratio: e.mean_ratio,
            bvh_ms: bvh.as_secs_f64() * 1e3,
        };
        println!(
            "{:>7} {:>10.3} {:>12.4e} {:>12.4e} {:>8.4}",
            row.spp,
            row.seconds,
            row.rel_mse,
            row.rmse,
            (row.mean_ratio[0] + row.mean_ratio[1] + row.mean_ratio[2]) / 3.0
        );
        rows.push(row);
        if step >= args.max_spp {
            break;
        }
        step = (step * 2).min(args.max_spp);
    }
    if let Some(path) = &args.csv {
        append_csv(path, &rows)?;
    }
    if let Some(out) = &args.plot {
        let all = match &args.csv {
            Some(csv) => read_csv(csv)?,
            None => rows,
        };
        plot::save_svg(&all, out)?;
        eprintln!("plot: {}", out.display());
    }
    Ok(())
}

/// The image a step measures, denoised with `denoise` where asked, and the time the denoiser took
/// (the user waits for it too, but only for the image they keep: it does not accumulate).
fn read_measured(
    renderer: &Progressive,
    denoise: Option<crate::options::DenoiseArg>,
) -> Result<(RgbImage, Duration)> {
    let image = renderer.read_image()?;
    let (pixels, took) = if let Some(denoiser) = denoise {
        let aovs = renderer
            .read_aovs()?
            .context("the renderer did not keep albedo and normals")?;
        let started = Instant::now();
        let denoised = image
            .denoised(&aovs, denoiser.choice())
            .map_err(anyhow::Error::msg)?;
        (denoised.pixels, started.elapsed())
    } else {
        (image.rgb(), Duration::ZERO)
    };
    let measured = RgbImage {
        width: image.width,
        height: image.height,
        pixels,
    };
    Ok((measured, took))
}

/// A series' name from its settings: the estimator, roulette, clamp, sampler, light sampler,
/// denoiser, depth and BVH quality.
fn default_label(args: &ConvergeArgs, scene: &rt_core::Scene) -> String {
    format!(
        "{}{}{}depth {} {:?}",
        if scene.settings.integrator == rt_core::Integrator::Bdpt {
            "BDPT, "
        } else if args.estimator.no_nee {
            "BSDF only, "
        } else if args.estimator.nee_only {
            "NEE only, "
        } else {
            "NEE+MIS, "
        },
        if args.estimator.no_roulette {
            "no roulette, "
        } else {
            ""
        },
        scene
            .settings
            .clamp
            .map_or(String::new(), |c| format!("clamp {c}, "))
            + if scene.settings.sampler == rt_core::math::rng::SamplerKind::Sobol {
                "Sobol, "
            } else {
                "independent, "
            }
            + match scene.settings.light_sampler {
                rt_core::LightSampler::Auto => "",
                rt_core::LightSampler::Power => "lights by power, ",
                rt_core::LightSampler::Tree => "light tree, ",
            }
            + &args
                .denoise
                .map_or(String::new(), |d| format!("denoised ({}), ", d.name())),
        scene.settings.max_depth,
        args.bvh.bvh_quality
    )
}
