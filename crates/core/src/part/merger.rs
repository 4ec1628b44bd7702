//! Merging parts: `Merger` adds them one at a time, checking that they belong to one render and
//! that no sample counts twice, and `finish` yields the merged part.

use std::path::{Path, PathBuf};

use super::{Guides, Part, PartHeader};
use crate::accumulation;
use crate::error::{Error, Result};
use crate::first_hits::FirstHits;

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
    /// Sample-weighted sums of the first hits and positions, and the first sample of the part
    /// whose object ids are kept (`None` once a part has none).
    hit_sums: Option<HitSums>,
}

/// What `Merger` adds of the parts' first hits: coverage, depth × coverage and what catchers
/// caught weighted by each pixel's samples, positions by its samples that met something (a
/// position is linear in the depth), and the object ids of the earliest part (the frame's first
/// sample's, as one render keeps them).
struct HitSums {
    coverage: Vec<f64>,
    depth_weighted: Vec<f64>,
    caught: Vec<[f64; 3]>,
    position: Option<Vec<[f64; 3]>>,
    object: Vec<u32>,
    object_from: u32,
}

impl HitSums {
    fn of(part: &Part) -> Option<Self> {
        let hits = &part.hits;
        let size = part.counts.len();
        if hits.coverage.len() != size {
            return None;
        }
        let n = |i: usize| f64::from(part.counts[i]);
        let covered = |i: usize| n(i) * f64::from(hits.coverage[i]);
        Some(HitSums {
            coverage: (0..size).map(covered).collect(),
            depth_weighted: (0..size)
                .map(|i| n(i) * f64::from(hits.depth_weighted[i]))
                .collect(),
            caught: (0..size)
                .map(|i| hits.caught[i].map(|c| n(i) * f64::from(c)))
                .collect(),
            position: (part.position.len() == size).then(|| {
                (0..size)
                    .map(|i| part.position[i].map(|p| covered(i) * f64::from(p)))
                    .collect()
            }),
            object: hits.object.clone(),
            object_from: part.header.sample_ranges.first().map_or(0, |r| r[0]),
        })
    }

    fn add(&mut self, more: HitSums) {
        let add = |a: &mut [f64], b: &[f64]| a.iter_mut().zip(b).for_each(|(x, y)| *x += y);
        add(&mut self.coverage, &more.coverage);
        add(&mut self.depth_weighted, &more.depth_weighted);
        for (a, b) in self.caught.iter_mut().zip(&more.caught) {
            add(a, b);
        }
        self.position = match (self.position.take(), more.position) {
            (Some(mut a), Some(b)) => {
                for (x, y) in a.iter_mut().zip(&b) {
                    add(x, y);
                }
                Some(a)
            }
            _ => None,
        };
        if more.object_from < self.object_from {
            (self.object, self.object_from) = (more.object, more.object_from);
        }
    }

    /// The means over `counts` samples per pixel.
    fn means(self, counts: &[u32]) -> (FirstHits, Vec<[f32; 3]>) {
        let per = |sum: f64, n: f64| if n > 0.0 { (sum / n) as f32 } else { 0.0 };
        let n = |i: usize| f64::from(counts[i]);
        let hits = FirstHits {
            coverage: (0..counts.len())
                .map(|i| per(self.coverage[i], n(i)))
                .collect(),
            depth_weighted: (0..counts.len())
                .map(|i| per(self.depth_weighted[i], n(i)))
                .collect(),
            object: self.object,
            caught: (0..counts.len())
                .map(|i| self.caught[i].map(|c| per(c, n(i))))
                .collect(),
        };
        let position = self.position.map_or_else(Vec::new, |sums| {
            sums.iter()
                .zip(&self.coverage)
                .map(|(p, &covered)| p.map(|x| per(x, covered)))
                .collect()
        });
        (hits, position)
    }
}

impl Merger {
    pub fn new(path: &Path, first: Part) -> Self {
        let guide_sums = weighted_guides(&first);
        let hit_sums = HitSums::of(&first);
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
            hit_sums,
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
        match (self.hit_sums.as_mut(), HitSums::of(part)) {
            (Some(sums), Some(more)) => sums.add(more),
            _ => self.hit_sums = None,
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
        let fields: [(&str, String, String); 9] = [
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
            (
                "layers",
                format!("{:?}", f.layers),
                format!("{:?}", h.layers),
            ),
        ];
        for (name, a, b) in fields {
            if a != b {
                let why = match name {
                    "scene_hash" | "assets_hash" => " (another scene, or changed assets)",
                    "settings_hash" => " (another seed, camera, size, depth or estimator)",
                    "layers" => " (alpha or passes asked for in one render and not the other)",
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
        (total.hits, total.position) = match self.hit_sums {
            Some(sums) => sums.means(&total.counts),
            None => Default::default(),
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
    use crate::part::tests::part;

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
        other_seed.1.header.layers.transparent = true;
        let e = merge(&[a.clone(), other_seed.clone()], false)
            .unwrap_err()
            .to_string();
        assert!(e.contains("layers"), "{e}");
        let mut other_seed = b.clone();
        other_seed.1.header.settings_hash = "y".into();
        other_seed.1.header.layers.transparent = false;
        let e = merge(&[a, other_seed], false).unwrap_err().to_string();
        assert!(e.contains("settings_hash") && e.contains("b.exr"), "{e}");
    }

    /// First hits merge as one render keeps them: coverage, depth and what catchers caught as
    /// means over every sample, positions over the samples that met something, object ids from
    /// the frame's first sample (the part holding it, whatever the order of merging).
    #[test]
    fn first_hits_merge_as_one_render_keeps_them() {
        let with_hits = |ranges, seed, coverage: f32, depth: f32, object: u32, x: f32| {
            let mut p = part(ranges, seed);
            p.header.layers.transparent = true;
            p.hits = FirstHits {
                coverage: vec![coverage; 6],
                depth_weighted: vec![depth * coverage; 6],
                object: vec![object; 6],
                caught: vec![[coverage, 0.5 * coverage, coverage]; 6],
            };
            p.position = vec![[x, 0.0, 0.0]; 6];
            p
        };
        // Samples 0..3 all met something at depth 2; samples 3..8 half of them at depth 4.
        let a = (
            PathBuf::from("a.exr"),
            with_hits(vec![[0, 3]], 1, 1.0, 2.0, 7, 1.0),
        );
        let b = (
            PathBuf::from("b.exr"),
            with_hits(vec![[3, 8]], 2, 0.5, 4.0, 9, 3.0),
        );
        let merged = merge(&[b, a], false).unwrap();
        let hits = &merged.hits;
        let coverage = (3.0 * 1.0 + 5.0 * 0.5) / 8.0;
        assert!((hits.coverage[0] - coverage).abs() < 1e-6);
        // Mean depth over the samples that met something: (3·2 + 2.5·4) / 5.5.
        assert!((hits.depth(0) - (3.0 * 2.0 + 2.5 * 4.0) / 5.5).abs() < 1e-5);
        assert!((merged.position[0][0] - (3.0 * 1.0 + 2.5 * 3.0) / 5.5).abs() < 1e-5);
        assert_eq!(hits.object, vec![7; 6], "the first sample's object");
        assert!((hits.caught[0][1] - 0.5 * coverage).abs() < 1e-6);
    }
}
