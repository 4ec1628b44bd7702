//! `rt-cli bench`: fixed scenes at fixed settings; BVH build time, paths/s and rays/s. Not a test.

use std::path::{Path, PathBuf};
use std::time::Instant;

use anyhow::Result;
use clap::Args;
use rt_core::{GpuScene, Scene};
use rt_gpu::progressive::Progressive;
use rt_gpu::{Kernel, RenderOptions, Renderer, Tuning};

use crate::options::{BvhArgs, EngineArgs, open_device};
use serde::Serialize;

#[derive(Args, Debug)]
pub struct BenchArgs {
    /// Folder with the large benchmark meshes (`stanford-bunny/`, `stanford-dragon/`); scenes whose
    /// files are missing are skipped with a message.
    #[arg(long, default_value = "../shared/models")]
    models: PathBuf,
    #[arg(long, default_value_t = 512)]
    size: u32,
    #[arg(long, default_value_t = 16)]
    spp: u32,
    /// Benchmark BSDF sampling only (next-event estimation off).
    #[arg(long)]
    no_nee: bool,
    /// How next-event estimation picks emitters (as `render --light-sampler`; the scenes' own
    /// setting when left out).
    #[arg(long, value_enum)]
    light_sampler: Option<crate::options::LightSamplerArg>,
    /// How light is gathered (as `render --integrator`): bdpt measures the CPU backend.
    #[arg(long, value_enum)]
    integrator: Option<crate::options::IntegratorArg>,
    /// Use the generic kernel (every feature compiled in) instead of one specialised per scene.
    #[arg(long)]
    generic: bool,
    /// The megakernel's work-group shape, e.g. 8x8 (the default), 16x4, 32x1; another shape than
    /// 8x8 selects the megakernel unless --kernel says otherwise (then it is an error).
    #[arg(long, default_value = "8x8", value_parser = parse_workgroup)]
    workgroup: [u32; 2],
    /// Target time of one dispatch (of the megakernel) or one wave (of the wavefront kernels), ms.
    #[arg(long, default_value_t = 40)]
    dispatch_ms: u64,
    #[command(flatten)]
    bvh: BvhArgs,
    #[command(flatten)]
    engine: EngineArgs,
    /// Only the scenes whose names contain this.
    #[arg(long)]
    only: Option<String>,
    /// Measure the interactive viewport instead (`rt_gpu::live`, as the editor runs it): change to
    /// first image, UI frame times while refining, spp after 5 s and --seconds, relMSE of the
    /// denoised view against a reference.
    #[arg(long)]
    interactive: bool,
    /// Measure the editor's raster preview instead (`rt_preview`): its first frame and the
    /// frames of a camera orbit, at --view-size.
    #[arg(long, conflicts_with = "interactive")]
    preview: bool,
    /// The interactive view's (and the preview's) size.
    #[arg(long, default_value = "1280x720", value_parser = crate::interactive::parse_size)]
    view_size: [u32; 2],
    /// How long the interactive view refines after the drag.
    #[arg(long, default_value_t = 30.0)]
    seconds: f64,
    /// Folder of references (NAME-WxH.exr) for the interactive view's relMSE.
    #[arg(long)]
    reference_dir: Option<PathBuf>,
    /// Render a missing reference with this many samples (0: skip the relMSE).
    #[arg(long, default_value_t = 0)]
    reference_spp: u32,
    /// The interactive view without its denoiser.
    #[arg(long)]
    no_denoise: bool,
}

fn parse_workgroup(s: &str) -> Result<[u32; 2], String> {
    let [x, y] = crate::options::parse_pair(s, "8x8", 256, "a work-group side")?;
    if x * y > 256 {
        return Err(format!(
            "{x}x{y} is more than 256 invocations per work group"
        ));
    }
    Ok([x, y])
}

/// The Cornell box with spheres of more material kinds: metal, or metal, glass and a texture
/// seen through a thin lens ("all").
fn material_scene(all: bool) -> Result<Scene> {
    use rt_core::{Material, Object, Texture, Transform};
    let mut scene = rt_io::assets::cornell_box()?;
    let mut mesh = rt_core::shapes::uv_sphere(80.0, 24, 48);
    // Spherical coordinates as texture coordinates, for the textured ball.
    mesh.uvs = Some(
        mesh.positions
            .iter()
            .map(|p| {
                let d = p.normalize_or_zero();
                glam::Vec2::new(
                    0.5 + d.z.atan2(d.x) / std::f32::consts::TAU,
                    0.5 + d.y.clamp(-1.0, 1.0).asin() / std::f32::consts::PI,
                )
            })
            .collect(),
    );
    let sphere = std::sync::Arc::new(mesh);
    let place = |x: f32, z: f32| Transform {
        translation: [x, 80.0, z],
        ..Transform::default()
    };
    scene.objects.push(Object {
        shadow_catcher: false,
        animation_node: None,
        name: "metal ball".into(),
        mesh: sphere.clone(),
        material: Material::Metal {
            albedo: [0.95, 0.64, 0.54],
            fuzz: 0.1,
        },
        transform: place(150.0, 150.0),
    });
    if all {
        scene.objects.push(Object {
            shadow_catcher: false,
            animation_node: None,
            name: "glass ball".into(),
            mesh: sphere.clone(),
            material: Material::Dielectric {
                ior: 1.5,
                tint: [1.0; 3],
            },
            transform: place(400.0, 200.0),
        });
        let texels: Vec<u8> = (0..64)
            .flat_map(|i| {
                let on = (i % 8 + i / 8) % 2 == 0;
                if on {
                    [230, 230, 230, 255]
                } else {
                    [40, 60, 160, 255]
                }
            })
            .collect();
        scene.textures.push(Texture {
            sampler: Default::default(),
            name: "checker".into(),
            width: 8,
            height: 8,
            rgba8: texels.into(),
        });
        scene.objects.push(Object {
            shadow_catcher: false,
            animation_node: None,
            name: "textured ball".into(),
            mesh: sphere,
            material: Material::Lambertian {
                albedo: [1.0; 3],
                texture: Some(0),
            },
            transform: place(280.0, 380.0),
        });
        scene.camera.aperture_radius = 5.0;
        scene.camera.focus_distance = Some(1000.0);
    }
    Ok(scene)
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
    /// Bvh2 or Cwbvh.
    bvh: String,
    /// "wavefront" or "megakernel".
    kernel: String,
    /// "bvh" or "hw" (ray queries).
    trace: String,
    dispatch_ms: u64,
    width: u32,
    height: u32,
    spp: u32,
    max_depth: u32,
    next_event_estimation: bool,
    render_s: f64,
    paths_per_s: f64,
    rays_per_s: f64,
    gpu_scene_bytes: u64,
    /// The process's peak resident memory so far (after this scene), MB; `None` off Linux.
    peak_rss_mb: Option<f64>,
    generic_kernel: bool,
    workgroup: String,
}

/// A benchmark mesh, loaded as every caller loads an OBJ (`rt_io::load`), then overridden
/// with the fixed view, ambient light and path length the suite has always used: the view decides
/// how many rays hit the mesh and so paths/s, and the recorded runs (docs/benchmarks.md,
/// docs/data/*.jsonl) and the interactive bench's references were made with these; following the
/// loader's framing would make new numbers incomparable with them.
fn mesh_scene(path: &Path) -> Result<Scene> {
    let mut scene = rt_io::load(path, &rt_io::LoadOptions::default())?;
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
    let integrator = args
        .integrator
        .map_or(rt_core::Integrator::Path, Into::into);
    let settings = rt_core::RenderSettings {
        integrator,
        ..Default::default()
    };
    let on_cpu = args.engine.on_cpu_for(&settings)?.0;
    if integrator == rt_core::Integrator::Bdpt && (args.interactive || args.preview) {
        anyhow::bail!(
            "--interactive and --preview measure the live views, which path trace: drop --integrator bdpt"
        );
    }
    if args.interactive || args.preview {
        return run_views(&args, on_cpu);
    }
    if on_cpu {
        return run_on_cpu(&args);
    }
    let ctx = open_device(&args.engine.adapter)?;
    let kernel = match args.engine.kernel {
        Some(kernel) => kernel.into(),
        None if args.workgroup != rt_gpu::options::DEFAULT_WORKGROUP => Kernel::Megakernel,
        None => Kernel::Wavefront,
    };
    let options = RenderOptions {
        kernel,
        target_dispatch: std::time::Duration::from_millis(args.dispatch_ms.max(1)),
        // A benchmark measures the kernels without lavapipe's memory workaround.
        tuning: Tuning {
            count_rays: true,
            generic_kernel: args.generic,
            workgroup: args.workgroup,
            ..Default::default()
        },
        ..args.engine.render_options(false)
    };
    options.validate()?;
    let suite = bench_suite(&args)?;
    println!(
        "{:<12} {:>9} {:>9} {:>9} {:>6} {:>9} {:>9} {:>9} {:>9} {:>9}",
        "scene",
        "triangles",
        "BVH ms",
        "build ms",
        "depth",
        "GPU MB",
        "render s",
        "Mpaths/s",
        "Mrays/s",
        "peak MB"
    );
    let mut records = Vec::new();
    for (name, scene) in suite {
        let Some(scene) = selected(&args, &name, scene)? else {
            continue;
        };
        let build_started = Instant::now();
        let gpu_scene = build(&args, &scene)?;
        let build_ms = build_started.elapsed().as_secs_f64() * 1e3;
        // Warm-up: compiles the pipeline and settles the dispatch size.
        let warm = Renderer::for_scene(&ctx, &scene, &gpu_scene, options)?;
        Progressive::Gpu(Box::new(warm)).render(2)?;
        let renderer = Renderer::for_scene(&ctx, &scene, &gpu_scene, options)?;
        let (kernel, trace) = (renderer.kernel().name(), renderer.trace().name());
        let mut run = Progressive::Gpu(Box::new(renderer));
        let started = Instant::now();
        run.render(args.spp)?;
        let secs = started.elapsed().as_secs_f64();
        let paths = f64::from(args.size) * f64::from(args.size) * f64::from(args.spp);
        let record = Record {
            scene: name,
            adapter: ctx.adapter_label(),
            triangles: gpu_scene.triangles.len(),
            bvh_build_ms: gpu_scene.bvh_build_time.as_secs_f64() * 1e3,
            scene_build_ms: build_ms,
            bvh_depth: gpu_scene.bvh_depth,
            bvh: format!("{:?}", gpu_scene.layout),
            kernel: kernel.into(),
            trace: trace.into(),
            dispatch_ms: args.dispatch_ms,
            width: args.size,
            height: args.size,
            spp: args.spp,
            max_depth: scene.settings.max_depth,
            next_event_estimation: gpu_scene.features.nee,
            render_s: secs,
            paths_per_s: paths / secs,
            rays_per_s: run.rays_traced() as f64 / secs,
            gpu_scene_bytes: gpu_scene.buffer_sizes().iter().map(|(_, b)| b).sum(),
            peak_rss_mb: peak_rss_mb(),
            generic_kernel: args.generic,
            workgroup: format!("{}x{}", args.workgroup[0], args.workgroup[1]),
        };
        println!(
            "{:<12} {:>9} {:>9.1} {:>9.1} {:>6} {:>9.1} {:>9.2} {:>9.3} {:>9.3} {:>9}",
            record.scene,
            record.triangles,
            record.bvh_build_ms,
            record.scene_build_ms,
            record.bvh_depth,
            record.gpu_scene_bytes as f64 / 1e6,
            record.render_s,
            record.paths_per_s / 1e6,
            record.rays_per_s / 1e6,
            megabytes(record.peak_rss_mb)
        );
        records.push(record);
    }
    for r in &records {
        println!("{}", serde_json::to_string(r)?);
    }
    Ok(())
}

/// The benchmark scenes: the Cornell box and its material variants, then the large meshes found
/// under `--models`.
fn bench_suite(args: &BenchArgs) -> Result<Vec<(String, SceneLoader)>> {
    let mut suite: Vec<(String, SceneLoader)> = vec![
        (
            "cornell".into(),
            Box::new(|| rt_io::assets::cornell_box().map_err(Into::into)),
        ),
        ("cornell+metal".into(), Box::new(|| material_scene(false))),
        ("cornell+all".into(), Box::new(|| material_scene(true))),
    ];
    for (name, file) in [
        ("bunny-69k", "stanford-bunny/stanford-bunny.obj"),
        ("dragon-202k", "stanford-dragon/dragon_vrip_res2.obj"),
        ("dragon-871k", "stanford-dragon/dragon_vrip.obj"),
    ] {
        let path = args.models.join(file);
        if path.exists() {
            suite.push((name.into(), Box::new(move || mesh_scene(&path))));
        } else {
            eprintln!(
                "skipping {name}: {} not found (pass --models DIR)",
                path.display()
            );
        }
    }
    Ok(suite)
}

/// The process's peak resident set (`VmHWM` in `/proc/self/status`), MB: what a backend needed at
/// most, host memory included. `None` where the file is missing (not Linux).
fn peak_rss_mb() -> Option<f64> {
    let status = std::fs::read_to_string("/proc/self/status").ok()?;
    let line = status.lines().find(|l| l.starts_with("VmHWM:"))?;
    let kib: f64 = line.split_whitespace().nth(1)?.parse().ok()?;
    Some(kib * 1024.0 / 1e6)
}

/// A table cell for an optional size in MB.
fn megabytes(mb: Option<f64>) -> String {
    mb.map_or_else(|| "-".into(), |mb| format!("{mb:.0}"))
}

/// `--interactive` and `--preview`: the editor's path-traced view (on the CPU backend where that
/// is the device) and its raster preview (always a GPU pass), per scene of the suite.
fn run_views(args: &BenchArgs, on_cpu: bool) -> Result<()> {
    let suite = bench_suite(args)?;
    let mut scenes = Vec::new();
    // A name that matches exactly selects that scene alone ("cornell", not its variants).
    let exact = args
        .only
        .as_ref()
        .is_some_and(|o| suite.iter().any(|(n, _)| n == o));
    for (name, scene) in suite {
        let wanted = args.only.as_ref().is_none_or(|o| {
            if exact {
                name == *o
            } else {
                name.contains(o.as_str())
            }
        });
        if wanted {
            scenes.push((name, scene()?));
        }
    }
    if args.preview {
        // The raster preview is a GPU pass whatever renders the path-traced images.
        let ctx = open_device(&args.engine.adapter)?;
        return crate::preview_bench::run(&ctx, scenes, args.view_size);
    }
    let interactive = crate::interactive::InteractiveArgs {
        size: args.view_size,
        seconds: args.seconds,
        reference_dir: args.reference_dir.clone(),
        reference_spp: args.reference_spp,
        no_denoise: args.no_denoise,
        kernel: args
            .engine
            .kernel
            .map_or(rt_gpu::live::LiveSettings::default().kernel, Into::into),
    };
    let ctx = if on_cpu {
        None
    } else {
        Some(open_device(&args.engine.adapter)?)
    };
    crate::interactive::run(ctx, scenes, &interactive)
}

/// The suite on the native CPU backend: the same scenes, paths/s, rays/s and peak memory.
fn run_on_cpu(args: &BenchArgs) -> Result<()> {
    if args.generic || args.engine.kernel.is_some() {
        anyhow::bail!(
            "--generic and --kernel measure the GPU kernels; drop them with --device cpu"
        );
    }
    let label = format!(
        "CPU (native backend, {} threads)",
        rt_core::cpu_render::threads()
    );
    println!(
        "{:<12} {:>9} {:>9} {:>6} {:>9} {:>9} {:>9} {:>9}",
        "scene", "triangles", "BVH ms", "depth", "render s", "Mpaths/s", "Mrays/s", "peak MB"
    );
    for (name, scene) in bench_suite(args)? {
        let Some(scene) = selected(args, &name, scene)? else {
            continue;
        };
        let gpu_scene = build(args, &scene)?;
        let mut run = match Progressive::cpu(&scene, &gpu_scene, 0, false) {
            Ok(run) => run,
            Err(e) => {
                eprintln!("{name}: skipped: {e}");
                continue;
            }
        };
        let started = Instant::now();
        run.render(args.spp)?;
        let secs = started.elapsed().as_secs_f64();
        let paths = f64::from(args.size) * f64::from(args.size) * f64::from(args.spp);
        let peak = peak_rss_mb();
        println!(
            "{:<12} {:>9} {:>9.1} {:>6} {:>9.2} {:>9.3} {:>9.3} {:>9}",
            name,
            gpu_scene.triangles.len(),
            gpu_scene.bvh_build_time.as_secs_f64() * 1e3,
            gpu_scene.bvh_depth,
            secs,
            paths / secs / 1e6,
            run.rays_traced() as f64 / secs / 1e6,
            megabytes(peak)
        );
        println!(
            "{}",
            serde_json::json!({
                "scene": name, "adapter": label, "bvh": format!("{:?}", gpu_scene.layout),
                "width": args.size, "height": args.size, "spp": args.spp,
                "max_depth": scene.settings.max_depth, "render_s": secs,
                "paths_per_s": paths / secs,
                "rays_per_s": run.rays_traced() as f64 / secs, "peak_rss_mb": peak,
            })
        );
    }
    Ok(())
}

/// A suite scene `--only` selects, at the benchmark's size and light sampling; `None` otherwise.
/// Loads a suite scene when it is selected: `--only cornell` does not parse the dragon.
type SceneLoader = Box<dyn FnOnce() -> Result<Scene>>;

fn selected(args: &BenchArgs, name: &str, scene: SceneLoader) -> Result<Option<Scene>> {
    if args
        .only
        .as_ref()
        .is_some_and(|o| !name.contains(o.as_str()))
    {
        return Ok(None);
    }
    let mut scene = scene()?;
    scene.settings.width = args.size;
    scene.settings.height = args.size;
    // Every pixel takes every sample: the rate measured is per sample, not per stop rule.
    scene.settings.adaptive_threshold = None;
    scene.settings.next_event_estimation = !args.no_nee;
    if let Some(sampler) = args.light_sampler {
        scene.settings.light_sampler = sampler.into();
    }
    if let Some(integrator) = args.integrator {
        scene.settings.integrator = integrator.into();
    }
    Ok(Some(scene))
}

/// The scene's GPU arrays with the BVH `--bvh` and `--bvh-quality` ask for.
fn build(args: &BenchArgs, scene: &Scene) -> Result<GpuScene> {
    let (quality, layout) = (args.bvh.bvh_quality.into(), args.bvh.bvh.into());
    Ok(GpuScene::build_with_layout(scene, quality, layout)?)
}
