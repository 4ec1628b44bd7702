//! glTF 2.0 import: a file using every supported feature round-trips into the scene model exactly;
//! .glb and .gltf agree; unsupported and broken input is a clear error, never a panic (10,000
//! mutated files); Debian's assimp-testmodels corpus of real (and deliberately broken) files.
//!
//! `features.rs` holds the supported features, `textures.rs` textures, samplers and alpha,
//! `broken_input.rs` unsupported, broken and mutated files and the corpus.

#![expect(clippy::unwrap_used, reason = "test helpers fail by panicking")]

mod broken_input;
mod features;
mod hierarchy;
mod khronos_samples;
mod textures;

use std::path::Path;

use base64::Engine as _;
use rt_core::{Material, Scene};
use rt_io::gltf::{load_gltf, load_gltf_bytes};
use serde_json::{Value, json};

/// A quad's positions, normals, UVs and u16 indices, little-endian, 140 bytes.
fn quad_buffer() -> Vec<u8> {
    let mut b = Vec::new();
    let f = |b: &mut Vec<u8>, v: &[f32]| v.iter().for_each(|x| b.extend(x.to_le_bytes()));
    f(
        &mut b,
        &[-1., 0., 1., 1., 0., 1., 1., 0., -1., -1., 0., -1.],
    );
    f(&mut b, &[0., 1., 0., 0., 1., 0., 0., 1., 0., 0., 1., 0.]);
    f(&mut b, &[0., 0.25, 1., 0.25, 1., 1., 0., 1.]);
    for i in [0u16, 1, 2, 0, 2, 3] {
        b.extend(i.to_le_bytes());
    }
    b
}

/// A document using every mapped feature; its buffer `uri` is filled in by the caller.
fn document() -> Value {
    let h = std::f64::consts::FRAC_1_SQRT_2;
    json!({
        "asset": {"version": "2.0"},
        "extensionsUsed": ["KHR_lights_punctual", "KHR_materials_emissive_strength",
            "KHR_materials_transmission", "KHR_materials_ior", "KHR_materials_volume"],
        "scene": 0,
        "scenes": [{"nodes": [0, 1, 3, 4, 5]}, {"nodes": [0]}],
        "nodes": [
            {"name": "quad A", "mesh": 0, "translation": [1, 2, 3], "scale": [2, 2, 2]},
            {"name": "parent", "matrix": [1,0,0,0, 0,1,0,0, 0,0,1,0, 5,0,0,1], "children": [2]},
            {"name": "quad B", "mesh": 0, "rotation": [0, h, 0, h]},
            {"name": "cam", "camera": 0, "translation": [0, 1, 10]},
            {"name": "bulb", "translation": [0, 5, 0],
             "extensions": {"KHR_lights_punctual": {"light": 0}}},
            {"name": "spot", "translation": [0, 5, 0], "rotation": [-h, 0, 0, h],
             "extensions": {"KHR_lights_punctual": {"light": 1}}}
        ],
        "meshes": [{"primitives": [{"attributes": {"POSITION": 0, "NORMAL": 1, "TEXCOORD_0": 2},
            "indices": 3, "material": 0}]}],
        "materials": [{
            "pbrMetallicRoughness": {"baseColorFactor": [0.5, 0.6, 0.7, 1.0],
                "metallicFactor": 0.25, "roughnessFactor": 0.75},
            "emissiveFactor": [1.0, 0.5, 0.25],
            "extensions": {
                "KHR_materials_emissive_strength": {"emissiveStrength": 4.0},
                "KHR_materials_transmission": {"transmissionFactor": 0.5},
                "KHR_materials_ior": {"ior": 1.33},
                "KHR_materials_volume": {"attenuationColor": [0.5, 0.5, 1.0], "attenuationDistance": 2.0}
            }
        }],
        "cameras": [{"type": "perspective",
            "perspective": {"yfov": 0.7, "aspectRatio": 2.0, "znear": 0.1}}],
        "extensions": {"KHR_lights_punctual": {"lights": [
            {"type": "point", "color": [1.0, 0.5, 0.25], "intensity": 683.0},
            {"type": "spot", "intensity": 1366.0,
             "spot": {"innerConeAngle": 0.2, "outerConeAngle": 0.6}}
        ]}},
        "accessors": [
            {"bufferView": 0, "componentType": 5126, "count": 4, "type": "VEC3",
             "min": [-1, 0, -1], "max": [1, 0, 1]},
            {"bufferView": 1, "componentType": 5126, "count": 4, "type": "VEC3"},
            {"bufferView": 2, "componentType": 5126, "count": 4, "type": "VEC2"},
            {"bufferView": 3, "componentType": 5123, "count": 6, "type": "SCALAR"}
        ],
        "bufferViews": [
            {"buffer": 0, "byteOffset": 0, "byteLength": 48},
            {"buffer": 0, "byteOffset": 48, "byteLength": 48},
            {"buffer": 0, "byteOffset": 96, "byteLength": 32},
            {"buffer": 0, "byteOffset": 128, "byteLength": 12}
        ],
        "buffers": [{"byteLength": 140}]
    })
}

fn embedded(mut doc: Value) -> Vec<u8> {
    let data = base64::engine::general_purpose::STANDARD.encode(quad_buffer());
    doc["buffers"][0]["uri"] = json!(format!("data:application/octet-stream;base64,{data}"));
    serde_json::to_vec(&doc).unwrap()
}

/// The GLB container: header, JSON chunk (space-padded), BIN chunk (zero-padded).
fn glb(doc: &Value) -> Vec<u8> {
    let mut json = serde_json::to_vec(doc).unwrap();
    while !json.len().is_multiple_of(4) {
        json.push(b' ');
    }
    let mut bin = quad_buffer();
    while !bin.len().is_multiple_of(4) {
        bin.push(0);
    }
    let total = 12 + 8 + json.len() + 8 + bin.len();
    let mut out = Vec::new();
    out.extend(b"glTF");
    out.extend(2u32.to_le_bytes());
    out.extend((total as u32).to_le_bytes());
    out.extend((json.len() as u32).to_le_bytes());
    out.extend(b"JSON");
    out.extend(json);
    out.extend((bin.len() as u32).to_le_bytes());
    out.extend(b"BIN\0");
    out.extend(bin);
    out
}

fn no_files(p: &Path) -> rt_core::Result<Vec<u8>> {
    Err(rt_core::Error::File {
        path: p.into(),
        message: "no such file in this test".into(),
    })
}

fn load(bytes: &[u8], scene: Option<usize>) -> rt_core::Result<Scene> {
    load_gltf_bytes(
        bytes,
        Path::new("test.gltf"),
        Path::new("."),
        &no_files,
        scene,
    )
}

/// `scene` saved as a project and loaded back.
fn through_a_project(scene: &Scene) -> Scene {
    use rt_io::project::{PROJECT_FORMAT, decode_archive, encode_archive};
    let path = Path::new("scene.rtproj");
    let bytes = encode_archive(scene, PROJECT_FORMAT, path).unwrap();
    decode_archive(&bytes, path, PROJECT_FORMAT, &Default::default()).unwrap()
}
