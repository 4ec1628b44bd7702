//! `rt-cli`: render scenes headless, describe them, and benchmark the renderer.

mod bench;
mod info;
mod render;
mod scene_args;

use std::process::ExitCode;

use clap::{Parser, Subcommand};

#[derive(Parser)]
#[command(name = "rt-cli", version, about = "rt: a physically based path tracer (headless)")]
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
    /// Print a scene's objects, materials, triangle count and bounds.
    Info(info::InfoArgs),
    /// Run the fixed benchmark suite and print a table and one JSON record per scene.
    Bench(bench::BenchArgs),
}

fn main() -> ExitCode {
    let cli = match Cli::try_parse() {
        Ok(cli) => cli,
        Err(e) => {
            let code = if e.use_stderr() { 2 } else { 0 };
            let _ = e.print();
            return ExitCode::from(code);
        }
    };
    let level = if cli.verbose { "info" } else { "warn" };
    env_logger::Builder::from_env(env_logger::Env::default().default_filter_or(level))
        .format_timestamp(None)
        .init();
    let result = match cli.command {
        Command::Render(args) => render::run(args, cli.verbose),
        Command::Info(args) => info::run(args),
        Command::Bench(args) => bench::run(args),
    };
    match result {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("error: {e:#}");
            ExitCode::from(2)
        }
    }
}
