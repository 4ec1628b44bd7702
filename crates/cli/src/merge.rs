//! `rt-cli merge PARTS… -o OUT`: adds the parts' samples (exactly: `rt_core::part::merge`) and
//! saves the frame: as .exr a part again (merges associate), else a tone-mapped image; with the
//! alpha and passes the render asked for (`--transparent`, `--aov`), from the parts' first hits.

use std::path::PathBuf;

use anyhow::{Context, Result};
use clap::Args;
use rt_core::output::{ImageFormat, SampleCounts};

use crate::render::ViewArgs;

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
    /// albedo and normals: after the merge, so the denoiser sees the whole frame's samples
    /// (`--denoise[=auto|oidn|atrous]`, as `render --denoise`).
    #[arg(long, value_enum, num_args = 0..=1, require_equals = true, default_missing_value = "auto", value_name = "DENOISER")]
    denoise: Option<crate::options::DenoiseArg>,
    /// Exposure, view transform and white balance for 8-bit outputs, as `render`'s.
    #[command(flatten)]
    display: ViewArgs,
}

pub fn run(args: MergeArgs) -> Result<()> {
    let format = ImageFormat::from_path(&args.output)?;
    // One part in memory at a time besides the total.
    let (first, rest) = args.parts.split_first().context("no parts to merge")?;
    let mut merger = rt_core::part::Merger::new(first, rt_core::part::read_part(first)?);
    for path in rest {
        merger.add(path, &rt_core::part::read_part(path)?)?;
    }
    let merged = merger.finish(args.allow_partial)?;
    let view = args.display.view();
    let (width, height) = (merged.header.width, merged.header.height);
    let saved = if !merged.header.layers.is_empty() {
        save_with_layers(&args.output, &merged, view)
    } else if format == ImageFormat::Exr {
        rt_core::part::save_part(&args.output, &merged).map_err(Into::into)
    } else {
        let pixels = merged.pixels();
        let counts = SampleCounts::PerPixel(&merged.counts);
        rt_core::output::save_render(&args.output, width, height, &pixels, counts, view)
            .map_err(Into::into)
    };
    saved.with_context(|| format!("saving {}", args.output.display()))?;
    let h = &merged.header;
    eprintln!(
        "merged:         {} parts, samples {} of {} ({}), {}x{}",
        args.parts.len(),
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
    if let Some(denoiser) = args.denoise {
        let (image, aovs) = rt_gpu::Image::from_part(&merged);
        let aovs = aovs.context("the parts carry no albedo and normals to guide the denoiser")?;
        crate::render::save_denoised_image(&args.output, &image, &aovs, view, denoiser)?;
    }
    eprintln!("saved:          {}", args.output.display());
    Ok(())
}

/// The merged frame with the alpha and passes its render asked for (the parts' `layers`): an EXR
/// part with `A` and the pass layers beside (as `render` writes them), or a PNG with alpha.
fn save_with_layers(
    output: &std::path::Path,
    merged: &rt_core::part::Part,
    view: rt_core::output::View,
) -> Result<()> {
    let layers = &merged.header.layers;
    let passes = match layers.passes.is_empty() {
        true => None,
        false => Some(
            rt_core::passes::parse_passes(&layers.passes.join(","))
                .map_err(|e| anyhow::anyhow!("the parts' passes: {e}"))?,
        ),
    };
    crate::layers::check(output, layers.transparent, passes.as_deref())?;
    let hits = &merged.hits;
    if hits.is_empty() {
        anyhow::bail!("the parts ask for alpha or passes but carry no first hits");
    }
    let alpha = hits.alphas();
    let mut extra = Vec::new();
    if layers.transparent {
        extra.push(("A".to_string(), alpha.clone()));
    }
    if let Some(passes) = &passes {
        if merged.guides.albedo.len() != merged.counts.len() {
            anyhow::bail!("the parts carry no albedo and normals for the passes");
        }
        let inputs = rt_core::passes::PassInputs {
            albedo: &merged.guides.albedo,
            normal: &merged.guides.normal,
            hits,
            position: &merged.position,
            material_ids: &layers.material_ids,
        };
        extra.extend(rt_core::passes::pass_channels(passes, &inputs));
    }
    let bytes = if ImageFormat::from_path(output)? == ImageFormat::Exr {
        rt_core::part::encode_part_with(merged, &extra)?
    } else {
        let size = [merged.header.width, merged.header.height];
        let counts = SampleCounts::PerPixel(&merged.counts);
        let pixels = merged.pixels();
        rt_core::output::encode_with_alpha(
            ImageFormat::Png,
            size,
            &pixels,
            counts,
            &alpha,
            (&[], &[]),
            view,
        )?
    };
    rt_core::output::write_atomically(output, &bytes)?;
    Ok(())
}
