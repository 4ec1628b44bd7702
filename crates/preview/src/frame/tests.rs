//! Unit tests of `frame`.

use super::*;
use crate::types::light_kind;

#[test]
fn the_cornell_frame_has_its_light_and_a_sane_exposure() {
    let scene = rt_io::assets::cornell_box().expect("embedded scene");
    let frame = build_frame(&scene, &scene.camera, scene.bounds(), Some(0), [400, 300]);
    assert_eq!(frame.objects.len(), scene.objects.len());
    assert_eq!(frame.view.light_count, 1);
    assert_eq!(frame.view.lights[0].shadow[0], light_kind::EMITTER);
    assert_eq!(frame.objects[0].flags[0], 1, "selection flagged");
    assert_eq!(frame.objects[1].flags[0], 0);
    // The light's centre lies under the ceiling, inside the box.
    let y = frame.view.lights[0].position[1];
    assert!(y > 400.0 && y < 560.0, "{y}");
    assert!(!frame.grid.is_empty() && frame.grid.len().is_multiple_of(2));
}

/// The grid lies just below the scene's lowest point (a floor there hides it rather than
/// fighting it for depth), opaque at its centre and faded out at its rim.
#[test]
fn the_grid_lies_just_under_the_floor_and_fades_to_its_rim() {
    let scene = rt_io::assets::cornell_box().expect("embedded scene");
    let (lo, hi) = scene.bounds().unwrap();
    let frame = build_frame(&scene, &scene.camera, Some((lo, hi)), None, [400, 300]);
    let extent = (hi - lo).max_element();
    for v in &frame.grid {
        let below = lo.y - v.position[1];
        assert!(below > 1e-3 * extent && below < 1e-2 * extent, "{below}");
    }
    let alphas: Vec<f32> = frame.grid.iter().map(|v| v.color[3]).collect();
    let max = alphas.iter().copied().fold(0.0, f32::max);
    let min = alphas.iter().copied().fold(1.0, f32::min);
    assert!(max > 0.95 && min == 0.0, "alpha from {min} to {max}");
}

/// A PBR material's emission makes a preview light as an emissive material does, and a spot
/// keeps its axis and cones (the other lights have none).
#[test]
fn pbr_emitters_light_the_preview_and_spots_keep_their_cones() {
    let mut scene = rt_io::assets::cornell_box().expect("embedded scene");
    scene
        .objects
        .retain(|o| !matches!(o.material, Material::Emissive { .. }));
    scene.objects[0].material = Material::Pbr(Box::new(rt_core::material::Pbr {
        emission: [1.0, 0.5, 0.2],
        emission_strength: 3.0,
        ..Default::default()
    }));
    let mut spot = rt_core::Light::new(rt_core::LightKind::Spot, "spot");
    spot.direction = [0.0, -2.0, 0.0];
    spot.inner_angle_deg = 20.0;
    spot.outer_angle_deg = 30.0;
    scene.lights = vec![spot];
    let frame = build_frame(&scene, &scene.camera, scene.bounds(), None, [400, 300]);
    assert_eq!(frame.view.light_count, 2);
    let lights = &frame.view.lights[..2];
    let spot = lights
        .iter()
        .find(|l| l.shadow[0] == light_kind::SPOT)
        .unwrap();
    assert_eq!(spot.direction[..3], [0.0, -1.0, 0.0]);
    assert!((spot.direction[3] - 30f32.to_radians().cos()).abs() < 1e-6);
    assert!((spot.cone[0] - 20f32.to_radians().cos()).abs() < 1e-6);
    let emitter = lights
        .iter()
        .find(|l| l.shadow[0] == light_kind::EMITTER)
        .unwrap();
    // The emitter's radiance, as the render gives it.
    let radiance = Vec3::from_slice(&emitter.color[..3]);
    assert!((radiance - Vec3::new(3.0, 1.5, 0.6)).length() < 1e-5);
    assert!(
        emitter.shadow[3] == 1,
        "its own object, which its shadow map leaves out"
    );
}

/// Bounce light: in the Cornell box the probes in the middle get more from below (the lit floor)
/// than from above (the ceiling, lit only by bounces, yet lit), see the sky only through the open
/// front, and with black walls get none.
#[test]
fn a_closed_room_fills_with_bounce_light_and_a_black_one_does_not() {
    let scene = rt_io::assets::cornell_box().expect("embedded scene");
    let frame = build_frame(&scene, &scene.camera, scene.bounds(), None, [64, 64]);
    let v = &frame.volume;
    assert_eq!(v.dims, [4, 4, 4]);
    let lum = |t: [f32; 4]| rt_core::math::sampling::luminance(Vec3::from_slice(&t[..3]));
    let (mut below, mut above) = (0.0, 0.0);
    for [x, z] in [[1, 1], [1, 2], [2, 1], [2, 2]] {
        below += lum(v.at([x, 2, z], 3));
        above += lum(v.at([x, 2, z], 2));
    }
    eprintln!("bounce from below {below}, from above {above}");
    assert!(below > 1.1 * above && above > 0.0, "{below} {above}");
    // The box is open towards −z (the camera): its back wall hides the sky from every probe,
    // and the front row sees the opening.
    for z in 0..4 {
        for y in 0..4 {
            for x in 0..4 {
                let (back, front) = (v.at([x, y, z], 4)[3], v.at([x, y, 0], 5)[3]);
                assert!(
                    back < 0.05 && front > 0.3,
                    "sky {back} behind, {front} in front"
                );
            }
        }
    }
    let mut black = scene.clone();
    for o in &mut black.objects {
        if !matches!(o.material, Material::Emissive { .. }) {
            o.material = Material::Lambertian {
                albedo: [0.0; 3],
                texture: None,
            };
        }
    }
    let frame = build_frame(&black, &black.camera, black.bounds(), None, [64, 64]);
    assert!(frame.volume.texels.iter().all(|t| t[0] == 0.0));
}

/// An interactive frame of a large scene shows the last bounce light while a thread builds the
/// new one, and says so; a later frame gets the new one.
#[test]
fn a_large_scenes_bounce_light_is_built_on_a_thread() {
    let mut scene = rt_io::assets::cornell_box().expect("embedded scene");
    let mut ball = scene.objects[0].clone();
    ball.name = "ball".into();
    ball.mesh = rt_core::shapes::uv_sphere(80.0, 120, 200).into();
    ball.transform.translation = [280.0, 300.0, 280.0];
    scene.objects.push(ball);
    assert!(scene.triangle_count() > crate::volume_cache::SYNC_TRIANGLES);
    let frame = |scene: &Scene| {
        build_interactive_frame(scene, &scene.camera, scene.bounds(), None, [64, 64])
    };
    assert!(frame(&scene).settling, "the first frame does not wait");
    let started = std::time::Instant::now();
    let done = loop {
        let f = frame(&scene);
        if !f.settling {
            break f;
        }
        assert!(started.elapsed().as_secs() < 60, "the volume never arrived");
        std::thread::sleep(std::time::Duration::from_millis(20));
    };
    assert_eq!(done.volume.dims, [4, 4, 4]);
}

/// A flat emitter's light is all along its normal; a closed one's is isotropic.
#[test]
fn an_emitters_projected_area_follows_its_shape() {
    let flat = rt_core::Object {
        shadow_catcher: false,
        animation_node: None,
        name: "quad".into(),
        mesh: rt_core::shapes::quad(Vec3::ZERO, Vec3::NEG_Y, 2.0).into(),
        material: Material::Emissive {
            color: [1.0; 3],
            intensity: 1.0,
        },
        transform: Default::default(),
    };
    let (area, _, normal) = emitter_shape(&flat);
    assert!((area - 4.0).abs() < 1e-4 && (normal - Vec3::new(0.0, -4.0, 0.0)).length() < 1e-4);
    let ball = rt_core::Object {
        mesh: rt_core::shapes::uv_sphere(1.0, 32, 64).into(),
        ..flat
    };
    let (area, center, normal) = emitter_shape(&ball);
    assert!((area - 4.0 * std::f32::consts::PI).abs() < 0.05, "{area}");
    assert!(normal.length() < 1e-3 && center.length() < 1e-3);
}

#[test]
fn the_scene_centre_projects_to_the_middle_of_the_view() {
    let scene = rt_io::assets::cornell_box().expect("embedded scene");
    let m = view_projection(&scene.camera, 1.0, scene.bounds());
    let (lo, hi) = scene.bounds().unwrap();
    let from = Vec3::from(scene.camera.from);
    let dir = (Vec3::from(scene.camera.to) - from).normalize();
    let p = m.project_point3(from + dir * ((lo + hi) * 0.5 - from).dot(dir));
    assert!(p.x.abs() < 1e-4 && p.y.abs() < 1e-4, "{p}");
    assert!((0.0..=1.0).contains(&p.z), "inside the depth range: {p}");
}
