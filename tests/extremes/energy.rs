//! Materials and light at their limits: chains of glass, glass of index one, emitter intensity,
//! fully fuzzy metal and the firefly clamp.

use super::*;

/// A chain of ten glass slabs at normal incidence with max depth 64: for non-absorbing layers the
/// "resistances" 1/T − 1 add, so T₁₀ = 1 / (1 + 10 · 2R/(1−R)) with R = 4% per face (n = 1.5).
#[test]
fn a_chain_of_glass_slabs_transmits_the_layered_fresnel_value() {
    let Some(ctx) = gpu() else { return };
    let mut objects: Vec<rt_core::Object> = (0..10)
        .map(|i| {
            let z = -2.0 * i as f32;
            object(
                "slab",
                cuboid(
                    Vec3::new(-20.0, -20.0, z - 0.5),
                    Vec3::new(20.0, 20.0, z + 0.5),
                    false,
                ),
                Material::Dielectric {
                    ior: 1.5,
                    tint: [1.0; 3],
                },
            )
        })
        .collect();
    objects.push(object(
        "emitter",
        quad(Vec3::new(0.0, 0.0, -30.0), Vec3::Z, 200.0),
        Material::Emissive {
            color: [1.0; 3],
            intensity: 1.0,
        },
    ));
    let scene = scene(
        objects,
        camera(Vec3::new(0.0, 0.0, 5.0), Vec3::ZERO, 1.0),
        [0.0; 3],
        settings(16, 16, 256, 64),
    );
    let image = render(ctx, &scene);
    let r = 0.04f64;
    let expected = 1.0 / (1.0 + 10.0 * 2.0 * r / (1.0 - r));
    let (m, std_error) = pixel_mean_and_error(&image);
    assert!(
        (m - expected).abs() <= 4.0 * std_error + 1e-4,
        "transmission {m} vs {expected} (σ {std_error})"
    );
}

/// Glass of IOR 1.0 bends and reflects nothing: the image equals the scene without it. (Max depth
/// counts segments, and crossing the glass takes two, so the depth must be high enough that no path
/// is cut: 64, cheap with Russian roulette.)
#[test]
fn glass_of_index_one_is_invisible() {
    let Some(ctx) = gpu() else { return };
    let mut without = rt_io::assets::cornell_box().unwrap();
    without.ambient = [1.0; 3];
    without.settings = settings(32, 32, 64, 64);
    let mut with = without.clone();
    let mut ball = object(
        "ball",
        rt_core::shapes::uv_sphere(120.0, 12, 24),
        Material::Dielectric {
            ior: 1.0,
            tint: [1.0; 3],
        },
    );
    ball.transform.translation = [278.0, 280.0, 250.0];
    with.objects.push(ball);
    let (a, ea) = mean_and_error(ctx, &without, 4);
    let (b, eb) = mean_and_error(ctx, &with, 4);
    let sigma = (ea * ea + eb * eb).sqrt();
    assert!(
        (a - b).abs() <= 5.0 * sigma,
        "with IOR-1 glass {b} vs without {a} (σ {sigma})"
    );
}

/// Emitters of intensity 1e-6 and 1e6 scale the image exactly (same seed, same paths), with no
/// overflow or underflow to NaN, Inf or zero.
#[test]
fn emitter_intensity_scales_the_image_linearly() {
    let Some(ctx) = gpu() else { return };
    let render_with = |intensity: f32| {
        let mut scene = rt_io::assets::cornell_box().unwrap();
        for o in &mut scene.objects {
            if let Material::Emissive { intensity: i, .. } = &mut o.material {
                *i = intensity;
            }
        }
        scene.settings = settings(16, 16, 8, 8);
        mean(&render(ctx, &scene))
    };
    let unit = render_with(1.0);
    for intensity in [1e-6f32, 1e6] {
        let ratio = render_with(intensity) / unit / f64::from(intensity);
        assert!(
            (ratio - 1.0).abs() < 1e-4,
            "intensity {intensity}: image scaled by {ratio} × intensity"
        );
    }
}

/// Fuzz 1 scatters widely but never adds energy: an albedo-1 metal sphere under ambient 1 is at
/// most 1 everywhere; at grazing angles fuzzed directions fall below the surface and are absorbed.
#[test]
fn fully_fuzzy_metal_does_not_create_energy() {
    let Some(ctx) = gpu() else { return };
    let mut sphere = rt_core::shapes::uv_sphere(1.0, 12, 24);
    sphere.normals = None;
    let scene = scene(
        vec![object(
            "sphere",
            sphere,
            Material::Metal {
                albedo: [1.0; 3],
                fuzz: 1.0,
            },
        )],
        camera(Vec3::new(0.0, 0.0, 4.0), Vec3::ZERO, 40.0),
        [1.0; 3],
        settings(16, 16, 16, 4),
    );
    let image = render(ctx, &scene);
    assert!(
        image.pixels.iter().all(|p| p[0] <= 1.0 + 1e-6),
        "a pixel exceeds the furnace bound"
    );
    let darkest = image
        .pixels
        .iter()
        .map(|p| p[0])
        .fold(f32::INFINITY, f32::min);
    assert!(
        darkest < 0.9,
        "grazing pixels should lose energy to absorption: darkest {darkest}"
    );
    assert_eq!(
        image.pixels[8 * 16 + 8][0],
        1.0,
        "at normal incidence nothing is absorbed"
    );
}

/// The firefly clamp scales down light that has bounced (never a directly seen emitter), so with
/// the same random numbers every clamped pixel is at most the unclamped one, emitter pixels are
/// unchanged, energy is removed when it bites (it is biased, hence off by default), and nothing
/// changes when it is above every contribution.
#[test]
fn the_firefly_clamp_only_lowers_bounced_light_and_is_exact_when_it_does_not_bite() {
    let Some(ctx) = gpu() else { return };
    let mut s = rt_io::assets::cornell_box().unwrap();
    s.settings.width = 32;
    s.settings.height = 32;
    s.settings.samples_per_pixel = 8;
    let gpu_scene = GpuScene::build(&s).unwrap();
    let free = render_gpu(ctx, &s, &gpu_scene, RenderOptions::default());
    s.settings.clamp = Some(1e30);
    let loose = render_gpu(ctx, &s, &gpu_scene, RenderOptions::default());
    assert!(
        loose.pixels == free.pixels,
        "a clamp above every contribution changes nothing"
    );
    s.settings.clamp = Some(0.05);
    let clamped = render_gpu(ctx, &s, &gpu_scene, RenderOptions::default());
    // Pixels that see only the light (partly covered ones also see the ceiling).
    let light = free.pixels.iter().map(|p| p[0]).fold(0.0f32, f32::max);
    let mut emitter_pixels = 0;
    for (c, f) in clamped.pixels.iter().zip(&free.pixels) {
        for k in 0..3 {
            assert!(
                c[k] <= f[k] * (1.0 + 1e-5) + 1e-7,
                "clamping added light: {c:?} vs {f:?}"
            );
        }
        if f[0] >= light * 0.9999 {
            emitter_pixels += 1;
            assert_eq!(c[..3], f[..3], "a directly seen emitter is never clamped");
        }
    }
    assert!(emitter_pixels > 0, "the light is in view");
    let (a, b) = (free.channel_means(), clamped.channel_means());
    assert!(
        b[0] < a[0] * 0.99,
        "clamping removes energy: {a:?} vs {b:?}"
    );
    s.settings.clamp = Some(-1.0);
    assert!(rt_core::frame::validate(&s).is_err());
}
