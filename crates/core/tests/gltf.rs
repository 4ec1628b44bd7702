//! glTF 2.0 import: a file using every supported feature round-trips into the scene model exactly;
//! .glb and .gltf agree; unsupported and broken input is a clear error, never a panic (10,000
//! mutated files); Debian's assimp-testmodels corpus of real (and deliberately broken) files.

#![expect(clippy::unwrap_used, reason = "test helpers fail by panicking")]

use std::path::{Path, PathBuf};
use std::sync::Arc;

use base64::Engine as _;
use rt_core::io::gltf::{load_gltf, load_gltf_bytes};
use rt_core::light::{LightKind, SpotFalloff};
use rt_core::{Material, Scene};
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

fn close(a: [f32; 3], b: [f32; 3]) -> bool {
    a.iter().zip(b).all(|(x, y)| (x - y).abs() < 1e-4)
}

#[test]
fn every_supported_feature_maps_onto_the_scene_model() {
    let scene = load(&embedded(document()), None).unwrap();
    assert_eq!(scene.objects.len(), 2);
    let (a, b) = (&scene.objects[0], &scene.objects[1]);
    assert_eq!((a.name.as_str(), b.name.as_str()), ("quad A", "quad B"));
    assert!(Arc::ptr_eq(&a.mesh, &b.mesh), "instances share their mesh");
    assert!(close(a.transform.translation, [1.0, 2.0, 3.0]));
    assert!(close(a.transform.scale, [2.0; 3]));
    assert!(
        close(b.transform.translation, [5.0, 0.0, 0.0]),
        "{:?}",
        b.transform
    );
    assert!(
        close(b.transform.rotation_deg, [0.0, 90.0, 0.0]),
        "{:?}",
        b.transform
    );
    let mesh = &a.mesh;
    assert_eq!(mesh.indices, vec![[0, 1, 2], [0, 2, 3]]);
    assert_eq!(mesh.normals.as_ref().unwrap()[0], glam::Vec3::Y);
    assert_eq!(
        mesh.uvs.as_ref().unwrap()[0],
        glam::Vec2::new(0.0, 0.75),
        "v flipped to rt's convention"
    );
    let Material::Pbr(p) = &a.material else {
        panic!("PBR expected")
    };
    assert_eq!(p.base_color, [0.5, 0.6, 0.7]);
    assert_eq!((p.metallic, p.roughness), (0.25, 0.75));
    assert_eq!((p.emission, p.emission_strength), ([1.0, 0.5, 0.25], 4.0));
    assert_eq!((p.transmission, p.ior), (0.5, 1.33));
    assert_eq!(
        (p.attenuation_color, p.attenuation_distance),
        ([0.5, 0.5, 1.0], Some(2.0))
    );
    let c = &scene.camera;
    assert!(close(c.from, [0.0, 1.0, 10.0]) && close(c.to, [0.0, 1.0, 9.0]));
    assert!((c.vfov_deg - 0.7f32.to_degrees()).abs() < 1e-4);
    assert_eq!(
        scene.settings.height,
        scene.settings.width / 2,
        "aspect ratio 2"
    );
    assert_eq!(scene.lights.len(), 2);
    let (bulb, spot) = (&scene.lights[0], &scene.lights[1]);
    assert_eq!(bulb.kind, LightKind::Point);
    assert!((bulb.intensity - 1.0).abs() < 1e-6, "683 cd = 1 W/sr");
    assert_eq!(bulb.color, [1.0, 0.5, 0.25]);
    assert!(close(bulb.position, [0.0, 5.0, 0.0]));
    assert_eq!(
        (spot.kind, spot.falloff),
        (LightKind::Spot, SpotFalloff::Gltf)
    );
    assert!((spot.intensity - 2.0).abs() < 1e-6);
    assert!(
        close(spot.direction, [0.0, -1.0, 0.0]),
        "{:?}",
        spot.direction
    );
    assert!((spot.inner_angle_deg - 0.2f32.to_degrees()).abs() < 1e-4);
    assert!((spot.outer_angle_deg - 0.6f32.to_degrees()).abs() < 1e-4);
    assert!(scene.environment.is_none(), "the file brings its lights");
    assert!(!p.thin_walled, "transmission with a volume refracts");
    let mut doc = document();
    let ext = doc["materials"][0]["extensions"].as_object_mut().unwrap();
    ext.remove("KHR_materials_volume");
    let thin = load(&embedded(doc), None).unwrap();
    let Material::Pbr(p) = &thin.objects[0].material else {
        panic!()
    };
    assert!(
        p.thin_walled,
        "transmission without a volume is thin-walled"
    );
    rt_core::GpuScene::build(&scene).unwrap();
}

#[test]
fn glb_and_embedded_gltf_agree_and_scenes_are_chosen() {
    let mut doc = document();
    let from_gltf = load(&embedded(doc.clone()), None).unwrap();
    let from_glb = load(&glb(&doc), None).unwrap();
    assert_eq!(from_gltf, from_glb);
    let second = load(&embedded(doc.clone()), Some(1)).unwrap();
    assert_eq!(second.objects.len(), 1);
    assert!(second.lights.is_empty());
    assert!(
        second.environment.is_none(),
        "its emissive material lights it"
    );
    let mut dark = doc.clone();
    dark["materials"][0]["emissiveFactor"] = json!([0, 0, 0]);
    let second = load(&embedded(dark), Some(1)).unwrap();
    assert!(
        second.environment.is_some(),
        "no light at all: the default environment"
    );
    let e = load(&embedded(doc.clone()), Some(7))
        .unwrap_err()
        .to_string();
    assert!(e.contains("no scene 7"), "{e}");
    // Without a camera: framed automatically.
    doc["scenes"][0]["nodes"] = json!([0]);
    let framed = load(&embedded(doc), None).unwrap();
    assert_ne!(framed.camera, rt_core::Camera::default());
}

#[test]
fn a_file_with_a_separate_bin_and_percent_encoded_name_loads_from_disk() {
    let dir = std::env::temp_dir().join(format!("rt-gltf-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    std::fs::write(dir.join("my quad.bin"), quad_buffer()).unwrap();
    let mut doc = document();
    doc["buffers"][0]["uri"] = json!("my%20quad.bin");
    let path = dir.join("scene.gltf");
    std::fs::write(&path, serde_json::to_vec(&doc).unwrap()).unwrap();
    assert_eq!(load_gltf(&path, None).unwrap().objects.len(), 2);
    std::fs::remove_file(dir.join("my quad.bin")).unwrap();
    let e = load_gltf(&path, None).unwrap_err().to_string();
    assert!(e.contains("my quad.bin"), "{e}");
    std::fs::remove_dir_all(&dir).ok();
}

/// Each broken or unsupported file is an error saying what is wrong.
#[test]
fn unsupported_and_broken_files_are_clear_errors() {
    type Edit = Box<dyn Fn(&mut Value)>;
    let cases: Vec<(&str, Edit, &str)> = vec![
        (
            "Draco",
            Box::new(|d| {
                d["extensionsRequired"] = json!(["KHR_draco_mesh_compression"]);
                d["extensionsUsed"] = json!(["KHR_draco_mesh_compression"]);
            }),
            "gltf-transform",
        ),
        (
            "quantization",
            Box::new(|d| {
                d["extensionsRequired"] = json!(["KHR_mesh_quantization"]);
                d["extensionsUsed"] = json!(["KHR_mesh_quantization"]);
            }),
            "KHR_mesh_quantization",
        ),
        (
            "points",
            Box::new(|d| d["meshes"][0]["primitives"][0]["mode"] = json!(0)),
            "Points",
        ),
        (
            "short buffer",
            Box::new(|d| d["buffers"][0]["byteLength"] = json!(400)),
            "declares 400",
        ),
        (
            "huge count",
            Box::new(|d| d["accessors"][0]["count"] = json!(1_000_000_000u64)),
            "accessor 0 needs",
        ),
        (
            "view past buffer",
            Box::new(|d| d["bufferViews"][3]["byteLength"] = json!(4000)),
            "past its buffer",
        ),
        (
            "cycle",
            Box::new(|d| d["nodes"][2]["children"] = json!([1])),
            "",
        ),
        (
            "no scenes",
            Box::new(|d| {
                d["scenes"] = json!([]);
                d.as_object_mut().unwrap().remove("scene");
            }),
            "",
        ),
    ];
    for (what, edit, says) in cases {
        let mut doc = document();
        edit(&mut doc);
        let e = load(&embedded(doc), None).unwrap_err().to_string();
        assert!(e.contains(says), "{what}: {e}");
        assert!(e.contains("test.gltf"), "{what}: names the file: {e}");
    }
    let mut doc = document();
    doc["buffers"][0]["uri"] = json!("data:application/octet-stream,AAAA");
    let e = load(&serde_json::to_vec(&doc).unwrap(), None)
        .unwrap_err()
        .to_string();
    assert!(e.contains("not base64"), "{e}");
    doc["buffers"][0]["uri"] = json!("data:application/octet-stream;base64,@@@@");
    let e = load(&serde_json::to_vec(&doc).unwrap(), None)
        .unwrap_err()
        .to_string();
    assert!(e.contains("base64"), "{e}");
    // An index past the vertices.
    let mut bytes = quad_buffer();
    bytes[128] = 9;
    let data = base64::engine::general_purpose::STANDARD.encode(&bytes);
    let mut doc = document();
    doc["buffers"][0]["uri"] = json!(format!("data:application/octet-stream;base64,{data}"));
    let e = load(&serde_json::to_vec(&doc).unwrap(), None)
        .unwrap_err()
        .to_string();
    assert!(e.contains("index 9"), "{e}");
    let e = load(b"{not json", None).unwrap_err().to_string();
    assert!(e.contains("not valid glTF"), "{e}");
}

/// A tiny deterministic generator (xorshift) for the fuzzer.
struct Xorshift(u64);

impl Xorshift {
    fn next(&mut self) -> u64 {
        self.0 ^= self.0 << 13;
        self.0 ^= self.0 >> 7;
        self.0 ^= self.0 << 17;
        self.0
    }
    fn below(&mut self, n: usize) -> usize {
        (self.next() % n.max(1) as u64) as usize
    }
}

/// Byte flips, insertions, truncations and numbers swapped for extreme ones, of both the .gltf
/// and the .glb: 10,000 files, none of which may panic (an error is fine).
#[test]
fn ten_thousand_mutated_gltf_and_glb_files_never_panic() {
    let originals = [embedded(document()), glb(&document())];
    let extremes: [&[u8]; 6] = [b"-1", b"4294967295", b"1e39", b"0", b"99999999999", b"null"];
    static PANICS: std::sync::atomic::AtomicUsize = std::sync::atomic::AtomicUsize::new(0);
    let default_hook = std::panic::take_hook();
    std::panic::set_hook(Box::new(move |info| {
        PANICS.fetch_add(1, std::sync::atomic::Ordering::SeqCst);
        default_hook(info);
    }));
    let mut rng = Xorshift(0x9e37_79b9_7f4a_7c15);
    let (mut ok, mut errors) = (0, 0);
    for i in 0..10_000 {
        let mut bytes = originals[i % 2].clone();
        for _ in 0..1 + rng.below(4) {
            match rng.below(4) {
                0 => {
                    let at = rng.below(bytes.len());
                    bytes[at] ^= 1 << rng.below(8);
                }
                1 => {
                    let at = rng.below(bytes.len());
                    bytes.truncate(at.max(1));
                }
                2 => {
                    // Replace a run of digits by an extreme number.
                    let digits: Vec<usize> = (0..bytes.len())
                        .filter(|&k| bytes[k].is_ascii_digit())
                        .collect();
                    if !digits.is_empty() {
                        let at = digits[rng.below(digits.len())];
                        let end = (at..bytes.len())
                            .find(|&k| !bytes[k].is_ascii_digit())
                            .unwrap_or(bytes.len());
                        let with = extremes[rng.below(extremes.len())];
                        bytes.splice(at..end, with.iter().copied());
                    }
                }
                _ => {
                    let at = rng.below(bytes.len());
                    let b = bytes[rng.below(bytes.len())];
                    bytes.insert(at, b);
                }
            }
        }
        match load(&bytes, None) {
            Ok(scene) => {
                ok += 1;
                let _ = rt_core::GpuScene::build(&scene);
            }
            Err(_) => errors += 1,
        }
    }
    eprintln!("{ok} mutated files loaded, {errors} were errors");
    assert_eq!(
        PANICS.load(std::sync::atomic::Ordering::SeqCst),
        0,
        "the loader (or a crate under it) panicked, even if the guard caught it"
    );
    assert!(errors > 1000, "the mutations must break most files");
}

fn corpus() -> Option<PathBuf> {
    let dir = PathBuf::from("/usr/share/assimp/models/glTF2");
    dir.is_dir().then_some(dir)
}

fn files_under(dir: &Path, out: &mut Vec<PathBuf>) {
    for entry in std::fs::read_dir(dir).into_iter().flatten().flatten() {
        let p = entry.path();
        if p.is_dir() {
            files_under(&p, out);
        } else if p.extension().is_some_and(|e| e == "gltf" || e == "glb") {
            out.push(p);
        }
    }
}

/// Debian's assimp-testmodels (installed by scripts/test): every real glTF 2.0 file either loads
/// or is a clear error naming it (never a panic); the known-good sample models load; the
/// deliberately broken ones are errors.
#[test]
fn the_assimp_gltf2_corpus_loads_or_fails_cleanly() {
    let Some(dir) = corpus() else {
        assert!(
            std::env::var_os("CI").is_none(),
            "CI: /usr/share/assimp/models/glTF2 is missing (scripts/test installs assimp-testmodels)"
        );
        eprintln!("skipped: install assimp-testmodels for the glTF corpus test");
        return;
    };
    let mut files = Vec::new();
    files_under(&dir, &mut files);
    files.sort();
    assert!(files.len() > 30, "{} files", files.len());
    let (mut loaded, mut failed) = (Vec::new(), Vec::new());
    for file in &files {
        match load_gltf(file, None) {
            Ok(scene) => {
                rt_core::GpuScene::build(&scene)
                    .map(|_| ())
                    .unwrap_or_else(|e| eprintln!("{}: builds with an error: {e}", file.display()));
                loaded.push(file.clone());
            }
            Err(e) => {
                let message = e.to_string();
                assert!(
                    message.contains(&*file.file_name().unwrap().to_string_lossy())
                        || message.contains(".bin")
                        || message.contains(".png")
                        || message.contains(".jpg"),
                    "{}: the error names no file: {message}",
                    file.display()
                );
                failed.push((file.clone(), message));
            }
        }
    }
    eprintln!("{} of {} corpus files loaded", loaded.len(), files.len());
    for (p, m) in &failed {
        eprintln!("refused {}: {m}", p.display());
    }
    for good in [
        "BoxTextured-glTF/BoxTextured.gltf",
        "BoxTextured-glTF-Binary/BoxTextured.glb",
        "BoxTextured-glTF-Embedded/BoxTextured.gltf",
    ] {
        assert!(
            loaded.iter().any(|p| p.ends_with(good)),
            "{good} should load; errors: {:?}",
            failed.iter().find(|(p, _)| p.ends_with(good))
        );
    }
    for bad in ["IndexOutOfRange", "MissingBin", "RecursiveNodes"] {
        let mine: Vec<_> = files
            .iter()
            .filter(|p| p.to_string_lossy().contains(bad))
            .collect();
        assert!(!mine.is_empty(), "{bad}: no files");
        for p in mine {
            assert!(
                !loaded.contains(p),
                "{} is broken and must not load",
                p.display()
            );
        }
    }
}

/// `scene` saved as a project and loaded back.
fn through_a_project(scene: &Scene) -> Scene {
    use rt_core::io::project::{PROJECT_FORMAT, decode_archive, encode_archive};
    let path = Path::new("scene.rtproj");
    let bytes = encode_archive(scene, PROJECT_FORMAT, path).unwrap();
    decode_archive(&bytes, path, PROJECT_FORMAT, &Default::default()).unwrap()
}

/// A glTF scene saved as a project reloads as the same scene (materials, lights, camera, shared
/// meshes).
#[test]
fn a_gltf_scene_round_trips_through_a_project() {
    let scene = load(&embedded(document()), None).unwrap();
    let back = through_a_project(&scene);
    assert_eq!(back, scene);
    assert!(Arc::ptr_eq(&back.objects[0].mesh, &back.objects[1].mesh));
}

/// A base colour texture (a data-URI PNG) with a `KHR_texture_transform`: the image is decoded,
/// and its offset, rotation and scale are baked into the UVs (then flipped to rt's v-up).
#[test]
fn textures_load_and_texture_transforms_bake_into_the_uvs() {
    let mut png = std::io::Cursor::new(Vec::new());
    image::RgbaImage::from_raw(2, 1, vec![255, 0, 0, 255, 0, 0, 255, 255])
        .unwrap()
        .write_to(&mut png, image::ImageFormat::Png)
        .unwrap();
    let uri = format!(
        "data:image/png;base64,{}",
        base64::engine::general_purpose::STANDARD.encode(png.get_ref())
    );
    let mut doc = document();
    doc["images"] = json!([{"uri": uri}]);
    doc["textures"] = json!([{"source": 0}]);
    doc["extensionsUsed"]
        .as_array_mut()
        .unwrap()
        .push(json!("KHR_texture_transform"));
    doc["materials"][0]["pbrMetallicRoughness"]["baseColorTexture"] = json!({"index": 0,
        "extensions": {"KHR_texture_transform": {"offset": [0.5, 0.25], "scale": [2.0, 3.0]}}});
    doc["materials"][0]["normalTexture"] = json!({"index": 0, "scale": 0.5});
    // Vertex colours: COLOR_0 as normalized u8 RGBA, a fifth buffer view.
    let mut buffer = quad_buffer();
    buffer.extend([
        255u8, 0, 0, 255, 0, 255, 0, 255, 0, 0, 255, 255, 255, 255, 255, 255,
    ]);
    doc["buffers"][0]["byteLength"] = json!(buffer.len());
    doc["bufferViews"]
        .as_array_mut()
        .unwrap()
        .push(json!({"buffer": 0, "byteOffset": 140, "byteLength": 16}));
    doc["accessors"]
        .as_array_mut()
        .unwrap()
        .push(json!({"bufferView": 4, "componentType": 5121,
        "normalized": true, "count": 4, "type": "VEC4"}));
    doc["meshes"][0]["primitives"][0]["attributes"]["COLOR_0"] = json!(4);
    doc["buffers"][0]["uri"] = json!(format!(
        "data:application/octet-stream;base64,{}",
        base64::engine::general_purpose::STANDARD.encode(&buffer)
    ));
    let scene = load(&serde_json::to_vec(&doc).unwrap(), None).unwrap();
    let colors = scene.objects[0].mesh.colors.as_ref().expect("COLOR_0 read");
    assert_eq!(colors[1], glam::Vec3::Y);
    assert_eq!(scene.textures.len(), 1, "one image, decoded once");
    assert_eq!((scene.textures[0].width, scene.textures[0].height), (2, 1));
    let Material::Pbr(p) = &scene.objects[0].material else {
        panic!()
    };
    assert_eq!(
        (p.texture, p.normal_texture, p.normal_scale),
        (Some(0), Some(0), 0.5)
    );
    // Vertex 0 has glTF uv (0, 0.25): scaled (0, 0.75), offset (0.5, 1.0), v flipped: (0.5, 0.0).
    let uv = scene.objects[0].mesh.uvs.as_ref().unwrap()[0];
    assert!((uv - glam::Vec2::new(0.5, 0.0)).length() < 1e-6, "{uv}");
    rt_core::GpuScene::build(&scene).unwrap();
}

/// `document()` with a 2×1 data-URI PNG as image 0.
fn document_with_image() -> Value {
    let mut png = std::io::Cursor::new(Vec::new());
    image::RgbaImage::from_raw(2, 1, vec![255, 0, 0, 255, 0, 0, 255, 0])
        .unwrap()
        .write_to(&mut png, image::ImageFormat::Png)
        .unwrap();
    let mut doc = document();
    doc["images"] = json!([{"uri": format!(
        "data:image/png;base64,{}",
        base64::engine::general_purpose::STANDARD.encode(png.get_ref())
    )}]);
    doc
}

/// Samplers' wrap modes and magnification filter reach the textures (one image read through two
/// samplers is two textures; through the same sampler, one); the emissive texture is an emission
/// image; MASK keeps its cutoff and BLEND the base colour factor's alpha; the occlusion texture
/// is left out.
#[test]
fn samplers_emissive_textures_and_alpha_modes_map_onto_the_material() {
    use rt_core::material::AlphaMode;
    use rt_core::{Filter, Wrap};
    let mut doc = document_with_image();
    doc["samplers"] = json!([
        {"wrapS": 33071, "wrapT": 33648, "magFilter": 9728},
        {}
    ]);
    doc["textures"] = json!([
        {"source": 0, "sampler": 0},
        {"source": 0, "sampler": 1},
        {"source": 0, "sampler": 0}
    ]);
    let m = &mut doc["materials"][0];
    m["pbrMetallicRoughness"]["baseColorTexture"] = json!({"index": 0});
    m["pbrMetallicRoughness"]["baseColorFactor"] = json!([1.0, 1.0, 1.0, 0.6]);
    m["pbrMetallicRoughness"]["metallicRoughnessTexture"] = json!({"index": 2});
    m["emissiveTexture"] = json!({"index": 1});
    m["occlusionTexture"] = json!({"index": 1});
    m["alphaMode"] = json!("MASK");
    m["alphaCutoff"] = json!(0.25);
    let scene = load(&embedded(doc.clone()), None).unwrap();
    assert_eq!(scene.textures.len(), 2, "one image through two samplers");
    let s = scene.textures[0].sampler;
    assert_eq!(
        (s.wrap_s, s.wrap_t, s.filter),
        (Wrap::ClampToEdge, Wrap::MirroredRepeat, Filter::Nearest)
    );
    assert_eq!(
        scene.textures[1].sampler,
        rt_core::TextureSampler::default()
    );
    let Material::Pbr(p) = &scene.objects[0].material else {
        panic!()
    };
    assert_eq!(
        (p.texture, p.metallic_roughness_texture, p.emission_texture),
        (Some(0), Some(0), Some(1))
    );
    assert_eq!(
        (p.alpha_mode, p.alpha, p.alpha_cutoff),
        (AlphaMode::Mask, 0.6, 0.25)
    );
    let gpu = rt_core::GpuScene::build(&scene).unwrap();
    assert!(gpu.features.alpha && gpu.features.textures);
    let g = &gpu.materials[0];
    assert_eq!(
        g.flags & rt_core::gpu_types::ALPHA_MASK,
        rt_core::gpu_types::ALPHA_MASK
    );
    // Clamp (1) on s, mirror (2) on t, nearest: 1 | 2 << 2 | 1 << 4 in the base and
    // metallic-roughness slots; the emission slot's sampler is the default (0).
    assert_eq!(
        g.samplers,
        0b11001
            | 0b11001
                << (rt_core::gpu_types::SAMPLER_BITS * rt_core::gpu_types::SLOT_METALLIC_ROUGHNESS)
    );
    assert_ne!(
        g.texture(rt_core::gpu_types::SLOT_EMISSION).offset,
        rt_core::gpu_types::NO_TEXTURE
    );

    doc["materials"][0]["alphaMode"] = json!("BLEND");
    let scene = load(&embedded(doc.clone()), None).unwrap();
    let Material::Pbr(p) = &scene.objects[0].material else {
        panic!()
    };
    assert_eq!((p.alpha_mode, p.alpha), (AlphaMode::Blend, 0.6));
    // A project keeps samplers, the emission image and the alpha mode.
    let back = through_a_project(&scene);
    assert_eq!(back, scene);
}

/// The spec requires POSITION's min and max, and the gltf crate refuses files without them, but
/// exporters leave them out: rt computes its own bounds and opens such files (and ones whose
/// bounds are malformed) with the same geometry.
#[test]
fn position_accessors_without_min_and_max_still_load() {
    let full = load(&embedded(document()), None).unwrap();
    for bounds in [json!(null), json!("nonsense"), json!([1, 2])] {
        let mut doc = document();
        let accessor = doc["accessors"][0].as_object_mut().unwrap();
        if bounds.is_null() {
            accessor.remove("min");
            accessor.remove("max");
        } else {
            accessor.insert("min".into(), bounds.clone());
        }
        let scene = load(&embedded(doc), None).unwrap_or_else(|e| panic!("bounds {bounds}: {e}"));
        assert_eq!(scene.objects[0].mesh, full.objects[0].mesh);
    }
}
