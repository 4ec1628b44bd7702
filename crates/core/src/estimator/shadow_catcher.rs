//! Shadow catchers (Cycles' Object ▸ Shadow Catcher), as `shadow_catcher.wgsl` beside it (its
//! twin) computes them. On a transparent film a catcher object is seen as only the shadows and
//! the reflections of other objects it receives, over the transparent background, for
//! compositing rendered objects into a photograph.
//!
//! A camera ray that meets a catcher first records, per sample, the irradiance there with and
//! without the scene's shadows, from one light sample (emitters and the environment map as
//! next-event estimation samples them), the delta lights, and a cosine-sampled direction for a
//! uniform ambient light (which no light sample finds):
//!   E_lit = Σ L cosθ V / p,   E_free = Σ L cosθ / p   (luminance; V the shadow ray's visibility).
//! The pixel's alpha over its samples is then (`crate::first_hits::FirstHits::alpha`)
//!   α = coverage − s · Ē_lit / Ē_free,
//! s the share of its samples that met a catcher first: 1 − the shadowed irradiance ratio on a
//! whole catcher pixel, a ratio of means (as Cycles' shadow catcher pass) rather than a mean of
//! per-sample ratios, which would be 0/0 wherever a light sample leaves nothing. Irradiance, not
//! the catcher's BSDF: the shadow is the light that did not arrive, whatever the surface is.
//!
//! The path then goes on from the catcher by its BSDF as a *matte* path (`PathState::matte`): it
//! adds nothing until it meets an object that is not a catcher (the background, emitters and the
//! direct light are in the ratio, so the film keeps them out), and from there on adds its light as
//! any path does, which is the catcher's reflection of that object, premultiplied. What the
//! ratio leaves out: media along the shadow rays, and a catcher's own shadows on itself count as
//! shadows (the unshadowed irradiance tests no visibility at all).

/// The WGSL twin of this module, `shadow_catcher.wgsl` beside it (composed into the kernels by
/// `rt_gpu::shaders`).
pub const WGSL: &str = include_str!("shadow_catcher.wgsl");

use glam::Vec3;

use super::light::{delta_light_incidence, sample_light};
use super::occluded;
use crate::gpu_scene::GpuScene;
use crate::gpu_types::{Frame, SHADOW_CATCHER};
use crate::light_kind::LightTag;
use crate::light_tree::in_tree;
use crate::math::intersect::offset_ray_origin;
use crate::math::rng::Rng;
use crate::math::sampling::{luminance, sample_cosine_hemisphere};

/// Whether the surface of material flags `flags` is a shadow catcher on this frame's film (only a
/// transparent film has a background to show through it; on an opaque one it renders as its
/// material).
pub fn catches_shadows(frame: &Frame, flags: u32) -> bool {
    frame.transparent != 0 && flags & SHADOW_CATCHER != 0
}

/// The irradiance luminance at `p` (geometric normal `ng`, facing the camera) with and without
/// the scene's shadows: `[E_lit, E_free]` of one sample (the module's equation). Draws four
/// random numbers where lights are sampled and two more under a uniform ambient light; adds the
/// shadow rays it traces to `rays`.
pub fn catcher_irradiance(
    scene: &GpuScene,
    frame: &Frame,
    p: Vec3,
    ng: Vec3,
    rng: &mut Rng,
    rays: &mut u32,
) -> [f32; 2] {
    let mut e = [0.0f32; 2];
    let mut add = |irradiance: f32, origin: Vec3, dir: Vec3, distance: f32, rays: &mut u32| {
        *rays += 1;
        e[1] += irradiance;
        if !occluded(scene, origin, dir, distance) {
            e[0] += irradiance;
        }
    };
    let lights_sampled =
        frame.emitter_count > 0 || frame.env_pick > 0.0 || frame.light_sampler == 1;
    if lights_sampled && let Some(light) = sample_light(scene, frame, p, ng, false, rng) {
        let cos = light.direction.dot(ng);
        let irradiance = luminance(light.radiance_over_pdf) * cos;
        if cos > 0.0 && irradiance > 0.0 {
            add(
                irradiance,
                light.origin,
                light.direction,
                light.distance,
                rays,
            );
        }
    }
    let above = offset_ray_origin(p, ng, frame.offset_scale);
    for light in &scene.delta_lights {
        if light.kind == LightTag::None.tag() || (frame.light_sampler == 1 && in_tree(light)) {
            continue;
        }
        let (dir, distance, irradiance) = delta_light_incidence(light, above);
        let cos = dir.dot(ng);
        let irradiance = luminance(irradiance) * cos;
        if cos > 0.0 && irradiance > 0.0 {
            add(irradiance, above, dir, distance, rays);
        }
    }
    // A uniform ambient light L: E = π L, a cosine-distributed direction's estimate.
    let ambient = luminance(Vec3::from(frame.ambient));
    if frame.env_width == 0 && ambient > 0.0 {
        let dir = sample_cosine_hemisphere(ng, rng);
        if dir.dot(ng) > 0.0 {
            add(std::f32::consts::PI * ambient, above, dir, 3.0e38, rays);
        }
    }
    e
}

#[cfg(test)]
mod tests;
