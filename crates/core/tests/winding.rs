#![allow(clippy::unwrap_used)]
//! A triangle's front is where its vertex normals point, whatever its winding: a glass ball whose
//! faces wind inward but whose normals point out (as `bench/scenes/glass-caustics` was written)
//! is the same solid glass as one wound outward, in the scene's arrays and in the image; without
//! normals, the winding alone decides.

use std::sync::Arc;
use std::sync::atomic::AtomicBool;

use rt_core::cpu_render::CpuAccumulation;
use rt_core::scene::{Mesh, Object, RenderSettings, Scene};
use rt_core::{Camera, GpuScene, Material};

fn glass_ball(mesh: Mesh) -> Scene {
    Scene {
        objects: vec![Object {
            shadow_catcher: false,
            animation_node: None,
            name: "ball".into(),
            mesh: Arc::new(mesh),
            material: Material::Dielectric {
                ior: 1.5,
                tint: [1.0; 3],
            },
            transform: Default::default(),
        }],
        camera: Camera {
            from: [0.0, 0.5, 3.0],
            to: [0.0, 0.0, 0.0],
            ..Default::default()
        },
        ambient: [0.6, 0.7, 0.9],
        settings: RenderSettings {
            width: 16,
            height: 16,
            max_depth: 6,
            ..Default::default()
        },
        ..Default::default()
    }
}

fn reversed(mut mesh: Mesh) -> Mesh {
    for t in &mut mesh.indices {
        t.swap(1, 2);
    }
    mesh
}

fn image(scene: &Scene) -> Vec<[f32; 4]> {
    let gpu = GpuScene::build(scene).unwrap();
    let frame = rt_core::frame::frame_for(scene, &gpu).unwrap();
    let mut accumulation = CpuAccumulation::new(&frame, 0, None, false);
    assert!(accumulation.add_batch(&gpu, &frame, 8, &AtomicBool::new(false)));
    accumulation.pixels()
}

#[test]
fn vertex_normals_decide_the_front_of_a_triangle() {
    let outward = rt_core::shapes::uv_sphere(1.0, 12, 24);
    let inward_wound = reversed(outward.clone());
    let (a, b) = (glass_ball(outward.clone()), glass_ball(inward_wound));
    assert_eq!(
        GpuScene::build(&a).unwrap().triangles,
        GpuScene::build(&b).unwrap().triangles,
        "the inward-wound ball's triangles are not turned to its normals"
    );
    assert_eq!(image(&a), image(&b));
    // Without normals the winding is the only orientation there is: turned over, the ball is
    // glass seen from inside, another image.
    let flat = |mesh: Mesh| Mesh {
        normals: None,
        ..mesh
    };
    let (c, d) = (
        glass_ball(flat(outward.clone())),
        glass_ball(flat(reversed(outward))),
    );
    assert_ne!(
        image(&c),
        image(&d),
        "without normals the winding should decide"
    );
    assert!(image(&a).iter().any(|p| p[0] > 0.0), "all black");
}
