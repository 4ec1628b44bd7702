//! The editor's command line and window: `rt [FILE] [--adapter ...] [--smoke-test DIR]`. Both the
//! `rt` binary (crates/app) and `cargo run` at the workspace root (the root package's
//! `rt-editor`) call `main` here.

use std::path::PathBuf;
use std::process::ExitCode;

use clap::Parser;

use crate::interactive_bench::InteractiveBench;
use crate::smoke::{Outcome, SmokeTest};
use crate::{AppOptions, RtApp};

#[derive(Parser, Debug)]
#[command(
    name = "rt",
    version,
    about = "rt: a physically based path tracer and scene editor"
)]
struct Args {
    /// A Wavefront OBJ, an rt project (.rtproj) or lighting file (.rtlight) to open.
    path: Option<PathBuf>,
    /// Which GPU renders: "auto", "lavapipe" (a software GPU; also "cpu") or part of an adapter's
    /// name.
    #[arg(long, default_value = "auto")]
    adapter: String,
    /// What renders the render windows and the path-traced viewport: auto (the default: a
    /// hardware GPU when there is one, else cpu), gpu, or cpu (rt's native CPU backend); the
    /// Render panel's Device changes it.
    #[arg(long, default_value = "auto", value_parser = ["auto", "gpu", "cpu"])]
    device: String,
    /// Render a few samples, save an image, a project and a screenshot into DIR, and quit (a
    /// test of the real window).
    #[arg(long, value_name = "DIR")]
    smoke_test: Option<PathBuf>,
    /// Measure the path-traced viewport while it answers a scripted orbit (change to first image,
    /// UI frame times, samples after 5 s and 30 s), write the report to FILE and quit; the window
    /// is 1920x1000 (under Xvfb: `xvfb-run -s "-screen 0 1920x1080x24"`).
    #[arg(long, value_name = "FILE", conflicts_with = "smoke_test")]
    interactive_bench: Option<PathBuf>,
}

fn has_display() -> bool {
    if !cfg!(target_os = "linux") {
        return true;
    }
    ["DISPLAY", "WAYLAND_DISPLAY"]
        .iter()
        .any(|v| std::env::var_os(v).is_some_and(|d| !d.is_empty()))
}

/// Parses the command line and runs the editor until its window closes.
pub fn main() -> ExitCode {
    rt_core::memory_budget::return_large_blocks_to_the_system();
    env_logger::Builder::from_env(env_logger::Env::default().default_filter_or("warn")).init();
    let args = Args::parse();
    if !has_display() {
        eprintln!(
            "rt: no display (neither DISPLAY nor WAYLAND_DISPLAY is set). On a headless machine \
             render with the command line instead, e.g. `rt-cli render -o cornell.png`."
        );
        return ExitCode::from(2);
    }
    let options = AppOptions {
        config_dir: if args.smoke_test.is_some() || args.interactive_bench.is_some() {
            None
        } else {
            crate::recent::default_config_dir()
        },
        open: args.path.clone(),
        adapter: args.adapter.parse().unwrap_or_default(),
        // The binary reads the environment; the libraries take the value.
        device: rt_gpu::DeviceOptions::from_no_ray_query_var(
            std::env::var_os("RT_NO_RAY_QUERY").as_deref(),
        ),
        render_device: match args.device.as_str() {
            "gpu" => crate::render_job::DeviceChoice::Gpu,
            "cpu" => crate::render_job::DeviceChoice::Cpu,
            _ => crate::render_job::DeviceChoice::Auto,
        },
    };
    let native = eframe::NativeOptions {
        viewport: egui::ViewportBuilder::default()
            .with_title("rt")
            .with_inner_size(if args.interactive_bench.is_some() {
                [1920.0, 1000.0]
            } else {
                [1280.0, 800.0]
            })
            .with_drag_and_drop(true),
        renderer: eframe::Renderer::Wgpu,
        ..Default::default()
    };
    let outcome: Outcome = Default::default();
    let smoke_dir = args.smoke_test.clone();
    let bench_report = args.interactive_bench.clone();
    if let Some(dir) = &smoke_dir
        && let Err(e) = std::fs::create_dir_all(dir)
    {
        eprintln!("rt: {}: {e}", dir.display());
        return ExitCode::from(2);
    }
    let result = {
        let outcome = outcome.clone();
        eframe::run_native(
            "rt",
            native,
            Box::new(move |cc| {
                let app = RtApp::from_creation_context(cc, &options);
                Ok(match (smoke_dir, bench_report) {
                    (Some(dir), _) => Box::new(SmokeTest::new(app, dir, outcome)),
                    (None, Some(report)) => Box::new(InteractiveBench::new(app, report, outcome)),
                    (None, None) => Box::new(app),
                })
            }),
        )
    };
    if let Err(e) = result {
        eprintln!("rt: could not open the window: {e}");
        return ExitCode::FAILURE;
    }
    if args.smoke_test.is_some() || args.interactive_bench.is_some() {
        let passed = outcome
            .lock()
            .ok()
            .and_then(|o| o.clone())
            .is_some_and(|r| r.is_ok());
        if !passed {
            return ExitCode::FAILURE;
        }
    }
    ExitCode::SUCCESS
}
