#![allow(clippy::unwrap_used)]
//! A scene whose build cannot fit in this machine's memory (here a million-triangle mesh placed
//! 200,000 times: 2·10¹¹ triangles, tens of terabytes flattened) is a clear error at once, before
//! anything is allocated for it, not an out-of-memory kill.

use std::sync::Arc;

use rt_core::scene::{Mesh, Object};
use rt_core::{GpuScene, Material, Scene};

#[test]
fn a_scene_too_big_for_memory_is_an_error_before_the_build() {
    let mesh = Arc::new(Mesh {
        positions: vec![glam::Vec3::ZERO, glam::Vec3::X, glam::Vec3::Y],
        normals: None,
        uvs: None,
        colors: None,
        indices: vec![[0, 1, 2]; 1_000_000],
    });
    let objects = (0..200_000)
        .map(|i| Object {
            shadow_catcher: false,
            animation_node: None,
            name: format!("copy {i}"),
            mesh: mesh.clone(),
            material: Material::lambertian([0.5; 3]),
            transform: Default::default(),
        })
        .collect();
    let scene = Scene {
        objects,
        ..Default::default()
    };
    let (quality, layout) = (Default::default(), Default::default());
    let message = GpuScene::build_flattened(&scene, quality, layout)
        .unwrap_err()
        .to_string();
    assert!(
        message.contains("200000000000 triangles")
            && message.contains("GB of memory are available"),
        "{message}"
    );
}
