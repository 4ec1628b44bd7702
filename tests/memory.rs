#![allow(clippy::unwrap_used)]
//! Host memory during long renders. Mesa 22.3's lavapipe keeps memory for every path the compiled
//! megakernel runs (about 75 MB/s on a 128 x 128 Cornell box render on a 2-core VM) and frees it
//! only when that pipeline is destroyed, so `Renderer` can rebuild its pipeline on CPU adapters
//! every `Tuning::pipeline_rebuilds`; the wavefront kernels (the default) do not grow. Its own test binary with one test: resident memory is per
//! process, and other tests running alongside would move it. (That a rebuild changes no sample is
//! `tests/extremes/renderer.rs::rebuilding_the_pipeline_changes_no_sample`.)

mod common;

use std::time::{Duration, Instant};

use common::*;
use rt_core::GpuScene;
use rt_gpu::{RenderOptions, Renderer};

fn resident_mb() -> Option<f64> {
    let status = std::fs::read_to_string("/proc/self/status").ok()?;
    let line = status.lines().find(|l| l.starts_with("VmRSS:"))?;
    let kb: f64 = line.split_whitespace().nth(1)?.parse().ok()?;
    Some(kb / 1024.0)
}

fn cornell(size: u32, spp: u32) -> (rt_core::Scene, GpuScene) {
    let mut scene = rt_io::assets::cornell_box().unwrap();
    scene.settings.width = size;
    scene.settings.height = size;
    scene.settings.samples_per_pixel = spp;
    let gpu_scene = GpuScene::build(&scene).unwrap();
    (scene, gpu_scene)
}

/// Resident memory growth over four seconds of rendering after the first, and the rebuilds.
fn growth(ctx: &rt_gpu::GpuContext, options: RenderOptions) -> (f64, u32) {
    let (scene, gpu_scene) = cornell(128, u32::MAX);
    let mut renderer = Renderer::for_scene(ctx, &scene, &gpu_scene, options).unwrap();
    let started = Instant::now();
    let mut baseline = None;
    let mut peak = 0.0f64;
    while started.elapsed() < Duration::from_secs(5) {
        renderer.render_batch(u32::MAX).unwrap();
        let now = resident_mb().unwrap();
        if started.elapsed() >= Duration::from_secs(1) {
            let base = *baseline.get_or_insert(now);
            peak = peak.max(now - base);
        }
    }
    eprintln!(
        "{:?}: {} samples, {} pipeline rebuilds, peak growth {peak:.0} MB",
        options.kernel,
        renderer.samples_done(),
        renderer.pipeline_rebuilds()
    );
    (peak, renderer.pipeline_rebuilds())
}

/// The wavefront kernels (the default) need no rebuilds: four seconds of rendering leave resident
/// memory within 100 MB of where it was after the first second. The megakernel grows (~300 MB in
/// those four seconds here without rebuilds: set its lifetime to `None` to see it), and with its
/// pipeline rebuilt every 0.3 s it stays within the same 100 MB. (A GPU is not measured.)
#[test]
fn long_renders_keep_host_memory_flat() {
    let Some(ctx) = gpu() else { return };
    if ctx.info.device_type != wgpu::DeviceType::Cpu {
        eprintln!("SKIPPED: measures lavapipe's memory; this adapter is a GPU");
        return;
    }
    let Some(_) = resident_mb() else {
        eprintln!("SKIPPED: no /proc/self/status to read resident memory from");
        return;
    };
    let (peak, rebuilds) = growth(ctx, RenderOptions::default());
    assert_eq!(rebuilds, 0);
    assert!(
        peak < 100.0,
        "wavefront kernels: resident memory grew {peak:.0} MB in 4 s of rendering"
    );
    let (peak, rebuilds) = growth(
        ctx,
        RenderOptions {
            kernel: rt_gpu::Kernel::Megakernel,
            tuning: rt_gpu::Tuning {
                pipeline_rebuilds: rt_gpu::PipelineRebuilds::Every(Duration::from_millis(300)),
                ..Default::default()
            },
            ..Default::default()
        },
    );
    assert!(
        rebuilds >= 2,
        "the megakernel's pipeline was rebuilt only {rebuilds} times"
    );
    assert!(
        peak < 100.0,
        "megakernel with rebuilds: resident memory grew {peak:.0} MB in 4 s of rendering"
    );
}
