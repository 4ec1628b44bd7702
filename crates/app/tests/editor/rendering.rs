//! Rendering from the editor: start and cancel, the path-traced viewport, adaptive sampling, a
//! region, passes and shadow catchers.

use super::*;
use egui_kittest::kittest::Queryable;

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

/// The Render panel's Device picks rt's native CPU backend for the render windows: the status bar
/// says so, a render finishes with its samples and the denoiser's guides, and cancel stops one.
/// Needs no GPU.
#[test]
fn renders_on_the_cpu_backend_from_the_render_panel() {
    let mut harness = harness();
    harness.run_ok();
    harness.get_by_label("CPU").click();
    harness.run_ok();
    assert!(harness.state().ui.render_device.on_cpu(false).0);
    harness.get_by_label_contains("renders on CPU (native backend");
    harness.state_mut().doc.edit("small", "small", |s| {
        s.settings.width = 32;
        s.settings.height = 24;
        s.settings.samples_per_pixel = 1_000_000;
    });
    harness.get_by_label("Render image").click();
    harness.step();
    assert!(harness.state().is_rendering());
    step_until(&mut harness, "first samples on the CPU", |app| {
        app.renders[0].job.progress.samples_done > 0
    });
    harness.get_by_label("Cancel render").click();
    step_until(&mut harness, "the cancelled render to stop", |app| {
        !app.is_rendering()
    });
    assert_eq!(harness.state().renders[0].job.state, JobState::Cancelled);
    harness.state_mut().doc.edit("few", "few", |s| {
        s.settings.samples_per_pixel = 4;
    });
    harness.get_by_label("Render image").click();
    step_until(&mut harness, "the CPU render to finish", |app| {
        app.renders.len() == 2 && !app.is_rendering()
    });
    let job = &harness.state().renders[1].job;
    assert_eq!(job.state, JobState::Finished);
    let image = job.image.as_ref().unwrap();
    assert_eq!(image.samples_per_pixel, 4);
    assert!(image.pixels.iter().any(|p| p[0] > 0.0), "a black image");
    assert!(job.aovs.is_some(), "no denoiser guides");
}

/// Where the path-traced view runs on the CPU backend (here, without a hardware GPU: `auto`'s
/// choice), the viewport opens path-traced and shows the path tracer's first image.
#[test]
fn without_a_hardware_gpu_the_viewport_opens_path_traced() {
    if !have_gpu() || rt_gpu::hardware_gpu().is_some() {
        return;
    }
    let mut harness = opening_harness();
    assert!(
        harness.state().live.enabled,
        "the viewport opened on the raster preview"
    );
    step_until(&mut harness, "the path-traced view's first image", |app| {
        app.live
            .view
            .as_ref()
            .is_some_and(|v| v.display().is_some())
    });
}

/// The Render panel's Region renders only that window of the image, its pixels the whole render's
/// there (the same samples, on the CPU backend); the render window's Passes save as EXR layers.
/// Needs no GPU.
#[test]
fn a_render_region_and_passes_from_the_editor() {
    let mut harness = harness();
    harness.run_ok();
    harness.get_by_label("CPU").click();
    harness.state_mut().doc.edit("small", "small", |s| {
        s.settings.width = 32;
        s.settings.height = 24;
        s.settings.samples_per_pixel = 2;
    });
    harness.run_ok();
    harness.state_mut().start_render();
    step_until(&mut harness, "the whole image", |app| !app.is_rendering());
    harness.get_by_label("Region").click();
    harness.run_ok();
    assert_eq!(harness.state().ui.render_region, Some([8, 6, 24, 18]));
    harness.state_mut().ui.render_region = Some([4, 3, 20, 11]);
    harness.state_mut().start_render();
    step_until(&mut harness, "the region", |app| {
        app.renders.len() == 2 && !app.is_rendering()
    });
    let (whole, window) = {
        let renders = &harness.state().renders;
        (
            renders[0].job.image.clone().unwrap(),
            renders[1].job.image.clone().unwrap(),
        )
    };
    assert_eq!((window.width, window.height), (16, 8));
    for y in 0..8 {
        for x in 0..16 {
            assert_eq!(
                window.pixels[(y * 16 + x) as usize],
                whole.pixels[((y + 3) * 32 + x + 4) as usize],
                "pixel ({x}, {y}) of the region"
            );
        }
    }
    assert_eq!(
        harness.state().doc.scene.settings.width,
        32,
        "the scene keeps its size"
    );
    let dir = std::env::temp_dir().join(format!("rt-editor-passes-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let exr = dir.join("passes.exr");
    let view = &mut harness.state_mut().renders[1];
    use rt_core::passes::Pass;
    view.passes = vec![Pass::Depth, Pass::Object, Pass::Cryptomatte];
    rt_app::ui::renders::save(view, &exr).unwrap();
    let layers = exr::prelude::read_all_flat_layers_from_file(&exr).unwrap();
    let names: Vec<String> = layers.layer_data[0]
        .channel_data
        .list
        .iter()
        .map(|c| c.name.to_string())
        .collect();
    for name in [
        "depth.Z",
        "object.ID",
        "CryptoObject00.r",
        "CryptoObject02.a",
    ] {
        assert!(names.iter().any(|n| n == name), "{name} not in {names:?}");
    }
    let manifest = (layers.layer_data[0].attributes.other.iter())
        .find(|(name, _)| name.to_string().ends_with("/manifest"))
        .map(|(_, value)| format!("{value:?}"));
    assert!(
        manifest.is_some_and(|m| m.contains("floor")),
        "Cryptomatte's manifest names the objects"
    );
    std::fs::remove_dir_all(&dir).unwrap();
}

/// The Inspector's Shadow catcher marks the selected object (one undo step), says that it needs
/// a transparent film until the Render panel's Transparent background is on.
#[test]
fn the_inspector_makes_a_shadow_catcher() {
    if !have_gpu() {
        return;
    }
    let mut harness = harness();
    harness.run_ok();
    harness.get_by_label("floor").click();
    harness.run_ok();
    let index = index_of(harness.state(), "floor");
    // Below the material, out of the panel's view: clicked through accessibility.
    harness.get_by_label("Shadow catcher").click_accesskit();
    harness.run_ok();
    assert!(harness.state().doc.scene.objects[index].shadow_catcher);
    harness.get_by_label_contains("Needs \"Transparent background\"");
    harness
        .get_by_label("Transparent background")
        .click_accesskit();
    harness.run_ok();
    assert!(harness.state().doc.scene.settings.transparent);
    assert!(
        harness
            .query_by_label_contains("Needs \"Transparent background\"")
            .is_none()
    );
    harness.key_press_modifiers(egui::Modifiers::COMMAND, egui::Key::Z);
    harness.run_ok();
    assert!(
        !harness.state().doc.scene.settings.transparent,
        "the film undone"
    );
    harness.key_press_modifiers(egui::Modifiers::COMMAND, egui::Key::Z);
    harness.run_ok();
    assert!(
        !harness.state().doc.scene.objects[index].shadow_catcher,
        "the catcher undone"
    );
}
