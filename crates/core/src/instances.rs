//! Instances: a mesh that several objects share is stored once, in its own space, under its own
//! BVH, and each object that uses it is an instance — the mesh's BVH root, the object's transform
//! and material — found through a top-level BVH over the instances' world boxes (as Embree's and
//! pbrt-v4's object instances, Mitsuba's `shapegroup`/`instance`, Cycles' object instancing).
//! Memory grows with the unique triangles, not with the copies: a forest of one tree costs one
//! tree.
//!
//! Which objects become instances: those whose mesh (the same `Arc`) at least one other object
//! uses with the same triangle records (vertex colours applied or not, tangents or not). Emitters
//! and alpha-tested objects stay in world space: the emitter table, the light tree and the
//! alpha test read world-space triangles with their own material, exactly as before.
//!
//! Both backends trace them (`estimator/instance_bvh.rs` ⇄ `instance_bvh.wgsl`), and so do the
//! driver's ray queries: one bottom-level structure per shared mesh, an instance of it per copy
//! (`rt_gpu::accel`).

use std::collections::HashMap;
use std::sync::Arc;

use bytemuck::{Pod, Zeroable};
use glam::{Mat4, Vec3};

use crate::gpu_types::{
    ALPHA_BLEND, ALPHA_MASK, HAS_NORMALS, Material, Shading, TANGENTS, Triangle,
};
use crate::math::sampling::luminance;
use crate::scene::{Mesh, Object, Scene};

/// A triangle of an instance's mesh placed in the world (`Instance::place`).
#[derive(Clone, Copy, Debug)]
pub struct PlacedTriangle {
    pub tri: Triangle,
    pub shading: Shading,
    pub tangents: [[f32; 4]; 3],
}

crate::gpu_types::gpu_struct! {
/// One placed copy of a shared mesh, as the kernels read it (`Instance` in `instances.wgsl`).
/// Rows of 3×4 affine matrices: a point p goes to (r·(p, 1)) per row r.
#[repr(C, align(16))]
#[derive(Clone, Copy, Debug, Default, PartialEq, Pod, Zeroable)]
pub struct Instance {
    /// World to the mesh's space.
    pub to_object: [[f32; 4]; 3], // 0
    /// The mesh's space to world.
    pub to_world: [[f32; 4]; 3], // 48
    /// Its mesh's BVH root in the scene's node array (of its layout).
    pub root: u32, // 96
    /// The object it draws (its material).
    pub material: u32, // 100
    /// 1 where the transform mirrors (a negative determinant): the winding turns over.
    pub mirrored: u32, // 104
    /// Its mesh's first triangle in `GpuScene::triangles` (the mesh's triangles follow in order):
    /// where the driver's ray queries, which count a hit's primitive from the mesh's first,
    /// find rt's triangle index (`ray_query.wgsl`).
    pub first_triangle: u32, // 108
}
}

fn rows(m: Mat4) -> [[f32; 4]; 3] {
    let t = m.transpose();
    [t.x_axis.into(), t.y_axis.into(), t.z_axis.into()]
}

/// `row`·(v, w): the product `instances.wgsl` computes.
fn apply(row: [f32; 4], v: Vec3, w: f32) -> f32 {
    row[0] * v.x + row[1] * v.y + row[2] * v.z + row[3] * w
}

impl Instance {
    pub fn new(object: &Object, index: u32, (root, first_triangle): (u32, u32)) -> Self {
        let m = object.transform.matrix();
        Instance {
            to_object: rows(m.inverse()),
            to_world: rows(m),
            root,
            material: index,
            mirrored: u32::from(m.determinant() < 0.0),
            first_triangle,
        }
    }

    /// A world-space point in the mesh's space (`instance_point` in `instances.wgsl`).
    pub fn point_to_object(&self, p: Vec3) -> Vec3 {
        let [x, y, z] = self.to_object.map(|r| apply(r, p, 1.0));
        Vec3::new(x, y, z)
    }

    /// A world-space direction in the mesh's space, not renormalised: t measures the same
    /// distance along the ray in both spaces.
    pub fn direction_to_object(&self, d: Vec3) -> Vec3 {
        let [x, y, z] = self.to_object.map(|r| apply(r, d, 0.0));
        Vec3::new(x, y, z)
    }

    fn point_to_world(&self, p: Vec3) -> Vec3 {
        let [x, y, z] = self.to_world.map(|r| apply(r, p, 1.0));
        Vec3::new(x, y, z)
    }

    fn vector_to_world(&self, d: Vec3) -> Vec3 {
        let [x, y, z] = self.to_world.map(|r| apply(r, d, 0.0));
        Vec3::new(x, y, z)
    }

    /// A normal to world space: by the inverse transpose of the linear part, whose rows are
    /// `to_object`'s columns.
    fn normal_to_world(&self, n: Vec3) -> Vec3 {
        let [a, b, c] = self.to_object.map(|r| Vec3::new(r[0], r[1], r[2]));
        a * n.x + b * n.y + c * n.z
    }

    /// Turns `t`, a triangle of this instance's mesh in the mesh's space, into the world-space
    /// triangle the flattened scene holds (`ObjectFrame` of `object_frames`): corners placed,
    /// normals by the inverse transpose, tangents by the transform (their handedness flips with
    /// a mirror, whose corners 1 and 2 swap). `place_triangle` in `instances.wgsl`.
    pub fn place(&self, t: &mut PlacedTriangle) {
        let tri = &mut t.tri;
        let p = |v: [f32; 3]| self.point_to_world(Vec3::from(v)).to_array();
        (tri.v0, tri.v1, tri.v2) = (p(tri.v0), p(tri.v1), p(tri.v2));
        tri.material = self.material;
        let s = &mut t.shading;
        if tri.has_normals & HAS_NORMALS != 0 {
            let n = |v: [f32; 3]| {
                self.normal_to_world(Vec3::from(v))
                    .normalize_or_zero()
                    .to_array()
            };
            (s.n0, s.n1, s.n2) = (n(s.n0), n(s.n1), n(s.n2));
        }
        self.place_tangents(&mut t.tangents);
        if self.mirrored != 0 {
            std::mem::swap(&mut tri.v1, &mut tri.v2);
            std::mem::swap(&mut s.n1, &mut s.n2);
            std::mem::swap(&mut s.c1, &mut s.c2);
            std::mem::swap(&mut s.uv1, &mut s.uv2);
        }
    }

    /// A triangle's corner tangents in world space, corners 1 and 2 swapped with a mirror
    /// (`place_tangents` in `instances.wgsl`).
    pub fn place_tangents(&self, tangents: &mut [[f32; 4]; 3]) {
        let sign = if self.mirrored != 0 { -1.0 } else { 1.0 };
        for c in tangents.iter_mut() {
            let d = self.vector_to_world(Vec3::new(c[0], c[1], c[2]));
            let d = d.normalize_or_zero();
            *c = [d.x, d.y, d.z, c[3] * sign];
        }
        if self.mirrored != 0 {
            tangents.swap(1, 2);
        }
    }

    /// The world box of a mesh whose box in its own space is `lo..hi`.
    pub fn world_box(&self, lo: Vec3, hi: Vec3) -> (Vec3, Vec3) {
        let (mut wlo, mut whi) = (Vec3::splat(f32::INFINITY), Vec3::splat(f32::NEG_INFINITY));
        for corner in 0..8 {
            let pick = |bit: u32, a: f32, b: f32| if corner & bit == 0 { a } else { b };
            let c = Vec3::new(
                pick(1, lo.x, hi.x),
                pick(2, lo.y, hi.y),
                pick(4, lo.z, hi.z),
            );
            let w = self.point_to_world(c);
            (wlo, whi) = (wlo.min(w), whi.max(w));
        }
        (wlo, whi)
    }
}

/// The objects that share meshes, grouped: each group's objects draw the same triangle records
/// (same mesh, same use of vertex colours and tangents), at least two to a group; `materials`
/// are the objects' packed materials. Objects in no group stay in world space.
pub fn shared_meshes(scene: &Scene, materials: &[Material]) -> Vec<Vec<usize>> {
    let mut groups: HashMap<(*const Mesh, bool, bool), Vec<usize>> = HashMap::new();
    for (index, (object, material)) in scene.objects.iter().zip(materials).enumerate() {
        let emits = luminance(Vec3::from(material.emission)) > 0.0;
        if emits || material.flags & (ALPHA_MASK | ALPHA_BLEND) != 0 {
            continue;
        }
        let count = object.mesh.positions.len();
        let colored = object
            .mesh
            .colors
            .as_ref()
            .is_some_and(|c| c.len() == count)
            && matches!(
                object.material,
                crate::material::Material::Lambertian { .. } | crate::material::Material::Pbr(_)
            );
        let key = (
            Arc::as_ptr(&object.mesh),
            colored,
            material.flags & TANGENTS != 0,
        );
        groups.entry(key).or_default().push(index);
    }
    let mut groups: Vec<Vec<usize>> = groups.into_values().filter(|g| g.len() > 1).collect();
    // In scene order, whatever the hash map's.
    groups.sort_by_key(|g| g[0]);
    groups
}

/// `object` as its mesh's representative: the same, placed at the origin unturned and unscaled,
/// so that its triangles come out in the mesh's own space.
pub fn in_mesh_space(object: &Object) -> Object {
    Object {
        transform: crate::scene::Transform::default(),
        ..object.clone()
    }
}
