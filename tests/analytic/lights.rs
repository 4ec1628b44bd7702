//! Directional, point, spot and sun-and-sky light with known answers, and the Sobol sampler's
//! lower error on smooth lighting.

use super::*;

fn lit_plane(light: rt_core::Light, from: Vec3, vfov: f32) -> rt_core::Scene {
    let mut s = scene(
        vec![object(
            "plane",
            quad(Vec3::ZERO, Vec3::Y, 100.0),
            Material::lambertian([0.5; 3]),
        )],
        camera(from, Vec3::ZERO, vfov),
        [0.0; 3],
        settings(8, 8, 4, 2),
    );
    s.lights.push(light);
    s
}

/// A sun of irradiance E at 60° from the normal lights a diffuse plane of albedo ρ with radiance
/// ρ/π · E cos60° everywhere: exactly, with no noise (a delta light has one sample).
#[test]
fn a_directional_light_gives_the_lambert_cosine_law_exactly() {
    let Some(ctx) = gpu() else { return };
    let angle = 60f32.to_radians();
    let mut sun = rt_core::Light::new(rt_core::LightKind::Directional, "sun");
    sun.direction = [angle.sin(), -angle.cos(), 0.0];
    sun.color = [1.0, 0.5, 0.25];
    sun.intensity = 3.0;
    let s = lit_plane(sun, Vec3::new(0.0, 5.0, 0.001), 30.0);
    let e = 0.5 / std::f32::consts::PI * 3.0 * angle.cos();
    assert_all_pixels(&render(ctx, &s), [e, e * 0.5, e * 0.25], 1e-5, "sun");
}

/// A point light of intensity I at height h over the plane: the point straight below receives
/// E = I/h², so radiance ρ/π · I/h² (a narrow view so every pixel sees the point below, within
/// 1e-4 of it). A spot light pointing away gives nothing; pointing down within its inner cone it
/// equals the point light; an occluder casts an exact shadow.
#[test]
fn point_and_spot_lights_follow_the_inverse_square_law_and_cast_shadows() {
    let Some(ctx) = gpu() else { return };
    let h = 2.0;
    let mut point = rt_core::Light::new(rt_core::LightKind::Point, "bulb");
    point.position = [0.0, h, 0.0];
    point.intensity = 8.0;
    let from = Vec3::new(0.0, 10.0, 0.0001);
    let s = lit_plane(point.clone(), from, 0.01);
    let expected = 0.5 / std::f32::consts::PI * 8.0 / (h * h);
    assert_all_pixels(
        &render(ctx, &s),
        [expected; 3],
        expected * 1e-4,
        "point light",
    );

    let mut spot = point.clone();
    spot.kind = rt_core::LightKind::Spot;
    spot.direction = [0.0, -1.0, 0.0];
    let s = lit_plane(spot.clone(), from, 0.01);
    assert_all_pixels(
        &render(ctx, &s),
        [expected; 3],
        expected * 1e-4,
        "spot, inside",
    );
    spot.direction = [1.0, 0.0, 0.0];
    let s = lit_plane(spot, from, 0.01);
    assert_all_pixels(&render(ctx, &s), [0.0; 3], 0.0, "spot pointing away");

    let mut shadowed = lit_plane(point, from, 0.01);
    shadowed.objects.push(object(
        "blocker",
        quad(Vec3::new(0.0, 1.0, 0.0), Vec3::Y, 0.5),
        Material::lambertian([0.0; 3]),
    ));
    // The camera sees the blocker's black top; move it to see the plane under it from the side.
    shadowed.camera = camera(Vec3::new(0.0, 0.5, 3.0), Vec3::ZERO, 0.01);
    assert_all_pixels(&render(ctx, &shadowed), [0.0; 3], 0.0, "shadow");
}

/// On smooth lighting (a plane under a large area light, direct light only) Owen-scrambled Sobol
/// points converge faster than independent samples: at 64 spp the squared error against a
/// 4096-spp reference is less than half, and its image mean matches the reference's.
#[test]
fn the_sobol_sampler_has_less_error_on_smooth_lighting() {
    let Some(ctx) = gpu() else { return };
    let mut s = scene(
        vec![
            object(
                "floor",
                quad(Vec3::ZERO, Vec3::Y, 4.0),
                Material::lambertian([0.7; 3]),
            ),
            object(
                "panel",
                quad(Vec3::new(0.3, 1.5, 0.0), -Vec3::Y, 2.0),
                Material::Emissive {
                    color: [1.0; 3],
                    intensity: 3.0,
                },
            ),
        ],
        camera(Vec3::new(0.0, 1.0, 3.0), Vec3::ZERO, 50.0),
        [0.0; 3],
        settings(32, 32, 4096, 2),
    );
    s.settings.russian_roulette = false;
    let reference = render(ctx, &s);
    let error = |image: &rt_gpu::Image| -> f64 {
        image
            .pixels
            .iter()
            .zip(&reference.pixels)
            .map(|(a, b)| (f64::from(a[1]) - f64::from(b[1])).powi(2))
            .sum::<f64>()
            / image.pixels.len() as f64
    };
    s.settings.samples_per_pixel = 64;
    s.settings.seed = 7;
    s.settings.sampler = rt_core::math::rng::SamplerKind::Independent;
    let independent = render(ctx, &s);
    s.settings.sampler = rt_core::math::rng::SamplerKind::Sobol;
    let sobol = render(ctx, &s);
    let (e_ind, e_sob) = (error(&independent), error(&sobol));
    assert!(
        e_sob < 0.5 * e_ind,
        "Sobol's squared error {e_sob:.3e} is not below half the independent {e_ind:.3e}"
    );
    // Unbiased: the image mean matches the reference's within 5 standard errors (pixels are
    // scrambled independently, so the mean's error is about sqrt(error / pixels)).
    let mean = |image: &rt_gpu::Image| image.channel_means()[1];
    let tolerance = 5.0 * (e_ind / reference.pixels.len() as f64).sqrt();
    assert!(
        (mean(&sobol) - mean(&reference)).abs() <= tolerance,
        "Sobol's image mean {} differs from the reference {} by more than {tolerance}",
        mean(&sobol),
        mean(&reference)
    );
}

/// A white Lambertian plane under the physical sun and sky (strength 1) reflects ρ/π times the
/// horizontal irradiance of the map it is lit by: Σ over the upper rows' texels of L ∫cosθ dω,
/// exact for the piecewise-constant map (the sun's disk included). Seen from 45° above; each channel's
/// image mean within 4 standard errors of the pixels' spread.
#[test]
fn a_white_plane_under_the_sun_and_sky_reflects_its_irradiance() {
    let Some(ctx) = gpu() else { return };
    let sky = rt_core::sky::SunSky {
        elevation_deg: 40.0,
        turbidity: 3.0,
    };
    let mut env = sky.environment();
    env.strength = 1.0;
    let map = env.map.clone();
    let mut s = scene(
        vec![object(
            "plane",
            quad(Vec3::ZERO, Vec3::Y, 1000.0),
            Material::lambertian([0.5; 3]),
        )],
        camera(Vec3::new(0.0, 1.0, 1.0), Vec3::ZERO, 30.0),
        [0.0; 3],
        settings(16, 16, 256, 2),
    );
    s.environment = Some(env);
    let (w, h) = (map.width as usize, map.height as usize);
    let mut expected = [0.0f64; 3];
    for row in 0..h / 2 {
        // ∫ cosθ sinθ dθ over the row, times its texels' Δφ.
        let (t0, t1) = (
            std::f64::consts::PI * row as f64 / h as f64,
            std::f64::consts::PI * (row + 1) as f64 / h as f64,
        );
        let weight = (t1.sin().powi(2) - t0.sin().powi(2)) / 2.0 * std::f64::consts::TAU / w as f64;
        for t in &map.texels[row * w..(row + 1) * w] {
            for c in 0..3 {
                expected[c] += f64::from(t[c]) * weight * 0.5 / std::f64::consts::PI;
            }
        }
    }
    let image = render(ctx, &s);
    for c in 0..3 {
        let values: Vec<f64> = image.pixels.iter().map(|p| f64::from(p[c])).collect();
        let n = values.len() as f64;
        let mean = values.iter().sum::<f64>() / n;
        let error = (values.iter().map(|v| (v - mean).powi(2)).sum::<f64>() / (n - 1.0) / n).sqrt();
        assert!(
            (mean - expected[c]).abs() < 4.0 * error + 1e-4 * expected[c],
            "channel {c}: {mean} ± {error}, expected {}",
            expected[c]
        );
        eprintln!(
            "channel {c}: {mean:.5} ± {error:.5}, expected {:.5}",
            expected[c]
        );
        // The test has power: the sun alone is most of the light.
        assert!(
            error < 0.005 * expected[c],
            "channel {c}: error {error} of {}",
            expected[c]
        );
    }
}
