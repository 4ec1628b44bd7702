//! Scenes with known answers, rendered on the GPU: furnaces, a lens-filling emitter, a mirror and a
//! glass slab at normal incidence, and an empty scene.

mod common;

use common::*;
use glam::Vec3;
use rt_core::shapes::{cuboid, quad, uv_sphere};
use rt_core::{GpuScene, Material};
use rt_gpu::RenderOptions;

fn assert_all_pixels(image: &rt_gpu::Image, expected: [f32; 3], tolerance: f32, what: &str) {
    for (i, p) in image.pixels.iter().enumerate() {
        for c in 0..3 {
            assert!(
                (p[c] - expected[c]).abs() <= tolerance,
                "{what}: pixel {i} channel {c} is {} but should be {}",
                p[c],
                expected[c]
            );
        }
    }
}

/// An albedo-1 convex object under ambient 1 reflects exactly 1 along every path.
#[test]
fn white_furnace_sphere_is_uniformly_one() {
    let Some(ctx) = gpu() else { return };
    let mut sphere = uv_sphere(1.0, 12, 24);
    sphere.normals = None; // flat: shading normals would lose energy at grazing angles
    let scene = scene(
        vec![object("sphere", sphere, Material::lambertian([1.0; 3]))],
        camera(Vec3::new(0.0, 0.0, 4.0), Vec3::ZERO, 40.0),
        [1.0; 3],
        settings(24, 24, 16, 4),
    );
    assert_all_pixels(&render(ctx, &scene), [1.0; 3], 1e-5, "white furnace");
}

/// Inside a closed room of albedo a emitting Le, a path of at most d segments carries exactly
/// Le·Σ_{k<d} a^k (pbrt's inside-out sphere test), whatever the geometry. Exact per pixel without
/// Russian roulette; with it (unbiased, but random), the image mean must match within 4 standard
/// errors, taken from the spread of the pixels (all of which have the same expected value).
#[test]
fn closed_room_radiance_is_the_geometric_series() {
    let Some(ctx) = gpu() else { return };
    let room = cuboid(Vec3::splat(-1.0), Vec3::splat(1.0), true);
    for depth in [1u32, 2, 3, 6, 12] {
        for roulette in [false, true] {
            let mut scene = scene(
                vec![object("room", room.clone(), Material::lambertian([0.5; 3]))],
                camera(Vec3::new(0.1, 0.2, 0.3), Vec3::new(0.0, 0.0, -1.0), 90.0),
                [0.0; 3],
                settings(16, 16, 64, depth),
            );
            scene.settings.russian_roulette = roulette;
            let mut gpu_scene = GpuScene::build(&scene).unwrap();
            gpu_scene.materials[0].emission = [0.5; 3];
            let image = render_gpu(ctx, &scene, &gpu_scene, RenderOptions::default());
            let expected = 1.0 - 0.5f32.powi(depth as i32);
            let what = format!("max depth {depth}, roulette {roulette}");
            if !roulette {
                assert_all_pixels(&image, [expected; 3], 1e-5, &what);
                continue;
            }
            let (mean, std_error) = pixel_mean_and_error(&image);
            let expected = f64::from(expected);
            assert!(
                (mean - expected).abs() <= 4.0 * std_error + 1e-6,
                "{what}: mean {mean} vs {expected} (σ {std_error})"
            );
        }
    }
}

#[test]
fn lens_filling_emitter_shows_its_radiance() {
    let Some(ctx) = gpu() else { return };
    let emitter = Material::Emissive {
        color: [0.5, 1.0, 2.0],
        intensity: 3.0,
    };
    let scene = scene(
        vec![object(
            "emitter",
            quad(Vec3::new(0.0, 0.0, -1.0), Vec3::Z, 100.0),
            emitter,
        )],
        camera(Vec3::ZERO, Vec3::new(0.0, 0.0, -1.0), 60.0),
        [0.0; 3],
        settings(16, 16, 4, 1),
    );
    assert_all_pixels(
        &render(ctx, &scene),
        [1.5, 3.0, 6.0],
        1e-5,
        "lens-filling emitter",
    );
}

#[test]
fn back_of_an_emitter_is_black() {
    let Some(ctx) = gpu() else { return };
    let emitter = Material::Emissive {
        color: [1.0; 3],
        intensity: 1.0,
    };
    let scene = scene(
        vec![object(
            "emitter",
            quad(Vec3::new(0.0, 0.0, -1.0), -Vec3::Z, 100.0),
            emitter,
        )],
        camera(Vec3::ZERO, Vec3::new(0.0, 0.0, -1.0), 60.0),
        [0.0; 3],
        settings(8, 8, 4, 4),
    );
    assert_all_pixels(
        &render(ctx, &scene),
        [0.0; 3],
        0.0,
        "back face of an emitter",
    );
}

/// A perfect mirror (fuzz 0) tinted by its albedo reflects an emitter behind the camera.
#[test]
fn perfect_mirror_reflects_albedo_times_radiance() {
    let Some(ctx) = gpu() else { return };
    let scene = scene(
        vec![
            object(
                "mirror",
                quad(Vec3::new(0.0, 0.0, -10.0), Vec3::Z, 50.0),
                Material::Metal {
                    albedo: [0.9, 0.8, 0.7],
                    fuzz: 0.0,
                },
            ),
            object(
                "emitter",
                quad(Vec3::new(0.0, 0.0, 10.0), -Vec3::Z, 50.0),
                Material::Emissive {
                    color: [2.0; 3],
                    intensity: 1.0,
                },
            ),
        ],
        camera(Vec3::ZERO, Vec3::new(0.0, 0.0, -1.0), 10.0),
        [0.0; 3],
        settings(16, 16, 4, 3),
    );
    assert_all_pixels(&render(ctx, &scene), [1.8, 1.6, 1.4], 1e-5, "mirror");
}

/// Through a glass slab at normal incidence each face reflects R = ((n−1)/(n+1))² = 4% for n = 1.5,
/// so with all inter-reflections the slab transmits (1−R)/(1+R) and reflects 2R/(1+R).
#[test]
fn glass_slab_at_normal_incidence_follows_fresnel() {
    let Some(ctx) = gpu() else { return };
    for ior in [1.0001f32, 1.5, 2.417, 4.0] {
        let r = ((f64::from(ior) - 1.0) / (f64::from(ior) + 1.0)).powi(2);
        for (emitter_z, facing, expected) in [
            (-10.0, Vec3::Z, (1.0 - r) / (1.0 + r)),
            (10.0, -Vec3::Z, 2.0 * r / (1.0 + r)),
        ] {
            let slab = cuboid(
                Vec3::new(-20.0, -20.0, -0.5),
                Vec3::new(20.0, 20.0, 0.5),
                false,
            );
            let emitter = quad(Vec3::new(0.0, 0.0, emitter_z), facing, 60.0);
            let mut scene = scene(
                vec![
                    object(
                        "slab",
                        slab,
                        Material::Dielectric {
                            ior,
                            tint: [1.0; 3],
                        },
                    ),
                    object(
                        "emitter",
                        emitter,
                        Material::Emissive {
                            color: [1.0; 3],
                            intensity: 1.0,
                        },
                    ),
                ],
                camera(Vec3::new(0.0, 0.0, 5.0), Vec3::ZERO, 1.0),
                [0.0; 3],
                settings(32, 32, 256, 24),
            );
            // Without roulette each path carries exactly 0 or 1 (the 1/η² factors cancel on
            // leaving), so the image mean of n paths is a binomial proportion: σ = sqrt(p(1−p)/n).
            scene.settings.russian_roulette = false;
            let image = render(ctx, &scene);
            let n = (32 * 32 * 256) as f64;
            let sigma = (expected * (1.0 - expected) / n).sqrt();
            for (c, mean) in image.channel_means().iter().enumerate() {
                assert!(
                    (mean - expected).abs() < 5.0 * sigma + 1e-6,
                    "IOR {ior}, channel {c}: {mean} vs {expected} (σ {sigma})"
                );
            }
        }
    }
}

#[test]
fn empty_scene_renders_the_ambient_colour() {
    let Some(ctx) = gpu() else { return };
    let scene = scene(
        Vec::new(),
        camera(Vec3::ZERO, Vec3::new(0.0, 0.0, -1.0), 45.0),
        [0.25, 0.5, 0.75],
        settings(8, 8, 2, 4),
    );
    assert_all_pixels(&render(ctx, &scene), [0.25, 0.5, 0.75], 0.0, "empty scene");
}

/// An accumulation buffer larger than the adapter allows is a clear error naming the buffer.
#[test]
fn too_large_an_image_is_a_clear_error() {
    let Some(ctx) = gpu() else { return };
    let scene = scene(
        Vec::new(),
        camera(Vec3::ZERO, Vec3::new(0.0, 0.0, -1.0), 45.0),
        [0.0; 3],
        settings(16384, 16384, 1, 1),
    );
    let gpu_scene = GpuScene::build(&scene).unwrap();
    let Err(err) = rt_gpu::Renderer::for_scene(ctx, &scene, &gpu_scene, RenderOptions::default())
    else {
        let limit = ctx.device.limits().max_storage_buffer_binding_size;
        assert!(
            limit >= 16384 * 16384 * rt_core::accumulation::CHANNEL_SUM_BYTES,
            "renderer accepted a buffer over the limit"
        );
        return;
    };
    let message = err.to_string();
    assert!(
        message.contains("accumulation") && message.contains("4294967296"),
        "{message}"
    );
}

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

/// Renders a white PBR sphere under a uniform white environment (importance-sampled, with MIS)
/// and returns, per pixel, (mean, standard error) of the red channel.
fn pbr_furnace(ctx: &rt_gpu::GpuContext, p: rt_core::material::Pbr, spp: u32) -> Vec<(f64, f64)> {
    let mut sphere = uv_sphere(1.0, 24, 48);
    sphere.normals = None;
    let mut scene = scene(
        vec![object("sphere", sphere, pbr(p))],
        camera(Vec3::new(0.0, 0.0, 4.0), Vec3::ZERO, 24.0),
        [0.0; 3],
        settings(16, 16, spp, 64),
    );
    scene.environment = Some(rt_core::Environment::new(
        "white",
        rt_core::EnvironmentMap::uniform([1.0; 3]),
    ));
    let image = render(ctx, &scene);
    image
        .pixels
        .iter()
        .map(|px| {
            let mean = f64::from(px[0]);
            // The fourth channel is the running mean of squared luminance (= red², all white).
            let var =
                (f64::from(px[3]) - mean * mean).max(0.0) * f64::from(spp) / f64::from(spp - 1);
            (mean, (var / f64::from(spp)).sqrt())
        })
        .collect()
}

/// White furnace on the GPU: a white rough metal sphere keeps ≥ 0.9 of the light at roughness
/// {0, 0.1, 0.5, 1} and never more than 1; rough glass (with its internal bounces) never more
/// than 1, and smooth glass all of it. Per pixel within z·σ (Šidák over all pixels and cases).
#[test]
fn pbr_spheres_under_a_white_environment_conserve_energy() {
    use rt_core::material::Pbr;
    let Some(ctx) = gpu() else { return };
    let spp = 256;
    let z = z_threshold(1.0 - (1.0 - 1e-3f64).powf(1.0 / (256.0 * 8.0)));
    for roughness in [0.0, 0.1, 0.5, 1.0] {
        let metal = Pbr {
            base_color: [1.0; 3],
            metallic: 1.0,
            roughness,
            ..Default::default()
        };
        let glass = Pbr {
            base_color: [1.0; 3],
            roughness,
            transmission: 1.0,
            ..Default::default()
        };
        for (what, p, floor) in [
            ("metal", metal, 0.9),
            ("glass", glass, if roughness <= 0.1 { 0.97 } else { 0.0 }),
        ] {
            for (i, (mean, se)) in pbr_furnace(ctx, p, spp).into_iter().enumerate() {
                assert!(
                    mean <= 1.0 + z * se + 1e-3 && mean >= floor - z * se - 1e-3,
                    "{what}, roughness {roughness}: pixel {i} is {mean:.4} ± {se:.4} \
                     (should lie in [{floor}, 1])"
                );
            }
        }
    }
}

/// A normal map tilts the shading normal exactly as its texels say, about MikkTSpace's tangent:
/// a plane whose u runs along +x, mapped to the normal n = (sin θ, 0, cos θ) in tangent space (one
/// 8-bit texel), under a sun tilted φ towards +x, has radiance ρ/π · E · (n·l) with n·l computed
/// from the decoded texel — cos(θ − φ) up to 8-bit rounding. A PBR dielectric of IOR 1 has no
/// specular layer (F = 0), so it is exactly Lambertian. Without the map, cos φ.
#[test]
fn a_normal_map_tilts_the_lambert_cosine_exactly() {
    use rt_core::material::Pbr;
    let Some(ctx) = gpu() else { return };
    let (theta, phi) = (20f32.to_radians(), 35f32.to_radians());
    let byte = |v: f32| ((v * 0.5 + 0.5) * 255.0).round() as u8;
    let texel = [byte(theta.sin()), 128, byte(theta.cos()), 255];
    let mut plane = quad(Vec3::ZERO, Vec3::Y, 100.0);
    plane.normals = Some(vec![Vec3::Y; 4]);
    plane.uvs = Some(
        plane
            .positions
            .iter()
            .map(|p| glam::Vec2::new(p.x / 100.0 + 0.5, -p.z / 100.0 + 0.5))
            .collect(),
    );
    let material = |normal_texture| {
        pbr(Pbr {
            base_color: [0.5; 3],
            ior: 1.0,
            roughness: 1.0,
            normal_texture,
            ..Default::default()
        })
    };
    let mut sun = rt_core::Light::new(rt_core::LightKind::Directional, "sun");
    sun.direction = [-phi.sin(), -phi.cos(), 0.0];
    sun.intensity = 2.0;
    let mut s = scene(
        vec![object("plane", plane, material(Some(0)))],
        camera(Vec3::new(0.0, 5.0, 0.001), Vec3::ZERO, 20.0),
        [0.0; 3],
        settings(8, 8, 2, 2),
    );
    s.textures.push(rt_core::Texture {
        sampler: Default::default(),
        name: "tilt".into(),
        width: 1,
        height: 1,
        rgba8: texel.to_vec().into(),
    });
    s.lights.push(sun);
    let m = Vec3::new(texel[0] as f32, texel[1] as f32, texel[2] as f32) / 255.0 * 2.0 - Vec3::ONE;
    // Tangent +x, bitangent −z (where v grows), normal +y.
    let n = Vec3::new(m.x, m.z, -m.y).normalize();
    let l = Vec3::new(phi.sin(), phi.cos(), 0.0);
    let expected = 0.5 / std::f32::consts::PI * 2.0 * n.dot(l);
    assert!((n.dot(l) - (theta - phi).cos()).abs() < 0.01);
    assert_all_pixels(&render(ctx, &s), [expected; 3], 1e-5, "normal-mapped plane");
    s.objects[0].material = material(None);
    let flat = 0.5 / std::f32::consts::PI * 2.0 * phi.cos();
    assert_all_pixels(&render(ctx, &s), [flat; 3], 1e-5, "the same plane unmapped");
}

/// A square facing the camera at the origin from z = −1, a bit wider than a 60° view, with `u`
/// running 0..`u_max` from left to right and v = ½.
fn view_filling_square(z: f32, u_max: f32) -> rt_core::Mesh {
    let h = (30f32).to_radians().tan() * -z * 1.0001;
    let positions = [(-h, -h), (h, -h), (h, h), (-h, h)]
        .map(|(x, y)| Vec3::new(x, y, z))
        .to_vec();
    rt_core::Mesh {
        positions,
        normals: None,
        uvs: Some(
            [0.0, u_max, u_max, 0.0]
                .map(|u| glam::Vec2::new(u, 0.5))
                .to_vec(),
        ),
        colors: None,
        indices: vec![[0, 1, 2], [0, 2, 3]],
    }
}

/// Mean of `channel` over image columns `cols` (all rows).
fn column_mean(image: &rt_gpu::Image, cols: std::ops::Range<usize>, channel: usize) -> Vec<f32> {
    let w = image.width as usize;
    cols.map(|x| {
        let col: Vec<f32> = image
            .pixels
            .iter()
            .skip(x)
            .step_by(w)
            .map(|p| p[channel])
            .collect();
        col.iter().sum::<f32>() / col.len() as f32
    })
    .collect()
}

/// A 2×1 emission image (white | black) read with the nearest filter across u ∈ [0, 2], seen head
/// on: repeat tiles it (white, black, white, black by quarters), mirrored repeat mirrors the second
/// copy (white, black, black, white), clamp extends the edge (white, black, black, black). Exact.
#[test]
fn wrap_modes_and_the_nearest_filter_tile_an_emission_image_exactly() {
    use rt_core::material::Pbr;
    use rt_core::{Filter, TextureSampler, Wrap};
    let Some(ctx) = gpu() else { return };
    let mut s = scene(
        vec![object(
            "panel",
            view_filling_square(-1.0, 2.0),
            pbr(Pbr {
                base_color: [0.0; 3],
                emission: [1.0, 2.0, 3.0],
                emission_texture: Some(0),
                ..Default::default()
            }),
        )],
        camera(Vec3::ZERO, Vec3::new(0.0, 0.0, -1.0), 60.0),
        [0.0; 3],
        settings(16, 16, 4, 1),
    );
    for (wrap, quarters) in [
        (Wrap::Repeat, [1.0, 0.0, 1.0, 0.0]),
        (Wrap::MirroredRepeat, [1.0, 0.0, 0.0, 1.0]),
        (Wrap::ClampToEdge, [1.0, 0.0, 0.0, 0.0]),
    ] {
        s.textures = vec![rt_core::Texture {
            name: "white | black".into(),
            width: 2,
            height: 1,
            rgba8: vec![255, 255, 255, 255, 0, 0, 0, 255].into(),
            sampler: TextureSampler {
                wrap_s: wrap,
                wrap_t: wrap,
                filter: Filter::Nearest,
            },
        }];
        let image = render(ctx, &s);
        for (q, expected) in quarters.iter().enumerate() {
            // The two middle columns of each quarter (the edges fall between pixels).
            let cols = q * 4 + 1..q * 4 + 3;
            for (ch, scale) in [1.0f32, 2.0, 3.0].iter().enumerate() {
                for m in column_mean(&image, cols.clone(), ch) {
                    assert!(
                        (m - expected * scale).abs() < 1e-5,
                        "{wrap:?}: quarter {q} channel {ch} is {m}, expected {}",
                        expected * scale
                    );
                }
            }
        }
    }
}

/// A black square in front of a lens-filling emitter of radiance 2. Masked by an image whose
/// alpha is 0 on the left half and 1 on the right, the left half shows the emitter exactly and the
/// right half is black. Blended at α = ¼, each pixel shows (1 − ¼)·2 = 1.5 on average: the image
/// mean is tested against its standard error from the pixels' spread.
#[test]
fn an_alpha_mask_cuts_exact_holes_and_blending_lets_one_minus_alpha_through() {
    use rt_core::material::{AlphaMode, Pbr};
    use rt_core::{Filter, TextureSampler, Wrap};
    let Some(ctx) = gpu() else { return };
    let screen = |alpha_mode, alpha, texture| {
        pbr(Pbr {
            base_color: [0.0; 3],
            texture,
            alpha_mode,
            alpha,
            ..Default::default()
        })
    };
    let mut s = scene(
        vec![
            object(
                "emitter",
                quad(Vec3::new(0.0, 0.0, -2.0), Vec3::Z, 100.0),
                Material::Emissive {
                    color: [1.0; 3],
                    intensity: 2.0,
                },
            ),
            object(
                "screen",
                view_filling_square(-1.0, 1.0),
                screen(AlphaMode::Mask, 1.0, Some(0)),
            ),
        ],
        camera(Vec3::ZERO, Vec3::new(0.0, 0.0, -1.0), 60.0),
        [0.0; 3],
        settings(16, 16, 4, 2),
    );
    s.textures.push(rt_core::Texture {
        name: "hole | solid".into(),
        width: 2,
        height: 1,
        rgba8: vec![255, 255, 255, 0, 255, 255, 255, 255].into(),
        sampler: TextureSampler {
            wrap_s: Wrap::ClampToEdge,
            wrap_t: Wrap::ClampToEdge,
            filter: Filter::Nearest,
        },
    });
    let image = render(ctx, &s);
    for (x, m) in column_mean(&image, 0..16, 0).iter().enumerate() {
        let expected = if x < 8 { 2.0 } else { 0.0 };
        if x != 7 && x != 8 {
            assert!(
                (m - expected).abs() < 1e-5,
                "mask: column {x} is {m}, expected {expected}"
            );
        }
    }
    // Opaque mode ignores the same image's alpha.
    s.objects[1].material = screen(AlphaMode::Opaque, 1.0, Some(0));
    assert_all_pixels(&render(ctx, &s), [0.0; 3], 1e-6, "opaque screen");

    s.objects[1].material = screen(AlphaMode::Blend, 0.25, None);
    s.settings.samples_per_pixel = 64;
    s.settings.width = 32;
    s.settings.height = 32;
    // Through rt's BVH, and through the driver's ray queries where the adapter has them.
    let mut traces = vec![rt_gpu::Trace::Bvh];
    if ctx.has_ray_queries() {
        traces.push(rt_gpu::Trace::Hardware);
    }
    let gpu_scene = GpuScene::build(&s).unwrap();
    for trace in traces {
        let options = RenderOptions {
            trace,
            ..Default::default()
        };
        let image = render_gpu(ctx, &s, &gpu_scene, options);
        let (mean, error) = pixel_mean_and_error(&image);
        // Each sample is 0 or 2: a pixel of 64 has σ = 2·√(¼·¾/64) ≈ 0.108, the image mean
        // ≈ 0.0034.
        assert!(
            error > 0.001 && error < 0.01,
            "{trace:?}: standard error {error}"
        );
        assert!(
            (mean - 1.5).abs() < 4.0 * error,
            "{trace:?}: blend at alpha 0.25: mean {mean} ± {error}, expected 1.5"
        );
    }
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
