//! `rt-cli render --device cpu`: the native CPU backend (`rt_core::cpu_render`, the Rust twin of
//! the kernels on every core). It takes the same samples as the GPU, so its images and render
//! parts (`--shard`, `--sample-range`) are the GPU's up to rounding and merge with GPU parts; it
//! keeps the denoiser's guides, samples adaptively, and stops at a time limit or noise target as
//! the GPU path does. Flags that choose a GPU (`--adapter`, `--kernel`) are errors here.

use std::sync::atomic::AtomicBool;
use std::time::Instant;

use anyhow::{Result, bail};
use rt_core::cpu_render::CpuAccumulation;
use rt_core::{GpuScene, Scene};

use super::{RenderArgs, progress_bar, stop_rule};
use crate::summary::{Finish, estimator_summary, print_image_summary};

/// `--device` values.
#[derive(clap::ValueEnum, Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum DeviceArg {
    /// A hardware GPU when there is one, else the native CPU backend (software adapters such as
    /// lavapipe do not count); a GPU whenever --adapter or --kernel is given.
    Auto,
    /// A GPU through wgpu (lavapipe on a machine without one).
    #[default]
    Gpu,
    /// The native CPU backend: the estimator's Rust twin on every core.
    Cpu,
}

impl DeviceArg {
    /// The backend to run (`Gpu` or `Cpu`) and why, given whether GPU-only flags were passed.
    pub fn resolve(self, gpu_flags: bool) -> (DeviceArg, String) {
        match self {
            DeviceArg::Auto if gpu_flags => (
                DeviceArg::Gpu,
                "auto: --adapter or --kernel asks for a GPU".into(),
            ),
            DeviceArg::Auto => match rt_gpu::hardware_gpu() {
                Some(name) => (DeviceArg::Gpu, format!("auto: hardware GPU {name}")),
                None => (
                    DeviceArg::Cpu,
                    "auto: no hardware GPU (software adapters such as lavapipe do not count)"
                        .into(),
                ),
            },
            DeviceArg::Gpu => (DeviceArg::Gpu, "--device gpu".into()),
            DeviceArg::Cpu => (DeviceArg::Cpu, "--device cpu".into()),
        }
    }
}

/// Each batch should take about this long: short enough for the time limit and the progress
/// bar, long enough that the adaptive rule and the noise estimate between batches cost little.
const TARGET_BATCH_SECS: f64 = 0.25;

/// Renders `scene` (its settings applied) on the CPU and saves it, or for a shard (`range`) its
/// part.
pub fn run(args: &RenderArgs, scene: &Scene, range: Option<[u32; 2]>, why: &str) -> Result<()> {
    let gpu_flags: Vec<&str> = [
        (args.engine.kernel.is_some(), "--kernel"),
        (
            args.engine.adapter != rt_gpu::AdapterChoice::Auto,
            "--adapter",
        ),
    ]
    .into_iter()
    .filter_map(|(given, flag)| given.then_some(flag))
    .collect();
    if !gpu_flags.is_empty() {
        bail!(
            "{} choose{} how a GPU renders, and --device cpu renders without one: drop {}, or \
             render with --device gpu",
            gpu_flags.join(" and "),
            if gpu_flags.len() == 1 { "s" } else { "" },
            if gpu_flags.len() == 1 { "it" } else { "them" },
        );
    }
    let gpu_scene = GpuScene::build(scene)?;
    let frame = rt_core::frame::frame_for(scene, &gpu_scene)?;
    let [first, end] = range.unwrap_or([0, scene.settings.samples_per_pixel]);
    let adaptive = rt_core::adaptive::Adaptive::of_settings(&scene.settings);
    let guides = args.denoise.is_some() || range.is_some();
    let mut accumulation = CpuAccumulation::new(&frame, first, adaptive, guides);
    let threads = rt_core::cpu_render::threads();
    let spp = end - first;
    let bar = progress_bar(args.open_ended(), spp);
    let started = Instant::now();
    let never = AtomicBool::new(false);
    let mut stopped_by = "samples per pixel";
    let mut batch = 1;
    while accumulation.samples < spp && accumulation.active_pixels() > 0 {
        let batch_start = Instant::now();
        let count = batch.min(spp - accumulation.samples);
        accumulation.add_batch(&gpu_scene, &frame, count, &never);
        // Grow batches towards the target time; with a noise target, by at most 1/8 of the
        // samples so far, so the stop overshoots little (as on the GPU).
        let took = batch_start.elapsed().as_secs_f64();
        if took < TARGET_BATCH_SECS / 2.0 {
            batch *= 2;
        }
        if args.noise_target.is_some() {
            batch = batch.min((accumulation.samples / 8).max(1));
        }
        let noise = estimated_noise(&accumulation);
        let secs = started.elapsed().as_secs_f64().max(1e-9);
        let paths: f64 = accumulation.counts().iter().map(|&c| f64::from(c)).sum();
        bar.set_position(u64::from(accumulation.samples));
        bar.set_message(format!(
            "{:.2} Mpaths/s  noise ≈ {noise:.4}",
            paths / secs / 1e6
        ));
        if let Some(rule) = stop_rule(args, noise, secs) {
            stopped_by = rule;
            break;
        }
    }
    if accumulation.active_pixels() == 0 {
        stopped_by = "adaptive sampling: every pixel converged";
    }
    bar.finish_and_clear();
    let finish = Finish {
        render_time: started.elapsed(),
        stopped_by,
    };
    let image = rt_gpu::progressive::image_of(&accumulation);
    let aovs = accumulation.guides().map(|g| rt_gpu::Aovs {
        albedo: g.albedo.clone(),
        normal: g.normal.clone(),
        emission: g.emission.clone(),
    });
    match range {
        Some(range) => {
            let note = format!(
                "samples {}..{}: CPU (native, {threads} threads)",
                range[0], range[1]
            );
            let scenes = (scene, &gpu_scene);
            crate::shard::save(&args.output, range, scenes, &image, aovs.as_ref(), note)?;
        }
        None => super::save(args, &image)?,
    }
    eprintln!("device:         CPU (native backend, {threads} threads; {why})");
    eprintln!("triangles:      {}", gpu_scene.triangles.len());
    eprintln!(
        "estimator:      {}",
        estimator_summary(&scene.settings, &gpu_scene)
    );
    print_image_summary((scene, &gpu_scene), &image, range, &finish);
    if args.denoise.is_some() {
        super::save_denoised(args, &image, aovs.as_ref())?;
    }
    eprintln!("saved:          {}", args.output.display());
    Ok(())
}

/// The image's estimated noise (`rt_gpu::Image::estimated_noise`), without copying its sums.
fn estimated_noise(accumulation: &CpuAccumulation) -> f64 {
    let counts = accumulation.counts();
    rt_core::metrics::estimated_rel_mse(
        &accumulation.pixels(),
        rt_core::output::SampleCounts::PerPixel(&counts),
    )
    .sqrt()
}
