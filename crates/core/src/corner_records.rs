//! Shading attributes stored once per vertex, not once per triangle: `GpuScene::shading`, the
//! word list the kernels read a hit's normals, colours and texture coordinates from.
//!
//! Its first `3 × triangles` words say, for triangle i, where in the list each of its three
//! corners' records begins (`NO_RECORD` for a triangle without attributes, which the kernels
//! never look up); the records follow, `CORNER_WORDS` words each: the vertex's normal in world
//! space (x, y, z as `f32` bits), its colour (RGBA8 sRGB, `u32::MAX` without colours) and its
//! texture coordinates (u, v). A vertex that six triangles share is stored once: a closed mesh
//! has half as many vertices as triangles, so 12 + 24 / 2 = 24 bytes a triangle instead of the 80
//! a per-triangle record took. The
//! kernels gather a triangle's record (`GpuScene::stored_shading`, `stored_shading` in
//! `gpu_scene.wgsl`) only where its flags say it has attributes.

use crate::error::{Error, Result};
use crate::gpu_types::{CORNER_WORDS, NO_RECORD};
use crate::object_frames::ObjectFrame;

/// Writes the list as the build places triangles: the corner words at each triangle's index, and
/// an object's vertex records the first time one of its triangles has attributes (a scene with
/// none keeps the list empty).
pub(crate) struct CornerRecords {
    /// Triangles the whole build places (the corner words come first, three per triangle).
    triangles: usize,
    /// Where each frame's vertex records begin, `NO_RECORD` until written.
    bases: Vec<u32>,
}

impl CornerRecords {
    pub fn new(triangles: usize) -> Self {
        CornerRecords {
            triangles,
            bases: Vec::new(),
        }
    }

    /// Starts a mesh BVH's triangles, drawn from `frames` frames (indices into them follow).
    pub fn begin(&mut self, frames: usize) {
        self.bases.clear();
        self.bases.resize(frames, NO_RECORD);
    }

    /// Triangle `triangle`'s corners, vertices `corners` of frame `f`.
    pub fn push(
        &mut self,
        words: &mut Vec<u32>,
        triangle: usize,
        (f, frame): (usize, &ObjectFrame),
        corners: [u32; 3],
    ) -> Result<()> {
        if triangle >= self.triangles {
            return Err(Error::Scene(format!(
                "triangle {triangle} placed past the {} the build counted",
                self.triangles
            )));
        }
        if words.is_empty() {
            words.resize(3 * self.triangles, NO_RECORD);
        }
        if self.bases[f] == NO_RECORD {
            let base = words.len();
            let end = base as u64 + (frame.vertices() * CORNER_WORDS) as u64;
            if end >= u64::from(NO_RECORD) {
                return Err(Error::Scene(format!(
                    "the scene's shading attributes need {end} words, more than a 32-bit index reaches"
                )));
            }
            words.reserve_exact(frame.vertices() * CORNER_WORDS);
            for v in 0..frame.vertices() as u32 {
                words.extend(frame.corner_record(v));
            }
            self.bases[f] = base as u32;
        }
        let base = self.bases[f];
        for (k, c) in corners.into_iter().enumerate() {
            words[3 * triangle + k] = base + c * CORNER_WORDS as u32;
        }
        Ok(())
    }
}
