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
            name: "floor".into(),
            mesh: rt_core::shapes::quad(Vec3::ZERO, Vec3::Y, 40.0).into(),
            material: pbr([0.8; 3], [0.0; 3]),
            transform: Default::default(),
        },
        Object {
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

/// The lamp is drawn in its emission's colour, brighter than the floor (it was black: only its
/// base colour was drawn); the floor, which lies in the grid's
/// plane, shows no grid lines (they were rows of dashes where the two fought for depth): over the
/// viewport away from the lamp, no pixel differs sharply from its neighbour.
#[test]
fn emitters_glow_and_the_grid_does_not_show_through_the_floor() {
    if !have_gpu() {
        return;
    }
    let mut harness = harness();
    harness.run_ok();
    harness
        .state_mut()
        .doc
        .edit("floor and lamp", "scene", |s| *s = floor_and_lamp());
    harness.state_mut().selection = None;
    harness.run_ok();
    let image = harness.render().unwrap();
    let dir = std::path::Path::new(env!("CARGO_TARGET_TMPDIR"));
    image.save(dir.join("editor-floor-and-lamp.png")).unwrap();
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
        "{lamp} lamp and {floor} floor samples: the lamp should glow (screenshot in {})",
        dir.display()
    );
    assert!(
        edges < floor / 200,
        "{edges} of {floor} floor samples at a sharp edge: grid lines through the floor? \
         (screenshot in {})",
        dir.display()
    );
}
