//! glTF animations read into the scene's [`Animation`]: every node's parent and local transform
//! at rest, and the translation, rotation and scale channels of every animation in the file (all
//! play at once); `nodes.rs` records the node each mesh, camera and light hangs under, so an
//! animated camera or lamp moves too. Morph-target weights and skins are not read (rt does not
//! deform meshes).

use gltf::animation::util::ReadOutputs;
use gltf::animation::{Interpolation as GltfInterpolation, Property as GltfProperty};

use rt_core::animation::{Animation, Channel, Interpolation, Node, Property};

/// The file's animation, or `None` when it has no translation, rotation or scale channel.
pub(super) fn read_animation(
    doc: &gltf::Document,
    buffers: &[Vec<u8>],
) -> Result<Option<Animation>, String> {
    let mut channels = Vec::new();
    for animation in doc.animations() {
        for channel in animation.channels() {
            let node = channel.target().node();
            let property = match channel.target().property() {
                GltfProperty::Translation => Property::Translation,
                GltfProperty::Rotation => Property::Rotation,
                GltfProperty::Scale => Property::Scale,
                GltfProperty::MorphTargetWeights => continue,
            };
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
            let values: Vec<[f32; 4]> = match reader.read_outputs() {
                Some(ReadOutputs::Translations(v)) | Some(ReadOutputs::Scales(v)) => {
                    v.map(|[x, y, z]| [x, y, z, 0.0]).collect()
                }
                Some(ReadOutputs::Rotations(r)) => r.into_f32().collect(),
                _ => return Err(format!("{}: its values cannot be read", context())),
            };
            channels.push(Channel {
                node: node.index() as u32,
                property,
                interpolation: match channel.sampler().interpolation() {
                    GltfInterpolation::Step => Interpolation::Step,
                    GltfInterpolation::Linear => Interpolation::Linear,
                    GltfInterpolation::CubicSpline => Interpolation::CubicSpline,
                },
                times,
                values,
            });
        }
    }
    if channels.is_empty() {
        return Ok(None);
    }
    let mut nodes: Vec<Node> = doc
        .nodes()
        .map(|n| {
            let (translation, rotation, scale) = n.transform().decomposed();
            Node {
                parent: None,
                translation,
                rotation,
                scale,
            }
        })
        .collect();
    for parent in doc.nodes() {
        for child in parent.children() {
            nodes[child.index()].parent = Some(parent.index() as u32);
        }
    }
    let animation = Animation { nodes, channels };
    animation.validate()?;
    Ok(Some(animation))
}
