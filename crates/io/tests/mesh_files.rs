//! PLY and STL: a mesh written by the encodings exporters use reads back with the same
//! triangles and attributes; the files Debian's assimp-testmodels ships load (point clouds and
//! files without faces are clear errors); a PLY or STL of a mesh renders the same image as its
//! OBJ; broken files are errors naming the line or element.

#![expect(clippy::unwrap_used, reason = "test helpers fail by panicking")]

#[path = "common/mesh_writers.rs"]
mod mesh_writers;

use std::path::{Path, PathBuf};
use std::sync::atomic::AtomicBool;

use glam::Vec3;
use mesh_writers::{PlyEncoding, obj, ply, stl_ascii, stl_binary, triangle_faces};
use rt_core::cpu_render::CpuAccumulation;
use rt_core::math::sampling::srgb_to_linear;
use rt_core::scene::{Mesh, Scene};
use rt_io::LoadOptions;
use rt_io::ply::read_ply;
use rt_io::stl::read_stl;

/// A sphere with normals and texture coordinates.
fn sphere() -> Mesh {
    let mut mesh = rt_core::shapes::uv_sphere(1.5, 6, 9);
    let uvs = mesh
        .positions
        .iter()
        .map(|p| glam::Vec2::new(p.x.atan2(p.z), p.y / 1.5))
        .collect();
    mesh.uvs = Some(uvs);
    mesh
}

fn vertex_colors(n: usize) -> Vec<[u8; 3]> {
    (0..n)
        .map(|i| [(i * 37 % 256) as u8, (i * 91 % 256) as u8, 200])
        .collect()
}

/// The corners of each triangle, in order: what an image depends on, whatever the vertex order.
fn corner_positions(mesh: &Mesh) -> Vec<[Vec3; 3]> {
    mesh.indices
        .iter()
        .map(|t| t.map(|i| mesh.positions[i as usize]))
        .collect()
}

#[test]
fn ply_round_trips_in_every_encoding() {
    let mesh = sphere();
    assert!(mesh.normals.is_some() && mesh.uvs.is_some());
    let colors = vertex_colors(mesh.positions.len());
    for encoding in [
        PlyEncoding::Ascii,
        PlyEncoding::LittleEndian,
        PlyEncoding::BigEndian,
    ] {
        let bytes = ply(&mesh, Some(&colors), &triangle_faces(&mesh), encoding);
        let read = read_ply(Path::new("sphere.ply"), &bytes).unwrap();
        assert_eq!(read.positions, mesh.positions, "{encoding:?}");
        assert_eq!(read.normals, mesh.normals, "{encoding:?}");
        assert_eq!(read.uvs, mesh.uvs, "{encoding:?}");
        assert_eq!(read.indices, mesh.indices, "{encoding:?}");
        let expected: Vec<Vec3> = colors
            .iter()
            .map(|c| Vec3::from(c.map(|b| srgb_to_linear(f32::from(b) / 255.0))))
            .collect();
        assert_eq!(
            read.colors.unwrap(),
            expected,
            "{encoding:?}: colours are sRGB bytes"
        );
    }
}

#[test]
fn ply_polygons_are_fans_and_attributes_are_optional() {
    let mesh = Mesh {
        positions: vec![
            Vec3::new(0.0, 0.0, 0.0),
            Vec3::new(1.0, 0.0, 0.0),
            Vec3::new(1.0, 1.0, 0.0),
            Vec3::new(0.0, 1.0, 0.0),
            Vec3::new(0.5, 1.5, 0.0),
        ],
        normals: None,
        uvs: None,
        colors: None,
        indices: Vec::new(),
    };
    let faces = vec![vec![0, 1, 2, 4, 3], vec![0, 1, 2, 3], vec![0, 1]];
    let read = read_ply(
        Path::new("fan.ply"),
        &ply(&mesh, None, &faces, PlyEncoding::Ascii),
    )
    .unwrap();
    assert_eq!(
        read.indices,
        vec![[0, 1, 2], [0, 2, 4], [0, 4, 3], [0, 1, 2], [0, 2, 3]],
        "a pentagon and a quad as fans; the two-vertex face skipped"
    );
    assert!(read.normals.is_none() && read.uvs.is_none() && read.colors.is_none());
}

#[test]
fn stl_round_trips_ascii_and_binary() {
    let mesh = sphere();
    let cases = [
        ("ascii, solid and a tab", stl_ascii(&mesh, false)),
        ("ascii, two solids", stl_ascii(&mesh, true)),
        ("binary", stl_binary(&mesh, "rt test")),
        (
            "binary whose header starts with 'solid'",
            stl_binary(&mesh, "solid rt test"),
        ),
    ];
    for (what, bytes) in cases {
        let read = read_stl(Path::new("sphere.stl"), &bytes).unwrap();
        assert_eq!(corner_positions(&read), corner_positions(&mesh), "{what}");
        assert!(read.normals.is_none(), "{what}: STL is shaded flat");
        // Welded: the sphere's poles and seam repeat positions, so at most its vertex count.
        assert!(read.positions.len() <= mesh.positions.len(), "{what}");
    }
}

#[test]
fn a_binary_stl_padded_after_a_solid_header_still_reads() {
    let mesh = sphere();
    let mut bytes = stl_binary(&mesh, "solid exported");
    bytes.extend([0u8; 7]);
    let read = read_stl(Path::new("padded.stl"), &bytes).unwrap();
    assert_eq!(corner_positions(&read), corner_positions(&mesh));
}

fn error(result: rt_core::Result<Mesh>) -> String {
    match result {
        Ok(_) => panic!("read without an error"),
        Err(e) => e.to_string(),
    }
}

#[test]
fn broken_ply_files_are_errors_naming_what_is_wrong() {
    let mesh = sphere();
    let faces = triangle_faces(&mesh);
    let ascii = String::from_utf8(ply(&mesh, None, &faces, PlyEncoding::Ascii)).unwrap();
    let header_lines = ascii.lines().position(|l| l == "end_header").unwrap() + 1;
    // A bad number on the third vertex line.
    let mut lines: Vec<&str> = ascii.lines().collect();
    lines[header_lines + 2] = "0 zero 0 0 1 0 0.5 0.5";
    let path = Path::new("bad.ply");
    let message = error(read_ply(path, lines.join("\n").as_bytes()));
    assert!(
        message.starts_with(&format!("bad.ply:{}: 'vertex' element 2", header_lines + 3)),
        "{message}"
    );

    let last_face = ascii.trim_end().lines().last().unwrap();
    let out_of_range = ascii.replace(last_face, "3 0 999 1");
    let message = error(read_ply(path, out_of_range.as_bytes()));
    assert!(
        message.contains("names vertex 999")
            && message.contains(&format!("{} vertices", mesh.positions.len())),
        "{message}"
    );

    let short = &ascii[..ascii.len() - 40];
    let message = error(read_ply(path, short.as_bytes()));
    assert!(message.contains("'face' element"), "{message}");

    let binary = ply(&mesh, None, &faces, PlyEncoding::LittleEndian);
    let message = error(read_ply(path, &binary[..binary.len() - 10]));
    assert!(
        message.contains("'face' element") && message.contains("ends early"),
        "{message}"
    );

    let points =
        ascii.split("element face").next().unwrap().to_string() + "end_header\n0 0 0 0 0 1 0 0\n";
    let points = points.replace(
        &format!("element vertex {}", mesh.positions.len()),
        "element vertex 1",
    );
    let message = error(read_ply(path, points.as_bytes()));
    assert!(message.contains("point cloud"), "{message}");

    let message = error(read_ply(path, b"solid not a ply\n"));
    assert!(message.contains("not a PLY file"), "{message}");
}

#[test]
fn broken_stl_files_are_errors_naming_what_is_wrong() {
    let mesh = sphere();
    let path = Path::new("bad.stl");
    let ascii = String::from_utf8(stl_ascii(&mesh, false)).unwrap();
    let bad = ascii.replacen("vertex ", "vertex x", 2);
    let message = error(read_stl(path, bad.as_bytes()));
    assert!(message.starts_with("bad.stl:"), "{message}");
    assert!(message.contains("is not a finite number"), "{message}");
    let message = error(read_stl(
        path,
        ascii.replacen("endloop", "end loop", 1).as_bytes(),
    ));
    assert!(message.contains("'end' is not an STL keyword"), "{message}");

    let binary = stl_binary(&mesh, "rt test");
    let message = error(read_stl(path, &binary[..binary.len() - 50]));
    assert!(
        message.contains(&format!("declares {} triangles", mesh.indices.len())),
        "{message}"
    );
    let message = error(read_stl(path, b"12 bytes abc"));
    assert!(message.contains("too short"), "{message}");
}

fn image(scene: &Scene) -> Vec<[f32; 4]> {
    let mut scene = scene.clone();
    scene.settings.width = 24;
    scene.settings.height = 24;
    let gpu = rt_core::GpuScene::build(&scene).unwrap();
    let frame = rt_core::frame::frame_for(&scene, &gpu).unwrap();
    let mut accumulation = CpuAccumulation::new(&frame, 0, None, false);
    assert!(accumulation.add_batch(&gpu, &frame, 4, &AtomicBool::new(false)));
    accumulation.pixels()
}

fn scratch_dir() -> PathBuf {
    let dir = std::env::temp_dir().join(format!("rt-mesh-files-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

#[test]
fn a_ply_or_stl_renders_the_same_image_as_its_obj() {
    let dir = scratch_dir();
    let smooth = sphere();
    let flat = Mesh {
        normals: None,
        uvs: None,
        ..smooth.clone()
    };
    let load = |name: &str, bytes: &[u8]| {
        let path = dir.join(name);
        std::fs::write(&path, bytes).unwrap();
        rt_io::load(&path, &LoadOptions::default()).unwrap()
    };
    let smooth_obj = load("smooth.obj", obj(&smooth).as_bytes());
    let smooth_ply = load(
        "smooth.ply",
        &ply(
            &smooth,
            None,
            &triangle_faces(&smooth),
            PlyEncoding::LittleEndian,
        ),
    );
    let flat_obj = load("flat.obj", obj(&flat).as_bytes());
    let flat_stl = load("flat.stl", &stl_binary(&flat, "flat"));
    std::fs::remove_dir_all(&dir).unwrap();
    assert_eq!(smooth_ply.camera, smooth_obj.camera, "framed alike");
    assert_eq!(
        smooth_ply.objects[0].material,
        smooth_obj.objects[0].material
    );
    assert_eq!(image(&smooth_ply), image(&smooth_obj), "PLY vs OBJ");
    assert_eq!(image(&flat_stl), image(&flat_obj), "STL vs OBJ");
    assert_ne!(
        image(&smooth_obj),
        image(&flat_obj),
        "normals matter in this scene"
    );
}

/// Debian's assimp-testmodels (installed by scripts/test): every PLY and STL file with faces
/// loads and renders (a small image, every pixel finite); the point clouds are errors saying so.
#[test]
fn the_assimp_ply_and_stl_files_load() {
    let root = Path::new("/usr/share/assimp/models");
    if !root.join("PLY").is_dir() {
        assert!(
            std::env::var_os("CI").is_none(),
            "CI: /usr/share/assimp/models is missing (scripts/test installs assimp-testmodels)"
        );
        eprintln!("skipped: install assimp-testmodels for the PLY/STL corpus test");
        return;
    }
    let expected_triangles = [
        ("PLY/Wuson.ply", 3732),
        ("PLY/cube.ply", 12),
        ("PLY/cube_binary.ply", 12),
        ("PLY/cube_uv.ply", 12),
        ("PLY/float-color.ply", 1),
        ("STL/3DSMaxExport.STL", 2000),
        ("STL/Spider_ascii.stl", 1368),
        ("STL/Spider_binary.stl", 1368),
        ("STL/Wuson.stl", 3732),
        ("STL/sphereWithHole.stl", 285),
        ("STL/triangle.stl", 1),
        ("STL/triangle_with_empty_solid.stl", 1),
        ("STL/triangle_with_two_solids.stl", 2),
    ];
    for (file, triangles) in expected_triangles {
        let scene = rt_io::load(&root.join(file), &LoadOptions::default())
            .unwrap_or_else(|e| panic!("{file}: {e}"));
        assert_eq!(scene.triangle_count(), triangles, "{file}");
        let small = image(&scene);
        assert!(
            small.iter().flatten().all(|c| c.is_finite()),
            "{file}: a pixel is not finite"
        );
    }
    let ascii = rt_io::load(&root.join("STL/Spider_ascii.stl"), &LoadOptions::default()).unwrap();
    let binary = rt_io::load(&root.join("STL/Spider_binary.stl"), &LoadOptions::default()).unwrap();
    assert_eq!(
        ascii.objects[0].mesh.positions.len(),
        binary.objects[0].mesh.positions.len()
    );
    let colored = rt_io::load(&root.join("PLY/float-color.ply"), &LoadOptions::default()).unwrap();
    assert!(
        colored.objects[0].mesh.colors.is_some(),
        "float-color.ply has vertex colours"
    );
    for points in ["PLY/points.ply", "PLY/pond.0.ply", "PLY/issue623.ply"] {
        let message = rt_io::load(&root.join(points), &LoadOptions::default())
            .unwrap_err()
            .to_string();
        assert!(
            message.contains(points.trim_start_matches("PLY/")) && message.contains("point cloud"),
            "{message}"
        );
    }
}
