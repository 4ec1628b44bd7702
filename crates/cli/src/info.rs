//! `rt-cli info`: what a scene contains.

use anyhow::Result;
use clap::Args;

use crate::scene_args::SceneArgs;

#[derive(Args, Debug)]
pub struct InfoArgs {
    #[command(flatten)]
    scene: SceneArgs,
    /// With -v: also the adapter (and driver) that `render` would use.
    #[arg(long, default_value = "auto")]
    adapter: rt_gpu::AdapterChoice,
}

pub fn run(args: InfoArgs, verbose: bool) -> Result<()> {
    let started = std::time::Instant::now();
    let scene = args.scene.load()?;
    let load_time = started.elapsed();
    println!("objects: {}", scene.objects.len());
    for o in &scene.objects {
        println!(
            "  {:<24} {:>8} triangles  {:<22} {:?}{}",
            o.name,
            o.mesh.indices.len(),
            o.material.kind_name(),
            o.material,
            if o.shadow_catcher {
                "  (shadow catcher)"
            } else {
                ""
            }
        );
    }
    println!("textures: {}", scene.textures.len());
    for t in &scene.textures {
        let s = t.sampler;
        let sampler = if s == rt_core::TextureSampler::default() {
            String::new()
        } else {
            format!(", wrap {:?}/{:?}, {:?}", s.wrap_s, s.wrap_t, s.filter)
        };
        println!("  {} ({}x{}{sampler})", t.name, t.width, t.height);
    }
    println!("triangles: {}", scene.triangle_count());
    match scene.bounds() {
        Some((lo, hi)) => println!("bounds: min {lo} max {hi}"),
        None => println!("bounds: empty scene"),
    }
    let c = &scene.camera;
    let projection = match c.projection {
        rt_core::camera::Projection::Perspective => format!("vfov {}°", c.vfov_deg),
        rt_core::camera::Projection::Orthographic => {
            format!("orthographic, {} high", c.ortho_height_in(scene.bounds()))
        }
        rt_core::camera::Projection::Panorama => "panorama (equirectangular)".into(),
        rt_core::camera::Projection::Fisheye => format!("fisheye {}°", c.fisheye_angle_deg),
    };
    println!(
        "camera: from {:?} to {:?} up {:?} {projection}",
        c.from, c.to, c.up
    );
    println!("ambient: {:?}", scene.ambient);
    match &scene.environment {
        Some(e) => println!(
            "environment: {} ({}x{}, rotation {}°, strength {})",
            e.source, e.map.width, e.map.height, e.rotation_deg, e.strength
        ),
        None => println!("environment: none"),
    }
    if scene.fog.is_on() {
        let f = &scene.fog;
        println!(
            "fog: density {} (mean free path {:.3}), albedo {:?}, anisotropy {}",
            f.density,
            1.0 / f.density,
            f.albedo,
            f.anisotropy
        );
    }
    println!("lights: {}", scene.lights.len());
    if let Some(animation) = &scene.animation {
        let times = animation.channels.iter().flat_map(|c| &c.times);
        let end = times.fold(0.0f32, |end, t| end.max(*t));
        let nodes = (animation.channels.iter().map(|c| c.node))
            .collect::<std::collections::BTreeSet<_>>()
            .len();
        let count = |n: usize, what: &str| format!("{n} {what}{}", if n == 1 { "" } else { "s" });
        println!(
            "animation: {} moving {}, 0 to {end:.3} s (render --frames)",
            count(animation.channels.len(), "channel"),
            count(nodes, "node")
        );
    }
    if verbose {
        // Where loading time goes: parsing the file, then flattening and the BVH build.
        let built = std::time::Instant::now();
        let gpu_scene = rt_core::GpuScene::build(&scene)?;
        println!(
            "load: {load_time:.2?} reading the file; {:.2?} building the GPU scene, of which {:.2?} the BVH",
            built.elapsed(),
            gpu_scene.bvh_build_time
        );
        // The adapter is opened only on request: it takes a second on lavapipe.
        match crate::options::open_device(&args.adapter) {
            Ok(ctx) => println!("adapter: {} (render --device gpu)", ctx.adapter_label()),
            Err(e) => println!("adapter: none ({e})"),
        }
        println!(
            "cpu backend: native, {} threads (render --device cpu)",
            rt_core::cpu_render::threads()
        );
    }
    Ok(())
}
