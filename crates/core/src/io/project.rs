//! Project files: a whole scene in one zip archive, so that a project can be mailed or moved
//! without breaking paths.
//!
//! Layout (format version 4; version 1 had no `lights`, versions before 3 no environment, before 4
//! no texture samplers, PBR emission textures or alpha modes):
//! - `project.json`: `{"format": "rt-project", "version": 1, ...}` with the camera, ambient light,
//!   render settings, and per object its name, material, transform and the mesh entry it uses;
//!   per texture its name, size, sampler and image entry.
//! - `meshes/N.bin`: one mesh each, in the little-endian layout of [`encode_mesh`]; objects that
//!   share a mesh in memory share the entry.
//! - `textures/N.png`: the RGBA8 texels, lossless.
//! - `environment.bin`: the environment map's linear RGB texels as little-endian f32, row-major
//!   from the top (version 3).
//!
//! A lighting file (`.rtlight`) is the same container with `"format": "rt-lighting"`, holding only
//! the ambient light, the emissive objects and the point, spot and directional lights, to reuse a
//! light set across projects.
//!
//! Loading reads every entry into memory and never writes anything, so hostile entry names cannot
//! reach the file system; they are rejected anyway, and decompressed sizes are capped by reading,
//! not by trusting the sizes the archive declares.

use std::collections::HashMap;
use std::io::{Cursor, Read, Write};
use std::path::{Path, PathBuf};
use std::sync::Arc;

use glam::{Vec2, Vec3};
use serde::{Deserialize, Serialize};

use crate::camera::Camera;
use crate::error::{Error, Result};
use crate::material::{Material, Rgb};
use crate::output::write_atomically;
use crate::scene::{Mesh, Object, RenderSettings, Scene, Texture, Transform};

/// The format version this build writes; it reads this and every earlier one. Version 2 added
/// point, spot and directional lights (`lights`); version 3 the PBR material and environment maps.
pub const FORMAT_VERSION: u32 = 4;
pub const PROJECT_FORMAT: &str = "rt-project";
pub const LIGHTING_FORMAT: &str = "rt-lighting";
/// File extensions the editor offers.
pub const PROJECT_EXTENSION: &str = "rtproj";
pub const LIGHTING_EXTENSION: &str = "rtlight";

const MANIFEST: &str = "project.json";
const MESH_MAGIC: &[u8; 8] = b"RTMESH1\0";

/// Caps on what loading a project may decompress.
#[derive(Clone, Copy, Debug)]
pub struct LoadLimits {
    pub max_entry_bytes: u64,
    pub max_total_bytes: u64,
    pub max_entries: usize,
}

impl Default for LoadLimits {
    fn default() -> Self {
        LoadLimits {
            // A 16k x 16k RGBA texture decoded, or ~40M triangles: far above real projects,
            // far below what would take the machine down.
            max_entry_bytes: 1 << 30,
            max_total_bytes: 4 << 30,
            max_entries: 100_000,
        }
    }
}

#[derive(Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
struct Manifest {
    format: String,
    version: u32,
    #[serde(default)]
    camera: Option<Camera>,
    ambient: Rgb,
    #[serde(default)]
    settings: Option<RenderSettings>,
    objects: Vec<ObjectEntry>,
    #[serde(default)]
    textures: Vec<TextureEntry>,
    #[serde(default)]
    lights: Vec<crate::light::Light>,
    #[serde(default)]
    environment: Option<EnvironmentEntry>,
}

#[derive(Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
struct EnvironmentEntry {
    source: String,
    rotation_deg: f32,
    strength: f32,
    file: String,
    width: u32,
    height: u32,
}

const ENVIRONMENT_ENTRY: &str = "environment.bin";

#[derive(Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
struct ObjectEntry {
    name: String,
    mesh: String,
    material: Material,
    #[serde(default)]
    transform: Transform,
}

#[derive(Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
struct TextureEntry {
    name: String,
    file: String,
    width: u32,
    height: u32,
    /// Absent in files of earlier versions: repeat, bilinear.
    #[serde(default)]
    sampler: crate::scene::TextureSampler,
}

/// Just the version fields, read first so that a future file gets a version error rather than a
/// confusing field error.
#[derive(Deserialize)]
struct Header {
    format: String,
    version: u32,
}

/// The ambient light and emissive objects of a lighting file.
#[derive(Clone, Debug, PartialEq)]
pub struct Lighting {
    pub ambient: Rgb,
    /// Emissive objects.
    pub lights: Vec<Object>,
    /// Point, spot and directional lights.
    pub delta_lights: Vec<crate::light::Light>,
}

impl Lighting {
    pub fn of(scene: &Scene) -> Self {
        Lighting {
            ambient: scene.ambient,
            lights: scene
                .objects
                .iter()
                .filter(|o| matches!(o.material, Material::Emissive { .. }))
                .cloned()
                .collect(),
            delta_lights: scene.lights.clone(),
        }
    }

    /// Replaces the scene's ambient light and emissive objects with these.
    pub fn apply(&self, scene: &mut Scene) {
        scene
            .objects
            .retain(|o| !matches!(o.material, Material::Emissive { .. }));
        scene.objects.extend(self.lights.iter().cloned());
        scene.lights = self.delta_lights.clone();
        scene.ambient = self.ambient;
    }
}

/// Saves `scene` as a project file, atomically.
pub fn save_project(scene: &Scene, path: &Path) -> Result<()> {
    let bytes = encode_archive(scene, PROJECT_FORMAT, path)?;
    write_atomically(path, &bytes)
}

/// Loads a project file with the default [`LoadLimits`].
pub fn load_project(path: &Path) -> Result<Scene> {
    let bytes = read_file(path)?;
    decode_archive(&bytes, path, PROJECT_FORMAT, &LoadLimits::default())
}

/// Saves the scene's ambient light and emissive objects, atomically.
pub fn save_lighting(lighting: &Lighting, path: &Path) -> Result<()> {
    let scene = Scene {
        objects: lighting.lights.clone(),
        ambient: lighting.ambient,
        lights: lighting.delta_lights.clone(),
        ..Scene::default()
    };
    let bytes = encode_archive(&scene, LIGHTING_FORMAT, path)?;
    write_atomically(path, &bytes)
}

pub fn load_lighting(path: &Path) -> Result<Lighting> {
    let bytes = read_file(path)?;
    let scene = decode_archive(&bytes, path, LIGHTING_FORMAT, &LoadLimits::default())?;
    if let Some(o) = scene
        .objects
        .iter()
        .find(|o| !matches!(o.material, Material::Emissive { .. }))
    {
        return Err(Error::File {
            path: path.into(),
            message: format!("object '{}' of a lighting file is not emissive", o.name),
        });
    }
    Ok(Lighting {
        ambient: scene.ambient,
        lights: scene.objects,
        delta_lights: scene.lights,
    })
}

fn read_file(path: &Path) -> Result<Vec<u8>> {
    if path.is_dir() {
        return Err(Error::File {
            path: path.into(),
            message: "is a directory, not a project file".into(),
        });
    }
    std::fs::read(path).map_err(|source| Error::Io {
        path: path.into(),
        source,
    })
}

/// The archive bytes of `scene`; `path` only names the file in errors.
pub fn encode_archive(scene: &Scene, format: &str, path: &Path) -> Result<Vec<u8>> {
    let err = |message: String| Error::File {
        path: path.into(),
        message,
    };
    let zip_err = |e: zip::result::ZipError| err(format!("writing the archive: {e}"));
    let io_err = |e: std::io::Error| err(format!("writing the archive: {e}"));
    let mut zip = zip::ZipWriter::new(Cursor::new(Vec::new()));
    let deflate = zip::write::SimpleFileOptions::default()
        .compression_method(zip::CompressionMethod::Deflated)
        .large_file(true);
    let stored = zip::write::SimpleFileOptions::default()
        .compression_method(zip::CompressionMethod::Stored)
        .large_file(true);

    let mut mesh_entries: HashMap<*const Mesh, String> = HashMap::new();
    let mut objects = Vec::with_capacity(scene.objects.len());
    for object in &scene.objects {
        let key = Arc::as_ptr(&object.mesh);
        let entry = match mesh_entries.get(&key) {
            Some(entry) => entry.clone(),
            None => {
                let entry = format!("meshes/{}.bin", mesh_entries.len());
                zip.start_file(entry.as_str(), deflate).map_err(zip_err)?;
                zip.write_all(&encode_mesh(&object.mesh)).map_err(io_err)?;
                mesh_entries.insert(key, entry.clone());
                entry
            }
        };
        objects.push(ObjectEntry {
            name: object.name.clone(),
            mesh: entry,
            material: object.material.clone(),
            transform: object.transform.clone(),
        });
    }
    let mut textures = Vec::with_capacity(scene.textures.len());
    for (i, texture) in scene.textures.iter().enumerate() {
        let file = format!("textures/{i}.png");
        let mut png = Cursor::new(Vec::new());
        image::RgbaImage::from_raw(texture.width, texture.height, texture.rgba8.to_vec())
            .ok_or_else(|| err(format!("texture '{}' has no pixel data", texture.name)))?
            .write_to(&mut png, image::ImageFormat::Png)
            .map_err(|e| err(format!("encoding texture '{}': {e}", texture.name)))?;
        zip.start_file(file.as_str(), stored).map_err(zip_err)?;
        zip.write_all(png.get_ref()).map_err(io_err)?;
        textures.push(TextureEntry {
            name: texture.name.clone(),
            file,
            width: texture.width,
            height: texture.height,
            sampler: texture.sampler,
        });
    }
    let environment = match &scene.environment {
        Some(env) => {
            let bytes: Vec<u8> = env
                .map
                .texels
                .iter()
                .flat_map(|t| t.iter().flat_map(|c| c.to_le_bytes()))
                .collect();
            zip.start_file(ENVIRONMENT_ENTRY, deflate)
                .map_err(zip_err)?;
            zip.write_all(&bytes).map_err(io_err)?;
            Some(EnvironmentEntry {
                source: env.source.clone(),
                rotation_deg: env.rotation_deg,
                strength: env.strength,
                file: ENVIRONMENT_ENTRY.into(),
                width: env.map.width,
                height: env.map.height,
            })
        }
        None => None,
    };
    let is_project = format == PROJECT_FORMAT;
    let manifest = Manifest {
        format: format.into(),
        version: FORMAT_VERSION,
        camera: is_project.then(|| scene.camera.clone()),
        ambient: scene.ambient,
        settings: is_project.then(|| scene.settings.clone()),
        objects,
        textures,
        lights: scene.lights.clone(),
        environment,
    };
    let json = serde_json::to_vec_pretty(&manifest)
        .map_err(|e| err(format!("encoding {MANIFEST}: {e}")))?;
    zip.start_file(MANIFEST, deflate).map_err(zip_err)?;
    zip.write_all(&json).map_err(io_err)?;
    Ok(zip.finish().map_err(zip_err)?.into_inner())
}

/// Reads an archive of the given format (`PROJECT_FORMAT` or `LIGHTING_FORMAT`) from memory.
pub fn decode_archive(
    bytes: &[u8],
    path: &Path,
    expected_format: &str,
    limits: &LoadLimits,
) -> Result<Scene> {
    let mut archive = Archive::open(bytes, path, limits)?;
    let json = archive.read(MANIFEST)?;
    let header: Header =
        serde_json::from_slice(&json).map_err(|e| archive.error(format!("{MANIFEST}: {e}")))?;
    if header.format != expected_format {
        return Err(archive.error(format!(
            "{MANIFEST}: format is '{}', expected '{expected_format}'",
            header.format
        )));
    }
    if header.version == 0 || header.version > FORMAT_VERSION {
        return Err(archive.error(format!(
            "format version {} is not supported: this build of rt reads versions 1 to \
             {FORMAT_VERSION} (a file from a newer rt needs that newer rt)",
            header.version
        )));
    }
    let manifest: Manifest =
        serde_json::from_slice(&json).map_err(|e| archive.error(format!("{MANIFEST}: {e}")))?;

    let mut meshes: HashMap<String, Arc<Mesh>> = HashMap::new();
    let mut objects = Vec::with_capacity(manifest.objects.len());
    for (i, entry) in manifest.objects.into_iter().enumerate() {
        let mesh = match meshes.get(&entry.mesh) {
            Some(mesh) => mesh.clone(),
            None => {
                let data = archive.read(&entry.mesh)?;
                let mesh = Arc::new(
                    decode_mesh(&data)
                        .map_err(|m| archive.error(format!("{}: {m}", entry.mesh)))?,
                );
                meshes.insert(entry.mesh.clone(), mesh.clone());
                mesh
            }
        };
        let object = Object {
            name: entry.name,
            mesh,
            material: entry.material,
            transform: entry.transform,
        };
        check_object(&object, i).map_err(|m| archive.error(format!("{MANIFEST}: {m}")))?;
        objects.push(object);
    }
    let mut textures = Vec::with_capacity(manifest.textures.len());
    for (i, entry) in manifest.textures.into_iter().enumerate() {
        let data = archive.read(&entry.file)?;
        let rgba = image::load_from_memory_with_format(&data, image::ImageFormat::Png)
            .map_err(|e| archive.error(format!("{} (texture '{}'): {e}", entry.file, entry.name)))?
            .to_rgba8();
        if (rgba.width(), rgba.height()) != (entry.width, entry.height) {
            return Err(archive.error(format!(
                "{MANIFEST}: textures[{i}] says {}x{}, but {} is {}x{}",
                entry.width,
                entry.height,
                entry.file,
                rgba.width(),
                rgba.height()
            )));
        }
        textures.push(Texture {
            sampler: entry.sampler,
            name: entry.name,
            width: entry.width,
            height: entry.height,
            rgba8: rgba.into_raw().into(),
        });
    }
    let environment = match manifest.environment {
        Some(entry) => {
            let data = archive.read(&entry.file)?;
            let expected = entry.width as u64 * entry.height as u64 * 12;
            if entry.width == 0 || entry.height == 0 || data.len() as u64 != expected {
                return Err(archive.error(format!(
                    "{MANIFEST}: environment says {}x{} ({expected} bytes), but {} has {} bytes",
                    entry.width,
                    entry.height,
                    entry.file,
                    data.len()
                )));
            }
            let texels = data
                .chunks_exact(12)
                .map(|c| {
                    let f = |i: usize| f32::from_le_bytes([c[i], c[i + 1], c[i + 2], c[i + 3]]);
                    [f(0), f(4), f(8)]
                })
                .collect();
            let (map, _) =
                crate::environment::EnvironmentMap::from_texels(entry.width, entry.height, texels);
            Some(crate::environment::Environment {
                source: entry.source,
                rotation_deg: entry.rotation_deg,
                strength: entry.strength,
                map: Arc::new(map),
            })
        }
        None => None,
    };
    let scene = Scene {
        objects,
        textures,
        camera: manifest.camera.unwrap_or_default(),
        ambient: manifest.ambient,
        settings: manifest.settings.unwrap_or_default(),
        lights: manifest.lights,
        environment,
    };
    check_scene(&scene).map_err(|m| archive.error(format!("{MANIFEST}: {m}")))?;
    Ok(scene)
}

fn finite(values: &[f32]) -> bool {
    values.iter().all(|v| v.is_finite())
}

fn check_object(object: &Object, i: usize) -> Result<(), String> {
    let at = format!("objects[{i}] ('{}')", object.name);
    let t = &object.transform;
    if !(finite(&t.translation) && finite(&t.rotation_deg) && finite(&t.scale)) {
        return Err(format!("{at}.transform: every number must be finite"));
    }
    object.material.validate(&format!("{at}.material"))
}

/// What serde cannot check: references between parts and numbers a JSON parser turns into ±inf.
fn check_scene(scene: &Scene) -> Result<(), String> {
    for (i, object) in scene.objects.iter().enumerate() {
        let slots = match &object.material {
            Material::Lambertian { texture, .. } => vec![("texture", *texture)],
            Material::Pbr(p) => p.textures().to_vec(),
            _ => Vec::new(),
        };
        for (slot, texture) in slots {
            if let Some(t) = texture
                && t >= scene.textures.len()
            {
                return Err(format!(
                    "objects[{i}] ('{}').material.{slot}: texture {t} does not exist ({} textures)",
                    object.name,
                    scene.textures.len()
                ));
            }
        }
    }
    for light in &scene.lights {
        light.validate()?;
    }
    if let Some(env) = &scene.environment {
        env.validate()?;
    }
    let c = &scene.camera;
    if !(finite(&c.from) && finite(&c.to) && finite(&c.up) && c.vfov_deg.is_finite()) {
        return Err("camera: every number must be finite".into());
    }
    if !(finite(&[c.aperture_radius]) && c.focus_distance.is_none_or(f32::is_finite)) {
        return Err("camera: aperture and focus distance must be finite".into());
    }
    if !scene.ambient.iter().all(|v| v.is_finite() && *v >= 0.0) {
        return Err("ambient: must be finite and >= 0".into());
    }
    scene
        .settings
        .validate()
        .map_err(|m| format!("settings: {m}"))
}

/// An opened archive with its entry names checked and a running total of decompressed bytes.
struct Archive<'a> {
    zip: zip::ZipArchive<Cursor<&'a [u8]>>,
    path: PathBuf,
    limits: LoadLimits,
    total: u64,
}

impl<'a> Archive<'a> {
    fn open(bytes: &'a [u8], path: &Path, limits: &LoadLimits) -> Result<Self> {
        let error = |message: String| Error::File {
            path: path.into(),
            message,
        };
        let zip = zip::ZipArchive::new(Cursor::new(bytes))
            .map_err(|e| error(format!("not a readable project archive: {e}")))?;
        if zip.len() > limits.max_entries {
            return Err(error(format!(
                "has {} entries; the limit is {}",
                zip.len(),
                limits.max_entries
            )));
        }
        for name in zip.file_names() {
            let name = name.map_err(|e| error(format!("unreadable entry name: {e}")))?;
            check_entry_name(&name).map_err(|m| error(format!("entry '{name}': {m}")))?;
        }
        Ok(Archive {
            zip,
            path: path.into(),
            limits: *limits,
            total: 0,
        })
    }

    fn error(&self, message: String) -> Error {
        Error::File {
            path: self.path.clone(),
            message,
        }
    }

    /// An entry's bytes, read through a cap so that a lying size field cannot exhaust memory.
    fn read(&mut self, name: &str) -> Result<Vec<u8>> {
        check_entry_name(name).map_err(|m| self.error(format!("entry '{name}': {m}")))?;
        let remaining = self.limits.max_total_bytes.saturating_sub(self.total);
        let cap = self.limits.max_entry_bytes.min(remaining);
        let mut data = Vec::new();
        let result = match self.zip.by_name(name) {
            Ok(file) => file
                .take(cap + 1)
                .read_to_end(&mut data)
                .map_err(|e| format!("entry '{name}' is corrupt: {e}")),
            Err(zip::result::ZipError::FileNotFound) => Err(format!("entry '{name}' is missing")),
            Err(e) => Err(format!("entry '{name}': {e}")),
        };
        result.map_err(|m| self.error(m))?;
        if data.len() as u64 > cap {
            return Err(self.error(format!(
                "entry '{name}' decompresses to more than {} bytes (limits: {} per entry, {} in all)",
                cap, self.limits.max_entry_bytes, self.limits.max_total_bytes
            )));
        }
        self.total += data.len() as u64;
        Ok(data)
    }
}

/// Entry names must be plain relative paths: no absolute paths, drive letters, `..` or backslashes.
fn check_entry_name(name: &str) -> Result<(), &'static str> {
    if name.is_empty() || name.contains('\0') {
        return Err("empty or contains NUL");
    }
    if name.starts_with('/') || name.contains('\\') || name.as_bytes().get(1) == Some(&b':') {
        return Err("absolute or non-portable path (possible path traversal)");
    }
    if name.split('/').any(|part| part == "..") {
        return Err("contains '..' (path traversal)");
    }
    Ok(())
}

/// `MESH_MAGIC`, then u32 vertex count, u32 triangle count, u32 flags (1: normals, 2: UVs, 4: vertex
/// colours), then positions (3 f32 per vertex), normals (3 f32), UVs (2 f32), colours (3 f32) and
/// indices (3 u32 per triangle), all little-endian.
pub fn encode_mesh(mesh: &Mesh) -> Vec<u8> {
    let n = mesh.positions.len();
    let mut out = Vec::with_capacity(20 + n * 32 + mesh.indices.len() * 12);
    out.extend_from_slice(MESH_MAGIC);
    let flags = u32::from(mesh.normals.is_some())
        | (u32::from(mesh.uvs.is_some()) << 1)
        | (u32::from(mesh.colors.is_some()) << 2);
    for v in [n as u32, mesh.indices.len() as u32, flags] {
        out.extend_from_slice(&v.to_le_bytes());
    }
    let mut put = |v: f32| out.extend_from_slice(&v.to_le_bytes());
    for p in &mesh.positions {
        p.to_array().into_iter().for_each(&mut put);
    }
    for normal in mesh.normals.iter().flatten() {
        normal.to_array().into_iter().for_each(&mut put);
    }
    for uv in mesh.uvs.iter().flatten() {
        uv.to_array().into_iter().for_each(&mut put);
    }
    for colour in mesh.colors.iter().flatten() {
        colour.to_array().into_iter().for_each(&mut put);
    }
    for tri in &mesh.indices {
        for i in tri {
            out.extend_from_slice(&i.to_le_bytes());
        }
    }
    out
}

pub fn decode_mesh(bytes: &[u8]) -> Result<Mesh, String> {
    let header = bytes
        .get(..20)
        .filter(|h| h.starts_with(MESH_MAGIC))
        .ok_or("not an rt mesh (bad header)")?;
    let word =
        |i: usize| u32::from_le_bytes([header[i], header[i + 1], header[i + 2], header[i + 3]]);
    let (vertices, triangles, flags) = (word(8) as usize, word(12) as usize, word(16));
    if flags > 7 {
        return Err(format!("unknown mesh flags {flags}"));
    }
    let floats_per_vertex =
        3 + 3 * (flags & 1) as usize + 2 * ((flags >> 1) & 1) as usize + 3 * (flags >> 2) as usize;
    let expected = (vertices as u128) * (floats_per_vertex as u128) * 4 + (triangles as u128) * 12;
    if expected != (bytes.len() - 20) as u128 {
        return Err(format!(
            "{vertices} vertices and {triangles} triangles need {expected} bytes, found {}",
            bytes.len() - 20
        ));
    }
    let mut words = bytes[20..]
        .chunks_exact(4)
        .map(|c| [c[0], c[1], c[2], c[3]]);
    let mut float = || f32::from_le_bytes(words.next().unwrap_or_default());
    let positions: Vec<Vec3> = (0..vertices)
        .map(|_| Vec3::new(float(), float(), float()))
        .collect();
    let normals = (flags & 1 != 0).then(|| {
        (0..vertices)
            .map(|_| Vec3::new(float(), float(), float()))
            .collect()
    });
    let uvs =
        (flags & 2 != 0).then(|| (0..vertices).map(|_| Vec2::new(float(), float())).collect());
    let colors = (flags & 4 != 0).then(|| {
        (0..vertices)
            .map(|_| Vec3::new(float(), float(), float()))
            .collect()
    });
    let offset = 20 + vertices * floats_per_vertex * 4;
    let indices: Vec<[u32; 3]> = bytes[offset..]
        .chunks_exact(12)
        .map(|c| {
            let u = |i: usize| u32::from_le_bytes([c[i], c[i + 1], c[i + 2], c[i + 3]]);
            [u(0), u(4), u(8)]
        })
        .collect();
    if let Some((t, tri)) = indices
        .iter()
        .enumerate()
        .find(|(_, tri)| tri.iter().any(|&i| i as usize >= vertices))
    {
        return Err(format!("triangle {t} indexes vertex {tri:?} of {vertices}"));
    }
    if let Some(v) = positions.iter().position(|p| !p.is_finite()) {
        return Err(format!("vertex {v} is not finite"));
    }
    Ok(Mesh {
        positions,
        normals,
        uvs,
        colors,
        indices,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn mesh_encoding_round_trips_with_and_without_attributes() {
        let mut mesh = crate::shapes::uv_sphere(1.0, 4, 6);
        assert_eq!(decode_mesh(&encode_mesh(&mesh)).unwrap(), mesh);
        mesh.normals = None;
        mesh.uvs = None;
        assert_eq!(decode_mesh(&encode_mesh(&mesh)).unwrap(), mesh);
    }

    #[test]
    fn mesh_decoding_rejects_bad_sizes_and_indices() {
        let mesh = crate::shapes::quad(Vec3::ZERO, Vec3::Z, 1.0);
        let bytes = encode_mesh(&mesh);
        assert!(decode_mesh(&bytes[..bytes.len() - 1]).is_err());
        assert!(decode_mesh(&bytes[..10]).is_err());
        let mut bad = bytes.clone();
        let last = bad.len() - 4;
        bad[last..].copy_from_slice(&99u32.to_le_bytes());
        assert!(decode_mesh(&bad).unwrap_err().contains("vertex"));
    }

    #[test]
    fn entry_names_that_could_escape_are_rejected() {
        for name in ["../x", "a/../../x", "/etc/passwd", "C:/x", "a\\..\\x", ""] {
            assert!(check_entry_name(name).is_err(), "{name}");
        }
        assert!(check_entry_name("meshes/0.bin").is_ok());
    }
}
