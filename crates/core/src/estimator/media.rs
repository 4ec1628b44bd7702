//! The media a path is in: a stack of two medium ids (entered through a front face, left through
//! a back face), and the medium an id names. Mirrored one-to-one in `media.wgsl` beside it.

use crate::gpu_scene::GpuScene;
use crate::gpu_types::{Frame, Medium};

/// The WGSL twin of this module, `media.wgsl` beside it (composed into the kernels by
/// `rt_gpu::shaders`).
pub const WGSL: &str = include_str!("media.wgsl");

/// The medium a path is in, as an id: 0 the scene's fog (`Frame::fog`, vacuum without fog), m + 1
/// the interior of material m (`Material::medium`). The path keeps a stack of two in `media`, 16
/// bits each, the innermost low: transmission into a closed surface enters its material's
/// medium, transmission out of it leaves it, so a liquid in a glass in fog comes out right; a
/// third level drops the outermost.
pub fn media_top(media: u32) -> u32 {
    media & 0xffff
}

/// The stack after entering material `material`'s interior (materials past 65,534 have none).
pub fn media_enter(media: u32, material: u32) -> u32 {
    if material >= 0xffff {
        return media;
    }
    (media << 16) | (material + 1)
}

/// The stack after leaving material `material`'s interior: the entry removed wherever it is (a
/// path may leave an inner volume through an outer one's surface); unchanged if the path never
/// entered it (it started inside).
pub fn media_leave(media: u32, material: u32) -> u32 {
    let id = material + 1;
    if media & 0xffff == id {
        media >> 16
    } else if media >> 16 == id {
        media & 0xffff
    } else {
        media
    }
}

/// The medium of id `id` (`media_top`).
pub fn medium_of(scene: &GpuScene, frame: &Frame, id: u32) -> Medium {
    if id == 0 {
        frame.fog
    } else {
        scene.materials[id as usize - 1].medium
    }
}
