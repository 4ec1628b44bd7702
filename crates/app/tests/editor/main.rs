//! The editor driven headless through `egui_kittest`, rendering through wgpu (lavapipe in CI):
//! open, select, edit, undo, add lights, render and cancel, save and reload.
//!
//! `scene_editing.rs` holds opening and editing, `rendering.rs` renders and the viewport,
//! `files.rs` saving, loading and dropped files.

mod files;
mod preview;
mod rendering;
mod scene_editing;

use std::time::{Duration, Instant};

use egui_kittest::Harness;
use rt_app::render_job::JobState;
use rt_app::{AppOptions, RtApp};

/// Whether a GPU adapter exists, under the suites' one policy (`GpuContext::for_tests`): without
/// one the test fails under CI and is skipped with a message elsewhere.
fn have_gpu() -> bool {
    rt_gpu::GpuContext::for_tests().is_some()
}

/// The editor as it opens, but on the raster preview (where the viewport opens path-traced, as it
/// does without a hardware GPU, the tests that look at the preview or press P start from the same
/// view; `opening_harness` is the editor as a user opens it).
fn harness() -> Harness<'static, RtApp> {
    let mut harness = opening_harness();
    harness.state_mut().live.enabled = false;
    harness
}

fn opening_harness() -> Harness<'static, RtApp> {
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
