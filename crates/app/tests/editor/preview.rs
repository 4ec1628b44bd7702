//! The raster preview against what a newcomer expects of it: emitters glow, the grid stays out of
//! the floor.

use super::*;
use glam::Vec3;
use rt_core::material::Pbr;
use rt_core::{Material, Object};

/// A large white floor seen from straight above, and on it a lamp: a PBR quad with a black base
/// colour and an orange emission (as Blender exports a lamp shade), under a dim ambient.
fn floor_and_lamp() -> rt_core::Scene {
    let mut scene = rt_core::Scene::default();
    let pbr = |base_color: [f32; 3], emission: [f32; 3]| {
        Material::Pbr(Box::new(Pbr {
            base_color,
            roughness: 1.0,
            emission,
            emission_strength: 4.0,
            ..Default::default()
        }))
    };
    scene.objects = vec![
        Object {
            shadow_catcher: false,
            animation_node: None,
            name: "floor".into(),
            mesh: rt_core::shapes::quad(Vec3::ZERO, Vec3::Y, 40.0).into(),
            material: pbr([0.8; 3], [0.0; 3]),
            transform: Default::default(),
        },
        Object {
            shadow_catcher: false,
            animation_node: None,
            name: "lamp".into(),
            mesh: rt_core::shapes::quad(Vec3::new(0.0, 0.5, 0.0), Vec3::Y, 2.0).into(),
            material: pbr([0.0; 3], [1.0, 0.5, 0.1]),
            transform: Default::default(),
        },
    ];
    scene.camera.from = [0.0, 8.0, 0.0];
    scene.camera.to = [0.0, 0.0, 0.0];
    scene.camera.up = [0.0, 0.0, -1.0];
    scene.camera.vfov_deg = 60.0;
    scene.ambient = [0.4; 3];
    scene
}

/// The editor showing `scene` with nothing selected, and a screenshot of it saved as `name` (the
/// path returned) for a failing test to point at.
fn editor_on(
    scene: rt_core::Scene,
    name: &str,
) -> (Harness<'static, RtApp>, image::RgbaImage, String) {
    let mut harness = harness();
    harness.run_ok();
    harness
        .state_mut()
        .doc
        .edit("test scene", "scene", |s| *s = scene);
    harness.state_mut().selection = None;
    harness.run_ok();
    let image = harness.render().expect("the editor renders");
    let path = std::path::Path::new(env!("CARGO_TARGET_TMPDIR")).join(name);
    image.save(&path).expect("the screenshot is saved");
    (harness, image, path.display().to_string())
}

/// The lamp is drawn in its emission's colour, brighter than the floor (it was black: only its
/// base colour was drawn); the floor, which lies in the grid's
/// plane, shows no grid lines (they were rows of dashes where the two fought for depth): over the
/// viewport away from the lamp, no pixel differs sharply from its neighbour.
#[test]
fn emitters_glow_and_the_grid_does_not_show_through_the_floor() {
    if !have_gpu() {
        return;
    }
    let (_harness, image, screenshot) = editor_on(floor_and_lamp(), "editor-floor-and-lamp.png");
    let (w, h) = image.dimensions();
    let pixel = |x: u32, y: u32| image.get_pixel(x, y).0.map(i32::from);
    // Brighter than the white floor and warm (the display's tone curve pales the orange).
    let orange = |[r, g, b, _]: [i32; 4]| r > 230 && r >= g && g > b + 15;
    // The viewport lies between the side panels; the lamp at its centre.
    let (x0, x1, y0, y1) = (w / 4, w * 3 / 4, h / 5, h * 4 / 5);
    let mut lamp = 0;
    let mut edges = 0;
    let mut floor = 0;
    for y in (y0..y1).step_by(2) {
        for x in (x0..x1).step_by(2) {
            let p = pixel(x, y);
            if orange(p) {
                lamp += 1;
                continue;
            }
            // Away from the lamp's outline: the floor and its neighbours.
            let around = [
                pixel(x + 2, y),
                pixel(x, y + 2),
                pixel(x - 2, y),
                pixel(x, y - 2),
            ];
            if around.iter().any(|q| orange(*q)) {
                continue;
            }
            floor += 1;
            if around
                .iter()
                .any(|q| (0..3).any(|c| (q[c] - p[c]).abs() > 24))
            {
                edges += 1;
            }
        }
    }
    assert!(
        lamp > 200 && floor > 5000,
        "{lamp} lamp and {floor} floor samples: the lamp should glow (screenshot {screenshot})"
    );
    assert!(
        edges < floor / 200,
        "{edges} of {floor} floor samples at a sharp edge: grid lines through the floor? \
         (screenshot {screenshot})"
    );
}

/// A spot lights only its cone: the floor seen from above, lit by a spot straight overhead with a
/// 15° outer cone and no ambient light, is bright under it and dark in the viewport's corners
/// (drawn as a point light, as it was, the corners got 28% of the centre's irradiance).
#[test]
fn a_spot_lights_only_its_cone() {
    use rt_core::{Light, LightKind};
    if !have_gpu() {
        return;
    }
    let mut scene = floor_and_lamp();
    scene.objects.truncate(1);
    scene.ambient = [0.0; 3];
    let mut spot = Light::new(LightKind::Spot, "spot");
    spot.position = [0.0, 4.0, 0.0];
    spot.direction = [0.0, -1.0, 0.0];
    spot.inner_angle_deg = 10.0;
    spot.outer_angle_deg = 15.0;
    spot.intensity = 50.0;
    scene.lights = vec![spot];
    let (_harness, image, screenshot) = editor_on(scene, "editor-floor-and-spot.png");
    let (w, h) = image.dimensions();
    // The mean green level over a small square at (x, y), in fractions of the window.
    let level = |fx: f32, fy: f32| {
        let (cx, cy) = ((fx * w as f32) as u32, (fy * h as f32) as u32);
        let mut sum = 0u32;
        for y in cy - 4..cy + 4 {
            for x in cx - 4..cx + 4 {
                sum += u32::from(image.get_pixel(x, y).0[1]);
            }
        }
        sum / 64
    };
    // The viewport's centre (between the side panels) and its corners.
    let centre = level(0.5, 0.5);
    let corners =
        [(0.27, 0.22), (0.73, 0.22), (0.27, 0.78), (0.73, 0.78)].map(|(x, y)| level(x, y));
    assert!(
        centre > 170 && corners.iter().all(|&c| c < 110),
        "centre {centre}, corners {corners:?} (screenshot {screenshot})"
    );
}

/// Lights have marks in the viewport, and clicking one selects its light (the inspector then
/// shows it, and G moves it); a click on the floor beside it selects the floor.
#[test]
fn clicking_a_light_mark_selects_the_light() {
    use rt_core::{Light, LightKind};
    if !have_gpu() {
        return;
    }
    let mut scene = floor_and_lamp();
    scene.objects.truncate(1);
    let mut point = Light::new(LightKind::Point, "bulb");
    point.position = [1.5, 2.0, 1.0];
    point.intensity = 5.0;
    scene.lights = vec![point];
    let (mut harness, _, _) = editor_on(scene, "editor-floor-and-bulb.png");
    let rect = harness
        .state()
        .ui
        .viewport_rect
        .expect("the viewport was drawn");
    let mark = rt_app::ui::light_marks::anchor_on_screen(harness.state(), rect, 0)
        .expect("the bulb is in view");
    assert!(rect.contains(mark));
    let click = |harness: &mut Harness<'_, RtApp>, pos: egui::Pos2| {
        harness.drag_at(pos);
        harness.step();
        harness.drop_at(pos);
        harness.run_ok();
    };
    click(&mut harness, mark);
    assert_eq!(harness.state().selected_light, Some(0));
    assert_eq!(harness.state().selection, None);
    let image = harness.render().unwrap();
    let [r, g, b, _] = image
        .get_pixel(mark.x.round() as u32, mark.y.round() as u32)
        .0;
    assert!(
        r > 200 && g > 100 && b < 80,
        "the selected mark is orange: {r} {g} {b}"
    );
    // G moves the selected light as it moves objects.
    for key in [egui::Key::G, egui::Key::Z] {
        harness.key_press(key);
        harness.step();
    }
    harness.event(egui::Event::Text("-1".into()));
    harness.step();
    harness.key_press(egui::Key::Enter);
    harness.run_ok();
    assert_eq!(
        harness.state().doc.scene.lights[0].position,
        [1.5, 2.0, 0.0]
    );
    let mark = rt_app::ui::light_marks::anchor_on_screen(harness.state(), rect, 0).unwrap();
    click(&mut harness, mark + egui::vec2(60.0, 60.0));
    assert_eq!(harness.state().selected_light, None);
    assert_eq!(harness.state().selection, Some(0), "the floor");
}

/// Fog in the raster preview, as in the render: thick smoke (it only absorbs) darkens everything
/// behind it, the lamp included; thick white fog hides the lamp in an even glow.
#[test]
fn fog_hazes_the_preview() {
    if !have_gpu() {
        return;
    }
    let centre_stats = |image: &image::RgbaImage| {
        let (w, h) = image.dimensions();
        let values: Vec<f64> = (h * 2 / 5..h * 3 / 5)
            .flat_map(|y| (w * 2 / 5..w * 3 / 5).map(move |x| (x, y)))
            .map(|(x, y)| {
                let p = image.get_pixel(x, y).0;
                (f64::from(p[0]) + f64::from(p[1]) + f64::from(p[2])) / 3.0
            })
            .collect();
        let n = values.len() as f64;
        let mean = values.iter().sum::<f64>() / n;
        let spread = (values.iter().map(|v| (v - mean).powi(2)).sum::<f64>() / n).sqrt();
        (mean, spread)
    };
    let (_h, clear, _) = editor_on(floor_and_lamp(), "editor-fog-clear.png");
    let (clear_mean, clear_spread) = centre_stats(&clear);
    let mut smoke = floor_and_lamp();
    smoke.fog = rt_core::fog::Fog {
        density: 1.0,
        albedo: [0.0; 3],
        anisotropy: 0.0,
    };
    let (_h, smoky, shot) = editor_on(smoke, "editor-fog-smoke.png");
    let (smoke_mean, _) = centre_stats(&smoky);
    assert!(
        smoke_mean < 0.25 * clear_mean,
        "smoke {smoke_mean} against {clear_mean} without it (screenshot {shot})"
    );
    let mut white = floor_and_lamp();
    white.fog = rt_core::fog::Fog {
        density: 1.0,
        ..Default::default()
    };
    let (_h, foggy, shot) = editor_on(white, "editor-fog-white.png");
    let (fog_mean, fog_spread) = centre_stats(&foggy);
    assert!(
        fog_mean > 2.0 * smoke_mean && fog_spread < 0.25 * clear_spread,
        "white fog: mean {fog_mean}, spread {fog_spread} against {clear_spread} clear \
         (screenshot {shot})"
    );
}
