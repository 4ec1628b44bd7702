//! The rt editor: open, preview, edit, light, render and save scenes. The binary (`rt`) is a thin
//! shell around [`launch::main`] and [`app::RtApp`], which tests drive headless through `egui_kittest`.

pub mod app;
pub mod document;
pub mod gallery;
pub mod launch;
pub mod navigation;
pub mod presets;
pub mod preview;
pub mod recent;
pub mod render_job;
pub mod ui;

// The `rt` binary's `--smoke-test` and `--interactive-bench` sessions, driven from `launch`: not
// part of the library's API.
mod interactive_bench;
mod smoke;

pub use app::{AppOptions, RtApp};
