//! Merging parts: `Merger` adds them one at a time, checking that they belong to one render and
//! that no sample counts twice, and `finish` yields the merged part.

use std::path::{Path, PathBuf};

use super::{Guides, Part, PartHeader};
use crate::accumulation;
use crate::error::{Error, Result};

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
        other_seed.1.header.settings_hash = "y".into();
        let e = merge(&[a, other_seed], false).unwrap_err().to_string();
        assert!(e.contains("settings_hash") && e.contains("b.exr"), "{e}");
    }
}
