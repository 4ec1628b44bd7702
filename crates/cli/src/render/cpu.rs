//! `rt-cli render --device cpu`: the native CPU backend (`rt_core::cpu_render`, the Rust twin of
//! the kernels on every core). It takes the same samples as the GPU, so its images and render
//! parts (`--shard`, `--sample-range`) are the GPU's up to rounding and merge with GPU parts; it
//! keeps the denoiser's guides, samples adaptively, and stops at a time limit or noise target as
//! the GPU path does; `rt_gpu::progressive` sizes its batches.

use std::sync::atomic::AtomicBool;
use std::time::Instant;

use anyhow::Result;
use rt_core::{GpuScene, Scene};
use rt_gpu::progressive::Progressive;

use super::{RenderArgs, progress_bar, stop_rule};
use crate::summary::{Finish, estimator_summary, print_image_summary};

/// Renders `scene` (its settings applied) on the CPU and saves it, or for a shard (`range`) its
/// part.
pub fn run(args: &RenderArgs, scene: &Scene, range: Option<[u32; 2]>, why: &str) -> Result<()> {
    let gpu_scene = GpuScene::build(scene)?;
    let [first, end] = range.unwrap_or([0, scene.settings.samples_per_pixel]);
    let guides = args.denoise.is_some() || range.is_some();
    let mut renderer = Progressive::cpu(scene, &gpu_scene, first, guides)?;
    let threads = rt_core::cpu_render::threads();
    let spp = end - first;
    let bar = progress_bar(args.open_ended(), spp);
    let started = Instant::now();
    let pixels = f64::from(scene.settings.width) * f64::from(scene.settings.height);
    let never = AtomicBool::new(false);
    let mut stopped_by = "samples per pixel";
    while renderer.samples_done() < spp && renderer.active_pixels() > 0 {
        let done = renderer.samples_done();
        // With a noise target, at most 1/8 of the samples so far at a time, so the stop
        // overshoots little (as on the GPU); the backend sizes batches to its time otherwise.
        let most = match args.noise_target {
            Some(_) => (done / 8).max(1),
            None => spp - done,
        };
        renderer.render_batch(most.min(spp - done), &never)?;
        let noise = renderer.estimated_noise()?;
        let secs = started.elapsed().as_secs_f64().max(1e-9);
        let done = renderer.samples_done();
        bar.set_position(u64::from(done));
        bar.set_message(format!(
            "{:.2} Mpaths/s  noise ≈ {noise:.4}",
            pixels * f64::from(done) / secs / 1e6
        ));
        if let Some(rule) = stop_rule(args, noise, secs) {
            stopped_by = rule;
            break;
        }
    }
    if renderer.active_pixels() == 0 {
        stopped_by = "adaptive sampling: every pixel converged";
    }
    bar.finish_and_clear();
    let finish = Finish {
        render_time: started.elapsed(),
        stopped_by,
    };
    let image = renderer.read_image()?;
    let aovs = renderer.read_aovs()?;
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
