//! Procedural meshes: test scenes, and primitives the editor can add.

use glam::Vec3;

use crate::scene::Mesh;

/// A UV sphere of `radius` at the origin, outward-facing (counter-clockwise seen from outside).
pub fn uv_sphere(radius: f32, rings: u32, segments: u32) -> Mesh {
    let mut positions = Vec::new();
    let mut normals = Vec::new();
    for r in 0..=rings {
        let theta = std::f32::consts::PI * r as f32 / rings as f32;
        for s in 0..=segments {
            let phi = std::f32::consts::TAU * s as f32 / segments as f32;
            let n = Vec3::new(
                theta.sin() * phi.cos(),
                theta.cos(),
                theta.sin() * phi.sin(),
            );
            positions.push(n * radius);
            normals.push(n);
        }
    }
    let mut indices = Vec::new();
    let row = segments + 1;
    for r in 0..rings {
        for s in 0..segments {
            let (a, b, c, d) = (
                r * row + s,
                (r + 1) * row + s,
                (r + 1) * row + s + 1,
                r * row + s + 1,
            );
            if r != 0 {
                indices.push([a, d, b]);
            }
            if r + 1 != rings {
                indices.push([d, c, b]);
            }
        }
    }
    Mesh {
        positions,
        normals: Some(normals),
        uvs: None,
        colors: None,
        indices,
    }
}

/// An axis-aligned rectangle centred at `center`, facing `normal` (±X, ±Y or ±Z), `size` per side.
pub fn quad(center: Vec3, normal: Vec3, size: f32) -> Mesh {
    let (t, b) = crate::math::sampling::onb(normal.normalize());
    let h = size * 0.5;
    let positions = vec![
        center - t * h - b * h,
        center + t * h - b * h,
        center + t * h + b * h,
        center - t * h + b * h,
    ];
    // onb gives t × b = n, so (0, 1, 2) is counter-clockwise seen from the front.
    Mesh {
        positions,
        normals: None,
        uvs: None,
        colors: None,
        indices: vec![[0, 1, 2], [0, 2, 3]],
    }
}

/// An axis-aligned box with outward faces; `inward` flips them (a room seen from inside).
pub fn cuboid(min: Vec3, max: Vec3, inward: bool) -> Mesh {
    let c = |x: bool, y: bool, z: bool| {
        Vec3::new(
            if x { max.x } else { min.x },
            if y { max.y } else { min.y },
            if z { max.z } else { min.z },
        )
    };
    let positions: Vec<Vec3> = (0..8)
        .map(|i| c(i & 1 != 0, i & 2 != 0, i & 4 != 0))
        .collect();
    // Each face as four corners counter-clockwise seen from outside.
    let faces = [
        [0, 4, 6, 2],
        [1, 3, 7, 5],
        [0, 1, 5, 4],
        [2, 6, 7, 3],
        [0, 2, 3, 1],
        [4, 5, 7, 6],
    ];
    let mut indices = Vec::new();
    for f in faces {
        let (a, b, cc, d) = (f[0], f[1], f[2], f[3]);
        if inward {
            indices.push([a, cc, b]);
            indices.push([a, d, cc]);
        } else {
            indices.push([a, b, cc]);
            indices.push([a, cc, d]);
        }
    }
    Mesh {
        positions,
        normals: None,
        uvs: None,
        colors: None,
        indices,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn outward(mesh: &Mesh, center: Vec3) -> bool {
        mesh.indices.iter().all(|t| {
            let p = t.map(|i| mesh.positions[i as usize]);
            let n = (p[1] - p[0]).cross(p[2] - p[0]);
            n.length() < 1e-9 || n.dot((p[0] + p[1] + p[2]) / 3.0 - center) > 0.0
        })
    }

    #[test]
    fn generated_meshes_face_outward() {
        assert!(outward(&uv_sphere(1.0, 8, 16), Vec3::ZERO));
        assert!(outward(
            &cuboid(Vec3::splat(-1.0), Vec3::ONE, false),
            Vec3::ZERO
        ));
        assert!(!outward(
            &cuboid(Vec3::splat(-1.0), Vec3::ONE, true),
            Vec3::ZERO
        ));
        let q = quad(Vec3::ZERO, Vec3::Z, 2.0);
        let n = (q.positions[1] - q.positions[0]).cross(q.positions[2] - q.positions[0]);
        assert!(n.normalize().dot(Vec3::Z) > 0.99);
    }
}
