//! A part's EXR: the viewable channels, the exact sums, the guides and the `rt.part` header,
//! written atomically and read back with every channel, size and range checked.

use std::collections::BTreeMap;
use std::path::Path;

use super::{Guides, HEADER_ATTRIBUTE, PART_FORMAT_VERSION, Part, PartHeader};
use crate::accumulation::PixelSums;
use crate::error::{Error, Result};
use crate::first_hits::FirstHits;

/// The EXR bytes of `part`.
pub fn encode_part(part: &Part) -> Result<Vec<u8>> {
    encode_part_with(part, &[])
}

/// The EXR bytes of `part` with `extra` channels beside (a merged frame's alpha and passes, for
/// viewers; a part read back ignores them; one named as a guide channel is that guide).
pub fn encode_part_with(part: &Part, extra: &[(String, Vec<f32>)]) -> Result<Vec<u8>> {
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
    channels.extend(hit_channels(part, size)?);
    for (name, values) in extra {
        // The normal and albedo passes are the guides, already there under the same names.
        let there = channels.iter().any(|c| c.name.to_string() == *name);
        if values.len() == size && !there {
            channels.push(f32s(name, values.clone()));
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

/// The first hits' channels (`FirstHits`; `Part::position`).
const COVERAGE: &str = "rt.hits.coverage";
const DEPTH_WEIGHTED: &str = "rt.hits.depth";
const OBJECT: &str = "rt.hits.object";
const CAUGHT: [&str; 3] = [
    "rt.hits.caught.share",
    "rt.hits.caught.lit",
    "rt.hits.caught.free",
];
const POSITION: [&str; 3] = [
    "rt.hits.position.X",
    "rt.hits.position.Y",
    "rt.hits.position.Z",
];

/// The channels of a part's first hits and positions, where it has them.
fn hit_channels(
    part: &Part,
    size: usize,
) -> Result<Vec<exr::prelude::AnyChannel<exr::prelude::FlatSamples>>> {
    use exr::prelude::{AnyChannel, FlatSamples};
    let hits = &part.hits;
    let mut channels = Vec::new();
    if hits.is_empty() {
        return Ok(channels);
    }
    let sizes = [
        hits.depth_weighted.len(),
        hits.object.len(),
        hits.caught.len(),
    ];
    if hits.coverage.len() != size || sizes.iter().any(|&n| n != size) {
        return Err(Error::Scene(
            "the part's first hits do not match its pixels".into(),
        ));
    }
    let f32s = |name: &str, values: Vec<f32>| AnyChannel::new(name, FlatSamples::F32(values));
    channels.push(f32s(COVERAGE, hits.coverage.clone()));
    channels.push(f32s(DEPTH_WEIGHTED, hits.depth_weighted.clone()));
    channels.push(AnyChannel::new(
        OBJECT,
        FlatSamples::U32(hits.object.clone()),
    ));
    for (k, name) in CAUGHT.iter().enumerate() {
        channels.push(f32s(name, hits.caught.iter().map(|c| c[k]).collect()));
    }
    if part.position.len() == size {
        for (k, name) in POSITION.iter().enumerate() {
            channels.push(f32s(name, part.position.iter().map(|p| p[k]).collect()));
        }
    }
    Ok(channels)
}

/// The guides' EXR layers and channel names, in the order of `Guides::planes`.
const GUIDE_CHANNELS: [(&str, [&str; 3]); 3] = [
    ("albedo", ["R", "G", "B"]),
    ("normal", ["X", "Y", "Z"]),
    ("emission", ["R", "G", "B"]),
];

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
    let (hits, position) = decode_hits(&channels, size)?;
    Ok(Part {
        header,
        counts,
        sums,
        guides,
        hits,
        position,
    })
}

/// A part's first hits and positions, where it has them (all of the hits' channels or none).
fn decode_hits(
    channels: &BTreeMap<String, &exr::prelude::FlatSamples>,
    size: usize,
) -> std::result::Result<(FirstHits, Vec<[f32; 3]>), String> {
    use exr::prelude::FlatSamples;
    if !channels.contains_key(COVERAGE) {
        return Ok((FirstHits::default(), Vec::new()));
    }
    let f32s = |name: &str| -> std::result::Result<&Vec<f32>, String> {
        match channels.get(name) {
            Some(FlatSamples::F32(v)) => Ok(v),
            Some(_) => Err(format!("channel {name} is not f32")),
            None => Err(format!("channel {name} is missing")),
        }
    };
    let object = match channels.get(OBJECT) {
        Some(FlatSamples::U32(v)) => v.clone(),
        _ => return Err(format!("channel {OBJECT} is missing or not u32")),
    };
    let caught = [f32s(CAUGHT[0])?, f32s(CAUGHT[1])?, f32s(CAUGHT[2])?];
    let hits = FirstHits {
        coverage: f32s(COVERAGE)?.clone(),
        depth_weighted: f32s(DEPTH_WEIGHTED)?.clone(),
        object,
        caught: (0..size)
            .map(|i| [caught[0][i], caught[1][i], caught[2][i]])
            .collect(),
    };
    let position = match POSITION.map(|name| f32s(name).ok()) {
        [Some(x), Some(y), Some(z)] => (0..size).map(|i| [x[i], y[i], z[i]]).collect(),
        _ => Vec::new(),
    };
    Ok((hits, position))
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

#[cfg(test)]
mod tests {
    use super::*;
    use crate::part::tests::part;

    #[test]
    fn a_part_round_trips_through_its_exr() {
        let mut p = part(vec![[0, 3], [5, 8]], 1);
        let back = decode_part(&encode_part(&p).unwrap()).unwrap();
        assert_eq!(back, p);
        // With first hits and positions (alpha and passes).
        p.header.layers.transparent = true;
        p.hits = FirstHits {
            coverage: vec![1.0, 0.5, 0.0, 1.0, 1.0, 0.25],
            depth_weighted: vec![2.0, 1.0, 0.0, 3.0, 4.0, 0.5],
            object: vec![1, 2, 0, 1, 3, 2],
            caught: vec![[1.0, 0.5, 2.0]; 6],
        };
        p.position = vec![[0.5, -1.0, 2.0]; 6];
        let back = decode_part(&encode_part(&p).unwrap()).unwrap();
        assert_eq!(back, p);
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
