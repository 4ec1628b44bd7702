//! Shadow catchers against closed forms: a floor that catches the shadow of a sphere under a sun
//! straight above and a uniform sky.

use std::sync::Arc;
use std::sync::atomic::AtomicBool;

use glam::Vec3;

use crate::cpu_render::CpuAccumulation;
use crate::light::{Light, LightKind};
use crate::scene::{Object, RenderSettings, Scene, Transform};
use crate::shapes::{quad, uv_sphere};
use crate::{Camera, GpuScene, Material};

const SPHERE_RADIUS: f32 = 0.5;
const SPHERE_HEIGHT: f32 = 2.0;
const SUN: f32 = 2.0;
const SKY: f32 = 0.3;
const SAMPLES: u32 = 1024;

/// A catcher floor at y = 0 seen at the point below the sphere's centre (one pixel, 0.2° wide),
/// the sphere `albedo` grey (`None`: no sphere), lit by a sun from straight above (E = `SUN`)
/// and a uniform sky (L = `SKY`), on a transparent film.
fn floor_under_sphere(albedo: Option<f32>) -> Scene {
    let object = |name: &str, mesh, material, translation, shadow_catcher| Object {
        name: name.into(),
        mesh: Arc::new(mesh),
        material,
        transform: Transform {
            translation,
            ..Default::default()
        },
        shadow_catcher,
        animation_node: None,
    };
    let mut objects = vec![object(
        "floor",
        quad(Vec3::ZERO, Vec3::Y, 20.0),
        Material::lambertian([0.8; 3]),
        [0.0; 3],
        true,
    )];
    if let Some(albedo) = albedo {
        objects.push(object(
            "sphere",
            uv_sphere(SPHERE_RADIUS, 96, 192),
            Material::lambertian([albedo; 3]),
            [0.0, SPHERE_HEIGHT, 0.0],
            false,
        ));
    }
    Scene {
        objects,
        textures: Vec::new(),
        camera: Camera {
            from: [0.0, 1.0, 6.0],
            to: [0.0; 3],
            vfov_deg: 0.2,
            ..Default::default()
        },
        ambient: [SKY; 3],
        settings: RenderSettings {
            width: 1,
            height: 1,
            max_depth: 4,
            transparent: true,
            ..Default::default()
        },
        lights: vec![sun()],
        environment: None,
        fog: Default::default(),
        animation: None,
    }
}

fn sun() -> Light {
    let mut sun = Light::new(LightKind::Directional, "sun");
    sun.direction = [0.0, -1.0, 0.0];
    sun.intensity = SUN;
    sun
}

/// The pixel's colour and alpha after `SAMPLES` samples.
fn render(scene: &Scene) -> ([f32; 4], f32) {
    let gpu = GpuScene::build(scene).unwrap();
    let frame = crate::frame::frame_for(scene, &gpu).unwrap();
    let mut film = CpuAccumulation::new(&frame, 0, None, true);
    assert!(film.add_batch(&gpu, &frame, SAMPLES, &AtomicBool::new(false)));
    let alpha = film.first_hits().unwrap().alpha(0);
    (film.pixels()[0], alpha)
}

/// Under the sphere the sun is blocked and the sky loses the sphere's cap, of half-angle
/// asin(r/h): E_lit = πL(1 − r²/h²) of E_free = πL + E_sun, so α = 1 − E_lit/E_free. The
/// tolerance is four standard deviations of the sky's visibility (a Bernoulli per sample; the
/// sun's is exact). A black sphere reflects nothing, so the catcher adds no colour: the sky and
/// the direct light it receives are in its alpha, not its colour.
#[test]
fn alpha_is_one_minus_the_shadowed_irradiance_ratio() {
    let (colour, alpha) = render(&floor_under_sphere(Some(0.0)));
    let sky = std::f32::consts::PI * SKY;
    let unshadowed = 1.0 - (SPHERE_RADIUS / SPHERE_HEIGHT).powi(2);
    let expected = 1.0 - sky * unshadowed / (sky + SUN);
    let sigma = sky * (unshadowed * (1.0 - unshadowed) / SAMPLES as f32).sqrt() / (sky + SUN);
    assert!(
        (alpha - expected).abs() < 4.0 * sigma,
        "alpha {alpha}, expected {expected} ± {}",
        4.0 * sigma
    );
    assert_eq!(&colour[..3], &[0.0; 3], "a black sphere's reflection");
}

/// Nothing casts a shadow: the catcher is wholly transparent (its samples' lit and free
/// irradiance are the same numbers) and adds no light.
#[test]
fn a_catcher_without_shadows_is_transparent() {
    let (colour, alpha) = render(&floor_under_sphere(None));
    assert_eq!(alpha, 0.0);
    assert_eq!(&colour[..3], &[0.0; 3]);
}

/// A white sphere's light reaches the camera by way of the catcher (its reflection and bounce
/// light), while the shadow is as deep as under a black one.
#[test]
fn a_catcher_shows_the_light_other_objects_send_it() {
    let (black, black_alpha) = render(&floor_under_sphere(Some(0.0)));
    let (white, white_alpha) = render(&floor_under_sphere(Some(0.9)));
    assert!(white[1] > 0.0 && black[1] == 0.0, "{white:?} {black:?}");
    assert_eq!(white_alpha, black_alpha);
}

/// On an opaque film the flag does nothing: the floor renders as its material.
#[test]
fn an_opaque_film_renders_the_catcher_as_its_material() {
    let mut scene = floor_under_sphere(None);
    scene.settings.transparent = false;
    let (colour, _) = render(&scene);
    scene.objects[0].shadow_catcher = false;
    let (plain, _) = render(&scene);
    assert_eq!(colour, plain);
    assert!(colour[1] > 0.0);
}

/// What a shadow catcher is for: its render laid over a photograph of the empty floor,
/// colour + (1 − α) · photo, is the render of the objects on an ordinary floor. On a Lambertian
/// floor under a sun and a uniform sky this holds in expectation pixel by pixel: the photo is
/// ρ/π E_free, the ratio turns it into ρ/π E_lit, and the colour adds ρ/π times the light the
/// objects send it (here a white sphere's, a tenth of the shadow's radiance). Z-test of the mean
/// difference over the floor's pixels, its standard error from the differences' spread (each
/// pixel's expected difference is zero; three renders with their own seeds).
#[test]
fn a_catcher_over_the_empty_floor_composites_to_the_full_render() {
    let mut scene = floor_under_sphere(Some(0.9));
    scene.objects[1].transform.translation = [0.0, 0.8, 0.0];
    scene.lights[0].direction = [0.5, -1.0, 0.2];
    scene.camera = Camera {
        from: [0.0, 4.0, 3.0],
        to: [0.4, 0.0, 0.0],
        vfov_deg: 40.0,
        ..Default::default()
    };
    (scene.settings.width, scene.settings.height) = (24, 24);
    let render = |scene: &Scene, seed: u32| {
        let mut scene = scene.clone();
        scene.settings.seed = seed;
        let gpu = GpuScene::build(&scene).unwrap();
        let frame = crate::frame::frame_for(&scene, &gpu).unwrap();
        let mut film = CpuAccumulation::new(&frame, 0, None, true);
        assert!(film.add_batch(&gpu, &frame, 128, &AtomicBool::new(false)));
        let hits = film.first_hits().unwrap().clone();
        (film.pixels(), hits)
    };
    let (caught, hits) = render(&scene, 1);
    let mut ordinary = scene.clone();
    ordinary.settings.transparent = false;
    ordinary.objects[0].shadow_catcher = false;
    let (truth, _) = render(&ordinary, 2);
    ordinary.objects.truncate(1);
    let (photo, _) = render(&ordinary, 3);
    let floor: Vec<usize> = (0..caught.len())
        .filter(|&i| hits.caught[i][0] == 1.0)
        .collect();
    let shadowed = floor.iter().filter(|&&i| hits.alpha(i) > 0.5).count();
    assert!(
        floor.len() > 300 && shadowed > 20,
        "{} {shadowed}",
        floor.len()
    );
    for c in 0..3 {
        let d: Vec<f64> = floor
            .iter()
            .map(|&i| {
                let composite = caught[i][c] + (1.0 - hits.alpha(i)) * photo[i][c];
                f64::from(composite - truth[i][c])
            })
            .collect();
        let n = d.len() as f64;
        let mean = d.iter().sum::<f64>() / n;
        let var = d.iter().map(|x| (x - mean).powi(2)).sum::<f64>() / (n - 1.0);
        let z = mean / (var / n).sqrt();
        assert!(z.abs() < 4.0, "channel {c}: mean difference {mean}, z {z}");
    }
}
