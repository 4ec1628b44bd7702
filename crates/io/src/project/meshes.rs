//! The mesh entries (`meshes/N.bin`): rt's little-endian mesh layout, written and read back with
//! every size and index checked.

use glam::{Vec2, Vec3};

use rt_core::error::Result;
use rt_core::scene::Mesh;

const MESH_MAGIC: &[u8; 8] = b"RTMESH1\0";

/// `MESH_MAGIC`, then u32 vertex count, u32 triangle count, u32 flags (1: normals, 2: UVs, 4: vertex
/// colours), then positions (3 f32 per vertex), normals (3 f32), UVs (2 f32), colours (3 f32) and
/// indices (3 u32 per triangle), all little-endian.
pub fn encode_mesh(mesh: &Mesh) -> Vec<u8> {
    let n = mesh.positions.len();
    let mut out = Vec::with_capacity(20 + n * 32 + mesh.indices.len() * 12);
    out.extend_from_slice(MESH_MAGIC);
    let flags = u32::from(mesh.normals.is_some())
        | (u32::from(mesh.uvs.is_some()) << 1)
        | (u32::from(mesh.colors.is_some()) << 2);
    for v in [n as u32, mesh.indices.len() as u32, flags] {
        out.extend_from_slice(&v.to_le_bytes());
    }
    let mut put = |v: f32| out.extend_from_slice(&v.to_le_bytes());
    for p in &mesh.positions {
        p.to_array().into_iter().for_each(&mut put);
    }
    for normal in mesh.normals.iter().flatten() {
        normal.to_array().into_iter().for_each(&mut put);
    }
    for uv in mesh.uvs.iter().flatten() {
        uv.to_array().into_iter().for_each(&mut put);
    }
    for colour in mesh.colors.iter().flatten() {
        colour.to_array().into_iter().for_each(&mut put);
    }
    for tri in &mesh.indices {
        for i in tri {
            out.extend_from_slice(&i.to_le_bytes());
        }
    }
    out
}

pub fn decode_mesh(bytes: &[u8]) -> Result<Mesh, String> {
    let header = bytes
        .get(..20)
        .filter(|h| h.starts_with(MESH_MAGIC))
        .ok_or("not an rt mesh (bad header)")?;
    let word =
        |i: usize| u32::from_le_bytes([header[i], header[i + 1], header[i + 2], header[i + 3]]);
    let (vertices, triangles, flags) = (word(8) as usize, word(12) as usize, word(16));
    if flags > 7 {
        return Err(format!("unknown mesh flags {flags}"));
    }
    let floats_per_vertex =
        3 + 3 * (flags & 1) as usize + 2 * ((flags >> 1) & 1) as usize + 3 * (flags >> 2) as usize;
    let expected = (vertices as u128) * (floats_per_vertex as u128) * 4 + (triangles as u128) * 12;
    if expected != (bytes.len() - 20) as u128 {
        return Err(format!(
            "{vertices} vertices and {triangles} triangles need {expected} bytes, found {}",
            bytes.len() - 20
        ));
    }
    let mut words = bytes[20..]
        .chunks_exact(4)
        .map(|c| [c[0], c[1], c[2], c[3]]);
    let mut float = || f32::from_le_bytes(words.next().unwrap_or_default());
    let positions: Vec<Vec3> = (0..vertices)
        .map(|_| Vec3::new(float(), float(), float()))
        .collect();
    let normals = (flags & 1 != 0).then(|| {
        (0..vertices)
            .map(|_| Vec3::new(float(), float(), float()))
            .collect()
    });
    let uvs =
        (flags & 2 != 0).then(|| (0..vertices).map(|_| Vec2::new(float(), float())).collect());
    let colors = (flags & 4 != 0).then(|| {
        (0..vertices)
            .map(|_| Vec3::new(float(), float(), float()))
            .collect()
    });
    let offset = 20 + vertices * floats_per_vertex * 4;
    let indices: Vec<[u32; 3]> = bytes[offset..]
        .chunks_exact(12)
        .map(|c| {
            let u = |i: usize| u32::from_le_bytes([c[i], c[i + 1], c[i + 2], c[i + 3]]);
            [u(0), u(4), u(8)]
        })
        .collect();
    if let Some((t, tri)) = indices
        .iter()
        .enumerate()
        .find(|(_, tri)| tri.iter().any(|&i| i as usize >= vertices))
    {
        return Err(format!("triangle {t} indexes vertex {tri:?} of {vertices}"));
    }
    if let Some(v) = positions.iter().position(|p| !p.is_finite()) {
        return Err(format!("vertex {v} is not finite"));
    }
    Ok(Mesh {
        positions,
        normals,
        uvs,
        colors,
        indices,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn mesh_encoding_round_trips_with_and_without_attributes() {
        let mut mesh = rt_core::shapes::uv_sphere(1.0, 4, 6);
        assert_eq!(decode_mesh(&encode_mesh(&mesh)).unwrap(), mesh);
        mesh.normals = None;
        mesh.uvs = None;
        assert_eq!(decode_mesh(&encode_mesh(&mesh)).unwrap(), mesh);
    }

    #[test]
    fn mesh_decoding_rejects_bad_sizes_and_indices() {
        let mesh = rt_core::shapes::quad(Vec3::ZERO, Vec3::Z, 1.0);
        let bytes = encode_mesh(&mesh);
        assert!(decode_mesh(&bytes[..bytes.len() - 1]).is_err());
        assert!(decode_mesh(&bytes[..10]).is_err());
        let mut bad = bytes.clone();
        let last = bad.len() - 4;
        bad[last..].copy_from_slice(&99u32.to_le_bytes());
        assert!(decode_mesh(&bad).unwrap_err().contains("vertex"));
    }
}
