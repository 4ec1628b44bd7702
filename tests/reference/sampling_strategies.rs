//! NEE with MIS, NEE only and BSDF sampling converge to the same image.

use super::*;
use rt_core::shapes::uv_sphere;

/// Per-pixel, per-channel Z-tests of two CPU estimates of one image, each with its own sample
/// variance: α = 0.01 over the image with Šidák's correction. Returns the failures and the number of
/// tests.
fn z_test_failures(
    a: &estimator::ReferenceImage,
    n_a: u32,
    b: &estimator::ReferenceImage,
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

fn total_variance(image: &estimator::ReferenceImage) -> f64 {
    image
        .variance
        .iter()
        .flat_map(|v| v.iter())
        .map(|v| f64::from(*v))
        .sum()
}

/// `scene` rendered by the CPU reference at `spp`, and the frame it was rendered with.
fn render(scene: &Scene, spp: u32) -> (estimator::ReferenceImage, rt_core::gpu_types::Frame) {
    let gpu_scene = GpuScene::build(scene).unwrap();
    let frame = rt_core::frame::frame_for(scene, &gpu_scene).unwrap();
    (estimator::render(&gpu_scene, &frame, spp), frame)
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
    let (n_mis, n_nee, n_bsdf) = (2048u32, 4096u32, 16384u32);
    let (mis, frame) = render(&scene, n_mis);
    assert_eq!(frame.emitter_count, 6);
    assert_eq!(frame.nee_only, 0);
    scene.settings.nee_only = true;
    let (nee, frame) = render(&scene, n_nee);
    assert_eq!(
        frame.nee_only, 1,
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
    let (n_mis, n_nee, n_bsdf) = (2048u32, 4096u32, 16384u32);
    let (mis, _) = render(&scene, n_mis);
    scene.settings.nee_only = true;
    let (nee, _) = render(&scene, n_nee);
    scene.settings.nee_only = false;
    scene.settings.next_event_estimation = false;
    let (bsdf, _) = render(&scene, n_bsdf);
    for (what, a, n_a) in [("NEE-only", &nee, n_nee), ("NEE+MIS", &mis, n_mis)] {
        let (failed, tests) = z_test_failures(a, n_a, &bsdf, n_bsdf);
        assert!(
            failed as f64 <= 0.005 * tests as f64,
            "{what} vs BSDF-only: {failed} of {tests} pixel tests failed"
        );
    }
}

/// The room with forty small emitters of varied power, position and facing (some on the walls and
/// ceiling, some in the air, some facing away from everything the camera sees), a diffuse ball
/// and a rough glass ball that lights behind it shine through.
fn room_with_many_lights() -> Scene {
    let mut scene = room_with_three_lights();
    scene.objects.retain(|o| o.name != "light");
    let mut rng = rt_core::math::rng::Rng::new(7, 0, 0x1e);
    for i in 0..40 {
        let u = |rng: &mut rt_core::math::rng::Rng| rng.next_f32() * 2.0 - 1.0;
        let centre = Vec3::new(
            1.8 * u(&mut rng),
            1.8 * u(&mut rng),
            -1.0 + 1.8 * u(&mut rng),
        );
        let facing = Vec3::new(u(&mut rng), u(&mut rng), u(&mut rng)).normalize_or(Vec3::NEG_Y);
        let strength = 10f32.powf(2.0 * rng.next_f32());
        scene.objects.push(object(
            &format!("light {i}"),
            quad(centre, facing, 0.1 + 0.2 * rng.next_f32()),
            Material::Emissive {
                color: [strength, strength * 0.8, strength * 0.6],
                intensity: 1.0,
            },
        ));
    }
    let mut glass = object(
        "rough glass",
        uv_sphere(0.5, 8, 16),
        pbr(rt_core::material::Pbr {
            base_color: [1.0; 3],
            roughness: 0.4,
            transmission: 1.0,
            ..Default::default()
        }),
    );
    glass.transform.translation = [-0.6, -0.8, -1.6];
    scene.objects.push(glass);
    scene
}

/// The light tree picks emitters by their importance at each vertex, not by power alone: an
/// unbiased estimator with different noise. On a room with forty emitters and rough glass, NEE+MIS
/// through the tree, through the power table and BSDF sampling alone agree per pixel, and so does
/// NEE alone through the tree (so the tree's pmf at the sample is its pmf on a BSDF hit: MIS
/// weights that did not sum to one would shift the MIS images away from NEE alone and from BSDF
/// sampling alone). The tree wastes fewer shadow rays here: its per-sample variance is lower.
#[test]
fn light_tree_power_sampling_and_bsdf_sampling_converge_to_the_same_image() {
    let mut scene = room_with_many_lights();
    let (n_tree, n_power, n_nee, n_bsdf) = (2048u32, 2048u32, 4096u32, 16384u32);
    scene.settings.light_sampler = rt_core::LightSampler::Tree;
    let (tree, frame) = render(&scene, n_tree);
    assert_eq!((frame.emitter_count, frame.light_sampler), (80, 1));
    scene.settings.nee_only = true;
    let (tree_nee, frame) = render(&scene, n_nee);
    assert_eq!((frame.nee_only, frame.light_sampler), (1, 1));
    scene.settings.nee_only = false;
    scene.settings.light_sampler = rt_core::LightSampler::Power;
    let (power, frame) = render(&scene, n_power);
    assert_eq!(frame.light_sampler, 0);
    scene.settings.next_event_estimation = false;
    let (bsdf, frame) = render(&scene, n_bsdf);
    assert_eq!(frame.emitter_count, 0);
    for (what, a, n_a, b, n_b) in [
        ("tree vs BSDF-only", &tree, n_tree, &bsdf, n_bsdf),
        ("power vs BSDF-only", &power, n_power, &bsdf, n_bsdf),
        ("tree vs power", &tree, n_tree, &power, n_power),
        (
            "tree NEE-only vs BSDF-only",
            &tree_nee,
            n_nee,
            &bsdf,
            n_bsdf,
        ),
        ("tree vs tree NEE-only", &tree, n_tree, &tree_nee, n_nee),
    ] {
        let (failed, tests) = z_test_failures(a, n_a, b, n_b);
        assert!(
            failed as f64 <= 0.005 * tests as f64,
            "{what}: {failed} of {tests} pixel tests failed"
        );
    }
    let (var_tree, var_power) = (total_variance(&tree), total_variance(&power));
    assert!(
        var_tree < var_power,
        "the tree should cut the per-sample variance: tree {var_tree}, power {var_power}"
    );
}

/// Light found through a diffuse or rough transmission has no next-event estimate (the shadow rays
/// leave above the surface), so its BSDF sample must keep weight one, whichever pdf the light
/// sampler would give it: a small bright lamp behind a diffusely transmitting pane (paper, a
/// lampshade) renders the same with NEE+MIS as with BSDF sampling alone, per pixel, through the
/// power table and through the light tree (weighed against either, the pane would be black).
#[test]
fn light_through_a_transmitting_surface_is_not_weighed_against_light_sampling() {
    let pane = object(
        "paper",
        quad(Vec3::new(0.0, 0.0, -1.0), Vec3::Z, 1.5),
        pbr(rt_core::material::Pbr {
            base_color: [1.0; 3],
            roughness: 1.0,
            diffuse_transmission: 1.0,
            thin_walled: true,
            ..Default::default()
        }),
    );
    let lamp = object(
        "lamp",
        quad(Vec3::new(0.2, 0.1, -1.6), Vec3::Z, 0.25),
        Material::Emissive {
            color: [40.0, 30.0, 20.0],
            intensity: 1.0,
        },
    );
    let mut scene = scene(
        vec![pane, lamp],
        camera(Vec3::ZERO, Vec3::new(0.0, 0.0, -1.0), 50.0),
        [0.0; 3],
        settings(8, 8, 1, 3),
    );
    let n = 4096;
    scene.settings.light_sampler = rt_core::LightSampler::Power;
    let (power, _) = render(&scene, n);
    scene.settings.light_sampler = rt_core::LightSampler::Tree;
    let (tree, _) = render(&scene, n);
    scene.settings.next_event_estimation = false;
    let (bsdf, _) = render(&scene, n);
    let mean = |image: &estimator::ReferenceImage| -> f64 {
        image.mean.iter().map(|p| f64::from(p[0])).sum::<f64>() / image.mean.len() as f64
    };
    assert!(
        mean(&bsdf) > 0.5,
        "the lamp lights the paper: {}",
        mean(&bsdf)
    );
    for (what, a) in [("power", &power), ("tree", &tree)] {
        let (failed, tests) = z_test_failures(a, n, &bsdf, n);
        assert!(
            failed as f64 <= 0.005 * tests as f64,
            "{what} NEE+MIS vs BSDF-only: {failed} of {tests} pixel tests failed (means {} vs {})",
            mean(a),
            mean(&bsdf)
        );
    }
}

/// The room with three emitters, thirty point and spot lights (both falloffs, some hard-edged), a
/// rough glass ball and a thin paper pane with lights on both sides (a vertex there takes lights
/// from its far side).
pub(super) fn room_with_points_spots_glass_and_paper() -> Scene {
    use rt_core::light::SpotFalloff;
    use rt_core::{Light, LightKind};
    let mut scene = room_with_three_lights();
    scene.objects.push(object(
        "paper",
        quad(Vec3::new(0.9, -0.6, -1.2), Vec3::new(-0.3, 0.2, 1.0), 1.2),
        pbr(rt_core::material::Pbr {
            base_color: [0.9, 0.8, 0.7],
            roughness: 1.0,
            diffuse_transmission: 0.6,
            thin_walled: true,
            ..Default::default()
        }),
    ));
    let mut glass = object(
        "rough glass",
        uv_sphere(0.45, 8, 16),
        pbr(rt_core::material::Pbr {
            base_color: [1.0; 3],
            roughness: 0.4,
            transmission: 1.0,
            ..Default::default()
        }),
    );
    glass.transform.translation = [-0.9, -0.9, -1.4];
    scene.objects.push(glass);
    let mut rng = rt_core::math::rng::Rng::new(11, 0, 0x5b);
    for i in 0..30 {
        let mut u = || rng.next_f32() * 2.0 - 1.0;
        let kind = [LightKind::Point, LightKind::Spot][i % 2];
        let mut light = Light::new(kind, &format!("delta {i}"));
        // A third behind the pane, the rest anywhere in the room.
        light.position = if i % 3 == 0 {
            [0.9 + 0.5 * u(), -0.6 + 0.5 * u(), -2.2 + 0.6 * u()]
        } else {
            [1.8 * u(), 1.8 * u(), -1.0 + 1.8 * u()]
        };
        light.direction = Vec3::new(u(), u(), u())
            .normalize_or(Vec3::NEG_Y)
            .to_array();
        light.intensity = 0.2 + 0.8 * (u() + 1.0);
        light.color = [1.0, 0.6 + 0.2 * u(), 0.5];
        light.outer_angle_deg = 50.0 + 30.0 * u();
        // Every fifth spot hard-edged (inner = outer, as a glTF importer makes of inner > outer).
        light.inner_angle_deg = if i % 10 == 1 {
            light.outer_angle_deg
        } else {
            light.outer_angle_deg * (0.5 + 0.4 * u())
        };
        if i % 4 == 3 {
            light.falloff = SpotFalloff::Gltf;
        }
        scene.lights.push(light);
    }
    scene
}

/// Point and spot lights through the light tree: one picked by its importance at each vertex (its
/// irradiance over its pmf) instead of all of them summed, an unbiased estimate with other noise.
/// On `room_with_points_spots_glass_and_paper` (where the paper is lit from behind, the tree weighs
/// lights with no receiver normal) the tree's image and the sum's agree per pixel.
#[test]
fn point_and_spot_lights_sampled_through_the_tree_converge_to_their_sum() {
    let mut scene = room_with_points_spots_glass_and_paper();
    let (n_tree, n_sum) = (4096u32, 1024u32);
    scene.settings.light_sampler = rt_core::LightSampler::Tree;
    let (tree, frame) = render(&scene, n_tree);
    assert_eq!((frame.emitter_count, frame.light_sampler), (6, 1));
    scene.settings.light_sampler = rt_core::LightSampler::Power;
    let (sum, frame) = render(&scene, n_sum);
    assert_eq!(frame.light_sampler, 0);
    let (failed, tests) = z_test_failures(&tree, n_tree, &sum, n_sum);
    assert!(
        failed as f64 <= 0.005 * tests as f64,
        "tree vs sum: {failed} of {tests} pixel tests failed"
    );
}
