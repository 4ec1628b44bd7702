//! `rt-cli render --shard i/n` (or `--sample-range A..B`): one machine's range of a frame's
//! samples, saved as a part (`rt_core::part`) for `rt-cli merge`.

use std::path::Path;

use anyhow::{Context, Result};
use clap::Args;
use rt_core::part::{Guides, Layers, PART_FORMAT_VERSION, Part, PartHeader};

#[derive(Args, Debug, Clone, Default)]
pub struct ShardArgs {
    /// Render shard INDEX of COUNT (from 0): samples [⌊N·i/n⌋, ⌊N·(i+1)/n⌋) of the --spp N
    /// sample frame, saved as an EXR part for `rt-cli merge`.
    #[arg(long, value_name = "INDEX/COUNT", value_parser = rt_core::part::parse_shard,
          conflicts_with = "sample_range")]
    pub shard: Option<(u32, u32)>,
    /// Render samples FIRST..END (end excluded) of the --spp sample frame, saved as an EXR part.
    #[arg(long, value_name = "FIRST..END", value_parser = rt_core::part::parse_sample_range)]
    pub sample_range: Option<[u32; 2]>,
}

impl ShardArgs {
    /// The samples to render of a `total`-sample frame, when this is a shard.
    pub fn range(&self, total: u32) -> Result<Option<[u32; 2]>> {
        let range = match (self.shard, self.sample_range) {
            (Some((i, n)), _) => rt_core::part::shard_range(total, i, n),
            (None, Some(r)) => r,
            (None, None) => return Ok(None),
        };
        if range[1] > total {
            anyhow::bail!(
                "--sample-range {}..{} reaches past the frame's {total} samples (--spp is the \
                 whole frame's count)",
                range[0],
                range[1]
            );
        }
        Ok(Some(range))
    }
}

/// The checks a shard's other options must pass: parts are EXR, have a fixed range, and are
/// denoised only once merged.
pub fn check_options(output: &Path, open_ended: bool, denoise: bool) -> Result<()> {
    if rt_core::output::ImageFormat::from_path(output)? != rt_core::output::ImageFormat::Exr {
        anyhow::bail!(
            "{}: a shard is saved as an EXR part (its exact sums are what `rt-cli merge` adds); \
             name it .exr",
            output.display()
        );
    }
    if open_ended {
        anyhow::bail!(
            "a shard renders a fixed range of samples: --time-limit and --noise-target do not apply"
        );
    }
    if denoise {
        anyhow::bail!("denoise the whole frame after the merge: `rt-cli merge --denoise`");
    }
    Ok(())
}

/// Everything a part's header says of the render but its samples.
struct PartIdentity {
    scene_hash: String,
    assets_hash: String,
    settings_hash: String,
    total_spp: u32,
}

impl PartIdentity {
    fn of(scene: &rt_core::Scene, gpu_scene: &rt_core::GpuScene) -> Self {
        let (scene_hash, assets_hash, settings_hash) =
            rt_core::part::scene_hashes(scene, gpu_scene);
        PartIdentity {
            scene_hash,
            assets_hash,
            settings_hash,
            total_spp: scene.settings.samples_per_pixel,
        }
    }
}

/// The part of samples `range` read back from a render, with the first hits `layers` needs.
fn part_from(
    identity: PartIdentity,
    range: [u32; 2],
    (image, aovs): (&rt_gpu::Image, Option<&rt_gpu::Aovs>),
    layers: Layers,
    note: String,
) -> Part {
    let counts = match &image.sample_counts {
        Some(counts) => counts.clone(),
        None => vec![image.samples_per_pixel; image.pixels.len()],
    };
    let guides = aovs
        .map(|a| Guides {
            albedo: a.albedo.clone(),
            normal: a.normal.clone(),
            emission: a.emission.clone(),
        })
        .unwrap_or_default();
    Part {
        header: PartHeader {
            format_version: PART_FORMAT_VERSION,
            rt_version: env!("CARGO_PKG_VERSION").to_string(),
            scene_hash: identity.scene_hash,
            assets_hash: identity.assets_hash,
            settings_hash: identity.settings_hash,
            width: image.width,
            height: image.height,
            total_spp: identity.total_spp,
            sample_ranges: vec![range],
            notes: vec![note],
            layers,
        },
        counts,
        sums: image.sums.clone(),
        guides,
        hits: Default::default(),
        position: Vec::new(),
    }
}

/// Saves samples `range` read back from a render of `scene` as a part at `path` (atomically),
/// with the first hits (and positions) that `layers`' alpha and passes need; `note` says where
/// they were rendered.
pub fn save(
    path: &Path,
    range: [u32; 2],
    (scene, gpu_scene): (&rt_core::Scene, &rt_core::GpuScene),
    rendered: (&rt_gpu::Image, Option<&rt_gpu::Aovs>),
    layers: Layers,
    note: String,
) -> Result<()> {
    let identity = PartIdentity::of(scene, gpu_scene);
    let keep_hits = !layers.is_empty();
    let position = layers.passes.iter().any(|p| p == "position");
    let mut part = part_from(identity, range, rendered, layers, note);
    if keep_hits {
        let aovs = rendered
            .1
            .context("the render kept no first hits for alpha or passes")?;
        part.hits = aovs.hits.clone();
        if position {
            let frame = rt_core::frame::frame_for(scene, gpu_scene)?;
            part.position = rt_core::passes::positions(&frame, &part.hits);
        }
    }
    rt_core::part::save_part(path, &part).with_context(|| format!("saving {}", path.display()))
}
