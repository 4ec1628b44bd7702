//! glTF 2.0 (.gltf with its buffers, .glb, embedded data URIs) through the `gltf` crate, mapped onto
//! rt's scene model:
//! - meshes: triangles, triangle strips and fans (other modes are an error naming the mode),
//!   indexed or not, positions, normals, the first UV set (flipped to rt's v-up convention) and
//!   vertex colours (COLOR_0, alpha dropped);
//!   each primitive is one shared mesh, so instances cost no copies;
//! - the node hierarchy (TRS or matrices) of the default scene or the one asked for;
//! - materials onto `Material::Pbr` (metallic-roughness with its textures and their samplers'
//!   wrap modes and magnification filter, normal maps, emission with its texture and
//!   `KHR_materials_emissive_strength`, `KHR_materials_transmission`, `_ior`, `_volume`,
//!   `_specular`, `_clearcoat` and `_sheen` with their textures, the factors of
//!   `_diffuse_transmission` and `_iridescence`, alpha MASK and BLEND; the base
//!   colour texture's `KHR_texture_transform` baked into the UVs);
//! - `KHR_lights_punctual` (candela and lux divided by 683 lm/W, as Blender's importer; spots with
//!   glTF's own falloff) and the first perspective camera.
//!
//! Files that require an extension rt does not support get an error naming it. What rt does not
//! map (texture transforms that differ from the base colour texture's, other UV sets,
//! skins, morph targets) is ignored with a warning; occlusion textures
//! are not used (a path tracer computes occlusion). Every byte range is checked before it is
//! read, so a broken file is an error naming the part at fault, never a panic.

mod animation;
mod buffers;
mod draco;
mod lights;
mod materials;
mod meshes;
pub mod meshopt;
mod nodes;

use std::collections::HashMap;
use std::path::Path;
use std::sync::Arc;

use glam::Mat4;

use rt_core::error::{Error, Result};
use rt_core::light::Light;
use rt_core::material::Material;
use rt_core::scene::{Mesh, Object, Scene, Texture, TextureSampler};

use buffers::load_buffers;
pub use lights::LUMENS_PER_WATT;

/// Extensions rt reads; a file may require only these.
pub const SUPPORTED_EXTENSIONS: &[&str] = &[
    "KHR_lights_punctual",
    "KHR_materials_anisotropy",
    "KHR_materials_clearcoat",
    "KHR_materials_diffuse_transmission",
    "KHR_materials_dispersion",
    "KHR_materials_emissive_strength",
    "KHR_materials_ior",
    "KHR_materials_iridescence",
    "KHR_materials_sheen",
    "KHR_materials_specular",
    "KHR_materials_transmission",
    "KHR_materials_volume",
    "KHR_materials_volume_scatter",
    "KHR_texture_transform",
    "EXT_texture_webp",
    "KHR_texture_basisu",
    "KHR_mesh_quantization",
    "EXT_meshopt_compression",
    "KHR_draco_mesh_compression",
];

/// Loads a .gltf or .glb file; `scene` picks one of its scenes (the default scene, else the first,
/// when `None`).
pub fn load_gltf(path: &Path, scene: Option<usize>) -> Result<Scene> {
    load_gltf_at(path, scene, None)
}

/// `load_gltf` posed at `time` seconds of the file's animations (`None`: the nodes as they stand,
/// the animation kept in [`Scene::animation`]; `rt_core::posing::posed_at`).
pub fn load_gltf_at(path: &Path, scene: Option<usize>, time: Option<f32>) -> Result<Scene> {
    let bytes = std::fs::read(path).map_err(|source| Error::Io {
        path: path.to_path_buf(),
        source,
    })?;
    let base = path.parent().unwrap_or(Path::new(".")).to_path_buf();
    let read = |p: &Path| {
        std::fs::read(p).map_err(|source| Error::Io {
            path: p.to_path_buf(),
            source,
        })
    };
    load_gltf_bytes_at(&bytes, path, &base, &read, scene, time)
}

/// `load_gltf` over bytes in memory; `read_file` loads what URIs name (relative to `base`).
pub fn load_gltf_bytes(
    bytes: &[u8],
    path: &Path,
    base: &Path,
    read_file: &dyn Fn(&Path) -> Result<Vec<u8>>,
    scene: Option<usize>,
) -> Result<Scene> {
    load_gltf_bytes_at(bytes, path, base, read_file, scene, None)
}

/// `load_gltf_bytes` posed at `time` seconds of the file's animations.
pub fn load_gltf_bytes_at(
    bytes: &[u8],
    path: &Path,
    base: &Path,
    read_file: &dyn Fn(&Path) -> Result<Vec<u8>>,
    scene: Option<usize>,
    time: Option<f32>,
) -> Result<Scene> {
    // The gltf crate's validation can panic on some malformed files: a bug in it must not take
    // the program down, so it becomes an error naming the file.
    let loaded = std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| {
        load_unguarded(bytes, path, base, read_file, scene)
    }))
    .unwrap_or_else(|_| {
        Err(Error::File {
            path: path.to_path_buf(),
            message: "the glTF parser failed on this file (malformed input)".into(),
        })
    })?;
    Ok(match time {
        Some(time) => crate::load::posed(loaded, path, time),
        None => loaded,
    })
}

/// A glTF 1.0 file: a binary container of version 1, or JSON whose `asset.version` is 1.x (or,
/// without an asset, whose meshes are a map by id, as 1.0 wrote them).
fn is_gltf_1(bytes: &[u8]) -> bool {
    if let Some(version) = bytes.strip_prefix(b"glTF").and_then(|rest| rest.get(..4)) {
        return version == 1u32.to_le_bytes();
    }
    let Ok(json) = serde_json::from_slice::<serde_json::Value>(bytes) else {
        return false;
    };
    match json["asset"]["version"].as_str() {
        Some(version) => version.starts_with("1."),
        None => json["meshes"].is_object(),
    }
}

fn load_unguarded(
    bytes: &[u8],
    path: &Path,
    base: &Path,
    read_file: &dyn Fn(&Path) -> Result<Vec<u8>>,
    scene: Option<usize>,
) -> Result<Scene> {
    let err = |message: String| Error::File {
        path: path.to_path_buf(),
        message,
    };
    // Required extensions are checked before validation, which would only call them unsupported.
    let unvalidated = gltf::Gltf::from_slice_without_validation(bytes).map_err(|e| {
        if is_gltf_1(bytes) {
            err(
                "glTF 1.0; rt reads glTF 2.0 (gltf-pipeline upgrades a file: \
                 npx gltf-pipeline -i in.gltf -o out.gltf)"
                    .into(),
            )
        } else {
            err(format!("not valid glTF: {e}"))
        }
    })?;
    for ext in unvalidated.document.extensions_required() {
        if !SUPPORTED_EXTENSIONS.contains(&ext) {
            return Err(err(unsupported_extension(ext)));
        }
    }
    let blob = unvalidated.blob;
    let mut root = unvalidated.document.into_json();
    // Checked above against what rt reads: gltf-json's own list lacks some of those
    // (`KHR_materials_volume`, `_specular`, `_clearcoat`, `_sheen`) and would refuse them.
    root.extensions_required.clear();
    // gltf-json's validation reads primitives' accessors before checking their indices.
    for (m, mesh) in root.meshes.iter().enumerate() {
        for (p, primitive) in mesh.primitives.iter().enumerate() {
            if let Some(bad) = primitive
                .attributes
                .values()
                .map(|a| a.value())
                .find(|&a| a >= root.accessors.len())
            {
                return Err(err(format!(
                    "mesh {m} primitive {p} uses accessor {bad}; the file has {}",
                    root.accessors.len()
                )));
            }
        }
    }
    fill_position_bounds(&mut root, path);
    use_extension_sources(&mut root);
    give_draco_accessors_a_view(&mut root);
    let document =
        gltf::Document::from_json(root).map_err(|e| err(format!("not valid glTF: {e}")))?;
    let gltf = gltf::Gltf { document, blob };
    let doc = &gltf.document;
    for ext in doc.extensions_used() {
        if !SUPPORTED_EXTENSIONS.contains(&ext) {
            log::warn!("{}: ignoring the optional extension {ext}", path.display());
        }
    }
    let buffers = load_buffers(doc, gltf.blob.as_deref(), base, read_file).map_err(err)?;
    let animation = animation::read_animation(doc, &buffers).map_err(err)?;
    let mut loader = Loader {
        path,
        buffers: &buffers,
        meshes: HashMap::new(),
        textures: Vec::new(),
        texture_of_image: HashMap::new(),
        objects: Vec::new(),
        lights: Vec::new(),
        camera: None,
        base,
        read_file,
        document: doc,
        skipped_primitives: 0,
        animated: animation.is_some(),
    };
    let chosen = match scene {
        Some(i) => doc.scenes().nth(i).ok_or_else(|| {
            err(format!(
                "there is no scene {i} (the file has {} scenes)",
                doc.scenes().len()
            ))
        })?,
        None => match doc.default_scene().or_else(|| doc.scenes().next()) {
            Some(s) => s,
            None => return Err(err("the file has no scene".into())),
        },
    };
    let mut stack = Vec::new();
    for node in chosen.nodes() {
        loader
            .visit(&node, Mat4::IDENTITY, &mut stack)
            .map_err(err)?;
    }
    if loader.skipped_primitives > 0 {
        if loader.objects.is_empty() {
            return Err(err(format!(
                "its {} primitives are points or lines, nothing rt can render (it renders \
                 surfaces: triangles, strips and fans)",
                loader.skipped_primitives
            )));
        }
        log::warn!(
            "{}: skipped {} primitives of points or lines (rt renders surfaces)",
            path.display(),
            loader.skipped_primitives
        );
    }
    let mut out = Scene {
        objects: loader.objects,
        textures: loader.textures,
        lights: loader.lights,
        animation: animation.map(Arc::new),
        ..Scene::default()
    };
    match loader.camera {
        Some((camera, aspect)) => {
            out.camera = camera;
            if let Some(aspect) = aspect.filter(|a| a.is_finite() && *a > 0.0) {
                out.settings.height = ((out.settings.width as f32 / aspect).round() as u32).max(1);
            }
        }
        None => {
            out.frame_for_viewing();
        }
    }
    if !out.has_emitters() && out.lights.is_empty() && !has_pbr_emission(&out) {
        out.environment = Some(crate::assets::default_environment()?);
    }
    Ok(out)
}

/// The spec requires POSITION accessors to state their `min` and `max`, and the gltf crate's
/// validation refuses files without them; some exporters leave them out. rt computes its own
/// bounds and never reads them, so missing or malformed ones get a placeholder (with a warning)
/// and the file opens.
fn fill_position_bounds(root: &mut gltf::json::Root, path: &Path) {
    let positions: Vec<usize> = root
        .meshes
        .iter()
        .flat_map(|m| &m.primitives)
        .filter_map(|p| {
            p.attributes
                .iter()
                .find(|(semantic, _)| {
                    matches!(
                        semantic,
                        gltf::json::validation::Checked::Valid(
                            gltf::json::mesh::Semantic::Positions
                        )
                    )
                })
                .map(|(_, a)| a.value())
        })
        .collect();
    let valid = |v: &Option<gltf::json::Value>| {
        v.as_ref()
            .is_some_and(|v| serde_json::from_value::<[f32; 3]>(v.clone()).is_ok())
    };
    for i in positions {
        let Some(accessor) = root.accessors.get_mut(i) else {
            continue;
        };
        if !(valid(&accessor.min) && valid(&accessor.max)) {
            log::warn!(
                "{}: accessor {i} (POSITION) lacks a valid min/max; rt computes its own bounds",
                path.display()
            );
            accessor.min = Some(serde_json::json!([0.0, 0.0, 0.0]));
            accessor.max = Some(serde_json::json!([0.0, 0.0, 0.0]));
        }
    }
}

/// `KHR_texture_basisu` and `EXT_texture_webp`: a texture reads the KTX2 or WebP image its
/// extension names (rt decodes both) rather than the fallback `source` (which the extensions let
/// a file leave out).
fn use_extension_sources(root: &mut gltf::json::Root) {
    let images = root.images.len();
    for texture in &mut root.textures {
        let source = ["KHR_texture_basisu", "EXT_texture_webp"]
            .iter()
            .find_map(|name| {
                texture
                    .extensions
                    .as_ref()
                    .and_then(|e| e.others.get(*name))
                    .and_then(|ext| ext["source"].as_u64())
                    .filter(|&i| (i as usize) < images)
            });
        if let Some(image) = source {
            texture.source = gltf::json::Index::new(image as u32);
        }
    }
}

/// `KHR_draco_mesh_compression`'s accessors may have no buffer view (the data is in the Draco
/// stream), which gltf-json's validation refuses: they get the stream's view, which rt never
/// reads through them.
fn give_draco_accessors_a_view(root: &mut gltf::json::Root) {
    let views = root.buffer_views.len();
    let mut placeholders = Vec::new();
    for primitive in root.meshes.iter().flat_map(|m| &m.primitives) {
        let stream = primitive
            .extensions
            .as_ref()
            .and_then(|e| e.others.get("KHR_draco_mesh_compression"))
            .and_then(|d| d["bufferView"].as_u64())
            .filter(|&v| (v as usize) < views);
        if let Some(view) = stream {
            let accessors = primitive.attributes.values().map(|a| a.value());
            placeholders.extend(
                accessors
                    .chain(primitive.indices.map(|i| i.value()))
                    .map(|a| (a, view)),
            );
        }
    }
    for (accessor, view) in placeholders {
        if let Some(accessor) = root.accessors.get_mut(accessor)
            && accessor.buffer_view.is_none()
        {
            accessor.buffer_view = Some(gltf::json::Index::new(view as u32));
        }
    }
}

fn has_pbr_emission(scene: &Scene) -> bool {
    scene.objects.iter().any(|o| match &o.material {
        Material::Pbr(p) => p.emission_strength > 0.0 && p.emission.iter().any(|c| *c > 0.0),
        _ => false,
    })
}

fn unsupported_extension(ext: &str) -> String {
    let what = match ext {
        "KHR_meshopt_compression" => {
            "compressed meshes; decompress them first, e.g. `gltf-transform copy IN OUT` (it \
             decodes Draco and meshopt)"
        }
        "KHR_mesh_quantization" => {
            "quantized vertex attributes; dequantize first, e.g. `gltf-transform dequantize IN OUT`"
        }
        "EXT_texture_avif" => {
            "textures in a format rt cannot decode; convert them to PNG or JPEG first, e.g. \
             `gltf-transform png IN OUT`"
        }
        _ => "an extension rt does not support",
    };
    format!("the file requires the extension {ext}: {what}")
}

/// One load's state: the file's buffers, the meshes and textures built so far (shared by every
/// node that uses them) and the scene's parts. Its methods live beside what they load: `nodes`
/// (the hierarchy, cameras, lights), `meshes` and `materials` (with their textures).
struct Loader<'a> {
    path: &'a Path,
    buffers: &'a [Vec<u8>],
    meshes: HashMap<(usize, usize), Arc<Mesh>>,
    textures: Vec<Texture>,
    texture_of_image: HashMap<(usize, TextureSampler), usize>,
    objects: Vec<Object>,
    lights: Vec<Light>,
    camera: Option<(rt_core::camera::Camera, Option<f32>)>,
    base: &'a Path,
    read_file: &'a dyn Fn(&Path) -> Result<Vec<u8>>,
    /// For the textures extensions name by index (`KHR_materials_clearcoat`, `_sheen`).
    document: &'a gltf::Document,
    /// Primitives of points or lines met (rt renders surfaces): skipped with a warning, an error
    /// only when nothing else is left.
    skipped_primitives: usize,
    /// Whether the file has an animation: then objects, lights and the camera record the node
    /// they hang under (`animation.rs`).
    animated: bool,
}
