#![allow(clippy::unwrap_used)]
//! Instances (`rt_core::instances`): a scene whose objects share meshes, built with each shared
//! mesh once (`GpuScene::build`) and flattened (`GpuScene::build_flattened`),
//! finds the same surfaces along the same rays — turned, scaled unevenly, mirrored — and renders
//! the same image; emitters stay in world space; a singular transform is an error naming the
//! object.

use std::sync::Arc;

use glam::Vec3;
use rt_core::bvh::{BvhLayout, BvhQuality};
use rt_core::estimator::instances::hit_triangle;
use rt_core::gpu_types::Hit;
use rt_core::math::rng::Rng;
use rt_core::scene::{Mesh, Object, RenderSettings, Scene, Transform};
use rt_core::{Camera, GpuScene, Material};

fn object(name: &str, mesh: &Arc<Mesh>, material: Material, transform: Transform) -> Object {
    Object {
        shadow_catcher: false,
        animation_node: None,
        name: name.into(),
        mesh: mesh.clone(),
        material,
        transform,
    }
}

fn placed(translation: [f32; 3], rotation_deg: [f32; 3], scale: [f32; 3]) -> Transform {
    Transform {
        translation,
        rotation_deg,
        scale,
    }
}

/// A floor and a lamp of their own, and one ball mesh (with vertex normals) placed four times:
/// moved, turned and stretched, mirrored, shrunk; each copy in its own colour.
fn shared_balls() -> Scene {
    let ball = Arc::new(rt_core::shapes::uv_sphere(0.5, 10, 20));
    let floor = Arc::new(rt_core::shapes::quad(Vec3::ZERO, Vec3::Y, 6.0));
    let lamp = Arc::new(rt_core::shapes::quad(
        Vec3::new(0.0, 3.0, 0.0),
        -Vec3::Y,
        1.5,
    ));
    let red = Material::lambertian([0.8, 0.2, 0.2]);
    let green = Material::lambertian([0.2, 0.8, 0.2]);
    let metal = Material::Metal {
        albedo: [0.9, 0.8, 0.6],
        fuzz: 0.2,
    };
    Scene {
        objects: vec![
            object(
                "floor",
                &floor,
                Material::lambertian([0.7; 3]),
                placed([0.0; 3], [0.0; 3], [1.0; 3]),
            ),
            object(
                "lamp",
                &lamp,
                Material::Emissive {
                    color: [1.0; 3],
                    intensity: 8.0,
                },
                Transform::default(),
            ),
            object(
                "moved",
                &ball,
                red.clone(),
                placed([-1.2, 0.5, 0.0], [0.0; 3], [1.0; 3]),
            ),
            object(
                "turned and stretched",
                &ball,
                green,
                placed([1.2, 0.6, 0.3], [30.0, 45.0, 10.0], [1.6, 0.7, 1.0]),
            ),
            object(
                "mirrored",
                &ball,
                metal,
                placed([0.0, 0.5, -1.2], [0.0, 20.0, 0.0], [-1.0, 1.0, 1.0]),
            ),
            object(
                "small",
                &ball,
                red,
                placed([0.0, 0.25, 1.2], [0.0; 3], [0.5; 3]),
            ),
        ],
        camera: Camera {
            from: [0.0, 2.5, 5.0],
            to: [0.0, 0.4, 0.0],
            ..Default::default()
        },
        ambient: [0.1, 0.12, 0.15],
        settings: RenderSettings {
            width: 24,
            height: 18,
            max_depth: 5,
            ..Default::default()
        },
        ..Default::default()
    }
}

fn builds(scene: &Scene, layout: BvhLayout) -> (GpuScene, GpuScene) {
    let flat = GpuScene::build_flattened(scene, BvhQuality::default(), layout).unwrap();
    let shared = GpuScene::build_with_layout(scene, BvhQuality::default(), layout).unwrap();
    shared.check_kernel_indices().unwrap();
    (flat, shared)
}

#[test]
fn a_shared_mesh_is_stored_once_and_its_objects_are_instances() {
    let scene = shared_balls();
    let ball = scene.objects[2].mesh.indices.len();
    let (flat, shared) = builds(&scene, BvhLayout::default());
    assert_eq!(shared.instances.len(), 4);
    assert_eq!(flat.triangles.len() - shared.triangles.len(), 3 * ball);
    assert!(flat.instances.is_empty());
    // The lamp is the one emitter either way.
    assert_eq!(flat.emitters.len(), shared.emitters.len());
    assert_eq!(flat.emitter_power, shared.emitter_power);
    assert!((flat.extent - shared.extent).abs() <= 1e-5 * flat.extent);
}

/// The surface a ray meets in a build: distance, world-space corners, material, shading normal.
fn surface(scene: &GpuScene, origin: Vec3, direction: Vec3) -> Option<(f32, [Vec3; 3], u32, Vec3)> {
    let mut hit: Hit = rt_core::estimator::trace(scene, origin, direction, f32::MAX);
    if hit.triangle == u32::MAX {
        return None;
    }
    let mut placed = None;
    let t = hit_triangle(scene, &mut hit, &mut placed);
    let b = [1.0 - hit.b1 - hit.b2, hit.b1, hit.b2];
    let s = t.shading();
    let n = Vec3::from(s.n0) * b[0] + Vec3::from(s.n1) * b[1] + Vec3::from(s.n2) * b[2];
    let corners = [t.tri.v0, t.tri.v1, t.tri.v2].map(Vec3::from);
    Some((hit.t, corners, t.tri.material, n.normalize_or_zero()))
}

#[test]
fn rays_meet_the_same_surfaces_through_instances_as_through_copies() {
    let scene = shared_balls();
    for layout in [BvhLayout::Bvh2, BvhLayout::Cwbvh] {
        let (flat, shared) = builds(&scene, layout);
        let mut rng = Rng::new(7, 0, 1);
        let (mut compared, mut mismatched) = (0, 0);
        for _ in 0..40_000 {
            let origin = Vec3::new(
                rng.next_f32() * 6.0 - 3.0,
                rng.next_f32() * 3.0,
                rng.next_f32() * 6.0 - 3.0,
            );
            // Uniform on the sphere: z uniform in [-1, 1], the azimuth uniform.
            let (z, phi) = (
                rng.next_f32() * 2.0 - 1.0,
                rng.next_f32() * std::f32::consts::TAU,
            );
            let r = (1.0 - z * z).max(0.0).sqrt();
            let direction = Vec3::new(r * phi.cos(), r * phi.sin(), z);
            let (a, b) = (
                surface(&flat, origin, direction),
                surface(&shared, origin, direction),
            );
            match (a, b) {
                (None, None) => {}
                (Some((ta, ca, ma, na)), Some((tb, cb, mb, nb))) => {
                    compared += 1;
                    let same = (ta - tb).abs() <= 1e-4 * ta.max(1.0)
                        && ma == mb
                        && (0..3).all(|k| ca[k].distance(cb[k]) <= 1e-4)
                        && na.distance(nb) <= 1e-3;
                    if !same {
                        mismatched += 1;
                        eprintln!("{layout:?} {origin} {direction}: {a:?} vs {b:?}");
                    }
                }
                // A grazing ray may slip past an edge in one build and not the other.
                _ => mismatched += 1,
            }
        }
        assert!(compared > 8_000, "{compared}");
        assert!(
            mismatched <= 2,
            "{layout:?}: {mismatched} of {compared} rays differ"
        );
    }
}

#[test]
fn a_scene_renders_the_same_with_instances_as_with_copies() {
    let scene = shared_balls();
    let (flat, shared) = builds(&scene, BvhLayout::default());
    let frame = rt_core::frame::frame_for(&scene, &flat).unwrap();
    assert_eq!(frame, rt_core::frame::frame_for(&scene, &shared).unwrap());
    let spp = 64;
    let a = rt_core::estimator::render(&flat, &frame, spp);
    let b = rt_core::estimator::render(&shared, &frame, spp);
    let mut worst: f32 = 0.0;
    for i in 0..a.mean.len() {
        for c in 0..3 {
            let diff = a.mean[i][c] - b.mean[i][c];
            let sigma = ((a.variance[i][c] + b.variance[i][c]) / spp as f32).sqrt();
            if diff != 0.0 {
                worst = worst.max(diff.abs() / sigma.max(1e-6));
            }
        }
    }
    // Both follow the same random numbers, so most pixels agree exactly; the rest within noise.
    assert!(worst < 4.5, "a pixel differs by {worst} standard errors");
    let total = |img: &rt_core::estimator::ReferenceImage| -> f64 {
        img.mean.iter().flatten().map(|&v| f64::from(v)).sum()
    };
    let (ta, tb) = (total(&a), total(&b));
    assert!((ta - tb).abs() <= 0.01 * ta, "image sums {ta} and {tb}");
}

#[test]
fn emitters_stay_in_world_space() {
    let mut scene = shared_balls();
    let lamp = scene.objects[1].mesh.clone();
    scene.objects.push(object(
        "second lamp",
        &lamp,
        scene.objects[1].material.clone(),
        placed([1.0, 0.2, 0.0], [0.0; 3], [1.0; 3]),
    ));
    let (flat, shared) = builds(&scene, BvhLayout::default());
    assert_eq!(shared.instances.len(), 4, "the lamps are not instanced");
    assert_eq!(flat.emitters.len(), shared.emitters.len());
}

#[test]
fn a_singular_instance_transform_is_an_error_naming_the_object() {
    let mut scene = shared_balls();
    scene.objects[3].transform.scale = [1.0, 0.0, 1.0];
    let message = GpuScene::build(&scene).unwrap_err().to_string();
    assert!(message.contains("turned and stretched"), "{message}");
}
