//! Vertex normals for a mesh that has none (STL always, PLY scans and many OBJ files often): each
//! corner gets the angle-weighted mean of the normals of the faces around its vertex that lie
//! within a crease angle of its own face (Thürmer and Wüthrich's angle weighting; the crease as
//! Blender's "Auto Smooth" draws it, 30° by default there), so curved surfaces shade smoothly
//! and edges sharper than the crease stay sharp. Vertices on a crease are split, one per side.
//! Faces meet at a position, not an index: vertices a file split for their texture coordinates
//! (a UV seam, as OBJ files and the loaders' single index make them) shade as one where they lie
//! within a millionth of the mesh's size of each other (a seam's two copies often differ in the
//! last bits).

use std::collections::HashMap;

use glam::Vec3;

use crate::scene::Mesh;

/// `mesh` with normals from its faces, split where faces meet at more than `crease_deg` degrees;
/// a mesh that has normals is returned as it is.
pub fn smooth_normals(mesh: &Mesh, crease_deg: f32) -> Mesh {
    if mesh.normals.is_some() || mesh.indices.is_empty() {
        return mesh.clone();
    }
    let p = |i: u32| mesh.positions[i as usize];
    let face_normals: Vec<Vec3> = mesh
        .indices
        .iter()
        .map(|t| {
            (p(t[1]) - p(t[0]))
                .cross(p(t[2]) - p(t[0]))
                .normalize_or_zero()
        })
        .collect();
    // The angle of each face at each of its corners.
    let angle = |t: &[u32; 3], c: usize| {
        let (a, b, o) = (p(t[(c + 1) % 3]), p(t[(c + 2) % 3]), p(t[c]));
        (a - o)
            .normalize_or_zero()
            .angle_between((b - o).normalize_or_zero())
    };
    // Each vertex's position group: positions on one cell of a grid a millionth of the mesh's
    // size wide.
    let size = mesh
        .positions
        .iter()
        .fold(0.0f32, |m, v| m.max(v.abs().max_element()))
        .max(f32::MIN_POSITIVE);
    let cell = f64::from(size) * 1e-6;
    let mut group_of_position: HashMap<[i64; 3], usize> = HashMap::new();
    let group: Vec<usize> = mesh
        .positions
        .iter()
        .map(|&v| {
            let next = group_of_position.len();
            let key = v.to_array().map(|c| (f64::from(c) / cell).round() as i64);
            *group_of_position.entry(key).or_insert(next)
        })
        .collect();
    let mut around: Vec<Vec<(u32, f32)>> = vec![Vec::new(); group_of_position.len()];
    for (f, t) in mesh.indices.iter().enumerate() {
        for c in 0..3 {
            let weight = angle(t, c);
            around[group[t[c] as usize]]
                .push((f as u32, if weight.is_finite() { weight } else { 0.0 }));
        }
    }
    let cos_crease = crease_deg.clamp(0.0, 180.0).to_radians().cos();
    let mut out = Mesh {
        positions: Vec::new(),
        normals: Some(Vec::new()),
        uvs: mesh.uvs.as_ref().map(|_| Vec::new()),
        colors: mesh.colors.as_ref().map(|_| Vec::new()),
        indices: Vec::with_capacity(mesh.indices.len()),
    };
    // (original vertex, the normal's bits) → the vertex made for it.
    let mut made: HashMap<(u32, [u32; 3]), u32> = HashMap::new();
    for (f, t) in mesh.indices.iter().enumerate() {
        let own = face_normals[f];
        let corner = |c: usize| {
            let v = t[c];
            let sum: Vec3 = around[group[v as usize]]
                .iter()
                .filter(|&&(g, _)| own.dot(face_normals[g as usize]) >= cos_crease - 1e-6)
                .map(|&(g, w)| face_normals[g as usize] * w)
                .sum();
            let normal = sum.try_normalize().unwrap_or(own);
            (v, normal)
        };
        let mut triangle = [0u32; 3];
        for (c, slot) in triangle.iter_mut().enumerate() {
            let (v, normal) = corner(c);
            *slot = *made
                .entry((v, normal.to_array().map(f32::to_bits)))
                .or_insert_with(|| {
                    out.positions.push(mesh.positions[v as usize]);
                    if let (Some(o), Some(n)) = (out.normals.as_mut(), Some(normal)) {
                        o.push(n);
                    }
                    if let (Some(o), Some(uvs)) = (out.uvs.as_mut(), &mesh.uvs) {
                        o.push(uvs[v as usize]);
                    }
                    if let (Some(o), Some(colors)) = (out.colors.as_mut(), &mesh.colors) {
                        o.push(colors[v as usize]);
                    }
                    (out.positions.len() - 1) as u32
                });
        }
        out.indices.push(triangle);
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    fn without_normals(mut mesh: Mesh) -> Mesh {
        mesh.normals = None;
        mesh
    }

    #[test]
    fn a_cube_keeps_its_edges_below_ninety_degrees_and_rounds_them_above() {
        let cube = without_normals(crate::shapes::cuboid(Vec3::splat(-1.0), Vec3::ONE, false));
        let faceted = smooth_normals(&cube, 30.0);
        let normals = faceted.normals.as_ref().unwrap();
        for t in &faceted.indices {
            let face = (faceted.positions[t[1] as usize] - faceted.positions[t[0] as usize])
                .cross(faceted.positions[t[2] as usize] - faceted.positions[t[0] as usize])
                .normalize();
            for &i in t {
                assert!(
                    (normals[i as usize] - face).length() < 1e-5,
                    "a corner off its face's normal"
                );
            }
        }
        // Above 90°, each corner is the mean over the three faces at its vertex: the diagonal.
        let round = smooth_normals(&cube, 100.0);
        for (p, n) in round.positions.iter().zip(round.normals.as_ref().unwrap()) {
            assert!((*n - p.normalize()).length() < 1e-5, "{n} at {p}");
        }
        assert_eq!(round.positions.len(), 8, "one vertex a corner, none split");
    }

    #[test]
    fn a_faceted_sphere_shades_radially() {
        let sphere = without_normals(crate::shapes::uv_sphere(1.0, 24, 48));
        let smooth = smooth_normals(&sphere, 30.0);
        for (p, n) in smooth
            .positions
            .iter()
            .zip(smooth.normals.as_ref().unwrap())
        {
            if p.y.abs() < 0.99 {
                assert!(n.dot(p.normalize()) > 0.999, "{n} at {p}");
            }
        }
        let mut given = sphere.clone();
        given.normals = Some(vec![Vec3::Z; sphere.positions.len()]);
        assert_eq!(
            smooth_normals(&given, 30.0),
            given,
            "normals given are kept"
        );
    }
}
