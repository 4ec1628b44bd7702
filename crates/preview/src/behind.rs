//! What solid glass sees through itself and a smooth metal mirrors: a copy of the frame as drawn
//! before them (its colour and depth), which their pass reads along each refracted or reflected
//! view ray (screen-space refraction and reflection, as Eevee draws them; `behind_along` in
//! `shaders/preview_glass.wgsl`). Why: the render sees the lit floor and whatever else lies
//! beyond a glass ball, or before a mirror, sharply; the irradiance volume's probes, a cell or
//! more apart, see it from elsewhere and blurred. The copy is taken only on frames that draw such
//! objects; they do not see each other in it.

use super::{COLOR_FORMAT, DEPTH_FORMAT, target_texture};

/// Which pass draws an object.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(super) enum Layer {
    /// With the opaque pass (and seen through glass).
    Opaque,
    /// Solid glass and smooth metals: after the opaque pass, reading its copy.
    Reading,
    /// Alpha and thin transmitting sheets: last, over what they cover.
    Blended,
}

/// The layer of `frame`'s object `i`.
pub(super) fn layer(frame: &super::PreviewFrame, i: usize) -> Layer {
    if frame.blended.get(i).copied().unwrap_or(false) {
        return Layer::Blended;
    }
    let Some(o) = frame.objects.get(i) else {
        return Layer::Opaque;
    };
    // The IOR of solid glass (`frame.rs`), which only transmitting objects refract through.
    let glass = o.flags[3] != 0 && o.params[2] > 0.0;
    // A metal whose reflection is sharp enough to read (`SHARP_ROUGHNESS`; a brushed one's
    // roughness across its stretch). Dielectrics reflect a few percent: not worth a march per
    // pixel.
    let mirror = o.params[0] >= 0.5 && o.params[1] < SHARP_ROUGHNESS;
    if glass || mirror {
        Layer::Reading
    } else {
        Layer::Opaque
    }
}

/// The roughness from which what lies beyond glass or before a metal is the probes' alone
/// (`sharp_share` in `shaders/preview_glass.wgsl`).
pub(super) const SHARP_ROUGHNESS: f32 = 0.5;

/// The copy of the target that the glass pass reads.
pub(super) struct Behind {
    color_texture: wgpu::Texture,
    pub(super) color: wgpu::TextureView,
    depth_texture: wgpu::Texture,
    pub(super) depth: wgpu::TextureView,
}

impl Behind {
    pub(super) fn new(device: &wgpu::Device, size: [u32; 2]) -> Self {
        let usage = wgpu::TextureUsages::COPY_DST | wgpu::TextureUsages::TEXTURE_BINDING;
        let color_texture =
            target_texture(device, "preview behind glass", size, COLOR_FORMAT, usage);
        let depth_texture = target_texture(
            device,
            "preview depth behind glass",
            size,
            DEPTH_FORMAT,
            usage,
        );
        Behind {
            color: color_texture.create_view(&Default::default()),
            color_texture,
            depth: depth_texture.create_view(&Default::default()),
            depth_texture,
        }
    }

    /// Records the copy of the target's colour and depth as drawn so far.
    pub(super) fn copy_from(
        &self,
        encoder: &mut wgpu::CommandEncoder,
        color: &wgpu::Texture,
        depth: &wgpu::Texture,
    ) {
        let size = self.color_texture.size();
        encoder.copy_texture_to_texture(
            color.as_image_copy(),
            self.color_texture.as_image_copy(),
            size,
        );
        encoder.copy_texture_to_texture(
            depth.as_image_copy(),
            self.depth_texture.as_image_copy(),
            size,
        );
    }
}
