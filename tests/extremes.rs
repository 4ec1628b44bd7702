//! Degenerate geometry and extreme settings render without NaN/Inf (checked by `render_gpu`) and
//! with the expected result, or fail with a clear error (part of issue 5's suite).

mod common;

use common::*;
use glam::Vec3;
use rt_core::shapes::{cuboid, quad};
use rt_core::{GpuScene, Material, Mesh};
use rt_gpu::{Kernel, RenderOptions, Renderer, Tuning};
use std::time::Duration;

fn lit_room() -> Vec<rt_core::Object> {
    vec![
        object(
            "room",
            cuboid(Vec3::splat(-2.0), Vec3::splat(2.0), true),
            Material::lambertian([0.6; 3]),
        ),
        object(
            "light",
            quad(Vec3::new(0.0, 1.99, 0.0), -Vec3::Y, 1.0),
            Material::Emissive {
                color: [8.0; 3],
                intensity: 1.0,
            },
        ),
    ]
}

fn mean(image: &rt_gpu::Image) -> f64 {
    image.channel_means().iter().sum::<f64>() / 3.0
}

#[test]
fn zero_area_and_duplicated_triangles_are_harmless() {
    let Some(ctx) = gpu() else { return };
    let mut objects = lit_room();
    // A needle, a point-triangle, a duplicated face and a duplicated vertex.
    let mesh = Mesh {
        positions: vec![
            Vec3::ZERO,
            Vec3::X,
            Vec3::X * 2.0,
            Vec3::ZERO,
            Vec3::new(0.0, 0.5, 0.0),
            Vec3::X,
        ],
        normals: None,
        uvs: None,
        colors: None,
        indices: vec![[0, 1, 2], [0, 0, 0], [0, 1, 4], [0, 1, 4], [3, 5, 4]],
    };
    objects.push(object("degenerate", mesh, Material::lambertian([0.5; 3])));
    // Degenerate emitters too: they get no share of next-event estimation.
    let needle = Mesh {
        positions: vec![Vec3::ZERO, Vec3::Y, Vec3::Y * 2.0],
        normals: None,
        uvs: None,
        colors: None,
        indices: vec![[0, 1, 2]],
    };
    objects.push(object(
        "needle light",
        needle,
        Material::Emissive {
            color: [1.0; 3],
            intensity: 1.0,
        },
    ));
    let scene = scene(
        objects,
        camera(Vec3::new(0.0, 0.0, 1.8), Vec3::ZERO, 70.0),
        [0.0; 3],
        settings(16, 16, 16, 6),
    );
    let gpu_scene = GpuScene::build(&scene).unwrap();
    assert_eq!(
        gpu_scene.emitters.len(),
        2,
        "only the light's two triangles have area"
    );
    let image = render_gpu(ctx, &scene, &gpu_scene, RenderOptions::default());
    assert!(mean(&image) > 0.05, "the room should be lit");
}

#[test]
fn one_triangle_and_camera_inside_an_object() {
    let Some(ctx) = gpu() else { return };
    let one = Mesh {
        positions: vec![
            Vec3::new(-1.0, -1.0, -1.0),
            Vec3::new(1.0, -1.0, -1.0),
            Vec3::new(0.0, 1.0, -1.0),
        ],
        normals: None,
        uvs: None,
        colors: None,
        indices: vec![[0, 1, 2]],
    };
    let scene1 = scene(
        vec![object(
            "tri",
            one,
            Material::Emissive {
                color: [1.0; 3],
                intensity: 1.0,
            },
        )],
        camera(Vec3::ZERO, -Vec3::Z, 30.0),
        [0.0; 3],
        settings(9, 9, 4, 2),
    );
    let image = render(ctx, &scene1);
    assert_eq!(
        image.pixels[4 * 9 + 4][0],
        1.0,
        "the centre pixel sees the emitting triangle"
    );
    // Inside a closed box lit from inside: every pixel sees the inside walls.
    let scene2 = scene(
        lit_room(),
        camera(Vec3::new(0.3, -0.5, 0.2), Vec3::new(1.0, 0.0, -1.0), 60.0),
        [5.0; 3],
        settings(8, 8, 8, 4),
    );
    let image = render(ctx, &scene2);
    assert!(
        image.pixels.iter().all(|p| p[0] > 0.0),
        "a closed room lets no ambient light in but is lit"
    );
}

#[test]
fn extreme_fields_of_view_and_image_sizes() {
    let Some(ctx) = gpu() else { return };
    for (vfov, width, height) in [
        (0.1f32, 4, 4),
        (179.0, 16, 8),
        (40.0, 1, 1),
        (40.0, 1, 37),
        (60.0, 53, 1),
    ] {
        let scene = scene(
            lit_room(),
            camera(Vec3::new(0.0, 0.0, 1.5), Vec3::ZERO, vfov),
            [0.0; 3],
            settings(width, height, 2, 5),
        );
        let image = render(ctx, &scene);
        assert_eq!(image.pixels.len(), (width * height) as usize);
        assert!(
            mean(&image) > 0.0,
            "vfov {vfov} {width}x{height}: black image"
        );
    }
}

#[test]
fn max_depth_zero_is_black_and_one_shows_emitters_only() {
    let Some(ctx) = gpu() else { return };
    let objects = lit_room();
    let look_up = camera(Vec3::ZERO, Vec3::new(0.0, 1.0, 0.001), 20.0);
    let image = render(
        ctx,
        &scene(
            objects.clone(),
            look_up.clone(),
            [1.0; 3],
            settings(4, 4, 2, 0),
        ),
    );
    assert!(
        image.pixels.iter().all(|p| p[..3] == [0.0; 3]),
        "max depth 0 traces nothing"
    );
    let image = render(
        ctx,
        &scene(objects, look_up, [1.0; 3], settings(4, 4, 2, 1)),
    );
    assert!(
        image.pixels.iter().all(|p| p[..3] == [8.0; 3]),
        "max depth 1 sees only the light: {:?}",
        image.pixels[0]
    );
}

#[test]
fn invalid_geometry_is_rejected_naming_object_and_vertex() {
    let mut scene = scene(
        Vec::new(),
        camera(Vec3::Z, Vec3::ZERO, 40.0),
        [0.0; 3],
        settings(4, 4, 1, 1),
    );
    let mesh = Mesh {
        positions: vec![Vec3::ZERO, Vec3::new(f32::NAN, 0.0, 0.0), Vec3::Y],
        normals: None,
        uvs: None,
        colors: None,
        indices: vec![[0, 1, 2]],
    };
    scene
        .objects
        .push(object("broken", mesh, Material::lambertian([0.5; 3])));
    let message = GpuScene::build(&scene).unwrap_err().to_string();
    assert!(
        message.contains("'broken'") && message.contains("vertex 2"),
        "{message}"
    );
    std::sync::Arc::make_mut(&mut scene.objects[0].mesh).positions[1] = Vec3::X;
    std::sync::Arc::make_mut(&mut scene.objects[0].mesh).indices[0] = [0, 1, 7];
    let message = GpuScene::build(&scene).unwrap_err().to_string();
    assert!(
        message.contains("'broken'") && message.contains("vertex 8"),
        "{message}"
    );
    std::sync::Arc::make_mut(&mut scene.objects[0].mesh).indices[0] = [0, 1, 2];
    scene.objects[0].transform.scale = [0.0, 1.0, 1.0];
    assert!(
        GpuScene::build(&scene)
            .unwrap_err()
            .to_string()
            .contains("singular")
    );
}

/// The Cornell box scaled by 1e-4 … 1e6, and moved 1e5 away from the origin, renders the same image
/// (camera scaled and moved with it): no self-intersection acne, no leaks through closed corners.
/// Compared by the image means of independent renders, within 5 standard errors of the difference.
#[test]
fn scene_scale_and_offset_do_not_change_the_image() {
    let Some(ctx) = gpu() else { return };
    let base = rt_core::assets::cornell_box().unwrap();
    let render_at = |scale: f32, offset: Vec3| {
        let mut scene = base.clone();
        for o in &mut scene.objects {
            o.transform.scale = [scale; 3];
            o.transform.translation = offset.to_array();
        }
        let moved = |p: [f32; 3]| (Vec3::from(p) * scale + offset).to_array();
        scene.camera.from = moved(scene.camera.from);
        scene.camera.to = moved(scene.camera.to);
        scene.settings = settings(48, 48, 32, 8);
        mean_and_error(ctx, &scene, 4)
    };
    let (reference, ref_err) = render_at(1.0, Vec3::ZERO);
    for (scale, offset) in [
        (1e-8f32, Vec3::ZERO),
        (1e-6, Vec3::ZERO),
        (1e-4, Vec3::ZERO),
        (1e4, Vec3::ZERO),
        (1e6, Vec3::ZERO),
        (1.0, Vec3::splat(1e5)),
    ] {
        let (m, err) = render_at(scale, offset);
        let sigma = (ref_err * ref_err + err * err).sqrt();
        assert!(
            (m - reference).abs() <= 5.0 * sigma + 1e-4 * reference,
            "scale {scale}, offset {offset}: mean {m} vs {reference} at scale 1 (σ {sigma})"
        );
    }
}

/// Stopping after any batch leaves a readable image of the samples so far, and a new render can
/// start at once on the same device.
#[test]
fn a_render_can_be_cancelled_and_restarted() {
    let Some(ctx) = gpu() else { return };
    let mut scene = rt_core::assets::cornell_box().unwrap();
    scene.settings = settings(32, 32, 1000, 8);
    let gpu_scene = GpuScene::build(&scene).unwrap();
    let mut renderer =
        rt_gpu::Renderer::for_scene(ctx, &scene, &gpu_scene, RenderOptions::default()).unwrap();
    renderer.render(1000, |done| done < 3).unwrap();
    let partial = renderer.read_image().unwrap();
    assert!(partial.samples_per_pixel >= 3 && partial.samples_per_pixel < 1000);
    assert!(
        partial
            .pixels
            .iter()
            .all(|p| p.iter().all(|c| c.is_finite()))
            && mean(&partial) > 0.0
    );
    scene.settings.samples_per_pixel = 4;
    let again = render(ctx, &scene);
    assert_eq!(again.samples_per_pixel, 4);
}

/// 100,000 samples per pixel accumulate without drift: the running mean (updated one sample at a
/// time) of a random, unbiased estimate with a known value stays within 4 standard errors of it.
#[test]
fn a_hundred_thousand_samples_accumulate_without_drift() {
    let Some(ctx) = gpu() else { return };
    let spp = 100_000;
    let mut scene = scene(
        vec![object(
            "room",
            cuboid(Vec3::splat(-1.0), Vec3::splat(1.0), true),
            Material::lambertian([0.5; 3]),
        )],
        camera(Vec3::ZERO, -Vec3::Z, 60.0),
        [0.0; 3],
        settings(2, 2, spp, 10),
    );
    scene.settings.russian_roulette = true;
    let mut gpu_scene = GpuScene::build(&scene).unwrap();
    gpu_scene.materials[0].emission = [0.5; 3];
    let image = render_gpu(ctx, &scene, &gpu_scene, RenderOptions::default());
    assert_eq!(image.samples_per_pixel, spp);
    let expected = 1.0 - 0.5f64.powi(10);
    for p in &image.pixels {
        // Grey values: luminance = value, so w holds the mean of squares.
        let (m, m2) = (f64::from(p[0]), f64::from(p[3]));
        let std_error = ((m2 - m * m).max(0.0) / f64::from(spp)).sqrt();
        assert!(std_error > 0.0, "roulette should make the samples random");
        assert!(
            (m - expected).abs() <= 4.0 * std_error,
            "mean {m} vs {expected} (σ {std_error})"
        );
    }
}

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

/// Replicated image means (seeds 1..=k) and their standard error.
fn mean_and_error(ctx: &rt_gpu::GpuContext, scene: &rt_core::Scene, k: u32) -> (f64, f64) {
    let mut scene = scene.clone();
    let replicas: Vec<f64> = (1..=k)
        .map(|seed| {
            scene.settings.seed = seed;
            mean(&render(ctx, &scene))
        })
        .collect();
    let m = replicas.iter().sum::<f64>() / f64::from(k);
    let var = replicas.iter().map(|r| (r - m).powi(2)).sum::<f64>() / f64::from(k - 1);
    (m, (var / f64::from(k)).sqrt())
}

/// Glass of IOR 1.0 bends and reflects nothing: the image equals the scene without it. (Max depth
/// counts segments, and crossing the glass takes two, so the depth must be high enough that no path
/// is cut: 64, cheap with Russian roulette.)
#[test]
fn glass_of_index_one_is_invisible() {
    let Some(ctx) = gpu() else { return };
    let mut without = rt_core::assets::cornell_box().unwrap();
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
        let mut scene = rt_core::assets::cornell_box().unwrap();
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

/// An n×n grid of quads over [-1, 1]² in the plane y = 0, facing +y: many shared edges and
/// vertices shared by up to six triangles.
fn grid(n: u32) -> Mesh {
    let mut positions = Vec::new();
    for j in 0..=n {
        for i in 0..=n {
            positions.push(Vec3::new(
                -1.0 + 2.0 * i as f32 / n as f32,
                0.0,
                -1.0 + 2.0 * j as f32 / n as f32,
            ));
        }
    }
    let mut indices = Vec::new();
    let at = |i: u32, j: u32| j * (n + 1) + i;
    for j in 0..n {
        for i in 0..n {
            // Alternate the diagonal so that some vertices join six triangles.
            if (i + j) % 2 == 0 {
                indices.push([at(i, j), at(i, j + 1), at(i + 1, j + 1)]);
                indices.push([at(i, j), at(i + 1, j + 1), at(i + 1, j)]);
            } else {
                indices.push([at(i, j), at(i, j + 1), at(i + 1, j)]);
                indices.push([at(i + 1, j), at(i, j + 1), at(i + 1, j + 1)]);
            }
        }
    }
    Mesh {
        positions,
        normals: None,
        uvs: None,
        colors: None,
        indices,
    }
}

/// Grazing rays (0.01° to 0.09° to the plane), rays exactly along the axes (zero direction
/// components), and rays aimed exactly at shared vertices and edges all hit the grid, at the right
/// distance, on the GPU and in the CPU reference alike: no cracks, no misses from infinities in the
/// slab test.
#[test]
fn grazing_axis_aligned_and_vertex_rays_hit_where_they_should() {
    let Some(ctx) = gpu() else { return };
    let n = 8;
    let s = scene(
        vec![object("grid", grid(n), Material::lambertian([0.5; 3]))],
        camera(Vec3::new(0.0, 3.0, 3.0), Vec3::ZERO, 40.0),
        [0.0; 3],
        settings(4, 4, 1, 1),
    );
    let gpu_scene = GpuScene::build(&s).unwrap();
    let ray = |origin: Vec3, direction: Vec3| rt_core::gpu_types::Ray {
        origin: origin.to_array(),
        t_max: f32::MAX,
        direction: direction.normalize().to_array(),
        _pad: 0.0,
    };
    // (ray, expected distance)
    let mut cases = Vec::new();
    for degrees in [0.01f32, 0.03, 0.05, 0.09] {
        let angle = degrees.to_radians();
        for z in [-0.9f32, -0.3, 0.0, 0.55] {
            // Starts 1.5 before the hit at x = 0.1 (and at z = 0: along a row of shared edges).
            let distance = 1.5f32;
            let origin = Vec3::new(0.1 - distance * angle.cos(), distance * angle.sin(), z);
            cases.push((
                ray(origin, Vec3::new(angle.cos(), -angle.sin(), 0.0)),
                distance,
            ));
        }
    }
    // Interior vertices and edges only: a ray through the mesh's outer boundary may rightly go
    // either way.
    for j in 1..n {
        for i in 1..n {
            let x = -1.0 + 2.0 * i as f32 / n as f32;
            let z = -1.0 + 2.0 * j as f32 / n as f32;
            // Exactly down the y axis onto every vertex, and onto the middle of an edge.
            cases.push((ray(Vec3::new(x, 1.0, z), Vec3::NEG_Y), 1.0));
            cases.push((ray(Vec3::new(x + 1.0 / n as f32, 2.0, z), Vec3::NEG_Y), 2.0));
            // Obliquely at the vertex from above.
            let from = Vec3::new(x + 0.3, 0.7, z - 0.2);
            let target = Vec3::new(x, 0.0, z);
            cases.push((ray(from, target - from), (target - from).length()));
        }
    }
    let rays: Vec<_> = cases.iter().map(|(r, _)| *r).collect();
    let hits = rt_gpu::trace_rays::trace_rays(ctx, &gpu_scene, &rays, rt_gpu::Trace::Bvh).unwrap();
    for ((r, expected), gpu_hit) in cases.iter().zip(&hits) {
        let cpu =
            rt_core::reference::trace(&gpu_scene, r.origin.into(), r.direction.into(), r.t_max);
        for (what, hit) in [("GPU", gpu_hit), ("CPU", &cpu)] {
            assert_ne!(hit.triangle, u32::MAX, "{what} missed: {r:?}");
            assert!(
                (hit.t - expected).abs() <= 1e-4 * expected,
                "{what} hit at {} instead of {expected}: {r:?}",
                hit.t
            );
        }
    }
    assert!(cases.len() > 150);
}

/// An image whose accumulation buffer would not fit renders in bands of rows; the stitched image
/// is bit-identical to the untiled one (random numbers are keyed by the pixel's place in the whole
/// image), whatever the tile height, including one row per tile.
#[test]
fn tiled_renders_are_bit_identical_to_untiled_ones() {
    let Some(ctx) = gpu() else { return };
    let mut s = scene(
        lit_room(),
        camera(Vec3::new(0.0, 0.0, 1.9), Vec3::ZERO, 70.0),
        [0.0; 3],
        settings(37, 23, 3, 5),
    );
    s.settings.seed = 7;
    let gpu_scene = GpuScene::build(&s).unwrap();
    // With the denoiser's AOVs, which tiles must stitch too.
    let options = RenderOptions {
        aovs: true,
        ..Default::default()
    };
    let mut renderer = Renderer::for_scene(ctx, &s, &gpu_scene, options).unwrap();
    renderer.render(3, |_| true).unwrap();
    let whole = renderer.read_image().unwrap();
    let whole_aovs = renderer.read_aovs().unwrap().unwrap();
    let frame = rt_core::frame::frame_for(&s, &gpu_scene).unwrap();
    for rows in [1u32, 5, 22] {
        let rt_gpu::TiledRender { image: tiled, aovs } = rt_gpu::render_tiled(
            ctx,
            &gpu_scene,
            frame,
            options,
            3,
            Some(u64::from(rows) * 37 * rt_gpu::pixel_binding_bytes(&options)),
            |_| true,
        )
        .unwrap();
        assert_eq!((tiled.width, tiled.height), (37, 23));
        assert_eq!(tiled.samples_per_pixel, 3);
        assert!(
            tiled.pixels == whole.pixels && tiled.sums == whole.sums,
            "tiles of {rows} rows differ from the untiled image"
        );
        let aovs = aovs.unwrap();
        assert!(
            aovs.albedo == whole_aovs.albedo
                && aovs.normal == whole_aovs.normal
                && aovs.emission == whole_aovs.emission,
            "tiles of {rows} rows: the stitched AOVs differ from the untiled ones"
        );
    }
    // Tiles are sized by the largest per-pixel binding: the guides when the denoiser keeps them.
    assert_eq!(rt_gpu::pixel_binding_bytes(&options), 48);
    assert_eq!(rt_gpu::pixel_binding_bytes(&RenderOptions::default()), 16);
    assert_eq!(rt_gpu::tile_rows(16384, 16384, 16, 128 << 20), 512);
    assert_eq!(rt_gpu::tile_rows(2560, 1440, 48, 128 << 20), 1092);
    let whole = |options| rt_gpu::whole_image_binding_bytes(2560, 1440, options);
    assert!(whole(&options) > 128 << 20);
    assert!(whole(&RenderOptions::default()) <= 128 << 20);
}

/// The firefly clamp scales down light that has bounced (never a directly seen emitter), so with
/// the same random numbers every clamped pixel is at most the unclamped one, emitter pixels are
/// unchanged, energy is removed when it bites (it is biased, hence off by default), and nothing
/// changes when it is above every contribution.
#[test]
fn the_firefly_clamp_only_lowers_bounced_light_and_is_exact_when_it_does_not_bite() {
    let Some(ctx) = gpu() else { return };
    let mut s = rt_core::assets::cornell_box().unwrap();
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

/// A context of its own (for faults that must not disturb the other tests) and a 16 x 16 Cornell
/// box.
fn own_context_and_small_cornell() -> (rt_gpu::GpuContext, rt_core::Scene, GpuScene) {
    let ctx = rt_gpu::GpuContext::new(&rt_gpu::AdapterChoice::Software).unwrap();
    let mut s = rt_core::assets::cornell_box().unwrap();
    s.settings.width = 16;
    s.settings.height = 16;
    let gpu_scene = GpuScene::build(&s).unwrap();
    (ctx, s, gpu_scene)
}

/// A device lost mid-render (simulated with `Device::destroy`) makes the next batch and readback
/// return errors, not panic; the image read back before the loss is intact, so it can be saved.
#[test]
fn a_lost_device_is_an_error_and_earlier_readbacks_stay_usable() {
    if gpu().is_none() {
        return;
    }
    let (ctx, s, gpu_scene) = own_context_and_small_cornell();
    let mut renderer =
        rt_gpu::Renderer::for_scene(&ctx, &s, &gpu_scene, RenderOptions::default()).unwrap();
    renderer.render_batch(2).unwrap();
    let before = renderer.read_image().unwrap();
    assert!(before.channel_means()[0] > 0.0);
    ctx.device.destroy();
    let batch = renderer.render_batch(2);
    let read = renderer.read_image();
    assert!(
        batch.is_err() || read.is_err(),
        "a destroyed device went unnoticed"
    );
    let message = batch.err().or(read.err()).unwrap().to_string();
    assert!(
        message.to_lowercase().contains("lost")
            || message.to_lowercase().contains("destroy")
            || message.to_lowercase().contains("invalid"),
        "{message}"
    );
}

/// Out of memory mid-render (injected: `GpuContext::inject_out_of_memory` fails the next GPU
/// operation as an allocation would) is a clear error, not a panic; nothing rendered before is
/// lost (the accumulation reads back unchanged), and the render can go on once memory allows.
#[test]
fn out_of_memory_mid_render_is_an_error_and_loses_no_samples() {
    if gpu().is_none() {
        return;
    }
    let (ctx, s, gpu_scene) = own_context_and_small_cornell();
    for options in [
        RenderOptions::default(),
        RenderOptions {
            kernel: Kernel::Megakernel,
            ..Default::default()
        },
    ] {
        let mut renderer = rt_gpu::Renderer::for_scene(&ctx, &s, &gpu_scene, options).unwrap();
        renderer.render_batch(2).unwrap();
        let before = renderer.read_image().unwrap();
        assert!(before.channel_means()[0] > 0.0);
        ctx.inject_out_of_memory(1);
        let error = renderer.render_batch(2).unwrap_err();
        assert!(
            matches!(error, rt_gpu::GpuError::OutOfMemory(_))
                && error.to_string().contains("ran out of memory"),
            "{error}"
        );
        let after = renderer.read_image().unwrap();
        assert_eq!(after.samples_per_pixel, before.samples_per_pixel);
        assert!(
            after.pixels == before.pixels,
            "the failed batch changed the image"
        );
        // A batch takes up to 2 samples (how many depends on the measured speed).
        let batch = renderer.render_batch(2).unwrap();
        assert!(batch.samples >= 1);
        assert_eq!(
            renderer.samples_done(),
            before.samples_per_pixel + batch.samples
        );
    }
}

/// A batch that fails part-way (out of memory injected while its bands of rows are being
/// rendered) is finished by the next one: the render then goes on to the same image, bit for bit,
/// as one that never failed; no band gets a sample twice. (A first batch would hide the bug: it
/// starts every pixel's mean afresh.) The failure is injected at many points of the batch, without
/// knowing how many GPU operations a band takes; a failure that left some rows rendered and others
/// not (seen in the image read back after it) must occur among them.
#[test]
fn a_batch_failing_part_way_is_finished_by_the_next() {
    if gpu().is_none() {
        return;
    }
    let (ctx, mut s, _) = own_context_and_small_cornell();
    s.settings.width = 64;
    s.settings.height = 20;
    s.settings.samples_per_pixel = 3;
    let gpu_scene = GpuScene::build(&s).unwrap();
    // With adaptive sampling too: its waves walk the list of pixels still sampling, 64 at a time.
    let adaptive = rt_gpu::Adaptive {
        threshold: 0.3,
        min_samples: 2,
    };
    for (kernel, adaptive) in [
        (Kernel::Wavefront, None),
        (Kernel::Megakernel, None),
        (Kernel::Wavefront, Some(adaptive)),
    ] {
        // A 1 µs target shrinks batches after the first to one sample in bands of one row.
        let options = RenderOptions {
            kernel,
            adaptive,
            target_dispatch: Duration::from_micros(1),
            ..Default::default()
        };
        let clean = render_gpu(&ctx, &s, &gpu_scene, options);
        let mut failed_part_way = false;
        for operations in [2, 3, 5, 8, 13, 21, 34, 55, 89] {
            let mut renderer = rt_gpu::Renderer::for_scene(&ctx, &s, &gpu_scene, options).unwrap();
            renderer.render_batch(1).unwrap();
            let before = renderer.read_image().unwrap();
            ctx.inject_out_of_memory(operations);
            let Err(error) = renderer.render_batch(1) else {
                // The batch ended before the failure: disarm it for the next renderer.
                ctx.inject_out_of_memory(0);
                continue;
            };
            assert!(
                matches!(error, rt_gpu::GpuError::OutOfMemory(_)),
                "{kernel:?}: {error}"
            );
            // A failure in the batch's last operation (reading its counters back) comes after
            // every band has its sample.
            assert!(
                matches!(renderer.samples_done(), 1 | 2),
                "{kernel:?}: {} samples",
                renderer.samples_done()
            );
            let after = renderer.read_image().unwrap();
            let rows_changed = (0..20)
                .filter(|y| {
                    let row = y * 64..(y + 1) * 64;
                    after.pixels[row.clone()] != before.pixels[row]
                })
                .count();
            failed_part_way |= rows_changed > 0 && rows_changed < 20;
            renderer.render(3, |_| true).unwrap();
            let resumed = renderer.read_image().unwrap();
            assert_eq!(resumed.samples_per_pixel, 3);
            assert!(
                resumed.pixels == clean.pixels && resumed.sample_counts == clean.sample_counts,
                "{kernel:?}, adaptive {adaptive:?}, failing at GPU operation {operations}: the \
                 resumed render differs from one that never failed"
            );
        }
        assert!(
            failed_part_way,
            "{kernel:?}: no injected failure landed part-way through a batch"
        );
    }
}

/// The generic kernel (every feature compiled in) and other work-group shapes compute the same
/// image bit for bit as the specialised 8 x 8 default: specialisation only removes dead code, and
/// each pixel's samples do not depend on how pixels are grouped.
#[test]
fn generic_kernels_and_workgroup_shapes_give_identical_images() {
    let Some(ctx) = gpu() else { return };
    let mut s = rt_core::assets::cornell_box().unwrap();
    s.settings.width = 29;
    s.settings.height = 17;
    s.settings.samples_per_pixel = 3;
    let gpu_scene = GpuScene::build(&s).unwrap();
    // Work-group shapes are the megakernel's; the wavefront kernels are specialised too.
    let mega = RenderOptions {
        kernel: Kernel::Megakernel,
        ..Default::default()
    };
    let experiment = |kernel: Kernel, generic_kernel: bool, workgroup: [u32; 2]| RenderOptions {
        kernel,
        tuning: Tuning {
            generic_kernel,
            workgroup,
            ..Default::default()
        },
        ..Default::default()
    };
    let base = render_gpu(ctx, &s, &gpu_scene, mega);
    for options in [
        experiment(Kernel::Megakernel, true, [8, 8]),
        experiment(Kernel::Megakernel, false, [16, 4]),
        experiment(Kernel::Megakernel, true, [32, 1]),
        experiment(Kernel::Wavefront, true, [8, 8]),
    ] {
        let image = render_gpu(ctx, &s, &gpu_scene, options);
        assert!(image.pixels == base.pixels, "{options:?} changed the image");
    }
}

/// A work group too large for the traversal stacks in work-group memory, or a work-group shape
/// asked of the wavefront kernels (whose shape is fixed), is a clear error, not a validation panic
/// or a silently ignored option.
#[test]
fn an_impossible_work_group_is_a_clear_error() {
    let Some(ctx) = gpu() else { return };
    let s = rt_core::assets::cornell_box().unwrap();
    let gpu_scene = GpuScene::build(&s).unwrap();
    for (kernel, workgroup) in [
        (Kernel::Megakernel, [16, 16]),
        (Kernel::Megakernel, [0, 8]),
        (Kernel::Megakernel, [65, 1]),
        (Kernel::Wavefront, [16, 4]),
    ] {
        let options = RenderOptions {
            kernel,
            tuning: Tuning {
                workgroup,
                ..Default::default()
            },
            ..Default::default()
        };
        let Err(e) = rt_gpu::Renderer::for_scene(ctx, &s, &gpu_scene, options) else {
            panic!("{kernel:?} with work group {workgroup:?} was accepted");
        };
        assert!(
            matches!(e, rt_gpu::GpuError::Options(_)) && e.to_string().contains("work group"),
            "{e}"
        );
    }
}

/// A rebuilt pipeline (`RenderOptions::pipeline_lifetime`, against lavapipe's memory growth:
/// `tests/memory.rs`) changes no sample: rebuilding before every batch gives the same bytes as
/// never rebuilding.
#[test]
fn rebuilding_the_pipeline_changes_no_sample() {
    let Some(ctx) = gpu() else { return };
    let mut scene = rt_core::assets::cornell_box().unwrap();
    scene.settings.width = 24;
    scene.settings.height = 24;
    let gpu_scene = GpuScene::build(&scene).unwrap();
    for kernel in [Kernel::Wavefront, Kernel::Megakernel] {
        let render = |lifetime: Duration| {
            let options = RenderOptions {
                max_samples_per_dispatch: Some(1),
                kernel,
                tuning: Tuning {
                    pipeline_lifetime: Some(lifetime),
                    ..Default::default()
                },
                ..Default::default()
            };
            let mut renderer = Renderer::for_scene(ctx, &scene, &gpu_scene, options).unwrap();
            renderer.render(12, |_| true).unwrap();
            (renderer.read_image().unwrap(), renderer.pipeline_rebuilds())
        };
        let (rebuilt, rebuilds) = render(Duration::ZERO);
        let (kept, kept_rebuilds) = render(Duration::from_secs(3600));
        assert!(rebuilds >= 11, "{kernel:?}: {rebuilds} rebuilds");
        assert_eq!(kept_rebuilds, 0);
        assert_eq!(rebuilt.samples_per_pixel, 12);
        assert!(
            rebuilt.pixels == kept.pixels,
            "{kernel:?}: images differ after pipeline rebuilds"
        );
    }
}
