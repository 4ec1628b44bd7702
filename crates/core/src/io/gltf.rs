//! glTF 2.0 (.gltf with its buffers, .glb, embedded data URIs) through the `gltf` crate, mapped onto
//! rt's scene model:
//! - meshes: triangles, triangle strips and fans (other modes are an error naming the mode),
//!   indexed or not, positions, normals, the first UV set (flipped to rt's v-up convention) and
//!   vertex colours (COLOR_0, alpha dropped);
//!   each primitive is one shared mesh, so instances cost no copies;
//! - the node hierarchy (TRS or matrices) of the default scene or the one asked for;
//! - materials onto `Material::Pbr` (metallic-roughness with its textures and their samplers'
//!   wrap modes and magnification filter, normal maps, emission with its texture and
//!   `KHR_materials_emissive_strength`, `KHR_materials_transmission`, `_ior`, `_volume`, alpha
//!   MASK and BLEND; the base colour texture's `KHR_texture_transform` baked into the UVs);
//! - `KHR_lights_punctual` (candela and lux divided by 683 lm/W, as Blender's importer; spots with
//!   glTF's own falloff) and the first perspective camera.
//!
//! Files that require an extension rt does not support get an error naming it. What rt does not
//! map (texture transforms that differ from the base colour texture's, other UV sets,
//! `KHR_materials_specular`, skins, morph targets) is ignored with a warning; occlusion textures
//! are not used (a path tracer computes occlusion). Every byte range is checked before it is
//! read, so a broken file is an error naming the part at fault, never a panic.

use std::collections::HashMap;
use std::path::{Path, PathBuf};
use std::sync::Arc;

use glam::{Mat4, Vec2, Vec3};

use crate::error::{Error, Result};
use crate::light::{Light, LightKind, SpotFalloff};
use crate::material::{AlphaMode, Material, Pbr};
use crate::scene::{Filter, Mesh, Object, Scene, Texture, TextureSampler, Transform, Wrap};

/// Extensions rt reads; a file may require only these.
pub const SUPPORTED_EXTENSIONS: &[&str] = &[
    "KHR_lights_punctual",
    "KHR_materials_emissive_strength",
    "KHR_materials_ior",
    "KHR_materials_transmission",
    "KHR_materials_volume",
    "KHR_texture_transform",
];

/// Node trees deeper than this are refused (real files nest a few dozen levels).
const MAX_NODE_DEPTH: usize = 1024;

/// Loads a .gltf or .glb file; `scene` picks one of its scenes (the default scene, else the first,
/// when `None`).
pub fn load_gltf(path: &Path, scene: Option<usize>) -> Result<Scene> {
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
    load_gltf_bytes(&bytes, path, &base, &read, scene)
}

/// `load_gltf` over bytes in memory; `read_file` loads what URIs name (relative to `base`).
pub fn load_gltf_bytes(
    bytes: &[u8],
    path: &Path,
    base: &Path,
    read_file: &dyn Fn(&Path) -> Result<Vec<u8>>,
    scene: Option<usize>,
) -> Result<Scene> {
    // The gltf crate's validation can panic on some malformed files: a bug in it must not take
    // the program down, so it becomes an error naming the file.
    std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| {
        load_unguarded(bytes, path, base, read_file, scene)
    }))
    .unwrap_or_else(|_| {
        Err(Error::File {
            path: path.to_path_buf(),
            message: "the glTF parser failed on this file (malformed input)".into(),
        })
    })
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
    let unvalidated = gltf::Gltf::from_slice_without_validation(bytes)
        .map_err(|e| err(format!("not valid glTF: {e}")))?;
    for ext in unvalidated.document.extensions_required() {
        if !SUPPORTED_EXTENSIONS.contains(&ext) {
            return Err(err(unsupported_extension(ext)));
        }
    }
    let blob = unvalidated.blob;
    let mut root = unvalidated.document.into_json();
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
    let mut out = Scene {
        objects: loader.objects,
        textures: loader.textures,
        lights: loader.lights,
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

fn has_pbr_emission(scene: &Scene) -> bool {
    scene.objects.iter().any(|o| match &o.material {
        Material::Pbr(p) => p.emission_strength > 0.0 && p.emission.iter().any(|c| *c > 0.0),
        _ => false,
    })
}

fn unsupported_extension(ext: &str) -> String {
    let what = match ext {
        "KHR_draco_mesh_compression" | "EXT_meshopt_compression" | "KHR_meshopt_compression" => {
            "compressed meshes; decompress them first, e.g. `gltf-transform copy IN OUT` (it \
             decodes Draco and meshopt)"
        }
        "KHR_mesh_quantization" => {
            "quantized vertex attributes; dequantize first, e.g. `gltf-transform dequantize IN OUT`"
        }
        "KHR_texture_basisu" | "EXT_texture_webp" | "EXT_texture_avif" => {
            "textures in a format rt cannot decode; convert them to PNG or JPEG first, e.g. \
             `gltf-transform png IN OUT`"
        }
        _ => "an extension rt does not support",
    };
    format!("the file requires the extension {ext}: {what}")
}

/// Reads what a URI names: a base64 data URI or a file relative to `base` (percent-decoded).
fn read_uri(
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

fn load_buffers(
    doc: &gltf::Document,
    blob: Option<&[u8]>,
    base: &Path,
    read_file: &dyn Fn(&Path) -> Result<Vec<u8>>,
) -> std::result::Result<Vec<Vec<u8>>, String> {
    let mut out = Vec::with_capacity(doc.buffers().len());
    for buffer in doc.buffers() {
        let data = match buffer.source() {
            gltf::buffer::Source::Bin => blob
                .ok_or_else(|| {
                    format!(
                        "buffer {} refers to a GLB chunk the file lacks",
                        buffer.index()
                    )
                })?
                .to_vec(),
            gltf::buffer::Source::Uri(uri) => read_uri(uri, base, read_file)
                .map_err(|e| format!("buffer {}: {e}", buffer.index()))?,
        };
        if data.len() < buffer.length() {
            return Err(format!(
                "buffer {} has {} bytes but declares {}",
                buffer.index(),
                data.len(),
                buffer.length()
            ));
        }
        out.push(data);
    }
    Ok(out)
}

/// What an attribute's accessor may hold.
#[derive(Clone, Copy)]
enum Expect {
    Vec3F32,
    Uv,
    Indices,
    Color,
}

/// Checks that `accessor` holds what `expect` says and that every byte it reads lies inside its
/// view and buffer (the gltf crate's readers assume both).
fn check_accessor(
    accessor: &gltf::Accessor,
    buffers: &[Vec<u8>],
    expect: Expect,
) -> std::result::Result<(), String> {
    use gltf::accessor::{DataType as T, Dimensions as D};
    let what = || format!("accessor {}", accessor.index());
    let (ty, dims) = (accessor.data_type(), accessor.dimensions());
    let ok = match expect {
        Expect::Vec3F32 => ty == T::F32 && dims == D::Vec3,
        Expect::Uv => matches!(ty, T::F32 | T::U8 | T::U16) && dims == D::Vec2,
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

struct Loader<'a> {
    path: &'a Path,
    buffers: &'a [Vec<u8>],
    meshes: HashMap<(usize, usize), Arc<Mesh>>,
    textures: Vec<Texture>,
    texture_of_image: HashMap<(usize, TextureSampler), usize>,
    objects: Vec<Object>,
    lights: Vec<Light>,
    camera: Option<(crate::camera::Camera, Option<f32>)>,
    base: &'a Path,
    read_file: &'a dyn Fn(&Path) -> Result<Vec<u8>>,
}

impl Loader<'_> {
    fn visit(
        &mut self,
        node: &gltf::Node,
        parent: Mat4,
        stack: &mut Vec<usize>,
    ) -> std::result::Result<(), String> {
        if stack.contains(&node.index()) {
            return Err(format!("node {} is its own ancestor", node.index()));
        }
        if stack.len() >= MAX_NODE_DEPTH {
            return Err(format!("nodes nest deeper than {MAX_NODE_DEPTH} levels"));
        }
        let local = Mat4::from_cols_array_2d(&node.transform().matrix());
        let world = parent * local;
        if !world.is_finite() {
            return Err(format!(
                "node {}: its transform is not finite",
                node.index()
            ));
        }
        stack.push(node.index());
        let name = node
            .name()
            .map(str::to_string)
            .unwrap_or_else(|| format!("node {}", node.index()));
        if let Some(mesh) = node.mesh() {
            for primitive in mesh.primitives() {
                let m = self.mesh(&mesh, &primitive)?;
                let material = self.material(&primitive.material())?;
                let object_name = if mesh.primitives().len() > 1 {
                    format!("{name} ({})", primitive.index())
                } else {
                    name.clone()
                };
                self.objects.push(Object {
                    name: object_name,
                    mesh: m,
                    material,
                    transform: transform_of(world),
                });
            }
        }
        if let Some(camera) = node.camera()
            && self.camera.is_none()
        {
            match camera.projection() {
                gltf::camera::Projection::Perspective(p) => {
                    let from = world.transform_point3(Vec3::ZERO);
                    let forward = world.transform_vector3(Vec3::NEG_Z).normalize_or_zero();
                    let up = world.transform_vector3(Vec3::Y).normalize_or_zero();
                    self.camera = Some((
                        crate::camera::Camera {
                            from: from.to_array(),
                            to: (from + forward).to_array(),
                            up: up.to_array(),
                            vfov_deg: p.yfov().to_degrees(),
                            ..Default::default()
                        },
                        p.aspect_ratio(),
                    ));
                }
                gltf::camera::Projection::Orthographic(_) => log::warn!(
                    "{}: {name} has an orthographic camera, which rt cannot use",
                    self.path.display()
                ),
            }
        }
        if let Some(light) = node.light() {
            self.lights.push(light_of(&light, world, &name));
        }
        for child in node.children() {
            self.visit(&child, world, stack)?;
        }
        stack.pop();
        Ok(())
    }

    fn mesh(
        &mut self,
        mesh: &gltf::Mesh,
        primitive: &gltf::Primitive,
    ) -> std::result::Result<Arc<Mesh>, String> {
        let key = (mesh.index(), primitive.index());
        if let Some(m) = self.meshes.get(&key) {
            return Ok(m.clone());
        }
        let at = format!("mesh {} primitive {}", mesh.index(), primitive.index());
        use gltf::mesh::Mode;
        let mode = primitive.mode();
        if !matches!(
            mode,
            Mode::Triangles | Mode::TriangleStrip | Mode::TriangleFan
        ) {
            return Err(format!(
                "{at}: primitive mode {mode:?} is not made of triangles (rt renders surfaces)"
            ));
        }
        let positions_accessor = primitive
            .get(&gltf::Semantic::Positions)
            .ok_or_else(|| format!("{at} has no POSITION attribute"))?;
        check_accessor(&positions_accessor, self.buffers, Expect::Vec3F32)
            .map_err(|e| format!("{at}: {e}"))?;
        for (semantic, expect) in [
            (gltf::Semantic::Normals, Expect::Vec3F32),
            (gltf::Semantic::TexCoords(0), Expect::Uv),
            (gltf::Semantic::Colors(0), Expect::Color),
        ] {
            if let Some(a) = primitive.get(&semantic) {
                check_accessor(&a, self.buffers, expect).map_err(|e| format!("{at}: {e}"))?;
            }
        }
        if let Some(a) = primitive.indices() {
            check_accessor(&a, self.buffers, Expect::Indices).map_err(|e| format!("{at}: {e}"))?;
        }
        let reader = primitive.reader(|b| self.buffers.get(b.index()).map(Vec::as_slice));
        let positions: Vec<Vec3> = reader
            .read_positions()
            .ok_or_else(|| format!("{at}: unreadable POSITION"))?
            .map(Vec3::from)
            .collect();
        if let Some(bad) = positions.iter().position(|p| !p.is_finite()) {
            return Err(format!("{at}: vertex {bad} is not finite"));
        }
        let n = positions.len();
        let normals: Option<Vec<Vec3>> = reader
            .read_normals()
            .map(|it| it.map(Vec3::from).collect::<Vec<_>>())
            .filter(|v| v.len() == n && v.iter().all(|x| x.is_finite()));
        let uv_transform = uv_transform_of(&primitive.material());
        let uvs: Option<Vec<Vec2>> = reader
            .read_tex_coords(0)
            .map(|t| {
                t.into_f32()
                    .map(|uv| {
                        let [u, v] = uv_transform(uv);
                        Vec2::new(u, 1.0 - v)
                    })
                    .collect::<Vec<_>>()
            })
            .filter(|v| v.len() == n && v.iter().all(|x| x.is_finite()));
        let colors: Option<Vec<Vec3>> = reader
            .read_colors(0)
            .map(|c| c.into_rgb_f32().map(Vec3::from).collect::<Vec<_>>())
            .filter(|v| v.len() == n && v.iter().all(|x| x.is_finite()));
        let flat: Vec<u32> = match reader.read_indices() {
            Some(i) => i.into_u32().collect(),
            None => (0..n as u32).collect(),
        };
        if let Some(bad) = flat.iter().find(|&&i| i as usize >= n) {
            return Err(format!("{at}: index {bad} is past its {n} vertices"));
        }
        let indices: Vec<[u32; 3]> = match mode {
            Mode::Triangles => flat.chunks_exact(3).map(|c| [c[0], c[1], c[2]]).collect(),
            Mode::TriangleStrip => (2..flat.len())
                .map(|i| {
                    if i % 2 == 0 {
                        [flat[i - 2], flat[i - 1], flat[i]]
                    } else {
                        [flat[i - 1], flat[i - 2], flat[i]]
                    }
                })
                .collect(),
            _ => (2..flat.len())
                .map(|i| [flat[0], flat[i - 1], flat[i]])
                .collect(),
        };
        let mesh = Arc::new(Mesh {
            positions,
            normals,
            uvs,
            colors,
            indices,
        });
        self.meshes.insert(key, mesh.clone());
        Ok(mesh)
    }

    /// rt's texture for a glTF texture: its image decoded once for each sampler that reads it.
    fn texture(&mut self, texture: &gltf::Texture) -> std::result::Result<usize, String> {
        let image = texture.source();
        let sampler = sampler_of(&texture.sampler());
        if let Some(&i) = self.texture_of_image.get(&(image.index(), sampler)) {
            return Ok(i);
        }
        let bytes = match image.source() {
            gltf::image::Source::View { view, .. } => {
                let buffer = &self.buffers[view.buffer().index()];
                let end = view.offset() as u64 + view.length() as u64;
                if end > buffer.len() as u64 {
                    return Err(format!(
                        "image {}: its view ends past its buffer",
                        image.index()
                    ));
                }
                buffer[view.offset()..end as usize].to_vec()
            }
            gltf::image::Source::Uri { uri, .. } => read_uri(uri, self.base, self.read_file)
                .map_err(|e| format!("image {}: {e}", image.index()))?,
        };
        let name = image
            .name()
            .map(str::to_string)
            .unwrap_or_else(|| format!("{} image {}", self.path.display(), image.index()));
        let decoded =
            decode_texture(&bytes).map_err(|e| format!("image {}: {e}", image.index()))?;
        let index = self.textures.len();
        self.textures.push(Texture {
            sampler,
            name,
            width: decoded.width(),
            height: decoded.height(),
            rgba8: decoded.into_raw().into(),
        });
        self.texture_of_image
            .insert((image.index(), sampler), index);
        Ok(index)
    }

    /// The texture of one material slot; `transform` is the slot's `KHR_texture_transform` and
    /// `baked` the one baked into the mesh's UVs (the base colour texture's).
    fn slot(
        &mut self,
        info: Option<(gltf::Texture, u32, Option<UvTransform>)>,
        baked: Option<UvTransform>,
        what: &str,
    ) -> std::result::Result<Option<usize>, String> {
        let Some((texture, tex_coord, transform)) = info else {
            return Ok(None);
        };
        if tex_coord != 0 {
            log::warn!(
                "{}: the {what} uses UV set {tex_coord}; rt reads only the first: ignoring it",
                self.path.display()
            );
            return Ok(None);
        }
        if transform.is_some() && transform != baked {
            log::warn!(
                "{}: the {what}'s KHR_texture_transform differs from the base colour texture's \
                 and is not applied (rt bakes the base colour texture's into the UVs, which every \
                 texture of the material then uses)",
                self.path.display()
            );
        }
        self.texture(&texture).map(Some)
    }

    fn material(&mut self, m: &gltf::Material) -> std::result::Result<Material, String> {
        let pbr = m.pbr_metallic_roughness();
        fn info<'a>(
            i: Option<gltf::texture::Info<'a>>,
        ) -> Option<(gltf::Texture<'a>, u32, Option<UvTransform>)> {
            i.map(|i| {
                let t = i.texture_transform().map(|t| UvTransform {
                    offset: t.offset(),
                    rotation: t.rotation(),
                    scale: t.scale(),
                });
                (i.texture(), i.tex_coord(), t)
            })
        }
        let base_color = pbr.base_color_factor();
        let base_info = info(pbr.base_color_texture());
        let baked = base_info.as_ref().and_then(|i| i.2);
        let texture = self.slot(base_info, baked, "base colour texture")?;
        let metallic_roughness_texture = self.slot(
            info(pbr.metallic_roughness_texture()),
            baked,
            "metallic-roughness texture",
        )?;
        let normal = m.normal_texture();
        let normal_scale = normal.as_ref().map_or(1.0, |n| n.scale());
        let normal_texture = self.slot(
            normal.map(|n| (n.texture(), n.tex_coord(), None)),
            baked,
            "normal map",
        )?;
        let emission_texture = self.slot(info(m.emissive_texture()), baked, "emissive texture")?;
        if m.occlusion_texture().is_some() {
            log::info!(
                "{}: material {}: the occlusion texture is not used (the path tracer computes \
                 occlusion itself, as Cycles does)",
                self.path.display(),
                m.index().map_or("default".into(), |i| i.to_string())
            );
        }
        let alpha_mode = match m.alpha_mode() {
            gltf::material::AlphaMode::Opaque => AlphaMode::Opaque,
            gltf::material::AlphaMode::Mask => AlphaMode::Mask,
            gltf::material::AlphaMode::Blend => AlphaMode::Blend,
        };
        let cutoff = m.alpha_cutoff().unwrap_or(0.5);
        let transmission = m.transmission().map_or(0.0, |t| t.transmission_factor());
        let volume = m.volume();
        let (attenuation_color, attenuation_distance) =
            volume.as_ref().map_or(([1.0; 3], None), |v| {
                let d = v.attenuation_distance();
                (
                    v.attenuation_color(),
                    (d.is_finite() && d > 0.0).then_some(d),
                )
            });
        let clamp01 = |v: f32| {
            if v.is_finite() {
                v.clamp(0.0, 1.0)
            } else {
                0.0
            }
        };
        let colour = |c: [f32; 3]| c.map(|v| if v.is_finite() { v.max(0.0) } else { 0.0 });
        let ior = m
            .ior()
            .filter(|i| i.is_finite() && *i >= 1.0)
            .unwrap_or(1.5);
        Ok(Material::Pbr(Box::new(Pbr {
            base_color: colour([base_color[0], base_color[1], base_color[2]]),
            texture,
            metallic_roughness_texture,
            normal_texture,
            normal_scale: if normal_scale.is_finite() {
                normal_scale
            } else {
                1.0
            },
            metallic: clamp01(pbr.metallic_factor()),
            roughness: clamp01(pbr.roughness_factor()),
            ior,
            transmission: clamp01(transmission),
            // glTF: transmission without a volume is a thin-walled surface.
            thin_walled: transmission > 0.0 && volume.is_none(),
            attenuation_color: colour(attenuation_color).map(|c| c.min(1.0)),
            attenuation_distance,
            emission: colour(m.emissive_factor()),
            emission_strength: m
                .emissive_strength()
                .filter(|s| s.is_finite() && *s >= 0.0)
                .unwrap_or(1.0),
            emission_texture,
            alpha_mode,
            alpha: clamp01(base_color[3]),
            alpha_cutoff: if cutoff.is_finite() { cutoff } else { 0.5 },
        })))
    }
}

/// A `KHR_texture_transform`: offset, rotation (radians) and scale.
#[derive(Clone, Copy, Debug, PartialEq)]
struct UvTransform {
    offset: [f32; 2],
    rotation: f32,
    scale: [f32; 2],
}

/// rt's sampler for a glTF sampler: its wraps and its magnification filter (rt has no mipmaps).
fn sampler_of(sampler: &gltf::texture::Sampler) -> TextureSampler {
    use gltf::texture::{MagFilter, WrappingMode};
    let wrap = |w: WrappingMode| match w {
        WrappingMode::ClampToEdge => Wrap::ClampToEdge,
        WrappingMode::MirroredRepeat => Wrap::MirroredRepeat,
        WrappingMode::Repeat => Wrap::Repeat,
    };
    TextureSampler {
        wrap_s: wrap(sampler.wrap_s()),
        wrap_t: wrap(sampler.wrap_t()),
        filter: match sampler.mag_filter() {
            Some(MagFilter::Nearest) => Filter::Nearest,
            _ => Filter::Linear,
        },
    }
}

fn decode_texture(bytes: &[u8]) -> std::result::Result<image::RgbaImage, String> {
    let reader = image::ImageReader::new(std::io::Cursor::new(bytes))
        .with_guessed_format()
        .map_err(|e| e.to_string())?;
    let (w, h) = reader
        .into_dimensions()
        .map_err(|e| format!("unreadable image: {e}"))?;
    let limit = crate::io::texture::MAX_TEXTURE_SIDE;
    if w > limit || h > limit {
        return Err(format!("{w}x{h}; the limit is {limit} per side"));
    }
    image::ImageReader::new(std::io::Cursor::new(bytes))
        .with_guessed_format()
        .map_err(|e| e.to_string())?
        .decode()
        .map(|i| i.to_rgba8())
        .map_err(|e| format!("unreadable image: {e}"))
}

/// The base colour texture's `KHR_texture_transform` (glTF's uv' = T·R·S·uv, in glTF's v-down
/// space), baked into the mesh's UVs: rt's textures share one UV set per mesh.
fn uv_transform_of(m: &gltf::Material) -> impl Fn([f32; 2]) -> [f32; 2] + use<> {
    let t = m
        .pbr_metallic_roughness()
        .base_color_texture()
        .and_then(|i| i.texture_transform())
        .map(|t| (t.offset(), t.rotation(), t.scale()));
    move |[u, v]| match t {
        Some((offset, rotation, scale))
            if offset.iter().chain(&scale).all(|x| x.is_finite()) && rotation.is_finite() =>
        {
            let (su, sv) = (u * scale[0], v * scale[1]);
            let (s, c) = rotation.sin_cos();
            [c * su + s * sv + offset[0], -s * su + c * sv + offset[1]]
        }
        _ => [u, v],
    }
}

/// rt's TRS of a node's world matrix (shear, which TRS cannot hold, is dropped).
fn transform_of(world: Mat4) -> Transform {
    let (scale, rotation, translation) = world.to_scale_rotation_translation();
    let (x, y, z) = rotation.to_euler(glam::EulerRot::XYZ);
    Transform {
        translation: translation.to_array(),
        rotation_deg: [x.to_degrees(), y.to_degrees(), z.to_degrees()],
        scale: scale.to_array(),
    }
}

/// Photometric glTF units to rt's radiometric ones at 683 lm/W (Blender's importer does the same).
pub const LUMENS_PER_WATT: f32 = 683.0;

fn light_of(light: &gltf::khr_lights_punctual::Light, world: Mat4, name: &str) -> Light {
    use gltf::khr_lights_punctual::Kind;
    let (kind, inner, outer) = match light.kind() {
        Kind::Directional => (LightKind::Directional, 0.0, 0.0),
        Kind::Point => (LightKind::Point, 0.0, 0.0),
        Kind::Spot {
            inner_cone_angle,
            outer_cone_angle,
        } => (LightKind::Spot, inner_cone_angle, outer_cone_angle),
    };
    let mut out = Light::new(kind, light.name().unwrap_or(name));
    out.position = world.transform_point3(Vec3::ZERO).to_array();
    out.direction = world
        .transform_vector3(Vec3::NEG_Z)
        .normalize_or(Vec3::NEG_Y)
        .to_array();
    out.color = light
        .color()
        .map(|c| if c.is_finite() { c.max(0.0) } else { 0.0 });
    let intensity = light.intensity();
    out.intensity = if intensity.is_finite() && intensity >= 0.0 {
        intensity / LUMENS_PER_WATT
    } else {
        0.0
    };
    if kind == LightKind::Spot {
        let outer = outer.clamp(0.0, std::f32::consts::FRAC_PI_2);
        out.outer_angle_deg = outer.to_degrees();
        out.inner_angle_deg = inner.clamp(0.0, outer).to_degrees();
        out.falloff = SpotFalloff::Gltf;
    }
    out
}
