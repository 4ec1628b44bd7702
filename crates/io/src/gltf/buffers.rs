//! The glTF file's bytes: buffers from the GLB chunk, data URIs or files beside it, and the checks
//! that every accessor reads what it is used for and stays inside its view and buffer.

use std::path::{Path, PathBuf};

use rt_core::error::Result;

/// Reads what a URI names: a base64 data URI or a file relative to `base` (percent-decoded).
pub(super) fn read_uri(
    uri: &str,
    base: &Path,
    read_file: &dyn Fn(&Path) -> Result<Vec<u8>>,
) -> std::result::Result<Vec<u8>, String> {
    if let Some(rest) = uri.strip_prefix("data:") {
        let (header, data) = rest
            .split_once(',')
            .ok_or_else(|| "a data URI without a comma".to_string())?;
        if !header.ends_with(";base64") {
            return Err("a data URI that is not base64".into());
        }
        use base64::Engine as _;
        return base64::engine::general_purpose::STANDARD
            .decode(data)
            .map_err(|e| format!("a data URI that is not valid base64: {e}"));
    }
    if uri.contains("://") {
        return Err(format!("'{uri}' is not a local file"));
    }
    let relative = percent_decode(uri);
    let file: PathBuf = base.join(relative);
    read_file(&file).map_err(|e| e.to_string())
}

fn percent_decode(s: &str) -> String {
    let bytes = s.as_bytes();
    let mut out = Vec::with_capacity(bytes.len());
    let mut i = 0;
    while i < bytes.len() {
        if bytes[i] == b'%'
            && i + 2 < bytes.len()
            && let Some(v) = std::str::from_utf8(&bytes[i + 1..i + 3])
                .ok()
                .and_then(|h| u8::from_str_radix(h, 16).ok())
        {
            out.push(v);
            i += 3;
            continue;
        }
        out.push(bytes[i]);
        i += 1;
    }
    String::from_utf8_lossy(&out).into_owned()
}

pub(super) fn load_buffers(
    doc: &gltf::Document,
    blob: Option<&[u8]>,
    base: &Path,
    read_file: &dyn Fn(&Path) -> Result<Vec<u8>>,
) -> std::result::Result<Vec<Vec<u8>>, String> {
    let compressed = compressed_views(doc)?;
    let mut out = Vec::with_capacity(doc.buffers().len());
    for buffer in doc.buffers() {
        let index = buffer.index();
        let has_uri = matches!(buffer.source(), gltf::buffer::Source::Uri(_));
        // `EXT_meshopt_compression`'s placeholder: no data of its own (not the GLB chunk, which
        // only buffer 0 may name), filled by decompressing the views that refer to it.
        let placeholder = !has_uri
            && (index > 0 || blob.is_none())
            && doc.views().any(|v| v.buffer().index() == index)
            && doc
                .views()
                .filter(|v| v.buffer().index() == index)
                .all(|v| compressed.iter().any(|c| c.view == v.index()));
        if placeholder {
            let end = doc
                .views()
                .filter(|v| v.buffer().index() == index)
                .map(|v| v.offset() + v.length())
                .max()
                .unwrap_or(0);
            out.push(vec![0u8; end]);
            continue;
        }
        let data = match buffer.source() {
            gltf::buffer::Source::Bin => blob
                .ok_or_else(|| format!("buffer {index} refers to a GLB chunk the file lacks"))?
                .to_vec(),
            gltf::buffer::Source::Uri(uri) => {
                read_uri(uri, base, read_file).map_err(|e| format!("buffer {index}: {e}"))?
            }
        };
        if data.len() < buffer.length() {
            return Err(format!(
                "buffer {index} has {} bytes but declares {}",
                data.len(),
                buffer.length()
            ));
        }
        out.push(data);
    }
    for view in &compressed {
        view.decompress_into(&mut out)?;
    }
    Ok(out)
}

/// A buffer view stored with `EXT_meshopt_compression`.
struct CompressedView {
    view: usize,
    /// Where its decompressed bytes go: the view's own buffer and range.
    target: (usize, usize, usize),
    /// Where its compressed bytes are: buffer, offset, length.
    source: (usize, usize, usize),
    stride: usize,
    count: usize,
    mode: String,
    filter: String,
}

fn compressed_views(doc: &gltf::Document) -> std::result::Result<Vec<CompressedView>, String> {
    let mut out = Vec::new();
    for view in doc.views() {
        let Some(ext) = view.extension_value("EXT_meshopt_compression") else {
            continue;
        };
        let at = format!("buffer view {} (EXT_meshopt_compression)", view.index());
        let number = |key: &str, default: Option<u64>| {
            ext.get(key)
                .and_then(serde_json::Value::as_u64)
                .or(default)
                .map(|n| n as usize)
                .ok_or_else(|| format!("{at}: '{key}' is missing or not a count"))
        };
        let text = |key: &str, default: &str| {
            ext.get(key)
                .and_then(serde_json::Value::as_str)
                .unwrap_or(default)
                .to_string()
        };
        let (stride, count) = (number("byteStride", None)?, number("count", None)?);
        let source = (
            number("buffer", None)?,
            number("byteOffset", Some(0))?,
            number("byteLength", None)?,
        );
        if source.0 >= doc.buffers().len() {
            return Err(format!("{at}: there is no buffer {}", source.0));
        }
        let decoded = stride
            .checked_mul(count)
            .ok_or(format!("{at}: too large"))?;
        if decoded > view.length() {
            return Err(format!(
                "{at}: {count} elements of {stride} bytes do not fit its {} bytes",
                view.length()
            ));
        }
        // The codecs cannot expand data more than 64-fold (2 header bits for 16 bytes); a larger
        // claim is damage, refused before anything is allocated for it.
        if decoded > 64 * source.2 + 4096 {
            return Err(format!(
                "{at}: {decoded} bytes cannot come from {} compressed bytes",
                source.2
            ));
        }
        out.push(CompressedView {
            view: view.index(),
            target: (view.buffer().index(), view.offset(), decoded),
            source,
            stride,
            count,
            mode: text("mode", ""),
            filter: text("filter", "NONE"),
        });
    }
    Ok(out)
}

impl CompressedView {
    fn decompress_into(&self, buffers: &mut [Vec<u8>]) -> std::result::Result<(), String> {
        use super::meshopt;
        let at = format!("buffer view {} (EXT_meshopt_compression)", self.view);
        let (buffer, offset, length) = self.source;
        let data = buffers[buffer]
            .get(offset..offset.saturating_add(length))
            .ok_or_else(|| format!("{at}: its data lies past buffer {buffer}"))?;
        let indices = |values: Vec<u32>| match self.stride {
            2 => Ok(values
                .iter()
                .flat_map(|&i| (i as u16).to_le_bytes())
                .collect()),
            4 => Ok(values.iter().flat_map(|&i| i.to_le_bytes()).collect()),
            s => Err(format!("indices of {s} bytes (2 or 4 expected)")),
        };
        let mut bytes: Vec<u8> = match self.mode.as_str() {
            "ATTRIBUTES" => meshopt::decode_attributes(data, self.count, self.stride),
            "TRIANGLES" => meshopt::decode_triangles(data, self.count).and_then(indices),
            "INDICES" => meshopt::decode_indices(data, self.count).and_then(indices),
            other => Err(format!("unknown mode '{other}'")),
        }
        .map_err(|e| format!("{at}: {e}"))?;
        match self.filter.as_str() {
            "NONE" => Ok(()),
            "OCTAHEDRAL" => meshopt::filter_octahedral(&mut bytes, self.stride),
            "QUATERNION" => meshopt::filter_quaternion(&mut bytes, self.stride),
            "EXPONENTIAL" => meshopt::filter_exponential(&mut bytes, self.stride),
            other => Err(format!("unknown filter '{other}'")),
        }
        .map_err(|e| format!("{at}: {e}"))?;
        let (target, start, decoded) = self.target;
        let slot = buffers[target]
            .get_mut(start..start + decoded)
            .ok_or_else(|| format!("{at}: the view lies past buffer {target}"))?;
        slot.copy_from_slice(&bytes);
        Ok(())
    }
}

/// What an attribute's accessor may hold (with `KHR_mesh_quantization`'s integer types).
#[derive(Clone, Copy)]
pub(super) enum Expect {
    /// Floats, or integers of 8 or 16 bits, normalized or not.
    Position,
    /// Floats, or normalized signed integers of 8 or 16 bits.
    Normal,
    /// Floats, or integers of 8 or 16 bits, normalized or not.
    Uv,
    Indices,
    Color,
}

/// Checks that `accessor` holds what `expect` says and that every byte it reads lies inside its
/// view and buffer (the gltf crate's readers assume both).
pub(super) fn check_accessor(
    accessor: &gltf::Accessor,
    buffers: &[Vec<u8>],
    expect: Expect,
) -> std::result::Result<(), String> {
    use gltf::accessor::{DataType as T, Dimensions as D};
    let what = || format!("accessor {}", accessor.index());
    let (ty, dims) = (accessor.data_type(), accessor.dimensions());
    let small_integer = matches!(ty, T::I8 | T::U8 | T::I16 | T::U16);
    let ok = match expect {
        Expect::Position => (ty == T::F32 || small_integer) && dims == D::Vec3,
        Expect::Normal => {
            (ty == T::F32 || (matches!(ty, T::I8 | T::I16) && accessor.normalized()))
                && dims == D::Vec3
        }
        Expect::Uv => (ty == T::F32 || small_integer) && dims == D::Vec2,
        Expect::Indices => matches!(ty, T::U8 | T::U16 | T::U32) && dims == D::Scalar,
        Expect::Color => matches!(ty, T::F32 | T::U8 | T::U16) && matches!(dims, D::Vec3 | D::Vec4),
    };
    if !ok {
        return Err(format!(
            "{}: {dims:?} of {ty:?} is not what it is used for",
            what()
        ));
    }
    if accessor.count() == 0 {
        return Err(format!("{} is empty", what()));
    }
    if accessor.sparse().is_some() {
        return Err(format!("{}: sparse accessors are not supported", what()));
    }
    let Some(view) = accessor.view() else {
        return Err(format!("{} has no buffer view", what()));
    };
    let buffer = &buffers[view.buffer().index()];
    let view_end = (view.offset() as u64) + (view.length() as u64);
    if view_end > buffer.len() as u64 {
        return Err(format!(
            "buffer view {} ends at byte {view_end}, past its buffer's {} bytes",
            view.index(),
            buffer.len()
        ));
    }
    let count = accessor.count() as u64;
    let size = accessor.size() as u64;
    let stride = view.stride().map_or(size, |s| s as u64);
    if stride < size {
        return Err(format!(
            "buffer view {}: stride {stride} is shorter than {}'s {size}-byte elements",
            view.index(),
            what()
        ));
    }
    let needed = accessor.offset() as u64 + stride * (count - 1) + size;
    if needed > view.length() as u64 {
        return Err(format!(
            "{} needs {needed} bytes of buffer view {}, which has {}",
            what(),
            view.index(),
            view.length()
        ));
    }
    Ok(())
}

/// A checked accessor's elements as floats, `N` per element, dequantized as glTF says: a
/// normalized integer c of b bits is c / (2^b − 1) unsigned, max(c / (2^(b−1) − 1), −1) signed;
/// a plain integer is its value (`KHR_mesh_quantization`, where the node's transform scales it).
pub(super) fn read_floats<const N: usize>(
    accessor: &gltf::Accessor,
    buffers: &[Vec<u8>],
) -> Vec<[f32; N]> {
    use gltf::accessor::DataType as T;
    let Some(view) = accessor.view() else {
        return Vec::new();
    };
    let buffer = &buffers[view.buffer().index()];
    let size = accessor.size();
    let stride = view.stride().unwrap_or(size);
    let start = view.offset() + accessor.offset();
    let normalized = accessor.normalized();
    let ty = accessor.data_type();
    let component = ty.size();
    let value = |bytes: &[u8]| -> f32 {
        let raw = |b: &[u8]| match ty {
            T::I8 => f32::from(b[0] as i8),
            T::U8 => f32::from(b[0]),
            T::I16 => f32::from(i16::from_le_bytes([b[0], b[1]])),
            T::U16 => f32::from(u16::from_le_bytes([b[0], b[1]])),
            T::U32 => u32::from_le_bytes([b[0], b[1], b[2], b[3]]) as f32,
            T::F32 => f32::from_le_bytes([b[0], b[1], b[2], b[3]]),
        };
        let c = raw(bytes);
        match (normalized, ty) {
            (true, T::I8) => (c / 127.0).max(-1.0),
            (true, T::U8) => c / 255.0,
            (true, T::I16) => (c / 32767.0).max(-1.0),
            (true, T::U16) => c / 65535.0,
            _ => c,
        }
    };
    (0..accessor.count())
        .map(|i| {
            let at = start + i * stride;
            std::array::from_fn(|k| value(&buffer[at + k * component..]))
        })
        .collect()
}
