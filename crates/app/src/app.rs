//! The editor's state and the actions on it. The panels in `ui/` draw this state and call these
//! actions; nothing here draws.

use std::path::{Path, PathBuf};
use std::sync::Arc;
use std::time::Duration;

use glam::Vec3;
use rt_core::io::project::{self, LIGHTING_EXTENSION, Lighting, PROJECT_EXTENSION};
use rt_core::{Material, Object, Scene, Transform};

use crate::document::{Document, Origin, recommended_max_depth};
use crate::recent::RecentFiles;
use crate::render_job::{JobOptions, JobState, RenderDevice, RenderJob};

/// Settings fixed when the editor starts.
#[derive(Clone, Debug, Default)]
pub struct AppOptions {
    /// Where the recent-files list lives; `None` keeps it in memory.
    pub config_dir: Option<PathBuf>,
    /// A file to open at start (OBJ, project or lighting).
    pub open: Option<PathBuf>,
    pub adapter: rt_gpu::AdapterChoice,
}

/// A finished or running render with its viewer's settings.
pub struct RenderView {
    pub id: u64,
    pub job: RenderJob,
    pub open: bool,
    pub exposure: f32,
    pub transform: rt_core::output::ViewTransform,
    pub zoom: f32,
    pub texture: Option<egui::TextureHandle>,
    /// (image revision, exposure, view transform, denoised) the texture was made from.
    pub texture_key: Option<(u64, f32, rt_core::output::ViewTransform, bool)>,
    /// Show (and save) the denoised image instead of the raw one.
    pub show_denoised: bool,
    /// The denoised image, computed on first use.
    pub denoised: Option<Vec<[f32; 3]>>,
    /// Which denoiser made `denoised`.
    pub denoiser: Option<&'static str>,
}

/// The path-traced viewport: its engine, what it was last asked for, and the texture it shows.
pub struct LiveViewport {
    pub enabled: bool,
    /// The engine's threads while the view is on (`rt_gpu::live`); dropped when it is turned off,
    /// which stops its work and frees its buffers.
    pub view: Option<rt_gpu::live::LiveView>,
    /// (document revision, viewport size) last sent to the view.
    pub key: Option<(u64, [u32; 2])>,
    /// Whether the user was dragging in the viewport at the last frame.
    pub interacting: bool,
    /// Show the denoised image (on by default); the raw one is a click away.
    pub show_denoised: bool,
    pub texture: Option<egui::TextureHandle>,
    /// (change, samples, pixel size, denoised) the texture was made from.
    pub texture_key: Option<(u64, u32, u32, bool)>,
}

impl Default for LiveViewport {
    fn default() -> Self {
        LiveViewport {
            enabled: false,
            view: None,
            key: None,
            interacting: false,
            show_denoised: true,
            texture: None,
            texture_key: None,
        }
    }
}

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum LightShape {
    Box,
    Quad,
}

/// Dialog and interaction state of the UI.
#[derive(Default)]
pub struct UiState {
    pub error: Option<String>,
    pub pending_delete: Option<usize>,
    /// Right-drag orbits around the selection instead of turning the camera in place.
    pub orbit_mode: bool,
    /// The next click in the viewport sets the focus distance.
    pub picking_focus: bool,
    pub status: String,
    pub last_render: Option<Duration>,
    /// A scripted session (`rt --interactive-bench`) is dragging in the viewport.
    pub scripted_drag: bool,
    /// The window title last sent.
    pub window_title: Option<String>,
}

pub struct RtApp {
    pub doc: Document,
    /// The selected object.
    pub selection: Option<usize>,
    /// The selected point, spot or directional light (exclusive with `selection`).
    pub selected_light: Option<usize>,
    pub device: RenderDevice,
    pub renders: Vec<RenderView>,
    pub live: LiveViewport,
    pub ui: UiState,
    pub recent: RecentFiles,
    /// Whether the raster preview's GPU resources exist (egui runs on wgpu).
    pub preview_available: bool,
    /// egui's own adapter, for the status bar until a render opens the render device.
    pub display_adapter: Option<String>,
    next_render_id: u64,
    repaint: Option<egui::Context>,
}

impl RtApp {
    /// An editor on the embedded Cornell box (or on `options.open`), without a window: the state
    /// the UI draws. `egui_ctx` lets render threads wake the UI.
    pub fn new(options: &AppOptions, egui_ctx: Option<egui::Context>) -> Self {
        let scene = rt_core::assets::cornell_box().unwrap_or_default();
        let mut app = RtApp {
            doc: Document::new(scene, Origin::Embedded),
            selection: None,
            selected_light: None,
            device: RenderDevice::new(options.adapter.clone()),
            renders: Vec::new(),
            live: LiveViewport::default(),
            ui: UiState::default(),
            recent: RecentFiles::load(options.config_dir.as_deref()),
            preview_available: false,
            display_adapter: None,
            next_render_id: 1,
            repaint: egui_ctx,
        };
        if let Some(path) = &options.open {
            app.open_path(path);
        }
        app
    }

    /// Creates the app inside eframe, installing the preview's GPU resources.
    pub fn from_creation_context(cc: &eframe::CreationContext<'_>, options: &AppOptions) -> Self {
        let mut app = RtApp::new(options, Some(cc.egui_ctx.clone()));
        if let Some(render_state) = &cc.wgpu_render_state {
            crate::preview::gpu::install(render_state);
            app.preview_available = true;
            let info = render_state.adapter.get_info();
            app.display_adapter = Some(rt_gpu::context::adapter_label(&info));
        }
        app
    }

    fn waker(&self) -> impl Fn() + Send + Sync + 'static {
        let ctx = self.repaint.clone();
        move || {
            if let Some(ctx) = &ctx {
                ctx.request_repaint();
            }
        }
    }

    pub fn show_error(&mut self, message: impl Into<String>) {
        let message = message.into();
        log::error!("{message}");
        self.ui.error = Some(message);
    }

    // ---- files -------------------------------------------------------------------------------

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

    fn try_open(&mut self, path: &Path) -> anyhow::Result<()> {
        let extension = path
            .extension()
            .and_then(|e| e.to_str())
            .map(str::to_ascii_lowercase)
            .unwrap_or_default();
        match extension.as_str() {
            e if e == PROJECT_EXTENSION => {
                let scene = project::load_project(path)?;
                self.replace_document(Document::new(scene, Origin::Project(path.into())));
            }
            e if e == LIGHTING_EXTENSION => {
                let lighting = project::load_lighting(path)?;
                self.doc
                    .edit("load lighting", "load lighting", |s| lighting.apply(s));
                self.doc.seal();
                self.selection = None;
            }
            "obj" => {
                let mut scene = rt_core::io::obj::load_obj(path, 0)?;
                scene.frame_for_viewing();
                light_with_the_default_environment(&mut scene);
                scene.settings.max_depth = recommended_max_depth(&scene);
                self.replace_document(Document::new(scene, Origin::Obj(path.into())));
            }
            "gltf" | "glb" => {
                let mut scene = rt_core::io::gltf::load_gltf(path, None)?;
                scene.settings.max_depth = recommended_max_depth(&scene);
                self.replace_document(Document::new(scene, Origin::Obj(path.into())));
            }
            "exr" => {
                let (image, aovs, what) = read_rendered_exr(path)?;
                self.add_render_view(RenderJob::finished(image, aovs, Some(what)));
            }
            _ => anyhow::bail!(
                "unknown file type: rt opens Wavefront .obj, glTF .gltf/.glb, .{PROJECT_EXTENSION} \
                 projects, .{LIGHTING_EXTENSION} lighting files and .exr renders (into the viewer)"
            ),
        }
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
        let texture = match rt_core::io::texture::load_texture(path) {
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

    // ---- editing -----------------------------------------------------------------------------

    pub fn undo(&mut self) {
        if self.doc.undo() {
            self.clamp_selection();
        }
    }

    pub fn redo(&mut self) {
        if self.doc.redo() {
            self.clamp_selection();
        }
    }

    fn clamp_selection(&mut self) {
        if self
            .selection
            .is_some_and(|s| s >= self.doc.scene.objects.len())
        {
            self.selection = None;
        }
        if self
            .selected_light
            .is_some_and(|s| s >= self.doc.scene.lights.len())
        {
            self.selected_light = None;
        }
    }

    pub fn select_object(&mut self, index: Option<usize>) {
        self.selection = index;
        self.selected_light = None;
    }

    pub fn select_light(&mut self, index: Option<usize>) {
        self.selected_light = index;
        self.selection = None;
    }

    /// Adds a point, spot or directional light, placed and sized for the scene, and selects it.
    /// Point and spot lights go above the scene's centre by its size, pointing down, with an
    /// intensity that lights the centre about as brightly as a sky of radiance 1 would.
    pub fn add_delta_light(&mut self, kind: rt_core::LightKind) {
        let (center, size) = match self.doc.bounds() {
            Some((lo, hi)) => ((lo + hi) * 0.5, (hi - lo).max_element().max(1e-3)),
            None => (Vec3::ZERO, 1.0),
        };
        let count = self
            .doc
            .scene
            .lights
            .iter()
            .filter(|l| l.kind == kind)
            .count();
        let name = match kind {
            rt_core::LightKind::Point => "point light",
            rt_core::LightKind::Spot => "spot light",
            rt_core::LightKind::Directional => "sun",
        };
        let mut light = rt_core::Light::new(kind, &format!("{name} {}", count + 1));
        light.position = (center + Vec3::Y * size * 0.45).to_array();
        // E = I/h² below the light; a sky of radiance 1 gives E = π.
        let h = size * 0.45;
        light.intensity = match kind {
            rt_core::LightKind::Directional => std::f32::consts::PI,
            _ => std::f32::consts::PI * h * h,
        };
        if kind == rt_core::LightKind::Directional {
            light.direction = Vec3::new(0.3, -1.0, 0.2).normalize().to_array();
        }
        self.doc
            .edit("add light", "add light", |s| s.lights.push(light));
        self.doc.seal();
        self.select_light(Some(self.doc.scene.lights.len() - 1));
    }

    pub fn delete_delta_light(&mut self, index: usize) {
        if index >= self.doc.scene.lights.len() {
            return;
        }
        self.doc.edit("delete light", "delete light", |s| {
            s.lights.remove(index);
        });
        self.doc.seal();
        self.selected_light = None;
    }

    /// Adds an emissive box or quad at the centre of the scene (the origin in an empty scene),
    /// sized to a tenth of the scene, and selects it.
    pub fn add_light(&mut self, shape: LightShape) {
        let (center, size) = match self.doc.bounds() {
            Some((lo, hi)) => ((lo + hi) * 0.5, (hi - lo).max_element().max(1e-3) * 0.1),
            None => (Vec3::ZERO, 1.0),
        };
        let (name, mesh) = match shape {
            // Unit shapes; the transform places and sizes them so the fields read naturally.
            LightShape::Box => (
                "box light",
                rt_core::shapes::cuboid(Vec3::splat(-0.5), Vec3::splat(0.5), false),
            ),
            // Facing down: a ceiling panel.
            LightShape::Quad => (
                "quad light",
                rt_core::shapes::quad(Vec3::ZERO, Vec3::NEG_Y, 1.0),
            ),
        };
        let count = self
            .doc
            .scene
            .objects
            .iter()
            .filter(|o| matches!(o.material, Material::Emissive { .. }))
            .count();
        let object = Object {
            name: format!("{name} {}", count + 1),
            mesh: Arc::new(mesh),
            material: Material::Emissive {
                color: [1.0; 3],
                intensity: 10.0,
            },
            transform: Transform {
                translation: center.to_array(),
                rotation_deg: [0.0; 3],
                scale: [size; 3],
            },
        };
        self.doc
            .edit("add light", "add light", |s| s.objects.push(object));
        self.doc.seal();
        self.select_object(Some(self.doc.scene.objects.len() - 1));
    }

    pub fn delete_object(&mut self, index: usize) {
        if index >= self.doc.scene.objects.len() {
            return;
        }
        self.doc.edit("delete object", "delete object", |s| {
            s.objects.remove(index);
        });
        self.doc.seal();
        self.selection = None;
    }

    /// Points the camera at the selection (or the whole scene), keeping the view direction.
    pub fn frame_selection(&mut self) {
        let bounds = match self.selection {
            Some(i) => crate::navigation::object_bounds(&self.doc.scene, i),
            None => self.doc.bounds(),
        };
        if let Some((lo, hi)) = bounds {
            self.doc.edit("frame selection", "frame selection", |s| {
                s.camera.frame_bounds(lo, hi)
            });
            self.doc.seal();
        }
    }

    pub fn reset_view(&mut self) {
        let camera = self.doc.initial_camera.clone();
        self.doc
            .edit("reset view", "reset view", |s| s.camera = camera);
        self.doc.seal();
    }

    // ---- rendering ---------------------------------------------------------------------------

    /// Starts a render of the scene with its settings; earlier results stay open.
    pub fn start_render(&mut self) -> Option<u64> {
        if let Err(e) = rt_core::frame::validate(&self.doc.scene) {
            self.show_error(format!("Cannot render: {e}"));
            return None;
        }
        let job = RenderJob::start(
            self.device.clone(),
            self.doc.scene.clone(),
            None,
            JobOptions {
                preview_every: Some(Duration::from_millis(500)),
                keep_aovs: true,
            },
            self.waker(),
        );
        Some(self.add_render_view(job))
    }

    /// Opens a viewer window on `job`; returns its id.
    fn add_render_view(&mut self, job: RenderJob) -> u64 {
        let id = self.next_render_id;
        self.next_render_id += 1;
        self.renders.push(RenderView {
            id,
            job,
            open: true,
            exposure: 0.0,
            transform: Default::default(),
            zoom: 1.0,
            texture: None,
            texture_key: None,
            show_denoised: false,
            denoised: None,
            denoiser: None,
        });
        id
    }

    pub fn cancel_renders(&mut self) {
        for r in &self.renders {
            r.job.cancel();
        }
    }

    pub fn is_rendering(&self) -> bool {
        self.renders.iter().any(|r| r.job.is_running())
    }

    /// Takes in progress from the render threads; called once per frame.
    pub fn poll_jobs(&mut self) {
        for r in &mut self.renders {
            let was_running = r.job.is_running();
            r.job.poll();
            if was_running && !r.job.is_running() {
                match &r.job.state {
                    JobState::Finished | JobState::Cancelled => {
                        self.ui.last_render = Some(r.job.progress.elapsed);
                    }
                    JobState::Failed(message) => {
                        self.ui.error = Some(format!("The render failed:\n{message}"));
                    }
                    JobState::Running => {}
                }
            }
        }
        self.renders.retain(|r| r.open || r.job.is_running());
        if let Some(view) = &mut self.live.view {
            view.tick();
            if let Some(message) = view.error() {
                let message = message.to_string();
                self.live.enabled = false;
                self.live.view = None;
                self.show_error(format!("The path-traced viewport stopped:\n{message}"));
            }
        }
    }

    /// Keeps the path-traced viewport in step with the scene, the viewport's size and whether the
    /// user is dragging (the view then stays at its coarse step); starts and stops its threads.
    pub fn update_live_view(&mut self, size: [u32; 2], interacting: bool) {
        if !self.live.enabled {
            self.live.view = None;
            self.live.key = None;
            self.live.texture = None;
            self.live.texture_key = None;
            return;
        }
        let waker = self.waker();
        let device = self.device.clone();
        let view = self.live.view.get_or_insert_with(|| {
            rt_gpu::live::LiveView::start(
                move || device.get().map_err(|e| format!("{e:#}")),
                rt_gpu::live::LiveSettings::default(),
                waker,
            )
        });
        view.show_denoised = self.live.show_denoised;
        let key = (self.doc.revision(), size);
        if self.live.key == Some(key) {
            if interacting != self.live.interacting {
                view.set_interacting(interacting);
                self.live.interacting = interacting;
            }
            return;
        }
        let mut scene = self.doc.scene.clone();
        scene.settings.width = size[0].max(1);
        scene.settings.height = size[1].max(1);
        if rt_core::frame::validate(&scene).is_err() {
            return;
        }
        self.live.key = Some(key);
        self.live.interacting = interacting;
        view.request(rt_gpu::live::LiveRequest {
            scene,
            size,
            interacting,
        });
    }

    pub fn adapter_label(&self) -> String {
        self.device
            .adapter_label()
            .or_else(|| self.display_adapter.clone())
            .unwrap_or_else(|| "no adapter yet".into())
    }
}

impl RenderView {
    /// The exposure and view transform the viewer shows and saves with.
    pub fn view(&self) -> rt_core::output::View {
        rt_core::output::View {
            transform: self.transform,
            exposure_stops: self.exposure,
        }
    }
}

/// A scene that brings no light of its own (no emitters, lights or environment) gets the studio
/// environment rt ships, as a user opening a bare model expects to see it lit.
pub fn light_with_the_default_environment(scene: &mut Scene) {
    if scene.has_emitters() || !scene.lights.is_empty() || scene.environment.is_some() {
        return;
    }
    match rt_core::assets::default_environment() {
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
