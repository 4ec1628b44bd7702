//! `rt-cli merge PARTS… -o OUT`: adds the parts' samples (exactly: `rt_core::part::merge`) and
//! saves the frame: as .exr a part again (merges associate), else a tone-mapped image.

use std::path::PathBuf;

use anyhow::{Context, Result};
use clap::Args;
use rt_core::output::{ImageFormat, SampleCounts};

use crate::render::ViewArg;

#[derive(Args, Debug)]
pub struct MergeArgs {
    /// Parts written by `rt-cli render --shard` (or by an earlier merge).
    #[arg(required = true)]
    parts: Vec<PathBuf>,
    /// Output: .exr (itself a part, mergeable again) or .png, .jpg, .ppm (tone-mapped).
    #[arg(short, long)]
    output: PathBuf,
    /// Merge even when the parts do not hold every sample of the frame (the image is then that
    /// of fewer samples, and stays a part that a later merge can complete).
    #[arg(long)]
    allow_partial: bool,
    /// Also write a denoised copy beside the output (NAME.denoised.EXT), guided by the parts'
    /// albedo and normals: after the merge, so the denoiser sees the whole frame's samples.
    #[arg(long)]
    denoise: bool,
    /// Exposure in stops for 8-bit outputs.
    #[arg(long, default_value_t = 0.0, allow_hyphen_values = true)]
    exposure: f32,
    /// View transform for 8-bit outputs (as `render --view`).
    #[arg(long, value_enum, default_value = "standard")]
    view: ViewArg,
}

pub fn run(args: MergeArgs) -> Result<()> {
    let format = ImageFormat::from_path(&args.output)?;
    let mut parts = Vec::with_capacity(args.parts.len());
    for path in &args.parts {
        parts.push((path.clone(), rt_core::part::read_part(path)?));
    }
    let merged = rt_core::part::merge(&parts, args.allow_partial)?;
    let view = args.view.with_exposure(args.exposure);
    let (width, height) = (merged.header.width, merged.header.height);
    if format == ImageFormat::Exr {
        rt_core::part::save_part(&args.output, &merged)
    } else {
        let pixels = merged.pixels();
        rt_core::output::save_render(
            &args.output,
            width,
            height,
            &pixels,
            SampleCounts::PerPixel(&merged.counts),
            view,
        )
    }
    .with_context(|| format!("saving {}", args.output.display()))?;
    let h = &merged.header;
    eprintln!(
        "merged:         {} parts, samples {} of {} ({}), {}x{}",
        parts.len(),
        rt_core::part::format_ranges(&h.sample_ranges),
        h.total_spp,
        if merged.is_complete() {
            "the whole frame"
        } else {
            "partial"
        },
        width,
        height
    );
    if args.denoise {
        let image = rt_gpu::Image {
            width,
            height,
            samples_per_pixel: merged.counts.iter().copied().max().unwrap_or(0),
            sample_counts: Some(merged.counts.clone()),
            pixels: merged.pixels(),
            sums: merged.sums.clone(),
        };
        if merged.guides.albedo.len() != merged.counts.len() {
            anyhow::bail!("the parts carry no albedo and normals to guide the denoiser");
        }
        let aovs = rt_gpu::Aovs {
            albedo: merged.guides.albedo.clone(),
            normal: merged.guides.normal.clone(),
            emission: merged.guides.emission.clone(),
        };
        crate::render::save_denoised_image(&args.output, &image, &aovs, view)?;
    }
    eprintln!("saved:          {}", args.output.display());
    Ok(())
}
