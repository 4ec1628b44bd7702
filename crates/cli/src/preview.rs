//! `rt-cli preview`: the editor's raster preview of a scene, headless, saved as an image: the same
//! scene, camera and view flags as `render`, in milliseconds rather than minutes. A quick look at
//! a camera or a light before a render, or in a script.

use std::path::PathBuf;

use anyhow::{Context, Result};
use clap::Args;

use crate::options::open_device;
use crate::render::ViewArgs;
use crate::scene_args::SceneArgs;

#[derive(Args, Debug)]
pub struct PreviewArgs {
    #[command(flatten)]
    scene: SceneArgs,
    /// Output image: .png, .jpg, .ppm (sRGB through --view) or .exr (linear float).
    #[arg(short, long, default_value = "preview.png")]
    output: PathBuf,
    #[arg(long)]
    width: Option<u32>,
    #[arg(long)]
    height: Option<u32>,
    /// Exposure, view transform and white balance for 8-bit outputs, as `render`'s.
    #[command(flatten)]
    display: ViewArgs,
    /// Ray segments per path, as `render`'s: at most 2 leaves the bounce light out (light straight
    /// from the lights and the environment, as a render of that depth).
    #[arg(long)]
    max_depth: Option<u32>,
    /// Draw the editor's floor grid too (left out by default: it is a viewport aid, not part of
    /// the scene).
    #[arg(long)]
    grid: bool,
    /// GPU adapter: auto, lavapipe (also `cpu`), or part of an adapter's name.
    #[arg(long, default_value = "auto")]
    adapter: rt_gpu::AdapterChoice,
}

pub fn run(args: PreviewArgs) -> Result<()> {
    rt_core::output::ImageFormat::from_path(&args.output)?;
    let mut scene = args.scene.load()?;
    if let Some(width) = args.width {
        scene.settings.width = width;
    }
    if let Some(height) = args.height {
        scene.settings.height = height;
    }
    if let Some(depth) = args.max_depth {
        scene.settings.max_depth = depth;
    }
    let (width, height) = (scene.settings.width, scene.settings.height);
    anyhow::ensure!(
        (1..=16384).contains(&width) && (1..=16384).contains(&height),
        "--width and --height must be from 1 to 16384 (got {width}x{height})"
    );
    let ctx = open_device(&args.adapter)?;
    let limit = ctx.device.limits().max_texture_dimension_2d;
    anyhow::ensure!(
        width <= limit && height <= limit,
        "{width}x{height} is larger than this adapter's textures ({limit} a side)"
    );
    let started = std::time::Instant::now();
    let mut frame =
        rt_preview::build_frame(&scene, &scene.camera, scene.bounds(), None, [width, height]);
    if !args.grid {
        frame.grid.clear();
    }
    let pixels = rt_preview::render_image(&ctx, &frame)?;
    let elapsed = started.elapsed();
    let view = args.display.view();
    rt_core::output::save_image(&args.output, width, height, &pixels, view)
        .with_context(|| format!("saving {}", args.output.display()))?;
    eprintln!("device:         {}", ctx.adapter_label());
    eprintln!(
        "preview:        {width}x{height} in {:.0} ms (first frame, with shadow maps and the \
         environment's prefiltering)",
        elapsed.as_secs_f64() * 1e3
    );
    eprintln!("saved:          {}", args.output.display());
    Ok(())
}
