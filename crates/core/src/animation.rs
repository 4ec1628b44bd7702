//! Animation kept with the scene: the node hierarchy a glTF file's animations move, their
//! translation, rotation and scale channels (all of the file's animations play at once), and,
//! on each object, light and the camera, the node that carries it (`animation_node`).
//!
//! The scene holds the nodes at rest (as the file places them without its animation);
//! `crate::posing::posed_at` gives the scene at a time: each carried thing moves by its node's world matrix at
//! that time times the inverse of the node's world matrix at rest, so that an object the user has
//! since moved keeps that move. A node whose world matrix at rest is singular (scaled to zero, as
//! exporters write objects that grow in) places what it carries as the file's loader would: an
//! object's mesh in the node's space, a light or camera at its origin looking down its −z.
//!
//! Keys are sampled as glTF 2.0 says (Appendix C): STEP, LINEAR (rotations along the sphere) and
//! CUBICSPLINE, holding the first key before it and the last after it. Morph weights and skins are
//! not kept (rt does not deform meshes).

use glam::{Mat4, Quat, Vec3, Vec4};
use serde::{Deserialize, Serialize};

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

#[cfg(test)]
mod tests;
