//! The scene at a time of its animation (`crate::animation`): objects, lights and the camera moved
//! with the nodes that carry them, and the placement of a mesh by a world matrix that rt's
//! transforms cannot hold (shear), which the glTF loader shares. Tested with the animation
//! (`animation/tests.rs`).

use std::sync::Arc;

use glam::{Mat3, Mat4, Vec3};

use crate::scene::{Mesh, Scene, Transform};

/// The scene at `time` seconds: what each node carries moved with it (see the module's doc).
/// The result holds no animation (its objects stand where the time put them, so posing it again
/// would move them twice); a scene without one is returned as it is.
pub fn posed_at(scene: &Scene, time: f32) -> Scene {
    let mut posed = scene.clone();
    let Some(animation) = posed.animation.take() else {
        return posed;
    };
    let rest = animation.world_matrices(None);
    let now = animation.world_matrices(Some(time));
    // How a node moved since rest, or `None` where its rest matrix cannot be undone.
    let moved = |node: Option<u32>| -> Option<Result<Mat4, Mat4>> {
        let i = node? as usize;
        let (rest, now) = (*rest.get(i)?, *now.get(i)?);
        let undo = rest.inverse();
        Some(if rest.determinant() != 0.0 && undo.is_finite() {
            Ok(now * undo)
        } else {
            Err(now)
        })
    };
    for object in &mut posed.objects {
        let Some(motion) = moved(object.animation_node) else {
            continue;
        };
        let world = match motion {
            Ok(delta) => delta * object.transform.matrix(),
            Err(node) => node,
        };
        (object.mesh, object.transform) = if world.determinant() == 0.0 {
            // Scaled to nothing at this time (objects that shrink away): it draws nothing, as in
            // Blender, where a still scene's singular transform is an error naming the object.
            (Arc::new(Mesh::default()), Transform::default())
        } else {
            placed(object.mesh.clone(), world)
        };
    }
    for light in &mut posed.lights {
        let Some(motion) = moved(light.animation_node) else {
            continue;
        };
        let (position, direction) = match motion {
            Ok(delta) => (
                delta.transform_point3(Vec3::from(light.position)),
                delta.transform_vector3(Vec3::from(light.direction)),
            ),
            Err(node) => (
                node.transform_point3(Vec3::ZERO),
                node.transform_vector3(Vec3::NEG_Z),
            ),
        };
        light.position = position.to_array();
        let direction = direction.normalize_or_zero();
        if direction != Vec3::ZERO {
            light.direction = direction.to_array();
        }
    }
    if let Some(motion) = moved(posed.camera.animation_node) {
        let camera = &mut posed.camera;
        let (from, to, up) = match motion {
            Ok(delta) => (
                delta.transform_point3(Vec3::from(camera.from)),
                delta.transform_point3(Vec3::from(camera.to)),
                delta.transform_vector3(Vec3::from(camera.up)),
            ),
            Err(node) => {
                let from = node.transform_point3(Vec3::ZERO);
                let forward = node.transform_vector3(Vec3::NEG_Z).normalize_or_zero();
                (from, from + forward, node.transform_vector3(Vec3::Y))
            }
        };
        let up = up.normalize_or_zero();
        if from.is_finite() && to.is_finite() && from != to && up != Vec3::ZERO {
            camera.from = from.to_array();
            camera.to = to.to_array();
            camera.up = up.to_array();
        }
    }
    posed
}

/// `scene` with the objects an animation carries but has scaled to nothing where they stand (at
/// rest, objects that later frames grow in) drawing nothing: their meshes empty, their indices
/// kept. `None` where there are none. (Any other singular transform is an error naming the
/// object, `ObjectFrame::check_transform`.)
pub fn with_vanished_hidden(scene: &Scene) -> Option<Scene> {
    let vanished = |o: &crate::scene::Object| {
        o.animation_node.is_some() && o.transform.matrix().determinant() == 0.0
    };
    if !scene.objects.iter().any(vanished) {
        return None;
    }
    let mut shown = scene.clone();
    for object in shown.objects.iter_mut().filter(|o| vanished(o)) {
        (object.mesh, object.transform) = (Arc::new(Mesh::default()), Transform::default());
    }
    Some(shown)
}

/// A mesh and rt's transform for a world matrix. A matrix with shear (a non-uniform scale above a
/// turned node), which scale-rotate-translate cannot hold, is baked into a copy of the mesh placed
/// unmoved (positions by the matrix, normals by its inverse transpose, the winding turned over
/// where it mirrors): the right shape, at the cost of that copy not being shared.
pub fn placed(mesh: Arc<Mesh>, world: Mat4) -> (Arc<Mesh>, Transform) {
    let transform = transform_of(world);
    let held = transform.matrix();
    let size = world
        .to_cols_array()
        .iter()
        .fold(0.0f32, |m, v| m.max(v.abs()));
    let off = (held - world)
        .to_cols_array()
        .iter()
        .fold(0.0f32, |m, v| m.max(v.abs()));
    if off <= 1e-5 * size.max(1.0) || world.determinant() == 0.0 {
        return (mesh, transform);
    }
    let normals = Mat3::from_mat4(world).inverse().transpose();
    let mut baked = Mesh {
        positions: mesh
            .positions
            .iter()
            .map(|p| world.transform_point3(*p))
            .collect(),
        normals: (mesh.normals.as_ref()).map(|ns| {
            ns.iter()
                .map(|n| (normals * *n).normalize_or_zero())
                .collect()
        }),
        ..(*mesh).clone()
    };
    if world.determinant() < 0.0 {
        for t in &mut baked.indices {
            t.swap(1, 2);
        }
    }
    (Arc::new(baked), Transform::default())
}

/// rt's TRS of a world matrix. A singular one (an axis scaled to nothing) keeps its axes' lengths
/// as the scale and the turn of the axes that remain, so that the numbers stay finite (a project
/// holds only finite ones).
pub fn transform_of(world: Mat4) -> Transform {
    let (mut scale, mut rotation, translation) = world.to_scale_rotation_translation();
    if !(scale.is_finite() && rotation.is_finite()) {
        let axes = [world.x_axis, world.y_axis, world.z_axis].map(|a| a.truncate());
        scale = Vec3::from(axes.map(|a| a.length()));
        rotation = turn_of_axes(axes);
    }
    let (x, y, z) = rotation.to_euler(glam::EulerRot::XYZ);
    Transform {
        translation: translation.to_array(),
        rotation_deg: [x.to_degrees(), y.to_degrees(), z.to_degrees()],
        scale: scale.to_array(),
    }
}

/// The rotation whose x, y and z axes point along `axes` as far as they are not degenerate: the
/// longest axis kept, the next made perpendicular to it, the third their cross product (in the
/// right-handed order); the identity where no axis has a length.
fn turn_of_axes(axes: [Vec3; 3]) -> glam::Quat {
    let mut order = [0usize, 1, 2];
    order.sort_by(|&a, &b| {
        axes[b]
            .length_squared()
            .total_cmp(&axes[a].length_squared())
    });
    let [i, j, k] = order;
    let Some(first) = axes[i].try_normalize() else {
        return glam::Quat::IDENTITY;
    };
    let second = (axes[j] - first * axes[j].dot(first))
        .try_normalize()
        .unwrap_or_else(|| first.any_orthonormal_vector());
    let mut basis = [Vec3::ZERO; 3];
    basis[i] = first;
    basis[j] = second;
    // (i, j, k) cyclic: e_k = e_i × e_j; otherwise e_k = e_j × e_i.
    basis[k] = if (j + 3 - i) % 3 == 1 {
        first.cross(second)
    } else {
        second.cross(first)
    };
    glam::Quat::from_mat3(&Mat3::from_cols(basis[0], basis[1], basis[2]))
}
