//! `rt-cli bench`: fixed scenes at fixed settings; BVH build time, paths/s and rays/s. Not a test.

use std::path::{Path, PathBuf};
use std::time::Instant;

use anyhow::Result;
use clap::Args;
use rt_core::bvh::BvhQuality;
use rt_core::{GpuScene, Scene};
use rt_gpu::{AdapterChoice, GpuContext, RenderOptions, Renderer};
use serde::Serialize;

#[derive(Args, Debug)]
pub struct BenchArgs {
    /// Folder with the large benchmark meshes (`stanford-bunny/`, `stanford-dragon/`); scenes whose
    /// files are missing are skipped with a message.
    #[arg(long, default_value = "../shared/models")]
    models: PathBuf,
    #[arg(long, default_value = "auto")]
    adapter: AdapterChoice,
    #[arg(long, default_value_t = 512)]
    size: u32,
    #[arg(long, default_value_t = 16)]
    spp: u32,
    /// Benchmark BSDF sampling only (next-event estimation off).
    #[arg(long)]
    no_nee: bool,
}

#[derive(Serialize)]
struct Record {
    scene: String,
    adapter: String,
    triangles: usize,
    /// obvhs build alone.
    bvh_build_ms: f64,
    /// Flattening, transforms, BVH and packing: everything before upload.
    scene_build_ms: f64,
    bvh_depth: usize,
    width: u32,
    height: u32,
    spp: u32,
    max_depth: u32,
    next_event_estimation: bool,
    render_s: f64,
    paths_per_s: f64,
    rays_per_s: f64,
    gpu_scene_bytes: u64,
}

fn mesh_scene(path: &Path) -> Result<Scene> {
    let mut scene = rt_core::io::obj::load_obj(path, 0)?;
    let (lo, hi) = scene.bounds().unwrap_or_default();
    let center = (lo + hi) * 0.5;
    let radius = (hi - lo).length() * 0.5;
    scene.camera.to = center.to_array();
    scene.camera.from =
        (center + glam::Vec3::new(0.3, 0.2, 1.0).normalize() * radius * 2.6).to_array();
    scene.camera.vfov_deg = 45.0;
    scene.ambient = [1.0; 3];
    scene.settings.max_depth = 8;
    Ok(scene)
}

pub fn run(args: BenchArgs) -> Result<()> {
    let ctx = GpuContext::new(&args.adapter)?;
    let mut suite: Vec<(String, Result<Scene>)> = vec![(
        "cornell".into(),
        rt_core::assets::cornell_box().map_err(Into::into),
    )];
    for (name, file) in [
        ("bunny-69k", "stanford-bunny/stanford-bunny.obj"),
        ("dragon-202k", "stanford-dragon/dragon_vrip_res2.obj"),
        ("dragon-871k", "stanford-dragon/dragon_vrip.obj"),
    ] {
        let path = args.models.join(file);
        if path.exists() {
            suite.push((name.into(), mesh_scene(&path)));
        } else {
            eprintln!(
                "skipping {name}: {} not found (pass --models DIR)",
                path.display()
            );
        }
    }
    println!(
        "{:<12} {:>9} {:>9} {:>9} {:>6} {:>9} {:>9} {:>9} {:>9}",
        "scene",
        "triangles",
        "BVH ms",
        "build ms",
        "depth",
        "GPU MB",
        "render s",
        "Mpaths/s",
        "Mrays/s"
    );
    let mut records = Vec::new();
    for (name, scene) in suite {
        let mut scene = scene?;
        scene.settings.width = args.size;
        scene.settings.height = args.size;
        scene.settings.next_event_estimation = !args.no_nee;
        let build_started = Instant::now();
        let gpu_scene = GpuScene::build_with(&scene, BvhQuality::Medium)?;
        let build_ms = build_started.elapsed().as_secs_f64() * 1e3;
        let options = RenderOptions {
            count_rays: true,
            ..Default::default()
        };
        // Warm-up: compiles the pipeline and settles the dispatch size.
        let mut warm = Renderer::for_scene(&ctx, &scene, &gpu_scene, options)?;
        warm.render(2, |_| true)?;
        let mut renderer = Renderer::for_scene(&ctx, &scene, &gpu_scene, options)?;
        let started = Instant::now();
        renderer.render(args.spp, |_| true)?;
        let secs = started.elapsed().as_secs_f64();
        let paths = f64::from(args.size) * f64::from(args.size) * f64::from(args.spp);
        let record = Record {
            scene: name,
            adapter: ctx.adapter_label(),
            triangles: gpu_scene.triangles.len(),
            bvh_build_ms: gpu_scene.bvh_build_time.as_secs_f64() * 1e3,
            scene_build_ms: build_ms,
            bvh_depth: gpu_scene.bvh_depth,
            width: args.size,
            height: args.size,
            spp: args.spp,
            max_depth: scene.settings.max_depth,
            next_event_estimation: gpu_scene.features.nee,
            render_s: secs,
            paths_per_s: paths / secs,
            rays_per_s: renderer.rays_traced() as f64 / secs,
            gpu_scene_bytes: gpu_scene.buffer_sizes().iter().map(|(_, b)| b).sum(),
        };
        println!(
            "{:<12} {:>9} {:>9.1} {:>9.1} {:>6} {:>9.1} {:>9.2} {:>9.3} {:>9.3}",
            record.scene,
            record.triangles,
            record.bvh_build_ms,
            record.scene_build_ms,
            record.bvh_depth,
            record.gpu_scene_bytes as f64 / 1e6,
            record.render_s,
            record.paths_per_s / 1e6,
            record.rays_per_s / 1e6
        );
        records.push(record);
    }
    for r in &records {
        println!("{}", serde_json::to_string(r)?);
    }
    Ok(())
}
