//! `rt-cli`: render scenes headless, describe them, and benchmark the renderer.

mod animation;
mod bench;
mod compare;
mod converge;
mod info;
mod interactive;
mod layers;
mod merge;
mod options;
mod plot;
mod preview;
mod preview_bench;
mod region;
mod render;
mod scene_args;
mod series;
mod shard;
mod summary;

use std::process::ExitCode;

use clap::{Parser, Subcommand};

#[derive(Parser)]
#[command(
    name = "rt-cli",
    version,
    about = "rt: a physically based path tracer (headless)"
)]
struct Cli {
    /// More log output (also: RUST_LOG=info).
    #[arg(short, long, global = true)]
    verbose: bool,
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand)]
enum Command {
    /// Render a scene (the embedded Cornell box when none is given) to an image.
    Render(render::RenderArgs),
    /// The editor's raster preview of a scene, saved as an image (same scene and view flags as
    /// render; milliseconds, an approximation of the render).
    Preview(preview::PreviewArgs),
    /// Merge render parts (`render --shard`) into the frame: exact, and itself a part as .exr.
    Merge(merge::MergeArgs),
    /// Print a scene's objects, materials, triangle count and bounds.
    Info(info::InfoArgs),
    /// Error metrics (relMSE, RMSE, mean ratio) of an image against a reference image.
    Compare(compare::CompareArgs),
    /// Render at 1, 2, 4, ... spp and measure each image against a reference (CSV and SVG plot).
    Converge(converge::ConvergeArgs),
    /// Plot CSV files written by `converge` (relMSE against time or samples, log-log) as SVG.
    Plot(plot::PlotArgs),
    /// Run the fixed benchmark suite and print a table and one JSON record per scene.
    Bench(bench::BenchArgs),
}

fn main() -> ExitCode {
    rt_core::memory_budget::return_large_blocks_to_the_system();
    let cli = match Cli::try_parse() {
        Ok(cli) => cli,
        Err(e) if e.use_stderr() => {
            // One line, like every other error; `--help` explains the rest.
            let text = e.to_string();
            eprintln!(
                "{} (see --help)",
                text.lines()
                    .find(|l| !l.trim().is_empty())
                    .unwrap_or("invalid arguments")
            );
            return ExitCode::from(2);
        }
        Err(e) => {
            let _ = e.print();
            return ExitCode::SUCCESS;
        }
    };
    let level = if cli.verbose { "info" } else { "warn" };
    env_logger::Builder::from_env(env_logger::Env::default().default_filter_or(level))
        .format_timestamp(None)
        .init();
    let result = match cli.command {
        Command::Render(args) => render::run(args, cli.verbose),
        Command::Info(args) => info::run(args, cli.verbose),
        Command::Preview(args) => preview::run(args),
        Command::Merge(args) => merge::run(args),
        Command::Bench(args) => bench::run(args),
        Command::Compare(args) => compare::run(args),
        Command::Converge(args) => converge::run(args),
        Command::Plot(args) => plot::run(args),
    };
    match result {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("error: {e:#}");
            ExitCode::from(2)
        }
    }
}
