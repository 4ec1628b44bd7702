//! The estimator's Rust twin: a path tracer implementing, function for function, the same
//! estimator as the GPU kernels (`shaders/wavefront.wgsl`, `shaders/trace.wgsl`), with the same
//! random-number streams and the same data (`GpuScene`, `Frame`). It is the native CPU backend's
//! estimator (`crate::cpu_render` runs it over the image on every core), the raster preview's
//! ray caster for bounce light, and the tests' ground truth for the GPU.
//!
//! The estimator is the unidirectional path-tracing sum
//!   L ≈ Σ_{k=0}^{max_depth−1} β_k L_e(x_k → x_{k−1}),  β_{k+1} = β_k · f(x_k) cosθ / p(ω),
//! where each BSDF is sampled so that f·cosθ/p is its albedo (see `material::Material`), L_e is the
//! front-face emission of the surface hit (or the ambient radiance for a ray that leaves the scene),
//! and a path stops at an emitter, on absorption, or after `max_depth` segments.
//!
//! With next-event estimation (`frame.emitter_count > 0`), each diffuse vertex x also samples a point
//! y on an emitter (by power, `emitters::build_emitters`, or through the light tree,
//! `light_tree`) and adds, if y is visible from x,
//!   β f(x) L_e(y) cosθ_x · w_light / p_light,  p_light = p_A(y) · |x−y|² / cosθ_y,
//! and an emitter reached by BSDF sampling from a diffuse vertex counts with weight w_bsdf, where
//! w_light and w_bsdf are the power-heuristic weights p²/(p_light² + p_bsdf²), p_bsdf = cosθ/π.
//! Camera rays and rays leaving specular surfaces (metal, glass) count emitters with weight 1.
//!
//! Russian roulette (from segment `frame.roulette_from_depth` on): after scattering, the path goes on
//! with probability q = min(1, max component of β·η²) and β is divided by q, so E[β'] = β
//! (unbiased); η² is the product over the refractions so far (`PathState::eta_scale`), which
//! undoes the 1/η² that radiance takes inside glass.
//!
//! Each file is the twin of the WGSL file of its stem beside it (`bvh.rs` of `bvh.wgsl`,
//! `cwbvh.rs` of `cwbvh.wgsl`, `camera.rs` of `camera.wgsl`, `path.rs` of `path.wgsl`, `light.rs` of `light.wgsl`, `light_tree.rs` of
//! `light_tree.wgsl`, `shading.rs` of `shading.wgsl`, `media.rs` of `media.wgsl`, `shadow_catcher.rs` of `shadow_catcher.wgsl`, `surface.rs` of `surface.wgsl`, `texture.rs`
//! of `texture.wgsl`), exported
//! as its `WGSL` for `rt_gpu::shaders` to compose; the math they share with the rest of rt-core
//! (random numbers, sampling, intersection, microfacets, the PBR BSDF) lives in `crate::math`, each
//! file likewise beside its WGSL twin.
//! `tests/reference/` checks the GPU against this twin per pixel, in lockstep at a few
//! samples and statistically at many.

pub mod bvh;
pub mod camera;
pub mod cwbvh;
pub(crate) mod hit;
pub mod instance_bvh;
pub mod instances;
pub mod light;
pub mod light_tree;
pub mod media;
pub mod path;
pub mod shading;
pub mod shadow_catcher;
pub mod surface;
pub mod texture;

pub use camera::{camera_ray, pixel_centre_ray};
pub use hit::trace_brute_force;
pub use light::{
    LightSample, ShadowMedia, delta_lights_at, direct_light, power_heuristic, sample_light,
};
pub use path::{FirstHit, radiance, trace_path};
pub use surface::{PbrInputs, Surface, SurfaceSample};
pub use texture::{Slot, alpha_coin, base_color_texture, coverage, stops_ray, wrap_index};

use glam::Vec3;

use crate::gpu_scene::GpuScene;
use crate::gpu_types::{Frame, Hit};

/// Nearest hit through the scene's BVH, as `intersect_scene` computes it in the kernel: the
/// traversal of the scene's layout, as `rt_gpu::shaders` composes `bvh.wgsl` or `cwbvh.wgsl`. It
/// sits here, above both traversals, so that they depend only on `hit.rs` and not on each other.
pub fn trace(scene: &GpuScene, origin: Vec3, direction: Vec3, t_max: f32) -> Hit {
    instance_bvh::intersect_scene(scene, origin, direction, t_max, false)
}

/// Whether anything lies on the segment from `origin` along unit `direction` up to `distance`:
/// the traversal stops at the first hit it finds, as the kernels' shadow rays do.
pub fn occluded(scene: &GpuScene, origin: Vec3, direction: Vec3, distance: f32) -> bool {
    instance_bvh::intersect_scene(scene, origin, direction, distance, true).triangle != hit::MISS
}

/// Per-pixel mean and unbiased sample variance of each channel.
pub struct ReferenceImage {
    pub width: u32,
    pub height: u32,
    pub mean: Vec<[f32; 3]>,
    pub variance: Vec<[f32; 3]>,
}

/// Renders samples `frame.sample_offset..frame.sample_offset + spp` of every pixel (needs
/// `spp >= 2` for a variance).
pub fn render(scene: &GpuScene, frame: &Frame, spp: u32) -> ReferenceImage {
    let n = (frame.width * frame.height) as usize;
    let mut mean = vec![[0.0f32; 3]; n];
    let mut variance = vec![[0.0f32; 3]; n];
    for y in 0..frame.height {
        for x in 0..frame.width {
            let i = (y * frame.width + x) as usize;
            let (mut sum, mut sum_sq) = (glam::DVec3::ZERO, glam::DVec3::ZERO);
            for s in 0..spp {
                let l = radiance(scene, frame, x, y, frame.sample_offset + s).as_dvec3();
                sum += l;
                sum_sq += l * l;
            }
            let m = sum / spp as f64;
            let var = (sum_sq - sum * m) / (spp.max(2) - 1) as f64;
            mean[i] = m.as_vec3().to_array();
            variance[i] = var.max(glam::DVec3::ZERO).as_vec3().to_array();
        }
    }
    ReferenceImage {
        width: frame.width,
        height: frame.height,
        mean,
        variance,
    }
}
