//! `KHR_draco_mesh_compression`: a primitive's triangles and attributes decoded from its Draco
//! bitstream with `draco-core` (a pure-Rust decoder of Google's format, edgebreaker and
//! sequential meshes alike), mapped back onto the glTF semantics by the extension's attribute
//! ids. Values come out as the file's attributes hold them: floats, or integers read as
//! normalized where the attribute says so.

use draco_core::decoder_buffer::DecoderBuffer;
use draco_core::draco_types::DataType;
use draco_core::geometry_attribute::PointAttribute;
use draco_core::geometry_indices::{FaceIndex, PointIndex};
use draco_core::mesh::Mesh;
use draco_core::mesh_decoder::MeshDecoder;

/// A decoded primitive: every attribute per point, and the triangles.
pub struct DracoPrimitive {
    /// Each glTF attribute the extension names (`POSITION`, `NORMAL`, `TEXCOORD_0`, …), per point,
    /// `components` floats each.
    attributes: Vec<(String, usize, Vec<f32>)>,
    pub indices: Vec<u32>,
}

impl DracoPrimitive {
    /// The named attribute's values, `N` per point (missing or of other width: `None`).
    pub fn attribute<const N: usize>(&self, name: &str) -> Option<Vec<[f32; N]>> {
        let (_, components, values) = self.attributes.iter().find(|(n, _, _)| n == name)?;
        (*components == N).then(|| {
            values
                .chunks_exact(N)
                .map(|c| std::array::from_fn(|i| c[i]))
                .collect()
        })
    }
}

/// Decodes `bytes` (the extension's buffer view), reading the attributes `ids` maps from glTF
/// semantics to Draco attribute ids.
pub fn decode(
    bytes: &[u8],
    ids: &serde_json::Map<String, serde_json::Value>,
) -> Result<DracoPrimitive, String> {
    let mut mesh = Mesh::new();
    MeshDecoder::new()
        .decode(&mut DecoderBuffer::new(bytes), &mut mesh)
        .map_err(|e| format!("the Draco stream does not decode: {e:?}"))?;
    let points = mesh.num_points();
    let mut indices = Vec::with_capacity(3 * mesh.num_faces());
    for f in 0..mesh.num_faces() {
        for PointIndex(p) in mesh.face(FaceIndex(f as u32)) {
            if p as usize >= points {
                return Err(format!("face {f} names point {p} of {points}"));
            }
            indices.push(p);
        }
    }
    let mut attributes = Vec::new();
    for (name, id) in ids {
        let id = id
            .as_u64()
            .and_then(|i| u32::try_from(i).ok())
            .ok_or_else(|| format!("attribute {name}: its id is not a number"))?;
        let attribute = mesh
            .attribute_by_unique_id(id)
            .ok_or_else(|| format!("attribute {name}: the Draco stream has no attribute {id}"))?;
        let components = usize::from(attribute.num_components());
        attributes.push((name.clone(), components, values(attribute, points, name)?));
    }
    Ok(DracoPrimitive {
        attributes,
        indices,
    })
}

/// Reads one value of `size` bytes as a float (normalized where the flag says).
type ReadValue = fn(&[u8], bool) -> f32;

/// An attribute's values for points 0..`points`, as floats.
fn values(attribute: &PointAttribute, points: usize, name: &str) -> Result<Vec<f32>, String> {
    let components = usize::from(attribute.num_components());
    let stride = usize::try_from(attribute.byte_stride())
        .map_err(|_| format!("attribute {name}: a negative stride"))?;
    let normalized = attribute.normalized();
    let (size, read): (usize, ReadValue) = match attribute.data_type() {
        DataType::Float32 => (4, |b, _| f32::from_le_bytes([b[0], b[1], b[2], b[3]])),
        DataType::Int8 => (1, |b, n| scale(f32::from(b[0] as i8), n, 127.0)),
        DataType::Uint8 => (1, |b, n| scale(f32::from(b[0]), n, 255.0)),
        DataType::Int16 => (2, |b, n| {
            scale(f32::from(i16::from_le_bytes([b[0], b[1]])), n, 32767.0)
        }),
        DataType::Uint16 => (2, |b, n| {
            scale(f32::from(u16::from_le_bytes([b[0], b[1]])), n, 65535.0)
        }),
        DataType::Uint32 => (4, |b, _| {
            u32::from_le_bytes([b[0], b[1], b[2], b[3]]) as f32
        }),
        DataType::Int32 => (4, |b, _| {
            i32::from_le_bytes([b[0], b[1], b[2], b[3]]) as f32
        }),
        other => return Err(format!("attribute {name}: values of type {other:?}")),
    };
    let data = attribute.buffer().data();
    let mut out = Vec::with_capacity(points * components);
    for p in 0..points {
        let value = attribute.mapped_index(PointIndex(p as u32)).0 as usize;
        for c in 0..components {
            let at = value
                .checked_mul(stride)
                .and_then(|o| o.checked_add(c * size))
                .filter(|&o| o + size <= data.len())
                .ok_or_else(|| format!("attribute {name}: point {p} has no value"))?;
            out.push(read(&data[at..at + size], normalized));
        }
    }
    Ok(out)
}

/// A normalized integer's value (`max`: its type's largest), or the integer itself.
fn scale(value: f32, normalized: bool, max: f32) -> f32 {
    if normalized {
        (value / max).max(-1.0)
    } else {
        value
    }
}
