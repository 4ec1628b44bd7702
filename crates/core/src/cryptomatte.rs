//! Cryptomatte (Friedman and Jones, "Fully automatic ID mattes with support for motion blur and
//! transparency", 2015; Psyop's specification 1.2.0), as Blender and Nuke read it: for each pixel
//! the objects its camera rays meet, ranked by coverage, written as EXR layers
//! `CryptoObject00`–`02` (channels `r g b a`: id, coverage, id, coverage; six ranks, Blender's
//! default "levels") with the header's `cryptomatte/<key>/…` metadata: the layer's name, the hash
//! (`MurmurHash3_32`), the id conversion (`uint32_to_float32`) and the manifest (each object's
//! name and hash), so a compositor picks an object by name and gets its matte with antialiased,
//! motion-free edges.
//!
//! An object's id is the MurmurHash3 (x86, 32-bit, seed 0) of its name, its bits made a float that
//! is neither NaN, infinite nor denormal (the exponent clamped to [1, 254]). Coverage is counted
//! over the render's own first camera rays of each pixel (`path::start_path`: the same jitter,
//! lens and projection), at most [`MAX_SAMPLES`]: a visibility pass that traces only camera rays,
//! so it is the same whichever device rendered the colour. Glass and other transmissive surfaces
//! count as hits (Blender's default), alpha-cut surfaces as the render's rays see them; rays that
//! meet nothing leave the rest of the pixel to the background, which has no id.

use rayon::prelude::*;

use crate::estimator::path::start_path;
use crate::estimator::{instances, trace};
use crate::gpu_scene::GpuScene;
use crate::gpu_types::Frame;
use crate::output::{ExrAttribute, ExrChannel};
use crate::scene::Scene;

/// The layer's name (`CryptoObject00`… hold its ranks).
pub const LAYER: &str = "CryptoObject";
/// Ranks kept per pixel: three RGBA layers.
pub const RANKS: usize = 6;
/// Camera rays counted per pixel at most (coverage in steps of 1/32 at an edge); fewer when the
/// render takes fewer samples.
pub const MAX_SAMPLES: u32 = 32;

/// MurmurHash3, x86 32-bit variant (Appleby), of `key` with `seed`.
pub fn murmur3_32(key: &[u8], seed: u32) -> u32 {
    const C1: u32 = 0xcc9e_2d51;
    const C2: u32 = 0x1b87_3593;
    let mix = |k: u32| k.wrapping_mul(C1).rotate_left(15).wrapping_mul(C2);
    let mut h = seed;
    let blocks = key.chunks_exact(4);
    let tail = blocks.remainder();
    for block in blocks {
        h ^= mix(u32::from_le_bytes([block[0], block[1], block[2], block[3]]));
        h = h.rotate_left(13).wrapping_mul(5).wrapping_add(0xe654_6b64);
    }
    if !tail.is_empty() {
        let k = (tail.iter().enumerate()).fold(0u32, |k, (i, &b)| k | u32::from(b) << (8 * i));
        h ^= mix(k);
    }
    h ^= key.len() as u32;
    h ^= h >> 16;
    h = h.wrapping_mul(0x85eb_ca6b);
    h ^= h >> 13;
    h = h.wrapping_mul(0xc2b2_ae35);
    h ^ (h >> 16)
}

/// The name's hash, as the manifest lists it.
pub fn name_hash(name: &str) -> u32 {
    murmur3_32(name.as_bytes(), 0)
}

/// The id stored in the layers: the hash's bits as a float, its exponent clamped to [1, 254].
pub fn id_of_hash(hash: u32) -> f32 {
    let exponent = ((hash >> 23) & 0xff).clamp(1, 254);
    f32::from_bits((hash & 0x807f_ffff) | exponent << 23)
}

/// The metadata key of a layer: the first seven hex digits of its name's hash.
pub fn metadata_key(layer: &str) -> String {
    format!("{:08x}", name_hash(layer))[..7].to_string()
}

/// Each pixel's objects (`Scene::objects` indices) and the share of its first
/// `min(samples, MAX_SAMPLES)` camera rays that met each first, most covered first (ties by index).
pub fn coverage(scene: &GpuScene, frame: &Frame, samples: u32) -> Vec<Vec<(u32, f32)>> {
    let samples = samples.clamp(1, MAX_SAMPLES);
    let (width, height) = (frame.width, frame.height);
    (0..width * height)
        .into_par_iter()
        .map(|i| {
            let (x, y) = (i % width, i / width);
            let mut counts: Vec<(u32, u32)> = Vec::new();
            for sample in 0..samples {
                let path = start_path(frame, x, y, sample);
                if path.depth >= frame.max_depth {
                    continue; // outside a fisheye's image circle: nothing seen
                }
                let mut hit = trace(scene, path.origin, path.direction, f32::MAX);
                if hit.triangle == crate::estimator::hit::MISS {
                    continue;
                }
                let mut placed = None;
                let object = instances::hit_triangle(scene, &mut hit, &mut placed)
                    .tri
                    .material;
                match counts.iter_mut().find(|(o, _)| *o == object) {
                    Some((_, n)) => *n += 1,
                    None => counts.push((object, 1)),
                }
            }
            counts.sort_by(|a, b| b.1.cmp(&a.1).then(a.0.cmp(&b.0)));
            (counts.into_iter())
                .map(|(object, n)| (object, n as f32 / samples as f32))
                .collect()
        })
        .collect()
}

/// The EXR channels (`CryptoObject00.r` …) of `coverage` and the header's metadata.
pub fn layers(scene: &Scene, coverage: &[Vec<(u32, f32)>]) -> (Vec<ExrChannel>, Vec<ExrAttribute>) {
    let ids: Vec<f32> = (scene.objects.iter())
        .map(|o| id_of_hash(name_hash(&o.name)))
        .collect();
    let mut channels = Vec::new();
    for rank in 0..RANKS {
        let layer = format!("{LAYER}{:02}", rank / 2);
        // Lower case, as Blender names Cryptomatte's channels (its compositor reads these).
        let [id_channel, coverage_channel] = if rank % 2 == 0 {
            ["r", "g"]
        } else {
            ["b", "a"]
        };
        let ranked = |p: &Vec<(u32, f32)>| p.get(rank).copied();
        channels.push((
            format!("{layer}.{id_channel}"),
            (coverage.iter())
                .map(|p| ranked(p).map_or(0.0, |(o, _)| ids[o as usize]))
                .collect(),
        ));
        channels.push((
            format!("{layer}.{coverage_channel}"),
            (coverage.iter())
                .map(|p| ranked(p).map_or(0.0, |(_, c)| c))
                .collect(),
        ));
    }
    let prefix = format!("cryptomatte/{}", metadata_key(LAYER));
    let metadata = vec![
        (format!("{prefix}/name"), LAYER.to_string()),
        (format!("{prefix}/hash"), "MurmurHash3_32".to_string()),
        (
            format!("{prefix}/conversion"),
            "uint32_to_float32".to_string(),
        ),
        (format!("{prefix}/manifest"), manifest(scene)),
    ];
    (channels, metadata)
}

/// The manifest: `{"name": "hash in hex", …}` over the scene's object names, in ASCII (EXR text
/// attributes hold bytes: other characters are JSON escapes).
pub fn manifest(scene: &Scene) -> String {
    let mut names: Vec<&str> = scene.objects.iter().map(|o| o.name.as_str()).collect();
    names.sort_unstable();
    names.dedup();
    let entries: Vec<String> = (names.iter())
        .map(|name| {
            let quoted = serde_json::to_string(name).unwrap_or_default();
            let ascii: String = (quoted.encode_utf16())
                .map(|u| match char::from_u32(u32::from(u)) {
                    Some(c) if c.is_ascii() => c.to_string(),
                    _ => format!("\\u{u:04x}"),
                })
                .collect();
            format!("{ascii}:\"{:08x}\"", name_hash(name))
        })
        .collect();
    format!("{{{}}}", entries.join(","))
}

#[cfg(test)]
mod tests;
