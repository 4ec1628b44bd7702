//! The projections (`camera::Projection`) against what they must show: an orthographic camera sees
//! a card the same size at any distance, a fisheye maps angle linearly to its image circle (and
//! nothing outside it), a panorama wraps around with its left and right edges meeting. Each image is
//! rendered by the GPU kernels and by the Rust twin (the CPU backend's estimator).

use super::*;
use rt_core::camera::Projection;

const LE: f32 = 2.0;

fn emitter() -> Material {
    Material::Emissive {
        color: [1.0; 3],
        intensity: LE,
    }
}

/// The image's red channel per pixel from the Rust twin, `spp` samples each.
fn render_rust(scene: &rt_core::Scene) -> Vec<f32> {
    let g = GpuScene::build(scene).unwrap();
    let mut frame = rt_core::frame::frame_for(scene, &g).unwrap();
    frame.samples_this_dispatch = scene.settings.samples_per_pixel;
    let (w, h, spp) = (frame.width, frame.height, scene.settings.samples_per_pixel);
    (0..w * h)
        .map(|i| {
            let sum: f32 = (0..spp)
                .map(|s| rt_core::estimator::radiance(&g, &frame, i % w, i / w, s).x)
                .sum();
            sum / spp as f32
        })
        .collect()
}

/// The red channel per pixel from both backends: the GPU's (when an adapter is found) and the
/// Rust twin's.
fn both_images(scene: &rt_core::Scene) -> Vec<(&'static str, Vec<f32>)> {
    let mut out = vec![("Rust twin", render_rust(scene))];
    if let Some(ctx) = gpu() {
        let image = render(ctx, scene);
        out.push(("GPU", image.pixels.iter().map(|p| p[0]).collect()));
    }
    out
}

fn looking_down_minus_z(projection: Projection, width: u32, height: u32) -> rt_core::Scene {
    let mut cam = camera(Vec3::ZERO, Vec3::new(0.0, 0.0, -1.0), 40.0);
    cam.projection = projection;
    scene(Vec::new(), cam, [0.0; 3], settings(width, height, 16, 1))
}

/// A 1 × 1 emissive card seen by an orthographic camera 4 units high on a 64² image covers exactly
/// its 16 × 16 pixels, whether it stands 2 or 200 units away (a perspective view would shrink it
/// 100-fold in area).
#[test]
fn an_orthographic_camera_sees_a_card_at_its_true_size_at_any_distance() {
    for distance in [2.0, 200.0] {
        let mut scene = looking_down_minus_z(Projection::Orthographic, 64, 64);
        scene.camera.ortho_height = Some(4.0);
        scene.objects.push(object(
            "card",
            quad(Vec3::new(0.0, 0.0, -distance), Vec3::Z, 1.0),
            emitter(),
        ));
        for (backend, image) in both_images(&scene) {
            let lit = image.iter().filter(|v| **v > LE * 0.5).count();
            let total: f32 = image.iter().sum();
            assert_eq!(lit, 256, "{backend}, card at {distance}: lit pixels");
            assert!(
                (total - 256.0 * LE).abs() <= 1e-3 * 256.0 * LE,
                "{backend}, card at {distance}: total {total}, expected {}",
                256.0 * LE
            );
            for y in 24..40 {
                for x in 24..40 {
                    assert_eq!(image[y * 64 + x], LE, "{backend}: pixel ({x}, {y})");
                }
            }
        }
    }
}

/// An equidistant fisheye of 180° sees a sphere of radius 1 at distance 2 on its axis (half-angle
/// 30°) as a disc one third of the image circle's radius: π/36 of a square image. An equisolid or
/// stereographic lens would show it 20–40% larger; a perspective view 33% larger.
#[test]
fn a_fisheye_maps_the_angle_from_its_axis_linearly_to_the_image_circle() {
    let mut scene = looking_down_minus_z(Projection::Fisheye, 96, 96);
    scene.camera.fisheye_angle_deg = 180.0;
    let mut ball = object("ball", uv_sphere(1.0, 96, 192), emitter());
    ball.transform.translation = [0.0, 0.0, -2.0];
    scene.objects.push(ball);
    let expected = std::f32::consts::PI / 36.0;
    for (backend, image) in both_images(&scene) {
        let share = image.iter().sum::<f32>() / (LE * image.len() as f32);
        assert!(
            (share - expected).abs() <= 0.02 * expected,
            "{backend}: the ball covers {share} of the image, expected {expected}"
        );
    }
}

/// Outside the fisheye's image circle nothing is seen: under a uniform sky of 1 the image's mean
/// is the circle's share of it, π/(4 × 1.5) on a 3:2 image (the circle as high as the image), and
/// the corners are black.
#[test]
fn a_fisheye_sees_nothing_outside_its_image_circle() {
    let mut scene = looking_down_minus_z(Projection::Fisheye, 96, 64);
    scene.ambient = [1.0; 3];
    let expected = std::f32::consts::PI / 6.0;
    for (backend, image) in both_images(&scene) {
        let share = image.iter().sum::<f32>() / image.len() as f32;
        assert!(
            (share - expected).abs() <= 0.005,
            "{backend}: mean {share}, expected {expected}"
        );
        assert_eq!(image[0], 0.0, "{backend}: corner");
        assert_eq!(image[96 * 32 + 48], 1.0, "{backend}: centre");
        assert_eq!(image[96 * 32 + 2], 0.0, "{backend}: left of the circle");
    }
}

/// A panorama wraps around: a card behind the camera (above its horizon) appears split between
/// the left and right edges in equal parts, nothing of it in the middle; a floor below fills the
/// lower half.
#[test]
fn a_panoramas_left_and_right_edges_meet_behind_the_camera() {
    let (w, h) = (256u32, 128u32);
    let mut scene = looking_down_minus_z(Projection::Panorama, w, h);
    scene.objects.push(object(
        "behind",
        quad(Vec3::new(0.0, 1.0, 3.0), Vec3::NEG_Z, 1.0),
        emitter(),
    ));
    scene.objects.push(object(
        "floor",
        quad(Vec3::new(0.0, -1.0, 0.0), Vec3::Y, 2000.0),
        Material::Emissive {
            color: [1.0; 3],
            intensity: 1.0,
        },
    ));
    for (backend, image) in both_images(&scene) {
        let at = |x: u32, y: u32| image[(y * w + x) as usize];
        let upper: f32 = (0..h / 2)
            .flat_map(|y| (0..w).map(move |x| (x, y)))
            .map(|(x, y)| at(x, y))
            .sum();
        let left: f32 = (0..h / 2)
            .flat_map(|y| (0..w / 2).map(move |x| (x, y)))
            .map(|(x, y)| at(x, y))
            .sum();
        let right = upper - left;
        let middle: f32 = (0..h / 2).map(|y| at(w / 2, y) + at(w / 2 - 1, y)).sum();
        assert!(
            left > 20.0 * LE,
            "{backend}: the card barely shows ({left})"
        );
        assert!(
            (left - right).abs() <= 0.02 * (left + right),
            "{backend}: left edge {left}, right edge {right}"
        );
        assert_eq!(middle, 0.0, "{backend}: the card seen ahead");
        let lower: f32 = (h / 2 + 1..h)
            .flat_map(|y| (0..w).map(move |x| (x, y)))
            .map(|(x, y)| at(x, y))
            .sum();
        let lower_mean = lower / ((h / 2 - 1) * w) as f32;
        assert!(
            (lower_mean - 1.0).abs() <= 1e-4,
            "{backend}: the floor's mean {lower_mean}"
        );
    }
}
