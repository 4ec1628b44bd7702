//! The archive itself: a scene to zip bytes (meshes, textures, environment, manifest) and back,
//! with the format and version checked first and what serde cannot check checked after.

use std::collections::HashMap;
use std::io::{Cursor, Write};
use std::path::Path;
use std::sync::Arc;

use super::manifest::{
    ENVIRONMENT_ENTRY, EnvironmentEntry, FORMAT_VERSION, Header, MANIFEST, Manifest, ObjectEntry,
    PROJECT_FORMAT, TextureEntry, project_settings,
};
use super::meshes::{decode_mesh, encode_mesh};
use super::reader::{Archive, LoadLimits};
use rt_core::error::{Error, Result};
use rt_core::material::Material;
use rt_core::scene::{Mesh, Object, Scene, Texture};

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
            shadow_catcher: object.shadow_catcher,
            animation_node: object.animation_node,
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
        fog: scene.fog,
        animation: scene.animation.as_deref().filter(|_| is_project).cloned(),
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
            shadow_catcher: entry.shadow_catcher,
            animation_node: entry.animation_node,
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
            let (map, _) = rt_core::environment::EnvironmentMap::from_texels(
                entry.width,
                entry.height,
                texels,
            );
            Some(rt_core::environment::Environment {
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
        settings: project_settings(manifest.settings),
        lights: manifest.lights,
        environment,
        fog: manifest.fog,
        animation: manifest.animation.map(Arc::new),
    };
    check_scene(&scene).map_err(|m| archive.error(format!("{MANIFEST}: {m}")))?;
    Ok(scene)
}

/// The animation plays (`Animation::validate`) and every node an object, light or the camera
/// follows is one of its nodes.
fn check_animation(scene: &Scene) -> Result<(), String> {
    let nodes = match &scene.animation {
        Some(animation) => {
            animation.validate()?;
            animation.nodes.len()
        }
        None => 0,
    };
    let followed = (scene.objects.iter().enumerate())
        .map(|(i, o)| (format!("objects[{i}] ('{}')", o.name), o.animation_node))
        .chain(
            (scene.lights.iter().enumerate())
                .map(|(i, l)| (format!("lights[{i}] ('{}')", l.name), l.animation_node)),
        )
        .chain([("camera".to_string(), scene.camera.animation_node)]);
    for (what, node) in followed {
        if let Some(node) = node.filter(|&n| n as usize >= nodes) {
            return Err(format!(
                "{what}.animation_node: node {node} does not exist (the animation has {nodes})"
            ));
        }
    }
    Ok(())
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
    scene.fog.validate()?;
    check_animation(scene)?;
    let c = &scene.camera;
    if !(finite(&c.from) && finite(&c.to) && finite(&c.up) && c.vfov_deg.is_finite()) {
        return Err("camera: every number must be finite".into());
    }
    if !(finite(&[c.aperture_radius]) && c.focus_distance.is_none_or(f32::is_finite)) {
        return Err("camera: aperture and focus distance must be finite".into());
    }
    if !(c.ortho_height.is_none_or(|h| h.is_finite() && h > 0.0)
        && c.fisheye_angle_deg > 0.0
        && c.fisheye_angle_deg <= 360.0)
    {
        return Err("camera: ortho_height must be > 0 and fisheye_angle_deg in (0, 360]".into());
    }
    if !scene.ambient.iter().all(|v| v.is_finite() && *v >= 0.0) {
        return Err("ambient: must be finite and >= 0".into());
    }
    scene
        .settings
        .validate()
        .map_err(|m| format!("settings: {m}"))
}
