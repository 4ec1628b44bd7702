//! The native CPU backend (`rt_core::cpu_render`, what `--device cpu` runs) against the GPU
//! kernel on the reference scenes, between them every feature: metal and glass, point, spot and
//! sun lights, PBR materials under an environment, alpha masks and blending, emission and base
//! colour textures, normal maps and a thin lens. Both take the same samples from the same random
//! numbers, so pixels agree to rounding, except where a last-bit difference sends a path another
//! way (another lobe or side of an edge; alpha blending's coins flip most, since they hash the
//! ray's exact bits): those pixels hold another valid sample, so they are counted against a
//! bound per scene, and the image means must agree within the pixels' own noise.

use super::*;
use rt_core::cpu_render::CpuAccumulation;
use rt_gpu::Renderer;
use std::sync::atomic::AtomicBool;

/// Renders `scene` on both backends at its samples and returns the fraction of pixels that agree
/// to rounding, after checking the image means agree within four standard errors and that both
/// count the same rays, but for the paths of the pixels that differ.
fn agreement(scene: &Scene) -> Option<f64> {
    agreement_with(scene, &GpuScene::build(scene).unwrap())
}

/// `agreement` over `gpu_scene`, a build of `scene`.
fn agreement_with(scene: &Scene, gpu_scene: &GpuScene) -> Option<f64> {
    let ctx = gpu()?;
    let mut options = RenderOptions::default();
    options.tuning.count_rays = true;
    let mut renderer = Renderer::for_scene(ctx, scene, gpu_scene, options).unwrap();
    let spp = scene.settings.samples_per_pixel;
    renderer.render(spp, |_| true).unwrap();
    let gpu_image = renderer.read_image().unwrap();
    let frame = rt_core::frame::frame_for(scene, gpu_scene).unwrap();
    let mut cpu = CpuAccumulation::new(&frame, 0, None, false);
    assert!(cpu.add_batch(gpu_scene, &frame, spp, &AtomicBool::new(false)));
    let cpu_pixels = cpu.pixels();
    let agree = gpu_image
        .pixels
        .iter()
        .zip(&cpu_pixels)
        .filter(|(g, c)| {
            (0..3).all(|ch| (g[ch] - c[ch]).abs() <= 1e-4 * g[ch].abs().max(c[ch].abs()) + 1e-6)
        })
        .count();
    // Image means: each pixel's luminance variance (from its mean squared luminance) bounds the
    // noise of the difference between two independent-looking estimates of it.
    let n = cpu_pixels.len() as f64;
    let lum = |p: &[f32; 4]| {
        0.2126 * f64::from(p[0]) + 0.7152 * f64::from(p[1]) + 0.0722 * f64::from(p[2])
    };
    let (g_mean, c_mean) = (
        gpu_image.pixels.iter().map(lum).sum::<f64>() / n,
        cpu_pixels.iter().map(lum).sum::<f64>() / n,
    );
    let variance: f64 = cpu_pixels
        .iter()
        .map(|p| (f64::from(p[3]) - lum(p).powi(2)).max(0.0))
        .sum::<f64>()
        / (n * n * f64::from(spp));
    let sigma = (2.0 * variance).sqrt();
    assert!(
        (g_mean - c_mean).abs() <= 4.0 * sigma + 1e-6,
        "image luminance: GPU {g_mean}, CPU backend {c_mean}, σ {sigma}"
    );
    // A path traces at most an extension ray, a light sample's shadow ray and one per delta light
    // at each vertex: that bounds what the disagreeing pixels' samples can change.
    let per_path = u64::from(frame.max_depth) * (2 + gpu_scene.delta_lights.len() as u64);
    let bound = (cpu_pixels.len() - agree) as u64 * u64::from(spp) * per_path;
    let gpu_rays = renderer.rays_traced();
    eprintln!("rays traced: GPU {gpu_rays}, CPU backend {}", cpu.rays);
    assert!(
        cpu.rays.abs_diff(gpu_rays) <= bound && gpu_rays > 0,
        "rays traced: GPU {gpu_rays}, CPU backend {} (the differing pixels allow {bound})",
        cpu.rays
    );
    Some(agree as f64 / n)
}

#[test]
fn the_cpu_backend_renders_the_gpu_image_on_every_reference_scene() {
    let mut lights = cornell_with_metal_and_glass(16);
    let mut point = rt_core::Light::new(rt_core::LightKind::Point, "bulb");
    point.position = [150.0, 400.0, 250.0];
    point.intensity = 2e4;
    let mut sun = rt_core::Light::new(rt_core::LightKind::Directional, "sun");
    sun.direction = [0.3, -1.0, 0.2];
    lights.lights = vec![point, sun.clone()];
    lights.settings.samples_per_pixel = 8;
    let mut pbr = pbr_scene_with_environment(24, 18);
    pbr.settings.samples_per_pixel = 8;
    // The sun through its rough glass: delta lights beyond a transmitting surface.
    pbr.lights.push(sun);
    let mut alpha = alpha_and_emission_textures_scene(24, 20);
    alpha.settings.samples_per_pixel = 8;
    let mut textured = textured_scene_with_normals_metal_glass_and_lens();
    textured.settings.samples_per_pixel = 4;
    for (name, scene, bound) in [
        ("metal, glass, point and sun lights", lights, 0.98),
        ("PBR under an environment and the sun", pbr, 0.98),
        ("alpha and emission textures", alpha, 0.5),
        ("textures, normal maps, thin lens", textured, 0.98),
    ] {
        let Some(fraction) = agreement(&scene) else {
            return;
        };
        eprintln!(
            "{name}: {:.1}% of pixels agree to rounding",
            100.0 * fraction
        );
        assert!(
            fraction >= bound,
            "{name}: only {:.1}% of pixels agree",
            100.0 * fraction
        );
    }
}

/// `scene` with a second copy of each of its solid objects (whose mesh has height) sharing the
/// first's mesh: behind it, turned, shrunk and mirrored, so that the build makes instances.
fn with_mirrored_copies(mut scene: Scene) -> Scene {
    let copies: Vec<_> = (scene.objects.iter())
        .filter(|o| {
            let ys = o.mesh.positions.iter().map(|p| p.y);
            let (lo, hi) = ys.fold((f32::MAX, f32::MIN), |(l, h), y| (l.min(y), h.max(y)));
            hi - lo > 0.01
        })
        .map(|o| {
            let mut copy = o.clone();
            copy.name = format!("{} (copy)", o.name);
            let t = &mut copy.transform;
            t.translation = [
                t.translation[0] - 0.9,
                t.translation[1],
                t.translation[2] - 1.0,
            ];
            t.rotation_deg[1] += 40.0;
            t.scale = [-0.8 * t.scale[0], 0.8 * t.scale[1], 0.8 * t.scale[2]];
            copy
        })
        .collect();
    scene.objects.extend(copies);
    scene
}

#[test]
fn the_gpu_traces_instances_as_the_cpu_backend_does() {
    let mut textured = with_mirrored_copies(textured_scene_with_normals_metal_glass_and_lens());
    textured.settings.samples_per_pixel = 4;
    let mut pbr = with_mirrored_copies(pbr_scene_with_environment(24, 18));
    pbr.settings.samples_per_pixel = 8;
    for (name, scene) in [("textured, mirrored", textured), ("PBR, normal maps", pbr)] {
        let layout = rt_core::bvh::BvhLayout::default();
        let built = GpuScene::build_with_layout(&scene, Default::default(), layout).unwrap();
        assert!(!built.instances.is_empty(), "{name}: nothing instanced");
        let Some(fraction) = agreement_with(&scene, &built) else {
            return;
        };
        eprintln!(
            "{name}: {:.1}% of pixels agree to rounding",
            100.0 * fraction
        );
        assert!(
            fraction >= 0.95,
            "{name}: only {:.1}% of pixels agree",
            100.0 * fraction
        );
    }
}
