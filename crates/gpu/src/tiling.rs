//! Images larger than one accumulation buffer, rendered in bands of rows one after another.

use rt_core::GpuScene;
use rt_core::accumulation::{CHANNEL_SUM_BYTES, PixelSums};
use rt_core::gpu_types::Frame;

use crate::context::GpuContext;
use crate::error::Result;
use crate::image::{Aovs, Image};
use crate::options::RenderOptions;
use crate::renderer::{AOV_BYTES_PER_PIXEL, Renderer};

/// Bytes per pixel of the largest per-pixel binding a render with `options` allocates: one
/// accumulation channel (`CHANNEL_SUM_BYTES`), or the denoiser's guides when it keeps them. Tiles
/// are sized by this, so every per-pixel buffer of a tile fits in one binding.
pub fn pixel_binding_bytes(options: &RenderOptions) -> u64 {
    let guides = if options.aovs { AOV_BYTES_PER_PIXEL } else { 0 };
    CHANNEL_SUM_BYTES.max(guides)
}

/// Rows per tile so that each of a tile's per-pixel buffers (`pixel_bytes` per pixel, see
/// `pixel_binding_bytes`) fits in `max_bytes`.
pub fn tile_rows(width: u32, height: u32, pixel_bytes: u64, max_bytes: u64) -> u32 {
    let row_bytes = u64::from(width.max(1)) * pixel_bytes.max(1);
    ((max_bytes / row_bytes).max(1) as u32).min(height.max(1))
}

/// The largest per-pixel buffer of a whole `width` x `height` render with `options`: above the
/// adapter's binding limit, the image renders in tiles.
pub fn whole_image_binding_bytes(width: u32, height: u32, options: &RenderOptions) -> u64 {
    u64::from(width) * u64::from(height) * pixel_binding_bytes(options)
}

/// A tiled render's result: the image and, with `RenderOptions::aovs`, the denoiser's guides.
#[derive(Clone, Debug)]
pub struct TiledRender {
    pub image: Image,
    pub aovs: Option<Aovs>,
}

/// Renders `spp` samples per pixel of `scene` (built as `gpu_scene`), an image too large for one
/// accumulation buffer, tile by tile (bands of whole rows), and stitches the tiles (and their
/// AOVs). Each pixel's samples are
/// the same as in an untiled render (random numbers are keyed by the pixel's number in the whole
/// image), so the result is bit-identical, except with adaptive sampling: a pixel on a tile's
/// first or last row judges only its neighbours inside the tile, so it may stop sooner. `max_tile_bytes` defaults to the adapter's largest
/// storage binding; `progress(fraction)` returning false stops after the current batch (the
/// unrendered rest is black).
pub fn render_tiled(
    ctx: &GpuContext,
    (scene, gpu_scene): (&rt_core::Scene, &GpuScene),
    options: RenderOptions,
    spp: u32,
    max_tile_bytes: Option<u64>,
    mut progress: impl FnMut(f64) -> bool,
) -> Result<TiledRender> {
    let frame = rt_core::frame::frame_for(scene, gpu_scene)?;
    let adaptive = rt_core::adaptive::Adaptive::of_settings(&scene.settings);
    let limits = ctx.device.limits();
    let max_bytes = max_tile_bytes.unwrap_or(
        limits
            .max_storage_buffer_binding_size
            .min(limits.max_buffer_size),
    );
    let rows_per_tile = tile_rows(
        frame.width,
        frame.height,
        pixel_binding_bytes(&options),
        max_bytes,
    );
    let pixel_count = frame.width as usize * frame.height as usize;
    let mut pixels = vec![[0.0f32; 4]; pixel_count];
    let mut sums = vec![PixelSums::default(); pixel_count];
    let mut counts = adaptive.map(|_| vec![0u32; pixel_count]);
    let mut aovs = options.aovs.then(|| Aovs {
        albedo: vec![[0.0; 3]; pixel_count],
        normal: vec![[0.0; 3]; pixel_count],
        emission: vec![[0.0; 3]; pixel_count],
        hits: rt_core::first_hits::FirstHits::new(pixel_count),
    });
    let mut done_samples = spp;
    let mut begin = 0;
    let mut keep_going = true;
    while begin < frame.height && keep_going {
        let end = (begin + rows_per_tile).min(frame.height);
        let tile_frame = Frame {
            tile_row_begin: begin,
            tile_row_end: end,
            ..frame
        };
        let mut renderer = Renderer::new(ctx, gpu_scene, (tile_frame, adaptive), options)?;
        renderer.render(spp, |done| {
            let fraction = (f64::from(begin)
                + f64::from(end - begin) * f64::from(done) / f64::from(spp))
                / f64::from(frame.height);
            keep_going = progress(fraction);
            keep_going
        })?;
        // Adaptive tiles end when their pixels have all stopped, each at its own count: the image's
        // samples per pixel is then the most any took (its pixels' counts are at most that).
        done_samples = if adaptive.is_some() {
            if begin == 0 {
                renderer.samples_done()
            } else {
                done_samples.max(renderer.samples_done())
            }
        } else {
            done_samples.min(renderer.samples_done())
        };
        let tile = renderer.read_image()?;
        let start = begin as usize * frame.width as usize;
        let range = start..start + tile.pixels.len();
        pixels[range.clone()].copy_from_slice(&tile.pixels);
        sums[range.clone()].copy_from_slice(&tile.sums);
        if let (Some(all), Some(tile)) = (counts.as_mut(), &tile.sample_counts) {
            all[range.clone()].copy_from_slice(tile);
        }
        if let (Some(all), Some(tile)) = (aovs.as_mut(), renderer.read_aovs()?) {
            all.albedo[range.clone()].copy_from_slice(&tile.albedo);
            all.hits.copy_tile(start, &tile.hits);
            all.normal[range.clone()].copy_from_slice(&tile.normal);
            all.emission[range].copy_from_slice(&tile.emission);
        }
        begin = end;
    }
    Ok(TiledRender {
        image: Image {
            width: frame.width,
            height: frame.height,
            samples_per_pixel: done_samples,
            sample_counts: counts,
            pixels,
            sums,
        },
        aovs,
    })
}
