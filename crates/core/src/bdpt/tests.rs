//! Bidirectional path tracing against the path tracer, per pixel, on scenes both render without
//! bias (lit by emitters, point and spot lights, an environment map or the ambient light); light
//! tracing alone against the path tracer on a diffuse scene; and the MIS weights of
//! every strategy that makes one path summing to 1.

use std::sync::atomic::AtomicBool;

use glam::Vec3;

use super::connect::Contribution;
use super::*;
use crate::cpu_render::CpuAccumulation;
use crate::light::Light;
use crate::light_kind::LightKind;
use crate::scene::{Integrator, Object, RenderSettings, Scene, Transform};
use crate::shapes::{cuboid, quad, uv_sphere};

fn object(name: &str, mesh: crate::Mesh, material: crate::Material, at: [f32; 3]) -> Object {
    Object {
        shadow_catcher: false,
        animation_node: None,
        name: name.into(),
        mesh: std::sync::Arc::new(mesh),
        material,
        transform: Transform {
            translation: at,
            ..Default::default()
        },
    }
}

fn lambert(albedo: [f32; 3]) -> crate::Material {
    crate::Material::Lambertian {
        albedo,
        texture: None,
    }
}

/// A closed room with a lamp in its ceiling, a box on its floor, `extra` objects and `lights`.
fn room(extra: Vec<Object>, lights: Vec<Light>, size: (u32, u32)) -> (GpuScene, Frame) {
    room_of(lambert([0.7, 0.6, 0.5]), extra, lights, size)
}

/// `room` with walls of `walls`.
fn room_of(
    walls: crate::Material,
    extra: Vec<Object>,
    lights: Vec<Light>,
    (width, height): (u32, u32),
) -> (GpuScene, Frame) {
    let mut objects = vec![
        object(
            "room",
            cuboid(Vec3::splat(-1.0), Vec3::ONE, true),
            walls,
            [0.0; 3],
        ),
        object(
            "lamp",
            quad(Vec3::new(0.0, 0.99, 0.0), Vec3::NEG_Y, 0.5),
            crate::Material::Emissive {
                color: [1.0; 3],
                intensity: 6.0,
            },
            [0.0; 3],
        ),
        object(
            "box",
            cuboid(
                Vec3::new(-0.7, -1.0, -0.6),
                Vec3::new(-0.3, -0.5, -0.2),
                false,
            ),
            lambert([0.3, 0.6, 0.3]),
            [0.0; 3],
        ),
    ];
    objects.extend(extra);
    let camera = ([0.0, 0.0, 0.95], [0.0, -0.3, -1.0]);
    build(objects, camera, (width, height), lights, [0.0; 3], None)
}

/// The scene of `objects` seen from `camera` (from, to) at `size`, depth 5, built.
fn build(
    objects: Vec<Object>,
    (from, to): ([f32; 3], [f32; 3]),
    (width, height): (u32, u32),
    lights: Vec<Light>,
    ambient: [f32; 3],
    environment: Option<crate::environment::Environment>,
) -> (GpuScene, Frame) {
    let scene = Scene {
        objects,
        textures: Vec::new(),
        camera: crate::Camera {
            from,
            to,
            ..Default::default()
        },
        ambient,
        settings: RenderSettings {
            width,
            height,
            max_depth: 5,
            ..Default::default()
        },
        lights,
        environment,
        fog: Default::default(),
        animation: None,
    };
    let gpu = GpuScene::build(&scene).unwrap();
    let frame = crate::frame::frame_for(&scene, &gpu).unwrap();
    (gpu, frame)
}

fn point_and_spot() -> Vec<Light> {
    let mut point = Light::new(LightKind::Point, "point");
    point.position = [0.5, 0.3, -0.4];
    point.intensity = 0.6;
    let mut spot = Light::new(LightKind::Spot, "spot");
    spot.position = [-0.5, 0.8, 0.2];
    spot.direction = [0.3, -1.0, -0.4];
    spot.intensity = 2.0;
    vec![point, spot]
}

/// Glass, a rough metal and rough PBR glass: delta and glossy vertices.
fn glass_things() -> Vec<Object> {
    let rough_glass = crate::material::Pbr {
        base_color: [0.9, 0.95, 1.0],
        roughness: 0.3,
        transmission: 1.0,
        ..Default::default()
    };
    vec![
        object(
            "glass ball",
            uv_sphere(0.3, 24, 48),
            crate::Material::Dielectric {
                ior: 1.5,
                tint: [1.0; 3],
            },
            [0.35, -0.7, -0.4],
        ),
        object(
            "metal",
            cuboid(
                Vec3::new(0.2, -1.0, -0.95),
                Vec3::new(0.8, -0.2, -0.8),
                false,
            ),
            crate::Material::Metal {
                albedo: [0.8, 0.7, 0.6],
                fuzz: 0.1,
            },
            [0.0; 3],
        ),
        object(
            "rough glass",
            cuboid(Vec3::new(-0.2, -1.0, 0.1), Vec3::new(0.2, -0.6, 0.4), false),
            crate::Material::Pbr(Box::new(rough_glass)),
            [0.0; 3],
        ),
    ]
}

/// `blocks` images (per-pixel mean luminance) of `per_block` samples each, on disjoint samples.
fn blocks(
    scene: &GpuScene,
    frame: &Frame,
    integrator: Integrator,
    blocks: u32,
    per_block: u32,
) -> Vec<Vec<f64>> {
    let go = AtomicBool::new(false);
    (0..blocks)
        .map(|b| {
            let accumulation = CpuAccumulation::new(frame, b * per_block, None, false);
            let mut accumulation = accumulation
                .with_integrator(integrator, scene, frame)
                .unwrap();
            assert!(accumulation.add_batch(scene, frame, per_block, &go));
            accumulation
                .pixels()
                .iter()
                .map(|p| {
                    f64::from(crate::math::sampling::luminance(Vec3::new(
                        p[0], p[1], p[2],
                    )))
                })
                .collect()
        })
        .collect()
}

/// Per pixel, the mean over blocks and the variance of that mean.
fn mean_and_variance(blocks: &[Vec<f64>]) -> Vec<(f64, f64)> {
    let k = blocks.len() as f64;
    (0..blocks[0].len())
        .map(|i| {
            let mean = blocks.iter().map(|b| b[i]).sum::<f64>() / k;
            let var = blocks.iter().map(|b| (b[i] - mean).powi(2)).sum::<f64>() / (k - 1.0);
            (mean, var / k)
        })
        .collect()
}

/// Z-tests of two images' pixels and of their means: few pixels beyond 4σ (heavy-tailed pixels
/// make a few), and the image means within 4σ of each other.
fn assert_agree(a: &[Vec<f64>], b: &[Vec<f64>], what: &str) {
    let (a, b) = (mean_and_variance(a), mean_and_variance(b));
    let n = a.len();
    let mut outliers = 0;
    for (i, (&(ma, va), &(mb, vb))) in a.iter().zip(&b).enumerate() {
        let z = (ma - mb) / (va + vb).sqrt().max(1e-9);
        if z.abs() > 4.0 {
            outliers += 1;
            eprintln!("{what}: pixel {i}: {ma:.4} vs {mb:.4}, z = {z:.1}");
        }
    }
    assert!(
        outliers * 100 <= n,
        "{what}: {outliers} of {n} pixels differ beyond 4σ"
    );
    let sum = |v: &[(f64, f64)]| {
        let m = v.iter().map(|p| p.0).sum::<f64>() / n as f64;
        let var = v.iter().map(|p| p.1).sum::<f64>() / (n * n) as f64;
        (m, var)
    };
    let ((ma, va), (mb, vb)) = (sum(&a), sum(&b));
    let z = (ma - mb) / (va + vb).sqrt();
    assert!(
        z.abs() < 4.0,
        "{what}: image means {ma:.5} vs {mb:.5}, z = {z:.1}"
    );
    assert!(ma > 0.01, "{what}: the image is black");
}

/// A glossy plastic block (the PBR BSDF, whose energy compensation makes it non-reciprocal).
fn plastic() -> Object {
    let plastic = crate::material::Pbr {
        base_color: [0.8, 0.3, 0.2],
        roughness: 0.4,
        ..Default::default()
    };
    object(
        "plastic",
        cuboid(
            Vec3::new(0.1, -1.0, -0.9),
            Vec3::new(0.7, -0.4, -0.5),
            false,
        ),
        crate::Material::Pbr(Box::new(plastic)),
        [0.0; 3],
    )
}

#[test]
fn bdpt_agrees_with_path_tracing_on_diffuse_and_delta_lights() {
    let (scene, frame) = room(vec![plastic()], point_and_spot(), (16, 12));
    let path = blocks(&scene, &frame, Integrator::Path, 16, 64);
    let bdpt = blocks(&scene, &frame, Integrator::Bdpt, 16, 32);
    assert_agree(&path, &bdpt, "diffuse room");
}

#[test]
fn bdpt_agrees_with_path_tracing_through_glass_and_metal() {
    let (scene, frame) = room(glass_things(), Vec::new(), (16, 12));
    let path = blocks(&scene, &frame, Integrator::Path, 16, 128);
    let bdpt = blocks(&scene, &frame, Integrator::Bdpt, 16, 32);
    assert_agree(&path, &bdpt, "glass room");
}

/// A glass ball, a plastic block and a diffuse block on a floor under open sky: `environment`,
/// else the ambient light `ambient`.
fn outdoors(
    environment: Option<crate::environment::Environment>,
    ambient: [f32; 3],
) -> (GpuScene, Frame) {
    let (mut glass, plastic) = (glass_things().remove(0), plastic());
    glass.transform.translation = [0.0, -0.7, -0.3];
    let objects = vec![
        object(
            "floor",
            quad(Vec3::new(0.0, -1.0, 0.0), Vec3::Y, 4.0),
            lambert([0.7, 0.6, 0.5]),
            [0.0; 3],
        ),
        glass,
        plastic,
        object(
            "block",
            cuboid(
                Vec3::new(-0.8, -1.0, -0.8),
                Vec3::new(-0.4, -0.4, -0.4),
                false,
            ),
            lambert([0.3, 0.6, 0.3]),
            [0.0; 3],
        ),
    ];
    let camera = ([0.0, 0.4, 1.4], [0.0, -0.8, -0.4]);
    build(objects, camera, (16, 12), Vec::new(), ambient, environment)
}

/// A 16 × 8 sky, blue above the horizon and dark below, with a small bright sun.
fn sky() -> crate::environment::Environment {
    let (w, h) = (16u32, 8u32);
    let texels = (0..w * h)
        .map(|i| {
            let (x, y) = (i % w, i / w);
            if (x, y) == (5, 1) {
                [60.0, 50.0, 40.0]
            } else if y < h / 2 {
                [0.3, 0.45, 0.8]
            } else {
                [0.05, 0.04, 0.03]
            }
        })
        .collect();
    crate::environment::Environment {
        source: "test sky".into(),
        rotation_deg: 30.0,
        strength: 1.0,
        map: std::sync::Arc::new(crate::environment::EnvironmentMap {
            width: w,
            height: h,
            texels,
        }),
    }
}

/// An environment's share of light subpaths is its light above its mean: a map of radiance a
/// over the upper hemisphere and b below (mean (a + b)/2) has ∫ max(0, L − L̄) dω = (a − b)π; a
/// uniform one none.
#[test]
fn an_environment_starts_light_subpaths_with_its_light_above_its_mean() {
    let map = |upper: f32, lower: f32| {
        let (w, h) = (32u32, 64u32);
        let texels = (0..w * h)
            .map(|i| [if i / w < h / 2 { upper } else { lower }; 3])
            .collect();
        crate::environment::Environment {
            source: "two tones".into(),
            rotation_deg: 0.0,
            strength: 1.0,
            map: std::sync::Arc::new(crate::environment::EnvironmentMap {
                width: w,
                height: h,
                texels,
            }),
        }
    };
    let (scene, frame) = outdoors(Some(map(3.0, 1.0)), [0.0; 3]);
    let excess = lights::environment_excess(&scene, &frame);
    let expected = 2.0 * std::f32::consts::PI;
    assert!(
        (excess / expected - 1.0).abs() < 1e-3,
        "two tones: {excess}, expected {expected}"
    );
    let (scene, frame) = outdoors(Some(map(2.0, 2.0)), [0.0; 3]);
    let excess = lights::environment_excess(&scene, &frame);
    assert!(excess.abs() < 1e-5, "uniform: {excess}");
}

/// Light subpaths start from an environment map with a sun and strategy s = 1 connects to it;
/// a uniform ambient light starts none (camera paths that escape are its only strategy): either
/// way the images equal the path tracer's.
#[test]
fn bdpt_agrees_with_path_tracing_under_an_environment() {
    for (environment, ambient, picked, what) in [
        (Some(sky()), [0.0; 3], 1.0, "sky map"),
        (None, [0.5, 0.6, 0.8], 0.0, "ambient light"),
    ] {
        let (scene, frame) = outdoors(environment, ambient);
        let choice = LightChoice::new(&scene, &frame);
        assert!(
            (choice.environment - picked).abs() < 1e-6,
            "{what}: the environment is picked with {}, not {picked}",
            choice.environment
        );
        let path = blocks(&scene, &frame, Integrator::Path, 16, 128);
        let bdpt = blocks(&scene, &frame, Integrator::Bdpt, 16, 32);
        assert_agree(&path, &bdpt, what);
    }
}

/// Light tracing alone (every t = 1 strategy, unweighted), splatted: an unbiased image of its
/// own on a scene without delta surfaces; with glossy PBR walls it checks that light subpaths see
/// the PBR BSDF from the side they leave towards (a BSDF kept for the wrong ωo fails it).
#[test]
fn light_tracing_alone_agrees_with_path_tracing() {
    let glossy = crate::material::Pbr {
        base_color: [0.7, 0.6, 0.5],
        roughness: 0.5,
        ..Default::default()
    };
    for (walls, blocks_of) in [
        (lambert([0.7, 0.6, 0.5]), 16),
        (crate::Material::Pbr(Box::new(glossy)), 48),
    ] {
        let (scene, frame) = room_of(walls, Vec::new(), point_and_spot(), (16, 12));
        let light_tracing = light_tracing_blocks(&scene, &frame, blocks_of, 32);
        let path = blocks(&scene, &frame, Integrator::Path, blocks_of, 64);
        assert_agree(&path, &light_tracing, "light tracing");
    }
}

/// With the denoiser's guides asked for, bdpt records each sample's first hit as the path tracer
/// does, from the same camera rays: guides, alpha, depth and object ids equal the path tracer's
/// bit for bit (in a room with glass and metal, and outdoors where camera rays escape to a sky
/// map).
#[test]
fn bdpt_records_the_path_tracers_first_hits() {
    let room = room(glass_things(), point_and_spot(), (16, 12));
    for (what, (scene, frame)) in [
        ("room", room),
        ("outdoors", outdoors(Some(sky()), [0.0; 3])),
    ] {
        let go = AtomicBool::new(false);
        let run = |integrator| {
            let accumulation = CpuAccumulation::new(&frame, 0, None, true);
            let mut accumulation = accumulation
                .with_integrator(integrator, &scene, &frame)
                .unwrap();
            assert!(accumulation.add_batch(&scene, &frame, 3, &go));
            assert!(accumulation.add_batch(&scene, &frame, 2, &go));
            accumulation
        };
        let (path, bdpt) = (run(Integrator::Path), run(Integrator::Bdpt));
        let (a, b) = (path.guides().unwrap(), bdpt.guides().unwrap());
        assert_eq!(a.albedo, b.albedo, "{what}: albedo");
        assert_eq!(a.normal, b.normal, "{what}: normal");
        assert_eq!(a.emission, b.emission, "{what}: emission");
        let (a, b) = (path.first_hits().unwrap(), bdpt.first_hits().unwrap());
        assert_eq!(a.coverage, b.coverage, "{what}: coverage");
        assert_eq!(a.depth_weighted, b.depth_weighted, "{what}: depth");
        assert_eq!(a.object, b.object, "{what}: objects");
        assert!(b.coverage.contains(&1.0), "{what}: nothing met");
        // Outdoors some camera rays see the sky: the escaped rays' emission is compared too.
        let emitting = bdpt.guides().unwrap().emission.iter().any(|e| e[0] > 0.0);
        assert!(emitting || what == "room", "{what}: no light seen directly");
    }
}

/// Images of light tracing alone: `count` blocks of `per_block` light subpaths per pixel.
fn light_tracing_blocks(
    scene: &GpuScene,
    frame: &Frame,
    count: u32,
    per_block: u32,
) -> Vec<Vec<f64>> {
    let choice = LightChoice::new(scene, frame);
    let walks = Walks {
        scene,
        frame,
        choice: &choice,
    };
    let (w, h) = (frame.width, frame.height);
    (0..count)
        .map(|b| {
            let mut image = vec![Vec3::ZERO; (w * h) as usize];
            let mut light = Vec::new();
            for pixel in 0..w * h {
                for sample in b * per_block..(b + 1) * per_block {
                    let rng = crate::math::rng::Rng::new(pixel, sample, 77);
                    let mut state = walks.light_subpath(rng, &mut light);
                    let mut rays = 0;
                    for s in 2..=light.len() {
                        if let Some((Contribution::Splat { pixel, value }, _)) =
                            walks.connect(&light, &[], s, 1, &mut state.rng, &mut rays)
                        {
                            image[(pixel.1 * w + pixel.0) as usize] += value;
                        }
                    }
                }
            }
            // Each pixel's value: what all light subpaths splat there, over the samples per pixel.
            image
                .iter()
                .map(|&v| f64::from(crate::math::sampling::luminance(v)) / f64::from(per_block))
                .collect()
        })
        .collect()
}

/// For paths made by connecting random subpaths, every way of splitting the same path into a
/// light and a camera subpath (the strategies that could have made it) gets a weight, and the
/// weights sum to 1.
#[test]
fn mis_weights_of_one_path_sum_to_one() {
    let room = room(glass_things(), point_and_spot(), (16, 12));
    for (what, (scene, frame)) in [
        ("room", room),
        ("outdoors", outdoors(Some(sky()), [0.0; 3])),
    ] {
        let choice = LightChoice::new(&scene, &frame);
        let walks = Walks {
            scene: &scene,
            frame: &frame,
            choice: &choice,
        };
        let (mut camera, mut light) = (Vec::new(), Vec::new());
        let mut checked = 0;
        for sample in 0..4000u32 {
            let (x, y) = (sample % 16, (sample / 16) % 12);
            walks.camera_subpath(x, y, sample, false, &mut camera);
            let rng = crate::math::rng::Rng::new(sample, sample, 5);
            walks.light_subpath(rng, &mut light);
            for t in 2..=camera.len() {
                for s in 2..=light.len() {
                    if s + t - 1 > frame.max_depth as usize
                        || !(light[s - 1].connectible(&scene) && camera[t - 1].connectible(&scene))
                    {
                        continue;
                    }
                    let sum = split_weights(&walks, &light[..s], &camera[..t]);
                    assert!(
                        (sum - 1.0).abs() < 1e-4,
                        "{what}, sample {sample}, s = {s}, t = {t}: the weights sum to {sum}"
                    );
                    checked += 1;
                }
            }
        }
        assert!(checked > 500, "{what}: only {checked} paths checked");
    }
}

/// The full path y_0 … y_{s−1} z_{t−1} … z_0 split every way (s', t'), each split's vertices
/// given the densities of their new subpath's direction, and the MIS weights summed over the
/// splits whose connection could be made.
fn split_weights(walks: &Walks, light: &[Vertex], camera: &[Vertex]) -> f32 {
    let (scene, frame, choice) = (walks.scene, walks.frame, walks.choice);
    let full: Vec<Vertex> = light.iter().chain(camera.iter().rev()).copied().collect();
    let n = full.len();
    // Densities from the light's side (p_l) and the camera's (p_e) of each vertex of the full
    // path, from the vertices' places as `mis::weight` computes those at a connection (the walks
    // keep those of the directions they sampled, which differ in the last digits: a ray leaves
    // from just off its surface).
    let mut p_l = vec![0.0; n];
    let mut p_e = vec![0.0; n];
    p_l[0] = full[0].pdf_fwd;
    p_l[1] = full[0].pdf_light(scene, choice, &full[1]);
    for k in 2..n {
        p_l[k] = full[k - 1].pdf(scene, frame, choice, Some(&full[k - 2]), &full[k]);
    }
    p_e[n - 2] = full[n - 1].pdf(scene, frame, choice, None, &full[n - 2]);
    for k in (0..n - 2).rev() {
        p_e[k] = full[k + 1].pdf(scene, frame, choice, Some(&full[k + 2]), &full[k]);
    }
    let mut sum = 0.0;
    for s2 in 0..n {
        let t2 = n - s2;
        if s2 == 1 && t2 == 1 {
            continue;
        }
        let light2: Vec<Vertex> = (0..s2)
            .map(|k| Vertex {
                pdf_fwd: p_l[k],
                pdf_rev: p_e[k],
                ..full[k]
            })
            .collect();
        let camera2: Vec<Vertex> = (s2..n)
            .rev()
            .map(|k| Vertex {
                pdf_fwd: p_e[k],
                pdf_rev: p_l[k],
                ..full[k]
            })
            .collect();
        // The ends the split connects must be able to connect (s' = 0: the camera subpath ends
        // on the light itself; s' = 1: the light is sampled anew for the camera vertex).
        let ends = if s2 == 0 {
            matches!(
                full[0].point,
                vertex::Point::Emitter { .. } | vertex::Point::Environment { .. }
            )
        } else if s2 == 1 {
            full[1].connectible(scene)
        } else {
            full[s2 - 1].connectible(scene) && full[s2].connectible(scene)
        };
        if !ends {
            continue;
        }
        let sampled = match (s2, t2) {
            (1, _) => Some(light2[0]),
            (_, 1) => Some(camera2[0]),
            _ => None,
        };
        sum += mis::weight(walks, &light2, &camera2, sampled.as_ref(), s2, t2);
    }
    sum
}
