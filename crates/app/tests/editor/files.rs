//! Files: saving and reloading projects, bad files, merged EXRs, files dropped on the window.

use super::*;
use egui_kittest::kittest::Queryable;

#[test]
fn a_project_saved_and_reloaded_is_the_same_scene() {
    if !have_gpu() {
        return;
    }
    let mut harness = harness();
    harness.run_ok();
    harness.get_by_label("short_block").click();
    harness.run_ok();
    harness.get_by_label("Metal").click();
    harness.run_ok();
    harness.get_by_label("Add box light").click();
    harness.run_ok();
    let dir = std::env::temp_dir().join(format!("rt-editor-test-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let path = dir.join("cornell.rtproj");
    let app = harness.state_mut();
    app.doc.edit("camera", "camera", |s| {
        s.camera.vfov_deg = 50.0;
        s.camera.aperture_radius = 3.0;
        s.ambient = [0.1, 0.2, 0.3];
        s.objects[0].transform.rotation_deg = [0.0, 15.0, 0.0];
    });
    assert!(app.save_project_to(&path));
    assert!(!app.doc.is_dirty());
    let saved = app.doc.scene.clone();
    app.new_scene();
    assert!(app.doc.scene.objects.is_empty());
    assert!(app.open_path(&path));
    let loaded = &app.doc.scene;
    assert_eq!(loaded.camera, saved.camera);
    assert_eq!(loaded.ambient, saved.ambient);
    assert_eq!(loaded.settings, saved.settings);
    assert_eq!(loaded.objects.len(), saved.objects.len());
    for (a, b) in loaded.objects.iter().zip(&saved.objects) {
        assert_eq!(a.name, b.name);
        assert_eq!(a.material, b.material, "{}", a.name);
        assert_eq!(a.transform, b.transform, "{}", a.name);
        assert_eq!(a.mesh, b.mesh, "{}", a.name);
    }
    assert_eq!(*loaded, saved);
    assert_eq!(
        app.recent.paths.first(),
        Some(&path.canonicalize().unwrap())
    );
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn a_bad_file_shows_an_error_and_keeps_the_scene() {
    if !have_gpu() {
        return;
    }
    let mut harness = harness();
    harness.run_ok();
    let dir = std::env::temp_dir().join(format!("rt-editor-bad-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let bad = dir.join("bad.obj");
    std::fs::write(&bad, "v 1 2\nf 1 2 3\n").unwrap();
    let before = harness.state().doc.scene.clone();
    assert!(!harness.state_mut().open_path(&bad));
    harness.run_ok();
    let error = harness.state().ui.error.clone().expect("an error is shown");
    assert!(error.contains("bad.obj:1"), "names file and line: {error}");
    assert_eq!(harness.state().doc.scene, before, "the scene is kept");
    harness.get_by_label("OK").click();
    harness.run_ok();
    assert!(harness.state().ui.error.is_none());
    std::fs::remove_dir_all(&dir).unwrap();
}

/// A merged frame from the cluster (`rt-cli merge -o frame.exr`) opens in a viewer window with its
/// samples and guides, so it can be denoised, tone-mapped and saved there; a plain EXR opens as
/// colour.
#[test]
fn a_merged_exr_opens_in_the_viewer() {
    if !have_gpu() {
        return;
    }
    let mut harness = harness();
    harness.run_ok();
    let dir = std::env::temp_dir().join(format!("rt-editor-exr-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let (width, height) = (6u32, 4u32);
    let size = (width * height) as usize;
    let mut sums = vec![rt_core::accumulation::PixelSums::default(); size];
    for (i, s) in sums.iter_mut().enumerate() {
        for _ in 0..4 {
            rt_core::accumulation::add_sample(s, [i as f32 / 24.0, 0.25, 0.5]);
        }
    }
    let part = rt_core::part::Part {
        header: rt_core::part::PartHeader {
            format_version: rt_core::part::PART_FORMAT_VERSION,
            rt_version: "test".into(),
            scene_hash: "s".into(),
            assets_hash: "a".into(),
            settings_hash: "x".into(),
            width,
            height,
            total_spp: 4,
            sample_ranges: vec![[0, 4]],
            notes: vec![],
            layers: Default::default(),
        },
        counts: vec![4; size],
        sums,
        guides: rt_core::part::Guides {
            albedo: vec![[0.5; 3]; size],
            normal: vec![[0.0, 0.0, 1.0]; size],
            emission: vec![[0.0; 3]; size],
        },
        hits: Default::default(),
        position: Vec::new(),
    };
    let merged = dir.join("frame.exr");
    rt_core::part::save_part(&merged, &part).unwrap();
    let plain = dir.join("plain.exr");
    rt_core::output::save_image(&plain, width, height, &vec![[0.25; 3]; size], 0.0).unwrap();
    let scene_before = harness.state().doc.scene.clone();
    assert!(harness.state_mut().open_path(&merged));
    assert!(harness.state_mut().open_path(&plain));
    harness.run_ok();
    let app = harness.state();
    assert_eq!(
        app.doc.scene, scene_before,
        "opening an image keeps the scene"
    );
    assert_eq!(app.renders.len(), 2);
    let image = app.renders[0].job.image.as_ref().unwrap();
    assert_eq!(
        (image.width, image.height, image.samples_per_pixel),
        (6, 4, 4)
    );
    assert_eq!(image.pixels, part.pixels());
    assert!(app.renders[0].job.aovs.is_some(), "the guides came along");
    assert_eq!(JobState::Finished, app.renders[0].job.state);
    let colour = app.renders[1].job.image.as_ref().unwrap();
    assert_eq!(colour.pixels[0][1], 0.25);
    assert!(app.renders[1].job.aovs.is_none());
    harness.get_by_label_contains("Render 1").hover();
    std::fs::remove_dir_all(&dir).unwrap();
}

/// A file dropped on the window, as the windowing layer hands it over (a path).
#[derive(Debug)]
struct DroppedPath(std::path::PathBuf);

impl egui::DroppedFile for DroppedPath {
    fn path(&self) -> &std::path::Path {
        &self.0
    }

    fn bytes(&self) -> Result<Vec<u8>, String> {
        std::fs::read(&self.0).map_err(|e| e.to_string())
    }
}

/// Dropping a .glb on the window opens it (its objects and textures replace the scene) and puts
/// it first among the recent files; dropping a broken file shows an error and keeps the scene.
#[test]
fn a_gltf_dropped_on_the_window_opens() {
    if !have_gpu() {
        return;
    }
    let mut harness = harness();
    harness.run_ok();
    let glb = std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../cli/tests/data/BoxTextured.glb")
        .canonicalize()
        .unwrap();
    harness
        .input_mut()
        .dropped_files
        .push(std::sync::Arc::new(DroppedPath(glb.clone())));
    harness.run_ok();
    let app = harness.state();
    assert!(app.ui.error.is_none(), "{:?}", app.ui.error);
    let scene = &app.doc.scene;
    assert!(
        !scene.objects.is_empty() && scene.objects.iter().all(|o| o.name != "tall_block"),
        "the box replaced the Cornell box: {:?}",
        scene.objects.iter().map(|o| &o.name).collect::<Vec<_>>()
    );
    assert_eq!(scene.textures.len(), 1, "its base colour image");
    assert_eq!(app.recent.paths.first(), Some(&glb));

    let dir = std::env::temp_dir().join(format!("rt-editor-drop-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let broken = dir.join("broken.glb");
    std::fs::write(&broken, b"glTF\x02\0\0\0junk").unwrap();
    let before = harness.state().doc.scene.clone();
    harness
        .input_mut()
        .dropped_files
        .push(std::sync::Arc::new(DroppedPath(broken)));
    harness.run_ok();
    let error = harness.state().ui.error.clone().expect("an error is shown");
    assert!(error.contains("broken.glb"), "names the file: {error}");
    assert_eq!(harness.state().doc.scene, before, "the scene is kept");
    std::fs::remove_dir_all(&dir).unwrap();
}

/// A PLY or an STL opens as an OBJ does: one object named after the file, the camera framing it,
/// the studio environment lighting it.
#[test]
fn ply_and_stl_files_open_as_models() {
    if !have_gpu() {
        return;
    }
    let mut harness = harness();
    harness.run_ok();
    let dir = std::env::temp_dir().join(format!("rt-editor-ply-stl-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let corners = ["0 0 0", "1 0 0", "0 1 0", "0 0 1"];
    let faces = [[0, 2, 1], [0, 1, 3], [0, 3, 2], [1, 2, 3]];
    let mut stl = String::from("solid tetra\n");
    for f in faces {
        stl += "facet normal 0 0 0\nouter loop\n";
        for v in f {
            stl += &format!("vertex {}\n", corners[v]);
        }
        stl += "endloop\nendfacet\n";
    }
    stl += "endsolid tetra\n";
    let mut ply = String::from(
        "ply\nformat ascii 1.0\nelement vertex 4\nproperty float x\nproperty float y\n\
         property float z\nelement face 4\nproperty list uchar int vertex_indices\nend_header\n",
    );
    ply += &corners.join("\n");
    for f in faces {
        ply += &format!("\n3 {} {} {}", f[0], f[1], f[2]);
    }
    std::fs::write(dir.join("tetra.stl"), stl).unwrap();
    std::fs::write(dir.join("tetra.ply"), ply + "\n").unwrap();
    for name in ["tetra.stl", "tetra.ply"] {
        assert!(harness.state_mut().open_path(&dir.join(name)), "{name}");
        harness.run_ok();
        let scene = &harness.state().doc.scene;
        assert_eq!(scene.objects.len(), 1, "{name}");
        assert_eq!(scene.objects[0].name, "tetra", "{name}");
        assert_eq!(scene.triangle_count(), 4, "{name}");
        assert!(
            scene.environment.is_some(),
            "{name}: lit by the studio environment"
        );
        assert_ne!(
            scene.camera,
            rt_core::camera::Camera::default(),
            "{name}: framed"
        );
    }
    std::fs::remove_dir_all(&dir).unwrap();
}

/// A flat-shaded mesh gets "Shade smooth" in the Inspector: normals from its faces, undone by
/// undo.
#[test]
fn shade_smooth_gives_a_flat_mesh_normals_and_undo_takes_them_back() {
    if !have_gpu() {
        return;
    }
    let mut harness = harness();
    harness.run_ok();
    let dir = std::env::temp_dir().join(format!("rt-editor-smooth-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let path = dir.join("quad.obj");
    std::fs::write(&path, "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nf 1 2 3 4\n").unwrap();
    assert!(harness.state_mut().open_path(&path));
    harness.state_mut().selection = Some(0);
    harness.run_ok();
    assert!(harness.state().doc.scene.objects[0].mesh.normals.is_none());
    harness.get_by_label("Shade smooth").click();
    harness.run_ok();
    let normals = harness.state().doc.scene.objects[0].mesh.normals.clone();
    assert_eq!(
        normals,
        Some(vec![glam::Vec3::Z; 4]),
        "a flat quad's normals are its face's"
    );
    assert!(harness.state_mut().doc.undo());
    harness.run_ok();
    assert!(harness.state().doc.scene.objects[0].mesh.normals.is_none());
    std::fs::remove_dir_all(&dir).unwrap();
}
