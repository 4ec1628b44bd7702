#![allow(clippy::unwrap_used)]
//! Textures over a device's buffer budget are box-filtered down in the built scene: the result is
//! the scene built from the halved images (same texels, same material slots), and a scene within
//! the budget is left alone.

use std::sync::Arc;

use rt_core::material::Pbr;
use rt_core::scene::{Mesh, Object, Texture};
use rt_core::{GpuScene, Material, Scene};

fn texture(name: &str, width: u32, height: u32, seed: u32) -> Texture {
    let rgba: Vec<u8> = (0..width * height * 4)
        .map(|i| (i.wrapping_mul(2_654_435_761).wrapping_add(seed) >> 24) as u8)
        .collect();
    Texture {
        name: name.into(),
        width,
        height,
        rgba8: rgba.into(),
        sampler: Default::default(),
    }
}

/// The 2×2 block means of `t` (even sides), rounded as the fitting rounds.
fn halved(t: &Texture) -> Texture {
    let (w, h) = (t.width as usize, t.height as usize);
    let mut rgba = Vec::new();
    for y in 0..h / 2 {
        for x in 0..w / 2 {
            for c in 0..4 {
                let at = |dx: usize, dy: usize| {
                    u32::from(t.rgba8[4 * ((2 * y + dy) * w + 2 * x + dx) + c])
                };
                rgba.push(((at(0, 0) + at(1, 0) + at(0, 1) + at(1, 1) + 2) / 4) as u8);
            }
        }
    }
    Texture {
        width: t.width / 2,
        height: t.height / 2,
        rgba8: rgba.into(),
        ..t.clone()
    }
}

fn scene(textures: Vec<Texture>) -> Scene {
    let quad = Arc::new(Mesh {
        positions: vec![glam::Vec3::ZERO, glam::Vec3::X, glam::Vec3::Y],
        normals: Some(vec![glam::Vec3::Z; 3]),
        uvs: Some(vec![glam::Vec2::ZERO, glam::Vec2::X, glam::Vec2::Y]),
        colors: None,
        indices: vec![[0, 1, 2]],
    });
    let object = |name: &str, material| Object {
        shadow_catcher: false,
        animation_node: None,
        name: name.into(),
        mesh: quad.clone(),
        material,
        transform: Default::default(),
    };
    Scene {
        objects: vec![
            object(
                "diffuse",
                Material::Lambertian {
                    albedo: [1.0; 3],
                    texture: Some(0),
                },
            ),
            object(
                "pbr",
                Material::Pbr(Box::new(Pbr {
                    texture: Some(1),
                    metallic_roughness_texture: Some(0),
                    ..Default::default()
                })),
            ),
        ],
        textures,
        ..Default::default()
    }
}

#[test]
fn textures_over_the_budget_are_the_halved_images() {
    let (big, small) = (texture("big", 8, 8, 1), texture("small", 4, 4, 2));
    let built = GpuScene::build(&scene(vec![big.clone(), small.clone()])).unwrap();
    assert_eq!(built.texels.len(), 80);
    assert!(
        built.with_textures_within(320).is_none(),
        "within the budget: left alone"
    );

    let (fitted, fit) = built.with_textures_within(200).unwrap();
    assert_eq!(fit.downscaled, vec![((8, 8), (4, 4))]);
    assert_eq!((fit.needed_bytes, fit.budget_bytes), (320, 200));
    let expected = GpuScene::build(&scene(vec![halved(&big), small.clone()])).unwrap();
    assert_eq!(fitted.texels, expected.texels);
    assert_eq!(fitted.materials, expected.materials);

    // Both halved, the larger first, until they fit in 64 bytes (16 texels).
    let (fitted, fit) = built.with_textures_within(64).unwrap();
    assert_eq!(fit.downscaled, vec![((8, 8), (2, 2)), ((4, 4), (2, 2))]);
    let expected = GpuScene::build(&scene(vec![halved(&halved(&big)), halved(&small)])).unwrap();
    assert_eq!(fitted.texels, expected.texels);
    assert_eq!(fitted.materials, expected.materials);
    assert!(fit.to_string().contains("8×8 → 2×2"), "{fit}");
}
