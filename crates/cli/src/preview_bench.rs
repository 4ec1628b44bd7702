//! `rt-cli bench --preview`: the raster preview (`rt_preview`, the editor's first view)
//! headless at the interactive view's size. Per scene: the first frame (pipelines, shadow maps,
//! the environment's prefiltering) and then a camera orbit of `ORBIT_FRAMES` frames, each timed
//! from building the frame to the GPU finishing it, against the path-traced view's slice budget
//! (what the preview must stay within to be as interactive).

use std::time::{Duration, Instant};

use anyhow::Result;
use rt_core::Scene;
use rt_gpu::GpuContext;
use rt_preview::{PreviewRenderer, build_frame};

use crate::interactive::{ms, orbit, percentile};

const ORBIT_FRAMES: u32 = 60;

fn frame_of(scene: &Scene, size: [u32; 2]) -> rt_preview::PreviewFrame {
    build_frame(scene, &scene.camera, scene.bounds(), None, size)
}

pub fn run(ctx: &GpuContext, scenes: Vec<(String, Scene)>, size: [u32; 2]) -> Result<()> {
    let budget = rt_gpu::live::LiveSettings::default().budget;
    println!(
        "raster preview, {}x{}, adapter {}; the path-traced view's slice budget is {:.0} ms",
        size[0],
        size[1],
        ctx.adapter_label(),
        ms(budget)
    );
    for (name, scene) in scenes {
        let mut renderer = PreviewRenderer::new(&ctx.device, &ctx.queue);
        let started = Instant::now();
        renderer.draw_and_wait(ctx, &frame_of(&scene, size))?;
        let first = started.elapsed();
        let mut frames: Vec<Duration> = Vec::new();
        for k in 1..=ORBIT_FRAMES {
            let moved = orbit(&scene, 2.0 * k as f32);
            let started = Instant::now();
            renderer.draw_and_wait(ctx, &frame_of(&moved, size))?;
            frames.push(started.elapsed());
        }
        println!(
            "{name:<14} {:>8} triangles: first frame {:.0} ms; orbiting {} frames: median {:.1} \
             ms, p95 {:.1} ms, max {:.1} ms",
            scene.triangle_count(),
            ms(first),
            frames.len(),
            ms(percentile(&frames, 0.5)),
            ms(percentile(&frames, 0.95)),
            ms(percentile(&frames, 1.0)),
        );
    }
    Ok(())
}
