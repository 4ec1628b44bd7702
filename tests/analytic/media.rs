//! Participating media with known answers: fog and a volume that only scatter leave a closed glowing
//! room as bright as it was (a furnace), and a slab or fog that only absorbs dims a lens-filling
//! emitter by exp(−σ_t d) per channel.

use super::*;
use rt_core::gpu_types::Medium;
use rt_core::shapes::cuboid;

/// Inside a closed room of albedo a = ½ emitting Le = ½ the radiance is Le/(1 − a) = 1 everywhere.
/// Fog that scatters without absorbing changes where light goes, never how much: with any density
/// and anisotropy the room stays 1, and so it does with a scattering ball (its interior medium,
/// entered and left through index-matched glass) in the fog, and with a white subsurface-scattering
/// ball behind a refracting boundary. Paths run until Russian roulette ends
/// them, so every scattering order counts.
#[test]
fn scattering_media_keep_a_glowing_room_as_bright() {
    let Some(ctx) = gpu() else { return };
    let room = cuboid(Vec3::splat(-1.0), Vec3::splat(1.0), true);
    let ball = uv_sphere(0.5, 12, 24);
    let glass = Material::Dielectric {
        ior: 1.0,
        tint: [1.0; 3],
    };
    // Subsurface scattering: white inside, behind a smooth boundary of index 1.4 (Fresnel and total
    // internal reflection at every crossing), radius per channel.
    let mut facets = ball.clone();
    facets.normals = None; // flat: shading normals would lose energy at grazing angles
    let skin = pbr(rt_core::material::Pbr {
        base_color: [1.0; 3],
        roughness: 0.0,
        ior: 1.4,
        subsurface: 1.0,
        subsurface_radius: [0.2, 0.1, 0.05],
        scatter_anisotropy: 0.4,
        ..Default::default()
    });
    for (density, g, ball_density, subsurface) in [
        (0.6, 0.0, 0.0, false),
        (3.0, 0.85, 0.0, false),
        (1.5, -0.6, 0.0, false),
        (0.4, 0.3, 8.0, false),
        (0.2, 0.0, 0.0, true),
    ] {
        let mut objects = vec![object("room", room.clone(), Material::lambertian([0.5; 3]))];
        if ball_density > 0.0 {
            objects.push(object("ball", ball.clone(), glass.clone()));
        }
        if subsurface {
            objects.push(object("skin", facets.clone(), skin.clone()));
        }
        let mut scene = scene(
            objects,
            camera(Vec3::new(0.1, 0.7, 0.8), Vec3::new(0.0, -0.2, -1.0), 90.0),
            [0.0; 3],
            settings(16, 16, 64, 100_000),
        );
        scene.settings.russian_roulette = true;
        scene.fog = rt_core::fog::Fog {
            density,
            albedo: [1.0; 3],
            anisotropy: g,
        };
        let mut gpu_scene = GpuScene::build(&scene).unwrap();
        gpu_scene.materials[0].emission = [0.5; 3];
        if ball_density > 0.0 {
            gpu_scene.materials[1].medium = Medium {
                sigma_t: [ball_density; 3],
                anisotropy: 0.5,
                sigma_s: [ball_density; 3],
                _pad: 0.0,
            };
            gpu_scene.features.media = true;
        }
        let image = render_gpu(ctx, &scene, &gpu_scene, RenderOptions::default());
        let what =
            format!("fog σ_t {density} g {g}, ball σ_t {ball_density}, subsurface {subsurface}");
        assert_mean(&image, 1.0, &what);
        // The CPU twin too (it shares the GPU's random numbers, not its arithmetic).
        let frame = rt_core::frame::frame_for(&scene, &gpu_scene).unwrap();
        let cpu = rt_core::estimator::render(&gpu_scene, &frame, 16);
        let n = cpu.mean.len() as f64;
        let mean = cpu.mean.iter().map(|p| f64::from(p[0])).sum::<f64>() / n;
        let var = cpu.variance.iter().map(|v| f64::from(v[0])).sum::<f64>() / (n * n * 16.0);
        assert!(
            (mean - 1.0).abs() <= 4.0 * var.sqrt() + 1e-6,
            "{what}, CPU: mean {mean} (σ {})",
            var.sqrt()
        );
    }
}

/// A lens-filling emitter seen through a slab 0.5 thick whose volume absorbs with attenuation
/// colour c at distance 1 (σ_t = −ln c) shows Le·c^½ per channel; from a camera inside such a
/// volume, 1.25 from its far side, Le·c^1.25; through fog of density 0.7 that only absorbs, over a
/// distance of 2, Le·e^−1.4. Index-matched (IOR 1), so nothing reflects;
/// a 2° view, so every ray crosses the same thickness (within 2·10⁻⁴).
#[test]
fn absorbing_slab_and_fog_follow_beer_lambert_per_channel() {
    let Some(ctx) = gpu() else { return };
    let le = [0.5f32, 1.0, 2.0];
    let emitter = object(
        "emitter",
        quad(Vec3::new(0.0, 0.0, -2.0), Vec3::Z, 100.0),
        Material::Emissive {
            color: le,
            intensity: 1.0,
        },
    );
    let c = [0.2f32, 0.5, 0.8];
    let slab = object(
        "slab",
        cuboid(
            Vec3::new(-10.0, -10.0, -1.25),
            Vec3::new(10.0, 10.0, -0.75),
            false,
        ),
        pbr(rt_core::material::Pbr {
            base_color: [1.0; 3],
            roughness: 0.0,
            transmission: 1.0,
            ior: 1.0,
            attenuation_color: c,
            attenuation_distance: Some(1.0),
            ..Default::default()
        }),
    );
    let view = camera(Vec3::ZERO, Vec3::new(0.0, 0.0, -1.0), 2.0);
    let through_slab = scene(
        vec![emitter.clone(), slab],
        view.clone(),
        [0.0; 3],
        settings(8, 8, 4, 4),
    );
    let want: Vec<f32> = (0..3).map(|k| le[k] * c[k].sqrt()).collect();
    assert_all_pixels(
        &render(ctx, &through_slab),
        [want[0], want[1], want[2]],
        1e-3,
        "slab",
    );
    // The camera under water: inside the volume (its probe rays meet its inside first), 1.25 units
    // of it before the emitter.
    let mut water = through_slab.clone();
    water.objects[1].mesh = std::sync::Arc::new(cuboid(
        Vec3::new(-10.0, -10.0, -1.25),
        Vec3::new(10.0, 10.0, 0.5),
        false,
    ));
    {
        let g = GpuScene::build(&water).unwrap();
        let frame = rt_core::frame::frame_for(&water, &g).unwrap();
        assert_eq!(frame.camera_media, 2, "inside material 1");
    }
    let want: Vec<f32> = (0..3).map(|k| le[k] * c[k].powf(1.25)).collect();
    assert_all_pixels(
        &render(ctx, &water),
        [want[0], want[1], want[2]],
        1e-3,
        "camera inside the volume",
    );
    let mut in_fog = scene(vec![emitter], view, [0.0; 3], settings(8, 8, 4, 4));
    in_fog.fog = rt_core::fog::Fog {
        density: 0.7,
        albedo: [0.0; 3],
        anisotropy: 0.0,
    };
    let t = (-1.4f32).exp();
    assert_all_pixels(
        &render(ctx, &in_fog),
        [le[0] * t, le[1] * t, le[2] * t],
        1e-3,
        "absorbing fog",
    );
}

/// Media at numerical extremes and a volume that never closes render finite pixels on both
/// backends: fog far thinner and far denser than the scene (10⁻³⁰ and 10³⁰ per unit), a forward
/// peak of g = 0.999, a one-sided transmissive quad (entered, never left: its interior fills the
/// rest of the path, documented), and a scattering volume behind it.
#[test]
fn media_at_extremes_and_an_open_volume_stay_finite() {
    let Some(ctx) = gpu() else { return };
    let pane = pbr(rt_core::material::Pbr {
        base_color: [1.0; 3],
        roughness: 0.1,
        transmission: 1.0,
        attenuation_color: [0.3, 0.6, 0.9],
        attenuation_distance: Some(0.5),
        multiscatter_color: [0.9, 0.9, 0.9],
        scatter_anisotropy: 0.999 - 1e-4,
        ..Default::default()
    });
    let lamp = Material::Emissive {
        color: [4.0; 3],
        intensity: 1.0,
    };
    for (density, g) in [(1e-30, 0.0), (1e30, 0.5), (0.5, 0.999), (0.5, -0.999)] {
        let mut s = scene(
            vec![
                object(
                    "pane",
                    quad(Vec3::new(0.0, 0.0, -1.0), Vec3::Z, 1.5),
                    pane.clone(),
                ),
                object(
                    "lamp",
                    quad(Vec3::new(0.0, 1.0, -2.0), -Vec3::Y, 1.0),
                    lamp.clone(),
                ),
                object(
                    "floor",
                    quad(Vec3::new(0.0, -1.0, -2.0), Vec3::Y, 6.0),
                    Material::lambertian([0.5; 3]),
                ),
            ],
            camera(Vec3::ZERO, Vec3::new(0.0, 0.0, -1.0), 70.0),
            [0.2; 3],
            settings(12, 12, 8, 12),
        );
        s.fog = rt_core::fog::Fog {
            density,
            albedo: [0.9, 0.7, 1.0],
            anisotropy: g,
        };
        let what = format!("fog {density} g {g}");
        let image = render(ctx, &s);
        assert!(
            image
                .pixels
                .iter()
                .all(|p| p[..3].iter().all(|v| v.is_finite() && *v >= 0.0)),
            "{what}: a pixel is not finite on the GPU"
        );
        let gpu_scene = GpuScene::build(&s).unwrap();
        let frame = rt_core::frame::frame_for(&s, &gpu_scene).unwrap();
        let cpu = rt_core::estimator::render(&gpu_scene, &frame, 8);
        assert!(
            cpu.mean
                .iter()
                .flatten()
                .all(|v| v.is_finite() && *v >= 0.0),
            "{what}: a pixel is not finite on the CPU"
        );
    }
}
