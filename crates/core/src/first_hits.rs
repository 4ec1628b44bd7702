//! What each pixel's camera rays met first, beyond the denoiser's guides: the share of them that
//! met a surface (the pixel's alpha with a transparent film), how far away it was, and the object
//! its first sample met (an id, never averaged). Both backends keep them beside the guides
//! (`cpu_render`, and the w channels of the kernels' guide means in path.wgsl); the render passes
//! (`--aov`) and alpha come from here.

/// Per pixel, row-major.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct FirstHits {
    /// The mean of 1 (met something) or 0 (escaped): alpha, in [0, 1].
    pub coverage: Vec<f32>,
    /// The mean of distance × met: over `coverage`, the mean distance to what was met.
    pub depth_weighted: Vec<f32>,
    /// The object (`Scene::objects` index) plus one that the pixel's first sample met; 0 when it
    /// met none (or scattered in a medium first).
    pub object: Vec<u32>,
    /// The means of (1, E_lit, E_free) over the samples that met a shadow catcher first, zeros
    /// over the others (`crate::estimator::shadow_catcher`).
    pub caught: Vec<[f32; 3]>,
}

impl FirstHits {
    /// `n` pixels that have met nothing yet.
    pub fn new(n: usize) -> Self {
        FirstHits {
            coverage: vec![0.0; n],
            depth_weighted: vec![0.0; n],
            object: vec![0; n],
            caught: vec![[0.0; 3]; n],
        }
    }

    pub fn is_empty(&self) -> bool {
        self.coverage.is_empty()
    }

    /// Pixel `i`'s mean distance to what its rays met (infinite where they met nothing).
    pub fn depth(&self, i: usize) -> f32 {
        if self.coverage[i] > 0.0 {
            self.depth_weighted[i] / self.coverage[i]
        } else {
            f32::INFINITY
        }
    }

    /// Pixel `i`'s alpha on a transparent film: its coverage, less the light its shadow catchers
    /// show unshadowed (α = coverage − s · Ē_lit / Ē_free, `crate::estimator::shadow_catcher`).
    pub fn alpha(&self, i: usize) -> f32 {
        let [share, lit, free] = self.caught.get(i).copied().unwrap_or_default();
        let unshadowed = if free > 0.0 {
            (lit / free).clamp(0.0, 1.0)
        } else {
            1.0
        };
        (self.coverage[i] - share * unshadowed).clamp(0.0, 1.0)
    }

    /// Every pixel's alpha (`alpha`).
    pub fn alphas(&self) -> Vec<f32> {
        (0..self.coverage.len()).map(|i| self.alpha(i)).collect()
    }

    /// Copies `tile` (pixels from `start` on) into these planes.
    pub fn copy_tile(&mut self, start: usize, tile: &FirstHits) {
        let range = start..start + tile.coverage.len();
        self.coverage[range.clone()].copy_from_slice(&tile.coverage);
        self.depth_weighted[range.clone()].copy_from_slice(&tile.depth_weighted);
        self.object[range.clone()].copy_from_slice(&tile.object);
        self.caught[range].copy_from_slice(&tile.caught);
    }
}
