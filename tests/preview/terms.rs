//! The preview's light term by term against the path tracer's, per object, on five scenes of
//! different character: a studio (the showroom), a room lit by its lamp (the Cornell box), metals
//! over a checkered floor under a point light and a sun, a dark room lit by one lamp, and an
//! outdoor scene under the sun and sky. Direct light is what both draw at `max_depth` 2 (the
//! preview leaves its bounce light out there); bounce light is the rest. Checking each term, not
//! only their sum, keeps a wrong term from hiding behind a compensating one (a white texture's
//! bounce once hid a missing coat and a missing anisotropic highlight).

use glam::Vec3;
use rt_core::material::Pbr;
use rt_core::shapes::{cuboid, quad, uv_sphere};
use rt_core::{Light, LightKind, Material, Mesh, Object, Scene};

use crate::common::{camera, object, pbr, scene, settings};
use crate::pair::{luminance, preview_and_render};

const WIDTH: u32 = 160;
const HEIGHT: u32 = 120;

fn at(mut o: Object, position: [f32; 3]) -> Object {
    o.transform.translation = position;
    o
}

/// A checkered square of `size` on y = 0 with UVs (so its image and the tangents of anything
/// brushed follow them): eight squares a side, 0.9 and 0.05 grey (sRGB 243 and 63).
fn checkered_floor(scene: &mut Scene, size: f32) -> Object {
    let mut mesh = quad(Vec3::ZERO, Vec3::Y, size);
    mesh.uvs = Some(vec![
        glam::Vec2::new(0.0, 0.0),
        glam::Vec2::new(1.0, 0.0),
        glam::Vec2::new(1.0, 1.0),
        glam::Vec2::new(0.0, 1.0),
    ]);
    let side = 64u32;
    let rgba: Vec<u8> = (0..side * side)
        .flat_map(|i| {
            let (x, y) = (i % side, i / side);
            let v = if (x / 8 + y / 8) % 2 == 0 { 243 } else { 63 };
            [v, v, v, 255]
        })
        .collect();
    scene.textures.push(rt_core::Texture {
        sampler: Default::default(),
        name: "checker".into(),
        width: side,
        height: side,
        rgba8: rgba.into(),
    });
    object(
        "floor",
        mesh,
        pbr(Pbr {
            base_color: [1.0; 3],
            texture: Some(scene.textures.len() - 1),
            roughness: 0.8,
            ..Default::default()
        }),
    )
}

/// An upright cylinder (its axis along y, its base at y = 0), smooth-shaded, its side's UVs
/// running u around and v up (so a brushed material's tangent goes round it).
fn cylinder(radius: f32, height: f32, segments: u32) -> Mesh {
    let (mut positions, mut normals, mut uvs, mut indices) = (vec![], vec![], vec![], vec![]);
    for s in 0..=segments {
        let phi = std::f32::consts::TAU * s as f32 / segments as f32;
        let n = Vec3::new(phi.cos(), 0.0, -phi.sin());
        for (y, v) in [(0.0, 0.0), (height, 1.0)] {
            positions.push(n * radius + Vec3::Y * y);
            normals.push(n);
            uvs.push(glam::Vec2::new(s as f32 / segments as f32, v));
        }
    }
    for s in 0..segments {
        let (a, b, c, d) = (2 * s, 2 * s + 2, 2 * s + 3, 2 * s + 1);
        indices.push([a, b, c]);
        indices.push([a, c, d]);
    }
    // The lid, facing up.
    let center = positions.len() as u32;
    positions.push(Vec3::Y * height);
    normals.push(Vec3::Y);
    uvs.push(glam::Vec2::splat(0.5));
    for s in 0..segments {
        let phi = std::f32::consts::TAU * s as f32 / segments as f32;
        let next = std::f32::consts::TAU * (s + 1) as f32 / segments as f32;
        let first = positions.len() as u32;
        for angle in [phi, next] {
            positions.push(Vec3::new(angle.cos(), 0.0, -angle.sin()) * radius + Vec3::Y * height);
            normals.push(Vec3::Y);
            uvs.push(glam::Vec2::new(
                0.5 + 0.5 * angle.cos(),
                0.5 + 0.5 * angle.sin(),
            ));
        }
        indices.push([center, first, first + 1]);
    }
    Mesh {
        positions,
        normals: Some(normals),
        uvs: Some(uvs),
        colors: None,
        indices,
    }
}

fn sun_and_point(sun_strength: f32, point: [f32; 3], point_strength: f32) -> Vec<Light> {
    let mut sun = Light::new(LightKind::Directional, "sun");
    sun.direction = Vec3::new(-0.4, -1.0, -0.5).normalize().to_array();
    sun.intensity = sun_strength;
    let mut lamp = Light::new(LightKind::Point, "point");
    lamp.position = point;
    lamp.intensity = point_strength;
    vec![sun, lamp]
}

/// Gold, red plastic and a brushed aluminium can on a checkered floor, with two blue boxes, under a
/// point light and a sun and a dark ambient (issue 44's kind of scene, built here).
fn metals_on_a_checkered_floor() -> Scene {
    let mut s = scene(
        vec![],
        camera(Vec3::new(0.0, 4.5, 9.0), Vec3::new(0.0, 0.8, 0.0), 40.0),
        [0.03; 3],
        settings(WIDTH, HEIGHT, 128, 8),
    );
    let floor = checkered_floor(&mut s, 12.0);
    let plastic = |color: [f32; 3], roughness: f32| {
        pbr(Pbr {
            base_color: color,
            roughness,
            ..Default::default()
        })
    };
    s.objects = vec![
        floor,
        at(
            object(
                "gold",
                uv_sphere(1.0, 24, 48),
                pbr(Pbr {
                    base_color: [1.0, 0.766, 0.336],
                    metallic: 1.0,
                    roughness: 0.25,
                    ..Default::default()
                }),
            ),
            [-2.5, 1.0, 0.0],
        ),
        at(
            object(
                "red",
                uv_sphere(1.0, 24, 48),
                plastic([0.8, 0.05, 0.05], 0.3),
            ),
            [0.0, 1.0, 1.0],
        ),
        at(
            object(
                "can",
                cylinder(0.6, 2.0, 48),
                pbr(Pbr {
                    base_color: [0.91, 0.92, 0.92],
                    metallic: 1.0,
                    roughness: 0.35,
                    anisotropy: 0.8,
                    ..Default::default()
                }),
            ),
            [2.5, 0.0, 0.0],
        ),
        object(
            "box",
            cuboid(Vec3::new(0.5, 0.0, -3.0), Vec3::new(1.5, 1.0, -2.0), false),
            plastic([0.05, 0.15, 0.7], 0.6),
        ),
    ];
    s.lights = sun_and_point(3.0, [3.0, 4.0, 3.0], 80.0);
    s
}

/// A closed grey room at night (no ambient) lit by one warm emissive sphere: a floor, a diffuse
/// and a glossy sphere and a box, lit through one bounce as much as directly.
fn dark_room_with_one_lamp() -> Scene {
    let grey = |value: f32, roughness: f32| {
        pbr(Pbr {
            base_color: [value; 3],
            roughness,
            ..Default::default()
        })
    };
    let mut s = scene(
        vec![
            object(
                "room",
                cuboid(Vec3::new(-4.0, 0.0, -4.0), Vec3::new(4.0, 3.0, 4.0), true),
                grey(0.6, 0.9),
            ),
            at(
                object("matte", uv_sphere(0.6, 24, 48), grey(0.7, 1.0)),
                [-1.2, 0.6, 0.0],
            ),
            at(
                object("glossy", uv_sphere(0.6, 24, 48), grey(0.5, 0.2)),
                [0.6, 0.6, 0.8],
            ),
            object(
                "box",
                cuboid(Vec3::new(0.8, 0.0, -2.0), Vec3::new(2.0, 1.2, -1.0), false),
                grey(0.4, 0.7),
            ),
            at(
                object(
                    "lamp",
                    uv_sphere(0.15, 12, 24),
                    Material::Emissive {
                        color: [1.0, 0.7, 0.4],
                        intensity: 60.0,
                    },
                ),
                [0.0, 2.2, 0.0],
            ),
        ],
        camera(Vec3::new(0.0, 1.8, 3.9), Vec3::new(0.0, 0.8, -1.0), 60.0),
        [0.0; 3],
        settings(WIDTH, HEIGHT, 128, 8),
    );
    s.lights.clear();
    s
}

/// A grey ground, a grey box and a red sphere outdoors under rt's sun and sky (`sky:40`).
fn outdoors_under_the_sky() -> Scene {
    let sky = rt_core::sky::SunSky {
        elevation_deg: 40.0,
        turbidity: 3.0,
    };
    let mut s = scene(
        vec![
            object(
                "ground",
                quad(Vec3::ZERO, Vec3::Y, 30.0),
                pbr(Pbr {
                    base_color: [0.5; 3],
                    roughness: 0.9,
                    ..Default::default()
                }),
            ),
            object(
                "box",
                cuboid(Vec3::new(-2.0, 0.0, -1.5), Vec3::new(-0.5, 1.5, 0.0), false),
                pbr(Pbr {
                    base_color: [0.6; 3],
                    roughness: 0.7,
                    ..Default::default()
                }),
            ),
            at(
                object(
                    "sphere",
                    uv_sphere(0.8, 24, 48),
                    pbr(Pbr {
                        base_color: [0.7, 0.1, 0.08],
                        roughness: 0.4,
                        ..Default::default()
                    }),
                ),
                [1.2, 0.8, 0.3],
            ),
        ],
        camera(Vec3::new(0.0, 2.5, 6.0), Vec3::new(0.0, 0.6, 0.0), 45.0),
        [0.0; 3],
        settings(WIDTH, HEIGHT, 128, 8),
    );
    s.environment = Some(sky.environment());
    s
}

/// Smooth glass, a mirror and a diffuse ball on a grey floor before a wall, under a small lamp and
/// a dim grey ambient light (bench/scenes/glass-caustics' kind): what the glass shows lies beyond
/// it, bent (the floor, the wall, the mirror), and the mirror's brightest part is the lamp.
fn glass_and_a_mirror() -> Scene {
    let grey = pbr(Pbr {
        base_color: [0.6; 3],
        roughness: 0.9,
        ..Default::default()
    });
    scene(
        vec![
            object("floor", quad(Vec3::ZERO, Vec3::Y, 8.0), grey.clone()),
            object("wall", quad(Vec3::new(0.0, 2.0, -2.0), Vec3::Z, 8.0), grey),
            at(
                object(
                    "glass",
                    uv_sphere(0.5, 32, 64),
                    pbr(Pbr {
                        base_color: [1.0; 3],
                        roughness: 0.0,
                        transmission: 1.0,
                        ior: 1.5,
                        ..Default::default()
                    }),
                ),
                [-1.1, 0.5, 0.0],
            ),
            at(
                object(
                    "mirror",
                    uv_sphere(0.5, 32, 64),
                    pbr(Pbr {
                        base_color: [0.9; 3],
                        metallic: 1.0,
                        roughness: 0.0,
                        ..Default::default()
                    }),
                ),
                [0.2, 0.5, -0.4],
            ),
            at(
                object(
                    "diffuse",
                    uv_sphere(0.4, 24, 48),
                    pbr(Pbr {
                        base_color: [0.7, 0.2, 0.1],
                        roughness: 0.9,
                        ..Default::default()
                    }),
                ),
                [1.3, 0.4, 0.5],
            ),
            object(
                "lamp",
                quad(Vec3::new(0.0, 2.5, 0.6), Vec3::NEG_Y, 0.6),
                Material::Emissive {
                    color: [1.0, 0.95, 0.9],
                    intensity: 30.0,
                },
            ),
        ],
        camera(Vec3::new(0.0, 1.4, 4.5), Vec3::new(0.0, 0.5, 0.0), 40.0),
        [0.1; 3],
        settings(WIDTH, HEIGHT, 256, 8),
    )
}

/// Per object of `scene` with enough pixels: (name, total, direct, bounce share of the render's
/// light, bounce) as preview/render luminance ratios.
fn terms(scene: &Scene, name: &str) -> Vec<(String, f64, f64, f64, f64)> {
    let ctx = crate::common::gpu().expect("checked by the caller");
    let full = preview_and_render(ctx, scene, name);
    let mut shallow = scene.clone();
    shallow.settings.max_depth = 2;
    let direct = preview_and_render(ctx, &shallow, &format!("{name}-direct"));
    let mut rows = Vec::new();
    for (i, o) in scene.objects.iter().enumerate() {
        let pixels = full.hits.iter().filter(|h| h.is_some_and(|(k, _)| k == i));
        if pixels.count() <= 20 {
            continue;
        }
        let mean = |pair: &crate::pair::Pair, preview: bool| {
            let image = if preview { &pair.preview } else { &pair.render };
            luminance(pair.mean(image, &|object, _| object == i))
        };
        let (total_p, total_r) = (mean(&full, true), mean(&full, false));
        let (direct_p, direct_r) = (mean(&direct, true), mean(&direct, false));
        let share = (total_r - direct_r) / total_r;
        let bounce = (total_p - direct_p) / (total_r - direct_r);
        eprintln!(
            "{name:10} {:8} total {:+6.1}%  direct {:+6.1}%  bounce {:+6.1}% ({:.0}% of its light)",
            o.name,
            100.0 * (total_p / total_r - 1.0),
            100.0 * (direct_p / direct_r - 1.0),
            100.0 * (bounce - 1.0),
            100.0 * share
        );
        rows.push((
            o.name.clone(),
            total_p / total_r,
            direct_p / direct_r,
            share,
            bounce,
        ));
    }
    rows
}

/// The bounds each scene is held to, as measured (docs/editor.md "The preview against the render"):
/// (scene, total, direct). Direct light is held where it is at least half of an object's light;
/// bounce light, where it is at least a quarter, within 70%. Measured: direct within 8.4% but a
/// brushed can's (+10.9%); totals within 14.8% (that can: its reflections of a sunlit floor read
/// from probes that see the floor from elsewhere, −16.2% before its mirror direction read the
/// frame drawn, `behind.rs`); the Cornell box within 8.6%; glass and a mirror within 10.7% (the glass's own reflections are read from the
/// probes, not marched over the frame: −9.2% when they were, for 3–5 ms a frame). Before the
/// outer probes stood at the bounds, a dark room's walls and floor were +19% (probes a metre off
/// the floor saw the lamp's bright patch on the ceiling nearer).
const BOUNDS: [(&str, f64, f64); 6] = [
    ("studio", 0.10, 0.10),
    ("cornell", 0.12, 0.10),
    ("metals", 0.15, 0.15),
    ("dark", 0.16, 0.10),
    ("outdoors", 0.15, 0.10),
    ("glass", 0.12, 0.10),
];

#[test]
fn each_term_of_the_preview_matches_the_render_per_object() {
    if crate::common::gpu().is_none() {
        return;
    }
    let mut cornell = rt_io::assets::cornell_box().expect("embedded scene");
    cornell.settings = settings(128, 128, 128, 8);
    let scenes = [
        crate::showroom(),
        cornell,
        metals_on_a_checkered_floor(),
        dark_room_with_one_lamp(),
        outdoors_under_the_sky(),
        glass_and_a_mirror(),
    ];
    let mut failures = Vec::new();
    for (scene, (name, total_bound, direct_bound)) in scenes.iter().zip(BOUNDS) {
        for (object, total, direct, share, bounce) in terms(scene, name) {
            if (total - 1.0).abs() > total_bound {
                failures.push(format!("{name}, {object}: total {total:.3}"));
            }
            if share <= 0.5 && (direct - 1.0).abs() > direct_bound {
                failures.push(format!("{name}, {object}: direct {direct:.3}"));
            }
            if share >= 0.25 && (bounce - 1.0).abs() > 0.7 {
                failures.push(format!("{name}, {object}: bounce {bounce:.3}"));
            }
        }
    }
    assert!(failures.is_empty(), "{failures:#?}");
}
