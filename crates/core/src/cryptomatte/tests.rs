use std::sync::Arc;

use glam::Vec3;

use super::*;
use crate::camera::{Camera, Projection};
use crate::material::Material;
use crate::scene::{Mesh, Object};

/// The hashes Blender 5.2.3 wrote in its Cryptomatte manifest for these names, and the key of its
/// layer `ViewLayer.CryptoObject` (a Cycles render of five cubes so named).
#[test]
fn names_hash_as_blender_hashes_them() {
    for (name, hash) in [
        ("Cube", 0xa8fc_e865),
        ("bunny", 0x1385_1a76),
        ("Suzanne.001", 0x087a_6316),
        ("a", 0x3c25_69b2),
        ("floor (3)", 0x7d8f_966a),
    ] {
        assert_eq!(name_hash(name), hash, "{name}");
    }
    assert_eq!(metadata_key("ViewLayer.CryptoObject"), "542cafa");
    assert_eq!(murmur3_32(b"", 0), 0);
}

/// Ids are floats a compositor can hold and compare: never NaN, infinite or denormal, whatever the
/// hash's exponent bits; other bits are kept.
#[test]
fn ids_are_ordinary_floats() {
    for hash in [
        0u32,
        0x007f_ffff,
        0x7f80_0000,
        0xffff_ffff,
        0x8000_0001,
        0x3f80_1234,
    ] {
        let id = id_of_hash(hash);
        assert!(id.is_normal(), "{hash:08x} -> {id}");
        assert_eq!(id.to_bits() & 0x807f_ffff, hash & 0x807f_ffff);
    }
    assert_eq!(
        id_of_hash(0x3f80_1234).to_bits(),
        0x3f80_1234,
        "a normal float stays"
    );
}

/// A tall rectangle from x0 to x1 in the plane z = 0, facing +z.
fn strip(name: &str, x0: f32, x1: f32, material: Material) -> Object {
    Object {
        name: name.into(),
        mesh: Arc::new(Mesh {
            positions: vec![
                Vec3::new(x0, -5.0, 0.0),
                Vec3::new(x1, -5.0, 0.0),
                Vec3::new(x1, 5.0, 0.0),
                Vec3::new(x0, 5.0, 0.0),
            ],
            indices: vec![[0, 1, 2], [0, 2, 3]],
            ..Mesh::default()
        }),
        material,
        transform: Default::default(),
        shadow_catcher: false,
        animation_node: None,
    }
}

/// Two strips side by side, x ∈ [−1, 0] (a, diffuse) and [0, 1] (b, glass), seen by an
/// orthographic camera through five columns of pixels 0.5 wide centred on x = −1, −0.5, 0, 0.5,
/// 1: the column at the strips' seam is half a, half b; the outer ones half a strip and half
/// background (which has no id); the others all one strip.
#[test]
fn coverage_splits_pixels_at_edges_and_leaves_the_background_out() {
    let mut scene = Scene {
        objects: vec![
            strip("a", -1.0, 0.0, Material::lambertian([0.5; 3])),
            strip(
                "b",
                0.0,
                1.0,
                Material::Dielectric {
                    ior: 1.5,
                    tint: [1.0; 3],
                },
            ),
        ],
        camera: Camera {
            from: [0.0, 0.0, 5.0],
            to: [0.0; 3],
            projection: Projection::Orthographic,
            ortho_height: Some(0.5),
            ..Camera::default()
        },
        ..Scene::default()
    };
    (scene.settings.width, scene.settings.height) = (5, 1);
    let gpu = GpuScene::build(&scene).unwrap();
    let frame = crate::frame::frame_for(&scene, &gpu).unwrap();
    let per_pixel = coverage(&gpu, &frame, 64);
    let share = |pixel: usize, object: u32| {
        (per_pixel[pixel].iter())
            .find(|(o, _)| *o == object)
            .map_or(0.0, |(_, c)| *c)
    };
    let half = |c: f32| (c - 0.5).abs() <= 3.0 / 32.0;
    assert!(
        half(share(0, 0)) && per_pixel[0].len() == 1,
        "{:?}",
        per_pixel[0]
    );
    assert_eq!(per_pixel[1], [(0, 1.0)]);
    assert!(half(share(2, 0)) && half(share(2, 1)), "{:?}", per_pixel[2]);
    assert!((share(2, 0) + share(2, 1) - 1.0).abs() < 1e-6);
    assert_eq!(per_pixel[3], [(1, 1.0)], "glass counts as a hit");
    assert!(
        half(share(4, 1)) && per_pixel[4].len() == 1,
        "{:?}",
        per_pixel[4]
    );
    // Ranked by coverage: the seam's larger share first.
    let seam = &per_pixel[2];
    assert!(seam[0].1 >= seam[1].1);

    let (channels, metadata) = layers(&scene, &per_pixel);
    let get = |name: &str| &channels.iter().find(|(n, _)| n == name).unwrap().1;
    assert_eq!(channels.len(), 2 * RANKS);
    let a = id_of_hash(name_hash("a"));
    assert_eq!(get("CryptoObject00.r")[1], a);
    assert_eq!(get("CryptoObject00.g")[1], 1.0);
    assert_eq!(get("CryptoObject00.b")[1], 0.0, "one object: rank 1 empty");
    assert_eq!(get("CryptoObject00.a")[2], seam[1].1);
    assert_eq!(get("CryptoObject02.a"), &vec![0.0; 5]);
    let key = metadata_key(LAYER);
    let meta = |field: &str| {
        let name = format!("cryptomatte/{key}/{field}");
        metadata.iter().find(|(n, _)| *n == name).unwrap().1.clone()
    };
    assert_eq!(meta("name"), LAYER);
    assert_eq!(meta("hash"), "MurmurHash3_32");
    assert_eq!(meta("conversion"), "uint32_to_float32");
    let manifest: serde_json::Value = serde_json::from_str(&meta("manifest")).unwrap();
    assert_eq!(manifest["b"], format!("{:08x}", name_hash("b")));
}

/// Names outside ASCII are escaped (EXR text holds bytes), and read back as the same names.
#[test]
fn manifests_are_ascii_json() {
    let mut scene = Scene::default();
    for name in ["ünï \"quoted\"", "🐇", "plain"] {
        scene
            .objects
            .push(strip(name, 0.0, 1.0, Material::lambertian([0.5; 3])));
    }
    let text = manifest(&scene);
    assert!(text.is_ascii(), "{text}");
    let parsed: serde_json::Value = serde_json::from_str(&text).unwrap();
    for name in ["ünï \"quoted\"", "🐇", "plain"] {
        assert_eq!(parsed[name], format!("{:08x}", name_hash(name)), "{name}");
    }
}
