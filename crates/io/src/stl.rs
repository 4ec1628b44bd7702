//! STL, ASCII and binary, read as one object with flat shading (STL has no vertex normals).
//!
//! Read here rather than through `stl_io`, which takes any file starting with `solid ` for ASCII
//! (many binary exporters write that header) and needs a space after `solid` (some files have a
//! tab): two of the eight STL files in Debian's assimp-testmodels failed that way.
//! - Binary: 80-byte header, a little-endian u32 triangle count, 50 bytes per triangle (normal,
//!   three corners, a u16 attribute that is ignored). A file is binary when its size is exactly
//!   84 + 50 × count, or when it does not start with `solid`.
//! - ASCII: `solid name`, then `facet normal … outer loop vertex x y z … endloop endfacet`, then
//!   `endsolid`; several solids in one file are one mesh; keywords in any case; a loop of more
//!   than three vertices is a fan.
//!
//! The stored facet normals are not used: a facet's front is its counter-clockwise winding, as
//! Blender reads STL (exporters disagree on the normals, rarely on the winding). Corners with
//! bit-identical positions are welded into one vertex.

use std::collections::HashMap;
use std::path::Path;

use glam::Vec3;

use super::mesh_file::load_mesh_file;
use rt_core::error::{Error, Result};
use rt_core::scene::{Mesh, Scene};

const HEADER_BYTES: usize = 80;
const TRIANGLE_BYTES: usize = 50;

/// Loads an STL file as a scene of one object named after the file.
pub fn load_stl(path: &Path, seed: u32) -> Result<Scene> {
    load_mesh_file(path, seed, "STL", read_stl)
}

/// Reads an STL file held in memory into a mesh.
pub fn read_stl(path: &Path, bytes: &[u8]) -> Result<Mesh> {
    let declared = bytes
        .get(HEADER_BYTES..HEADER_BYTES + 4)
        .map(|b| u32::from_le_bytes([b[0], b[1], b[2], b[3]]) as usize);
    let exact_binary = declared.is_some_and(|n| {
        n.checked_mul(TRIANGLE_BYTES)
            .and_then(|b| b.checked_add(HEADER_BYTES + 4))
            == Some(bytes.len())
    });
    let starts_solid = bytes
        .trim_ascii_start()
        .get(..5)
        .is_some_and(|w| w.eq_ignore_ascii_case(b"solid"));
    let mut welder = Welder::default();
    if exact_binary || !starts_solid {
        read_binary(path, bytes, declared, &mut welder)?;
    } else if let Err(ascii_error) = read_ascii(path, bytes, &mut welder) {
        // A binary file whose header starts with "solid" and that holds more than its triangles.
        let fits = declared.is_some_and(|n| {
            n > 0
                && (HEADER_BYTES + 4).saturating_add(n.saturating_mul(TRIANGLE_BYTES))
                    <= bytes.len()
        });
        welder = Welder::default();
        if !fits || read_binary(path, bytes, declared, &mut welder).is_err() {
            return Err(ascii_error);
        }
    }
    if welder.indices.is_empty() {
        return Err(Error::File {
            path: path.into(),
            message: "no facets".into(),
        });
    }
    Ok(Mesh {
        positions: welder.positions,
        normals: None,
        uvs: None,
        colors: None,
        indices: welder.indices,
    })
}

fn read_binary(
    path: &Path,
    bytes: &[u8],
    declared: Option<usize>,
    welder: &mut Welder,
) -> Result<()> {
    let fail = |message: String| Error::File {
        path: path.into(),
        message,
    };
    let Some(count) = declared else {
        return Err(fail(format!(
            "{} bytes: too short for a binary STL (84 bytes of header and count) and not ASCII \
             STL (which starts with 'solid')",
            bytes.len()
        )));
    };
    let body = &bytes[HEADER_BYTES + 4..];
    let held = body.len() / TRIANGLE_BYTES;
    if held < count {
        return Err(fail(format!(
            "declares {count} triangles ({} bytes), but holds {held}",
            HEADER_BYTES + 4 + count.saturating_mul(TRIANGLE_BYTES)
        )));
    }
    if body.len() > count * TRIANGLE_BYTES {
        log::warn!(
            "{}: {} bytes after the {count} triangles it declares are ignored",
            path.display(),
            body.len() - count * TRIANGLE_BYTES
        );
    }
    for (index, record) in body.chunks_exact(TRIANGLE_BYTES).take(count).enumerate() {
        let float = |i: usize| {
            f32::from_le_bytes([
                record[4 * i],
                record[4 * i + 1],
                record[4 * i + 2],
                record[4 * i + 3],
            ])
        };
        let corner = |c: usize| Vec3::new(float(3 + 3 * c), float(4 + 3 * c), float(5 + 3 * c));
        let corners = [corner(0), corner(1), corner(2)];
        if !corners.iter().all(|c| c.is_finite()) {
            return Err(fail(format!(
                "triangle {index} has a corner that is not finite"
            )));
        }
        welder.polygon(&corners);
    }
    Ok(())
}

fn read_ascii(path: &Path, bytes: &[u8], welder: &mut Welder) -> Result<()> {
    let mut corners: Vec<Vec3> = Vec::new();
    let mut in_loop = false;
    for (line_index, raw) in bytes.split(|&b| b == b'\n').enumerate() {
        let fail = |message: String| Error::Parse {
            path: path.into(),
            line: line_index + 1,
            message,
        };
        let text = String::from_utf8_lossy(raw);
        let mut words = text.split_whitespace();
        let Some(keyword) = words.next() else {
            continue;
        };
        match keyword.to_ascii_lowercase().as_str() {
            "solid" | "endsolid" | "facet" | "endfacet" => {}
            "outer" => {
                corners.clear();
                in_loop = true;
            }
            "vertex" => {
                if !in_loop {
                    return Err(fail("'vertex' outside an 'outer loop'".into()));
                }
                let mut xyz = [0.0f32; 3];
                for value in &mut xyz {
                    let word = words
                        .next()
                        .ok_or_else(|| fail("'vertex' needs 3 coordinates".into()))?;
                    *value = word
                        .parse::<f32>()
                        .ok()
                        .filter(|v| v.is_finite())
                        .ok_or_else(|| fail(format!("'{word}' is not a finite number")))?;
                }
                corners.push(Vec3::from(xyz));
            }
            "endloop" => {
                if corners.len() < 3 {
                    return Err(fail(format!(
                        "a facet needs 3 vertices, found {}",
                        corners.len()
                    )));
                }
                welder.polygon(&corners);
                in_loop = false;
            }
            other => {
                return Err(fail(format!(
                    "'{other}' is not an STL keyword (solid, facet, outer loop, vertex, endloop, \
                     endfacet, endsolid)"
                )));
            }
        }
    }
    if in_loop {
        return Err(Error::File {
            path: path.into(),
            message: "the file ends inside a facet".into(),
        });
    }
    Ok(())
}

/// Indexed vertices from STL's unindexed corners: bit-identical positions become one vertex.
#[derive(Default)]
struct Welder {
    positions: Vec<Vec3>,
    indices: Vec<[u32; 3]>,
    index_of: HashMap<[u32; 3], u32>,
}

impl Welder {
    /// A polygon as a fan of triangles.
    fn polygon(&mut self, corners: &[Vec3]) {
        let ids: Vec<u32> = corners.iter().map(|&c| self.vertex(c)).collect();
        for pair in ids[1..].windows(2) {
            self.indices.push([ids[0], pair[0], pair[1]]);
        }
    }

    fn vertex(&mut self, position: Vec3) -> u32 {
        // -0.0 and 0.0 are one position.
        let key = (position + Vec3::ZERO).to_array().map(f32::to_bits);
        *self.index_of.entry(key).or_insert_with(|| {
            self.positions.push(position);
            (self.positions.len() - 1) as u32
        })
    }
}
