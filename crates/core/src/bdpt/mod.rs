//! Bidirectional path tracing (Veach 1997, ch. 10; pbrt-v4's `BDPTIntegrator` is the model read):
//! per pixel sample, a camera subpath z_0 … z_{t−1} from the lens and a light subpath
//! y_0 … y_{s−1} from a light (an emitter point, the environment, a point, spot or sun light,
//! chosen by flux), and every way of joining their prefixes:
//!   I ≈ Σ_{s,t} w_{s,t} C*_{s,t},  s + t − 1 ≤ max_depth segments,
//! where C*_{s,t} is the strategy's unweighted contribution (`connect`) and w_{s,t} its
//! power-heuristic MIS weight (`mis`). Light tracing (t = 1) lands anywhere on the film: those
//! contributions are splats, summed into their pixels like samples, and the image is the pixel's
//! own sum plus its splats over its sample count (one light subpath per camera sample).
//!
//! Caustics, light that reaches the camera only through specular surfaces from a small or delta
//! light, come from strategies t = 1 and t = 2 that the path tracer lacks: a sun through a glass
//! sphere focuses onto the floor here, where camera paths alone find nothing; so does the sun of
//! an environment map, from which light subpaths start as from any light.
//!
//! This is the CPU backend's (`cpu_render`); the GPU kernels have no twin yet, and `refusal` names
//! what it does not do (media, dispersion, projections other than perspective, render regions).
//! Russian roulette plays as in the path tracer (`frame.roulette_from_depth`), on a light subpath
//! with its throughput taken relative to its start.

mod connect;
mod importance;
pub mod lights;
mod mis;
mod point;
mod subpath;
#[cfg(test)]
mod tests;
mod vertex;

use glam::Vec3;

pub use connect::Contribution;
pub use lights::LightChoice;
pub use subpath::Walks;
use vertex::Vertex;

use crate::estimator::camera::film_pixel;
use crate::estimator::path::FirstHit;
use crate::gpu_scene::GpuScene;
use crate::gpu_types::{Frame, PbrLobe};
use crate::material_kind::MaterialKind;
use crate::math::medium::is_vacuum;
use crate::math::rng::Rng;

/// A stream number the light subpaths' random numbers are drawn with, apart from the camera's.
const LIGHT_STREAM: u32 = 0x6c69_6768;

/// One pixel sample's result: what it adds to its own pixel (the light-tracing splats it adds
/// anywhere go elsewhere), and what its camera ray met first when asked (the denoiser's guides,
/// alpha, depth and object: the same camera ray, so the same values, as the path tracer's).
#[derive(Clone, Debug, Default)]
pub struct BdptSample {
    pub radiance: Vec3,
    pub rays: u32,
    pub first_hit: Option<FirstHit>,
}

/// The subpaths a thread reuses from sample to sample.
#[derive(Default)]
pub struct Scratch {
    camera: Vec<Vertex>,
    light: Vec<Vertex>,
}

impl Walks<'_> {
    /// Pixel (x, y)'s sample `sample`: its own radiance (all strategies with t ≥ 2), with the
    /// light-tracing splats pushed onto `splats`; with `guides`, its first hit.
    pub fn sample(
        &self,
        x: u32,
        y: u32,
        sample: u32,
        guides: bool,
        scratch: &mut Scratch,
        splats: &mut Vec<((u32, u32), Vec3)>,
    ) -> BdptSample {
        let mut camera_path = std::mem::take(&mut scratch.camera);
        let mut light_path = std::mem::take(&mut scratch.light);
        let camera_state = self.camera_subpath(x, y, sample, guides, &mut camera_path);
        let mut rng = camera_state.rng;
        let light_rng = Rng::new(
            film_pixel(self.frame, x, y),
            sample,
            self.frame.seed ^ LIGHT_STREAM,
        );
        let light_state = self.light_subpath(light_rng, &mut light_path);
        let mut rays = camera_state.rays + light_state.rays;
        let mut radiance = Vec3::ZERO;
        let max_segments = self.frame.max_depth as usize;
        for t in 1..=camera_path.len() {
            for s in 0..=light_path.len() {
                if s + t < 2 || (s == 1 && t == 1) || s + t - 1 > max_segments {
                    continue;
                }
                match self.connect(&light_path, &camera_path, s, t, &mut rng, &mut rays) {
                    Some((Contribution::Pixel(c), w)) => radiance += c * w,
                    Some((Contribution::Splat { pixel, value }, w)) => {
                        splats.push((pixel, value * w))
                    }
                    None => {}
                }
            }
        }
        scratch.camera = camera_path;
        scratch.light = light_path;
        BdptSample {
            radiance,
            rays,
            first_hit: camera_state.first_hit,
        }
    }
}

/// What in `scene` and `frame` bidirectional path tracing does not render, named for the user;
/// `None` where it renders all of it.
pub fn refusal(scene: &GpuScene, frame: &Frame) -> Option<&'static str> {
    if scene.features.media || !is_vacuum(&frame.fog) {
        return Some("participating media (fog, or a material's volume)");
    }
    if frame.projection != 0 {
        return Some("a camera projection other than perspective");
    }
    if frame.film_width != frame.width || frame.film_height != frame.height {
        return Some("rendering a region, rows or shards of the image");
    }
    let dispersive = scene.materials.iter().any(|m| {
        m.kind == MaterialKind::Pbr.tag() && {
            let lobe = m.lobe_of::<PbrLobe>();
            lobe.dispersion > 0.0 && lobe.transmission > 0.0
        }
    });
    if dispersive {
        return Some("dispersion (KHR_materials_dispersion)");
    }
    let catcher = |m: &crate::gpu_types::Material| {
        crate::estimator::shadow_catcher::catches_shadows(frame, m.flags)
    };
    if scene.materials.iter().any(catcher) {
        return Some("shadow catchers");
    }
    None
}
