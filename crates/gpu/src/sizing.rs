//! Dispatch sizing: how many rows and samples per pixel one dispatch (or one wave) takes, so that
//! it runs about the target time and stays inside lavapipe's loop budget.

use std::time::Duration;

use rt_core::GpuScene;
use rt_core::gpu_types::Frame;

/// Mesa's lavapipe (22.3 and 25.0; 25.1 removed it) runs at most 65,535 loop iterations per
/// invocation, over all loops, and then silently cuts every loop short. Keep the estimated
/// iterations of one dispatch well under it.
pub const LOOP_BUDGET: u32 = 16_384;

/// The most samples per pixel one megakernel dispatch may take within `LOOP_BUDGET` (also bounds
/// a wave's samples), from the BVH depth, the max depth and the lights.
pub fn loop_cap(scene: &GpuScene, frame: &Frame) -> u32 {
    // Each path segment traces one ray, a shadow ray for NEE and one per delta light.
    let rays_per_segment = 2 + scene.delta_lights.len() as u32;
    // Loop iterations per ray: BVH2 visits ~2 nodes a level; the wide BVH visits fewer nodes but
    // each may test up to 24 triangles in its inner loop, so count it more generously.
    let depth = scene.bvh_depth as u32;
    let steps_per_ray = match scene.layout {
        rt_core::bvh::BvhLayout::Bvh2 => 2 * depth + 8,
        rt_core::bvh::BvhLayout::Cwbvh => 4 * depth + 24,
    };
    let mut steps_per_segment = steps_per_ray.saturating_mul(rays_per_segment);
    if frame.sampler == 1 {
        // Sobol's second dimension loops over the sample index's bits: up to 20 (a million
        // samples) for each of the ~4 such draws of a segment.
        steps_per_segment = steps_per_segment.saturating_add(80);
    }
    (LOOP_BUDGET
        / frame
            .max_depth
            .max(1)
            .saturating_mul(steps_per_segment)
            .max(1))
    .clamp(1, 64)
}

/// (rows, samples per pixel) of the next dispatches of a tile of `tile_rows` rows, given the
/// measured seconds per (sample x row): whole-tile dispatches with as many samples as fit the
/// target (at most `loop_cap`), or one sample in bands of rows when a whole tile would take
/// longer. A wave's paths must also fit its queues (`wave_capacity`). `None` without a
/// measurement.
pub fn dispatch_shape(
    seconds_per_sample_row: f64,
    target: Duration,
    width: u32,
    tile_rows: u32,
    loop_cap: u32,
    wave_capacity: Option<u32>,
) -> Option<(u32, u32)> {
    if seconds_per_sample_row.is_nan() || seconds_per_sample_row <= 0.0 {
        return None;
    }
    let budget = target.as_secs_f64() / seconds_per_sample_row;
    let height = f64::from(tile_rows);
    let (mut rows, mut samples) = if budget >= height {
        (tile_rows, ((budget / height) as u32).clamp(1, loop_cap))
    } else {
        (1.max((budget as u32).min(tile_rows)), 1)
    };
    if let Some(capacity) = wave_capacity {
        let row_paths = width.max(1);
        rows = rows.min((capacity / row_paths).max(1));
        let band = rows * row_paths;
        samples = samples.min((capacity / band).max(1));
    }
    Some((rows, samples))
}

#[cfg(test)]
mod tests {
    use super::*;

    // Powers of two, so that the divisions are exact.
    const TARGET: Duration = Duration::from_secs(1);

    #[test]
    fn a_slow_kernel_gets_bands_of_rows_and_a_fast_one_more_samples() {
        // 1/4 s per sample and row: 4 rows of one sample fit the target.
        assert_eq!(
            dispatch_shape(0.25, TARGET, 64, 128, 64, None),
            Some((4, 1))
        );
        // 1/4096 s per sample and row: the whole 128-row tile, 32 samples.
        let fast = 1.0 / 4096.0;
        assert_eq!(
            dispatch_shape(fast, TARGET, 64, 128, 64, None),
            Some((128, 32))
        );
        // ... but never more than the loop cap.
        assert_eq!(
            dispatch_shape(fast, TARGET, 64, 128, 8, None),
            Some((128, 8))
        );
        // Always at least one row and one sample, even when one row is too slow.
        assert_eq!(
            dispatch_shape(10.0, TARGET, 64, 128, 64, None),
            Some((1, 1))
        );
        assert_eq!(dispatch_shape(0.0, TARGET, 64, 128, 64, None), None);
        assert_eq!(dispatch_shape(f64::NAN, TARGET, 64, 128, 64, None), None);
    }

    #[test]
    fn a_wave_fits_its_queues() {
        let fast = 1.0 / 4096.0;
        // 8,192 paths of room: the 128 rows of 64 pixels at one sample, not 32.
        assert_eq!(
            dispatch_shape(fast, TARGET, 64, 128, 64, Some(8_192)),
            Some((128, 1))
        );
        // Room for fewer rows than the target asks: the band shrinks.
        assert_eq!(
            dispatch_shape(fast, TARGET, 64, 128, 64, Some(640)),
            Some((10, 1))
        );
        // Less room than a row still runs a row.
        assert_eq!(
            dispatch_shape(fast, TARGET, 64, 128, 64, Some(10)),
            Some((1, 1))
        );
    }
}
