//! Nested nodes: an object's world placement is its ancestors' matrices times its own, shear
//! included (a non-uniform scale above a turned node, which rt's scale-rotate-translate cannot
//! hold: such a mesh is baked in place), mirrors keep their front faces, and nodes that share a
//! mesh under plain transforms still share it (instances).

use super::*;
use glam::{Mat4, Quat, Vec3};

/// `quad B` under a parent scaled by `parent_scale`, turned 45° about y itself.
fn nested(parent_scale: [f32; 3]) -> (Scene, Mat4) {
    let mut doc = document();
    let h = std::f32::consts::FRAC_PI_8;
    let (s, c) = (h.sin(), h.cos());
    doc["nodes"][1] = json!({"name": "parent", "scale": parent_scale, "translation": [5, 0, 0],
        "children": [2]});
    doc["nodes"][2] = json!({"name": "quad B", "mesh": 0, "rotation": [0, s, 0, c]});
    let scene = load(&embedded(doc), None).unwrap();
    let world = Mat4::from_scale_rotation_translation(
        Vec3::from(parent_scale),
        Quat::IDENTITY,
        Vec3::new(5.0, 0.0, 0.0),
    ) * Mat4::from_quat(Quat::from_rotation_y(std::f32::consts::FRAC_PI_4));
    (scene, world)
}

fn world_corners(scene: &Scene, name: &str) -> Vec<Vec3> {
    let object = scene.objects.iter().find(|o| o.name == name).unwrap();
    let m = object.transform.matrix();
    let mut corners: Vec<Vec3> = (object.mesh.indices.iter())
        .flat_map(|t| t.map(|i| m.transform_point3(object.mesh.positions[i as usize])))
        .collect();
    // Compared as sets of corners: a mirror's copy may wind its triangles the other way.
    corners.sort_by(|a, b| a.to_array().partial_cmp(&b.to_array()).unwrap());
    corners
}

#[test]
fn a_sheared_node_is_placed_where_its_matrices_put_it() {
    for parent_scale in [[3.0, 1.0, 1.0], [-3.0, 1.0, 1.0], [2.0, 2.0, 2.0]] {
        let (scene, world) = nested(parent_scale);
        let quad = [
            [-1.0, 0.0, 1.0],
            [1.0, 0.0, 1.0],
            [1.0, 0.0, -1.0],
            [-1.0, 0.0, -1.0],
        ];
        let mut expected: Vec<Vec3> = [[0, 1, 2], [0, 2, 3]]
            .iter()
            .flat_map(|t: &[usize; 3]| t.map(|i| world.transform_point3(Vec3::from(quad[i]))))
            .collect();
        expected.sort_by(|a, b| a.to_array().partial_cmp(&b.to_array()).unwrap());
        let got = world_corners(&scene, "quad B");
        for (a, b) in got.iter().zip(&expected) {
            assert!(a.distance(*b) < 1e-4, "{parent_scale:?}: {a} vs {b}");
        }
        // The front face still faces the normals (up), mirrored or not.
        let object = scene.objects.iter().find(|o| o.name == "quad B").unwrap();
        let m = object.transform.matrix();
        let flip = if m.determinant() < 0.0 { -1.0 } else { 1.0 };
        let [a, b, c] = object.mesh.indices[0].map(|i| object.mesh.positions[i as usize]);
        let face = (b - a).cross(c - a) * flip;
        let n = object.mesh.normals.as_ref().unwrap()[0];
        assert!(face.dot(n) > 0.0, "{parent_scale:?}: the front turned away");
        // Plain scale-rotate-translate keeps the mesh shared with quad A.
        let shared = std::sync::Arc::ptr_eq(&object.mesh, &scene.objects[0].mesh);
        assert_eq!(shared, parent_scale == [2.0, 2.0, 2.0], "{parent_scale:?}");
    }
}
