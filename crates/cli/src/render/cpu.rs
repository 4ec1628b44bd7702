//! `rt-cli render --device cpu`: the native CPU backend (`rt_core::cpu_render`, the Rust twin of
//! the kernels on every core). It takes the same samples as the GPU, so its images and render
//! parts (`--shard`, `--sample-range`) are the GPU's up to rounding and merge with GPU parts. What
//! it does not do yet (adaptive sampling, `--time-limit`, `--noise-target`, `--denoise`) is an
//! error that says so, rather than being ignored.

use std::sync::atomic::AtomicBool;
use std::time::Instant;

use anyhow::{Result, bail};
use indicatif::{ProgressBar, ProgressStyle};
use rt_core::cpu_render::CpuAccumulation;
use rt_core::{GpuScene, Scene};

use super::RenderArgs;

/// `--device` values.
#[derive(clap::ValueEnum, Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum DeviceArg {
    /// A GPU through wgpu (lavapipe on a machine without one).
    #[default]
    Gpu,
    /// The native CPU backend: the estimator's Rust twin on every core.
    Cpu,
}

/// The flags the CPU backend cannot honour yet, named for the error.
fn unsupported(args: &RenderArgs, scene: &Scene) -> Vec<&'static str> {
    let mut out = Vec::new();
    if args.engine.kernel.is_some() {
        out.push("--kernel (the GPU's kernels)");
    }
    if args.engine.adapter != rt_gpu::AdapterChoice::Auto {
        out.push("--adapter (which GPU renders; --device cpu uses no GPU)");
    }
    if args.time_limit.is_some() {
        out.push("--time-limit");
    }
    if args.noise_target.is_some() {
        out.push("--noise-target");
    }
    if scene.settings.adaptive_threshold.is_some() {
        out.push("adaptive sampling (--adaptive or the scene's setting)");
    }
    if args.denoise.is_some() {
        out.push("--denoise");
    }
    out
}

/// Renders `scene` (its settings applied) on the CPU and saves it, or for a shard (`range`) its
/// part.
pub fn run(args: &RenderArgs, scene: &Scene, range: Option<[u32; 2]>) -> Result<()> {
    let missing = unsupported(args, scene);
    if !missing.is_empty() {
        bail!(
            "--device cpu does not support {} yet; render with --device gpu for that",
            missing.join(", ")
        );
    }
    let gpu_scene = GpuScene::build(scene)?;
    let frame = rt_core::frame::frame_for(scene, &gpu_scene)?;
    let [first, end] = range.unwrap_or([0, scene.settings.samples_per_pixel]);
    let threads = rt_core::cpu_render::threads();
    eprintln!("device:         CPU (native, {threads} threads)");
    eprintln!("triangles:      {}", gpu_scene.triangles.len());
    eprintln!(
        "estimator:      {}",
        crate::summary::estimator_summary(&scene.settings, &gpu_scene)
    );
    let bar = ProgressBar::new(u64::from(end - first));
    bar.set_style(
        ProgressStyle::with_template("{bar:40} {pos}/{len} spp  {elapsed} (eta {eta})")
            .expect("a valid template"),
    );
    let start = Instant::now();
    let mut accumulation = CpuAccumulation::new(&frame, first);
    let never = AtomicBool::new(false);
    while accumulation.samples < end - first {
        accumulation.add_batch(&gpu_scene, &frame, 1, &never);
        bar.set_position(u64::from(accumulation.samples));
    }
    bar.finish_and_clear();
    let secs = start.elapsed().as_secs_f64().max(1e-9);
    let image = rt_gpu::Image {
        width: accumulation.width,
        height: accumulation.height,
        samples_per_pixel: accumulation.samples,
        sample_counts: None,
        pixels: accumulation.pixels(),
        sums: accumulation.sums,
    };
    let paths =
        f64::from(image.width) * f64::from(image.height) * f64::from(image.samples_per_pixel);
    eprintln!(
        "rendered:       {} spp in {secs:.2} s ({:.2} M paths/s)",
        image.samples_per_pixel,
        paths / secs / 1e6
    );
    eprintln!("noise:          {:.4} (estimated)", image.estimated_noise());
    match range {
        Some(range) => {
            let note = format!(
                "samples {}..{}: CPU (native, {threads} threads)",
                range[0], range[1]
            );
            crate::shard::save(&args.output, range, (scene, &gpu_scene), &image, None, note)?;
        }
        None => super::save(args, &image)?,
    }
    eprintln!("saved:          {}", args.output.display());
    Ok(())
}
