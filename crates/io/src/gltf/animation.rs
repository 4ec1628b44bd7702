//! glTF animations evaluated at one time: the translation, rotation and scale channels of every
//! animation in the file, sampled with their interpolation (STEP, LINEAR with spherical rotation,
//! CUBICSPLINE), give the nodes they move new local transforms; `nodes.rs` places meshes, cameras
//! and lights under them, so an animated camera or lamp moves too. Morph-target weights and skins
//! are not animated (rt does not deform meshes).

use std::collections::HashMap;

use glam::{Mat4, Quat, Vec3, Vec4};
use gltf::animation::util::ReadOutputs;
use gltf::animation::{Interpolation, Property};

/// A node's local translation, rotation and scale.
#[derive(Clone, Copy)]
struct Trs {
    translation: Vec3,
    rotation: Quat,
    scale: Vec3,
}

/// The local matrices, at `time` seconds, of the nodes the file's animations move (all of its
/// animations play at once); also whether the file has any animation channel at all.
pub(super) fn animated_locals(
    doc: &gltf::Document,
    buffers: &[Vec<u8>],
    time: f32,
) -> Result<(HashMap<usize, Mat4>, bool), String> {
    let mut moved: HashMap<usize, Trs> = HashMap::new();
    let mut any = false;
    for animation in doc.animations() {
        for channel in animation.channels() {
            let node = channel.target().node();
            let property = channel.target().property();
            if property == Property::MorphTargetWeights {
                continue;
            }
            any = true;
            let reader = channel.reader(|b| buffers.get(b.index()).map(Vec::as_slice));
            let context = || {
                format!(
                    "animation {} channel targeting node {}",
                    animation.index(),
                    node.index()
                )
            };
            let times: Vec<f32> = reader
                .read_inputs()
                .ok_or_else(|| format!("{}: its key times cannot be read", context()))?
                .collect();
            let values: Vec<Vec4> = match reader.read_outputs() {
                Some(ReadOutputs::Translations(v)) | Some(ReadOutputs::Scales(v)) => {
                    v.map(|p| Vec3::from(p).extend(0.0)).collect()
                }
                Some(ReadOutputs::Rotations(r)) => r.into_f32().map(Vec4::from).collect(),
                _ => return Err(format!("{}: its values cannot be read", context())),
            };
            let interpolation = channel.sampler().interpolation();
            let spherical = property == Property::Rotation;
            let value = sample(&times, &values, interpolation, spherical, time)
                .ok_or_else(|| format!("{}: its keys and values do not match", context()))?;
            let (t, r, s) = node.transform().decomposed();
            let trs = moved.entry(node.index()).or_insert(Trs {
                translation: Vec3::from(t),
                rotation: Quat::from_array(r),
                scale: Vec3::from(s),
            });
            match property {
                Property::Translation => trs.translation = value.truncate(),
                Property::Scale => trs.scale = value.truncate(),
                _ => trs.rotation = Quat::from_vec4(value).normalize(),
            }
        }
    }
    let locals = moved
        .into_iter()
        .map(|(node, t)| {
            let m = Mat4::from_scale_rotation_translation(t.scale, t.rotation, t.translation);
            (node, m)
        })
        .collect();
    Ok((locals, any))
}

/// A channel's value at `time`: the first key's before it, the last's after it; `None` when the
/// counts of keys and values disagree (or there are no keys). Rotations (`spherical`) are
/// interpolated linearly along the sphere; a cubic spline's outputs are (in-tangent, value,
/// out-tangent) triples (glTF 2.0 Appendix C).
fn sample(
    times: &[f32],
    values: &[Vec4],
    interpolation: Interpolation,
    spherical: bool,
    time: f32,
) -> Option<Vec4> {
    let per_key = if interpolation == Interpolation::CubicSpline {
        3
    } else {
        1
    };
    if times.is_empty() || values.len() != times.len() * per_key {
        return None;
    }
    let value = |k: usize| values[k * per_key + per_key / 2];
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
    Some(match interpolation {
        Interpolation::Step => value(k),
        Interpolation::Linear if spherical => {
            let (a, b) = (Quat::from_vec4(value(k)), Quat::from_vec4(value(k + 1)));
            Vec4::from(a.normalize().slerp(b.normalize(), s))
        }
        Interpolation::Linear => value(k).lerp(value(k + 1), s),
        Interpolation::CubicSpline => {
            let out_tangent = values[k * 3 + 2] * span;
            let in_tangent = values[(k + 1) * 3] * span;
            let (s2, s3) = (s * s, s * s * s);
            value(k) * (2.0 * s3 - 3.0 * s2 + 1.0)
                + out_tangent * (s3 - 2.0 * s2 + s)
                + value(k + 1) * (-2.0 * s3 + 3.0 * s2)
                + in_tangent * (s3 - s2)
        }
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn linear_step_and_cubic_keys_interpolate_and_hold_at_the_ends() {
        let times = [1.0, 3.0];
        let values = [Vec4::new(0.0, 0.0, 0.0, 0.0), Vec4::new(4.0, 2.0, 0.0, 0.0)];
        let at = |i, t| sample(&times, &values, i, false, t).unwrap();
        assert_eq!(
            at(Interpolation::Linear, 2.0),
            Vec4::new(2.0, 1.0, 0.0, 0.0)
        );
        assert_eq!(
            at(Interpolation::Linear, 0.0),
            values[0],
            "before the first key"
        );
        assert_eq!(
            at(Interpolation::Linear, 9.0),
            values[1],
            "after the last key"
        );
        assert_eq!(at(Interpolation::Step, 2.9), values[0]);
        // A cubic spline with zero tangents eases: halfway is halfway, a quarter is 5/32.
        let cubic = [
            Vec4::ZERO,
            values[0],
            Vec4::ZERO,
            Vec4::ZERO,
            values[1],
            Vec4::ZERO,
        ];
        let c = |t| sample(&times, &cubic, Interpolation::CubicSpline, false, t).unwrap();
        assert!((c(2.0).x - 2.0).abs() < 1e-6);
        assert!((c(1.5).x - 4.0 * 5.0 / 32.0).abs() < 1e-6);
        // Rotations turn along the sphere: halfway between 0 and 90° about y is 45°.
        let q = [
            Vec4::from(Quat::IDENTITY),
            Vec4::from(Quat::from_rotation_y(std::f32::consts::FRAC_PI_2)),
        ];
        let half = Quat::from_vec4(sample(&times, &q, Interpolation::Linear, true, 2.0).unwrap());
        assert!(half.angle_between(Quat::from_rotation_y(std::f32::consts::FRAC_PI_4)) < 1e-5);
        assert!(sample(&times, &values[..1], Interpolation::Linear, false, 2.0).is_none());
    }
}
