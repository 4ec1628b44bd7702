//! A subpath vertex and the densities MIS weighs it with (pbrt-v4's `Vertex`): each vertex keeps
//! `pdf_fwd`, the density per unit area with which its own subpath reached it, and `pdf_rev`, the
//! density with which the other subpath would have, both as measured when it was sampled; the
//! connection recomputes the few that the connection changes (`mis::weight`).

use glam::Vec3;

use super::importance;
use super::lights::{LightChoice, delta_direction_pdf, environment_pdf, is_sun};
use super::point::SurfacePoint;
use crate::gpu_scene::GpuScene;
use crate::gpu_types::Frame;

/// What a vertex is.
// Subpath vertices live in a reused vector per thread: boxing the surface would allocate per
// vertex on the hot path.
#[allow(clippy::large_enum_variant)]
#[derive(Clone, Copy, Debug)]
pub enum Point {
    /// The camera's lens point (a camera subpath's first vertex, or the one light tracing connects
    /// to).
    Camera,
    /// A point on a surface.
    Surface(SurfacePoint),
    /// The point at barycentrics `b` of emitter triangle `index` (a light subpath's first vertex,
    /// or the one strategy s = 1 connects to).
    Emitter { index: u32, b: (f32, f32) },
    /// Delta light `index` (point, spot or sun).
    Delta { index: usize },
    /// The environment (or ambient light) in unit direction `toward` from the scene, with the
    /// radiance `le` arriving from there: where a camera subpath left the scene, a light subpath's
    /// start, or the light strategy s = 1 connects to.
    Environment { le: Vec3, toward: Vec3 },
}

#[derive(Clone, Copy, Debug)]
pub struct Vertex {
    pub point: Point,
    pub p: Vec3,
    /// The unit geometric normal (zero for the camera and the lights without one).
    pub n: Vec3,
    /// The subpath's throughput up to and including this vertex's arrival.
    pub beta: Vec3,
    pub pdf_fwd: f32,
    pub pdf_rev: f32,
    /// Whether the BSDF sampled here is a delta (no connection can end here).
    pub delta: bool,
}

impl Vertex {
    pub fn new(point: Point, p: Vec3, n: Vec3, beta: Vec3, pdf_fwd: f32) -> Vertex {
        Vertex {
            point,
            p,
            n,
            beta,
            pdf_fwd,
            pdf_rev: 0.0,
            delta: false,
        }
    }

    pub fn surface(&self) -> Option<&SurfacePoint> {
        match &self.point {
            Point::Surface(s) => Some(s),
            _ => None,
        }
    }

    /// Whether a connection can end here.
    pub fn connectible(&self, scene: &GpuScene) -> bool {
        match &self.point {
            Point::Surface(s) => !s.surface.is_delta() && !s.emits_only(scene),
            Point::Environment { .. } => false,
            Point::Delta { index } => !is_sun(&scene.delta_lights[*index]),
            Point::Camera | Point::Emitter { .. } => true,
        }
    }

    /// Whether this is a light with a delta in position or direction (no subpath can reach it).
    pub fn is_delta_light(&self) -> bool {
        matches!(self.point, Point::Delta { .. })
    }

    /// Whether this is at infinity (a sun, the environment).
    pub fn at_infinity(&self, scene: &GpuScene) -> bool {
        match self.point {
            Point::Environment { .. } => true,
            Point::Delta { index } => is_sun(&scene.delta_lights[index]),
            _ => false,
        }
    }

    /// `pdf` per solid angle at this vertex, towards `next`, as a density per unit area there.
    pub fn area_density(&self, scene: &GpuScene, pdf: f32, next: &Vertex) -> f32 {
        if next.at_infinity(scene) {
            return pdf;
        }
        let d = next.p - self.p;
        let inv_d2 = 1.0 / d.length_squared();
        let mut pdf = pdf * inv_d2;
        if next.n != Vec3::ZERO {
            pdf *= next.n.dot(d * inv_d2.sqrt()).abs();
        }
        pdf
    }

    /// The density per unit area with which this vertex, reached from `prev`, samples `next`.
    pub fn pdf(
        &self,
        scene: &GpuScene,
        frame: &Frame,
        choice: &LightChoice,
        prev: Option<&Vertex>,
        next: &Vertex,
    ) -> f32 {
        let w = (next.p - self.p).normalize();
        let pdf = match &self.point {
            Point::Camera => importance::direction_pdf(frame, self.p, w),
            Point::Surface(s) => {
                let Some(prev) = prev else { return 0.0 };
                let surface = s.facing(scene, (self.p - prev.p).normalize());
                if surface.is_delta() {
                    return 0.0;
                }
                surface.eval(w).1
            }
            _ => return self.pdf_light(scene, choice, next),
        };
        self.area_density(scene, pdf, next)
    }

    /// The density per unit area with which a light subpath starting at this light (an emitter
    /// point, a delta light, or a surface that emits) reaches `next` with its first segment.
    pub fn pdf_light(&self, scene: &GpuScene, choice: &LightChoice, next: &Vertex) -> f32 {
        if let Point::Environment { toward, .. } = self.point {
            // From the disk across the scene's bounding sphere, as a sun's.
            let disk = 1.0 / (std::f32::consts::PI * choice.radius * choice.radius);
            let cos = if next.n == Vec3::ZERO {
                1.0
            } else {
                next.n.dot(toward).abs()
            };
            return disk * cos;
        }
        if let Point::Delta { index } = self.point {
            let light = &scene.delta_lights[index];
            if is_sun(light) {
                let disk = 1.0 / (std::f32::consts::PI * choice.radius * choice.radius);
                let cos = if next.n == Vec3::ZERO {
                    1.0
                } else {
                    next.n.dot(Vec3::from(light.direction)).abs()
                };
                return disk * cos;
            }
            let w = (next.p - self.p).normalize();
            return self.area_density(scene, delta_direction_pdf(light, w), next);
        }
        let w = (next.p - self.p).normalize();
        let cos = w.dot(self.n);
        if cos <= 0.0 {
            return 0.0;
        }
        self.area_density(scene, cos * std::f32::consts::FRAC_1_PI, next)
    }

    /// The density per unit area with which a light subpath starts here (zero for a delta light,
    /// which no other strategy reaches; per solid angle for the environment).
    pub fn pdf_light_origin(&self, scene: &GpuScene, frame: &Frame, choice: &LightChoice) -> f32 {
        match &self.point {
            Point::Emitter { index, .. } => choice.per_area(scene, frame, *index),
            Point::Surface(s) => {
                if scene.materials[s.material as usize].emission == [0.0; 3] {
                    0.0
                } else {
                    choice.per_area(scene, frame, s.index)
                }
            }
            Point::Environment { toward, .. } => {
                choice.environment * environment_pdf(scene, frame, *toward)
            }
            _ => 0.0,
        }
    }
}
