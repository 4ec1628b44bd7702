//! Animation kept with the scene: the node hierarchy a glTF file's animations move, their
//! translation, rotation and scale channels (all of the file's animations play at once), and,
//! on each object, light and the camera, the node that carries it (`animation_node`).
//!
//! The scene holds the nodes at rest (as the file places them without its animation);
//! [`posed_at`] gives the scene at a time: each carried thing moves by its node's world matrix at
//! that time times the inverse of the node's world matrix at rest, so that an object the user has
//! since moved keeps that move. A node whose world matrix at rest is singular (scaled to zero, as
//! exporters write objects that grow in) places what it carries as the file's loader would: an
//! object's mesh in the node's space, a light or camera at its origin looking down its −z.
//!
//! Keys are sampled as glTF 2.0 says (Appendix C): STEP, LINEAR (rotations along the sphere) and
//! CUBICSPLINE, holding the first key before it and the last after it. Morph weights and skins are
//! not kept (rt does not deform meshes).

use std::sync::Arc;

use glam::{Mat3, Mat4, Quat, Vec3, Vec4};
use serde::{Deserialize, Serialize};

use crate::scene::{Mesh, Scene, Transform};

/// Node chains deeper than this are refused (the glTF loader's limit too).
pub const MAX_NODE_DEPTH: usize = 1024;

/// The animated node hierarchy and its channels.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Animation {
    pub nodes: Vec<Node>,
    pub channels: Vec<Channel>,
}

/// A node at rest: its parent (an index into [`Animation::nodes`]) and local transform.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Node {
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub parent: Option<u32>,
    pub translation: [f32; 3],
    /// A unit quaternion, x, y, z, w (glTF's order).
    pub rotation: [f32; 4],
    pub scale: [f32; 3],
}

/// Which part of a node's local transform a channel sets.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Property {
    Translation,
    Rotation,
    Scale,
}

/// How a channel's values go from key to key.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Interpolation {
    Step,
    Linear,
    /// Cubic Hermite: each key has (in-tangent, value, out-tangent).
    CubicSpline,
}

/// One animated property of one node: key times in seconds and their values (xyz and 0 for
/// translation and scale, a quaternion xyzw for rotation; three per key for a cubic spline).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Channel {
    pub node: u32,
    pub property: Property,
    pub interpolation: Interpolation,
    pub times: Vec<f32>,
    pub values: Vec<[f32; 4]>,
}

impl Animation {
    /// Why this animation cannot be played, naming the node or channel: node indices out of range,
    /// parents in a circle or deeper than [`MAX_NODE_DEPTH`], key counts that do not match,
    /// times that are not finite or decrease, values that are not finite.
    pub fn validate(&self) -> Result<(), String> {
        let n = self.nodes.len();
        for (i, node) in self.nodes.iter().enumerate() {
            let finite = node
                .translation
                .iter()
                .chain(&node.rotation)
                .chain(&node.scale);
            if !finite.into_iter().all(|v| v.is_finite()) {
                return Err(format!("animation node {i}: its transform is not finite"));
            }
            let mut depth = 0;
            let mut at = node.parent;
            while let Some(p) = at {
                let parent = self.nodes.get(p as usize).ok_or_else(|| {
                    format!("animation node {i}: its ancestor {p} is not a node (there are {n})")
                })?;
                depth += 1;
                if depth > MAX_NODE_DEPTH {
                    return Err(format!(
                        "animation node {i}: its ancestors circle or nest deeper than \
                         {MAX_NODE_DEPTH} levels"
                    ));
                }
                at = parent.parent;
            }
        }
        for (c, channel) in self.channels.iter().enumerate() {
            let what = |m: &str| format!("animation channel {c} (node {}): {m}", channel.node);
            if channel.node as usize >= n {
                return Err(what(&format!("there is no such node (there are {n})")));
            }
            let per_key = if channel.interpolation == Interpolation::CubicSpline {
                3
            } else {
                1
            };
            if channel.times.is_empty() || channel.values.len() != channel.times.len() * per_key {
                return Err(what(&format!(
                    "{} key times and {} values do not match",
                    channel.times.len(),
                    channel.values.len()
                )));
            }
            if channel.times.iter().any(|t| !t.is_finite())
                || channel.times.windows(2).any(|w| w[1] < w[0])
            {
                return Err(what("its key times are not finite and increasing"));
            }
            if channel.values.iter().flatten().any(|v| !v.is_finite()) {
                return Err(what("its values are not finite"));
            }
        }
        Ok(())
    }

    /// Every node's world matrix at `time` seconds, or at rest with `None`.
    pub fn world_matrices(&self, time: Option<f32>) -> Vec<Mat4> {
        let mut locals: Vec<(Vec3, Quat, Vec3)> = self
            .nodes
            .iter()
            .map(|n| {
                (
                    Vec3::from(n.translation),
                    Quat::from_array(n.rotation),
                    Vec3::from(n.scale),
                )
            })
            .collect();
        if let Some(time) = time {
            for channel in &self.channels {
                let Some(local) = locals.get_mut(channel.node as usize) else {
                    continue;
                };
                let Some(value) = sample(channel, time) else {
                    continue;
                };
                match channel.property {
                    Property::Translation => local.0 = value.truncate(),
                    Property::Rotation => local.1 = Quat::from_vec4(value).normalize(),
                    Property::Scale => local.2 = value.truncate(),
                }
            }
        }
        let mut world: Vec<Option<Mat4>> = vec![None; self.nodes.len()];
        let mut chain = Vec::new();
        for i in 0..self.nodes.len() {
            // Up to the first ancestor already placed (validated: no circles), then back down.
            let mut at = Some(i as u32);
            while let Some(node) =
                at.filter(|&n| world.get(n as usize).is_some_and(Option::is_none))
            {
                chain.push(node as usize);
                at = self.nodes[node as usize].parent;
                if chain.len() > MAX_NODE_DEPTH + 1 {
                    break;
                }
            }
            let mut parent = at.and_then(|p| world.get(p as usize).copied().flatten());
            while let Some(node) = chain.pop() {
                let (t, r, s) = locals[node];
                let local = Mat4::from_scale_rotation_translation(s, r, t);
                let placed = parent.map_or(local, |p| p * local);
                world[node] = Some(placed);
                parent = Some(placed);
            }
        }
        world.into_iter().map(Option::unwrap_or_default).collect()
    }
}

/// A channel's value at `time`: the first key's before it, the last's after it; `None` for a
/// channel [`Animation::validate`] refuses.
pub fn sample(channel: &Channel, time: f32) -> Option<Vec4> {
    let (times, values) = (&channel.times, &channel.values);
    let per_key = if channel.interpolation == Interpolation::CubicSpline {
        3
    } else {
        1
    };
    if times.is_empty() || values.len() != times.len() * per_key {
        return None;
    }
    let value = |k: usize| Vec4::from(values[k * per_key + per_key / 2]);
    let last = times.len() - 1;
    if time.is_nan() || time <= times[0] {
        return Some(value(0));
    }
    if time >= times[last] {
        return Some(value(last));
    }
    // The key interval holding `time`: times[k] <= time < times[k + 1].
    let k = times
        .partition_point(|t| *t <= time)
        .saturating_sub(1)
        .min(last - 1);
    let span = times[k + 1] - times[k];
    let s = if span > 0.0 {
        (time - times[k]) / span
    } else {
        0.0
    };
    Some(match channel.interpolation {
        Interpolation::Step => value(k),
        Interpolation::Linear if channel.property == Property::Rotation => {
            let (a, b) = (Quat::from_vec4(value(k)), Quat::from_vec4(value(k + 1)));
            Vec4::from(a.normalize().slerp(b.normalize(), s))
        }
        Interpolation::Linear => value(k).lerp(value(k + 1), s),
        Interpolation::CubicSpline => {
            let out_tangent = Vec4::from(values[k * 3 + 2]) * span;
            let in_tangent = Vec4::from(values[(k + 1) * 3]) * span;
            let (s2, s3) = (s * s, s * s * s);
            value(k) * (2.0 * s3 - 3.0 * s2 + 1.0)
                + out_tangent * (s3 - 2.0 * s2 + s)
                + value(k + 1) * (-2.0 * s3 + 3.0 * s2)
                + in_tangent * (s3 - s2)
        }
    })
}

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
        Some(if rest.determinant().abs() > 1e-12 {
            Ok(now * rest.inverse())
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
        (object.mesh, object.transform) = placed(object.mesh.clone(), world);
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

/// rt's TRS of a world matrix.
pub fn transform_of(world: Mat4) -> Transform {
    let (scale, rotation, translation) = world.to_scale_rotation_translation();
    let (x, y, z) = rotation.to_euler(glam::EulerRot::XYZ);
    Transform {
        translation: translation.to_array(),
        rotation_deg: [x.to_degrees(), y.to_degrees(), z.to_degrees()],
        scale: scale.to_array(),
    }
}

#[cfg(test)]
mod tests;
