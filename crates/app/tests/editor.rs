//! The editor driven headless through `egui_kittest`, rendering through wgpu (lavapipe in CI):
//! open, select, edit, undo, add lights, render and cancel, save and reload.

use std::time::{Duration, Instant};

use egui_kittest::Harness;
use egui_kittest::kittest::Queryable;
use rt_app::render_job::JobState;
use rt_app::{AppOptions, RtApp};
use rt_core::Material;

/// Whether a GPU adapter exists, under the suites' one policy (`GpuContext::for_tests`): without
/// one the test fails under CI and is skipped with a message elsewhere.
fn have_gpu() -> bool {
    rt_gpu::GpuContext::for_tests().is_some()
}

fn harness() -> Harness<'static, RtApp> {
    Harness::builder()
        .with_size([1280.0, 800.0])
        .with_max_steps(50)
        .wgpu()
        .build_eframe(|cc| RtApp::from_creation_context(cc, &AppOptions::default()))
}

fn index_of(app: &RtApp, name: &str) -> usize {
    app.doc
        .scene
        .objects
        .iter()
        .position(|o| o.name == name)
        .unwrap_or_else(|| panic!("no object {name}"))
}

/// Steps the UI until `done` holds (render threads report asynchronously).
fn step_until(harness: &mut Harness<'_, RtApp>, what: &str, done: impl Fn(&RtApp) -> bool) {
    let start = Instant::now();
    while !done(harness.state()) {
        assert!(
            start.elapsed() < Duration::from_secs(120),
            "timed out waiting for: {what}"
        );
        harness.step();
        std::thread::sleep(Duration::from_millis(20));
    }
    harness.step();
}

#[test]
fn the_cornell_box_opens_listed_and_previewed() {
    if !have_gpu() {
        return;
    }
    let mut harness = harness();
    harness.run_ok();
    assert!(harness.state().preview_available, "egui runs on wgpu");
    for name in ["floor", "tall_block", "short_block"] {
        harness.get_by_label(name);
    }
    harness.get_by_label("light");

    let image = harness.render().unwrap();
    let dir = std::path::Path::new(env!("CARGO_TARGET_TMPDIR"));
    image.save(dir.join("editor-cornell.png")).unwrap();
    // The viewport (between the side panels) shows the box: the red and green walls are there.
    let (w, h) = image.dimensions();
    let mut red = 0;
    let mut green = 0;
    for y in (h / 5..h * 4 / 5).step_by(4) {
        for x in (w / 4..w * 3 / 4).step_by(4) {
            let [r, g, b, _] = image.get_pixel(x, y).0;
            let (r, g, b) = (i32::from(r), i32::from(g), i32::from(b));
            if r > g + 40 && r > b + 40 {
                red += 1;
            }
            if g > r + 40 && g > b + 40 {
                green += 1;
            }
        }
    }
    assert!(
        red > 50 && green > 50,
        "the preview should show the red and green walls: {red} red, {green} green samples \
         (screenshot in {})",
        dir.display()
    );
}

#[test]
fn select_change_material_undo_and_redo() {
    if !have_gpu() {
        return;
    }
    let mut harness = harness();
    harness.run_ok();
    harness.get_by_label("tall_block").click();
    harness.run_ok();
    let index = index_of(harness.state(), "tall_block");
    assert_eq!(harness.state().selection, Some(index));
    let original = harness.state().doc.scene.objects[index].material.clone();

    harness.get_by_label("Metal").click();
    harness.run_ok();
    assert!(matches!(
        harness.state().doc.scene.objects[index].material,
        Material::Metal { .. }
    ));

    harness.key_press_modifiers(egui::Modifiers::COMMAND, egui::Key::Z);
    harness.run_ok();
    assert_eq!(
        harness.state().doc.scene.objects[index].material,
        original,
        "Ctrl+Z restores the material"
    );
    harness.key_press_modifiers(
        egui::Modifiers::COMMAND | egui::Modifiers::SHIFT,
        egui::Key::Z,
    );
    harness.run_ok();
    assert!(matches!(
        harness.state().doc.scene.objects[index].material,
        Material::Metal { .. }
    ));

    harness.get_by_label("Glass").click();
    harness.run_ok();
    assert!(matches!(
        harness.state().doc.scene.objects[index].material,
        Material::Dielectric { .. }
    ));
}

#[test]
fn add_a_light_then_delete_it_after_confirming() {
    if !have_gpu() {
        return;
    }
    let mut harness = harness();
    harness.run_ok();
    let before = harness.state().doc.scene.objects.len();
    harness.get_by_label("Add quad light").click();
    harness.run_ok();
    let app = harness.state();
    assert_eq!(app.doc.scene.objects.len(), before + 1);
    let added = app.doc.scene.objects.last().unwrap();
    assert!(matches!(added.material, Material::Emissive { .. }));
    assert_eq!(app.selection, Some(before), "the new light is selected");
    let name = added.name.clone();
    harness.get_by_label(&name);

    harness.get_by_label("Delete…").click();
    harness.run_ok();
    harness.get_by_label("Cancel").click();
    harness.run_ok();
    assert_eq!(
        harness.state().doc.scene.objects.len(),
        before + 1,
        "cancel keeps it"
    );

    harness.get_by_label("Delete…").click();
    harness.run_ok();
    harness.get_by_label("Delete").click();
    harness.run_ok();
    assert_eq!(harness.state().doc.scene.objects.len(), before);
    assert!(harness.query_by_label(&name).is_none());

    harness.key_press_modifiers(egui::Modifiers::COMMAND, egui::Key::Z);
    harness.run_ok();
    assert_eq!(
        harness.state().doc.scene.objects.len(),
        before + 1,
        "undo restores it"
    );
}

#[test]
fn start_and_cancel_a_render_then_render_to_the_end() {
    if !have_gpu() {
        return;
    }
    let mut harness = harness();
    harness.run_ok();
    {
        let app = harness.state_mut();
        app.doc.edit("small", "small", |s| {
            s.settings.width = 48;
            s.settings.height = 48;
            s.settings.samples_per_pixel = 1_000_000;
        });
    }
    harness.get_by_label("Render image").click();
    harness.step();
    assert!(harness.state().is_rendering());
    step_until(&mut harness, "first samples", |app| {
        app.renders[0].job.progress.samples_done > 0
    });
    harness.get_by_label("Cancel render").click();
    step_until(&mut harness, "the cancelled render to stop", |app| {
        !app.is_rendering()
    });
    let job = &harness.state().renders[0].job;
    assert_eq!(job.state, JobState::Cancelled);
    let image = job
        .image
        .as_ref()
        .expect("a cancelled render keeps its samples");
    assert!(image.samples_per_pixel > 0 && image.samples_per_pixel < 1_000_000);

    harness.state_mut().doc.edit("few", "few", |s| {
        s.settings.samples_per_pixel = 4;
    });
    harness.get_by_label("Render image").click();
    step_until(&mut harness, "the second render to finish", |app| {
        app.renders.len() == 2 && !app.is_rendering()
    });
    let app = harness.state();
    assert_eq!(app.renders[1].job.state, JobState::Finished);
    assert_eq!(
        app.renders[1].job.image.as_ref().unwrap().samples_per_pixel,
        4
    );
    assert!(app.ui.last_render.is_some());
    assert_eq!(app.renders.len(), 2, "the earlier result stays open");
    harness.get_all_by_label("Save as…").next().unwrap();
    // The finished render kept the denoiser's guides: show the denoised image.
    assert!(harness.state().renders[1].job.aovs.is_some());
    harness.get_all_by_label("denoised").last().unwrap().click();
    harness.run_ok();
    let view = &harness.state().renders[1];
    assert!(view.show_denoised && view.denoised.is_some());
}

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

/// `P` turns the path-traced view on (not while a text field has focus); after a camera move the
/// first image shown is coarse and reuses the GPU scene, and the view reaches full resolution and
/// a denoised image without input; `P` again stops it and drops its threads.
#[test]
fn the_path_traced_viewport_starts_coarse_refines_denoises_and_stops() {
    if !have_gpu() {
        return;
    }
    let mut harness = harness();
    harness.run_ok();
    // A focused text field takes the key: no toggle.
    let floor = index_of(harness.state(), "floor");
    harness.state_mut().select_object(Some(floor));
    harness.run_ok();
    harness
        .get_all_by_role(egui::accesskit::Role::TextInput)
        .find(|n| n.value().as_deref() == Some("floor"))
        .expect("the name field")
        .focus();
    harness.run_ok();
    harness.key_press(egui::Key::P);
    harness.run_ok();
    assert!(
        !harness.state().live.enabled,
        "P typed into a text field does not toggle the view"
    );
    harness.key_press(egui::Key::Escape);
    harness.run_ok();
    harness.key_press(egui::Key::P);
    harness.step();
    assert!(
        harness.state().live.enabled,
        "P turns the path-traced view on"
    );
    let display = |app: &RtApp| app.live.view.as_ref().and_then(|v| v.display()).cloned();
    step_until(&mut harness, "a full-resolution image", |app| {
        display(app).is_some_and(|f| f.pixel_size == 1)
    });
    harness.state_mut().doc.edit("camera", "camera", |s| {
        s.camera.vfov_deg = 30.0;
    });
    harness.step();
    let generation = harness.state().live.view.as_ref().unwrap().generation();
    step_until(&mut harness, "the first image after the move", |app| {
        display(app).is_some()
    });
    let first = display(harness.state()).unwrap();
    assert_eq!(first.generation, generation);
    assert!(
        first.pixel_size > 1,
        "the first image is coarse: {}",
        first.pixel_size
    );
    assert_eq!(
        first.rebuild,
        rt_gpu::live::Rebuild::Nothing,
        "a camera move rebuilds nothing"
    );
    step_until(&mut harness, "a denoised full-resolution image", |app| {
        display(app).is_some_and(|f| f.pixel_size == 1 && f.denoiser.is_some())
    });
    let image = harness.render().unwrap();
    image
        .save(std::path::Path::new(env!("CARGO_TARGET_TMPDIR")).join("editor-path-traced.png"))
        .unwrap();
    harness.key_press(egui::Key::P);
    harness.step();
    let app = harness.state();
    assert!(!app.live.enabled && app.live.view.is_none() && app.live.texture.is_none());
}

#[test]
fn add_edit_and_delete_point_spot_and_sun_lights() {
    if !have_gpu() {
        return;
    }
    let mut harness = harness();
    harness.run_ok();
    for (button, kind) in [
        ("Add point light", rt_core::LightKind::Point),
        ("Add spot light", rt_core::LightKind::Spot),
        ("Add sun", rt_core::LightKind::Directional),
    ] {
        harness.get_by_label(button).click();
        harness.run_ok();
        let app = harness.state();
        let light = app.doc.scene.lights.last().unwrap();
        assert_eq!(light.kind, kind);
        assert_eq!(app.selected_light, Some(app.doc.scene.lights.len() - 1));
        assert_eq!(app.selection, None, "selecting a light deselects objects");
        light.validate().unwrap();
    }
    assert_eq!(harness.state().doc.scene.lights.len(), 3);
    // The inspector edits the selected light (the sun): switch it to a point light.
    harness.get_by_label("Point").click();
    harness.run_ok();
    assert_eq!(
        harness.state().doc.scene.lights[2].kind,
        rt_core::LightKind::Point
    );
    harness.get_by_label("Delete light").click();
    harness.run_ok();
    assert_eq!(harness.state().doc.scene.lights.len(), 2);
    harness.key_press_modifiers(egui::Modifiers::COMMAND, egui::Key::Z);
    harness.run_ok();
    assert_eq!(
        harness.state().doc.scene.lights.len(),
        3,
        "undo brings it back"
    );
    // Lights render: a final render with them finishes.
    harness.state_mut().doc.edit("small", "small", |s| {
        s.settings.width = 16;
        s.settings.height = 16;
        s.settings.samples_per_pixel = 2;
    });
    harness.state_mut().start_render();
    step_until(&mut harness, "the render with delta lights", |app| {
        !app.is_rendering()
    });
    assert_eq!(harness.state().renders[0].job.state, JobState::Finished);
}

/// The Render panel's "Adaptive sampling" turns it on (threshold 0.02), and a render with a
/// threshold every pixel meets at once ends after the minimum samples, finished, not cancelled,
/// with per-pixel counts.
#[test]
fn adaptive_sampling_from_the_render_panel() {
    if !have_gpu() {
        return;
    }
    let mut harness = harness();
    harness.run_ok();
    harness.get_by_label("Adaptive sampling").click();
    harness.run_ok();
    assert_eq!(
        harness.state().doc.scene.settings.adaptive_threshold,
        Some(0.02)
    );
    harness.state_mut().doc.edit("loose", "loose", |s| {
        s.settings.width = 32;
        s.settings.height = 32;
        s.settings.samples_per_pixel = 1_000_000;
        s.settings.adaptive_threshold = Some(1e6);
    });
    harness.get_by_label("Render image").click();
    step_until(&mut harness, "the adaptive render to finish", |app| {
        !app.renders.is_empty() && !app.is_rendering()
    });
    let job = &harness.state().renders[0].job;
    assert_eq!(job.state, JobState::Finished);
    let image = job.image.as_ref().unwrap();
    let min = rt_core::scene::ADAPTIVE_MIN_SAMPLES;
    assert!(image.samples_per_pixel >= min && image.samples_per_pixel < 1_000_000);
    let counts = image.sample_counts.as_ref().expect("per-pixel counts");
    assert!(counts.iter().all(|&c| c == image.samples_per_pixel));
}

#[test]
fn a_physically_based_material_and_the_studio_environment_from_the_panels() {
    if !have_gpu() {
        return;
    }
    let mut harness = harness();
    harness.run_ok();
    harness.get_by_label("tall_block").click();
    harness.run_ok();
    let index = index_of(harness.state(), "tall_block");
    harness.get_by_label("Physically based").click();
    harness.run_ok();
    let Material::Pbr(p) = &harness.state().doc.scene.objects[index].material else {
        panic!("a PBR material expected")
    };
    assert_eq!(p.roughness, 0.5, "the default roughness");
    assert!(harness.state().doc.scene.environment.is_none());
    harness.get_by_label("Studio").click();
    harness.run_ok();
    let env = harness
        .state()
        .doc
        .scene
        .environment
        .as_ref()
        .expect("environment set");
    assert_eq!((env.map.width, env.map.height), (1024, 512));
    harness.get_by_label("None").click();
    harness.run_ok();
    assert!(harness.state().doc.scene.environment.is_none());
    harness.key_press_modifiers(egui::Modifiers::COMMAND, egui::Key::Z);
    harness.run_ok();
    assert!(
        harness.state().doc.scene.environment.is_some(),
        "removing the environment undoes"
    );
    harness.get_by_label("Sun and sky").click();
    harness.run_ok();
    let env = harness.state().doc.scene.environment.as_ref().unwrap();
    assert!(env.source.starts_with("sun and sky"), "{}", env.source);
    assert_eq!(env.strength, rt_core::sky::DAYLIGHT_STRENGTH);
}

#[test]
fn a_bare_model_is_lit_by_the_default_environment() {
    let mut scene = rt_core::Scene::default();
    rt_app::app::light_with_the_default_environment(&mut scene);
    assert!(scene.environment.is_some());
    let mut lit = rt_core::assets::cornell_box().unwrap();
    rt_app::app::light_with_the_default_environment(&mut lit);
    assert!(
        lit.environment.is_none(),
        "a scene with emitters keeps its own light"
    );
}

/// The editor's own defaults, on top of the loader all callers share, apply to models only: an OBJ
/// without light gets the studio and a max depth from its materials, a glTF (whose loader decides
/// its light) only the depth, and a project stays exactly as saved.
#[test]
fn editor_defaults_apply_to_models_not_projects() {
    use rt_app::app::apply_editor_defaults;
    use rt_core::io::SceneFormat;
    let bare = rt_core::Scene::default();
    assert_eq!(bare.settings.max_depth, 8);
    let mut obj = bare.clone();
    apply_editor_defaults(&mut obj, SceneFormat::Obj);
    assert!(obj.environment.is_some());
    assert_eq!(obj.settings.max_depth, 5, "diffuse (here: nothing) needs 5");
    let mut gltf = bare.clone();
    apply_editor_defaults(&mut gltf, SceneFormat::Gltf);
    assert!(gltf.environment.is_none());
    assert_eq!(gltf.settings.max_depth, 5);
    let mut project = bare.clone();
    apply_editor_defaults(&mut project, SceneFormat::Project);
    assert_eq!(project, bare);
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
        },
        counts: vec![4; size],
        sums,
        guides: rt_core::part::Guides {
            albedo: vec![[0.5; 3]; size],
            normal: vec![[0.0, 0.0, 1.0]; size],
            emission: vec![[0.0; 3]; size],
        },
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
