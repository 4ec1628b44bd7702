//! OBJ/MTL loading: polygons, indices, groups, material splits, every MTL mapping rule, textures,
//! forgiving reading of what Blender and assimp open (missing files, Windows paths, other
//! encodings, unnamed materials), and malformed input reported with file and line.
#![expect(
    clippy::unwrap_used,
    reason = "test helpers fail the test on unexpected errors"
)]

use std::path::{Path, PathBuf};

use rt_core::{Error, Material, Scene};
use rt_io::obj::load_obj;

/// A fresh folder with the given files.
fn dir_with(files: &[(&str, &[u8])]) -> PathBuf {
    static COUNTER: std::sync::atomic::AtomicU32 = std::sync::atomic::AtomicU32::new(0);
    let n = COUNTER.fetch_add(1, std::sync::atomic::Ordering::Relaxed);
    let dir = std::env::temp_dir().join(format!("rt-obj-test-{}-{n}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    for (name, contents) in files {
        std::fs::write(dir.join(name), contents).unwrap();
    }
    dir
}

fn load(obj: &str, mtl: Option<&str>) -> Result<Scene, Error> {
    let mut files: Vec<(&str, &[u8])> = vec![("scene.obj", obj.as_bytes())];
    if let Some(mtl) = mtl {
        files.push(("scene.mtl", mtl.as_bytes()));
    }
    load_obj(&dir_with(&files).join("scene.obj"), 7)
}

fn parse_error_line(result: Result<Scene, Error>) -> (usize, String) {
    match result {
        Err(Error::Parse {
            line,
            message,
            path,
        }) => {
            assert!(
                path.to_string_lossy().ends_with(".obj")
                    || path.to_string_lossy().ends_with(".mtl")
            );
            (line, message)
        }
        other => panic!("expected a parse error, got {other:?}"),
    }
}

const SQUARE: &str = "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\n";

#[test]
fn quads_and_ngons_are_triangulated() {
    let scene = load(
        &format!("{SQUARE}v 0.5 1.5 0\nf 1 2 3 4\nf 1 2 3 5 4\n"),
        None,
    )
    .unwrap();
    assert_eq!(scene.objects.len(), 1);
    assert_eq!(scene.objects[0].mesh.indices.len(), 2 + 3);
}

#[test]
fn negative_indices_count_back_from_the_last_vertex() {
    let relative = load(&format!("{SQUARE}f -4 -3 -2\n"), None).unwrap();
    let absolute = load(&format!("{SQUARE}f 1 2 3\n"), None).unwrap();
    let corners =
        |s: &Scene| s.objects[0].mesh.indices[0].map(|i| s.objects[0].mesh.positions[i as usize]);
    assert_eq!(corners(&relative), corners(&absolute));
}

#[test]
fn groups_become_objects_and_usemtl_splits_them() {
    let mtl = "newmtl a\nKd 1 0 0\nnewmtl b\nKd 0 1 0\n";
    let obj = format!(
        "mtllib scene.mtl\n{SQUARE}o first\nusemtl a\nf 1 2 3\nusemtl b\nf 1 3 4\ng second\nusemtl a\nf 1 2 4\n"
    );
    let scene = load(&obj, Some(mtl)).unwrap();
    let names: Vec<&str> = scene.objects.iter().map(|o| o.name.as_str()).collect();
    assert_eq!(names, ["first (a)", "first (b)", "second"]);
    assert_eq!(
        scene.objects[0].material,
        Material::lambertian([1.0, 0.0, 0.0])
    );
    assert_eq!(
        scene.objects[1].material,
        Material::lambertian([0.0, 1.0, 0.0])
    );
}

#[test]
fn missing_normals_stay_flat_and_given_normals_are_kept() {
    let flat = load(&format!("{SQUARE}f 1 2 3\n"), None).unwrap();
    assert!(
        flat.objects[0].mesh.normals.is_none(),
        "flat shading uses the geometric normal"
    );
    let smooth = load(&format!("{SQUARE}vn 0 0 1\nf 1//1 2//1 3//1\n"), None).unwrap();
    assert_eq!(
        smooth.objects[0].mesh.normals.as_ref().unwrap()[0],
        glam::Vec3::Z
    );
}

fn material_of(mtl_body: &str) -> Material {
    let mtl = format!("newmtl m\n{mtl_body}\n");
    let scene = load(
        &format!("mtllib scene.mtl\n{SQUARE}usemtl m\nf 1 2 3\n"),
        Some(&mtl),
    )
    .unwrap();
    scene.objects[0].material.clone()
}

#[test]
fn mtl_mapping_rules() {
    assert_eq!(
        material_of("Kd 0.5 0.25 0.125"),
        Material::lambertian([0.5, 0.25, 0.125])
    );
    assert_eq!(
        material_of("Kd 0 0 0\nKe 10 5 1"),
        Material::Emissive {
            color: [10.0, 5.0, 1.0],
            intensity: 1.0
        }
    );
    assert_eq!(
        material_of("Kd 0.25"),
        Material::lambertian([0.25; 3]),
        "one value is grey"
    );
    assert_eq!(
        material_of("Kd 0.5 0.5 0.5\nKe 0 0 0"),
        Material::lambertian([0.5; 3]),
        "Ke 0 is not an emitter"
    );
    let pbr = |p: rt_core::material::Pbr| Material::Pbr(Box::new(p));
    assert_eq!(
        material_of("Kd 0.2 0.2 0.2\nKs 0.9 0.8 0.7\nillum 3\nPr 0.25"),
        pbr(rt_core::material::Pbr {
            base_color: [0.9, 0.8, 0.7],
            metallic: 1.0,
            roughness: 0.25,
            ..Default::default()
        }),
        "PBR keys with illum 3: a rough metal"
    );
    assert_eq!(
        material_of("Kd 0.6 0.5 0.4\nPm 1\nPr 0.5"),
        pbr(rt_core::material::Pbr {
            base_color: [0.6, 0.5, 0.4],
            metallic: 1.0,
            roughness: 0.5,
            ..Default::default()
        }),
        "Ks absent: base colour from Kd"
    );
    assert_eq!(
        material_of("Kd 0.1 0.2 0.3\nPr 0.7\nNi 1.4"),
        pbr(rt_core::material::Pbr {
            base_color: [0.1, 0.2, 0.3],
            roughness: 0.7,
            ior: 1.4,
            ..Default::default()
        }),
        "Pr alone: a rough dielectric (plastic)"
    );
    assert_eq!(
        material_of("illum 7\nNi 1.45\nPr 0.3"),
        pbr(rt_core::material::Pbr {
            base_color: [1.0; 3],
            roughness: 0.3,
            ior: 1.45,
            transmission: 1.0,
            ..Default::default()
        }),
        "glass with Pr: rough glass"
    );
    assert_eq!(
        material_of("Kd 0.5 0.1 0.1\nPc 0.8\nPcr 0.05\nPs 0.3 0.2 2"),
        pbr(rt_core::material::Pbr {
            base_color: [0.5, 0.1, 0.1],
            clearcoat: 0.8,
            clearcoat_roughness: 0.05,
            sheen_color: [0.3, 0.2, 1.0],
            ..Default::default()
        }),
        "clear coat and sheen (clamped to [0, 1]) make a PBR material"
    );
    let Material::Metal { fuzz, .. } = material_of("Ks 1 1 1\nillum 3\nNs 198") else {
        panic!("metal expected")
    };
    assert!(
        (fuzz - 0.1).abs() < 1e-6,
        "fuzz from Ns: sqrt(2/(Ns+2)), got {fuzz}"
    );
    assert_eq!(
        material_of("illum 7\nNi 1.33"),
        Material::Dielectric {
            ior: 1.33,
            tint: [1.0; 3]
        }
    );
    assert_eq!(
        material_of("illum 4\nNi 2.4"),
        Material::Dielectric {
            ior: 2.4,
            tint: [1.0; 3]
        }
    );
    assert_eq!(
        material_of("illum 6"),
        Material::Dielectric {
            ior: 1.5,
            tint: [1.0; 3]
        },
        "default IOR"
    );
    assert_eq!(
        material_of("Kd 1 1 1\nd 0.5\nNi 1.6"),
        Material::Dielectric {
            ior: 1.6,
            tint: [1.0; 3]
        }
    );
    assert_eq!(
        material_of("Tf 0.9 1 0.8\nNi 1.5"),
        Material::Dielectric {
            ior: 1.5,
            tint: [0.9, 1.0, 0.8]
        }
    );
}

#[test]
fn objects_without_material_get_distinct_deterministic_colours() {
    let obj = format!("{SQUARE}o a\nf 1 2 3\no b\nf 1 3 4\n");
    let one = load(&obj, None).unwrap();
    let two = load(&obj, None).unwrap();
    assert_eq!(
        one.objects[0].material, two.objects[0].material,
        "same seed, same colours"
    );
    assert_ne!(
        one.objects[0].material, one.objects[1].material,
        "objects get different colours"
    );
}

#[test]
fn textures_load_relative_to_the_mtl_and_broken_ones_are_named() {
    let png = {
        let mut bytes = std::io::Cursor::new(Vec::new());
        image::RgbaImage::from_pixel(2, 2, image::Rgba([255, 0, 0, 255]))
            .write_to(&mut bytes, image::ImageFormat::Png)
            .unwrap();
        bytes.into_inner()
    };
    let obj =
        format!("mtllib scene.mtl\n{SQUARE}vt 0 0\nvt 1 0\nvt 1 1\nusemtl t\nf 1/1 2/2 3/3\n");
    let dir = dir_with(&[
        ("scene.obj", obj.as_bytes()),
        ("scene.mtl", b"newmtl t\nmap_Kd tex.png\n"),
        ("tex.png", &png),
    ]);
    let scene = load_obj(&dir.join("scene.obj"), 0).unwrap();
    assert_eq!(scene.textures.len(), 1);
    assert_eq!(
        scene.objects[0].material,
        Material::Lambertian {
            albedo: [0.8; 3],
            texture: Some(0)
        }
    );
    assert!(scene.objects[0].mesh.uvs.is_some());

    let dir = dir_with(&[
        ("scene.obj", obj.as_bytes()),
        ("scene.mtl", b"newmtl t\nmap_Kd bad.png\n"),
        ("bad.png", b"not a png"),
    ]);
    let err = load_obj(&dir.join("scene.obj"), 0).unwrap_err().to_string();
    assert!(
        err.contains("bad.png"),
        "error should name the corrupt texture: {err}"
    );
}

#[test]
fn a_texture_without_uvs_renders_white_with_a_warning() {
    let mut scene = Scene::default();
    scene.textures.push(rt_core::Texture {
        sampler: Default::default(),
        name: "t".into(),
        width: 1,
        height: 1,
        rgba8: vec![255, 0, 0, 255].into(),
    });
    scene.objects.push(rt_core::Object {
        shadow_catcher: false,
        animation_node: None,
        name: "no uvs".into(),
        mesh: rt_core::shapes::quad(glam::Vec3::ZERO, glam::Vec3::Z, 1.0).into(),
        material: Material::Lambertian {
            albedo: [0.3; 3],
            texture: Some(0),
        },
        transform: Default::default(),
    });
    let gpu = rt_core::GpuScene::build(&scene).unwrap();
    assert_eq!(gpu.materials[0].color, [1.0; 3]);
    assert_eq!(
        gpu.materials[0].textures[0].offset,
        rt_core::gpu_types::NO_TEXTURE
    );
    assert!(!gpu.features.textures);
}

#[test]
fn malformed_input_names_the_file_and_line() {
    let cases: &[(&str, usize, &str)] = &[
        ("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 9\n", 4, "out of range"),
        ("v 0 0 0\nv 1 0 0\nf 1 2\n", 3, "at least 3"),
        ("v 0 0 0\nv 1 x 0\n", 2, "not a number"),
        ("v 0 0\n", 1, "needs 3"),
        ("v 0 0 nan\n", 1, "not finite"),
        ("v 0 0 1e99\n", 1, "not finite"),
        ("v 0 0 0\nv 1 0 0\nv 0 1 0\n\nf 1 2 0\n", 5, "out of range"),
        (
            "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1/5 2 3\n",
            4,
            "texture coordinate index 5",
        ),
        (
            "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1//2 2 3\n",
            4,
            "normal index 2",
        ),
        ("v 0 0 0\nv 1 0 0\nv 0 1 0\nf -4 1 2\n", 4, "out of range"),
    ];
    for (obj, line, needle) in cases {
        let (got_line, message) = parse_error_line(load(obj, None));
        assert_eq!(got_line, *line, "wrong line for {obj:?}: {message}");
        assert!(
            message.contains(needle),
            "message for {obj:?} should mention '{needle}': {message}"
        );
    }
}

#[test]
fn a_material_without_a_name_is_named() {
    // Blender writes a material with an empty name as a bare `newmtl` (and `usemtl`), which tobj
    // refuses.
    let scene = load(
        "mtllib scene.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nusemtl\nf 1 2 3\n",
        Some("newmtl\nKd 1 0 0\n"),
    )
    .unwrap();
    assert_eq!(
        scene.objects[0].material,
        Material::lambertian([1.0, 0.0, 0.0])
    );
}

#[test]
fn missing_files_are_warnings_with_defaults() {
    let obj = format!("mtllib nowhere.mtl\n{SQUARE}f 1 2 3\n");
    let scene = load(&obj, None).unwrap();
    assert_eq!(
        scene.objects[0].material,
        Material::lambertian(rt_io::obj::distinct_color(7, 0)),
        "a missing mtllib leaves the object its default material"
    );
    let obj =
        format!("mtllib scene.mtl\n{SQUARE}vt 0 0\nvt 1 0\nvt 1 1\nusemtl t\nf 1/1 2/2 3/3\n");
    let scene = load(&obj, Some("newmtl t\nKd 0.2 0.3 0.4\nmap_Kd nowhere.png\n")).unwrap();
    assert_eq!(
        scene.objects[0].material,
        Material::Lambertian {
            albedo: [0.2, 0.3, 0.4],
            texture: None
        },
        "a missing texture leaves the material untextured"
    );
}

#[test]
fn windows_paths_other_cases_and_foreign_folders_find_the_file() {
    let png = {
        let mut bytes = std::io::Cursor::new(Vec::new());
        image::RgbaImage::from_pixel(1, 1, image::Rgba([0, 255, 0, 255]))
            .write_to(&mut bytes, image::ImageFormat::Png)
            .unwrap();
        bytes.into_inner()
    };
    let obj =
        format!("mtllib Scene.MTL\n{SQUARE}vt 0 0\nvt 1 0\nvt 1 1\nusemtl t\nf 1/1 2/2 3/3\n");
    for name in [
        ".\\tex.png",
        "TEX.PNG",
        "C:\\Users\\someone\\models\\tex.png",
        "/home/else/tex.png",
    ] {
        let mtl = format!("newmtl t\nmap_Kd {name}\n");
        let dir = dir_with(&[
            ("scene.obj", obj.as_bytes()),
            ("scene.mtl", mtl.as_bytes()),
            ("tex.png", &png),
        ]);
        let scene = load_obj(&dir.join("scene.obj"), 0).unwrap();
        assert_eq!(scene.textures.len(), 1, "{name}");
        assert_eq!(&scene.textures[0].rgba8[..], &[0, 255, 0, 255], "{name}");
    }
}

#[test]
fn text_in_other_encodings_is_read() {
    // Latin-1 names (an old Windows exporter), in the OBJ and its MTL alike.
    let mut obj =
        b"mtllib scene.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\no Gr\xfcn\nusemtl B\xe4r\nf 1 2 3\n"
            .to_vec();
    let dir = dir_with(&[
        ("scene.obj", &obj),
        ("scene.mtl", b"newmtl B\xe4r\nKd 0 0 1\n"),
    ]);
    let scene = load_obj(&dir.join("scene.obj"), 0).unwrap();
    assert_eq!(scene.objects[0].name, "Grün");
    assert_eq!(
        scene.objects[0].material,
        Material::lambertian([0.0, 0.0, 1.0])
    );
    // UTF-16 with a byte-order mark, both endiannesses.
    let text = format!("{SQUARE}o Wörld\nf 1 2 3 4\n");
    for big_endian in [true, false] {
        obj = if big_endian {
            vec![0xFE, 0xFF]
        } else {
            vec![0xFF, 0xFE]
        };
        for unit in text.encode_utf16() {
            obj.extend(if big_endian {
                unit.to_be_bytes()
            } else {
                unit.to_le_bytes()
            });
        }
        let dir = dir_with(&[("scene.obj", &obj)]);
        let scene = load_obj(&dir.join("scene.obj"), 0).unwrap();
        assert_eq!(
            (scene.objects[0].name.as_str(), scene.triangle_count()),
            ("Wörld", 2)
        );
    }
}

#[test]
fn bad_files_are_errors_not_panics() {
    let garbage: Vec<u8> = (0..4096u32)
        .map(|i| (i.wrapping_mul(2_654_435_761) >> 24) as u8)
        .collect();
    let dir = dir_with(&[("garbage.obj", &garbage)]);
    assert!(load_obj(&dir.join("garbage.obj"), 0).is_err());
    assert!(matches!(
        load_obj(&dir.join("missing.obj"), 0),
        Err(Error::Io { .. })
    ));
    assert!(
        matches!(load_obj(&dir, 0), Err(Error::File { .. })),
        "a directory is not an OBJ"
    );
    let (line, _) = parse_error_line(load(
        &format!("mtllib scene.mtl\n{SQUARE}f 1 2 3\n"),
        Some("newmtl a\nKd 1 x 1\n"),
    ));
    assert_eq!(line, 2, "MTL errors carry the MTL's line");
    let (line, message) = parse_error_line(load(
        &format!("mtllib scene.mtl\n{SQUARE}f 1 2 3\n"),
        Some("newmtl a\n\nKs 0 1\n"),
    ));
    assert_eq!(
        (line, message.contains("1 or 3 numbers")),
        (3, true),
        "{message}"
    );
}

#[test]
fn the_shipped_scenes_load() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("../..");
    let cornell = rt_io::assets::cornell_box().unwrap();
    assert_eq!(cornell.triangle_count(), 32);
    assert_eq!(cornell.objects.len(), 8);
    assert!(matches!(
        cornell
            .objects
            .iter()
            .find(|o| o.name == "light")
            .unwrap()
            .material,
        Material::Emissive { .. }
    ));
    let spot = load_obj(&root.join("assets/spot/spot_triangulated_textured.obj"), 0).unwrap();
    assert_eq!(spot.textures.len(), 1);
    assert_eq!(spot.triangle_count(), 5856);
    let bunny = load_obj(&root.join("assets/bunny/bunny-lowres-npm.obj"), 0).unwrap();
    assert_eq!(bunny.triangle_count(), 3674);
}

/// `v x y z r g b` gives the mesh vertex colours.
#[test]
fn vertex_colours_are_read() {
    let scene = load(
        "v 0 0 0 1 0 0\nv 1 0 0 0 1 0\nv 1 1 0 0 0 1\nf 1 2 3\n",
        None,
    )
    .unwrap();
    let colors = scene.objects[0].mesh.colors.as_ref().expect("colours");
    assert_eq!(colors[1], glam::Vec3::Y);
    let plain = load("v 0 0 0\nv 1 0 0\nv 1 1 0\nf 1 2 3\n", None).unwrap();
    assert!(plain.objects[0].mesh.colors.is_none());
}

/// A small image of `scene` on the CPU backend, every pixel finite.
fn assert_renders(scene: &Scene, what: &str) {
    let mut scene = scene.clone();
    (scene.settings.width, scene.settings.height) = (8, 8);
    let gpu = rt_core::GpuScene::build(&scene).unwrap_or_else(|e| panic!("{what}: {e}"));
    let frame = rt_core::frame::frame_for(&scene, &gpu).unwrap_or_else(|e| panic!("{what}: {e}"));
    let mut image = rt_core::cpu_render::CpuAccumulation::new(&frame, 0, None, false);
    let cancel = std::sync::atomic::AtomicBool::new(false);
    assert!(image.add_batch(&gpu, &frame, 1, &cancel), "{what}");
    assert!(
        image.pixels().iter().flatten().all(|c| c.is_finite()),
        "{what}: a pixel is not finite"
    );
}

/// Debian's assimp-testmodels (installed by scripts/test): every OBJ file Blender opens loads and
/// renders (a small image, every pixel finite), the forgiving cases among them (a Windows texture path, a missing MTL, Latin-1 and
/// UTF-16 text, an unnamed material, a 470-vertex face repeating its corners); the one made
/// invalid on purpose stays an error naming its line.
#[test]
fn the_assimp_obj_files_load() {
    let dir = Path::new("/usr/share/assimp/models/OBJ");
    if !dir.is_dir() {
        assert!(
            std::env::var_os("CI").is_none(),
            "CI: {} is missing (scripts/test installs assimp-testmodels)",
            dir.display()
        );
        eprintln!("skipped: install assimp-testmodels for the OBJ corpus test");
        return;
    }
    let mut files: Vec<PathBuf> = std::fs::read_dir(dir)
        .unwrap()
        .flatten()
        .map(|e| e.path())
        .filter(|p| p.extension().is_some_and(|e| e == "obj"))
        .collect();
    files.sort();
    assert!(files.len() >= 20, "{files:?}");
    for file in &files {
        let name = file.file_name().unwrap().to_string_lossy();
        let result = load_obj(file, 0);
        if name == "number_formats.obj" {
            // '3.1+e2' is no number (assimp's own test of a malformed exponent).
            let (line, message) = parse_error_line(result);
            assert_eq!(line, 11, "{message}");
            continue;
        }
        let scene = result.unwrap_or_else(|e| panic!("{name}: {e}"));
        assert_renders(&scene, &name);
    }
    let spider = load_obj(&dir.join("spider.obj"), 0).unwrap();
    assert_eq!(
        spider.textures.len(),
        5,
        "spider.mtl's '.\\\\*.jpg' textures"
    );
    let utf16 = load_obj(&dir.join("box_UTF16BE.obj"), 0).unwrap();
    assert_eq!(utf16.triangle_count(), 12);
}

/// Textures decode in every format the `image` crate writes here (DDS, which it only reads,
/// aside); by content where the format has a signature (a PNG named `.jpg` reads), by extension
/// where it has none (TGA).
#[test]
fn textures_decode_in_every_common_format() {
    let image = image::RgbaImage::from_fn(2, 1, |x, _| {
        if x == 0 {
            image::Rgba([255, 0, 0, 255])
        } else {
            image::Rgba([0, 0, 255, 255])
        }
    });
    let formats = [
        image::ImageFormat::Png,
        image::ImageFormat::Tga,
        image::ImageFormat::Bmp,
        image::ImageFormat::Tiff,
        image::ImageFormat::WebP,
        image::ImageFormat::Gif,
        image::ImageFormat::Qoi,
    ];
    for format in formats {
        let mut bytes = std::io::Cursor::new(Vec::new());
        let written = if format == image::ImageFormat::Gif {
            image::DynamicImage::ImageRgba8(image.clone()).write_to(&mut bytes, format)
        } else {
            image.write_to(&mut bytes, format)
        };
        written.unwrap_or_else(|e| panic!("{format:?}: {e}"));
        let name = match format {
            image::ImageFormat::Png => "misnamed.jpg".to_string(),
            _ => format!("texture.{}", format.extensions_str()[0]),
        };
        let dir = dir_with(&[(&name, &bytes.into_inner())]);
        let texture = rt_io::texture::load_texture(&dir.join(&name))
            .unwrap_or_else(|e| panic!("{format:?}: {e}"));
        assert_eq!((texture.width, texture.height), (2, 1), "{format:?}");
        assert_eq!(
            &texture.rgba8[..],
            &[255, 0, 0, 255, 0, 0, 255, 255],
            "{format:?}"
        );
    }
}

fn png(width: u32, height: u32, texel: [u8; 4]) -> Vec<u8> {
    let mut bytes = std::io::Cursor::new(Vec::new());
    image::RgbaImage::from_pixel(width, height, image::Rgba(texel))
        .write_to(&mut bytes, image::ImageFormat::Png)
        .unwrap();
    bytes.into_inner()
}

/// MTL's maps beyond `map_Kd` reach the PBR material's slots: a normal map (`norm`, with `-bm`), a
/// height map in `map_Bump` turned into one, `map_d` joined to the base colour's alpha, `map_Ke`,
/// `map_Pr`/`map_Pm` packed; a plain diffuse material with a map becomes a PBR one without a
/// specular layer; `map_Kd -o -s` moves the object's UVs.
#[test]
fn mtl_maps_reach_the_pbr_slots() {
    let obj = format!(
        "mtllib scene.mtl\n{SQUARE}vt 0 0\nvt 1 0\nvt 1 1\nvn 0 0 1\n\
         o a\nusemtl mapped\nf 1/1/1 2/2/1 3/3/1\no b\nusemtl bumped\nf 1/1/1 2/2/1 3/3/1\n\
         o c\nusemtl shiny\nf 1/1/1 2/2/1 3/3/1\n"
    );
    let mtl = "newmtl mapped\nKd 0.5 0.5 0.5\nmap_Kd -s 2 2 1 -o 0.5 0 diffuse.png\n\
               norm -bm 0.5 normal.png\nmap_d alpha.png\nmap_Ke glow.png\nmap_Pr rough.png\n\
               map_Pm metal.png\nPm 0.5\nmap_Ks ignored.png\n\
               newmtl bumped\nKd 0.2 0.4 0.6\nmap_Bump -bm 2 height.png\n\
               newmtl shiny\nKd 0.3 0.3 0.3\nKs 0.5 0.5 0.5\nNs 100\nmap_Ks spec.png\n\
               map_Ns shininess.png\n";
    let dir = dir_with(&[
        ("scene.obj", obj.as_bytes()),
        ("scene.mtl", mtl.as_bytes()),
        ("diffuse.png", &png(2, 2, [200, 100, 50, 255])),
        ("normal.png", &png(2, 2, [128, 128, 255, 255])),
        ("alpha.png", &png(2, 2, [64, 64, 64, 255])),
        ("glow.png", &png(1, 1, [255, 0, 0, 255])),
        ("rough.png", &png(1, 1, [30, 30, 30, 255])),
        ("metal.png", &png(1, 1, [90, 90, 90, 255])),
        ("height.png", &png(2, 2, [100, 100, 100, 255])),
        ("spec.png", &png(1, 1, [255, 200, 100, 255])),
        ("shininess.png", &png(1, 1, [255, 255, 255, 255])),
    ]);
    let scene = load_obj(&dir.join("scene.obj"), 0).unwrap();
    let Material::Pbr(mapped) = &scene.objects[0].material else {
        panic!("{:?}", scene.objects[0].material)
    };
    let texture = |i: Option<usize>| &scene.textures[i.unwrap()];
    assert_eq!(mapped.normal_scale, 0.5);
    assert_eq!(
        texture(mapped.normal_texture).name,
        dir.join("normal.png").display().to_string()
    );
    assert_eq!(mapped.alpha_mode, rt_core::material::AlphaMode::Blend);
    assert_eq!(
        &texture(mapped.texture).rgba8[..4],
        &[200, 100, 50, 64],
        "colour with map_d's alpha"
    );
    assert_eq!(
        (mapped.emission, texture(mapped.emission_texture).rgba8[0]),
        ([1.0; 3], 255)
    );
    assert_eq!(
        &texture(mapped.metallic_roughness_texture).rgba8[..],
        &[0, 30, 90, 255]
    );
    assert_eq!(
        (mapped.roughness, mapped.metallic),
        (1.0, 0.5),
        "factors: Pr missing, Pm 0.5"
    );
    assert_eq!(
        (mapped.specular, mapped.base_color),
        (1.0, [0.5; 3]),
        "Pm makes it PBR by the MTL mapping: its specular layer kept, the texture multiplying Kd"
    );
    let uvs = scene.objects[0].mesh.uvs.as_ref().unwrap();
    assert_eq!(
        uvs[1],
        glam::Vec2::new(2.5, 0.0),
        "(1, 0) scaled by 2 and offset by 0.5"
    );

    let Material::Pbr(bumped) = &scene.objects[1].material else {
        panic!("{:?}", scene.objects[1].material)
    };
    let normal = texture(bumped.normal_texture);
    assert!(
        normal.name.contains("normal map from height"),
        "{}",
        normal.name
    );
    assert_eq!(
        &normal.rgba8[..4],
        &[128, 128, 255, 255],
        "a flat height field faces straight out"
    );
    assert_eq!(
        (bumped.base_color, bumped.normal_scale, bumped.specular),
        ([0.2, 0.4, 0.6], 1.0, 0.0)
    );
    // map_Ks and map_Ns: a diffuse material gains a specular layer with its colour image, and a
    // roughness image from shininess (Ns 100 × white: √(√(2/102)) = 0.374, byte 95).
    let Material::Pbr(shiny) = &scene.objects[2].material else {
        panic!("{:?}", scene.objects[2].material)
    };
    assert_eq!((shiny.specular, shiny.specular_color), (1.0, [0.5; 3]));
    assert_eq!(
        &texture(shiny.specular_color_texture).rgba8[..],
        &[255, 200, 100, 255]
    );
    assert_eq!(texture(shiny.metallic_roughness_texture).rgba8[1], 95);
    assert_eq!((shiny.roughness, shiny.base_color), (1.0, [0.3; 3]));
    rt_core::GpuScene::build(&scene).unwrap();
}
