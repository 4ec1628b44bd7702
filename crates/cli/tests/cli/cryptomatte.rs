//! `--aov cryptomatte`: Cryptomatte's object layers and manifest in the EXR, as Blender and Nuke
//! read them.

use std::collections::{HashMap, HashSet};

use super::*;

/// The Cornell box from outside with `--aov cryptomatte,object`: the header names the layer, its
/// hash and conversion, and a manifest of the box's objects; inside an object (where the first
/// sample's object id is the same all round) the first rank is that object's id with all the
/// coverage, each object its own id; the background has none; every pixel's coverage adds up to
/// at most 1. A render part refuses the pass.
#[test]
fn cryptomatte_layers_and_manifest_are_written() {
    let dir = temp_dir("cryptomatte");
    let camera = super::outside_camera(&dir);
    let out = dir.join("crypto.exr");
    let size = 24;
    let (code, _, stderr) = rt_cli(&[
        "render",
        "--device",
        "cpu",
        "--width",
        "24",
        "--height",
        "24",
        "--spp",
        "8",
        "--camera",
        camera.to_str().unwrap(),
        "--aov",
        "cryptomatte,object",
        "-o",
        out.to_str().unwrap(),
    ]);
    assert_eq!(code, 0, "{stderr}");
    let image = exr::prelude::read_all_flat_layers_from_file(&out).unwrap();
    let layer = &image.layer_data[0];
    let attribute = |suffix: &str| {
        let (_, value) = (layer.attributes.other.iter())
            .find(|(name, _)| name.to_string().ends_with(suffix))
            .unwrap_or_else(|| panic!("no cryptomatte/…/{suffix} attribute"));
        match value {
            exr::meta::attribute::AttributeValue::Text(t) => t.to_string(),
            other => panic!("{suffix} is not text: {other:?}"),
        }
    };
    let key = rt_core::cryptomatte::metadata_key("CryptoObject");
    assert!(
        (layer.attributes.other.keys()).any(|k| k.to_string() == format!("cryptomatte/{key}/name"))
    );
    assert_eq!(attribute("/name"), "CryptoObject");
    assert_eq!(attribute("/hash"), "MurmurHash3_32");
    assert_eq!(attribute("/conversion"), "uint32_to_float32");
    let manifest: HashMap<String, String> = serde_json::from_str(&attribute("/manifest")).unwrap();
    assert!(manifest.len() >= 5, "{manifest:?}");
    let known: HashSet<u32> = (manifest.values())
        .map(|hex| {
            rt_core::cryptomatte::id_of_hash(u32::from_str_radix(hex, 16).unwrap()).to_bits()
        })
        .collect();
    let values = |name: &str| -> Vec<f32> {
        let channel = (layer.channel_data.list.iter())
            .find(|c| c.name.to_string() == name)
            .unwrap_or_else(|| panic!("no channel {name}"));
        channel.sample_data.values_as_f32().collect()
    };
    let object = values("object.ID");
    let ranks: Vec<(Vec<f32>, Vec<f32>)> = (0..3)
        .flat_map(|layer| [("r", "g"), ("b", "a")].map(|(i, c)| (layer, i, c)))
        .map(|(layer, i, c)| {
            let name = format!("CryptoObject{layer:02}");
            (
                values(&format!("{name}.{i}")),
                values(&format!("{name}.{c}")),
            )
        })
        .collect();
    let mut id_of_object: HashMap<u32, u32> = HashMap::new();
    for y in 1..size - 1 {
        for x in 1..size - 1 {
            let i = y * size + x;
            let total: f32 = ranks.iter().map(|(_, c)| c[i]).sum();
            assert!(total <= 1.0 + 1e-6, "pixel {x},{y}: coverage {total}");
            for (ids, coverage) in &ranks {
                if coverage[i] > 0.0 {
                    assert!(
                        known.contains(&ids[i].to_bits()),
                        "pixel {x},{y}: unknown id"
                    );
                }
            }
            let around = [i - 1, i + 1, i - size, i + size];
            if object[i] == 0.0 || around.iter().any(|&j| object[j] != object[i]) {
                continue;
            }
            assert_eq!(ranks[0].1[i], 1.0, "pixel {x},{y} inside an object");
            let id = ranks[0].0[i].to_bits();
            assert_eq!(*id_of_object.entry(object[i] as u32).or_insert(id), id);
        }
    }
    let distinct: HashSet<u32> = id_of_object.values().copied().collect();
    assert!(id_of_object.len() >= 3, "{id_of_object:?}");
    assert_eq!(distinct.len(), id_of_object.len(), "one id per object");
    assert_eq!((ranks[0].1[0], object[0]), (0.0, 0.0), "the background");

    let (code, _, stderr) = rt_cli(&[
        "render",
        "--shard",
        "1/2",
        "--aov",
        "cryptomatte",
        "-o",
        dir.join("part.exr").to_str().unwrap(),
    ]);
    assert_ne!(code, 0);
    assert!(stderr.contains("without --shard"), "{stderr}");
    std::fs::remove_dir_all(&dir).unwrap();
}
