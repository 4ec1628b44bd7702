//! Wavefront OBJ + MTL through `tobj`, mapped onto rt's scene model.
//!
//! MTL mapping (first rule that applies):
//! 1. `Ke` with a non-zero component → `Emissive { color: Ke, intensity: 1 }`.
//! 2. `illum` 4, 6 or 7, or `d` < 1, or `Tf` → `Dielectric { ior: Ni (1.5 if absent), tint: Tf (white) }`,
//!    or with `Pr` > 0 rough glass: `Pbr { base_color: Tf (white), roughness: Pr, ior: Ni (1.5),
//!    transmission: 1 }`.
//! 3. `Pr`, `Pm`, `Pc`, `Ps` or `aniso` (the PBR extension of MTL) → `Pbr { base_color: Kd (or Ks if
//!    non-zero, for a metal), texture: map_Kd, metallic: Pm (1 with `illum 3`, else 0), roughness:
//!    Pr, else √α with α = √(2/(Ns+2)) (Walter's Blinn–Phong match), else 0.5, ior: Ni (1.5),
//!    clearcoat: Pc, clearcoat_roughness: Pcr, sheen_color: Ps (one value: grey), anisotropy:
//!    aniso, anisotropy_rotation: 2π anisor (a fraction of a turn, as Blender reads it) }`, the
//!    layer values clamped to [0, 1].
//! 4. `illum 3` → `Metal { albedo: Ks if non-zero else Kd, fuzz: √(2/(Ns+2)) (0 without Ns) }`.
//! 5. otherwise → `Lambertian { albedo: Kd (0.8 grey if absent), texture: map_Kd }`.
//!
//! Objects with no material get a distinct colour derived from the seed. Faces are triangulated as
//! fans; `o`/`g` start new objects and `usemtl` splits an object by material.

use std::cell::RefCell;
use std::collections::HashMap;
use std::path::{Path, PathBuf};

use glam::{Vec2, Vec3};

use super::line_reader::LineCountingReader;
use super::texture::load_texture;
use rt_core::error::{Error, Result};
use rt_core::material::{Material, Rgb};
use rt_core::scene::{Mesh, Object, Scene, Texture};

/// Loads an OBJ file; `mtllib` and texture paths are resolved relative to the file that names them.
pub fn load_obj(path: &Path, seed: u32) -> Result<Scene> {
    if path.is_dir() {
        return Err(Error::File {
            path: path.into(),
            message: "is a directory, not an OBJ file".into(),
        });
    }
    let bytes = std::fs::read(path).map_err(|source| Error::Io {
        path: path.into(),
        source,
    })?;
    let dir = path.parent().map(Path::to_path_buf).unwrap_or_default();
    let read_file = |p: &Path| {
        std::fs::read(p).map_err(|source| Error::Io {
            path: p.into(),
            source,
        })
    };
    load_obj_bytes(
        path,
        &bytes,
        &dir,
        &read_file,
        &|p: &Path| load_texture(p),
        seed,
    )
}

/// Loads an OBJ held in memory; `read_file` supplies MTL files and `load_texture` textures, both by
/// path joined onto `dir`.
pub fn load_obj_bytes(
    obj_path: &Path,
    bytes: &[u8],
    dir: &Path,
    read_file: &dyn Fn(&Path) -> Result<Vec<u8>>,
    load_texture: &dyn Fn(&Path) -> Result<Texture>,
    seed: u32,
) -> Result<Scene> {
    let text = utf8_text(obj_path, bytes)?;
    validate_obj_text(obj_path, text)?;

    let mtl_error: RefCell<Option<Error>> = RefCell::new(None);
    let mtl_paths: RefCell<Vec<PathBuf>> = RefCell::new(Vec::new());
    let mut reader = LineCountingReader::new(text.as_bytes());
    let options = tobj::LoadOptions {
        triangulate: true,
        single_index: true,
        ..Default::default()
    };
    let loaded = guard_parser(obj_path, || {
        tobj::load_obj_buf(&mut reader, &options, |mtl_name| {
            let mtl_path = dir.join(mtl_name);
            let parsed =
                read_file(&mtl_path).and_then(|mtl_bytes| parse_mtl(&mtl_path, &mtl_bytes));
            match parsed {
                Ok(result) => {
                    mtl_paths.borrow_mut().push(mtl_path);
                    Ok(result)
                }
                Err(e) => {
                    mtl_error.borrow_mut().get_or_insert(e);
                    Err(tobj::LoadError::OpenFileFailed)
                }
            }
        })
    })?;
    if let Some(e) = mtl_error.into_inner() {
        return Err(e);
    }
    let (models, materials) = loaded.map_err(|e| Error::Parse {
        path: obj_path.into(),
        line: reader.current_line(),
        message: e.to_string(),
    })?;
    let materials = materials.map_err(|e| Error::File {
        path: obj_path.into(),
        message: e.to_string(),
    })?;

    // Textures in MTL files are relative to the MTL file; the first MTL's folder is used.
    let mtl_dir = mtl_paths
        .borrow()
        .first()
        .and_then(|p| p.parent().map(Path::to_path_buf));
    let mut scene = Scene::default();
    let mut texture_ids: HashMap<PathBuf, usize> = HashMap::new();
    let mut converted: Vec<Material> = Vec::with_capacity(materials.len());
    for m in &materials {
        let texture = match &m.diffuse_texture {
            Some(name) if !name.trim().is_empty() => {
                let tex_path = mtl_dir.as_deref().unwrap_or(dir).join(name.trim());
                let id = match texture_ids.get(&tex_path) {
                    Some(&id) => id,
                    None => {
                        scene.textures.push(load_texture(&tex_path)?);
                        texture_ids.insert(tex_path, scene.textures.len() - 1);
                        scene.textures.len() - 1
                    }
                };
                Some(id)
            }
            _ => None,
        };
        let material = material_from_mtl(m, texture);
        material
            .validate(&format!("material '{}'", m.name))
            .map_err(Error::Scene)?;
        converted.push(material);
    }

    let mut name_counts: HashMap<String, usize> = HashMap::new();
    for model in &models {
        *name_counts.entry(model.name.clone()).or_default() += 1;
    }
    for (index, model) in models.into_iter().enumerate() {
        let mesh = mesh_from_tobj(&model.mesh);
        if mesh.indices.is_empty() {
            continue;
        }
        let (material, material_name) = match model
            .mesh
            .material_id
            .and_then(|id| converted.get(id).zip(materials.get(id)))
        {
            Some((mat, mtl)) => (mat.clone(), Some(mtl.name.clone())),
            None => (
                Material::lambertian(distinct_color(seed, index as u32)),
                None,
            ),
        };
        let name = match (name_counts[&model.name] > 1, material_name) {
            (true, Some(mtl)) => format!("{} ({mtl})", model.name),
            _ => model.name.clone(),
        };
        scene.objects.push(Object {
            name,
            mesh: mesh.into(),
            material,
            transform: Default::default(),
        });
    }
    Ok(scene)
}

/// Checks what tobj accepts silently or reports without a line: vertex coordinates that are not
/// finite numbers, faces with fewer than 3 vertices, and indices that are zero or out of range.
fn validate_obj_text(path: &Path, text: &str) -> Result<()> {
    let (mut positions, mut uvs, mut normals) = (0i64, 0i64, 0i64);
    for (line_index, raw) in text.lines().enumerate() {
        let fail = |message: String| Error::Parse {
            path: path.into(),
            line: line_index + 1,
            message,
        };
        let mut words = raw.split_whitespace();
        let keyword = words.next().unwrap_or("");
        match keyword {
            "v" | "vn" | "vt" => {
                let needed = if keyword == "vt" { 1 } else { 3 };
                let mut count = 0;
                for word in words.by_ref().take(if keyword == "v" { 3 } else { needed }) {
                    let value: f32 = word
                        .parse()
                        .map_err(|_| fail(format!("'{word}' is not a number")))?;
                    if !value.is_finite() {
                        return Err(fail(format!("coordinate '{word}' is not finite")));
                    }
                    count += 1;
                }
                if count < needed {
                    return Err(fail(format!(
                        "'{keyword}' needs {needed} coordinates, found {count}"
                    )));
                }
                match keyword {
                    "v" => positions += 1,
                    "vt" => uvs += 1,
                    _ => normals += 1,
                }
            }
            "f" => {
                let mut corners = 0;
                for word in words {
                    corners += 1;
                    for (slot, part) in word.split('/').enumerate() {
                        if part.is_empty() && slot > 0 {
                            continue;
                        }
                        let (kind, count) = match slot {
                            0 => ("vertex", positions),
                            1 => ("texture coordinate", uvs),
                            2 => ("normal", normals),
                            _ => {
                                return Err(fail(format!("face corner '{word}' has too many '/'")));
                            }
                        };
                        let index: i64 = part
                            .parse()
                            .map_err(|_| fail(format!("'{part}' is not an index")))?;
                        let valid = (index > 0 && index <= count) || (index < 0 && -index <= count);
                        if !valid {
                            return Err(fail(format!(
                                "{kind} index {index} is out of range (1..={count} or -{count}..=-1)"
                            )));
                        }
                    }
                }
                if corners < 3 {
                    return Err(fail(format!(
                        "a face needs at least 3 vertices, found {corners}"
                    )));
                }
            }
            _ => {}
        }
    }
    Ok(())
}

/// The file as text, or an error naming the line where it stops being UTF-8 (a binary file).
fn utf8_text<'a>(path: &Path, bytes: &'a [u8]) -> Result<&'a str> {
    std::str::from_utf8(bytes).map_err(|e| Error::Parse {
        path: path.into(),
        line: bytes[..e.valid_up_to()]
            .iter()
            .filter(|&&b| b == b'\n')
            .count()
            + 1,
        message: "not UTF-8 text (binary file?)".into(),
    })
}

/// What tobj returns for an MTL file (its map type depends on tobj's features).
type MtlData = <tobj::MTLLoadResult as IntoIterator>::Item;

fn parse_mtl(path: &Path, bytes: &[u8]) -> Result<MtlData> {
    let text = normalize_mtl_colors(path, utf8_text(path, bytes)?)?;
    let mut reader = LineCountingReader::new(text.as_bytes());
    let result = guard_parser(path, || tobj::load_mtl_buf(&mut reader))?;
    result.map_err(|e| Error::Parse {
        path: path.into(),
        line: reader.current_line(),
        message: e.to_string(),
    })
}

/// Colour statements (`Ka`, `Kd`, `Ks`, `Ke`) checked and written with three values: the MTL format
/// lets g and b be omitted (`Kd 0.5` is grey), which tobj 4 does not accept (it panics), and
/// non-numbers or a missing blue get an error naming the line. Line numbers are kept.
fn normalize_mtl_colors(path: &Path, text: &str) -> Result<String> {
    let mut out = String::with_capacity(text.len() + 64);
    for (index, line) in text.lines().enumerate() {
        let mut words = line.split_whitespace();
        let keyword = words.next().unwrap_or("");
        if matches!(keyword, "Ka" | "Kd" | "Ks" | "Ke") {
            let fail = |message: String| Error::Parse {
                path: path.into(),
                line: index + 1,
                message,
            };
            let values = words
                .map(|w| match w.parse::<f32>() {
                    Ok(v) if v.is_finite() => Ok(v),
                    _ => Err(fail(format!("'{w}' in '{keyword}' is not a finite number (spectral and xyz colours are not supported)"))),
                })
                .collect::<Result<Vec<f32>>>()?;
            let rgb = match values.as_slice() {
                [g] => [*g; 3],
                [r, g, b, ..] => [*r, *g, *b],
                _ => {
                    return Err(fail(format!(
                        "'{keyword}' needs 1 or 3 numbers, found {}",
                        values.len()
                    )));
                }
            };
            out.push_str(&format!("{keyword} {} {} {}\n", rgb[0], rgb[1], rgb[2]));
        } else {
            out.push_str(line);
            out.push('\n');
        }
    }
    Ok(out)
}

/// Runs a tobj parser, turning a panic inside it (a bug in the parser, triggered by odd input) into
/// an error naming the file, so bad input never takes the program down.
fn guard_parser<T>(path: &Path, parse: impl FnOnce() -> T) -> Result<T> {
    std::panic::catch_unwind(std::panic::AssertUnwindSafe(parse)).map_err(|_| Error::File {
        path: path.into(),
        message: "the OBJ/MTL parser failed on this file (malformed input)".into(),
    })
}

fn param(m: &tobj::Material, key: &str) -> Option<Vec<f32>> {
    let text = m.unknown_param.get(key)?;
    let values: Option<Vec<f32>> = text.split_whitespace().map(|w| w.parse().ok()).collect();
    values.filter(|v| !v.is_empty())
}

fn rgb_param(m: &tobj::Material, key: &str) -> Option<Rgb> {
    let v = param(m, key)?;
    Some(match v.as_slice() {
        [g] => [*g; 3],
        [r, g, b, ..] => [*r, *g, *b],
        _ => return None,
    })
}

/// `v` clamped to [0, 1] (0 if not finite).
fn unit(v: f32) -> f32 {
    if v.is_finite() {
        v.clamp(0.0, 1.0)
    } else {
        0.0
    }
}

fn is_nonzero(c: &Rgb) -> bool {
    c.iter().any(|&v| v > 0.0)
}

/// Applies the MTL mapping documented at the top of this module.
pub fn material_from_mtl(m: &tobj::Material, texture: Option<usize>) -> Material {
    let emissive = m.emissive.or_else(|| rgb_param(m, "Ke"));
    if let Some(ke) = emissive.filter(is_nonzero) {
        return Material::Emissive {
            color: ke,
            intensity: 1.0,
        };
    }
    let illum = m.illumination_model.unwrap_or(2);
    let tf = rgb_param(m, "Tf");
    if matches!(illum, 4 | 6 | 7) || m.dissolve.is_some_and(|d| d < 1.0) || tf.is_some() {
        if let Some(pr) = param(m, "Pr").map(|v| v[0]).filter(|r| *r > 0.0) {
            return Material::Pbr(Box::new(rt_core::material::Pbr {
                base_color: tf.unwrap_or([1.0; 3]),
                roughness: pr.clamp(0.0, 1.0),
                ior: m.optical_density.filter(|n| *n >= 1.0).unwrap_or(1.5),
                transmission: 1.0,
                ..Default::default()
            }));
        }
        return Material::Dielectric {
            ior: m.optical_density.unwrap_or(1.5),
            tint: tf.unwrap_or([1.0; 3]),
        };
    }
    let kd = m.diffuse.unwrap_or([0.8; 3]);
    let blinn_alpha = m.shininess.map(|ns| (2.0 / (ns.max(0.0) + 2.0)).sqrt());
    let (pm, pr) = (param(m, "Pm").map(|v| v[0]), param(m, "Pr").map(|v| v[0]));
    let (pc, ps) = (param(m, "Pc").map(|v| v[0]), rgb_param(m, "Ps"));
    let aniso = param(m, "aniso").map(|v| v[0]);
    if pm.is_some() || pr.is_some() || pc.is_some() || ps.is_some() || aniso.is_some() {
        let metallic = pm
            .unwrap_or(if illum == 3 { 1.0 } else { 0.0 })
            .clamp(0.0, 1.0);
        let base_color = if metallic > 0.0 {
            m.specular.filter(is_nonzero).unwrap_or(kd)
        } else {
            kd
        };
        let roughness = pr.or(blinn_alpha.map(f32::sqrt)).unwrap_or(0.5);
        return Material::Pbr(Box::new(rt_core::material::Pbr {
            base_color,
            texture,
            metallic,
            roughness: roughness.clamp(0.0, 1.0),
            ior: m.optical_density.filter(|n| *n >= 1.0).unwrap_or(1.5),
            clearcoat: unit(pc.unwrap_or(0.0)),
            clearcoat_roughness: unit(param(m, "Pcr").map_or(0.0, |v| v[0])),
            sheen_color: ps.unwrap_or([0.0; 3]).map(unit),
            anisotropy: unit(aniso.unwrap_or(0.0)),
            anisotropy_rotation: param(m, "anisor")
                .map(|v| v[0])
                .filter(|v| v.is_finite())
                .map_or(0.0, |v| {
                    (v * std::f32::consts::TAU).rem_euclid(std::f32::consts::TAU)
                }),
            ..Default::default()
        }));
    }
    if illum == 3 {
        let albedo = m.specular.filter(is_nonzero).unwrap_or(kd);
        return Material::Metal {
            albedo,
            fuzz: blinn_alpha.unwrap_or(0.0).clamp(0.0, 1.0),
        };
    }
    Material::Lambertian {
        albedo: kd,
        texture,
    }
}

fn mesh_from_tobj(m: &tobj::Mesh) -> Mesh {
    let positions: Vec<Vec3> = m.positions.chunks_exact(3).map(Vec3::from_slice).collect();
    let normals = (m.normals.len() == m.positions.len() && !m.normals.is_empty())
        .then(|| m.normals.chunks_exact(3).map(Vec3::from_slice).collect());
    let uvs = (m.texcoords.len() / 2 == positions.len() && !m.texcoords.is_empty())
        .then(|| m.texcoords.chunks_exact(2).map(Vec2::from_slice).collect());
    let indices = m
        .indices
        .chunks_exact(3)
        .map(|t| [t[0], t[1], t[2]])
        .collect();
    let colors =
        (m.vertex_color.len() == m.positions.len() && !m.vertex_color.is_empty()).then(|| {
            m.vertex_color
                .chunks_exact(3)
                .map(Vec3::from_slice)
                .collect()
        });
    Mesh {
        positions,
        normals,
        uvs,
        colors,
        indices,
    }
}

/// A saturated colour, different for each object index and reproducible for a seed
/// (golden-ratio hue steps from a seed-dependent start).
pub fn distinct_color(seed: u32, index: u32) -> Rgb {
    let start = rt_core::math::rng::pcg_hash(seed) as f32 / u32::MAX as f32;
    let hue = (start + index as f32 * 0.618_034).fract();
    hsv_to_rgb(hue, 0.55, 0.8)
}

fn hsv_to_rgb(h: f32, s: f32, v: f32) -> Rgb {
    let h6 = h * 6.0;
    let f = |n: f32| {
        let k = (n + h6) % 6.0;
        v - v * s * k.min(4.0 - k).clamp(0.0, 1.0)
    };
    [f(5.0), f(3.0), f(1.0)]
}
