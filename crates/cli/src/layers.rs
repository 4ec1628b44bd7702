//! `render --transparent` and `--aov LIST`: the beauty with its alpha (EXR: premultiplied `A`, as
//! the colour already leaves out the background; PNG: straight alpha, as Blender writes both) and
//! the render passes as named layers of the same EXR (`rt_core::passes`), Cryptomatte's with its
//! header metadata.

use std::path::Path;

use anyhow::{Context, Result};
use rt_core::output::{ImageFormat, SampleCounts, View};
use rt_core::passes::{Pass, PassInputs};
use rt_core::{GpuScene, Scene};

/// `--aov`'s list (one value to clap, which would take a `Vec` for repeated flags).
#[derive(Clone, Debug)]
pub struct PassList(pub Vec<Pass>);

pub fn parse_pass_list(s: &str) -> Result<PassList, String> {
    rt_core::passes::parse_passes(s).map(PassList)
}

/// Checks that the output can hold what was asked for, before anything renders.
pub fn check(output: &Path, transparent: bool, passes: Option<&[Pass]>) -> Result<()> {
    let format = ImageFormat::from_path(output)?;
    if passes.is_some() && format != ImageFormat::Exr {
        anyhow::bail!("--aov writes layers of an EXR: name the output .exr");
    }
    if transparent && !matches!(format, ImageFormat::Exr | ImageFormat::Png) {
        anyhow::bail!("--transparent needs an output with alpha: .png or .exr");
    }
    Ok(())
}

/// Saves the image with its alpha and passes (atomically).
pub fn save(
    output: &Path,
    image: &rt_gpu::Image,
    aovs: &rt_gpu::Aovs,
    scenes: (&Scene, &GpuScene),
    passes: Option<&[Pass]>,
    view: View,
) -> Result<()> {
    let (scene, gpu_scene) = scenes;
    if aovs.hits.is_empty() {
        anyhow::bail!("this render kept no coverage or depth (alpha and passes need them)");
    }
    let format = ImageFormat::from_path(output)?;
    let mut extra = Vec::new();
    let mut metadata = Vec::new();
    if let Some(passes) = passes {
        let frame = rt_core::frame::frame_for(scene, gpu_scene)?;
        let position = rt_core::passes::positions(&frame, &aovs.hits);
        let material_ids = rt_core::passes::material_ids(scene);
        let inputs = PassInputs {
            albedo: &aovs.albedo,
            normal: &aovs.normal,
            hits: &aovs.hits,
            position: &position,
            material_ids: &material_ids,
        };
        extra.extend(rt_core::passes::pass_channels(passes, &inputs));
        let samples = image.samples_per_pixel;
        let (crypto, meta) =
            rt_core::passes::cryptomatte_layers(passes, scene, gpu_scene, samples)?;
        extra.extend(crypto);
        metadata = meta;
    }
    let counts = match &image.sample_counts {
        Some(c) => SampleCounts::PerPixel(c),
        None => SampleCounts::Uniform(image.samples_per_pixel),
    };
    let size = [image.width, image.height];
    let bytes = if scene.settings.transparent {
        let alpha = aovs.hits.alphas();
        rt_core::output::encode_with_alpha(
            format,
            size,
            &image.pixels,
            counts,
            &alpha,
            (&extra, &metadata),
            view,
        )?
    } else {
        let [w, h] = size;
        rt_core::output::encode_exr_layers(w, h, &image.pixels, counts, &extra, &metadata)?
    };
    rt_core::output::write_atomically(output, &bytes)
        .with_context(|| format!("saving {}", output.display()))
}
