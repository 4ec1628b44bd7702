//! Render parts: a range of a frame's samples rendered on one machine (`rt-cli render --shard`),
//! saved as an EXR that `rt-cli merge` combines exactly with the others.
//!
//! A part is an ordinary linear EXR (R, G, B, `variance.Y`, readable by any viewer) with, besides,
//! each pixel's sample count (`samples.Y`), its exact fixed-point sums of radiance and squared
//! luminance (`rt.sum.*`, four u32 words per channel: `accumulation`), the denoiser's guides
//! (`albedo.*`, `normal.*`, `emission.*`, sample-weighted means) and, in the header attribute
//! `rt.part`, a JSON `PartHeader`. Merging adds counts and sums, which is exact and associative,
//! so n merged shards are bit for bit the one-machine render of the same seed; the variance of a
//! merged pixel follows from its sums as it would for one render (the sufficient statistics merge
//! exactly, where float means and second moments would need Chan et al.'s pairwise update and
//! still round).

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

use serde::{Deserialize, Serialize};
use sha2::{Digest, Sha256};

use crate::accumulation::{self, PixelSums};
use crate::error::{Error, Result};
use crate::gpu_scene::GpuScene;
use crate::scene::Scene;

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
    let mut geometry = Sha256::new();
    geometry.update(bytemuck::cast_slice(&gpu_scene.triangles));
    geometry.update(bytemuck::cast_slice(&gpu_scene.shading));
    geometry.update(bytemuck::cast_slice(&gpu_scene.materials));
    geometry.update(bytemuck::cast_slice(&gpu_scene.tangents));
    geometry.update(bytemuck::cast_slice(&gpu_scene.emitters));
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
    let decisive = serde_json::json!({
        "settings": settings,
        "camera": scene.camera,
        "ambient": scene.ambient,
    });
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

/// The EXR bytes of `part`.
pub fn encode_part(part: &Part) -> Result<Vec<u8>> {
    use exr::prelude::{
        AnyChannel, AnyChannels, AttributeValue, Encoding, FlatSamples, Image, Layer,
        LayerAttributes, SmallVec, Text, WritableImage,
    };
    let h = &part.header;
    let size = h.width as usize * h.height as usize;
    if part.counts.len() != size || part.sums.len() != size {
        return Err(Error::Scene("part size does not match its pixels".into()));
    }
    let pixels = part.pixels();
    let counts = crate::output::SampleCounts::PerPixel(&part.counts);
    let variance = crate::output::pixel_variance(&pixels, counts);
    let f32s = |name: &str, values: Vec<f32>| AnyChannel::new(name, FlatSamples::F32(values));
    let mut channels = vec![
        f32s("R", pixels.iter().map(|p| p[0]).collect()),
        f32s("G", pixels.iter().map(|p| p[1]).collect()),
        f32s("B", pixels.iter().map(|p| p[2]).collect()),
        f32s("variance.Y", variance),
        AnyChannel::new("samples.Y", FlatSamples::U32(part.counts.clone())),
    ];
    for (c, name) in SUM_CHANNELS.iter().enumerate() {
        for w in 0..4 {
            channels.push(AnyChannel::new(
                format!("rt.sum.{name}.w{w}").as_str(),
                FlatSamples::U32(part.sums.iter().map(|s| s[c][w]).collect()),
            ));
        }
    }
    for ((prefix, names), values) in GUIDE_CHANNELS.iter().zip(part.guides.planes()) {
        if values.len() != size {
            continue;
        }
        for (k, name) in names.iter().enumerate() {
            channels.push(f32s(
                &format!("{prefix}.{name}"),
                values.iter().map(|v| v[k]).collect(),
            ));
        }
    }
    let header_json = serde_json::to_string(h)
        .map_err(|e| Error::Scene(format!("encoding the part header failed: {e}")))?;
    let mut attributes = LayerAttributes::named("rt part");
    attributes.other.insert(
        Text::from(HEADER_ATTRIBUTE),
        AttributeValue::Text(Text::from(header_json.as_str())),
    );
    let layer = Layer::new(
        (h.width as usize, h.height as usize),
        attributes,
        // ZIP: the sums' high words are mostly zero and shrink to almost nothing.
        Encoding::SMALL_LOSSLESS,
        AnyChannels::sort(SmallVec::from_vec(channels)),
    );
    let mut out = std::io::Cursor::new(Vec::new());
    Image::from_layer(layer)
        .write()
        .to_buffered(&mut out)
        .map_err(|e| Error::Scene(format!("encoding the part failed: {e}")))?;
    Ok(out.into_inner())
}

const SUM_CHANNELS: [&str; 4] = ["R", "G", "B", "Y2"];

/// The guides' EXR layers and channel names, in the order of `Guides::planes`.
const GUIDE_CHANNELS: [(&str, [&str; 3]); 3] = [
    ("albedo", ["R", "G", "B"]),
    ("normal", ["X", "Y", "Z"]),
    ("emission", ["R", "G", "B"]),
];

impl Guides {
    fn planes(&self) -> [&Vec<[f32; 3]>; 3] {
        [&self.albedo, &self.normal, &self.emission]
    }

    fn planes_mut(&mut self) -> [&mut Vec<[f32; 3]>; 3] {
        [&mut self.albedo, &mut self.normal, &mut self.emission]
    }
}

/// Saves `part` atomically (a killed or duplicated task leaves no half-written file).
pub fn save_part(path: &Path, part: &Part) -> Result<()> {
    crate::output::write_atomically(path, &encode_part(part)?)
}

/// Reads a part, with an error naming the file and what is wrong.
pub fn read_part(path: &Path) -> Result<Part> {
    let bytes = std::fs::read(path).map_err(|source| Error::Io {
        path: path.into(),
        source,
    })?;
    decode_part(&bytes).map_err(|e| Error::Scene(format!("{}: {e}", path.display())))
}

/// Decodes a part from EXR bytes.
pub fn decode_part(bytes: &[u8]) -> std::result::Result<Part, String> {
    use exr::prelude::{AttributeValue, FlatSamples, ReadChannels, ReadLayers, Text, read};
    let image = read()
        .no_deep_data()
        .largest_resolution_level()
        .all_channels()
        .first_valid_layer()
        .all_attributes()
        .from_buffered(std::io::Cursor::new(bytes))
        .map_err(|e| format!("not a readable EXR ({e}); a truncated or damaged file?"))?;
    let layer = &image.layer_data;
    let header_text = match layer.attributes.other.get(&Text::from(HEADER_ATTRIBUTE)) {
        Some(AttributeValue::Text(t)) => t.to_string(),
        _ => {
            return Err(format!(
                "an EXR without the `{HEADER_ATTRIBUTE}` header: not a part written by \
                 `rt-cli render --shard` or `rt-cli merge`"
            ));
        }
    };
    let header: PartHeader = serde_json::from_str(&header_text)
        .map_err(|e| format!("its `{HEADER_ATTRIBUTE}` header is not valid: {e}"))?;
    if header.format_version != PART_FORMAT_VERSION {
        return Err(format!(
            "part format version {} (this rt reads version {PART_FORMAT_VERSION})",
            header.format_version
        ));
    }
    let (w, h) = (layer.size.width(), layer.size.height());
    if (w, h) != (header.width as usize, header.height as usize) {
        return Err(format!(
            "its pixels are {w}x{h} but its header says {}x{}",
            header.width, header.height
        ));
    }
    check_ranges(&header.sample_ranges, header.total_spp)?;
    let channels: BTreeMap<String, &FlatSamples> = layer
        .channel_data
        .list
        .iter()
        .map(|c| (c.name.to_string(), &c.sample_data))
        .collect();
    let u32s = |name: &str| -> std::result::Result<&Vec<u32>, String> {
        match channels.get(name) {
            Some(FlatSamples::U32(v)) => Ok(v),
            Some(_) => Err(format!("channel {name} is not u32")),
            None => Err(format!("channel {name} is missing")),
        }
    };
    let counts = u32s("samples.Y")?.clone();
    let size = w * h;
    let mut sums = vec![PixelSums::default(); size];
    for (c, name) in SUM_CHANNELS.iter().enumerate() {
        for word in 0..4 {
            let values = u32s(&format!("rt.sum.{name}.w{word}"))?;
            for (s, &v) in sums.iter_mut().zip(values) {
                s[c][word] = v;
            }
        }
    }
    let most = header.sample_ranges.iter().map(|[a, b]| b - a).sum::<u32>();
    if let Some(i) = counts.iter().position(|&n| n > most) {
        return Err(format!(
            "pixel {i} holds {} samples, more than its ranges' {most}",
            counts[i]
        ));
    }
    let mut guides = Guides::default();
    for (slot, (prefix, names)) in guides.planes_mut().into_iter().zip(GUIDE_CHANNELS) {
        let planes: Option<Vec<&Vec<f32>>> = names
            .iter()
            .map(|n| match channels.get(&format!("{prefix}.{n}")) {
                Some(FlatSamples::F32(v)) => Some(v),
                _ => None,
            })
            .collect();
        if let Some(planes) = planes {
            *slot = (0..size)
                .map(|i| [planes[0][i], planes[1][i], planes[2][i]])
                .collect();
        }
    }
    Ok(Part {
        header,
        counts,
        sums,
        guides,
    })
}

/// Ranges must be non-empty, sorted, disjoint and inside `[0, total)`.
fn check_ranges(ranges: &[[u32; 2]], total: u32) -> std::result::Result<(), String> {
    if ranges.is_empty() {
        return Err("it holds no sample range".into());
    }
    for r in ranges {
        if r[0] >= r[1] || r[1] > total {
            return Err(format!(
                "sample range {}..{} is not inside the frame's 0..{total}",
                r[0], r[1]
            ));
        }
    }
    for pair in ranges.windows(2) {
        if pair[1][0] < pair[0][1] {
            return Err(format!(
                "sample ranges {}..{} and {}..{} are out of order or overlap",
                pair[0][0], pair[0][1], pair[1][0], pair[1][1]
            ));
        }
    }
    Ok(())
}

/// Joins touching ranges: [[0,4],[4,8]] -> [[0,8]].
fn coalesce(mut ranges: Vec<[u32; 2]>) -> Vec<[u32; 2]> {
    ranges.sort_unstable();
    let mut out: Vec<[u32; 2]> = Vec::with_capacity(ranges.len());
    for r in ranges {
        match out.last_mut() {
            Some(last) if last[1] == r[0] => last[1] = r[1],
            _ => out.push(r),
        }
    }
    out
}

/// Merges parts (each with the file it came from, for messages): see `Merger`.
pub fn merge(parts: &[(PathBuf, Part)], allow_partial: bool) -> Result<Part> {
    let mut parts = parts.iter();
    let Some((path, first)) = parts.next() else {
        return Err(Error::Scene("no parts to merge".into()));
    };
    let mut merger = Merger::new(path, first.clone());
    for (path, part) in parts {
        merger.add(path, part)?;
    }
    merger.finish(allow_partial)
}

/// Adds parts one at a time, so a merge holds one part besides the running total however many
/// there are (100 parts of a 4K frame would not fit in memory at once). Refuses a part that
/// disagrees with the first on any checked header field (naming it and both files) or whose
/// sample ranges overlap one already added; `finish` refuses (unless `allow_partial`) a union
/// that is not every sample of the frame. The result is itself a part.
pub struct Merger {
    first_path: PathBuf,
    total: Part,
    /// Every range added, with its file, to name both parts of an overlap.
    ranges: Vec<([u32; 2], PathBuf)>,
    /// Sample-weighted sums of the guides (`None` once a part has none).
    guide_sums: Option<[Vec<[f32; 3]>; 3]>,
}

impl Merger {
    pub fn new(path: &Path, first: Part) -> Self {
        let guide_sums = weighted_guides(&first);
        let ranges = first
            .header
            .sample_ranges
            .iter()
            .map(|r| (*r, path.to_path_buf()))
            .collect();
        Merger {
            first_path: path.into(),
            total: first,
            ranges,
            guide_sums,
        }
    }

    pub fn add(&mut self, path: &Path, part: &Part) -> Result<()> {
        self.check_header(path, &part.header)?;
        for r in &part.header.sample_ranges {
            if let Some((other, other_path)) =
                self.ranges.iter().find(|(o, _)| r[0] < o[1] && o[0] < r[1])
            {
                return Err(Error::Scene(format!(
                    "{} (samples {}..{}) and {} (samples {}..{}) overlap: a sample would count twice",
                    other_path.display(),
                    other[0],
                    other[1],
                    path.display(),
                    r[0],
                    r[1]
                )));
            }
        }
        self.ranges.extend(
            part.header
                .sample_ranges
                .iter()
                .map(|r| (*r, path.to_path_buf())),
        );
        for (c, &n) in self.total.counts.iter_mut().zip(&part.counts) {
            *c += n;
        }
        for (s, p) in self.total.sums.iter_mut().zip(&part.sums) {
            *s = accumulation::add_pixels(s, p);
        }
        match (self.guide_sums.as_mut(), weighted_guides(part)) {
            (Some(sums), Some(more)) => {
                for (plane, add) in sums.iter_mut().zip(more) {
                    for (a, b) in plane.iter_mut().zip(add) {
                        *a = [a[0] + b[0], a[1] + b[1], a[2] + b[2]];
                    }
                }
            }
            _ => self.guide_sums = None,
        }
        for note in &part.header.notes {
            if !self.total.header.notes.contains(note) {
                self.total.header.notes.push(note.clone());
            }
        }
        Ok(())
    }

    fn check_header(&self, path: &Path, h: &PartHeader) -> Result<()> {
        let f = &self.total.header;
        let fields: [(&str, String, String); 8] = [
            (
                "format_version",
                f.format_version.to_string(),
                h.format_version.to_string(),
            ),
            ("rt_version", f.rt_version.clone(), h.rt_version.clone()),
            ("scene_hash", f.scene_hash.clone(), h.scene_hash.clone()),
            ("assets_hash", f.assets_hash.clone(), h.assets_hash.clone()),
            (
                "settings_hash",
                f.settings_hash.clone(),
                h.settings_hash.clone(),
            ),
            ("width", f.width.to_string(), h.width.to_string()),
            ("height", f.height.to_string(), h.height.to_string()),
            (
                "total_spp",
                f.total_spp.to_string(),
                h.total_spp.to_string(),
            ),
        ];
        for (name, a, b) in fields {
            if a != b {
                let why = match name {
                    "scene_hash" | "assets_hash" => " (another scene, or changed assets)",
                    "settings_hash" => " (another seed, camera, size, depth or estimator)",
                    _ => "",
                };
                return Err(Error::Scene(format!(
                    "{} and {} do not belong to one render: their {name} differs{why}: {a} vs {b}",
                    self.first_path.display(),
                    path.display()
                )));
            }
        }
        Ok(())
    }

    /// The merged part.
    pub fn finish(self, allow_partial: bool) -> Result<Part> {
        let total_spp = self.total.header.total_spp;
        let union = coalesce(self.ranges.iter().map(|(r, _)| *r).collect());
        if !allow_partial && union != [[0, total_spp]] {
            let missing = missing_ranges(&union, total_spp);
            return Err(Error::Scene(format!(
                "the parts hold samples {} of the frame's 0..{total_spp}: missing {} (pass \
                 --allow-partial to merge them anyway)",
                format_ranges(&union),
                format_ranges(&missing)
            )));
        }
        let mut total = self.total;
        total.header.sample_ranges = union;
        total.guides = match self.guide_sums {
            Some([albedo, normal, emission]) => {
                let mean = |plane: Vec<[f32; 3]>| -> Vec<[f32; 3]> {
                    plane
                        .into_iter()
                        .zip(&total.counts)
                        .map(|(v, &n)| v.map(|x| x / (n.max(1) as f32)))
                        .collect()
                };
                Guides {
                    albedo: mean(albedo),
                    normal: mean(normal),
                    emission: mean(emission),
                }
            }
            None => Guides::default(),
        };
        Ok(total)
    }
}

/// A part's guides times each pixel's count (the guides merge as sample-weighted means).
fn weighted_guides(part: &Part) -> Option<[Vec<[f32; 3]>; 3]> {
    let size = part.counts.len();
    let planes = part.guides.planes();
    if planes.iter().any(|p| p.len() != size) {
        return None;
    }
    Some(planes.map(|plane| {
        plane
            .iter()
            .zip(&part.counts)
            .map(|(v, &n)| v.map(|x| x * n as f32))
            .collect()
    }))
}

fn missing_ranges(union: &[[u32; 2]], total: u32) -> Vec<[u32; 2]> {
    let mut missing = Vec::new();
    let mut at = 0;
    for r in union {
        if r[0] > at {
            missing.push([at, r[0]]);
        }
        at = r[1];
    }
    if at < total {
        missing.push([at, total]);
    }
    missing
}

/// "0..4, 8..16".
pub fn format_ranges(ranges: &[[u32; 2]]) -> String {
    ranges
        .iter()
        .map(|[a, b]| format!("{a}..{b}"))
        .collect::<Vec<_>>()
        .join(", ")
}

#[cfg(test)]
mod tests {
    use super::*;

    fn part(ranges: Vec<[u32; 2]>, seed: u32) -> Part {
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
            },
            counts: vec![samples; size],
            sums,
            guides: Guides {
                albedo: vec![[0.5; 3]; size],
                normal: vec![[0.0, 1.0, 0.0]; size],
                emission: vec![[0.0; 3]; size],
            },
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

    #[test]
    fn a_part_round_trips_through_its_exr() {
        let p = part(vec![[0, 3], [5, 8]], 1);
        let back = decode_part(&encode_part(&p).unwrap()).unwrap();
        assert_eq!(back, p);
    }

    #[test]
    fn merging_adds_the_samples_and_checks_the_parts() {
        let a = (PathBuf::from("a.exr"), part(vec![[0, 3]], 1));
        let b = (PathBuf::from("b.exr"), part(vec![[3, 8]], 2));
        let merged = merge(&[a.clone(), b.clone()], false).unwrap();
        assert!(merged.is_complete());
        assert_eq!(merged.counts, vec![8; 6]);
        // Associative and commutative: (a + b) == (b + a).
        assert_eq!(merge(&[b.clone(), a.clone()], false).unwrap(), merged);

        let missing = merge(std::slice::from_ref(&a), false)
            .unwrap_err()
            .to_string();
        assert!(missing.contains("missing 3..8"), "{missing}");
        assert!(merge(std::slice::from_ref(&a), true).is_ok());

        let overlapping = (PathBuf::from("c.exr"), part(vec![[2, 8]], 3));
        let e = merge(&[a.clone(), overlapping], false)
            .unwrap_err()
            .to_string();
        assert!(
            e.contains("a.exr") && e.contains("c.exr") && e.contains("overlap"),
            "{e}"
        );

        let mut other_seed = b.clone();
        other_seed.1.header.settings_hash = "y".into();
        let e = merge(&[a, other_seed], false).unwrap_err().to_string();
        assert!(e.contains("settings_hash") && e.contains("b.exr"), "{e}");
    }

    #[test]
    fn damaged_parts_are_clear_errors() {
        let bytes = encode_part(&part(vec![[0, 8]], 1)).unwrap();
        let e = decode_part(&bytes[..bytes.len() / 2]).unwrap_err();
        assert!(e.contains("truncated"), "{e}");
        let plain = crate::output::encode_exr_with_variance(
            1,
            1,
            &[[0.0; 4]],
            crate::output::SampleCounts::Uniform(1),
        )
        .unwrap();
        assert!(decode_part(&plain).unwrap_err().contains("rt.part"));
    }
}
