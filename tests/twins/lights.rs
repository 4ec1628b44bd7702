//! Twin tests of light sampling and traversal over a whole scene's buffers: `sample_light`,
//! `direct_light` (its shadow ray included) and the nearest hit (`intersect_scene` ⇄
//! `estimator::trace`), over both BVH layouts.

use super::*;
use rt_core::bvh::{BvhLayout, BvhQuality};
use rt_core::estimator::{
    ShadowMedia, Surface, delta_lights_at, direct_light, sample_light, trace,
};

/// The Cornell box with thirty more small emitters facing every way, twelve point and spot lights
/// (both falloffs) and a sun, picked through the light tree (the sun summed).
fn cornell_with_many_lights() -> rt_core::Scene {
    use rt_core::{Light, LightKind};
    let mut scene = rt_io::assets::cornell_box().unwrap();
    let (lo, hi) = scene.bounds().unwrap();
    let mut rng = Rng::new(8, 0, 0x3e);
    for i in 0..30 {
        let u = Vec3::new(rng.next_f32(), rng.next_f32(), rng.next_f32());
        let strength = 10f32.powf(2.0 * rng.next_f32());
        scene.objects.push(rt_core::Object {
            shadow_catcher: false,
            animation_node: None,
            name: format!("light {i}"),
            mesh: rt_core::shapes::quad(lo + (hi - lo) * u, unit(&mut rng), 40.0).into(),
            material: rt_core::Material::Emissive {
                color: [strength, 0.5 * strength, strength],
                intensity: 1.0,
            },
            transform: Default::default(),
        });
    }
    for i in 0..12 {
        let kind = [LightKind::Point, LightKind::Spot][i % 2];
        let mut light = Light::new(kind, &format!("delta {i}"));
        let u = Vec3::new(rng.next_f32(), rng.next_f32(), rng.next_f32());
        light.position = (lo + (hi - lo) * u).to_array();
        light.direction = unit(&mut rng).to_array();
        light.intensity = 10f32.powf(1.0 + 2.0 * rng.next_f32());
        light.outer_angle_deg = 20.0 + 60.0 * rng.next_f32();
        light.inner_angle_deg = light.outer_angle_deg * rng.next_f32();
        if i % 4 == 3 {
            light.falloff = rt_core::light::SpotFalloff::Gltf;
        }
        scene.lights.push(light);
    }
    let mut sun = Light::new(LightKind::Directional, "sun");
    sun.direction = [0.3, -1.0, -0.4];
    scene.lights.push(sun);
    scene.settings.light_sampler = rt_core::LightSampler::Tree;
    scene
}

/// The Cornell box, and with a random environment map (sampled with its own probability) over the
/// other BVH layout, and with many lights sampled through the light tree.
fn light_scenes() -> Vec<(&'static str, TwinScene)> {
    let mut out = Vec::new();
    for (name, layout, environment) in [
        ("area lights, CWBVH", BvhLayout::Cwbvh, false),
        ("area lights and environment, BVH2", BvhLayout::Bvh2, true),
        (
            "many lights through the tree, CWBVH",
            BvhLayout::Cwbvh,
            false,
        ),
        ("instanced blocks, mirrored, BVH2", BvhLayout::Bvh2, false),
        ("instanced blocks, mirrored, CWBVH", BvhLayout::Cwbvh, false),
    ] {
        let mut scene = if name.contains("tree") {
            cornell_with_many_lights()
        } else {
            rt_io::assets::cornell_box().unwrap()
        };
        if name.contains("instanced") {
            // Each block again, sharing its mesh: moved, turned and mirrored (instances).
            let copies: Vec<_> = (scene.objects.iter())
                .filter(|o| o.name.ends_with("block"))
                .map(|o| {
                    let mut copy = o.clone();
                    copy.name.push_str(" copy");
                    copy.transform.translation = [-120.0, 10.0, 60.0];
                    copy.transform.rotation_deg = [0.0, 35.0, 0.0];
                    copy.transform.scale = [-0.6, 0.5, 0.6];
                    copy
                })
                .collect();
            scene.objects.extend(copies);
        }
        if environment {
            let mut rng = Rng::new(5, 0, 0x11);
            let texels = (0..16 * 8)
                .map(|_| [rng.next_f32() * 4.0, rng.next_f32(), rng.next_f32() * 2.0])
                .collect();
            let map = EnvironmentMap::from_texels(16, 8, texels).0;
            let mut env = rt_core::Environment::new("random", map);
            env.rotation_deg = 40.0;
            scene.environment = Some(env);
        }
        let gpu =
            rt_core::GpuScene::build_with_layout(&scene, BvhQuality::default(), layout).unwrap();
        assert_eq!(gpu.layout, layout);
        assert_eq!(gpu.features.instances, name.contains("instanced"));
        let frame = rt_core::frame::frame_for(&scene, &gpu).unwrap();
        assert!(frame.emitter_count > 0 && (frame.env_pick > 0.0) == environment);
        assert_eq!(frame.light_sampler == 1, name.contains("tree"));
        out.push((name, TwinScene { frame, scene: gpu }));
    }
    out
}

/// A light sample from a point (area lights by power, the environment by its map, or through the
/// tree with point and spot lights, half the points lit from both sides), the direct light a
/// Lambertian surface gets through it (the shadow ray traced), the delta lights it sums, and the
/// nearest hit of a random ray, at random points in and around the box. A point whose shadow ray or light choice
/// sits on an edge may go the other way when a coordinate differs in its last bit: such items (a
/// few in a thousand at most) are counted, not compared.
#[test]
fn light_sampling_and_traversal_match_their_twin() {
    let Some(ctx) = gpu() else { return };
    for (name, scene) in light_scenes() {
        let g = &scene.scene;
        let (lo, hi) = g.triangles.iter().fold(
            (Vec3::splat(f32::MAX), Vec3::splat(f32::MIN)),
            |(lo, hi), t| {
                let v = [t.v0, t.v1, t.v2].map(Vec3::from);
                (
                    lo.min(v[0]).min(v[1]).min(v[2]),
                    hi.max(v[0]).max(v[1]).max(v[2]),
                )
            },
        );
        let input = inputs(12, |rng| {
            let u = Vec3::new(rng.next_f32(), rng.next_f32(), rng.next_f32());
            // Mostly inside the box, some outside it.
            let p = lo + (hi - lo) * (u * 1.2 - 0.1);
            let ng = unit(rng);
            let d = unit(rng);
            let albedo = Vec3::new(rng.next_f32(), rng.next_f32(), rng.next_f32());
            bits(&[p, ng, d, albedo].map(|v| v.to_array()).concat())
        });
        let kernel = TwinKernel {
            words_in: 12,
            words_out: 23,
            body: "let p = v3_in(item, 0u); let ng = v3_in(item, 3u); let d = v3_in(item, 6u);
    // Every fourth item a scattering in a medium: no normal, the phase function, dimmed rays.
    let in_medium = (item & 3u) == 3u;
    let n = select(ng, vec3(0.0), in_medium);
    let a = v3_in(item, 9u);
    let media = ShadowMedia(a * 0.5, a.zyx * 0.3);
    var r = rng_init(item, 3u, 9u);
    let l = sample_light(p, n, (item & 1u) == 1u, &r);
    let ok = l.distance > 0.0;
    put_u(item, 0u, u32(ok));
    put3(item, 1u, select(vec3(0.0), l.origin, ok)); put(item, 4u, select(0.0, l.distance, ok));
    put3(item, 5u, select(vec3(0.0), l.direction, ok)); put(item, 8u, select(0.0, l.p_light, ok));
    put3(item, 9u, select(vec3(0.0), l.radiance_over_pdf, ok));
    var s: Surface;
    s.kind = MAT_LAMBERTIAN; s.color = a; s.n = ng;
    if (in_medium) {
        s = phase_surface(d, a.x * 1.8 - 0.9);
    }
    var q = rng_init(item, 4u, 9u);
    var rays = 0u;
    put3(item, 12u, direct_light(p, n, s, media, &q, &rays));
    let h = intersect_scene(p, d, 3.0e38, false);
    put(item, 15u, h.t); put_u(item, 16u, h.triangle); put(item, 17u, h.b1); put(item, 18u, h.b2);
    put_u(item, 19u, rays);
    put3(item, 20u, delta_lights_at(p, n, s, media, &rays));",
            sobol: false,
        };
        let gpu_out = kernel.run_in(ctx, &scene, &input);
        let frame = &scene.frame;
        let mut set_aside = 0;
        let rows: Vec<Vec<u32>> = (0..ITEMS)
            .map(|item| {
                let f = |k: usize| f32::from_bits(input[item * 12 + k]);
                let v = |k: usize| Vec3::new(f(k), f(k + 1), f(k + 2));
                let (p, ng, d, albedo) = (v(0), v(3), v(6), v(9));
                let in_medium = item % 4 == 3;
                let n = if in_medium { Vec3::ZERO } else { ng };
                let media = ShadowMedia {
                    above: albedo * 0.5,
                    below: Vec3::new(albedo.z, albedo.y, albedo.x) * 0.3,
                };
                let mut rng = Rng::new(item as u32, 3, 9);
                let light = sample_light(g, frame, p, n, item % 2 == 1, &mut rng);
                let mut out = vec![u32::from(light.is_some())];
                let l = light.unwrap_or(rt_core::estimator::LightSample {
                    origin: Vec3::ZERO,
                    direction: Vec3::ZERO,
                    distance: 0.0,
                    radiance_over_pdf: Vec3::ZERO,
                    p_light: 0.0,
                });
                out.extend(bits(&l.origin.extend(l.distance).to_array()));
                out.extend(bits(&l.direction.extend(l.p_light).to_array()));
                out.extend(bits(&l.radiance_over_pdf.to_array()));
                let surface = if in_medium {
                    Surface::Phase {
                        direction: d,
                        g: albedo.x * 1.8 - 0.9,
                    }
                } else {
                    Surface::Lambert { albedo, ns: ng }
                };
                let mut q = Rng::new(item as u32, 4, 9);
                let mut rays = 0;
                out.extend(bits(
                    &direct_light(g, frame, p, n, &surface, &media, &mut q, &mut rays).to_array(),
                ));
                let h = trace(g, p, d, 3.0e38);
                out.extend([h.t.to_bits(), h.triangle, h.b1.to_bits(), h.b2.to_bits()]);
                out.push(rays);
                out.extend(bits(
                    &delta_lights_at(g, frame, p, n, &surface, &media, &mut rays).to_array(),
                ));
                // Another emitter, another side of an edge, or another triangle at an edge: the
                // GPU's row stands in for it, and it is counted.
                let gpu_row = &gpu_out[item * 23..item * 23 + 23];
                let differs = |k: usize| {
                    let (a, b) = (f32::from_bits(out[k]), f32::from_bits(gpu_row[k]));
                    (a - b).abs() > 1e-3 * a.abs().max(b.abs()).max(1.0)
                };
                if out[0] != gpu_row[0]
                    || (1..12).any(differs)
                    || (12..15).any(differs)
                    || (20..23).any(differs)
                    || out[16] != gpu_row[16]
                    || out[19] != gpu_row[19]
                {
                    set_aside += 1;
                    return gpu_row.to_vec();
                }
                out
            })
            .collect();
        eprintln!("{name}: {set_aside} of {ITEMS} items on an edge");
        assert!(
            set_aside <= ITEMS / 200,
            "{name}: {set_aside} items took another branch on the GPU"
        );
        let lit = rows.iter().filter(|r| r[0] == 1).count();
        let hits = rows.iter().filter(|r| r[16] != u32::MAX).count();
        let deltas = rows.iter().filter(|r| r[0] == 1 && r[8] == 0).count();
        assert_eq!(
            deltas > ITEMS / 50,
            name.contains("tree"),
            "{name}: {deltas} delta samples"
        );
        assert!(
            lit > ITEMS / 8 && hits > ITEMS / 2,
            "{name}: {lit} light samples, {hits} hits: the inputs miss the scene"
        );
        Comparison {
            name,
            rel: 2e-4,
            abs: 1e-5,
            exact_words: &[0, 16, 19],
        }
        .check_rows(&gpu_out, 23, &rows);
    }
}

/// Camera rays through a thin lens (`camera_ray_origin_dir` ⇄ `camera_ray`), the sky a ray that
/// leaves the scene sees, weighed against environment sampling (`escaped`), and the point, spot
/// and sun lights' sum at a point with their shadow rays (`delta_lights_at`), on the Cornell box
/// with an environment, three delta lights and an open aperture.
#[test]
fn camera_rays_escaped_sky_and_delta_lights_match_their_twin() {
    use rt_core::estimator::camera_ray;
    use rt_core::{Light, LightKind};
    let Some(ctx) = gpu() else { return };
    let mut scene = rt_io::assets::cornell_box().unwrap();
    let mut rng = Rng::new(6, 0, 0x12);
    let texels = (0..16 * 8)
        .map(|_| [rng.next_f32() * 4.0, rng.next_f32(), rng.next_f32() * 2.0])
        .collect();
    scene.environment = Some(rt_core::Environment::new(
        "random",
        EnvironmentMap::from_texels(16, 8, texels).0,
    ));
    scene.camera.aperture_radius = 0.05;
    let (lo, hi) = scene.bounds().unwrap();
    let centre = (lo + hi) * 0.5;
    let mut point = Light::new(LightKind::Point, "point");
    point.position = (centre + (hi - centre) * 0.6).to_array();
    point.intensity = 3.0;
    let mut spot = Light::new(LightKind::Spot, "spot");
    spot.position = (centre + (hi - centre) * Vec3::new(-0.5, 0.8, 0.2)).to_array();
    spot.direction = [0.2, -1.0, 0.1];
    spot.intensity = 5.0;
    let mut sun = Light::new(LightKind::Directional, "sun");
    sun.direction = [0.3, -1.0, -0.4];
    scene.lights = vec![point, spot, sun];
    let g = rt_core::GpuScene::build(&scene).unwrap();
    let frame = rt_core::frame::frame_for(&scene, &g).unwrap();
    assert!(frame.lens_radius > 0.0 && frame.env_pick > 0.0 && g.delta_lights.len() == 3);
    let input = inputs(11, |rng| {
        let u = Vec3::new(rng.next_f32(), rng.next_f32(), rng.next_f32());
        let p = lo + (hi - lo) * u;
        let ng = unit(rng);
        let d = unit(rng);
        let pdf = if rng.next_f32() < 0.5 {
            0.0
        } else {
            4.0 * rng.next_f32()
        };
        let pixel = (rng.next_f32() * (frame.width * frame.height) as f32) as u32;
        let mut words = bits(&[p, ng, d].map(|v| v.to_array()).concat());
        words.push(pdf.to_bits());
        words.push(pixel);
        words
    });
    let kernel = TwinKernel {
        words_in: 11,
        words_out: 13,
        body: "let p = v3_in(item, 0u); let ng = v3_in(item, 3u); let d = v3_in(item, 6u);
    let pixel = u_in(item, 10u);
    var r = rng_init(pixel, item, frame.seed);
    let ray = camera_ray_origin_dir(pixel % frame.width, pixel / frame.width, &r);
    put3(item, 0u, ray[0]); put3(item, 3u, ray[1]);
    put3(item, 6u, escaped(d, f_in(item, 9u)));
    var s: Surface;
    s.kind = MAT_LAMBERTIAN; s.color = vec3(0.8, 0.5, 0.3); s.n = ng;
    var rays = 0u;
    put3(item, 9u, delta_lights_at(p, ng, s, ShadowMedia(vec3(0.0), vec3(0.0)), &rays));
    put_u(item, 12u, rays);",
        sobol: true,
    };
    let twin = TwinScene { frame, scene: g };
    let gpu_out = kernel.run_in(ctx, &twin, &input);
    let (g, frame) = (&twin.scene, &twin.frame);
    let mut set_aside = 0;
    let rows: Vec<Vec<u32>> = (0..ITEMS)
        .map(|item| {
            let f = |k: usize| f32::from_bits(input[item * 11 + k]);
            let v = |k: usize| Vec3::new(f(k), f(k + 1), f(k + 2));
            let (p, ng, d) = (v(0), v(3), v(6));
            let pixel = input[item * 11 + 10];
            let mut r = Rng::with_sampler(pixel, item as u32, frame.seed, SamplerKind::Sobol);
            let (o, dir) = camera_ray(frame, pixel % frame.width, pixel / frame.width, &mut r);
            let sky = rt_core::estimator::light::escaped(g, frame, d, f(9));
            let surface = Surface::Lambert {
                albedo: Vec3::new(0.8, 0.5, 0.3),
                ns: ng,
            };
            let mut rays = 0;
            let lit = delta_lights_at(
                g,
                frame,
                p,
                ng,
                &surface,
                &ShadowMedia::default(),
                &mut rays,
            );
            let mut out = bits(&[o, dir, sky, lit].map(|v| v.to_array()).concat());
            out.push(rays);
            // A shadow ray grazing an edge, or a direction on an environment texel's boundary,
            // may go the other way on the GPU: set aside and counted.
            let gpu_row = &gpu_out[item * 13..item * 13 + 13];
            let differs = (6..12).any(|k| {
                let (a, b) = (f32::from_bits(out[k]), f32::from_bits(gpu_row[k]));
                (a - b).abs() > 1e-3 * a.abs().max(b.abs()).max(1e-3)
            }) || out[12] != gpu_row[12];
            if differs {
                set_aside += 1;
                return gpu_row.to_vec();
            }
            out
        })
        .collect();
    eprintln!("camera, sky and delta lights: {set_aside} of {ITEMS} items on an edge");
    assert!(set_aside <= ITEMS / 100, "{set_aside} items differ");
    let lit = rows
        .iter()
        .filter(|r| f32::from_bits(r[9]) + f32::from_bits(r[10]) > 0.0)
        .count();
    assert!(lit > ITEMS / 8, "only {lit} points lit by the delta lights");
    Comparison {
        name: "camera, sky and delta lights",
        rel: 2e-4,
        abs: 1e-5,
        exact_words: &[12],
    }
    .check_rows(&gpu_out, 13, &rows);
}

/// Camera rays of every projection (`camera_ray_origin_dir` ⇄ `camera_ray`): orthographic with a
/// thin lens, panorama and fisheye (pixels outside its circle get a zero direction in both), on a
/// wide and a tall image.
#[test]
fn camera_rays_of_every_projection_match_their_twin() {
    use rt_core::camera::Projection;
    use rt_core::estimator::camera_ray;
    let Some(ctx) = gpu() else { return };
    let cases = [
        (Projection::Orthographic, 0.05, 96, 64),
        (Projection::Panorama, 0.0, 128, 64),
        (Projection::Fisheye, 0.0, 96, 64),
        (Projection::Fisheye, 0.0, 48, 80),
    ];
    for (projection, aperture, width, height) in cases {
        let mut scene = rt_io::assets::cornell_box().unwrap();
        scene.camera.projection = projection;
        scene.camera.aperture_radius = aperture;
        scene.camera.fisheye_angle_deg = 200.0;
        scene.settings.width = width;
        scene.settings.height = height;
        let g = rt_core::GpuScene::build(&scene).unwrap();
        let frame = rt_core::frame::frame_for(&scene, &g).unwrap();
        assert_eq!(frame.projection, projection.tag());
        let input = inputs(1, |rng| {
            vec![(rng.next_f32() * (frame.width * frame.height) as f32) as u32]
        });
        let kernel = TwinKernel {
            words_in: 1,
            words_out: 6,
            body: "let pixel = u_in(item, 0u);
    var r = rng_init(pixel, item, frame.seed);
    let ray = camera_ray_origin_dir(pixel % frame.width, pixel / frame.width, &r);
    put3(item, 0u, ray[0]); put3(item, 3u, ray[1]);",
            sobol: true,
        };
        let twin = TwinScene { frame, scene: g };
        let gpu_out = kernel.run_in(ctx, &twin, &input);
        let frame = &twin.frame;
        let mut outside = 0;
        let rows: Vec<Vec<u32>> = (0..ITEMS)
            .map(|item| {
                let pixel = input[item];
                let mut r = Rng::with_sampler(pixel, item as u32, frame.seed, SamplerKind::Sobol);
                let (o, dir) = camera_ray(frame, pixel % frame.width, pixel / frame.width, &mut r);
                outside += usize::from(dir == Vec3::ZERO);
                bits(&[o, dir].map(|v| v.to_array()).concat())
            })
            .collect();
        if projection == Projection::Fisheye {
            assert!(
                outside > ITEMS / 20,
                "{projection:?}: {outside} rays outside the circle"
            );
        }
        Comparison {
            name: projection.name(),
            rel: 2e-4,
            abs: 1e-5,
            exact_words: &[],
        }
        .check_rows(&gpu_out, 6, &rows);
    }
}

/// The light tree's pmf of an emitter found by a BSDF-sampled ray (`emitter_pdf` through
/// `leaf_of` and `tree_pmf`), the packed normal it is weighed with, and the power table's pdf, at
/// random points, normals and emitters of the Cornell box with thirty more lights.
#[test]
fn emitter_pdfs_of_both_samplers_match_their_twin() {
    use rt_core::estimator::light::emitter_pdf;
    use rt_core::estimator::light_tree::{pack_normal, unpack_normal};
    let Some(ctx) = gpu() else { return };
    let scene = cornell_with_many_lights();
    let (lo, hi) = scene.bounds().unwrap();
    let g = rt_core::GpuScene::build(&scene).unwrap();
    let tree = rt_core::frame::frame_for(&scene, &g).unwrap();
    let power = Frame {
        light_sampler: 0,
        ..tree
    };
    assert_eq!(tree.light_sampler, 1);
    let emitters = g.emitters.clone();
    let input = inputs(9, |rng| {
        let u = Vec3::new(rng.next_f32(), rng.next_f32(), rng.next_f32());
        let x = lo + (hi - lo) * u;
        let n = unit(rng);
        let e = &emitters[(rng.next_f32() * emitters.len() as f32) as usize];
        let distance = 1.0 + 500.0 * rng.next_f32();
        let cos_l = 0.05 + 0.95 * rng.next_f32();
        let mut item = bits(&[x, n].map(|v| v.to_array()).concat());
        item.extend([e.triangle, distance.to_bits(), cos_l.to_bits()]);
        item
    });
    let body = "let x = v3_in(item, 0u); let packed = pack_normal(v3_in(item, 3u));
    put3(item, 0u, unpack_normal(packed));
    put(item, 3u, emitter_pdf(u_in(item, 6u), x, packed, f_in(item, 7u), f_in(item, 8u)));";
    let rows_of = |frame: &Frame| {
        let kernel = TwinKernel {
            words_in: 9,
            words_out: 4,
            body,
            sobol: false,
        };
        let gpu_out = kernel.run_in(
            ctx,
            &TwinScene {
                frame: *frame,
                scene: g.clone(),
            },
            &input,
        );
        let rows: Vec<Vec<u32>> = (0..ITEMS)
            .map(|item| {
                let w = |k: usize| input[item * 9 + k];
                let f = |k: usize| f32::from_bits(w(k));
                let x = Vec3::new(f(0), f(1), f(2));
                let packed = pack_normal(Vec3::new(f(3), f(4), f(5)));
                let mut out = bits(&unpack_normal(packed).to_array());
                out.push(emitter_pdf(&g, frame, w(6), x, packed, f(7), f(8)).to_bits());
                out
            })
            .collect();
        (gpu_out, rows)
    };
    for (name, frame) in [("tree", &tree), ("power", &power)] {
        let (gpu_out, rows) = rows_of(frame);
        let positive = rows.iter().filter(|r| f32::from_bits(r[3]) > 0.0).count();
        assert!(
            positive > ITEMS / 4,
            "{name}: only {positive} positive pdfs"
        );
        Comparison {
            name,
            rel: 1e-4,
            abs: 1e-9,
            exact_words: &[],
        }
        .check_rows(&gpu_out, 4, &rows);
    }
}
