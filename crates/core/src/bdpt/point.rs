//! A subpath's vertex on a surface: what the path tracer's `shade_vertex` works out at a hit
//! (position, normals, colour, the PBR inputs) kept so that the BSDF can be rebuilt for light
//! arriving from another side, as the MIS weights of other strategies need.

use glam::Vec3;

use crate::estimator::instances::hit_triangle;
use crate::estimator::path::{PathState, Shading, first_hit_albedo, shading_at};
use crate::estimator::surface::{PbrInputs, Surface};
use crate::estimator::texture::surface_emission;
use crate::gpu_scene::GpuScene;
use crate::gpu_types::{Hit, THIN_WALLED, Triangle};
use crate::material_kind::MaterialKind;

/// A hit surface point and what its BSDF is made from.
#[derive(Clone, Copy, Debug)]
pub struct SurfacePoint {
    pub p: Vec3,
    /// The triangle's unit geometric normal (its front side, by winding).
    pub ng: Vec3,
    /// The shading normal on the side the subpath arrived from.
    ns: Vec3,
    /// Whether the subpath arrived on the front side.
    front: bool,
    pub material: u32,
    color: Vec3,
    inputs: PbrInputs,
    /// The triangle as shading reads it (placed in world space for an instance), the hit's
    /// index and barycentrics: for the emission seen there.
    pub triangle: Triangle,
    pub index: u32,
    pub barycentrics: (f32, f32),
    /// The BSDF for the direction the subpath arrived along (`arrival`).
    pub surface: Surface,
    pub arrival: Vec3,
}

impl SurfacePoint {
    /// The surface point `hit` found on a ray travelling along `path.direction` (which draws a
    /// dispersive surface's channel, as `shade_vertex` does).
    pub fn at(scene: &GpuScene, path: &mut PathState, hit: Hit) -> SurfacePoint {
        let mut hit = hit;
        let mut placed = None;
        let found = hit_triangle(scene, &mut hit, &mut placed);
        let tri = *found.tri;
        let material = &scene.materials[tri.material as usize];
        let (v0, v1, v2) = (Vec3::from(tri.v0), Vec3::from(tri.v1), Vec3::from(tri.v2));
        let winding = (v1 - v0).cross(v2 - v0);
        let ng_raw = winding.normalize();
        let front = path.direction.dot(winding) < 0.0;
        let Shading {
            p,
            ng,
            ns,
            color,
            inputs,
        } = shading_at(scene, &found, hit, winding, front, path);
        let surface = Surface::of_material(
            scene,
            material,
            color,
            &inputs,
            path.direction,
            ng,
            ns,
            front,
        );
        let point = SurfacePoint {
            p,
            ng: ng_raw,
            ns,
            front,
            material: tri.material,
            color,
            inputs,
            triangle: tri,
            index: hit.triangle,
            barycentrics: (hit.b1, hit.b2),
            surface,
            arrival: path.direction,
        };
        // A camera subpath's first hit, recorded as the path tracer's `shade_vertex` does.
        if path.depth == 0
            && let Some(f) = path.first_hit.as_mut()
        {
            f.albedo = first_hit_albedo(scene, material, &found, hit);
            f.normal = ng;
            (f.coverage, f.depth, f.object) = (1.0, hit.t, tri.material + 1);
            f.emission = point.emitted(scene, -path.direction);
        }
        point
    }

    /// The BSDF for light arriving along `arrival` (a unit direction towards this point): the
    /// normals turned to face it.
    /// (The PBR BSDF holds the direction it is seen from, so it is built anew for another.)
    pub fn facing(&self, scene: &GpuScene, arrival: Vec3) -> Surface {
        let front = arrival.dot(self.ng) < 0.0;
        let same_side = front == self.front;
        if same_side && (self.reciprocal() || arrival == self.arrival) {
            return self.surface;
        }
        let mut inputs = self.inputs;
        let mut ns = self.ns;
        if !same_side {
            inputs.coat_normal = -inputs.coat_normal;
            ns = -ns;
        }
        let material = &scene.materials[self.material as usize];
        let ng = if front { self.ng } else { -self.ng };
        Surface::of_material(scene, material, self.color, &inputs, arrival, ng, ns, front)
    }

    /// The shading normal facing direction `w`.
    pub fn shading_normal(&self, w: Vec3) -> Vec3 {
        if w.dot(self.ns) < 0.0 {
            -self.ns
        } else {
            self.ns
        }
    }

    /// The shading-normal correction of an adjoint BSDF (Veach's thesis, §5.3): a light subpath
    /// here, arriving from `wo`, leaving along `wi`, carries f · |wo·n_s| |wi·n_g| / (|wo·n_g|
    /// |wi·n_s|) where a camera subpath carries f, so that both transport the same measurement.
    pub fn shading_correction(&self, wo: Vec3, wi: Vec3) -> f32 {
        let ns = self.shading_normal(wo);
        let denominator = wo.dot(self.ng).abs() * wi.dot(ns).abs();
        if denominator <= 0.0 {
            return 0.0;
        }
        wo.dot(ns).abs() * wi.dot(self.ng).abs() / denominator
    }

    /// Whether f(wo, wi) = f(wi, wo) up to refraction's η² (Lambert, metal, smooth glass), so that
    /// light subpaths may use the BSDF as sampled; the PBR BSDF's energy compensation depends on
    /// ωo alone, so light subpaths evaluate it from the other side.
    pub fn reciprocal(&self) -> bool {
        !matches!(self.surface, Surface::Pbr { .. })
    }

    /// Whether the surface only emits (no BSDF: a path ends there).
    pub fn emits_only(&self, scene: &GpuScene) -> bool {
        scene.materials[self.material as usize].kind == MaterialKind::Emissive.tag()
    }

    /// Whether the surface is a thin sheet (no refraction scaling across it).
    pub fn thin(&self, scene: &GpuScene) -> bool {
        scene.materials[self.material as usize].flags & THIN_WALLED != 0
    }

    /// The radiance the surface emits towards unit direction `w` (zero from its back).
    pub fn emitted(&self, scene: &GpuScene, w: Vec3) -> Vec3 {
        let cos = w.dot(self.ng);
        if cos <= 0.0 {
            return Vec3::ZERO;
        }
        let material = &scene.materials[self.material as usize];
        if material.emission == [0.0; 3] {
            return Vec3::ZERO;
        }
        surface_emission(
            scene,
            material,
            &self.triangle,
            self.index,
            self.barycentrics,
            cos,
        )
    }
}
