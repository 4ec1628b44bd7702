//! Tracing with the driver's ray queries (`Trace::Hardware`; lavapipe >= 24.1 implements them in
//! software, so they run in `cargo test` on CPU machines): the same nearest hits as brute force,
//! and the same images as rt's own BVH traversal, through both kernels. Bit identity is not
//! expected (the driver's triangle test is not rt's watertight one), agreement to rounding in all
//! but a few pixels is.

mod common;

use common::*;
use glam::Vec3;
use rt_core::estimator::trace_brute_force;
use rt_core::gpu_types::Ray;
use rt_core::{GpuScene, Scene};
use rt_gpu::{GpuContext, Kernel, RenderOptions, Trace};

/// The test context with ray queries, or `None` (with a message) where the adapter has none. A
/// lavapipe that should have them (Mesa 24.1 or newer) and does not fails the test.
fn ray_query_gpu() -> Option<&'static GpuContext> {
    let ctx = gpu()?;
    if ctx.has_ray_queries() {
        return Some(ctx);
    }
    let mesa = ctx.mesa_version();
    assert!(
        mesa.is_none_or(|v| v < (24, 1)),
        "{} (Mesa {mesa:?}) should offer ray queries",
        ctx.adapter_label()
    );
    eprintln!("SKIPPED: {} has no ray queries", ctx.adapter_label());
    None
}

#[test]
fn mesa_versions_are_read_from_the_driver_info() {
    use rt_gpu::context::mesa_version;
    assert_eq!(
        mesa_version("Mesa 25.0.7-2~bpo12+1 (LLVM 15.0.6)"),
        Some((25, 0))
    );
    assert_eq!(mesa_version("Mesa 22.3.6 (LLVM 15.0.6)"), Some((22, 3)));
    assert_eq!(mesa_version("NVIDIA 550.54"), None);
}

/// Rays from all around a mesh, a quarter of them aimed past it and an eighth with a short t_max:
/// the driver's nearest hits are brute force's (hit or miss, and the distance).
#[test]
fn ray_queries_find_the_nearest_hits_of_brute_force() {
    let Some(ctx) = ray_query_gpu() else { return };
    let path =
        std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("assets/bunny/bunny-lowres-npm.obj");
    let scene = rt_io::obj::load_obj(&path, 0).unwrap();
    let gpu_scene = GpuScene::build(&scene).unwrap();
    let (lo, hi) = scene.bounds().unwrap();
    let (center, radius) = ((lo + hi) * 0.5, (hi - lo).length() * 0.5);
    let mut state = 777u32;
    let mut unit = || {
        state = rt_core::math::rng::pcg_hash(state);
        let z = state as f32 / u32::MAX as f32 * 2.0 - 1.0;
        state = rt_core::math::rng::pcg_hash(state);
        let phi = state as f32 / u32::MAX as f32 * std::f32::consts::TAU;
        let r = (1.0 - z * z).max(0.0).sqrt();
        Vec3::new(r * phi.cos(), r * phi.sin(), z)
    };
    let rays: Vec<Ray> = (0..4096)
        .map(|i| {
            let origin = center + unit() * radius * 1.5;
            let target = center + unit() * radius * if i % 4 == 0 { 1.2 } else { 0.4 };
            Ray {
                origin: origin.to_array(),
                t_max: if i % 8 == 0 { radius } else { f32::MAX },
                direction: (target - origin).normalize().to_array(),
                _pad: 0.0,
            }
        })
        .collect();
    let hits = rt_gpu::trace_rays::trace_rays(ctx, &gpu_scene, &rays, Trace::Hardware).unwrap();
    let (mut hit_count, mut same_triangle, mut disagree) = (0, 0, Vec::new());
    for (ray, hw) in rays.iter().zip(&hits) {
        let cpu = trace_brute_force(
            &gpu_scene,
            ray.origin.into(),
            ray.direction.into(),
            ray.t_max,
        );
        hit_count += usize::from(cpu.triangle != u32::MAX);
        // The same hit: distance, and on the same triangle the same barycentrics (the estimator
        // interpolates normals and UVs with them); a tie on a shared edge may name either triangle.
        let same = (hw.triangle == u32::MAX) == (cpu.triangle == u32::MAX)
            && (cpu.triangle == u32::MAX
                || ((hw.t - cpu.t).abs() <= 1e-4 * cpu.t.max(1.0)
                    && (hw.triangle != cpu.triangle
                        || ((hw.b1 - cpu.b1).abs() <= 1e-3 && (hw.b2 - cpu.b2).abs() <= 1e-3))));
        same_triangle += usize::from(cpu.triangle != u32::MAX && hw.triangle == cpu.triangle);
        if !same {
            disagree.push((ray, *hw, cpu));
        }
    }
    assert!(hit_count > 2000, "too few rays hit the mesh ({hit_count})");
    assert!(
        same_triangle * 100 >= hit_count * 99,
        "only {same_triangle} of {hit_count} hits name brute force's triangle"
    );
    // A ray through a shared edge or vertex may be a hit for one test and a miss for the other.
    assert!(
        disagree.len() <= 4,
        "{} of {} rays disagree with brute force; first: {:?}",
        disagree.len(),
        rays.len(),
        &disagree[..disagree.len().min(3)]
    );
}

/// `Trace::Hardware` renders rt's-BVH image through both kernels, in every pixel but a few to
/// rounding (the same random numbers drive the same paths), on scenes with every feature.
#[test]
fn ray_queries_render_the_image_of_rts_bvh() {
    let Some(ctx) = ray_query_gpu() else { return };
    let mut metal = rt_io::assets::cornell_box().unwrap();
    metal.objects[0].material = rt_core::Material::Metal {
        albedo: [0.9; 3],
        fuzz: 0.2,
    };
    metal.objects[1].material = rt_core::Material::Dielectric {
        ior: 1.5,
        tint: [1.0; 3],
    };
    let mut bulb = rt_core::Light::new(rt_core::LightKind::Point, "bulb");
    bulb.position = [150.0, 400.0, 250.0];
    bulb.intensity = 40_000.0;
    metal.lights.push(bulb);
    let scenes: [(&str, Scene); 4] = [
        ("Cornell box with metal, glass and a point light", metal),
        // One bottom-level structure of the shared ball, three instances (one mirrored).
        ("instances", cornell_with_shared_balls()),
        (
            "textures, normals, thin lens",
            textured_scene_with_normals_metal_glass_and_lens(),
        ),
        // Holes: the driver hands every hit over as a candidate that rt's coverage test confirms.
        // (Blending's coin hashes the ray's exact bits, so the driver's rounding of hit points
        // sends later paths elsewhere: tests/analytic/ checks it over ray queries statistically.)
        (
            "alpha mask, emission textures",
            masked_only(alpha_and_emission_textures_scene(24, 24)),
        ),
    ];
    for (name, mut scene) in scenes {
        scene.settings.width = 24;
        scene.settings.height = 24;
        scene.settings.samples_per_pixel = 4;
        let gpu_scene = GpuScene::build(&scene).unwrap();
        assert_eq!(
            gpu_scene.instances.len(),
            if name == "instances" { 3 } else { 0 }
        );
        for kernel in [Kernel::Wavefront, Kernel::Megakernel] {
            let render = |trace| {
                let options = RenderOptions {
                    kernel,
                    trace,
                    ..Default::default()
                };
                let mut renderer =
                    rt_gpu::Renderer::for_scene(ctx, &scene, &gpu_scene, options).unwrap();
                assert_eq!(renderer.trace(), trace);
                renderer.render(4, |_| true).unwrap();
                renderer.read_image().unwrap()
            };
            let (bvh, hw) = (render(Trace::Bvh), render(Trace::Hardware));
            let apart = bvh
                .pixels
                .iter()
                .zip(&hw.pixels)
                .filter(|(a, b)| (0..3).any(|c| (a[c] - b[c]).abs() > 1e-4 * a[c].abs().max(1.0)))
                .count();
            assert!(
                apart * 50 <= bvh.pixels.len(),
                "{name}, {kernel:?}: {apart} of {} pixels differ",
                bvh.pixels.len()
            );
            let (m_bvh, m_hw) = (bvh.channel_means(), hw.channel_means());
            assert!(m_bvh[0] > 0.0);
            for c in 0..3 {
                assert!(
                    (m_bvh[c] - m_hw[c]).abs() <= 0.01 * m_bvh[c],
                    "{name}, {kernel:?}: channel {c} means {} vs {}",
                    m_bvh[c],
                    m_hw[c]
                );
            }
        }
    }
}

/// The Cornell box with three copies of one ball mesh (instances): turned, one mirrored and
/// stretched, one scaled down and metal.
fn cornell_with_shared_balls() -> Scene {
    let mut scene = rt_io::assets::cornell_box().unwrap();
    let ball = std::sync::Arc::new(rt_core::shapes::uv_sphere(60.0, 12, 24));
    let placements = [
        (
            [150.0, 60.0, 150.0],
            [1.0, 1.0, 1.0],
            rt_core::Material::lambertian([0.7, 0.6, 0.5]),
        ),
        (
            [400.0, 80.0, 300.0],
            [-1.0, 1.3, 1.0],
            rt_core::Material::lambertian([0.3, 0.5, 0.8]),
        ),
        (
            [280.0, 300.0, 280.0],
            [0.7, 0.7, 0.7],
            rt_core::Material::Metal {
                albedo: [0.9; 3],
                fuzz: 0.1,
            },
        ),
    ];
    for (i, (translation, scale, material)) in placements.into_iter().enumerate() {
        scene.objects.push(rt_core::scene::Object {
            name: format!("ball {i}"),
            mesh: ball.clone(),
            material,
            transform: rt_core::scene::Transform {
                translation,
                rotation_deg: [10.0, 30.0 * i as f32, 0.0],
                scale,
            },
            shadow_catcher: false,
            animation_node: None,
        });
    }
    scene
}

/// `Trace::Auto` picks rt's BVH on CPU adapters (lavapipe's ray queries are software too, and
/// slower there: docs/performance.md) and ray queries on GPUs that offer them.
#[test]
fn auto_tracing_picks_the_bvh_on_cpu_adapters() {
    let Some(ctx) = gpu() else { return };
    let scene = rt_io::assets::cornell_box().unwrap();
    let gpu_scene = GpuScene::build(&scene).unwrap();
    let expected = if ctx.has_ray_queries() && ctx.info.device_type != wgpu::DeviceType::Cpu {
        Trace::Hardware
    } else {
        Trace::Bvh
    };
    assert_eq!(ctx.resolve_trace(Trace::Auto, &gpu_scene), expected);
    let renderer =
        rt_gpu::Renderer::for_scene(ctx, &scene, &gpu_scene, RenderOptions::default()).unwrap();
    assert_eq!(renderer.trace(), expected);
    // An empty scene has nothing to build ray queries over.
    let mut empty = scene.clone();
    empty.objects.clear();
    let empty_gpu = GpuScene::build(&empty).unwrap();
    assert_eq!(ctx.resolve_trace(Trace::Auto, &empty_gpu), Trace::Bvh);
}
