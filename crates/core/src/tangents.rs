//! Tangent frames for normal maps: MikkTSpace (Mikkelsen 2008, the `mikktspace` crate), the
//! convention glTF's normal maps are baked in, computed per triangle corner in object space.

use crate::scene::Mesh;

struct Corners<'a> {
    mesh: &'a Mesh,
    normals: &'a [glam::Vec3],
    uvs: &'a [glam::Vec2],
    out: Vec<[f32; 4]>,
}

impl mikktspace::Geometry for Corners<'_> {
    fn num_faces(&self) -> usize {
        self.mesh.indices.len()
    }
    fn num_vertices_of_face(&self, _face: usize) -> usize {
        3
    }
    fn position(&self, face: usize, vert: usize) -> [f32; 3] {
        self.mesh.positions[self.mesh.indices[face][vert] as usize].to_array()
    }
    fn normal(&self, face: usize, vert: usize) -> [f32; 3] {
        self.normals[self.mesh.indices[face][vert] as usize].to_array()
    }
    fn tex_coord(&self, face: usize, vert: usize) -> [f32; 2] {
        self.uvs[self.mesh.indices[face][vert] as usize].to_array()
    }
    fn set_tangent_encoded(&mut self, tangent: [f32; 4], face: usize, vert: usize) {
        self.out[face * 3 + vert] = tangent;
    }
}

/// Per triangle corner (3 per triangle, in `mesh.indices` order) the unit tangent in xyz and the
/// bitangent's sign in w (bitangent = w · normal × tangent); `None` without normals and UVs, or when
/// MikkTSpace finds the mesh unsuitable.
pub fn mikktspace_tangents(mesh: &Mesh) -> Option<Vec<[f32; 4]>> {
    let (normals, uvs) = (mesh.normals.as_deref()?, mesh.uvs.as_deref()?);
    if mesh.indices.is_empty() {
        return None;
    }
    let mut corners = Corners {
        mesh,
        normals,
        uvs,
        out: vec![[0.0; 4]; mesh.indices.len() * 3],
    };
    mikktspace::generate_tangents(&mut corners).then_some(corners.out)
}

#[cfg(test)]
mod tests {
    use glam::{Vec2, Vec3};

    /// On a quad in the xz plane facing +y whose u runs along +x and v along −z, the tangent is +x
    /// and the bitangent (w · n × t) is −z, the direction v grows in.
    #[test]
    fn a_flat_quad_gets_its_uv_axes() {
        let mut mesh = crate::shapes::quad(Vec3::ZERO, Vec3::Y, 2.0);
        mesh.normals = Some(vec![Vec3::Y; 4]);
        mesh.uvs = Some(
            mesh.positions
                .iter()
                .map(|p| Vec2::new(p.x * 0.5 + 0.5, -p.z * 0.5 + 0.5))
                .collect(),
        );
        let t = super::mikktspace_tangents(&mesh).unwrap();
        assert_eq!(t.len(), mesh.indices.len() * 3);
        for [x, y, z, w] in t {
            let tangent = Vec3::new(x, y, z);
            assert!((tangent - Vec3::X).length() < 1e-5, "{tangent}");
            let bitangent = w * Vec3::Y.cross(tangent);
            assert!((bitangent - Vec3::NEG_Z).length() < 1e-5, "{bitangent}");
        }
    }
}
