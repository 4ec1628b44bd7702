//! Stanford PLY (ASCII, binary little- and big-endian) through `ply-rs-bw`, read as one object.
//!
//! What is read, by property name (as Blender, MeshLab and assimp write them):
//! - element `vertex`: positions `x y z` (required); normals `nx ny nz`; texture coordinates
//!   `s t`, `u v`, `texture_u texture_v` or `texture_s texture_t`; colours `red green blue` or
//!   `diffuse_red diffuse_green diffuse_blue` (8- or 16-bit integers, or floats in [0, 1]), read as
//!   sRGB-encoded, as Blender's importer does by default, and kept linear;
//! - element `face`: a list `vertex_indices` (or `vertex_index`) of any length, triangulated as a
//!   fan; faces of fewer than 3 vertices are skipped with a warning;
//! - every other element (edges, materials, a scanner's range grid) is read past.
//!
//! A file without faces (a point cloud) is an error: rt renders surfaces. The mesh gets the
//! material of an OBJ object without one (`mesh_file::mesh_object_scene`).

use std::io::{BufRead, Cursor, Read};
use std::path::Path;

use glam::{Vec2, Vec3};
use ply_rs_bw::parser::Parser;
use ply_rs_bw::ply::{ElementDef, Encoding, Property, PropertyAccess};

use super::mesh_file::{load_mesh_file, srgb_to_linear};
use rt_core::error::{Error, Result};
use rt_core::scene::{Mesh, Scene};

/// Loads a PLY file as a scene of one object named after the file.
pub fn load_ply(path: &Path, seed: u32) -> Result<Scene> {
    load_mesh_file(path, seed, "PLY", read_ply)
}

/// Reads a PLY file held in memory into a mesh.
pub fn read_ply(path: &Path, bytes: &[u8]) -> Result<Mesh> {
    let fail = |message: String| Error::File {
        path: path.into(),
        message,
    };
    let (header_text, body) = split_header(bytes).map_err(fail)?;
    let mut reader = Cursor::new(header_text.as_bytes()).chain(Cursor::new(body));
    let header = Parser::<PlyVertex>::new()
        .read_header(&mut reader)
        .map_err(|e| {
            fail(one_line(&format!(
                "not a PLY file, or a broken header: {e}"
            )))
        })?;
    // The first body line, for ASCII errors: the header's lines plus one.
    let mut line = 1 + header_text.lines().count();

    let Some(vertex_def) = header.elements.get("vertex") else {
        return Err(fail("no 'vertex' element".into()));
    };
    for axis in ["x", "y", "z"] {
        if !vertex_def.properties.contains_key(axis) {
            return Err(fail(format!(
                "the 'vertex' element has no '{axis}' property"
            )));
        }
    }
    let face_list = header.elements.get("face").and_then(|face| {
        ["vertex_indices", "vertex_index"]
            .into_iter()
            .find(|name| face.properties.contains_key(*name))
    });
    if face_list.is_none() {
        return Err(fail(
            "no faces (an element 'face' with a list 'vertex_indices'): a point cloud; rt renders \
             surfaces"
                .into(),
        ));
    }
    let has = |names: &[&str]| names.iter().all(|n| vertex_def.properties.contains_key(*n));
    let has_normals = has(&["nx", "ny", "nz"]);
    let has_uvs = [
        ["s", "t"],
        ["u", "v"],
        ["texture_u", "texture_v"],
        ["texture_s", "texture_t"],
    ]
    .iter()
    .any(|pair| has(pair));
    let has_colors =
        has(&["red", "green", "blue"]) || has(&["diffuse_red", "diffuse_green", "diffuse_blue"]);

    let mut body = Body {
        path,
        reader: &mut reader,
        encoding: header.encoding,
        line: &mut line,
    };
    let (mut vertices, mut faces) = (Vec::new(), Vec::new());
    for (name, def) in &header.elements {
        match name.as_str() {
            "vertex" => vertices = body.read_elements::<PlyVertex>(def)?,
            "face" => faces = body.read_elements::<PlyFace>(def)?,
            _ => {
                body.read_elements::<Ignored>(def)?;
            }
        }
    }

    let mut indices = Vec::with_capacity(faces.len());
    let mut short_faces = 0usize;
    for (face_index, face) in faces.iter().enumerate() {
        if let Some(bad) = face.invalid_index {
            return Err(fail(format!(
                "face {face_index} has a negative vertex index {bad}"
            )));
        }
        if let Some(&out) = face.indices.iter().find(|&&i| i as usize >= vertices.len()) {
            return Err(fail(format!(
                "face {face_index} names vertex {out}, but the file has {} vertices",
                vertices.len()
            )));
        }
        match face.indices.as_slice() {
            [first, rest @ ..] if rest.len() >= 2 => {
                indices.extend(rest.windows(2).map(|pair| [*first, pair[0], pair[1]]));
            }
            _ => short_faces += 1,
        }
    }
    if short_faces > 0 {
        log::warn!(
            "{}: skipped {short_faces} faces of fewer than 3 vertices",
            path.display()
        );
    }
    if indices.is_empty() {
        return Err(fail("no faces of 3 or more vertices".into()));
    }
    if let Some(i) = vertices.iter().position(|v| !v.position.is_finite()) {
        return Err(fail(format!(
            "vertex {i} has a position that is not finite"
        )));
    }
    Ok(Mesh {
        positions: vertices.iter().map(|v| v.position).collect(),
        normals: has_normals.then(|| vertices.iter().map(|v| v.normal).collect()),
        uvs: has_uvs.then(|| vertices.iter().map(|v| v.uv).collect()),
        colors: has_colors.then(|| {
            vertices
                .iter()
                .map(|v| v.color.map(srgb_to_linear).into())
                .collect()
        }),
        indices,
    })
}

/// The file after its header, read element by element, so that errors can name the line (ASCII)
/// or the element (binary).
struct Body<'a, R> {
    path: &'a Path,
    reader: &'a mut R,
    encoding: Encoding,
    line: &'a mut usize,
}

impl<R: BufRead> Body<'_, R> {
    fn read_elements<E: PropertyAccess>(&mut self, def: &ElementDef) -> Result<Vec<E>> {
        let parser = Parser::<E>::new();
        let name = &def.name;
        // Grown as elements arrive, never sized by the header's count: a damaged count must not
        // allocate what the file does not hold.
        let mut elements = Vec::new();
        let mut text = String::new();
        while elements.len() < def.count {
            let read = match self.encoding {
                Encoding::Ascii => {
                    text.clear();
                    let n = self
                        .reader
                        .read_line(&mut text)
                        .map_err(|e| self.parse_error(e.to_string()))?;
                    if n == 0 {
                        return Err(self.parse_error(format!(
                            "the file ends after {} of its {} '{name}' elements",
                            elements.len(),
                            def.count
                        )));
                    }
                    *self.line += 1;
                    if text.trim().is_empty() {
                        continue;
                    }
                    parser.read_ascii_element(&text, def).map_err(|e| {
                        *self.line -= 1;
                        self.parse_error(format!(
                            "'{name}' element {}: {}",
                            elements.len(),
                            one_line(&e.to_string())
                        ))
                    })?
                }
                Encoding::BinaryLittleEndian => parser
                    .read_little_endian_element(self.reader, def)
                    .map_err(|e| self.binary_error(def, elements.len(), e))?,
                Encoding::BinaryBigEndian => parser
                    .read_big_endian_element(self.reader, def)
                    .map_err(|e| self.binary_error(def, elements.len(), e))?,
            };
            elements.push(read);
        }
        Ok(elements)
    }

    fn parse_error(&self, message: String) -> Error {
        Error::Parse {
            path: self.path.into(),
            line: *self.line,
            message,
        }
    }

    fn binary_error(&mut self, def: &ElementDef, index: usize, e: std::io::Error) -> Error {
        let at_end = self.reader.fill_buf().is_ok_and(<[u8]>::is_empty);
        let what = if at_end || e.kind() == std::io::ErrorKind::UnexpectedEof {
            "the file ends early".to_string()
        } else {
            one_line(&e.to_string())
        };
        Error::File {
            path: self.path.into(),
            message: format!("'{}' element {index} of {}: {what}", def.name, def.count),
        }
    }
}

/// The header (up to and including its `end_header` line) and the body. Header lines that are no
/// PLY keyword (Blender 2.4 wrote a bare "Created by Blender" line) become comments, as assimp
/// reads them, keeping the line count. Numbers beyond 64 bits are an error here, before ply-rs
/// (which panics on them).
fn split_header(bytes: &[u8]) -> Result<(String, &[u8]), String> {
    const KEYWORDS: [&str; 7] = [
        "ply",
        "format",
        "comment",
        "obj_info",
        "element",
        "property",
        "end_header",
    ];
    let mut header = String::new();
    let mut offset = 0;
    while offset < bytes.len() {
        let end = bytes[offset..]
            .iter()
            .position(|&b| b == b'\n')
            .map_or(bytes.len(), |i| offset + i + 1);
        let line = String::from_utf8_lossy(&bytes[offset..end]);
        offset = end;
        let keyword = line.split_whitespace().next().unwrap_or("");
        let line_number = header.lines().count() + 1;
        if matches!(keyword, "format" | "element") {
            let too_big = line
                .split(|c: char| c.is_whitespace() || c == '.')
                .any(|w| {
                    !w.is_empty()
                        && w.bytes().all(|b| b.is_ascii_digit())
                        && w.parse::<u64>().is_err()
                });
            if too_big {
                return Err(format!(
                    "header line {line_number}: a number beyond 64 bits"
                ));
            }
        }
        if header.is_empty() || KEYWORDS.contains(&keyword) {
            header.push_str(&line);
        } else {
            header.push_str("comment ");
            header.push_str(&line);
        }
        if keyword == "end_header" {
            return Ok((header, &bytes[offset..]));
        }
        if header.len() > MAX_HEADER_BYTES {
            break;
        }
    }
    Err("not a PLY file: no 'end_header' line (a PLY file starts with 'ply' and a header)".into())
}

/// A header longer than this is no PLY header (a binary file of another kind).
const MAX_HEADER_BYTES: usize = 1 << 20;

/// ply-rs's multi-line messages on one line.
fn one_line(message: &str) -> String {
    message
        .split(['\n', '\t'])
        .map(str::trim)
        .filter(|s| !s.is_empty())
        .collect::<Vec<_>>()
        .join("; ")
}

#[derive(Default)]
struct PlyVertex {
    position: Vec3,
    normal: Vec3,
    uv: Vec2,
    color: [f32; 3],
}

impl PropertyAccess for PlyVertex {
    fn new() -> Self {
        PlyVertex::default()
    }

    fn set_property(&mut self, name: String, property: Property) {
        let value = || scalar(&property);
        match name.as_str() {
            "x" => self.position.x = value(),
            "y" => self.position.y = value(),
            "z" => self.position.z = value(),
            "nx" => self.normal.x = value(),
            "ny" => self.normal.y = value(),
            "nz" => self.normal.z = value(),
            "s" | "u" | "texture_u" | "texture_s" => self.uv.x = value(),
            "t" | "v" | "texture_v" | "texture_t" => self.uv.y = value(),
            "red" | "diffuse_red" => self.color[0] = colour_channel(&property),
            "green" | "diffuse_green" => self.color[1] = colour_channel(&property),
            "blue" | "diffuse_blue" => self.color[2] = colour_channel(&property),
            _ => {}
        }
    }
}

#[derive(Default)]
struct PlyFace {
    indices: Vec<u32>,
    invalid_index: Option<i64>,
}

impl PropertyAccess for PlyFace {
    fn new() -> Self {
        PlyFace::default()
    }

    fn set_property(&mut self, name: String, property: Property) {
        if name != "vertex_indices" && name != "vertex_index" {
            return;
        }
        let signed: Vec<i64> = match property {
            Property::ListChar(v) => v.into_iter().map(i64::from).collect(),
            Property::ListUChar(v) => v.into_iter().map(i64::from).collect(),
            Property::ListShort(v) => v.into_iter().map(i64::from).collect(),
            Property::ListUShort(v) => v.into_iter().map(i64::from).collect(),
            Property::ListInt(v) => v.into_iter().map(i64::from).collect(),
            Property::ListUInt(v) => v.into_iter().map(i64::from).collect(),
            _ => Vec::new(),
        };
        self.invalid_index = signed
            .iter()
            .copied()
            .find(|&i| i < 0 || i > i64::from(u32::MAX));
        self.indices = signed.into_iter().map(|i| i as u32).collect();
    }
}

/// An element rt does not use, read past.
struct Ignored;

impl PropertyAccess for Ignored {
    fn new() -> Self {
        Ignored
    }
}

fn scalar(property: &Property) -> f32 {
    match *property {
        Property::Char(v) => v.into(),
        Property::UChar(v) => v.into(),
        Property::Short(v) => v.into(),
        Property::UShort(v) => v.into(),
        Property::Int(v) => v as f32,
        Property::UInt(v) => v as f32,
        Property::Float(v) => v,
        Property::Double(v) => v as f32,
        _ => f32::NAN,
    }
}

/// A colour channel in [0, 1]: integers are scaled by their type's maximum, floats kept.
fn colour_channel(property: &Property) -> f32 {
    let value = match *property {
        Property::UChar(v) => f32::from(v) / 255.0,
        Property::UShort(v) => f32::from(v) / 65535.0,
        _ => scalar(property),
    };
    if value.is_finite() {
        value.clamp(0.0, 1.0)
    } else {
        0.0
    }
}
