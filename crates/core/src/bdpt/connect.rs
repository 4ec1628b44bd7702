//! Joining a light subpath's first s vertices to a camera subpath's first t (Veach's strategy
//! (s, t)): the unweighted contribution
//!   C*_{s,t} = β_L(y_{s−1}) · f̂(y_{s−1}) · V / d² · f̂(z_{t−1}) · β_E(z_{t−1}),
//! where each f̂ is the BSDF times the geometric cosine at its end of the connecting segment
//! (at a light: L_e cosθ, or a point light's intensity), and the special cases: s = 0 (the camera
//! subpath met an emitter or escaped), s = 1 (a light point sampled anew for the camera vertex,
//! next-event estimation), t = 1 (a lens point sampled anew: light tracing, splatted where the
//! segment meets the film).

use glam::Vec3;

use super::importance::{importance_over_pdf, lens_point, raster};
use super::lights::{Picked, emitter_point, intensity, is_sun, sample_environment};
use super::mis;
use super::subpath::Walks;
use super::vertex::{Point, Vertex};
use crate::estimator::occluded;
use crate::math::intersect::offset_ray_origin;
use crate::math::rng::Rng;

/// What a strategy adds: to the pixel of the camera subpath, or (t = 1) to the pixel at `pixel`.
pub enum Contribution {
    Pixel(Vec3),
    Splat { pixel: (u32, u32), value: Vec3 },
}

impl Walks<'_> {
    /// f̂ at `v` towards unit `w`: the BSDF times |cosθ| there, in the light subpath's adjoint form
    /// when `importance`; an emitter's L_e cosθ, a point or spot light's intensity, a sun's
    /// irradiance, the environment's radiance.
    fn scatter_toward(&self, v: &Vertex, w: Vec3, importance: bool) -> Vec3 {
        let scene = self.scene;
        match &v.point {
            Point::Surface(sp) => {
                let wo = -sp.arrival;
                let ng = if wo.dot(sp.ng) > 0.0 { sp.ng } else { -sp.ng };
                let crosses = w.dot(ng) <= 0.0;
                if crosses && !sp.surface.transmits() {
                    return Vec3::ZERO;
                }
                if importance && !sp.reciprocal() {
                    // f(w, wo): the BSDF seen from the connection (see `Walks::scatter`).
                    let f = sp.facing(scene, -w).eval(wo).0;
                    return f * (w.dot(sp.ng).abs() / wo.dot(sp.ng).abs());
                }
                let mut f = sp.surface.eval(w).0;
                if importance {
                    f *= sp.shading_correction(wo, w);
                    if crosses && !sp.thin(scene) {
                        let eta = sp.surface.relative_eta();
                        f *= eta * eta;
                    }
                }
                f
            }
            Point::Emitter { index, b } => {
                let (_, n, le) = emitter_point(scene, *index, *b, w);
                le * w.dot(n).max(0.0)
            }
            Point::Delta { index } => {
                let light = &scene.delta_lights[*index];
                if is_sun(light) {
                    Vec3::from(light.power)
                } else {
                    intensity(light, w)
                }
            }
            Point::Environment { le, .. } => *le,
            Point::Camera => Vec3::ZERO,
        }
    }

    /// Whether nothing lies between `a` and `b` (each offset off its surface towards the other);
    /// counts the shadow ray in `rays`.
    fn visible(&self, a: &Vertex, b: &Vertex, rays: &mut u32) -> bool {
        let offset = self.frame.offset_scale;
        *rays += 1;
        let towards = |from: &Vertex, to: Vec3| {
            if from.n == Vec3::ZERO {
                from.p
            } else {
                let n = if (to - from.p).dot(from.n) > 0.0 {
                    from.n
                } else {
                    -from.n
                };
                offset_ray_origin(from.p, n, offset)
            }
        };
        if b.at_infinity(self.scene) {
            let dir = (b.p - a.p).normalize();
            return !occluded(self.scene, towards(a, b.p), dir, 3.0e38);
        }
        let origin = towards(a, b.p);
        let target = towards(b, a.p);
        let to = target - origin;
        let distance = to.length();
        distance > 0.0 && !occluded(self.scene, origin, to / distance, distance)
    }

    /// Strategy (s, t) on these subpaths: its unweighted contribution C*_{s,t} and its MIS
    /// weight; `rng` draws what s = 1 and t = 1 sample anew.
    pub fn connect(
        &self,
        light: &[Vertex],
        camera: &[Vertex],
        s: usize,
        t: usize,
        rng: &mut Rng,
        rays: &mut u32,
    ) -> Option<(Contribution, f32)> {
        let scene = self.scene;
        if t > 1 && s != 0 && matches!(camera[t - 1].point, Point::Environment { .. }) {
            return None;
        }
        let (value, sampled) = if s == 0 {
            let pt = &camera[t - 1];
            let le = match &pt.point {
                Point::Environment { le, .. } => *le,
                Point::Surface(sp) => sp.emitted(scene, -sp.arrival),
                _ => Vec3::ZERO,
            };
            (pt.beta * le, None)
        } else if t == 1 {
            return self.light_tracing(light, camera, s, rng, rays);
        } else if s == 1 {
            let pt = &camera[t - 1];
            if !pt.connectible(scene) {
                return None;
            }
            let sampled = self.sample_light_vertex(pt, rng)?;
            let d = sampled.p - pt.p;
            let (w, g) = if sampled.at_infinity(scene) {
                (d.normalize(), 1.0)
            } else {
                (d.normalize(), 1.0 / d.length_squared())
            };
            let value = pt.beta
                * self.scatter_toward(pt, w, false)
                * self.scatter_toward(&sampled, -w, true)
                * sampled.beta
                * g;
            if value == Vec3::ZERO || !self.visible(pt, &sampled, rays) {
                return None;
            }
            (value, Some(sampled))
        } else {
            let (qs, pt) = (&light[s - 1], &camera[t - 1]);
            if !(qs.connectible(scene) && pt.connectible(scene)) {
                return None;
            }
            let d = pt.p - qs.p;
            let w = d.normalize();
            let value = qs.beta
                * self.scatter_toward(qs, w, true)
                * self.scatter_toward(pt, -w, false)
                * pt.beta
                / d.length_squared();
            if value == Vec3::ZERO || !value.is_finite() || !self.visible(pt, qs, rays) {
                return None;
            }
            (value, None)
        };
        if value == Vec3::ZERO || !value.is_finite() {
            return None;
        }
        let weight = mis::weight(self, light, camera, sampled.as_ref(), s, t);
        Some((Contribution::Pixel(value), weight))
    }

    /// Strategy t = 1: the light subpath's vertex s − 1 joined to a point on the lens.
    fn light_tracing(
        &self,
        light: &[Vertex],
        camera: &[Vertex],
        s: usize,
        rng: &mut Rng,
        rays: &mut u32,
    ) -> Option<(Contribution, f32)> {
        let qs = &light[s - 1];
        if !qs.connectible(self.scene) {
            return None;
        }
        let lens = lens_point(self.frame, rng);
        let d = lens - qs.p;
        let distance = d.length();
        let w = d / distance;
        let (x, y) = raster(self.frame, lens, -w)?;
        let camera_vertex = Vertex::new(Point::Camera, lens, Vec3::ZERO, Vec3::ONE, 0.0);
        let value = qs.beta
            * self.scatter_toward(qs, w, true)
            * importance_over_pdf(self.frame, -w, distance);
        if value == Vec3::ZERO || !value.is_finite() || !self.visible(qs, &camera_vertex, rays) {
            return None;
        }
        let weight = mis::weight(self, light, camera, Some(&camera_vertex), s, 1);
        Some((
            Contribution::Splat {
                pixel: (x as u32, y as u32),
                value,
            },
            weight,
        ))
    }

    /// Strategy s = 1's light vertex for camera vertex `pt`, chosen as light subpaths start: its
    /// β is 1 over its density (per unit area, or the pick probability of a delta light), and its
    /// `pdf_fwd` that of a light subpath starting there.
    fn sample_light_vertex(&self, pt: &Vertex, rng: &mut Rng) -> Option<Vertex> {
        let (scene, frame) = (self.scene, self.frame);
        match self.choice.pick(scene, frame, rng)? {
            Picked::Triangle { index, b, per_area } => {
                let (y, n, _) = emitter_point(scene, index, b, Vec3::ZERO);
                if per_area <= 0.0 {
                    return None;
                }
                let mut v =
                    Vertex::new(Point::Emitter { index, b }, y, n, Vec3::ONE / per_area, 0.0);
                v.pdf_fwd = per_area;
                Some(v)
            }
            Picked::Environment { u, pick } => {
                let (toward, le, pdf_dir) = sample_environment(scene, frame, u);
                if pdf_dir.is_nan() || pdf_dir <= 0.0 || le == Vec3::ZERO {
                    return None;
                }
                // Far along the direction, as a sun's.
                let p = pt.p + toward * (self.choice.radius * 1.0e4);
                let per_solid_angle = pick * pdf_dir;
                let mut v = Vertex::new(
                    Point::Environment { le, toward },
                    p,
                    Vec3::ZERO,
                    Vec3::ONE / per_solid_angle,
                    0.0,
                );
                v.pdf_fwd = per_solid_angle;
                Some(v)
            }
            Picked::Delta { index, pick } => {
                let light = &scene.delta_lights[index];
                let p = if is_sun(light) {
                    // Far along the direction the sunlight comes from.
                    pt.p - Vec3::from(light.direction) * (self.choice.radius * 1.0e4)
                } else {
                    glam::Vec3::from(light.position)
                };
                Some(Vertex::new(
                    Point::Delta { index },
                    p,
                    Vec3::ZERO,
                    Vec3::ONE / pick,
                    0.0,
                ))
            }
        }
    }
}
