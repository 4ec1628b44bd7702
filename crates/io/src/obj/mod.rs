//! Wavefront OBJ + MTL through `tobj`, mapped onto rt's scene model; the MTL mapping is in
//! [`mtl`].
//!
//! Objects with no material get a distinct colour derived from the seed. Faces are triangulated as
//! fans; `o`/`g` start new objects and `usemtl` splits an object by material.
//!
//! Forgiving, as Blender and assimp are: text that is not UTF-8 is read as Latin-1 (UTF-16 with a
//! byte-order mark is decoded), a material without a name is named, and file names are found
//! through Windows separators, another case and the model's own folder ([`paths`]). A missing MTL
//! file or texture is a warning: its objects keep default materials, its material no texture. A
//! file that is there but broken stays an error naming it.

mod maps;
mod mtl;
mod paths;
mod text;
mod textures;

use std::cell::RefCell;
use std::collections::HashMap;
use std::path::{Path, PathBuf};

use glam::{Vec2, Vec3};

use super::line_reader::LineCountingReader;
use super::parse_guard::guard_parser;
use super::texture::load_texture;
use mtl::{MtlData, parse_mtl};
use rt_core::error::{Error, Result};
use rt_core::material::{Material, Rgb};
use rt_core::scene::{Mesh, Object, Scene, Texture};
use text::{decode_text, name_unnamed_materials, validate_obj_text};
use textures::MtlTextures;

pub use mtl::material_from_mtl;

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
        std::fs::read(paths::on_disk(p)).map_err(|source| Error::Io {
            path: p.into(),
            source,
        })
    };
    load_obj_bytes(
        path,
        &bytes,
        &dir,
        &read_file,
        &|p: &Path| load_texture(&paths::on_disk(p)),
        seed,
    )
}

/// Loads an OBJ held in memory; `read_file` supplies MTL files and `load_texture` textures, both by
/// path joined onto `dir` ([`paths::candidates`]).
pub fn load_obj_bytes(
    obj_path: &Path,
    bytes: &[u8],
    dir: &Path,
    read_file: &dyn Fn(&Path) -> Result<Vec<u8>>,
    load_texture: &dyn Fn(&Path) -> Result<Texture>,
    seed: u32,
) -> Result<Scene> {
    let text = decode_text(obj_path, bytes)?;
    let text = name_unnamed_materials(&text, "usemtl");
    validate_obj_text(obj_path, &text)?;

    let mtl_error: RefCell<Option<Error>> = RefCell::new(None);
    let mtl_paths: RefCell<Vec<PathBuf>> = RefCell::new(Vec::new());
    let mut reader = LineCountingReader::new(text.as_bytes());
    let options = tobj::LoadOptions {
        triangulate: true,
        single_index: true,
        ..Default::default()
    };
    let loaded = guard_parser(obj_path, "OBJ/MTL", || {
        tobj::load_obj_buf(&mut reader, &options, |mtl_name| {
            let Some((mtl_path, mtl_bytes)) =
                find_file(dir, &mtl_name.to_string_lossy(), read_file)
            else {
                log::warn!(
                    "{}: its material library '{}' is missing; its objects get default materials",
                    obj_path.display(),
                    mtl_name.display()
                );
                return Ok(MtlData::default());
            };
            match parse_mtl(&mtl_path, &mtl_bytes) {
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
    let mtl_name = mtl_paths.borrow().first().cloned().unwrap_or_default();
    let mut textures = MtlTextures::new(mtl_dir.as_deref().unwrap_or(dir), &mtl_name, load_texture);
    let mut converted: Vec<(Material, Option<UvTransform>)> = Vec::with_capacity(materials.len());
    for m in &materials {
        let loaded = textures.material(m)?;
        let material = maps::with_maps(material_from_mtl(m, loaded.diffuse), &loaded.maps, m);
        material
            .validate(&format!("material '{}'", m.name))
            .map_err(Error::Scene)?;
        let uv_transform = loaded
            .diffuse_statement
            .filter(|s| s.offset != [0.0; 2] || s.scale != [1.0; 2])
            .map(|s| (s.offset, s.scale));
        converted.push((material, uv_transform));
    }
    scene.textures = textures.textures;

    let mut name_counts: HashMap<String, usize> = HashMap::new();
    for model in &models {
        *name_counts.entry(model.name.clone()).or_default() += 1;
    }
    for (index, model) in models.into_iter().enumerate() {
        let mut mesh = mesh_from_tobj(&model.mesh);
        if mesh.indices.is_empty() {
            continue;
        }
        let (material, material_name) = match model
            .mesh
            .material_id
            .and_then(|id| converted.get(id).zip(materials.get(id)))
        {
            Some(((mat, uv_transform), mtl)) => {
                // `map_Kd -o u v -s u v`: baked into this object's UVs.
                if let (Some((offset, scale)), Some(uvs)) = (uv_transform, mesh.uvs.as_mut()) {
                    for uv in uvs {
                        *uv = *uv * Vec2::from(*scale) + Vec2::from(*offset);
                    }
                }
                (mat.clone(), Some(mtl.name.clone()))
            }
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
            shadow_catcher: false,
            animation_node: None,
            name,
            mesh: mesh.into(),
            material,
            transform: Default::default(),
        });
    }
    Ok(scene)
}

/// The first of `name`'s [`paths::candidates`] that `read_file` reads, with its bytes.
fn find_file(
    dir: &Path,
    name: &str,
    read_file: &dyn Fn(&Path) -> Result<Vec<u8>>,
) -> Option<(PathBuf, Vec<u8>)> {
    paths::candidates(dir, name)
        .into_iter()
        .find_map(|path| read_file(&path).ok().map(|bytes| (path, bytes)))
}

/// `map_Kd`'s `-o` offset and `-s` scale.
type UvTransform = ([f32; 2], [f32; 2]);

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
