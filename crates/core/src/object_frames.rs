//! An object's triangles in world space, read from its mesh when they are needed: the corners
//! for the BVH build, the shading attributes (normals, UVs, tangents, vertex colours) only when
//! the triangles are written out in BVH order. Keeping (object, face) pairs between the two,
//! 8 bytes a triangle, instead of every triangle's attributes (about 140 bytes) lowers the memory
//! a scene's build peaks at.

use glam::{Mat3, Mat4, Vec2, Vec3};

use crate::error::{Error, Result};
use crate::gpu_types::{self, CORNER_WORDS};
use crate::material::Material;
use crate::scene::Object;

/// What a triangle carries besides its corners and vertex records: its material (the object's
/// index), its normals and its tangents.
pub type TriangleData = (u32, Option<[Vec3; 3]>, Option<[[f32; 4]; 3]>);

/// One object, checked, with what its triangles need: its transform (and the normals'), whether
/// it mirrors, whether its vertex colours apply, and its tangents (three per face, with a normal
/// map).
pub struct ObjectFrame<'a> {
    object: &'a Object,
    index: u32,
    m: Mat4,
    nm: Mat3,
    flip: bool,
    colored: bool,
    tangents: Option<Vec<[f32; 4]>>,
}

impl<'a> ObjectFrame<'a> {
    /// Checks `object`'s mesh (finite vertices, indices in range) and transform (finite, not
    /// singular).
    pub fn new(object: &'a Object, index: u32, tangents: Option<Vec<[f32; 4]>>) -> Result<Self> {
        let mesh = &object.mesh;
        let label = || format!("object '{}'", object.name);
        Self::check_transform(object)?;
        let m = object.transform.matrix();
        for (i, p) in mesh.positions.iter().enumerate() {
            if !p.is_finite() {
                return Err(Error::Scene(format!(
                    "{}: vertex {} is not finite ({p})",
                    label(),
                    i + 1
                )));
            }
        }
        let count = mesh.positions.len();
        for (face, idx) in mesh.indices.iter().enumerate() {
            if let Some(bad) = idx.iter().find(|&&i| i as usize >= count) {
                return Err(Error::Scene(format!(
                    "{}: triangle {} uses vertex {} of {count}",
                    label(),
                    face + 1,
                    bad + 1
                )));
            }
        }
        // Vertex colours tint diffuse and PBR materials (the others have no base colour).
        let colored = mesh.colors.as_ref().is_some_and(|c| c.len() == count)
            && matches!(
                object.material,
                Material::Lambertian { .. } | Material::Pbr(_)
            );
        Ok(ObjectFrame {
            object,
            index,
            m,
            nm: object.transform.normal_matrix(),
            flip: m.determinant() < 0.0,
            colored,
            tangents,
        })
    }

    /// An error naming `object` where its transform is singular or not finite.
    pub fn check_transform(object: &Object) -> Result<()> {
        let m = object.transform.matrix();
        if !m.is_finite() || m.determinant() == 0.0 {
            return Err(Error::Scene(format!(
                "object '{}': transform is singular or not finite",
                object.name
            )));
        }
        Ok(())
    }

    pub fn faces(&self) -> usize {
        self.object.mesh.indices.len()
    }

    /// Face `face`'s vertex indices, two swapped where the transform mirrors (which reverses the
    /// winding) to keep the front face.
    pub fn corners(&self, face: usize) -> [u32; 3] {
        let idx = self.object.mesh.indices[face];
        if self.flip {
            [idx[0], idx[2], idx[1]]
        } else {
            idx
        }
    }

    /// Face `face`'s corners in world space.
    pub fn world(&self, face: usize) -> [Vec3; 3] {
        self.corners(face).map(|i| {
            self.m
                .transform_point3(self.object.mesh.positions[i as usize])
        })
    }

    /// What face `face` carries besides its corners: its material, its corners' normals in world
    /// space (where the mesh has normals) and tangents (with a normal map).
    pub fn data(&self, face: usize) -> TriangleData {
        let idx = self.corners(face);
        let n = self.has_normals().then(|| idx.map(|i| self.normal(i)));
        let corners = if self.flip { [0, 2, 1] } else { [0, 1, 2] };
        let sign = if self.flip { -1.0 } else { 1.0 };
        let t = self.tangents.as_ref().map(|t| {
            corners.map(|c| {
                let [x, y, z, w] = t[face * 3 + c];
                let d = self
                    .m
                    .transform_vector3(Vec3::new(x, y, z))
                    .normalize_or_zero();
                [d.x, d.y, d.z, w * sign]
            })
        });
        (self.index, n, t)
    }

    /// How many vertices the mesh has (its faces index them).
    pub fn vertices(&self) -> usize {
        self.object.mesh.positions.len()
    }

    /// Vertex `v`'s shading record as the kernels read it (`crate::corner_records`): its normal in
    /// world space (zero without normals), its colour (`u32::MAX` without colours) and its
    /// texture coordinates (zero without), the values `data` gives its faces' corners.
    pub fn corner_record(&self, v: u32) -> [u32; CORNER_WORDS] {
        let n = if self.has_normals() {
            self.normal(v)
        } else {
            Vec3::ZERO
        };
        let uv = if self.has_uvs() {
            self.uv(v)
        } else {
            Vec2::ZERO
        };
        let color = if self.has_colors() {
            self.color(v)
        } else {
            u32::MAX
        };
        let b = f32::to_bits;
        [b(n.x), b(n.y), b(n.z), color, b(uv.x), b(uv.y)]
    }

    /// Vertex `v`'s normal in world space (normalised; zero where the mesh gives a zero normal).
    fn normal(&self, v: u32) -> Vec3 {
        let n = (self.object.mesh.normals.as_ref()).and_then(|ns| ns.get(v as usize));
        (self.nm * n.copied().unwrap_or(Vec3::ZERO)).normalize_or_zero()
    }

    fn uv(&self, v: u32) -> Vec2 {
        let uv = (self.object.mesh.uvs.as_ref()).and_then(|uvs| uvs.get(v as usize));
        uv.copied().unwrap_or(Vec2::ZERO)
    }

    fn has_normals(&self) -> bool {
        self.object.mesh.normals.is_some()
    }

    /// Whether the mesh has texture coordinates (every face then has them).
    pub fn has_uvs(&self) -> bool {
        self.object.mesh.uvs.is_some()
    }

    /// Whether the faces carry vertex colours: the mesh has them and the material takes them.
    pub fn has_colors(&self) -> bool {
        self.colored
    }

    fn color(&self, v: u32) -> u32 {
        let c = (self.object.mesh.colors.as_ref()).and_then(|cs| cs.get(v as usize));
        gpu_types::pack_color(c.copied().unwrap_or(Vec3::ONE).to_array())
    }
}
