//! The film beyond colour: a transparent background's alpha (0 where camera rays escape, 1 on
//! objects, the covered share on edges), the background left out of the colour, and the depth
//! pass against an analytic plane; on the GPU kernels (megakernel and wavefront) and the Rust twin.

use super::*;
use rt_core::camera::Projection;
use rt_core::first_hits::FirstHits;

/// Coverage, depth and colour per pixel from the Rust twin (`trace_path` with its first hits).
fn rust_first_hits(scene: &rt_core::Scene) -> (FirstHits, Vec<f32>) {
    let g = GpuScene::build(scene).unwrap();
    let frame = rt_core::frame::frame_for(scene, &g).unwrap();
    let (w, h, spp) = (frame.width, frame.height, scene.settings.samples_per_pixel);
    let mut hits = FirstHits::new((w * h) as usize);
    let mut red = vec![0.0; (w * h) as usize];
    for i in 0..w * h {
        let k = i as usize;
        for s in 0..spp {
            let path = rt_core::estimator::trace_path(&g, &frame, i % w, i / w, s, true);
            let f = path.first_hit.unwrap();
            hits.coverage[k] += f.coverage / spp as f32;
            hits.depth_weighted[k] += f.depth * f.coverage / spp as f32;
            for (mean, v) in hits.caught[k].iter_mut().zip(f.caught) {
                *mean += v / spp as f32;
            }
            red[k] += path.radiance.x / spp as f32;
            if s == 0 {
                hits.object[k] = f.object;
            }
        }
    }
    (hits, red)
}

/// The same from the GPU with each kernel.
fn gpu_first_hits(
    ctx: &rt_gpu::GpuContext,
    scene: &rt_core::Scene,
) -> Vec<(String, FirstHits, Vec<f32>)> {
    let g = GpuScene::build(scene).unwrap();
    [rt_gpu::Kernel::Megakernel, rt_gpu::Kernel::Wavefront]
        .into_iter()
        .map(|kernel| {
            let options = RenderOptions {
                aovs: true,
                kernel,
                ..Default::default()
            };
            let mut renderer = rt_gpu::Renderer::for_scene(ctx, scene, &g, options).unwrap();
            renderer
                .render(scene.settings.samples_per_pixel, |_| true)
                .unwrap();
            let aovs = renderer.read_aovs().unwrap().unwrap();
            let red = renderer
                .read_image()
                .unwrap()
                .pixels
                .iter()
                .map(|p| p[0])
                .collect();
            (format!("{kernel:?}"), aovs.hits, red)
        })
        .collect()
}

/// Every backend's (name, first hits, red channel).
fn all_backends(scene: &rt_core::Scene) -> Vec<(String, FirstHits, Vec<f32>)> {
    let (hits, red) = rust_first_hits(scene);
    let mut out = vec![("Rust twin".to_string(), hits, red)];
    if let Some(ctx) = gpu() {
        out.extend(gpu_first_hits(ctx, scene));
    }
    out
}

/// An orthographic camera 4 units high over a 32² image looks at a 1 × 1 card 3 units away,
/// shifted half a pixel right, under a bright sky, on a transparent film: outside the card alpha
/// is 0 and so is the colour (the sky is left out), inside alpha is 1 and the depth is 3, and the
/// card's left and right edge columns are half covered.
#[test]
fn a_transparent_film_has_alpha_on_objects_only_and_the_depth_of_a_plane() {
    let mut cam = camera(Vec3::ZERO, Vec3::new(0.0, 0.0, -1.0), 40.0);
    cam.projection = Projection::Orthographic;
    cam.ortho_height = Some(4.0);
    let pixel = 4.0 / 32.0;
    let card = object(
        "card",
        quad(Vec3::new(pixel * 0.5, 0.0, -3.0), Vec3::Z, 1.0),
        Material::Emissive {
            color: [1.0; 3],
            intensity: 2.0,
        },
    );
    let mut scene = scene(vec![card], cam, [5.0; 3], settings(32, 32, 32, 2));
    scene.settings.transparent = true;
    for (backend, hits, red) in all_backends(&scene) {
        let at = |x: usize, y: usize| y * 32 + x;
        // The card spans x ∈ [-0.4375, 0.5625]: pixels 12.5 .. 20.5, rows 12 .. 20.
        for y in 12..20 {
            for x in 13..20 {
                assert_eq!(
                    hits.coverage[at(x, y)],
                    1.0,
                    "{backend}: ({x}, {y}) on the card"
                );
                let depth = hits.depth(at(x, y));
                assert!(
                    (depth - 3.0).abs() < 1e-4,
                    "{backend}: depth {depth} at ({x}, {y})"
                );
                assert_eq!(hits.object[at(x, y)], 1, "{backend}: object id");
            }
            for x in [12, 20] {
                let alpha = hits.coverage[at(x, y)];
                assert!(
                    (alpha - 0.5).abs() <= 0.1,
                    "{backend}: edge ({x}, {y}) alpha {alpha}"
                );
            }
            assert_eq!(hits.coverage[at(5, y)], 0.0, "{backend}: beside the card");
            assert_eq!(
                red[at(5, y)],
                0.0,
                "{backend}: the sky is left out of the colour"
            );
            assert_eq!(hits.object[at(5, y)], 0, "{backend}: no object");
        }
        assert_eq!(hits.coverage[at(0, 0)], 0.0, "{backend}: corner");
        assert!(
            (red[at(16, 16)] - 2.0).abs() < 1e-5,
            "{backend}: the card's colour"
        );
    }
}

/// Without a transparent film the sky stays in the colour and alpha still marks the objects.
#[test]
fn an_opaque_film_keeps_the_background_in_the_colour() {
    let scene = scene(
        Vec::new(),
        camera(Vec3::ZERO, Vec3::new(0.0, 0.0, -1.0), 40.0),
        [0.5; 3],
        settings(8, 8, 4, 2),
    );
    for (backend, hits, red) in all_backends(&scene) {
        assert!(
            red.iter().all(|r| (r - 0.5).abs() < 1e-6),
            "{backend}: {red:?}"
        );
        assert!(hits.coverage.iter().all(|c| *c == 0.0), "{backend}");
    }
}

/// A shadow catcher floor under a black sphere, a sun straight above (E = 2) and a uniform sky
/// (L = 0.3), seen at the point below the sphere's centre (a 4 × 4 image 0.2° wide): the
/// sun is blocked and the sky loses the sphere's cap, so α = 1 − πL(1 − r²/h²)/(πL + E) within
/// four standard deviations of the sky's visibility (a Bernoulli per sample), and the colour is
/// zero (a black sphere reflects nothing; sky and sun are in the alpha). On every backend.
#[test]
fn a_shadow_catcher_has_the_alpha_of_its_shadow() {
    let (radius, height, sun, sky) = (0.5f32, 2.0f32, 2.0f32, 0.3f32);
    let mut floor = object(
        "floor",
        quad(Vec3::ZERO, Vec3::Y, 20.0),
        Material::lambertian([0.8; 3]),
    );
    floor.shadow_catcher = true;
    let mut sphere = object(
        "sphere",
        uv_sphere(radius, 96, 192),
        Material::lambertian([0.0; 3]),
    );
    sphere.transform.translation = [0.0, height, 0.0];
    let cam = camera(Vec3::new(0.0, 1.0, 6.0), Vec3::ZERO, 0.2);
    let mut scene = scene(vec![floor, sphere], cam, [sky; 3], settings(4, 4, 256, 4));
    scene.settings.transparent = true;
    let mut light = rt_core::Light::new(rt_core::LightKind::Directional, "sun");
    light.intensity = sun;
    scene.lights.push(light);
    let sky_e = std::f32::consts::PI * sky;
    let unshadowed = 1.0 - (radius / height).powi(2);
    let expected = 1.0 - sky_e * unshadowed / (sky_e + sun);
    let samples = 16.0 * 256.0;
    let sigma = sky_e * (unshadowed * (1.0 - unshadowed) / samples).sqrt() / (sky_e + sun);
    for (backend, hits, red) in all_backends(&scene) {
        let alpha = hits.alphas().iter().sum::<f32>() / 16.0;
        assert!(
            (alpha - expected).abs() < 4.0 * sigma,
            "{backend}: alpha {alpha}, expected {expected} ± {}",
            4.0 * sigma
        );
        assert!(red.iter().all(|r| *r == 0.0), "{backend}: {red:?}");
        assert!(hits.caught.iter().all(|c| c[0] == 1.0), "{backend}");
    }
}

/// Lockstep, as the path tracer's (tests/reference/): a PBR scene under an environment map, an
/// area light, a sun and a point light, its floor a shadow catcher on a transparent film. The
/// twins draw the same random numbers, so per pixel the alpha (the catcher's lit and unshadowed
/// irradiance) and the colour (what the matte paths bring back) agree to rounding on all but a
/// rare pixel; the Rust twin with another seed differs in most, so the check has power.
#[test]
fn shadow_catchers_agree_with_their_twin_in_lockstep() {
    if gpu().is_none() {
        return;
    }
    let mut scene = pbr_scene_with_environment(20, 20);
    scene.objects[0].shadow_catcher = true;
    scene.settings.transparent = true;
    scene.settings.samples_per_pixel = 4;
    let mut sun = rt_core::Light::new(rt_core::LightKind::Directional, "sun");
    sun.direction = [0.3, -1.0, -0.2];
    sun.intensity = 2.0;
    let mut bulb = rt_core::Light::new(rt_core::LightKind::Point, "bulb");
    bulb.position = [0.5, 2.0, 0.5];
    bulb.intensity = 5.0;
    scene.lights.extend([sun, bulb]);
    let (twin, twin_red) = rust_first_hits(&scene);
    let apart = |hits: &FirstHits, red: &[f32]| {
        let alphas = (twin.alphas(), hits.alphas());
        (0..red.len())
            .filter(|&i| {
                let off = |a: f32, b: f32| (a - b).abs() > 1e-4 * b.abs().max(1.0);
                off(alphas.1[i], alphas.0[i]) || off(red[i], twin_red[i])
            })
            .count()
    };
    assert!(
        twin.caught.iter().any(|c| c[0] == 1.0 && c[1] < c[2]),
        "no shadow on the catcher"
    );
    let mut reseeded = scene.clone();
    reseeded.settings.seed += 1;
    let (other, other_red) = rust_first_hits(&reseeded);
    let control = apart(&other, &other_red);
    let covered = twin.coverage.iter().filter(|c| **c > 0.0).count();
    eprintln!("another seed: {control} of {covered} covered pixels apart");
    assert!(control * 2 > covered, "another seed agrees");
    for (backend, hits, red) in gpu_first_hits(gpu().unwrap(), &scene) {
        let n = apart(&hits, &red);
        eprintln!("{backend}: {n} of 400 pixels apart");
        assert!(n <= 4, "{backend}: {n} of 400 pixels apart");
    }
}
