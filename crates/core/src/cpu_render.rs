//! The native CPU backend: the Rust twin of the estimator (`reference`, function for function the
//! kernels' WGSL) run over the image on every core with rayon. Each pixel draws the same sample
//! streams as on the GPU and keeps the same fixed-point sums (`accumulation`), so a CPU image
//! equals a GPU one up to the twins' float rounding, and a CPU render part merges with GPU parts
//! of the same frame (`rt-cli merge`).
//!
//! Work is split into batches of samples over the whole image; a batch is split by rows across
//! threads, and checks for cancellation before each row. A cancelled batch adds nothing, so the
//! sums always hold whole batches: every pixel the same samples.

use std::sync::atomic::{AtomicBool, Ordering};

use rayon::prelude::*;

use crate::accumulation::{PixelSums, add_pixels, add_sample, add_splat, pixel_mean};
use crate::adaptive::{Adaptive, AdaptiveStreams, sums_f64};
use crate::estimator::path::FirstHit;
use crate::estimator::trace_path;
use crate::first_hits::FirstHits;
use crate::gpu_scene::GpuScene;
use crate::gpu_types::Frame;
use crate::part::Guides;

/// About how long one of the CPU backend's batches should take (its drivers size them to it): long
/// enough that a batch's set-up is nothing, short enough for progress, previews and cancelling.
pub const BATCH_DURATION: std::time::Duration = std::time::Duration::from_millis(250);

/// The threads a batch is spread over (rayon's pool: one per core unless `RAYON_NUM_THREADS` says
/// otherwise).
pub fn threads() -> usize {
    rayon::current_num_threads()
}

/// What a batch adds to one pixel.
#[derive(Clone, Copy, Debug, Default)]
struct PixelBatch {
    /// Its even and odd samples' sums (adaptive sampling's two streams).
    sums: [PixelSums; 2],
    /// Sums of the guides over the batch's samples.
    guides: [glam::Vec3; 3],
    /// Sums of coverage and of distance × coverage (`FirstHits`).
    hits: [f32; 2],
    /// Sums of what shadow catchers caught (`FirstHits::caught`).
    caught: glam::Vec3,
    /// The object (+1) the render's first sample met, when this batch took that sample.
    first_object: Option<u32>,
}

impl PixelBatch {
    /// Adds a sample's first hit: its guides, coverage and distance, and (from the render's first
    /// sample) the object it met.
    fn add_first_hit(&mut self, f: &FirstHit, first_of_render: bool) {
        for (sum, v) in self.guides.iter_mut().zip([f.albedo, f.normal, f.emission]) {
            *sum += v;
        }
        self.hits[0] += f.coverage;
        self.hits[1] += f.depth * f.coverage;
        self.caught += glam::Vec3::from(f.caught);
        if first_of_render {
            self.first_object = Some(f.object);
        }
    }
}

/// A frame's samples accumulated on the CPU.
#[derive(Clone, Debug)]
pub struct CpuAccumulation {
    pub width: u32,
    pub height: u32,
    /// The index of the first sample taken (a render part's range start).
    pub first_sample: u32,
    /// Batches' samples so far: every pixel still sampling has samples
    /// `first_sample..first_sample + samples`.
    pub samples: u32,
    /// Per pixel, row-major: the sums of its samples' radiance and squared luminance.
    pub sums: Vec<PixelSums>,
    /// Rays traced by the batches so far (extension and shadow rays, as the kernels count them).
    pub rays: u64,
    /// With adaptive sampling, its streams: even samples in one, odd in the other.
    adaptive: Option<AdaptiveStreams>,
    guides: Option<Guides>,
    /// Coverage, depth and object ids, kept with the guides.
    hits: Option<FirstHits>,
    /// What the batch in progress adds, per pixel (empty between renders' first batches).
    scratch: Vec<PixelBatch>,
    /// With bidirectional path tracing, how its light subpaths choose lights.
    bidirectional: Option<crate::bdpt::LightChoice>,
}

impl CpuAccumulation {
    /// No samples yet of a `frame.width × frame.height` image, starting at sample
    /// `first_sample`; pixels stop by `adaptive`'s rule, and the denoiser's guides are kept when
    /// `guides` asks.
    pub fn new(frame: &Frame, first_sample: u32, adaptive: Option<Adaptive>, guides: bool) -> Self {
        let n = (frame.width * frame.height) as usize;
        CpuAccumulation {
            width: frame.width,
            height: frame.height,
            first_sample,
            samples: 0,
            sums: vec![PixelSums::default(); n],
            rays: 0,
            adaptive: adaptive.map(|rule| AdaptiveStreams::new(rule, frame.width as usize, n)),
            guides: guides.then(|| Guides {
                albedo: vec![[0.0; 3]; n],
                normal: vec![[0.0; 3]; n],
                emission: vec![[0.0; 3]; n],
            }),
            hits: guides.then(|| FirstHits::new(n)),
            scratch: Vec::new(),
            bidirectional: None,
        }
    }

    /// Renders with `integrator`: bidirectional path tracing (`crate::bdpt`) takes every pixel's
    /// samples and splats its light tracing into the sums. An error names what of the scene or
    /// the render it does not do.
    pub fn with_integrator(
        mut self,
        integrator: crate::Integrator,
        scene: &GpuScene,
        frame: &Frame,
    ) -> Result<Self, String> {
        if integrator == crate::Integrator::Path {
            self.bidirectional = None;
            return Ok(self);
        }
        let refused = crate::bdpt::refusal(scene, frame)
            .or(self.adaptive.is_some().then_some("adaptive sampling"))
            .or((frame.clamp_max > 0.0).then_some("the firefly clamp"));
        if let Some(what) = refused {
            return Err(format!(
                "bidirectional path tracing (integrator bdpt) does not do {what} yet: render it \
                 with the path integrator"
            ));
        }
        self.bidirectional = Some(crate::bdpt::LightChoice::new(scene, frame));
        Ok(self)
    }

    /// Takes the next `count` samples of every pixel still sampling, then applies adaptive
    /// sampling's rule. Returns false, having added nothing, when `cancel` is set before the
    /// batch ends.
    pub fn add_batch(
        &mut self,
        scene: &GpuScene,
        frame: &Frame,
        count: u32,
        cancel: &AtomicBool,
    ) -> bool {
        self.add_batch_until(scene, frame, count, &|| cancel.load(Ordering::Relaxed))
    }

    /// `add_batch`, cancelled when `stop` says so (asked before each row).
    pub fn add_batch_until(
        &mut self,
        scene: &GpuScene,
        frame: &Frame,
        count: u32,
        stop: &(dyn Fn() -> bool + Sync),
    ) -> bool {
        let first = self.first_sample + self.samples;
        self.add_samples(scene, frame, first, count, stop)
    }

    /// Takes samples `first..first + count` of every pixel still sampling, wherever they lie:
    /// `--device all` deals a frame's samples out to the CPU and the GPU by ranges, so the CPU's
    /// share is not one run from `first_sample` (`samples` then counts them, not where they
    /// end). Returns false, having added nothing, when `stop` says so before a row.
    pub fn add_samples(
        &mut self,
        scene: &GpuScene,
        frame: &Frame,
        first: u32,
        count: u32,
        stop: &(dyn Fn() -> bool + Sync),
    ) -> bool {
        if let Some(choice) = self.bidirectional.take() {
            let done = self.add_bidirectional(scene, frame, &choice, first, count, stop);
            self.bidirectional = Some(choice);
            return done;
        }
        let width = self.width as usize;
        let stopped = self.adaptive.as_ref().map(|a| a.stopped());
        let keep_guides = self.guides.is_some();
        let first_of_render = self.first_sample;
        // Kept between batches, and zero between them: no fresh pages to fault in per batch.
        let mut scratch = std::mem::take(&mut self.scratch);
        scratch.resize(self.sums.len(), PixelBatch::default());
        let rays: Option<Vec<u64>> = scratch
            .par_chunks_mut(width.max(1))
            .enumerate()
            .map(|(y, row)| {
                if stop() {
                    return None;
                }
                let mut rays = 0;
                for (x, pixel) in row.iter_mut().enumerate() {
                    if stopped.is_some_and(|stopped| stopped[y * width + x] != 0) {
                        continue;
                    }
                    for s in first..first + count {
                        let path = trace_path(scene, frame, x as u32, y as u32, s, keep_guides);
                        rays += u64::from(path.rays);
                        // A sample that is not finite (or absurdly large) is dropped, as the
                        // kernels drop it: it adds zero and still counts.
                        add_sample(&mut pixel.sums[(s & 1) as usize], path.radiance.to_array());
                        if let Some(f) = path.first_hit {
                            pixel.add_first_hit(&f, s == first_of_render);
                        }
                    }
                }
                Some(rays)
            })
            .collect();
        let Some(rays) = rays else {
            scratch.fill(PixelBatch::default());
            self.scratch = scratch;
            return false;
        };
        self.rays += rays.iter().sum::<u64>();
        let before = self.samples_taken();
        let mut streams_added = self
            .adaptive
            .as_ref()
            .map(|_| Vec::with_capacity(scratch.len()));
        for (i, slot) in scratch.iter_mut().enumerate() {
            let add = std::mem::take(slot);
            let batch = add_pixels(&add.sums[0], &add.sums[1]);
            self.sums[i] = add_pixels(&self.sums[i], &batch);
            if let Some(streams_added) = &mut streams_added {
                streams_added.push(add.sums.map(|s| sums_f64(&s)));
            }
            if before[i] == self.samples || self.adaptive.is_none() {
                self.fold_first_hits(i, &add, before[i], count);
            }
        }
        self.scratch = scratch;
        self.samples += count;
        if let (Some(streams), Some(added)) = (&mut self.adaptive, streams_added) {
            let odd = (first..first + count).filter(|s| s & 1 == 1).count() as u32;
            streams.add([count - odd, odd], |i| added[i]);
            streams.settle();
        }
        true
    }

    /// `add_samples` by bidirectional path tracing: each row's samples in parallel, their splats
    /// added after (fixed-point sums: the order does not matter).
    fn add_bidirectional(
        &mut self,
        scene: &GpuScene,
        frame: &Frame,
        choice: &crate::bdpt::LightChoice,
        first: u32,
        count: u32,
        stop: &(dyn Fn() -> bool + Sync),
    ) -> bool {
        let walks = crate::bdpt::Walks {
            scene,
            frame,
            choice,
        };
        let width = self.width as usize;
        let guides = self.guides.is_some();
        let first_of_render = self.first_sample;
        let mut batch = vec![PixelBatch::default(); self.sums.len()];
        type Splats = Vec<((u32, u32), glam::Vec3)>;
        let rows: Option<Vec<(u64, Splats)>> = batch
            .par_chunks_mut(width.max(1))
            .enumerate()
            .map_init(crate::bdpt::Scratch::default, |scratch, (y, row)| {
                if stop() {
                    return None;
                }
                let (mut rays, mut splats) = (0, Vec::new());
                for (x, pixel) in row.iter_mut().enumerate() {
                    for s in first..first + count {
                        let (x, y) = (x as u32, y as u32);
                        let sample = walks.sample(x, y, s, guides, scratch, &mut splats);
                        rays += u64::from(sample.rays);
                        add_sample(&mut pixel.sums[0], sample.radiance.to_array());
                        if let Some(f) = sample.first_hit {
                            pixel.add_first_hit(&f, s == first_of_render);
                        }
                    }
                }
                Some((rays, splats))
            })
            .collect();
        let Some(rows) = rows else {
            return false;
        };
        for (rays, splats) in rows {
            self.rays += rays;
            for ((x, y), value) in splats {
                let i = y as usize * width + x as usize;
                if let Some(pixel) = batch.get_mut(i) {
                    add_splat(&mut pixel.sums[0], value.to_array());
                }
            }
        }
        for (i, add) in batch.iter().enumerate() {
            self.sums[i] = add_pixels(&self.sums[i], &add.sums[0]);
            self.fold_first_hits(i, add, self.samples, count);
        }
        self.samples += count;
        true
    }

    /// Folds a batch's sums of guides and first hits at pixel `i` into their running means over
    /// the pixel's own samples: `before` so far, `count` in the batch.
    fn fold_first_hits(&mut self, i: usize, add: &PixelBatch, before: u32, count: u32) {
        let n = before as f32;
        let total = n + count as f32;
        if let Some(g) = self.guides.as_mut() {
            for (plane, sum) in [&mut g.albedo, &mut g.normal, &mut g.emission]
                .into_iter()
                .zip(add.guides)
            {
                let mean = glam::Vec3::from(plane[i]);
                plane[i] = ((mean * n + sum) / total).to_array();
            }
        }
        if let Some(h) = self.hits.as_mut() {
            for (plane, sum) in [&mut h.coverage, &mut h.depth_weighted]
                .into_iter()
                .zip(add.hits)
            {
                plane[i] = (plane[i] * n + sum) / total;
            }
            let caught = glam::Vec3::from(h.caught[i]);
            h.caught[i] = ((caught * n + add.caught) / total).to_array();
            if let Some(object) = add.first_object {
                h.object[i] = object;
            }
        }
    }

    /// Each pixel's sample count: with adaptive sampling, the count its value's variance
    /// corresponds to (`AdaptiveStreams::value`).
    pub fn counts(&self) -> Vec<u32> {
        match &self.adaptive {
            None => vec![self.samples; self.sums.len()],
            Some(streams) => streams.sums_and_counts().1,
        }
    }

    /// The image's sums and counts: the samples' sums, or with adaptive sampling the sums its
    /// values stand for (`AdaptiveStreams::sums_and_counts`).
    pub fn image_sums(&self) -> (Vec<PixelSums>, Vec<u32>) {
        match &self.adaptive {
            None => (self.sums.clone(), self.counts()),
            Some(streams) => streams.sums_and_counts(),
        }
    }

    /// The samples each pixel took.
    pub fn samples_taken(&self) -> Vec<u32> {
        match &self.adaptive {
            None => vec![self.samples; self.sums.len()],
            Some(streams) => streams.samples_taken(),
        }
    }

    /// The pixels still taking samples.
    pub fn active_pixels(&self) -> usize {
        match &self.adaptive {
            None => self.sums.len(),
            Some(streams) => streams.active(),
        }
    }

    /// Whether adaptive sampling gives pixels counts of their own.
    pub fn adaptive(&self) -> bool {
        self.adaptive.is_some()
    }

    /// Each pixel's mean radiance (rgb) and mean squared luminance (a) over its own samples
    /// (with adaptive sampling, as its two streams keep them).
    pub fn pixels(&self) -> Vec<[f32; 4]> {
        let (sums, counts) = self.image_sums();
        sums.iter()
            .zip(counts)
            .map(|(s, n)| pixel_mean(s, n))
            .collect()
    }

    /// The denoiser's guides (running means over each pixel's samples), when kept.
    pub fn guides(&self) -> Option<&Guides> {
        self.guides.as_ref()
    }

    /// Coverage, depth and object ids (kept with the guides).
    pub fn first_hits(&self) -> Option<&FirstHits> {
        self.hits.as_ref()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::estimator::radiance;

    /// A closed grey room lit by a lamp in its ceiling, seen from inside (the loaders, and so
    /// the built-in Cornell box, are rt-io's, above this crate).
    fn cornell(width: u32, height: u32) -> (GpuScene, Frame) {
        use crate::scene::{Object, RenderSettings, Scene, Transform};
        use crate::shapes::{cuboid, quad};
        use glam::Vec3;
        let object = |name: &str, mesh, material| Object {
            shadow_catcher: false,
            animation_node: None,
            name: name.into(),
            mesh: std::sync::Arc::new(mesh),
            material,
            transform: Transform::default(),
        };
        let scene = Scene {
            objects: vec![
                object(
                    "room",
                    cuboid(Vec3::splat(-1.0), Vec3::ONE, true),
                    crate::Material::Lambertian {
                        albedo: [0.6, 0.5, 0.4],
                        texture: None,
                    },
                ),
                object(
                    "lamp",
                    quad(Vec3::new(0.0, 0.99, 0.0), Vec3::NEG_Y, 0.6),
                    crate::Material::Emissive {
                        color: [1.0; 3],
                        intensity: 5.0,
                    },
                ),
            ],
            textures: Vec::new(),
            camera: crate::Camera {
                from: [0.0, 0.0, 0.9],
                to: [0.0, 0.0, -1.0],
                ..Default::default()
            },
            ambient: [0.0; 3],
            settings: RenderSettings {
                width,
                height,
                max_depth: 4,
                ..Default::default()
            },
            lights: Vec::new(),
            environment: None,
            fog: Default::default(),
            animation: None,
        };
        let gpu = GpuScene::build(&scene).unwrap();
        let frame = crate::frame::frame_for(&scene, &gpu).unwrap();
        (gpu, frame)
    }

    /// The sums do not depend on how samples are batched (exact fixed-point addition), a
    /// cancelled batch adds nothing, and the means are the reference renderer's.
    #[test]
    fn batches_sum_exactly_and_a_cancelled_batch_adds_nothing() {
        let (scene, frame) = cornell(12, 9);
        let go = AtomicBool::new(false);
        let mut one_by_one = CpuAccumulation::new(&frame, 3, None, true);
        assert!(one_by_one.add_batch(&scene, &frame, 1, &go));
        assert!(one_by_one.add_batch(&scene, &frame, 2, &go));
        let mut at_once = CpuAccumulation::new(&frame, 3, None, true);
        assert!(at_once.add_batch(&scene, &frame, 3, &go));
        assert_eq!(one_by_one.sums, at_once.sums);
        assert_eq!(one_by_one.samples, 3);
        let before = at_once.clone();
        let stop = AtomicBool::new(true);
        assert!(!at_once.add_batch(&scene, &frame, 1, &stop));
        assert_eq!(
            (&at_once.sums, at_once.samples),
            (&before.sums, before.samples)
        );
        // Samples 3..6 of every pixel, as `estimator::radiance` gives them.
        let expected = |x: u32, y: u32| {
            (3..6).fold(glam::Vec3::ZERO, |s, i| {
                s + radiance(&scene, &frame, x, y, i)
            }) / 3.0
        };
        for (i, p) in before.pixels().iter().enumerate() {
            let e = expected(i as u32 % 12, i as u32 / 12);
            for c in 0..3 {
                assert!(
                    (p[c] - e[c]).abs() <= 1e-5 * e[c].abs().max(1.0),
                    "pixel {i}"
                );
            }
        }
        assert!(before.pixels().iter().any(|p| p[0] > 0.0), "all black");
    }
}
