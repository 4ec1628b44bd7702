//! The two random walks: a camera subpath from the lens, and a light subpath from a light, each
//! vertex keeping its throughput and the densities MIS needs (`Vertex::pdf_fwd`, and the
//! `pdf_rev` that the next vertex's sampling gives its predecessor).

use glam::Vec3;

use super::importance::direction_pdf;
use super::lights::{
    LightChoice, Picked, delta_direction, disk_origin, emitter_point, intensity, is_sun,
    sample_environment,
};
use super::point::SurfacePoint;
use super::vertex::{Point, Vertex};
use crate::estimator::hit::MISS;
use crate::estimator::light::escaped;
use crate::estimator::path::{FirstHit, PathState, start_path};
use crate::estimator::trace;
use crate::gpu_scene::GpuScene;
use crate::gpu_types::Frame;
use crate::math::intersect::offset_ray_origin;
use crate::math::rng::Rng;
use crate::math::sampling::sample_cosine_hemisphere;

/// The scene and the light choice the walks share.
pub struct Walks<'a> {
    pub scene: &'a GpuScene,
    pub frame: &'a Frame,
    pub choice: &'a LightChoice,
}

impl Walks<'_> {
    /// Pixel (x, y)'s camera subpath of sample `sample` into `path` (at most `max_depth` + 1
    /// vertices: the lens and what the segments meet). Returns the path's state (its random
    /// numbers, rays traced and, with `guides`, its first hit as the path tracer records it).
    pub fn camera_subpath(
        &self,
        x: u32,
        y: u32,
        sample: u32,
        guides: bool,
        path: &mut Vec<Vertex>,
    ) -> PathState {
        path.clear();
        let mut state = start_path(self.frame, x, y, sample);
        state.first_hit = guides.then(FirstHit::default);
        if state.beta == Vec3::ZERO {
            return state;
        }
        path.push(Vertex::new(
            Point::Camera,
            state.origin,
            Vec3::ZERO,
            Vec3::ONE,
            0.0,
        ));
        let pdf = direction_pdf(self.frame, state.origin, state.direction);
        let max = self.frame.max_depth as usize + 1;
        self.walk(&mut state, pdf, false, max, path);
        state
    }

    /// A light subpath into `path` (at most `max_depth` vertices), drawing from `rng`.
    pub fn light_subpath(&self, rng: Rng, path: &mut Vec<Vertex>) -> PathState {
        path.clear();
        let mut state = PathState {
            origin: Vec3::ZERO,
            direction: Vec3::Z,
            beta: Vec3::ZERO,
            channel: 0,
            radiance: Vec3::ZERO,
            prev_bsdf_pdf: 0.0,
            tree_normal: 0,
            media: 0,
            eta_scale: 1.0,
            depth: 0,
            matte: false,
            rng,
            first_hit: None,
            rays: 0,
        };
        let (scene, frame, choice) = (self.scene, self.frame, self.choice);
        if !choice.any() || frame.max_depth == 0 {
            return state;
        }
        let Some(picked) = choice.pick(scene, frame, &mut state.rng) else {
            return state;
        };
        let max = frame.max_depth as usize;
        match picked {
            Picked::Triangle { index, b, per_area } => {
                let n = {
                    let t = &scene.triangles[index as usize];
                    let (v0, v1, v2) = (Vec3::from(t.v0), Vec3::from(t.v1), Vec3::from(t.v2));
                    (v1 - v0).cross(v2 - v0).normalize()
                };
                let w = sample_cosine_hemisphere(n, &mut state.rng);
                let (y, n, le) = emitter_point(scene, index, b, w);
                let cos = w.dot(n);
                if le == Vec3::ZERO || cos <= 0.0 || per_area <= 0.0 {
                    return state;
                }
                path.push(Vertex::new(Point::Emitter { index, b }, y, n, le, per_area));
                // β = L_e cosθ / (p_A · cosθ/π)
                state.beta = le * std::f32::consts::PI / per_area;
                state.origin = offset_ray_origin(y, n, frame.offset_scale);
                state.direction = w;
                self.walk(
                    &mut state,
                    cos * std::f32::consts::FRAC_1_PI,
                    true,
                    max,
                    path,
                );
            }
            Picked::Environment { u, pick } => {
                let (toward, le, pdf_dir) = sample_environment(scene, frame, u);
                if pdf_dir.is_nan() || pdf_dir <= 0.0 || le == Vec3::ZERO {
                    return state;
                }
                let (origin, pdf_pos) = disk_origin(choice, -toward, &mut state.rng);
                let per_solid_angle = pick * pdf_dir;
                let point = Point::Environment { le, toward };
                path.push(Vertex::new(point, origin, Vec3::ZERO, le, per_solid_angle));
                // β = L_e / (p_pick p_ω p_disk)
                state.beta = le / (per_solid_angle * pdf_pos);
                self.walk_from_infinity(&mut state, origin, -toward, pdf_pos, max, path);
            }
            Picked::Delta { index, pick } => {
                let light = &scene.delta_lights[index];
                if is_sun(light) {
                    let dir = Vec3::from(light.direction);
                    let (origin, pdf_pos) = disk_origin(choice, dir, &mut state.rng);
                    let e = Vec3::from(light.power);
                    path.push(Vertex::new(
                        Point::Delta { index },
                        origin,
                        Vec3::ZERO,
                        e,
                        0.0,
                    ));
                    state.beta = e / (pick * pdf_pos);
                    self.walk_from_infinity(&mut state, origin, dir, pdf_pos, max, path);
                } else {
                    let (w, pdf_dir) = delta_direction(light, &mut state.rng);
                    let i = intensity(light, w);
                    let position = Vec3::from(light.position);
                    path.push(Vertex::new(
                        Point::Delta { index },
                        position,
                        Vec3::ZERO,
                        i,
                        0.0,
                    ));
                    if pdf_dir <= 0.0 || i == Vec3::ZERO {
                        return state;
                    }
                    state.beta = i / (pick * pdf_dir);
                    state.origin = position;
                    state.direction = w;
                    self.walk(&mut state, pdf_dir, true, max, path);
                }
            }
        }
        state
    }

    /// Extends a light subpath that starts at infinity (a sun, the environment) from `origin` on
    /// the disk that `disk_origin` drew with density `pdf_pos`, along `dir`.
    fn walk_from_infinity(
        &self,
        state: &mut PathState,
        origin: Vec3,
        dir: Vec3,
        pdf_pos: f32,
        max: usize,
        path: &mut Vec<Vertex>,
    ) {
        state.origin = origin;
        state.direction = dir;
        self.walk(state, 0.0, true, max, path);
        // The first hit's density is the disk's, projected (no distance falloff).
        if let Some(v) = path.get_mut(1) {
            v.pdf_fwd = pdf_pos * v.n.dot(dir).abs();
        }
    }

    /// Extends `path` from `state`'s ray, whose direction was drawn with density `pdf` per solid
    /// angle, until it holds `max` vertices, leaves the scene, or ends (absorbed, Russian
    /// roulette). `importance`: a light subpath (adjoint BSDFs: the shading-normal correction, and
    /// no 1/η² on refraction).
    fn walk(
        &self,
        state: &mut PathState,
        pdf: f32,
        importance: bool,
        max: usize,
        path: &mut Vec<Vertex>,
    ) {
        let (scene, frame) = (self.scene, self.frame);
        let mut pdf_fwd = pdf;
        if importance {
            // Russian roulette weighs a light subpath's throughput against its start (its β is in
            // units of the light's power, which would otherwise keep every subpath to full depth),
            // as a camera path's starts at 1: `eta_scale` is the factor roulette sees β by.
            state.eta_scale = 1.0 / state.beta.max_element().max(f32::MIN_POSITIVE);
        }
        while path.len() < max {
            let hit = trace(scene, state.origin, state.direction, f32::MAX);
            state.rays += 1;
            let last = path.len() - 1;
            if hit.triangle == MISS {
                if !importance {
                    let seen_directly = path.len() == 1 && frame.transparent != 0;
                    let le = if seen_directly {
                        Vec3::ZERO
                    } else {
                        escaped(scene, frame, state.direction, 0.0)
                    };
                    if let Some(f) = state.first_hit.as_mut().filter(|_| path.len() == 1) {
                        f.emission = le;
                    }
                    let p = path[last].p + state.direction;
                    path.push(Vertex::new(
                        Point::Environment {
                            le,
                            toward: state.direction,
                        },
                        p,
                        Vec3::ZERO,
                        state.beta,
                        pdf_fwd,
                    ));
                }
                return;
            }
            let sp = SurfacePoint::at(scene, state, hit);
            let mut v = Vertex::new(Point::Surface(sp), sp.p, sp.ng, state.beta, 0.0);
            v.pdf_fwd = path[last].area_density(scene, pdf_fwd, &v);
            path.push(v);
            if sp.emits_only(scene) || path.len() >= max {
                return;
            }
            let Some(next) = self.scatter(state, &sp, importance) else {
                return;
            };
            let here = path.len() - 1;
            path[here].delta = next.delta;
            let rev = path[here].area_density(scene, next.pdf_rev, &path[here - 1]);
            path[here - 1].pdf_rev = rev;
            pdf_fwd = next.pdf_fwd;
        }
    }

    /// Samples the BSDF at `sp` for the next segment and moves `state` onto it (throughput,
    /// Russian roulette, the ray). `None` ends the subpath.
    fn scatter(
        &self,
        state: &mut PathState,
        sp: &SurfacePoint,
        importance: bool,
    ) -> Option<Scattered> {
        let (scene, frame) = (self.scene, self.frame);
        let wo = -state.direction;
        let ng = if wo.dot(sp.ng) > 0.0 { sp.ng } else { -sp.ng };
        let sample = sp.surface.sample(state.direction, ng, &mut state.rng)?;
        let wi = sample.direction;
        let side = wi.dot(ng);
        if side == 0.0 || !wi.is_finite() {
            return None;
        }
        let transmitted = side < 0.0;
        if transmitted && !sp.surface.transmits() {
            return None;
        }
        let delta = sp.surface.is_delta();
        // The BSDF seen from the next vertex: f(wi, wo) |cos| and the reverse density.
        let (back, pdf_fwd) = if delta {
            ((Vec3::ZERO, 0.0), 0.0)
        } else {
            let fwd = if sample.pdf > 0.0 {
                sample.pdf
            } else {
                sp.surface.eval(wi).1
            };
            (sp.facing(scene, -wi).eval(wo), fwd)
        };
        let mut weight = sample.weight;
        let refracts = transmitted && !sp.thin(scene);
        let eta = sp.surface.relative_eta();
        if importance {
            weight = if sp.reciprocal() {
                weight * sp.shading_correction(wo, wi) * if refracts { eta * eta } else { 1.0 }
            } else {
                // Light carried from wo out along wi is what f(wi, wo) scatters (the PBR BSDF's
                // energy compensation makes f(wo, wi) differ).
                back.0 * (wi.dot(sp.ng).abs() / (wo.dot(sp.ng).abs() * pdf_fwd))
            };
        } else if refracts {
            state.eta_scale *= eta * eta;
        }
        state.beta *= weight;
        state.depth += 1;
        if frame.roulette_from_depth > 0 && state.depth >= frame.roulette_from_depth {
            let survive = (state.beta * state.eta_scale).max_element().min(1.0);
            if state.rng.next_f32() >= survive || survive.is_nan() {
                return None;
            }
            state.beta /= survive;
        }
        if state.beta == Vec3::ZERO || !state.beta.is_finite() {
            return None;
        }
        state.origin =
            offset_ray_origin(sp.p, if transmitted { -ng } else { ng }, frame.offset_scale);
        state.direction = wi;
        Some(Scattered {
            pdf_fwd,
            pdf_rev: back.1,
            delta,
        })
    }
}

/// What sampling a vertex's BSDF gave MIS: the next vertex's density per solid angle, the
/// reverse one (of reaching the vertex before from the next), and whether it was a delta.
struct Scattered {
    pdf_fwd: f32,
    pdf_rev: f32,
    delta: bool,
}
