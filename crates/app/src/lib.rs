//! The rt editor: open, preview, edit, light, render and save scenes. The binary (`rt`) is a thin
//! shell around [`launch::main`] and [`app::RtApp`], which tests drive headless through `egui_kittest`.

pub mod app;
pub mod document;
pub mod interactive_bench;
pub mod launch;
pub mod navigation;
pub mod presets;
pub mod preview;
pub mod recent;
pub mod render_job;
pub mod smoke;
pub mod ui;

pub use app::{AppOptions, RtApp};
