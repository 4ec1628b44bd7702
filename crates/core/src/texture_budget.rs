//! Textures that fit a device: where a scene's texels exceed what one buffer may hold (lavapipe
//! binds 128 MiB), the largest images are box-filtered down, halving until all fit, instead of
//! the render failing. Works on the built `GpuScene` (its texels and the materials' texture
//! slots), so the geometry is not rebuilt; images no material reads are left out. The averaging is
//! of the stored bytes (sRGB-encoded colour, linear data alike), as simple mipmap builders do.

use std::collections::BTreeMap;

use crate::gpu_scene::GpuScene;
use crate::gpu_types::TextureSlot;

/// What fitting the textures did, for the user: the budget, what they needed, each image halved.
#[derive(Clone, Debug, PartialEq)]
pub struct TextureFit {
    pub budget_bytes: u64,
    pub needed_bytes: u64,
    /// (before, after) sizes of each image that was made smaller.
    pub downscaled: Vec<((u32, u32), (u32, u32))>,
}

impl std::fmt::Display for TextureFit {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let mib = |b: u64| b as f64 / (1024.0 * 1024.0);
        let sizes: Vec<String> = self
            .downscaled
            .iter()
            .map(|((w, h), (w2, h2))| format!("{w}×{h} → {w2}×{h2}"))
            .collect();
        write!(
            f,
            "the textures need {:.1} MiB, the device holds {:.1} MiB in one buffer: {} box-filtered \
             down ({})",
            mib(self.needed_bytes),
            mib(self.budget_bytes),
            sizes.len(),
            sizes.join(", ")
        )
    }
}

impl GpuScene {
    /// This scene with its textures within `budget_bytes` (4 bytes a texel), or `None` where they
    /// already fit; an image is halved (each side rounded up) until the total fits or it is one
    /// texel.
    pub fn with_textures_within(&self, budget_bytes: u64) -> Option<(GpuScene, TextureFit)> {
        let needed_bytes = 4 * self.texels.len() as u64;
        if needed_bytes <= budget_bytes {
            return None;
        }
        // Each image by its offset.
        let mut images: BTreeMap<u32, Image> = BTreeMap::new();
        for slot in self.materials.iter().flat_map(|m| m.textures.iter()) {
            if slot.is_empty() {
                continue;
            }
            images.entry(slot.offset).or_insert_with(|| {
                let start = slot.offset as usize;
                let texels =
                    self.texels[start..start + (slot.width * slot.height) as usize].to_vec();
                let size = (slot.width, slot.height);
                Image {
                    before: size,
                    texels,
                    size,
                }
            });
        }
        let total = |images: &BTreeMap<u32, Image>| {
            images
                .values()
                .map(|i| 4 * i.texels.len() as u64)
                .sum::<u64>()
        };
        while total(&images) > budget_bytes {
            let Some(largest) = images
                .values_mut()
                .filter(|i| i.texels.len() > 1)
                .max_by_key(|i| i.texels.len())
            else {
                break;
            };
            (largest.texels, largest.size) = halve(&largest.texels, largest.size);
        }
        let mut fitted = self.clone();
        fitted.texels = Vec::with_capacity(images.values().map(|i| i.texels.len()).sum());
        let mut moved: BTreeMap<u32, TextureSlot> = BTreeMap::new();
        let mut downscaled = Vec::new();
        for (&offset, image) in &images {
            moved.insert(
                offset,
                TextureSlot {
                    offset: fitted.texels.len() as u32,
                    width: image.size.0,
                    height: image.size.1,
                },
            );
            fitted.texels.extend_from_slice(&image.texels);
            if image.before != image.size {
                downscaled.push((image.before, image.size));
            }
        }
        for slot in fitted
            .materials
            .iter_mut()
            .flat_map(|m| m.textures.iter_mut())
        {
            if let Some(&new) = moved.get(&slot.offset).filter(|_| !slot.is_empty()) {
                *slot = new;
            }
        }
        let fit = TextureFit {
            budget_bytes,
            needed_bytes,
            downscaled,
        };
        Some((fitted, fit))
    }
}

/// One image of the scene while it is fitted: its size as built, its texels and size now.
struct Image {
    before: (u32, u32),
    texels: Vec<u32>,
    size: (u32, u32),
}

/// An RGBA8 image at half its size (sides rounded up): each texel the mean of the 2×2 block it
/// covers (of the texels inside the image, at odd edges).
fn halve(texels: &[u32], (width, height): (u32, u32)) -> (Vec<u32>, (u32, u32)) {
    let (w, h) = (width as usize, height as usize);
    let (half_w, half_h) = (w.div_ceil(2), h.div_ceil(2));
    let mut out = Vec::with_capacity(half_w * half_h);
    for y in 0..half_h {
        for x in 0..half_w {
            let mut sum = [0u32; 4];
            let mut count = 0;
            for (dx, dy) in [(0, 0), (1, 0), (0, 1), (1, 1)] {
                let (sx, sy) = (2 * x + dx, 2 * y + dy);
                if sx < w && sy < h {
                    let texel = texels[sy * w + sx].to_le_bytes();
                    for c in 0..4 {
                        sum[c] += u32::from(texel[c]);
                    }
                    count += 1;
                }
            }
            let mean = sum.map(|s| ((s + count / 2) / count) as u8);
            out.push(u32::from_le_bytes(mean));
        }
    }
    (out, (half_w as u32, half_h as u32))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn halving_averages_each_block_and_keeps_odd_edges() {
        let texel = |v: u8| u32::from_le_bytes([v, v, v, 255]);
        // 3×1: [10, 30, 50] → [20, 50].
        let (out, size) = halve(&[texel(10), texel(30), texel(50)], (3, 1));
        assert_eq!((out, size), (vec![texel(20), texel(50)], (2, 1)));
        // 2×2 → 1×1 mean.
        let (out, size) = halve(&[texel(0), texel(100), texel(200), texel(100)], (2, 2));
        assert_eq!((out, size), (vec![texel(100)], (1, 1)));
    }
}
