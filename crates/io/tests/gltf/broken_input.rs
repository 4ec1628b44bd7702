//! Unsupported and broken input: clear errors, 10,000 mutated files, the assimp corpus.

use super::*;
use std::path::PathBuf;

use base64::Engine as _;

/// Each broken or unsupported file is an error saying what is wrong.
#[test]
fn unsupported_and_broken_files_are_clear_errors() {
    type Edit = Box<dyn Fn(&mut Value)>;
    let cases: Vec<(&str, Edit, &str)> = vec![
        (
            "meshopt's newer bitstreams",
            Box::new(|d| {
                d["extensionsRequired"] = json!(["KHR_meshopt_compression"]);
                d["extensionsUsed"] = json!(["KHR_meshopt_compression"]);
            }),
            "gltf-transform",
        ),
        (
            "quantized normals not normalized",
            Box::new(|d| {
                d["accessors"][1]["componentType"] = json!(5122);
            }),
            "is not what it is used for",
        ),
        (
            "points",
            Box::new(|d| d["meshes"][0]["primitives"][0]["mode"] = json!(0)),
            "points or lines, nothing rt can render",
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

/// Khronos' ClearCoatTest (in assimp-testmodels): its coated column gets coats, with their
/// textures (partial coating, roughness variations) and the coat's own normal maps.
#[test]
fn the_clear_coat_test_model_loads_its_coats() {
    let Some(dir) = corpus() else {
        assert!(
            std::env::var_os("CI").is_none(),
            "CI: assimp-testmodels missing"
        );
        return;
    };
    let scene = load_gltf(&dir.join("ClearCoat-glTF/ClearCoatTest.gltf"), None).unwrap();
    let coats: Vec<_> = scene
        .objects
        .iter()
        .filter_map(|o| match &o.material {
            rt_core::Material::Pbr(p) if p.clearcoat > 0.0 => Some(p),
            _ => None,
        })
        .collect();
    assert_eq!(coats.len(), 6, "one coated sample per row");
    assert!(coats.iter().any(|p| p.clearcoat_texture.is_some()));
    assert!(
        coats
            .iter()
            .any(|p| p.clearcoat_roughness_texture.is_some())
    );
    assert_eq!(
        coats
            .iter()
            .filter(|p| p.clearcoat_normal_texture.is_some())
            .count(),
        2,
        "the coat normal map and the shared normal map rows"
    );
    rt_core::GpuScene::build(&scene).unwrap();
}

/// glTF 1.0 (JSON with `asset.version` 1.0, or a binary container of version 1) is named as such,
/// with the way to upgrade it, not reported as broken 2.0; Debian's corpus has six such files.
#[test]
fn gltf_1_files_are_named_as_such() {
    let json_1 = json!({
        "asset": {"version": "1.0"},
        "meshes": {"mesh_1": {"primitives": []}},
        "scene": "defaultScene",
        "scenes": {"defaultScene": {"nodes": []}}
    });
    let mut glb_1 = b"glTF".to_vec();
    glb_1.extend(1u32.to_le_bytes());
    glb_1.extend(20u32.to_le_bytes());
    glb_1.extend([0u8; 8]);
    for (what, bytes) in [("JSON", json_1.to_string().into_bytes()), ("binary", glb_1)] {
        let message = load_gltf_bytes(
            &bytes,
            Path::new("old.gltf"),
            Path::new("."),
            &|p| {
                Err(rt_core::Error::File {
                    path: p.into(),
                    message: "no files".into(),
                })
            },
            None,
        )
        .unwrap_err()
        .to_string();
        assert!(
            message.starts_with("old.gltf: glTF 1.0; rt reads glTF 2.0")
                && message.contains("gltf-pipeline"),
            "{what}: {message}"
        );
    }
    let dir = Path::new("/usr/share/assimp/models/glTF");
    if dir.is_dir() {
        let mut files = Vec::new();
        files_under(dir, &mut files);
        assert!(files.len() >= 6, "{files:?}");
        for file in files {
            let message = load_gltf(&file, None).unwrap_err().to_string();
            assert!(
                message.contains("glTF 1.0"),
                "{}: {message}",
                file.display()
            );
        }
    }
}

/// Points and lines beside triangles are skipped (a scan's point cloud, an exporter's edges): the
/// triangles load.
#[test]
fn points_and_lines_beside_triangles_are_skipped() {
    let mut doc = document();
    let triangles = doc["meshes"][0]["primitives"][0].clone();
    for mode in [0, 1, 2, 3] {
        let mut other = triangles.clone();
        other["mode"] = json!(mode);
        doc["meshes"][0]["primitives"]
            .as_array_mut()
            .unwrap()
            .push(other);
    }
    let scene = load(&embedded(doc), None).unwrap();
    let plain = load(&embedded(document()), None).unwrap();
    assert_eq!(scene.triangle_count(), plain.triangle_count());
    assert_eq!(scene.objects.len(), plain.objects.len());
}
