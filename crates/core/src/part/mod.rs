//! Render parts: a range of a frame's samples rendered on one machine (`rt-cli render --shard`),
//! saved as an EXR that `rt-cli merge` combines exactly with the others.
//!
//! A part is an ordinary linear EXR (R, G, B, `variance.Y`, readable by any viewer) with, besides,
//! each pixel's sample count (`samples.Y`), its exact fixed-point sums of radiance and squared
//! luminance (`rt.sum.*`, four u32 words per channel: `accumulation`), the denoiser's guides
//! (`albedo.*`, `normal.*`, `emission.*`, sample-weighted means), where alpha or passes were
//! asked for the camera rays' first hits (`rt.hits.*`: coverage, depth, object ids, shadow
//! catchers, positions) and, in the header attribute `rt.part`, a JSON `PartHeader`. Merging adds counts and sums, which is exact and associative,
//! so n merged shards are bit for bit the one-machine render of the same seed; the variance of a
//! merged pixel follows from its sums as it would for one render (the sufficient statistics merge
//! exactly, where float means and second moments would need Chan et al.'s pairwise update and
//! still round).
//!
//! This module holds the header and the part in memory, shard ranges and the hashes;
//! `codec` reads and writes a part's EXR and `merger` adds parts together.

mod codec;
mod merger;

use serde::{Deserialize, Serialize};
use sha2::{Digest, Sha256};

use crate::accumulation::{self, PixelSums};
use crate::gpu_scene::GpuScene;
use crate::scene::Scene;

pub use codec::{decode_part, encode_part, encode_part_with, read_part, save_part};
pub use merger::{Merger, format_ranges, merge};

/// The part format's version: parts of other versions are refused.
pub const PART_FORMAT_VERSION: u32 = 1;

/// The EXR header attribute holding the JSON `PartHeader`.
pub const HEADER_ATTRIBUTE: &str = "rt.part";

/// What a part says of itself; `merge` checks that every field but `sample_ranges` and `notes`
/// agrees across the parts.
#[derive(Clone, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub struct PartHeader {
    pub format_version: u32,
    /// The rt that rendered it (another version may compute other samples).
    pub rt_version: String,
    /// SHA-256 of the scene as rendered: geometry, normals, UVs, materials, lights (not file names:
    /// a copy of the scene at another path matches).
    pub scene_hash: String,
    /// SHA-256 of every asset's decoded bytes: each texture's texels and the environment map's.
    pub assets_hash: String,
    /// SHA-256 of the settings that decide the samples: size, path depth, estimator, sampler, seed,
    /// camera, ambient.
    pub settings_hash: String,
    pub width: u32,
    pub height: u32,
    /// The whole frame's samples per pixel (`--spp` is always the total).
    pub total_spp: u32,
    /// The sample indices this part holds: sorted, disjoint, half-open `[begin, end)` ranges.
    pub sample_ranges: Vec<[u32; 2]>,
    /// Where each range was rendered (adapter and kernel): information, not checked.
    #[serde(default)]
    pub notes: Vec<String>,
    /// What the render writes beside its colour (checked: every part must agree).
    #[serde(default, skip_serializing_if = "Layers::is_empty")]
    pub layers: Layers,
}

/// What a render writes beside its colour, for a merge to write too: alpha (a transparent film)
/// and the passes (`--aov`, by name), with each object's material id for the material pass
/// (`passes::material_ids`: a merge has no scene).
#[derive(Clone, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
pub struct Layers {
    #[serde(default)]
    pub transparent: bool,
    #[serde(default)]
    pub passes: Vec<String>,
    #[serde(default)]
    pub material_ids: Vec<u32>,
}

impl Layers {
    pub fn is_empty(&self) -> bool {
        !self.transparent && self.passes.is_empty()
    }
}

/// A part in memory.
#[derive(Clone, Debug, PartialEq)]
pub struct Part {
    pub header: PartHeader,
    /// Each pixel's sample count (fewer than its ranges' length where adaptive sampling stopped it).
    pub counts: Vec<u32>,
    pub sums: Vec<PixelSums>,
    /// Sample-weighted mean albedo, normal and directly seen light, for denoising after a merge.
    pub guides: Guides,
    /// Coverage, depth and what shadow catchers caught (sample-weighted means) and the object of
    /// the part's first sample, where `header.layers` asks for alpha or passes; else empty.
    pub hits: crate::first_hits::FirstHits,
    /// Each pixel's position pass (`passes::positions`) where the passes include it; else empty.
    pub position: Vec<[f32; 3]>,
}

/// The denoiser's guides, per pixel.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Guides {
    pub albedo: Vec<[f32; 3]>,
    pub normal: Vec<[f32; 3]>,
    pub emission: Vec<[f32; 3]>,
}

/// Samples `[begin, end)` of shard `index` of `count` of an `spp`-sample frame:
/// `[⌊spp·i/n⌋, ⌊spp·(i+1)/n⌋)`.
pub fn shard_range(spp: u32, index: u32, count: u32) -> [u32; 2] {
    let at = |i: u32| (u64::from(spp) * u64::from(i) / u64::from(count)) as u32;
    [at(index), at(index + 1)]
}

/// Two whole numbers around `separator`, as `--shard` and `--sample-range` take them.
fn parse_pair(s: &str, separator: &str, expected: &str) -> std::result::Result<(u32, u32), String> {
    let (a, b) = s
        .split_once(separator)
        .ok_or_else(|| format!("expected {expected}, got '{s}'"))?;
    let parse = |t: &str| {
        t.trim()
            .parse::<u32>()
            .map_err(|_| format!("'{t}' is not a whole number (in '{s}')"))
    };
    Ok((parse(a)?, parse(b)?))
}

/// Parses `i/n` (0 ≤ i < n).
pub fn parse_shard(s: &str) -> std::result::Result<(u32, u32), String> {
    let (i, n) = parse_pair(s, "/", "INDEX/COUNT like 2/8")?;
    if n == 0 || i >= n {
        return Err(format!(
            "shard {i}/{n}: the index counts from 0 and must be below the count"
        ));
    }
    Ok((i, n))
}

/// Parses `A..B` (A < B).
pub fn parse_sample_range(s: &str) -> std::result::Result<[u32; 2], String> {
    let (a, b) = parse_pair(s, "..", "FIRST..END like 0..256")?;
    if a >= b {
        return Err(format!("sample range {a}..{b} is empty"));
    }
    Ok([a, b])
}

fn hex(digest: impl AsRef<[u8]>) -> String {
    digest.as_ref().iter().map(|b| format!("{b:02x}")).collect()
}

/// `scene_hash`, `assets_hash` and `settings_hash` of a scene about to be rendered.
pub fn scene_hashes(scene: &Scene, gpu_scene: &GpuScene) -> (String, String, String) {
    // The geometry as the scene states it (each shared mesh once, then every object's transform),
    // not as one build stores it: a CPU node's instanced build and a GPU node's flattened one of
    // the same scene render parts that merge.
    let mut geometry = Sha256::new();
    let mut meshes_seen = std::collections::HashMap::new();
    for object in &scene.objects {
        let mesh = &object.mesh;
        // Which mesh by its order of first use (an address differs between processes).
        let next = meshes_seen.len() as u64;
        let id = *meshes_seen
            .entry(std::sync::Arc::as_ptr(mesh))
            .or_insert(next);
        geometry.update(id.to_le_bytes());
        if id == next {
            geometry.update(bytemuck::cast_slice(&mesh.positions));
            geometry.update(bytemuck::cast_slice(&mesh.indices));
            for attribute in [&mesh.normals, &mesh.colors] {
                geometry.update(bytemuck::cast_slice(attribute.as_deref().unwrap_or(&[])));
            }
            geometry.update(bytemuck::cast_slice(mesh.uvs.as_deref().unwrap_or(&[])));
        }
        geometry.update(bytemuck::bytes_of(&object.transform.matrix()));
    }
    geometry.update(bytemuck::cast_slice(&gpu_scene.materials));
    geometry.update(bytemuck::cast_slice(&gpu_scene.delta_lights));
    let mut assets = Sha256::new();
    assets.update(bytemuck::cast_slice(&gpu_scene.texels));
    assets.update(bytemuck::cast_slice(&gpu_scene.env_texels));
    assets.update(gpu_scene.env_width.to_le_bytes());
    assets.update(gpu_scene.env_height.to_le_bytes());
    assets.update(gpu_scene.env_rotation.to_le_bytes());
    let settings = crate::scene::RenderSettings {
        // The total is a field of its own; a shard's own count is not a setting.
        samples_per_pixel: 0,
        ..scene.settings.clone()
    };
    let mut decisive = serde_json::json!({
        "settings": settings,
        "camera": scene.camera,
        "ambient": scene.ambient,
    });
    // Only where there is fog, so the settings hash of a scene without it stays as it was.
    if scene.fog.is_on() {
        decisive["fog"] = serde_json::json!(scene.fog);
    }
    let settings_hash = Sha256::digest(decisive.to_string().as_bytes());
    (
        hex(geometry.finalize()),
        hex(assets.finalize()),
        hex(settings_hash),
    )
}

impl Part {
    /// The mean radiance and mean squared luminance of each pixel.
    pub fn pixels(&self) -> Vec<[f32; 4]> {
        self.sums
            .iter()
            .zip(&self.counts)
            .map(|(s, &n)| accumulation::pixel_mean(s, n))
            .collect()
    }

    /// Whether the ranges cover every sample of the frame.
    pub fn is_complete(&self) -> bool {
        self.header.sample_ranges == [[0, self.header.total_spp]]
    }
}

impl Guides {
    fn planes(&self) -> [&Vec<[f32; 3]>; 3] {
        [&self.albedo, &self.normal, &self.emission]
    }

    fn planes_mut(&mut self) -> [&mut Vec<[f32; 3]>; 3] {
        [&mut self.albedo, &mut self.normal, &mut self.emission]
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    pub(super) fn part(ranges: Vec<[u32; 2]>, seed: u32) -> Part {
        let size = 6;
        let mut state = seed;
        let mut sums = vec![PixelSums::default(); size];
        let samples = ranges.iter().map(|[a, b]| b - a).sum::<u32>();
        for s in &mut sums {
            for _ in 0..samples {
                state = state.wrapping_mul(1_664_525).wrapping_add(1_013_904_223);
                let v = (state >> 8) as f32 / (1 << 24) as f32;
                accumulation::add_sample(s, [v, v * 0.5, v * 2.0]);
            }
        }
        Part {
            header: PartHeader {
                format_version: PART_FORMAT_VERSION,
                rt_version: "test".into(),
                scene_hash: "s".into(),
                assets_hash: "a".into(),
                settings_hash: "x".into(),
                width: 3,
                height: 2,
                total_spp: 8,
                sample_ranges: ranges,
                notes: vec![],
                layers: Layers::default(),
            },
            counts: vec![samples; size],
            sums,
            guides: Guides {
                albedo: vec![[0.5; 3]; size],
                normal: vec![[0.0, 1.0, 0.0]; size],
                emission: vec![[0.0; 3]; size],
            },
            hits: Default::default(),
            position: Vec::new(),
        }
    }

    #[test]
    fn shards_cover_the_samples_once() {
        for (spp, n) in [(7, 3), (64, 4), (5, 8), (1, 1)] {
            let ranges: Vec<_> = (0..n).map(|i| shard_range(spp, i, n)).collect();
            assert_eq!(ranges[0][0], 0);
            assert_eq!(ranges[n as usize - 1][1], spp);
            for pair in ranges.windows(2) {
                assert_eq!(pair[0][1], pair[1][0]);
            }
        }
        assert_eq!(parse_shard("2/8"), Ok((2, 8)));
        assert!(parse_shard("8/8").is_err());
        assert!(parse_shard("x").is_err());
        assert_eq!(parse_sample_range("4..12"), Ok([4, 12]));
        assert!(parse_sample_range("4..4").is_err());
    }
}
