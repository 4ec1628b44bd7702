//! File actions of the editor: opening scenes, lighting files and renders, starting a new scene,
//! saving the project or its lighting, and loading environment maps and textures into the scene;
//! with the editor's own defaults for a model it opens.

use std::path::Path;

use rt_core::{Material, Scene};
use rt_io::project::{self, LIGHTING_EXTENSION, Lighting, PROJECT_EXTENSION};
use rt_io::{LoadOptions, SceneFormat};

use super::RtApp;
use crate::document::{Document, Origin, recommended_max_depth};
use crate::render_job::RenderJob;

impl RtApp {
    /// Opens an OBJ, glTF, project or lighting file; on failure shows the error and keeps the scene.
    pub fn open_path(&mut self, path: &Path) -> bool {
        match self.try_open(path) {
            Ok(()) => {
                self.recent.add(path);
                self.ui.status = format!("opened {}", path.display());
                true
            }
            Err(e) => {
                self.show_error(format!("Could not open {}:\n{e:#}", path.display()));
                false
            }
        }
    }

    /// Lighting files and renders are not scenes and are handled here; every other file goes to
    /// the scene loader.
    fn try_open(&mut self, path: &Path) -> anyhow::Result<()> {
        let extension = path
            .extension()
            .and_then(|e| e.to_str())
            .map(str::to_ascii_lowercase)
            .unwrap_or_default();
        match extension.as_str() {
            e if e == LIGHTING_EXTENSION => {
                let lighting = project::load_lighting(path)?;
                self.doc
                    .edit("load lighting", "load lighting", |s| lighting.apply(s));
                self.doc.seal();
                self.selection = None;
            }
            "exr" => {
                let (image, aovs, what) = read_rendered_exr(path)?;
                self.add_render_view(RenderJob::finished(image, aovs, Some(what)));
            }
            _ => self.open_scene(path)?,
        }
        Ok(())
    }

    /// Opens a scene file with `rt_io::load`, the policy `rt-cli` shares, then adds the
    /// editor's own defaults for a model ([`apply_editor_defaults`]).
    fn open_scene(&mut self, path: &Path) -> anyhow::Result<()> {
        let Ok(format) = SceneFormat::of(path) else {
            anyhow::bail!(
                "unknown file type: rt opens scenes ({}), .{LIGHTING_EXTENSION} lighting files and \
                 .exr renders (into the viewer)",
                rt_io::scene_extensions_listed()
            );
        };
        let mut scene = rt_io::load(path, &LoadOptions::default())?;
        apply_editor_defaults(&mut scene, format);
        let origin = match format {
            SceneFormat::Project => Origin::Project(path.into()),
            SceneFormat::Obj | SceneFormat::Gltf | SceneFormat::Ply | SceneFormat::Stl => {
                Origin::Obj(path.into())
            }
        };
        self.replace_document(Document::new(scene, origin));
        Ok(())
    }

    fn replace_document(&mut self, doc: Document) {
        self.doc = doc;
        self.selection = None;
        self.selected_light = None;
        self.live.key = None;
    }

    /// Starts over with an empty scene, lit by the default environment.
    pub fn new_scene(&mut self) {
        let mut scene = Scene {
            ambient: [0.6; 3],
            ..Scene::default()
        };
        light_with_the_default_environment(&mut scene);
        self.replace_document(Document::new(scene, Origin::New));
    }

    /// Lights the scene with an environment map from `path` (keeping rotation and strength).
    pub fn set_environment_from_file(&mut self, path: &Path) -> bool {
        let map = match rt_core::environment::load_environment(path) {
            Ok(m) => m,
            Err(e) => {
                self.show_error(format!("Could not load the environment:\n{e}"));
                return false;
            }
        };
        let mut env = rt_core::Environment::new(path.display().to_string(), map);
        if let Some(old) = &self.doc.scene.environment {
            env.rotation_deg = old.rotation_deg;
            env.strength = old.strength;
        }
        self.doc.edit("set environment", "set environment", |s| {
            s.environment = Some(env)
        });
        self.doc.seal();
        true
    }

    /// Saves the project to `path` (atomically) and makes it the document's file.
    pub fn save_project_to(&mut self, path: &Path) -> bool {
        let mut path = path.to_path_buf();
        if path.extension().is_none() {
            path.set_extension(PROJECT_EXTENSION);
        }
        match project::save_project(&self.doc.scene, &path) {
            Ok(()) => {
                self.doc.mark_saved(Origin::Project(path.clone()));
                self.recent.add(&path);
                self.ui.status = format!("saved {}", path.display());
                true
            }
            Err(e) => {
                self.show_error(format!("Could not save the project:\n{e}"));
                false
            }
        }
    }

    pub fn save_lighting_to(&mut self, path: &Path) -> bool {
        let mut path = path.to_path_buf();
        if path.extension().is_none() {
            path.set_extension(LIGHTING_EXTENSION);
        }
        match project::save_lighting(&Lighting::of(&self.doc.scene), &path) {
            Ok(()) => {
                self.ui.status = format!("saved lighting to {}", path.display());
                true
            }
            Err(e) => {
                self.show_error(format!("Could not save the lighting:\n{e}"));
                false
            }
        }
    }

    /// Replaces a Lambertian object's texture with an image file (an undoable edit).
    pub fn set_texture_from_file(&mut self, object: usize, path: &Path) -> bool {
        let texture = match rt_io::texture::load_texture(path) {
            Ok(t) => t,
            Err(e) => {
                self.show_error(format!("Could not load the texture:\n{e}"));
                return false;
            }
        };
        self.doc.edit("set texture", "set texture", |scene| {
            let index = scene.textures.len();
            scene.textures.push(texture);
            if let Some(o) = scene.objects.get_mut(object) {
                match &mut o.material {
                    Material::Pbr(p) => p.texture = Some(index),
                    other => {
                        let albedo = match other {
                            Material::Lambertian { albedo, .. } => *albedo,
                            _ => [1.0; 3],
                        };
                        *other = Material::Lambertian {
                            albedo,
                            texture: Some(index),
                        };
                    }
                }
            }
        });
        self.doc.seal();
        true
    }
}

/// The editor's own choices for a model it opens, on top of `rt_io::load`'s policy: an OBJ,
/// PLY or STL that brings no light gets the studio environment (a glTF's loader decides its light itself), and
/// a model's max depth follows its materials ([`recommended_max_depth`]). They are the editor's,
/// not the shared policy, because they would change what `rt-cli render` makes of the same file
/// (there, `--environment default` and `--max-depth` choose). A project opens exactly as saved.
pub fn apply_editor_defaults(scene: &mut Scene, format: SceneFormat) {
    if format.is_bare_geometry() {
        light_with_the_default_environment(scene);
    }
    if format.is_model() {
        scene.settings.max_depth = recommended_max_depth(scene);
    }
}

/// A scene that brings no light of its own (no emitters, lights or environment) gets the studio
/// environment rt ships, as a user opening a bare model expects to see it lit.
pub fn light_with_the_default_environment(scene: &mut Scene) {
    if scene.has_emitters() || !scene.lights.is_empty() || scene.environment.is_some() {
        return;
    }
    match rt_io::assets::default_environment() {
        Ok(env) => scene.environment = Some(env),
        Err(e) => log::warn!("the built-in environment did not load: {e}"),
    }
}

/// An EXR for the viewer: a part or merged frame (`rt-cli render --shard`, `rt-cli merge`) with its
/// counts and denoiser guides, or any other EXR as plain colour; and what it is, for the window.
fn read_rendered_exr(path: &Path) -> anyhow::Result<(rt_gpu::Image, Option<rt_gpu::Aovs>, String)> {
    match rt_core::part::read_part(path) {
        Ok(part) => {
            let (image, aovs) = rt_gpu::Image::from_part(&part);
            let h = &part.header;
            let what = format!(
                "{} of {} samples from {}",
                rt_core::part::format_ranges(&h.sample_ranges),
                h.total_spp,
                path.display()
            );
            Ok((image, aovs, what))
        }
        Err(part_error) => {
            let plain = image::open(path)
                .map_err(|e| anyhow::anyhow!("{e} (and as a render part: {part_error})"))?;
            let rgb = plain.into_rgb32f();
            let (width, height) = rgb.dimensions();
            let pixels: Vec<[f32; 3]> = rgb.pixels().map(|p| p.0).collect();
            let what = format!("{} (colour only)", path.display());
            Ok((rt_gpu::Image::from_rgb(width, height, &pixels), None, what))
        }
    }
}
