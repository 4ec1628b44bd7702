//! A mutation fuzzer on stable Rust: at least 10,000 malformed OBJ and MTL inputs, 10,000 PLY and
//! 10,000 STL files (text and binary), 10,000 project archives and 2,000 camera files, made by mutating valid files, go through the loaders and the GPU scene build, which must return errors,
//! never panic. Deterministic (seeded), so a failure reproduces; any crashing input found is kept
//! as a regression case in `regressions()`.

#[path = "common/mesh_writers.rs"]
mod mesh_writers;

use std::path::Path;

use rt_core::math::rng::pcg_hash;
use rt_core::{Error, GpuScene, Texture};

const OBJ_SEEDS: &[&str] = &[
    include_str!("../../../assets/cornell/cornell.obj"),
    "mtllib scene.mtl\nv 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nvt 0 0\nvt 1 0\nvt 1 1\nvt 0 1\nvn 0 0 1\n\
     o quad\nusemtl tex\nf 1/1/1 2/2/1 3/3/1 4/4/1\ng other\nusemtl glass\nf -4 -3 -2\nusemtl metal\nf 1 3 4\n",
    "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0.5 1.5 0\nv 0 1 0\nf 1 2 3 4 5\no second\nf 1//1 2 3\nvn 0 0 1\n",
];

const MTL_SEEDS: &[&str] = &[
    include_str!("../../../assets/cornell/cornell.mtl"),
    "newmtl tex\nKd 1 1 1\nmap_Kd tex.png\nnewmtl glass\nillum 7\nNi 1.5\nTf 1 0.9 0.9\n\
     newmtl metal\nKs 0.9 0.8 0.7\nillum 3\nPr 0.2\nNs 100\nnewmtl light\nKe 10 10 10\nd 0.5\n",
];

const CAMERA_SEED: &str = include_str!("../../../assets/cornell/cornell.json");

const TOKENS: &[&str] = &[
    "",
    "0",
    "-0",
    "1",
    "-1",
    "2",
    "-2",
    "3",
    "nan",
    "NaN",
    "inf",
    "-inf",
    "1e39",
    "-1e39",
    "1e-45",
    "2147483647",
    "-2147483648",
    "4294967296",
    "99999999999999999999999999",
    "/",
    "//",
    "1/2/3/4",
    "1//",
    "//1",
    "\0",
    "é",
    "𝔣",
    "\t",
    " ",
    "f",
    "v",
    "vt",
    "vn",
    "o",
    "g",
    "usemtl",
    "mtllib",
    "newmtl",
    "map_Kd",
    "Ke",
    "Kd",
    "Ks",
    "Ni",
    "Pr",
    "Pm",
    "Pc",
    "Pcr",
    "Ps",
    "Tf",
    "illum",
    "d",
    "Ns",
    "scene.mtl",
    "../../../etc/passwd",
    "tex.png",
    "missing.png",
    "{",
    "}",
    "[",
    "]",
    ",",
    ":",
    "\"from\"",
    "null",
];

struct Fuzz(u32);

impl Fuzz {
    fn next(&mut self, n: usize) -> usize {
        self.0 = pcg_hash(self.0);
        (self.0 as usize) % n.max(1)
    }

    fn token(&mut self) -> String {
        if self.next(20) == 0 {
            return "9".repeat(1 + self.next(5000));
        }
        TOKENS[self.next(TOKENS.len())].to_string()
    }

    /// One random edit of `text`.
    fn mutate(&mut self, text: &str) -> String {
        let mut lines: Vec<String> = text.lines().map(str::to_string).collect();
        if lines.is_empty() {
            lines.push(String::new());
        }
        let i = self.next(lines.len());
        match self.next(8) {
            0 => {
                lines.remove(i);
            }
            1 => lines.insert(i, lines[i].clone()),
            2 => {
                let j = self.next(lines.len());
                lines.swap(i, j);
            }
            3 => {
                let mut words: Vec<String> = lines[i].split(' ').map(str::to_string).collect();
                let w = self.next(words.len());
                words[w] = self.token();
                lines[i] = words.join(" ");
            }
            4 => {
                let extra: Vec<String> = (0..1 + self.next(4)).map(|_| self.token()).collect();
                lines.insert(i, extra.join(" "));
            }
            5 => lines.truncate(i),
            6 => {
                let cut = self.next(lines[i].len() + 1);
                let cut = (0..=cut)
                    .rev()
                    .find(|&c| lines[i].is_char_boundary(c))
                    .unwrap_or(0);
                lines[i].truncate(cut);
            }
            _ => {
                let mut bytes = text.as_bytes().to_vec();
                if !bytes.is_empty() {
                    let at = self.next(bytes.len());
                    bytes[at] = self.next(256) as u8;
                }
                return String::from_utf8_lossy(&bytes).into_owned();
            }
        }
        lines.join("\n")
    }

    fn mutated(&mut self, text: &str) -> String {
        let mut out = text.to_string();
        for _ in 0..1 + self.next(4) {
            out = self.mutate(&out);
        }
        out
    }
}

/// Loads an OBJ with its MTL and a tiny texture from memory, then builds it for the GPU.
fn load_and_build(obj: &[u8], mtl: &[u8]) -> Result<(), Error> {
    let mtl = mtl.to_vec();
    let read_file = move |p: &Path| -> Result<Vec<u8>, Error> {
        if p.file_name().is_some_and(|n| n == "scene.mtl") {
            Ok(mtl.clone())
        } else {
            Err(Error::File {
                path: p.into(),
                message: "no such file".into(),
            })
        }
    };
    let load_texture = |p: &Path| -> Result<Texture, Error> {
        if p.file_name().is_some_and(|n| n == "tex.png") {
            Ok(Texture {
                sampler: Default::default(),
                name: "tex".into(),
                width: 2,
                height: 1,
                rgba8: vec![255; 8].into(),
            })
        } else {
            Err(Error::File {
                path: p.into(),
                message: "no such texture".into(),
            })
        }
    };
    let scene = rt_io::obj::load_obj_bytes(
        Path::new("fuzz/scene.obj"),
        obj,
        Path::new("fuzz"),
        &read_file,
        &load_texture,
        1,
    )?;
    GpuScene::build(&scene).map(|_| ())
}

fn assert_no_panic(what: &str, input: &str, f: impl FnOnce() + std::panic::UnwindSafe) {
    if std::panic::catch_unwind(f).is_err() {
        panic!("{what} panicked on input:\n{input:?}");
    }
}

#[test]
fn ten_thousand_malformed_obj_and_mtl_files_never_panic() {
    let mut fuzz = Fuzz(0x5eed);
    let mut errors = 0;
    let iterations = 10_000;
    for _ in 0..iterations {
        let obj_seed = OBJ_SEEDS[fuzz.next(OBJ_SEEDS.len())];
        let mtl_seed = MTL_SEEDS[fuzz.next(MTL_SEEDS.len())];
        let (obj, mtl) = match fuzz.next(3) {
            0 => (fuzz.mutated(obj_seed), mtl_seed.to_string()),
            1 => (obj_seed.to_string(), fuzz.mutated(mtl_seed)),
            _ => (fuzz.mutated(obj_seed), fuzz.mutated(mtl_seed)),
        };
        let obj = if obj.contains("mtllib") {
            obj
        } else {
            format!("mtllib scene.mtl\n{obj}")
        };
        let input = format!("--- OBJ\n{obj}\n--- MTL\n{mtl}");
        let (o, m) = (obj.clone(), mtl.clone());
        assert_no_panic("OBJ/MTL loading", &input, move || {
            let result = load_and_build(o.as_bytes(), m.as_bytes());
            if let Err(e) = &result {
                // The loader turns a panic inside tobj into this error; the fuzzer still counts it
                // as a bug to fix at its source (validation before tobj).
                assert!(
                    !e.to_string().contains("parser failed"),
                    "tobj panicked: {e}"
                );
            }
        });
        errors += usize::from(load_and_build(obj.as_bytes(), mtl.as_bytes()).is_err());
    }
    // The mutations must actually produce bad input most of the time, or this tests little.
    assert!(
        errors > iterations / 4,
        "only {errors} of {iterations} mutated inputs were rejected"
    );
}

#[test]
fn malformed_camera_files_never_panic() {
    let mut fuzz = Fuzz(0xca3e7a);
    for _ in 0..2_000 {
        let text = fuzz.mutated(CAMERA_SEED);
        let input = text.clone();
        assert_no_panic("camera JSON", &input, move || {
            if let Ok(camera) = rt_io::camera_json::CameraFile::parse(&text, Path::new("fuzz.json"))
            {
                let mut scene = rt_core::Scene::default();
                camera.apply(&mut scene);
                let _ = scene.camera.basis();
            }
        });
    }
}

/// Inputs that once crashed or misbehaved, kept so they stay fixed.
#[test]
fn regressions() {
    let cases: &[(&str, &str)] = &[
        // Found by this fuzzer: tobj 4 panics on a colour with one or two numbers ("Ks 0 ").
        (
            "v 0 0 0\nv 1 0 0\nv 0 1 0\nusemtl red\nf 1 2 3\n",
            "newmtl red\nKd 0.5 0 0\nKs 0 \nillum 1\n",
        ),
        (
            "v 0 0 0\nv 1 0 0\nv 0 1 0\nusemtl red\nf 1 2 3\n",
            "newmtl red\nKd 0.5 0\n",
        ),
        // An emitter quad given as one degenerate (zero-area) triangle plus a good one.
        (
            "v 0 0 0\nv 1 0 0\nv 2 0 0\nv 0 1 0\nusemtl light\nf 1 2 3\nf 1 2 4\n",
            "newmtl light\nKe 1 1 1\n",
        ),
    ];
    for (obj, mtl) in cases {
        let obj = format!("mtllib scene.mtl\n{obj}");
        assert_no_panic("regression", &obj.clone(), move || {
            if let Err(e) = load_and_build(obj.as_bytes(), mtl.as_bytes()) {
                assert!(
                    !e.to_string().contains("parser failed"),
                    "tobj panicked: {e}"
                );
            }
        });
    }
}

/// A project archive of the Cornell box plus a textured, transformed sphere: the fuzzer's seed.
fn seed_project() -> (Vec<u8>, Vec<(String, Vec<u8>)>) {
    use rt_io::project::{PROJECT_FORMAT, encode_archive};
    let mut scene = rt_io::assets::cornell_box().expect("embedded scene");
    scene.textures.push(rt_core::Texture {
        sampler: Default::default(),
        name: "t.png".into(),
        width: 2,
        height: 1,
        rgba8: vec![255, 0, 0, 255, 0, 0, 255, 255].into(),
    });
    scene.objects.push(rt_core::Object {
        shadow_catcher: false,
        animation_node: None,
        name: "ball".into(),
        mesh: rt_core::shapes::uv_sphere(40.0, 4, 6).into(),
        material: rt_core::Material::Lambertian {
            albedo: [1.0; 3],
            texture: Some(0),
        },
        transform: rt_core::Transform {
            translation: [200.0, 100.0, 200.0],
            rotation_deg: [0.0, 30.0, 0.0],
            scale: [1.0, 2.0, 1.0],
        },
    });
    let bytes = encode_archive(&scene, PROJECT_FORMAT, Path::new("seed.rtproj")).expect("encodes");
    let mut zip = zip::ZipArchive::new(std::io::Cursor::new(bytes.as_slice())).expect("reads");
    let entries = (0..zip.len())
        .map(|i| {
            let mut file = zip.by_index(i).expect("entry");
            let mut data = Vec::new();
            std::io::Read::read_to_end(&mut file, &mut data).expect("entry data");
            (file.name().expect("name").to_string(), data)
        })
        .collect();
    (bytes, entries)
}

fn rezip(entries: &[(String, Vec<u8>)]) -> Vec<u8> {
    use std::io::Write;
    let mut zip = zip::ZipWriter::new(std::io::Cursor::new(Vec::new()));
    for (name, data) in entries {
        zip.start_file(name.as_str(), zip::write::SimpleFileOptions::default())
            .expect("start entry");
        zip.write_all(data).expect("write entry");
    }
    zip.finish().expect("finish").into_inner()
}

#[test]
fn ten_thousand_malformed_project_files_never_panic() {
    use rt_io::project::{LoadLimits, PROJECT_FORMAT, decode_archive};
    let (bytes, entries) = seed_project();
    let manifest = entries
        .iter()
        .position(|(n, _)| n == "project.json")
        .expect("manifest entry");
    let mut fuzz = Fuzz(0x9e0);
    let iterations = 10_000;
    let mut errors = 0;
    for _ in 0..iterations {
        let input = match fuzz.next(4) {
            // Damage the archive itself: bytes changed, cut or inserted.
            0 => {
                let mut b = bytes.clone();
                for _ in 0..1 + fuzz.next(8) {
                    match fuzz.next(3) {
                        0 if !b.is_empty() => {
                            let at = fuzz.next(b.len());
                            b[at] = fuzz.next(256) as u8;
                        }
                        1 => b.truncate(fuzz.next(b.len() + 1)),
                        _ => {
                            let at = fuzz.next(b.len() + 1);
                            b.insert(at, fuzz.next(256) as u8);
                        }
                    }
                }
                b
            }
            // A damaged manifest in a sound archive.
            1 | 2 => {
                let mut e = entries.clone();
                let text = String::from_utf8_lossy(&e[manifest].1).into_owned();
                e[manifest].1 = fuzz.mutated(&text).into_bytes();
                rezip(&e)
            }
            // A damaged mesh or texture entry, or one renamed.
            _ => {
                let mut e = entries.clone();
                let i = fuzz.next(e.len());
                if fuzz.next(4) == 0 {
                    e[i].0 = ["../x", "/abs", "meshes/9.bin", "a\\b"][fuzz.next(4)].to_string();
                } else {
                    let data = &mut e[i].1;
                    if !data.is_empty() {
                        let at = fuzz.next(data.len());
                        data[at] = fuzz.next(256) as u8;
                        if fuzz.next(2) == 0 {
                            data.truncate(fuzz.next(data.len() + 1));
                        }
                    }
                }
                rezip(&e)
            }
        };
        let shown = format!("{} bytes: {:?}", input.len(), &input[..input.len().min(64)]);
        let copy = input.clone();
        assert_no_panic("project loading", &shown, move || {
            let limits = LoadLimits {
                max_entry_bytes: 16 << 20,
                max_total_bytes: 64 << 20,
                ..LoadLimits::default()
            };
            if let Ok(scene) =
                decode_archive(&copy, Path::new("fuzz.rtproj"), PROJECT_FORMAT, &limits)
            {
                let _ = GpuScene::build(&scene);
                let _ = rt_core::frame::validate(&scene);
            }
        });
        errors += usize::from(
            decode_archive(
                &input,
                Path::new("fuzz.rtproj"),
                PROJECT_FORMAT,
                &LoadLimits::default(),
            )
            .is_err(),
        );
    }
    assert!(
        errors > iterations / 4,
        "only {errors} of {iterations} mutated projects were rejected"
    );
}

/// One random edit of a binary file: a byte changed, a run removed or repeated, or the end cut.
fn mutate_bytes(fuzz: &mut Fuzz, bytes: &[u8]) -> Vec<u8> {
    let mut out = bytes.to_vec();
    for _ in 0..1 + fuzz.next(4) {
        if out.is_empty() {
            break;
        }
        let at = fuzz.next(out.len());
        let run = 1 + fuzz.next(16.min(out.len() - at));
        match fuzz.next(5) {
            0 => out[at] = fuzz.next(256) as u8,
            1 => {
                out.drain(at..at + run);
            }
            2 => {
                let copy = out[at..at + run].to_vec();
                out.splice(at..at, copy);
            }
            3 => out.truncate(at),
            _ => out[at..at + run].fill(0xff),
        }
    }
    out
}

/// PLY and STL seeds: a small mesh with normals, texture coordinates and colours in every
/// encoding.
fn mesh_seeds() -> (Vec<Vec<u8>>, Vec<Vec<u8>>) {
    use mesh_writers::{PlyEncoding, ply, stl_ascii, stl_binary, triangle_faces};
    let mut mesh = rt_core::shapes::uv_sphere(1.0, 3, 4);
    mesh.uvs = Some(
        mesh.positions
            .iter()
            .map(|p| glam::Vec2::new(p.x, p.y))
            .collect(),
    );
    let colors: Vec<[u8; 3]> = (0..mesh.positions.len())
        .map(|i| [i as u8, 7, 200])
        .collect();
    let mut faces = triangle_faces(&mesh);
    faces.push(vec![0, 1, 2, 3, 4]);
    let plys = [
        PlyEncoding::Ascii,
        PlyEncoding::LittleEndian,
        PlyEncoding::BigEndian,
    ]
    .into_iter()
    .map(|encoding| ply(&mesh, Some(&colors), &faces, encoding))
    .collect();
    let stls = vec![
        stl_ascii(&mesh, true),
        stl_binary(&mesh, "binary"),
        stl_binary(&mesh, "solid binary"),
    ];
    (plys, stls)
}

fn ten_thousand_malformed_mesh_files(
    format: &str,
    seeds: &[Vec<u8>],
    read: fn(&[u8]) -> Result<rt_core::scene::Mesh, Error>,
) {
    let mut fuzz = Fuzz(0x91e5 + format.len() as u32);
    let iterations = 10_000;
    let mut errors = 0;
    for _ in 0..iterations {
        let seed = &seeds[fuzz.next(seeds.len())];
        let input = if seed.is_ascii() && fuzz.next(2) == 0 {
            fuzz.mutated(&String::from_utf8_lossy(seed)).into_bytes()
        } else {
            mutate_bytes(&mut fuzz, seed)
        };
        let shown = String::from_utf8_lossy(&input).into_owned();
        let bytes = input.clone();
        assert_no_panic(format, &shown, move || {
            if let Ok(mesh) = read(&bytes) {
                let scene = rt_core::Scene {
                    objects: vec![rt_core::scene::Object {
                        shadow_catcher: false,
                        animation_node: None,
                        name: "fuzz".into(),
                        mesh: mesh.into(),
                        material: rt_core::Material::lambertian([0.5; 3]),
                        transform: Default::default(),
                    }],
                    ..Default::default()
                };
                let _ = GpuScene::build(&scene);
            }
        });
        errors += usize::from(read(&input).is_err());
    }
    assert!(
        errors > iterations / 4,
        "only {errors} of {iterations} mutated {format} files were rejected"
    );
}

#[test]
fn ten_thousand_malformed_ply_files_never_panic() {
    let (plys, _) = mesh_seeds();
    ten_thousand_malformed_mesh_files("PLY", &plys, |bytes| {
        rt_io::ply::read_ply(Path::new("fuzz.ply"), bytes)
    });
}

#[test]
fn ten_thousand_malformed_stl_files_never_panic() {
    let (_, stls) = mesh_seeds();
    ten_thousand_malformed_mesh_files("STL", &stls, |bytes| {
        rt_io::stl::read_stl(Path::new("fuzz.stl"), bytes)
    });
}

/// Basis Universal (KTX2) textures, decoded by another crate: 300 damaged copies never take the
/// program down (a panic inside the transcoder is caught and reported as an error naming the
/// file).
#[test]
fn damaged_ktx2_textures_never_panic() {
    let data = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/data");
    let ktx2 = std::fs::read(data.join("kodim23.ktx2")).expect("test data");
    let mut fuzz = Fuzz(0xba515);
    let dir = std::env::temp_dir().join(format!("rt-fuzz-ktx2-{}", std::process::id()));
    std::fs::create_dir_all(&dir).expect("temp dir");
    let file = dir.join("damaged.ktx2");
    let mut errors = 0;
    // 300: each transcode of the 768×512 image takes ~0.1 s in a debug build.
    for i in 0..300 {
        let bytes = mutate_bytes(&mut fuzz, &ktx2);
        std::fs::write(&file, &bytes).expect("temp file");
        let result = std::panic::catch_unwind(|| rt_io::texture::load_texture(&file));
        match result {
            Err(_) => panic!("damaged KTX2 {i} ({} bytes) panicked", bytes.len()),
            Ok(Err(e)) => {
                assert!(e.to_string().contains("damaged.ktx2"), "{e}");
                errors += 1;
            }
            Ok(Ok(_)) => {}
        }
    }
    std::fs::remove_dir_all(&dir).expect("temp dir");
    assert!(
        errors > 30,
        "only {errors} of 300 damaged KTX2 files were refused"
    );
}
