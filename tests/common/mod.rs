//! Shared helpers for the GPU tests: one lavapipe-preferring context for the whole test binary,
//! scene builders, and statistics.
#![allow(dead_code, reason = "each test binary uses a different subset")]

use std::sync::OnceLock;

use glam::Vec3;
use rt_core::{Camera, GpuScene, Material, Mesh, Object, RenderSettings, Scene};
use rt_gpu::{GpuContext, Image, RenderOptions, Renderer};

/// The test GPU context, one for the whole test binary, under the suites' one adapter policy
/// (`GpuContext::for_tests`: a CPU adapter when there is one; without any adapter the test fails
/// when `CI` is set, and otherwise says why and returns `None`).
pub fn gpu() -> Option<&'static GpuContext> {
    static CONTEXT: OnceLock<Option<GpuContext>> = OnceLock::new();
    CONTEXT.get_or_init(GpuContext::for_tests).as_ref()
}

pub fn object(name: &str, mesh: Mesh, material: Material) -> Object {
    Object {
        shadow_catcher: false,
        animation_node: None,
        name: name.into(),
        mesh: mesh.into(),
        material,
        transform: Default::default(),
    }
}

pub fn scene(
    objects: Vec<Object>,
    camera: Camera,
    ambient: [f32; 3],
    settings: RenderSettings,
) -> Scene {
    Scene {
        objects,
        textures: Vec::new(),
        camera,
        ambient,
        settings,
        lights: Vec::new(),
        environment: None,
        fog: Default::default(),
        animation: None,
    }
}

pub fn camera(from: Vec3, to: Vec3, vfov_deg: f32) -> Camera {
    Camera {
        from: from.to_array(),
        to: to.to_array(),
        vfov_deg,
        ..Default::default()
    }
}

pub fn settings(width: u32, height: u32, spp: u32, max_depth: u32) -> RenderSettings {
    RenderSettings {
        width,
        height,
        samples_per_pixel: spp,
        max_depth,
        seed: 1,
        next_event_estimation: true,
        russian_roulette: true,
        clamp: None,
        sampler: Default::default(),
        nee_only: false,
        adaptive_threshold: None,
        adaptive_min_samples: rt_core::scene::ADAPTIVE_MIN_SAMPLES,
        light_sampler: Default::default(),
        film_window: None,
        transparent: false,
        integrator: Default::default(),
    }
}

/// Renders `scene` (or its prepared `gpu_scene`) on the GPU to `scene.settings.samples_per_pixel`.
pub fn render_gpu(
    ctx: &GpuContext,
    scene: &Scene,
    gpu_scene: &GpuScene,
    options: RenderOptions,
) -> Image {
    let mut renderer = Renderer::for_scene(ctx, scene, gpu_scene, options).expect("renderer");
    renderer
        .render(scene.settings.samples_per_pixel, |_| true)
        .expect("render");
    assert_eq!(
        renderer.dropped_samples(),
        0,
        "NaN/Inf samples were produced"
    );
    renderer.read_image().expect("read back")
}

pub fn render(ctx: &GpuContext, scene: &Scene) -> Image {
    render_gpu(
        ctx,
        scene,
        &GpuScene::build(scene).expect("build"),
        RenderOptions::default(),
    )
}

/// Mean of the red channel over the image and its standard error, from the spread of the pixels:
/// valid when every pixel has the same expected value (furnaces, slabs seen through a tiny FOV).
pub fn pixel_mean_and_error(image: &Image) -> (f64, f64) {
    let values: Vec<f64> = image.pixels.iter().map(|p| f64::from(p[0])).collect();
    let n = values.len() as f64;
    let mean = values.iter().sum::<f64>() / n;
    let variance = values.iter().map(|v| (v - mean).powi(2)).sum::<f64>() / (n - 1.0);
    (mean, (variance / n).sqrt())
}

/// Two-sided p-value threshold |z| for a per-test significance `alpha`.
pub fn z_threshold(alpha: f64) -> f64 {
    // Inverse of the normal tail by bisection on erfc; accurate enough for test thresholds.
    let tail = |z: f64| libm_erfc(z / std::f64::consts::SQRT_2);
    let (mut lo, mut hi) = (0.0, 40.0);
    for _ in 0..200 {
        let mid = 0.5 * (lo + hi);
        if tail(mid) > alpha {
            lo = mid
        } else {
            hi = mid
        }
    }
    hi
}

/// Complementary error function (Numerical Recipes' erfcc, relative error < 1.2e-7).
fn libm_erfc(x: f64) -> f64 {
    let z = x.abs();
    let t = 1.0 / (1.0 + 0.5 * z);
    // Horner's rule from the highest coefficient; written as a fold because the nested form makes
    // rustfmt take tens of seconds on every test file that includes this module.
    let poly = [
        1.000_023_68,
        0.374_091_96,
        0.096_784_18,
        -0.186_288_06,
        0.278_868_07,
        -1.135_203_98,
        1.488_515_87,
        -0.822_152_23,
        0.170_872_77,
    ]
    .iter()
    .rev()
    .fold(0.0, |acc, c| c + t * acc);
    let r = t * (-z * z - 1.265_512_23 + t * poly).exp();
    if x >= 0.0 { r } else { 2.0 - r }
}

/// Smooth normals, a texture, a mirror sphere, a rotated and mirrored object, glass and a thin lens.
pub fn textured_scene_with_normals_metal_glass_and_lens() -> Scene {
    use rt_core::shapes::{quad, uv_sphere};
    use rt_core::{Texture, Transform};
    let mut floor = quad(Vec3::ZERO, Vec3::Y, 4.0);
    floor.uvs = Some(vec![
        glam::Vec2::new(0.0, 0.0),
        glam::Vec2::new(2.0, 0.0),
        glam::Vec2::new(2.0, 2.0),
        glam::Vec2::new(0.0, 2.0),
    ]);
    let checker: Vec<u8> = (0..16)
        .flat_map(|i| {
            if (i % 4 + i / 4) % 2 == 0 {
                [230u8, 40, 40, 255]
            } else {
                [30, 30, 200, 255]
            }
        })
        .collect();
    let mut sphere = object(
        "sphere",
        uv_sphere(0.5, 10, 20),
        Material::Metal {
            albedo: [0.95; 3],
            fuzz: 0.0,
        },
    );
    sphere.transform = Transform {
        translation: [0.0, 0.5, 0.0],
        rotation_deg: [10.0, 20.0, 30.0],
        scale: [1.0, -1.0, 1.0],
    };
    let mut scene = scene(
        vec![
            object(
                "floor",
                floor,
                Material::Lambertian {
                    albedo: [1.0; 3],
                    texture: Some(0),
                },
            ),
            sphere,
            object(
                "glass",
                uv_sphere(0.3, 8, 16),
                Material::Dielectric {
                    ior: 1.33,
                    tint: [1.0; 3],
                },
            ),
        ],
        camera(Vec3::new(0.0, 1.5, 3.0), Vec3::new(0.0, 0.3, 0.0), 50.0),
        [0.9, 0.9, 1.0],
        settings(16, 12, 1, 5),
    );
    scene.objects[2].transform.translation = [0.8, 0.3, 0.5];
    scene.camera.aperture_radius = 0.05;
    scene.textures.push(Texture {
        sampler: Default::default(),
        name: "checker".into(),
        width: 4,
        height: 4,
        rgba8: checker.into(),
    });
    scene
}

pub fn pbr(p: rt_core::material::Pbr) -> Material {
    Material::Pbr(Box::new(p))
}

/// A small procedural environment: a sky gradient, a warm "sun" texel and a dark ground.
pub fn test_environment() -> rt_core::Environment {
    let (w, h) = (16u32, 8u32);
    let mut texels = Vec::new();
    for y in 0..h {
        for x in 0..w {
            let t = y as f32 / (h - 1) as f32;
            texels.push(if (x, y) == (5, 2) {
                [60.0, 50.0, 35.0]
            } else if y >= h / 2 {
                [0.15, 0.12, 0.1]
            } else {
                [0.4 + 0.5 * t, 0.55 + 0.4 * t, 0.95]
            });
        }
    }
    let mut env = rt_core::Environment::new(
        "test sky",
        rt_core::EnvironmentMap::from_texels(w, h, texels).0,
    );
    env.rotation_deg = 30.0;
    env.strength = 1.5;
    env
}

/// Every PBR feature: a textured, brushed (anisotropic) plastic floor with a sheen, a coat and
/// specular images, rough gold under a clear coat and a thin film, rough anisotropic absorbing
/// glass, smooth glass, a rough metal with an interpolated normal, an emissive PBR plate
/// with a tinted specular strength, an area light and an
/// environment map (so next-event estimation picks between emitters and the environment).
pub fn pbr_scene_with_environment(width: u32, height: u32) -> Scene {
    use rt_core::material::Pbr;
    use rt_core::shapes::{quad, uv_sphere};
    let mut scene = textured_scene_with_normals_metal_glass_and_lens();
    scene.camera.aperture_radius = 0.0;
    scene.settings.width = width;
    scene.settings.height = height;
    scene.settings.max_depth = 6;
    // A bumpy normal map and a metallic-roughness image varying over the floor.
    let bumps: Vec<u8> = (0..16u32)
        .flat_map(|i| {
            let (x, y) = (i % 4, i / 4);
            let tilt = |v: u32| (128 + (v as i32 - 1) * 60) as u8;
            [tilt(x), tilt(y), 220, 255]
        })
        .collect();
    let mr: Vec<u8> = (0..16u32)
        .flat_map(|i| {
            [
                0,
                (40 + 13 * i) as u8,
                if i % 3 == 0 { 255 } else { 0 },
                255,
            ]
        })
        .collect();
    for (name, rgba) in [("bumps", bumps), ("metal-rough", mr)] {
        scene.textures.push(rt_core::Texture {
            sampler: Default::default(),
            name: name.into(),
            width: 4,
            height: 4,
            rgba8: rgba.into(),
        });
    }
    let mut floor = (*scene.objects[0].mesh).clone();
    floor.normals = Some(vec![Vec3::Y; floor.positions.len()]);
    floor.colors = Some(vec![
        Vec3::new(1.0, 0.9, 0.8),
        Vec3::new(0.3, 1.0, 0.5),
        Vec3::new(0.9, 0.4, 1.0),
        Vec3::ONE,
    ]);
    scene.objects[0].mesh = std::sync::Arc::new(floor);
    scene.objects[0].material = pbr(Pbr {
        base_color: [0.9; 3],
        texture: Some(0),
        normal_texture: Some(1),
        normal_scale: 0.8,
        metallic_roughness_texture: Some(2),
        roughness: 0.6,
        metallic: 0.8,
        sheen_color: [0.6, 0.3, 0.2],
        sheen_roughness: 0.4,
        // Every layer's image: bumps' red varies the coat, metal-rough's green its roughness.
        clearcoat: 0.7,
        clearcoat_roughness: 0.5,
        clearcoat_texture: Some(1),
        clearcoat_roughness_texture: Some(2),
        sheen_color_texture: Some(0),
        sheen_roughness_texture: Some(1),
        specular: 0.8,
        specular_texture: Some(1),
        specular_color_texture: Some(0),
        clearcoat_normal_texture: Some(1),
        clearcoat_normal_scale: 0.5,
        // Brushed along directions the bumps' red and green turn, by strengths their blue scales.
        anisotropy: 0.7,
        anisotropy_rotation: 0.5,
        anisotropy_texture: Some(1),
        ..Default::default()
    });
    scene.objects[1].material = pbr(Pbr {
        base_color: [1.0, 0.766, 0.336],
        metallic: 1.0,
        roughness: 0.5,
        clearcoat: 0.8,
        clearcoat_roughness: 0.15,
        // Under the coat, a thin film on the gold.
        iridescence: 0.7,
        iridescence_thickness_max: 450.0,
        // The film's weight and thickness vary with images.
        iridescence_texture: Some(0),
        iridescence_thickness_texture: Some(2),
        ..Default::default()
    });
    scene.objects[2].material = pbr(Pbr {
        base_color: [1.0; 3],
        roughness: 0.25,
        transmission: 1.0,
        attenuation_color: [0.6, 0.8, 0.9],
        attenuation_distance: Some(0.5),
        // Rough glass brushed around the sphere, splitting light into colours.
        anisotropy: 0.6,
        dispersion: 0.8,
        ..Default::default()
    });
    let mut smooth_glass = object(
        "smooth glass",
        uv_sphere(0.25, 8, 16),
        pbr(Pbr {
            base_color: [1.0; 3],
            roughness: 0.0,
            transmission: 1.0,
            ior: 1.5,
            ..Default::default()
        }),
    );
    smooth_glass.transform.translation = [-0.9, 0.25, 0.4];
    scene.objects.push(smooth_glass);
    let mut plate = object(
        "glowing plate",
        quad(Vec3::new(-0.6, 0.8, -1.0), Vec3::new(0.3, 0.0, 1.0), 0.5),
        pbr(Pbr {
            base_color: [0.2, 0.3, 0.8],
            roughness: 0.6,
            transmission: 0.6,
            thin_walled: true,
            emission: [1.0, 0.5, 0.2],
            emission_strength: 3.0,
            specular: 0.6,
            specular_color: [1.0, 0.5, 2.0],
            // Its emission passes a coat, towards the camera and towards light sampling alike.
            clearcoat: 0.6,
            // And some of its diffuse light goes through, greener.
            diffuse_transmission: 0.5,
            diffuse_transmission_color: [0.4, 1.0, 0.3],
            diffuse_transmission_texture: Some(1),
            diffuse_transmission_color_texture: Some(0),
            ..Default::default()
        }),
    );
    plate.transform.translation = [0.0; 3];
    scene.objects.push(plate);
    scene.objects.push(object(
        "lamp",
        quad(Vec3::new(0.5, 2.2, 0.5), Vec3::NEG_Y, 0.6),
        Material::Emissive {
            color: [1.0, 0.95, 0.9],
            intensity: 8.0,
        },
    ));
    scene.environment = Some(test_environment());
    scene
}

/// Per object of `scene`: the sums of `image`'s and of the reference image's (`path`, an EXR of the
/// same size) pixels that show it, per channel, and their count. A pixel shows the object a
/// camera ray through its centre first lands on (the pinhole camera's).
pub fn object_sums(
    scene: &Scene,
    image: &Image,
    path: &std::path::Path,
) -> Vec<([f64; 3], [f64; 3], usize)> {
    region_sums(scene, image, path, scene.objects.len(), |object, _, _| {
        Some(object)
    })
}

/// Each object's own pixels (`object_sums`) against another renderer's reference image: the sum
/// of its channels within `tolerance` (relative) of the reference's, so a small object cannot hide
/// behind the image's mean. Prints each object's difference.
pub fn assert_objects_match(
    scene: &Scene,
    image: &Image,
    path: &std::path::Path,
    who: &str,
    tolerance: f64,
) {
    let sums = object_sums(scene, image, path);
    for (object, (ours, theirs, pixels)) in scene.objects.iter().zip(sums) {
        if pixels == 0 {
            continue;
        }
        let difference = ours.iter().sum::<f64>() / theirs.iter().sum::<f64>() - 1.0;
        eprintln!(
            "{}: {pixels} pixels, rt/{who} {:+.2}%",
            object.name,
            100.0 * difference
        );
        assert!(
            difference.abs() <= tolerance,
            "{}: rt differs from {who} by {:+.2}% over its {pixels} pixels",
            object.name,
            100.0 * difference
        );
    }
}

/// As `object_sums`, for the pixels of object `name` in `tile` × `tile` squares of the image:
/// entry (y / tile) · ⌈width / tile⌉ + x / tile.
pub fn object_tile_sums(
    scene: &Scene,
    image: &Image,
    path: &std::path::Path,
    name: &str,
    tile: u32,
) -> Vec<([f64; 3], [f64; 3], usize)> {
    let wanted = scene.objects.iter().position(|o| o.name == name).unwrap();
    let across = image.width.div_ceil(tile);
    let regions = (across * image.height.div_ceil(tile)) as usize;
    region_sums(scene, image, path, regions, |object, x, y| {
        (object == wanted).then_some(((y / tile) * across + x / tile) as usize)
    })
}

/// Sums of `image`'s and the reference's pixels per region, `region(object, x, y)` naming the
/// region of the pixel that shows `object` (`object_sums`).
fn region_sums(
    scene: &Scene,
    image: &Image,
    path: &std::path::Path,
    regions: usize,
    region: impl Fn(usize, u32, u32) -> Option<usize>,
) -> Vec<([f64; 3], [f64; 3], usize)> {
    let (width, height) = (image.width, image.height);
    let theirs: Vec<[f32; 3]> = ::image::open(path)
        .unwrap_or_else(|e| panic!("reading {}: {e}", path.display()))
        .to_rgb32f()
        .pixels()
        .map(|p| p.0)
        .collect();
    let mut sums = vec![([0.0f64; 3], [0.0f64; 3], 0usize); regions];
    for (i, hit) in pixel_hits(scene, width, height).into_iter().enumerate() {
        let Some((object, _)) = hit else {
            continue;
        };
        let (x, y) = (i as u32 % width, i as u32 / width);
        let Some(r) = region(object, x, y) else {
            continue;
        };
        let s = &mut sums[r];
        for (c, (ours, reference)) in s.0.iter_mut().zip(&mut s.1).enumerate() {
            *ours += f64::from(image.pixels[i][c]);
            *reference += f64::from(theirs[i][c]);
        }
        s.2 += 1;
    }
    sums
}

/// Per pixel of a `width` × `height` image of `scene`: the object a camera ray through its centre
/// first lands on (the pinhole camera's) and where, or `None` where the ray leaves the scene.
pub fn pixel_hits(scene: &Scene, width: u32, height: u32) -> Vec<Option<(usize, Vec3)>> {
    let gpu_scene = rt_core::GpuScene::build(scene).unwrap();
    let frame = rt_core::frame::frame_for(scene, &gpu_scene).unwrap();
    let origin = Vec3::from(frame.cam_origin);
    (0..width * height)
        .map(|i| {
            let (x, y) = (i % width, i / width);
            let sx =
                (2.0 * (x as f32 + 0.5) / width as f32 - 1.0) * frame.tan_half_vfov * frame.aspect;
            let sy = (1.0 - 2.0 * (y as f32 + 0.5) / height as f32) * frame.tan_half_vfov;
            let direction = (sx * Vec3::from(frame.cam_u) + sy * Vec3::from(frame.cam_v)
                - Vec3::from(frame.cam_w))
            .normalize();
            let hit = rt_core::estimator::trace(&gpu_scene, origin, direction, f32::MAX);
            (hit.triangle != u32::MAX).then(|| {
                let object = gpu_scene.triangles[hit.triangle as usize].material as usize;
                (object, origin + direction * hit.t)
            })
        })
        .collect()
}

/// Compares a render with another renderer's reference image (`path`, an EXR of the same size):
/// every channel's mean within `mean_tolerance` (relative), and at most 5% of the 32-px blocks
/// off by more than `block_tolerance` (relative, on the sum of their channels; blocks dark in
/// both, less than 1e-3 per channel on average apart, agree).
pub fn assert_matches_reference(
    image: &Image,
    path: &std::path::Path,
    who: &str,
    mean_tolerance: f64,
    block_tolerance: f64,
) {
    let (width, height) = (image.width, image.height);
    let reference = ::image::open(path)
        .unwrap_or_else(|e| panic!("reading {}: {e}", path.display()))
        .to_rgb32f();
    assert_eq!(reference.dimensions(), (width, height));
    let reference: Vec<[f32; 3]> = reference.pixels().map(|p| p.0).collect();
    let n = f64::from(width * height);
    for ch in 0..3 {
        let ours: f64 = image.pixels.iter().map(|p| f64::from(p[ch])).sum::<f64>() / n;
        let theirs: f64 = reference.iter().map(|p| f64::from(p[ch])).sum::<f64>() / n;
        eprintln!("channel {ch}: rt {ours:.5}, {who} {theirs:.5}");
        assert!(
            (ours / theirs - 1.0).abs() <= mean_tolerance,
            "channel {ch}: rt's mean {ours:.5} is not within {}% of {who}'s {theirs:.5}",
            mean_tolerance * 100.0
        );
    }
    let (mut blocks, mut off) = (0, Vec::new());
    for by in (0..height).step_by(32) {
        for bx in (0..width).step_by(32) {
            let (mut ours, mut theirs) = (0.0f64, 0.0f64);
            for y in by..(by + 32).min(height) {
                for x in bx..(bx + 32).min(width) {
                    let i = (y * width + x) as usize;
                    ours += (0..3).map(|c| f64::from(image.pixels[i][c])).sum::<f64>();
                    theirs += reference[i].iter().map(|&c| f64::from(c)).sum::<f64>();
                }
            }
            blocks += 1;
            let d = (ours - theirs).abs();
            if d > block_tolerance * theirs && d > 1e-3 * 32.0 * 32.0 * 3.0 {
                off.push((bx, by, ours / theirs - 1.0));
            }
        }
    }
    assert!(
        off.len() as f64 <= 0.05 * f64::from(blocks),
        "{} of {blocks} blocks differ from {who} by more than {}%: {off:?}",
        off.len(),
        block_tolerance * 100.0
    );
}

/// glTF's texture and alpha features: a fence quad masked by its base colour image's alpha
/// (nearest, clamped), a curtain blended at α = 0.45 times its image's alpha, and an emissive
/// panel whose emission image repeats mirrored and whose holes (a cutoff over the factor's alpha
/// times the image) cut the light it gives, over a floor lit by an area light, a sun and the sky.
pub fn alpha_and_emission_textures_scene(width: u32, height: u32) -> Scene {
    use rt_core::material::{AlphaMode, Pbr};
    use rt_core::shapes::quad;
    use rt_core::{Filter, Texture, TextureSampler, Wrap};
    let uv_quad = |center: Vec3, normal: Vec3, size: f32, repeat: f32| {
        let mut q = quad(center, normal, size);
        q.uvs = Some(
            [(0.0, 0.0), (repeat, 0.0), (repeat, repeat), (0.0, repeat)]
                .map(|(u, v)| glam::Vec2::new(u, v))
                .to_vec(),
        );
        q
    };
    // 4x4 RGBA: a lattice of solid bars with holes; the curtain's stripes; the panel's pattern.
    let fence: Vec<u8> = (0..16u32)
        .flat_map(|i| {
            let solid = i % 4 == 0 || i / 4 == 0;
            [200, 150, 90, if solid { 255 } else { 0 }]
        })
        .collect();
    let stripes: Vec<u8> = (0..16u32)
        .flat_map(|i| [60, 90, 220, if i % 2 == 0 { 255 } else { 120 }])
        .collect();
    let pattern: Vec<u8> = (0..16u32)
        .flat_map(|i| {
            let lit = (i % 4 + i / 4) % 3 != 0;
            [
                255,
                if lit { 230 } else { 40 },
                120,
                if lit { 255 } else { 60 },
            ]
        })
        .collect();
    let sampler = |wrap: Wrap, filter: Filter| TextureSampler {
        wrap_s: wrap,
        wrap_t: wrap,
        filter,
    };
    let mut s = scene(
        vec![
            object(
                "floor",
                quad(Vec3::ZERO, Vec3::Y, 6.0),
                Material::lambertian([0.7; 3]),
            ),
            object(
                "fence",
                uv_quad(
                    Vec3::new(-0.6, 0.8, 0.3),
                    Vec3::new(0.3, 0.0, 1.0).normalize(),
                    1.4,
                    1.3,
                ),
                pbr(Pbr {
                    base_color: [1.0; 3],
                    texture: Some(0),
                    roughness: 0.7,
                    alpha_mode: AlphaMode::Mask,
                    ..Default::default()
                }),
            ),
            object(
                "curtain",
                uv_quad(
                    Vec3::new(0.7, 0.8, 0.0),
                    Vec3::new(-0.2, 0.0, 1.0).normalize(),
                    1.4,
                    1.0,
                ),
                pbr(Pbr {
                    base_color: [0.9; 3],
                    texture: Some(1),
                    roughness: 0.4,
                    alpha_mode: AlphaMode::Blend,
                    alpha: 0.45,
                    ..Default::default()
                }),
            ),
            object(
                "panel",
                uv_quad(
                    Vec3::new(0.0, 1.2, -1.2),
                    Vec3::new(0.0, -0.3, 1.0).normalize(),
                    1.6,
                    2.5,
                ),
                pbr(Pbr {
                    base_color: [0.2; 3],
                    texture: Some(2),
                    emission: [2.0, 1.5, 1.0],
                    emission_texture: Some(2),
                    alpha_mode: AlphaMode::Mask,
                    alpha: 0.9,
                    alpha_cutoff: 0.3,
                    ..Default::default()
                }),
            ),
            object(
                "light",
                quad(Vec3::new(0.0, 3.0, 0.5), Vec3::NEG_Y, 1.0),
                Material::Emissive {
                    color: [1.0, 0.95, 0.9],
                    intensity: 6.0,
                },
            ),
        ],
        camera(Vec3::new(0.3, 1.4, 3.2), Vec3::new(0.0, 0.7, 0.0), 50.0),
        [0.25, 0.3, 0.4],
        settings(width, height, 1, 5),
    );
    for (name, rgba, sampler) in [
        ("fence", fence, sampler(Wrap::ClampToEdge, Filter::Nearest)),
        ("stripes", stripes, sampler(Wrap::Repeat, Filter::Linear)),
        (
            "pattern",
            pattern,
            sampler(Wrap::MirroredRepeat, Filter::Linear),
        ),
    ] {
        s.textures.push(Texture {
            name: name.into(),
            width: 4,
            height: 4,
            rgba8: rgba.into(),
            sampler,
        });
    }
    let mut sun = rt_core::Light::new(rt_core::LightKind::Directional, "sun");
    sun.direction = [-0.3, -1.0, -0.4];
    sun.intensity = 1.5;
    s.lights.push(sun);
    s
}

/// `scene` with its blended surfaces made opaque (masks kept): for comparisons in lockstep, which
/// blending's coin, hashed from a ray's exact bits, does not survive rounding.
pub fn masked_only(mut scene: Scene) -> Scene {
    for o in &mut scene.objects {
        if let Material::Pbr(p) = &mut o.material
            && p.alpha_mode == rt_core::material::AlphaMode::Blend
        {
            p.alpha_mode = rt_core::material::AlphaMode::Opaque;
        }
    }
    scene
}
