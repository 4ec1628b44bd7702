//! The GPU kernel against the scalar CPU reference of the same estimator, the BVH traversal against
//! brute force, determinism, and the loop-budget sentinel.

mod common;

use common::*;
use glam::Vec3;
use rt_core::bvh::{BvhLayout, BvhQuality};
use rt_core::gpu_types::Ray;
use rt_core::reference::{self, trace_brute_force};
use rt_core::shapes::{quad, uv_sphere};
use rt_core::{GpuScene, Material, Scene};
use rt_gpu::{GpuContext, RenderOptions};

/// Per-pixel, per-channel Z-test of GPU means against CPU means with the CPU's sample variance
/// (both estimate the same quantity with the same variance): α = 0.01 over the whole image with
/// Šidák's correction, and at least 99.5% of tests must pass.
fn assert_images_agree(scene: &Scene, gpu_spp: u32, cpu_spp: u32) {
    let Some(ctx) = gpu() else { return };
    let gpu_scene = GpuScene::build(scene).unwrap();
    let mut gpu_settings = scene.clone();
    gpu_settings.settings.samples_per_pixel = gpu_spp;
    let image = render_gpu(ctx, &gpu_settings, &gpu_scene, RenderOptions::default());
    let frame = rt_core::frame::frame_for(scene, &gpu_scene).unwrap();
    let cpu = reference::render(&gpu_scene, &frame, cpu_spp);

    let tests = image.pixels.len() * 3;
    let alpha = 1.0 - (1.0 - 0.01f64).powf(1.0 / tests as f64);
    let z_max = z_threshold(alpha);
    let mut failed = Vec::new();
    for (i, (g, (c, var))) in image
        .pixels
        .iter()
        .zip(cpu.mean.iter().zip(&cpu.variance))
        .enumerate()
    {
        for ch in 0..3 {
            let diff = f64::from(g[ch]) - f64::from(c[ch]);
            let sigma =
                (f64::from(var[ch]) * (1.0 / f64::from(cpu_spp) + 1.0 / f64::from(gpu_spp))).sqrt();
            let ok = if sigma > 0.0 {
                (diff / sigma).abs() <= z_max
            } else {
                diff.abs() <= 1e-4
            };
            if !ok {
                failed.push((i, ch, g[ch], c[ch], sigma));
            }
        }
    }
    let pass_rate = 1.0 - failed.len() as f64 / tests as f64;
    assert!(
        pass_rate >= 0.995,
        "{} of {tests} pixel tests failed (|z| > {z_max:.2}); first: {:?}",
        failed.len(),
        &failed[..failed.len().min(5)]
    );
    // The means over the image must agree too (a bias spread thinly fails here).
    let g = image.channel_means();
    for ch in 0..3 {
        let c: f64 = cpu.mean.iter().map(|p| f64::from(p[ch])).sum::<f64>() / cpu.mean.len() as f64;
        let var: f64 = cpu.variance.iter().map(|p| f64::from(p[ch])).sum::<f64>()
            / (cpu.mean.len() as f64).powi(2);
        let sigma = (var * (1.0 / f64::from(cpu_spp) + 1.0 / f64::from(gpu_spp))).sqrt();
        assert!(
            (g[ch] - c).abs() <= 4.0 * sigma + 1e-6,
            "channel {ch} image mean: GPU {} CPU {c} σ {sigma}",
            g[ch]
        );
    }
}

fn cornell_with_metal_and_glass(size: u32) -> Scene {
    let mut scene = rt_core::assets::cornell_box().unwrap();
    for o in &mut scene.objects {
        match o.name.as_str() {
            "tall_block" => {
                o.material = Material::Metal {
                    albedo: [0.9, 0.8, 0.6],
                    fuzz: 0.2,
                }
            }
            "short_block" => {
                o.material = Material::Dielectric {
                    ior: 1.5,
                    tint: [0.9, 1.0, 0.9],
                }
            }
            _ => {}
        }
    }
    // Ambient light through the open front keeps the per-pixel variance low enough for the test to
    // have power (with only the small ceiling light, a 3% BSDF bias went undetected).
    scene.ambient = [1.0; 3];
    scene.settings = settings(size, size, 1, 6);
    scene
}

/// Point, spot and directional lights beside an area light, with metal: the GPU agrees with the CPU
/// reference per pixel.
#[test]
fn gpu_matches_cpu_reference_with_point_spot_and_directional_lights() {
    let mut scene = cornell_with_metal_and_glass(24);
    let mut point = rt_core::Light::new(rt_core::LightKind::Point, "bulb");
    point.position = [150.0, 400.0, 250.0];
    point.color = [1.0, 0.8, 0.6];
    point.intensity = 40_000.0;
    let mut spot = rt_core::Light::new(rt_core::LightKind::Spot, "spot");
    spot.position = [400.0, 500.0, 200.0];
    spot.direction = [0.0, -1.0, 0.3];
    spot.intensity = 80_000.0;
    spot.inner_angle_deg = 10.0;
    spot.outer_angle_deg = 25.0;
    let mut sun = rt_core::Light::new(rt_core::LightKind::Directional, "sun");
    sun.direction = [0.2, -1.0, 0.1];
    sun.intensity = 0.5;
    scene.lights = vec![point, spot, sun];
    assert_images_agree(&scene, 8192, 4096);
}

/// The Sobol sampler's kernel and CPU reference agree too (same points per pixel and sample).
#[test]
fn gpu_matches_cpu_reference_with_the_sobol_sampler() {
    let mut scene = cornell_with_metal_and_glass(16);
    scene.settings.sampler = rt_core::math::rng::SamplerKind::Sobol;
    assert_images_agree(&scene, 2048, 2048);
}

/// The NEE-only estimator (a diagnostic) in the kernel agrees with its CPU twin. On the Cornell box:
/// in the three-light room the largest light touches a wall, so next-event estimates there have a
/// heavy 1/r² tail and the sample variance of a few thousand samples understates it (the kernel and
/// the CPU gave the same means to 7 digits there at equal seeds, yet the Z-test failed 2 pixels).
#[test]
fn gpu_matches_cpu_reference_with_nee_only() {
    let mut scene = cornell_with_metal_and_glass(12);
    scene.settings.nee_only = true;
    assert_images_agree(&scene, 8192, 4096);
}

#[test]
fn gpu_matches_cpu_reference_on_cornell_with_metal_and_glass() {
    assert_images_agree(&cornell_with_metal_and_glass(12), 8192, 4096);
}

/// Smooth normals, a texture, a mirror sphere, a rotated and mirrored object and a thin lens.
/// Every PBR feature and the environment map: statistically the same image on the GPU and the CPU.
#[test]
fn gpu_matches_cpu_reference_with_pbr_materials_and_an_environment() {
    assert_images_agree(&pbr_scene_with_environment(24, 18), 256, 256);
}

/// Masked and blended surfaces (holes in shadows, in camera rays and in an emitter that
/// next-event estimation samples), emission images and every wrap mode and filter.
#[test]
fn gpu_matches_cpu_reference_with_alpha_and_emission_textures() {
    assert_images_agree(&alpha_and_emission_textures_scene(24, 20), 256, 256);
}

#[test]
fn gpu_matches_cpu_reference_on_textures_normals_and_thin_lens() {
    let scene = textured_scene_with_normals_metal_glass_and_lens();
    let gpu_scene = GpuScene::build(&scene).unwrap();
    assert!(
        gpu_scene.features.textures
            && gpu_scene
                .features
                .kinds
                .contains(rt_core::MaterialKind::Metal)
            && gpu_scene
                .features
                .kinds
                .contains(rt_core::MaterialKind::Dielectric)
            && gpu_scene.features.thin_lens
    );
    assert_images_agree(&scene, 8192, 4096);
}

fn random_unit(state: &mut u32) -> Vec3 {
    let mut next = || {
        *state = rt_core::math::rng::pcg_hash(*state);
        *state as f32 / u32::MAX as f32
    };
    let z = 1.0 - 2.0 * next();
    let phi = std::f32::consts::TAU * next();
    let s = (1.0 - z * z).sqrt();
    Vec3::new(s * phi.cos(), s * phi.sin(), z)
}

/// The kernel's BVH traversals (BVH2 and compressed wide BVH) find the same nearest hit as testing
/// every triangle, for rays from all around a real mesh (the Stanford bunny, 3,674 triangles) aimed
/// into it and past it.
#[test]
fn gpu_bvh_traversal_matches_brute_force() {
    let Some(ctx) = gpu() else { return };
    let path =
        std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("assets/bunny/bunny-lowres-npm.obj");
    let scene = rt_core::io::obj::load_obj(&path, 0).unwrap();
    for layout in [BvhLayout::Bvh2, BvhLayout::Cwbvh] {
        let gpu_scene = GpuScene::build_with_layout(&scene, BvhQuality::default(), layout).unwrap();
        check_traversal_against_brute_force(ctx, &scene, &gpu_scene);
    }
}

fn check_traversal_against_brute_force(ctx: &GpuContext, scene: &Scene, gpu_scene: &GpuScene) {
    let layout = gpu_scene.layout;
    let (lo, hi) = scene.bounds().unwrap();
    let (center, radius) = ((lo + hi) * 0.5, (hi - lo).length() * 0.5);
    let mut state = 12345u32;
    let rays: Vec<Ray> = (0..4096)
        .map(|i| {
            let origin = center + random_unit(&mut state) * radius * 1.5;
            let target =
                center + random_unit(&mut state) * radius * if i % 4 == 0 { 1.2 } else { 0.4 };
            let t_max = if i % 8 == 0 { radius } else { f32::MAX };
            Ray {
                origin: origin.to_array(),
                t_max,
                direction: (target - origin).normalize().to_array(),
                _pad: 0.0,
            }
        })
        .collect();
    let hits = rt_gpu::trace_rays::trace_rays(ctx, gpu_scene, &rays, rt_gpu::Trace::Bvh).unwrap();
    let mut hit_count = 0;
    for (ray, gpu_hit) in rays.iter().zip(&hits) {
        let cpu = trace_brute_force(
            gpu_scene,
            ray.origin.into(),
            ray.direction.into(),
            ray.t_max,
        );
        let cpu_bvh = reference::trace(
            gpu_scene,
            ray.origin.into(),
            ray.direction.into(),
            ray.t_max,
        );
        assert_eq!(
            cpu_bvh.triangle == u32::MAX,
            cpu.triangle == u32::MAX,
            "{layout:?}: CPU BVH vs brute force: {ray:?}"
        );
        assert_eq!(
            gpu_hit.triangle == u32::MAX,
            cpu.triangle == u32::MAX,
            "{layout:?}: hit/miss differs for {ray:?}: {gpu_hit:?} vs {cpu:?}"
        );
        if cpu.triangle != u32::MAX {
            hit_count += 1;
            // Same distance (a tie on a shared edge may pick either triangle).
            assert!(
                (gpu_hit.t - cpu.t).abs() <= 1e-5 * cpu.t.max(1.0),
                "{layout:?}: distance differs for {ray:?}: {gpu_hit:?} vs {cpu:?}"
            );
            assert!((cpu_bvh.t - cpu.t).abs() <= 1e-5 * cpu.t.max(1.0));
        }
    }
    assert!(
        hit_count > 2000,
        "{layout:?}: too few rays hit the mesh ({hit_count}) for the test to mean much"
    );
}

#[test]
fn same_seed_gives_identical_bytes_and_other_seeds_differ() {
    let Some(ctx) = gpu() else { return };
    let mut scene = cornell_with_metal_and_glass(32);
    scene.settings.samples_per_pixel = 8;
    let gpu_scene = GpuScene::build(&scene).unwrap();
    let bytes = |scene: &Scene, options: RenderOptions| {
        let image = render_gpu(ctx, scene, &gpu_scene, options);
        bytemuck::cast_slice::<[f32; 4], u8>(&image.pixels).to_vec()
    };
    let a = bytes(&scene, RenderOptions::default());
    // A different split into dispatches must not change a bit either.
    let b = bytes(
        &scene,
        RenderOptions {
            max_samples_per_dispatch: Some(3),
            target_dispatch: std::time::Duration::from_secs(10),
            ..Default::default()
        },
    );
    assert!(a == b, "same seed, different batching: images differ");
    scene.settings.seed = 2;
    let c = bytes(&scene, RenderOptions::default());
    assert!(a != c, "different seeds gave the same image");
}

/// Lavapipe silently cuts loops short after 65,535 iterations per invocation. The image does not
/// depend on how samples are batched, so the largest batch the renderer allows must give exactly the
/// image of one sample per dispatch; a truncated traversal or path loop would change it.
#[test]
fn largest_dispatch_gives_the_same_image_as_single_samples() {
    let Some(ctx) = gpu() else { return };
    let path =
        std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("assets/bunny/bunny-lowres-npm.obj");
    let mut scene = rt_core::io::obj::load_obj(&path, 0).unwrap();
    let mut room = rt_core::shapes::cuboid(Vec3::splat(-5.0), Vec3::splat(5.0), true);
    room.positions
        .iter_mut()
        .for_each(|p| *p += Vec3::new(0.0, 2.0, 0.0));
    scene
        .objects
        .push(object("room", room, Material::lambertian([0.8; 3])));
    scene.objects.push(object(
        "light",
        quad(Vec3::new(0.0, 6.9, 0.0), -Vec3::Y, 2.0),
        Material::Emissive {
            color: [10.0; 3],
            intensity: 1.0,
        },
    ));
    scene.camera = camera(Vec3::new(0.0, 1.0, 4.0), Vec3::new(0.0, 1.0, 0.0), 40.0);
    scene.settings = settings(16, 16, 64, 8);
    let gpu_scene = GpuScene::build(&scene).unwrap();
    // The megakernel runs whole paths per invocation, so it is the one at risk (a wavefront
    // invocation traces one ray).
    let slow = RenderOptions {
        target_dispatch: std::time::Duration::from_secs(60),
        kernel: rt_gpu::Kernel::Megakernel,
        ..Default::default()
    };
    let one = render_gpu(
        ctx,
        &scene,
        &gpu_scene,
        RenderOptions {
            max_samples_per_dispatch: Some(1),
            ..slow
        },
    );
    // With a generous time target the renderer grows dispatches to its loop-budget cap.
    let mut renderer = rt_gpu::Renderer::for_scene(ctx, &scene, &gpu_scene, slow).unwrap();
    let mut largest = 0;
    while renderer.samples_done() < 64 {
        largest = largest.max(
            renderer
                .render_batch(64 - renderer.samples_done())
                .unwrap()
                .samples,
        );
    }
    assert!(
        largest > 1,
        "the renderer never batched samples, so this test checks nothing"
    );
    let batched = renderer.read_image().unwrap();
    assert!(
        one.pixels == batched.pixels,
        "batched samples ({largest} per dispatch) changed the image: loop truncation?"
    );
}

/// Per-pixel, per-channel Z-tests of two CPU estimates of one image, each with its own sample
/// variance: α = 0.01 over the image with Šidák's correction. Returns the failures and the number of
/// tests.
fn z_test_failures(
    a: &reference::ReferenceImage,
    n_a: u32,
    b: &reference::ReferenceImage,
    n_b: u32,
) -> (usize, usize) {
    let tests = a.mean.len() * 3;
    let z_max = z_threshold(1.0 - (1.0 - 0.01f64).powf(1.0 / tests as f64));
    let mut failed = 0;
    for i in 0..a.mean.len() {
        for c in 0..3 {
            let sigma = (f64::from(a.variance[i][c]) / f64::from(n_a)
                + f64::from(b.variance[i][c]) / f64::from(n_b))
            .sqrt();
            let diff = f64::from(a.mean[i][c]) - f64::from(b.mean[i][c]);
            if (sigma > 0.0 && (diff / sigma).abs() > z_max) || (sigma == 0.0 && diff.abs() > 1e-6)
            {
                failed += 1;
            }
        }
    }
    (failed, tests)
}

fn total_variance(image: &reference::ReferenceImage) -> f64 {
    image
        .variance
        .iter()
        .flat_map(|v| v.iter())
        .map(|v| f64::from(*v))
        .sum()
}

/// A room lit by a small, a medium and a large emitter, and a ball.
fn room_with_three_lights() -> Scene {
    let mut room = rt_core::shapes::cuboid(Vec3::splat(-2.0), Vec3::splat(2.0), true);
    room.positions.iter_mut().for_each(|p| p.z -= 1.0);
    let light = |size: f32, x: f32, color: [f32; 3]| {
        object(
            "light",
            quad(Vec3::new(x, 1.99, -1.0), -Vec3::Y, size),
            Material::Emissive {
                color,
                intensity: 1.0,
            },
        )
    };
    let mut scene = scene(
        vec![
            object("room", room, Material::lambertian([0.7, 0.6, 0.5])),
            object(
                "ball",
                uv_sphere(0.6, 8, 16),
                Material::lambertian([0.3, 0.5, 0.8]),
            ),
            light(0.25, -1.2, [60.0, 50.0, 40.0]),
            light(0.7, 0.0, [4.0, 6.0, 8.0]),
            light(1.6, 1.2, [1.0, 1.0, 1.0]),
        ],
        camera(Vec3::new(0.0, 0.0, 0.9), Vec3::new(0.0, -0.3, -1.0), 80.0),
        [0.0; 3],
        settings(10, 8, 1, 4),
    );
    scene.objects[1].transform.translation = [0.3, -1.4, -1.5];
    scene
}

/// Next-event estimation with MIS, next-event estimation alone and BSDF sampling alone estimate the
/// same image: the room with three light sizes, all three estimators on the CPU reference (whose
/// kernel twin is checked above and in `gpu_matches_cpu_reference_with_nee_only`), compared pairwise
/// per pixel with both estimators' sample variances; ≥ 99.5% of the tests of each pair pass.
#[test]
fn nee_with_mis_nee_only_and_bsdf_sampling_converge_to_the_same_image() {
    let mut scene = room_with_three_lights();
    let render = |scene: &Scene, spp: u32| {
        let gpu_scene = GpuScene::build(scene).unwrap();
        let frame = rt_core::frame::frame_for(scene, &gpu_scene).unwrap();
        (reference::render(&gpu_scene, &frame, spp), frame)
    };
    let (n_mis, n_nee, n_bsdf) = (2048u32, 4096u32, 16384u32);
    let (mis, frame) = render(&scene, n_mis);
    assert_eq!(frame.emitter_count, 6);
    assert_eq!(frame.light_strategy, 0);
    scene.settings.nee_only = true;
    let (nee, frame) = render(&scene, n_nee);
    assert_eq!(
        frame.light_strategy, 1,
        "NEE-only run must say so to the estimator"
    );
    scene.settings.nee_only = false;
    scene.settings.next_event_estimation = false;
    let (bsdf, frame) = render(&scene, n_bsdf);
    assert_eq!(
        frame.emitter_count, 0,
        "BSDF-only run must not sample emitters"
    );

    for (what, a, n_a, b, n_b) in [
        ("NEE+MIS vs BSDF-only", &mis, n_mis, &bsdf, n_bsdf),
        ("NEE-only vs BSDF-only", &nee, n_nee, &bsdf, n_bsdf),
        ("NEE+MIS vs NEE-only", &mis, n_mis, &nee, n_nee),
    ] {
        let (failed, tests) = z_test_failures(a, n_a, b, n_b);
        assert!(
            failed as f64 <= 0.005 * tests as f64,
            "{what}: {failed} of {tests} pixel tests failed"
        );
    }
    // The three are different estimators, not one run thrice: their per-sample variances differ,
    // and combining the strategies beats either alone.
    let (var_mis, var_nee, var_bsdf) = (
        total_variance(&mis),
        total_variance(&nee),
        total_variance(&bsdf),
    );
    assert!(
        var_mis * 4.0 < var_bsdf,
        "NEE should cut the per-sample variance a lot: {var_mis} vs {var_bsdf}"
    );
    assert!(
        var_mis < var_nee && var_mis < var_bsdf,
        "MIS should beat both of its strategies here: MIS {var_mis}, NEE-only {var_nee}, BSDF-only {var_bsdf}"
    );
}

/// Next-event estimation must see what BSDF sampling sees on an emitter with an emission image and
/// holes: the room's middle light made a PBR panel whose emission image (mirrored past its edge)
/// varies over it and whose alpha mask cuts holes. NEE alone, NEE with MIS and BSDF sampling alone,
/// on the CPU reference (the kernels' twin), agree per pixel; a NEE that ignored the image or the
/// holes would be brighter.
#[test]
fn a_textured_emitter_with_holes_lights_alike_by_nee_and_bsdf_sampling() {
    use rt_core::material::{AlphaMode, Pbr};
    let mut scene = room_with_three_lights();
    let mut panel = quad(Vec3::new(0.0, 1.99, -1.0), -Vec3::Y, 1.2);
    panel.uvs = Some(
        [(0.0, 0.0), (1.5, 0.0), (1.5, 1.5), (0.0, 1.5)]
            .map(|(u, v)| glam::Vec2::new(u, v))
            .to_vec(),
    );
    scene.objects[3].mesh = panel.into();
    scene.objects[3].material = pbr(Pbr {
        base_color: [0.5; 3],
        texture: Some(0),
        emission: [8.0, 6.0, 4.0],
        emission_texture: Some(0),
        alpha_mode: AlphaMode::Mask,
        ..Default::default()
    });
    let rgba: Vec<u8> = (0..16u32)
        .flat_map(|i| {
            let hole = (i % 4 + i / 4) % 3 == 0;
            [
                255,
                (40 + 50 * (i % 4)) as u8,
                90,
                if hole { 0 } else { 255 },
            ]
        })
        .collect();
    scene.textures.push(rt_core::Texture {
        name: "pattern".into(),
        width: 4,
        height: 4,
        rgba8: rgba.into(),
        sampler: rt_core::TextureSampler {
            wrap_s: rt_core::Wrap::MirroredRepeat,
            wrap_t: rt_core::Wrap::MirroredRepeat,
            filter: rt_core::Filter::Nearest,
        },
    });
    let render = |scene: &Scene, spp: u32| {
        let gpu_scene = GpuScene::build(scene).unwrap();
        let frame = rt_core::frame::frame_for(scene, &gpu_scene).unwrap();
        reference::render(&gpu_scene, &frame, spp)
    };
    let (n_mis, n_nee, n_bsdf) = (2048u32, 4096u32, 16384u32);
    let mis = render(&scene, n_mis);
    scene.settings.nee_only = true;
    let nee = render(&scene, n_nee);
    scene.settings.nee_only = false;
    scene.settings.next_event_estimation = false;
    let bsdf = render(&scene, n_bsdf);
    for (what, a, n_a) in [("NEE-only", &nee, n_nee), ("NEE+MIS", &mis, n_mis)] {
        let (failed, tests) = z_test_failures(a, n_a, &bsdf, n_bsdf);
        assert!(
            failed as f64 <= 0.005 * tests as f64,
            "{what} vs BSDF-only: {failed} of {tests} pixel tests failed"
        );
    }
}

/// Lockstep: the kernels and the CPU reference draw the same random numbers in the same order (a
/// function of pixel, sample index and seed), so at a few samples per pixel on a small scene each
/// pixel agrees to rounding, not only in distribution: a reordered, extra or missing random draw
/// on either side sends almost every path elsewhere and fails here at once, long before a Z-test
/// over thousands of samples could see it. Rounding differences may still send a rare path
/// another way (a ray grazing an edge, a roulette or Fresnel draw at its threshold, lavapipe's
/// transcendentals, a GPU's fused multiply-adds), so up to 1% of pixels may differ by more than
/// rounding (on lavapipe none does). The CPU reference with another seed, the same kind of change
/// as a shifted random draw, must differ in most pixels: the check has the power it claims.
#[test]
fn the_kernels_and_the_cpu_reference_agree_per_pixel_in_lockstep() {
    let Some(ctx) = gpu() else { return };
    let mut independent = cornell_with_metal_and_glass(20);
    independent.settings.sampler = rt_core::math::rng::SamplerKind::Independent;
    let mut lit = cornell_with_metal_and_glass(20);
    let mut bulb = rt_core::Light::new(rt_core::LightKind::Point, "bulb");
    bulb.position = [150.0, 400.0, 250.0];
    bulb.intensity = 40_000.0;
    lit.lights.push(bulb);
    // The firefly clamp (a frame value both twins read) where it bites: it changes most pixels.
    let mut clamped = lit.clone();
    clamped.settings.clamp = Some(0.5);
    {
        let gpu_scene = GpuScene::build(&clamped).unwrap();
        let with = rt_core::frame::frame_for(&clamped, &gpu_scene).unwrap();
        assert_eq!(with.clamp_max, 0.5);
        let without = rt_core::gpu_types::Frame {
            clamp_max: 0.0,
            ..with
        };
        let (a, b) = (
            reference::render(&gpu_scene, &with, 1),
            reference::render(&gpu_scene, &without, 1),
        );
        let changed = a.mean.iter().zip(&b.mean).filter(|(x, y)| x != y).count();
        assert!(
            changed * 4 > a.mean.len(),
            "the clamp changes only {changed} of {} pixels",
            a.mean.len()
        );
    }
    let mut textured = textured_scene_with_normals_metal_glass_and_lens();
    textured.settings.width = 20;
    textured.settings.height = 20;
    let mut pbr_env = pbr_scene_with_environment(20, 20);
    let mut sun = rt_core::Light::new(rt_core::LightKind::Directional, "sun");
    sun.direction = [0.3, -1.0, -0.2];
    sun.intensity = 2.0;
    pbr_env.lights.push(sun);
    for (name, mut scene) in [
        (
            "Cornell box with metal and glass, Sobol",
            cornell_with_metal_and_glass(20),
        ),
        ("the same, independent samples", independent),
        ("with a point light", lit),
        ("with a point light and the firefly clamp", clamped),
        ("textures, normals, thin lens", textured),
        ("PBR materials, environment, area and sun light", pbr_env),
        (
            "alpha mask, emission textures, samplers",
            masked_only(alpha_and_emission_textures_scene(20, 20)),
        ),
        // Blending flips a coin hashed from the ray's exact bits (`alpha_coin` itself agrees bit
        // for bit, tests/twins/), but the twins' camera rays differ in their last bits (the
        // drivers' `normalize`), which flips ~10% of the coins: blending is compared
        // statistically (gpu_matches_cpu_reference_with_alpha_and_emission_textures).
    ] {
        let gpu_scene = GpuScene::build(&scene).unwrap();
        for spp in [1, 4] {
            scene.settings.samples_per_pixel = spp;
            let frame = rt_core::frame::frame_for(&scene, &gpu_scene).unwrap();
            let cpu = reference::render(&gpu_scene, &frame, spp);
            let reseeded = rt_core::gpu_types::Frame {
                seed: frame.seed + 1,
                ..frame
            };
            let other_seed = reference::render(&gpu_scene, &reseeded, spp);
            for kernel in [rt_gpu::Kernel::Wavefront, rt_gpu::Kernel::Megakernel] {
                let options = RenderOptions {
                    kernel,
                    ..Default::default()
                };
                let image = render_gpu(ctx, &scene, &gpu_scene, options);
                let apart = |cpu: &reference::ReferenceImage| -> Vec<(usize, [f32; 4], [f32; 3])> {
                    image
                        .pixels
                        .iter()
                        .zip(&cpu.mean)
                        .enumerate()
                        .filter(|(_, (g, c))| {
                            (0..3).any(|ch| (g[ch] - c[ch]).abs() > 1e-4 * c[ch].abs().max(1.0))
                        })
                        .map(|(i, (g, c))| (i, *g, *c))
                        .collect()
                };
                let control = apart(&other_seed).len() as f64 / image.pixels.len() as f64;
                assert!(
                    control > 0.5,
                    "{name}, {spp} spp: another seed differs in only {:.0}% of pixels",
                    control * 100.0
                );
                let apart = apart(&cpu);
                let fraction = apart.len() as f64 / image.pixels.len() as f64;
                eprintln!(
                    "{name}, {spp} spp, {kernel:?}: {:.2}% of pixels apart",
                    fraction * 100.0
                );
                assert!(
                    fraction <= 0.01,
                    "{name}, {spp} spp, {kernel:?}: {} of {} pixels differ from the CPU \
                     reference by more than rounding; first: {:?}",
                    apart.len(),
                    image.pixels.len(),
                    &apart[..apart.len().min(3)]
                );
            }
        }
    }
}
