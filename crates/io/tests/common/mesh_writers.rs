//! Writers for the tests of the PLY and STL readers: a mesh written the ways exporters write it.
//! (Each test binary uses some of them.)

#![allow(dead_code)]

use rt_core::scene::Mesh;

/// How a PLY file encodes its body.
#[derive(Clone, Copy, Debug)]
pub enum PlyEncoding {
    Ascii,
    LittleEndian,
    BigEndian,
}

/// `mesh` as PLY: positions, then normals and `s t` coordinates where it has them, `colors` as
/// 8-bit `red green blue` where given, and `faces` (polygons of any size) as `vertex_indices`.
pub fn ply(
    mesh: &Mesh,
    colors: Option<&[[u8; 3]]>,
    faces: &[Vec<u32>],
    encoding: PlyEncoding,
) -> Vec<u8> {
    let format = match encoding {
        PlyEncoding::Ascii => "ascii",
        PlyEncoding::LittleEndian => "binary_little_endian",
        PlyEncoding::BigEndian => "binary_big_endian",
    };
    let mut out = format!(
        "ply\nformat {format} 1.0\ncomment written by rt's tests\nelement vertex {}\n\
         property float x\nproperty float y\nproperty float z\n",
        mesh.positions.len()
    );
    if mesh.normals.is_some() {
        out += "property float nx\nproperty float ny\nproperty float nz\n";
    }
    if mesh.uvs.is_some() {
        out += "property float s\nproperty float t\n";
    }
    if colors.is_some() {
        out += "property uchar red\nproperty uchar green\nproperty uchar blue\n";
    }
    out += &format!(
        "element face {}\nproperty list uchar int vertex_indices\nend_header\n",
        faces.len()
    );
    let mut bytes = out.into_bytes();
    let float = |bytes: &mut Vec<u8>, v: f32| match encoding {
        PlyEncoding::Ascii => bytes.extend(format!("{v} ").bytes()),
        PlyEncoding::LittleEndian => bytes.extend(v.to_le_bytes()),
        PlyEncoding::BigEndian => bytes.extend(v.to_be_bytes()),
    };
    let int = |bytes: &mut Vec<u8>, v: i32| match encoding {
        PlyEncoding::Ascii => bytes.extend(format!("{v} ").bytes()),
        PlyEncoding::LittleEndian => bytes.extend(v.to_le_bytes()),
        PlyEncoding::BigEndian => bytes.extend(v.to_be_bytes()),
    };
    let byte = |bytes: &mut Vec<u8>, v: u8| match encoding {
        PlyEncoding::Ascii => bytes.extend(format!("{v} ").bytes()),
        _ => bytes.push(v),
    };
    let newline = |bytes: &mut Vec<u8>| {
        if let PlyEncoding::Ascii = encoding {
            bytes.pop();
            bytes.push(b'\n');
        }
    };
    for i in 0..mesh.positions.len() {
        mesh.positions[i]
            .to_array()
            .into_iter()
            .for_each(|v| float(&mut bytes, v));
        if let Some(normals) = &mesh.normals {
            normals[i]
                .to_array()
                .into_iter()
                .for_each(|v| float(&mut bytes, v));
        }
        if let Some(uvs) = &mesh.uvs {
            uvs[i]
                .to_array()
                .into_iter()
                .for_each(|v| float(&mut bytes, v));
        }
        if let Some(colors) = colors {
            colors[i].into_iter().for_each(|v| byte(&mut bytes, v));
        }
        newline(&mut bytes);
    }
    for face in faces {
        byte(&mut bytes, face.len() as u8);
        face.iter().for_each(|&i| int(&mut bytes, i as i32));
        newline(&mut bytes);
    }
    bytes
}

/// The triangles of `mesh` as PLY faces.
pub fn triangle_faces(mesh: &Mesh) -> Vec<Vec<u32>> {
    mesh.indices.iter().map(|t| t.to_vec()).collect()
}

/// `mesh`'s triangles as ASCII STL, in two solids when `two_solids`, with `solid` followed by a
/// tab (as some exporters write it).
pub fn stl_ascii(mesh: &Mesh, two_solids: bool) -> Vec<u8> {
    let mut out = String::from("solid\trt test\n");
    let half = mesh.indices.len() / 2;
    for (i, t) in mesh.indices.iter().enumerate() {
        if two_solids && i == half {
            out += "endsolid rt test\nsolid second\n";
        }
        out += "  facet normal 0 0 0\n    outer loop\n";
        for &v in t {
            let p = mesh.positions[v as usize];
            out += &format!("      vertex {} {} {}\n", p.x, p.y, p.z);
        }
        out += "    endloop\n  endfacet\n";
    }
    out += "endsolid\n";
    out.into_bytes()
}

/// `mesh`'s triangles as binary STL, its 80-byte header starting with `header` (exporters that
/// start it with "solid" are why the size decides the encoding).
pub fn stl_binary(mesh: &Mesh, header: &str) -> Vec<u8> {
    let mut out = vec![b' '; 80];
    out[..header.len()].copy_from_slice(header.as_bytes());
    out.extend((mesh.indices.len() as u32).to_le_bytes());
    for t in &mesh.indices {
        out.extend([0.0f32; 3].iter().flat_map(|v| v.to_le_bytes()));
        for &v in t {
            out.extend(
                mesh.positions[v as usize]
                    .to_array()
                    .iter()
                    .flat_map(|v| v.to_le_bytes()),
            );
        }
        out.extend(0u16.to_le_bytes());
    }
    out
}

/// `mesh` as OBJ text with its normals and texture coordinates where it has them.
pub fn obj(mesh: &Mesh) -> String {
    let mut out = String::new();
    for p in &mesh.positions {
        out += &format!("v {} {} {}\n", p.x, p.y, p.z);
    }
    for n in mesh.normals.iter().flatten() {
        out += &format!("vn {} {} {}\n", n.x, n.y, n.z);
    }
    for uv in mesh.uvs.iter().flatten() {
        out += &format!("vt {} {}\n", uv.x, uv.y);
    }
    for t in &mesh.indices {
        let corner = |i: u32| {
            let i = i + 1;
            match (mesh.uvs.is_some(), mesh.normals.is_some()) {
                (true, true) => format!("{i}/{i}/{i}"),
                (false, true) => format!("{i}//{i}"),
                (true, false) => format!("{i}/{i}"),
                (false, false) => format!("{i}"),
            }
        };
        out += &format!("f {} {} {}\n", corner(t[0]), corner(t[1]), corner(t[2]));
    }
    out
}
