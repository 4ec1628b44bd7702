//! The editor's state and the actions on it. The panels in `ui/` draw this state and call these
//! actions; nothing here draws. The state is here; the actions on it are grouped by what they do:
//! `files.rs` (open, save, load), `edit.rs` (undoable edits and selection) and `rendering.rs`
//! (render jobs and the path-traced viewport).

mod edit;
mod files;
mod rendering;
pub mod transform_tool;

use std::path::PathBuf;
use std::time::Duration;

use crate::document::{Document, Origin};
use crate::recent::RecentFiles;
use crate::render_job::{RenderDevice, RenderJob};

pub use files::{apply_editor_defaults, light_with_the_default_environment};

/// Settings fixed when the editor starts.
#[derive(Clone, Debug, Default)]
pub struct AppOptions {
    /// Where the recent-files list lives; `None` keeps it in memory.
    pub config_dir: Option<PathBuf>,
    /// A file to open at start (OBJ, project or lighting).
    pub open: Option<PathBuf>,
    pub adapter: rt_gpu::AdapterChoice,
    /// How to open the render device (`launch` fills it from `RT_NO_RAY_QUERY`).
    pub device: rt_gpu::DeviceOptions,
    /// Which backend renders the render windows at start (the Render panel's Device).
    pub render_device: crate::render_job::DeviceChoice,
}

/// A finished or running render with its viewer's settings.
pub struct RenderView {
    pub id: u64,
    pub job: RenderJob,
    pub open: bool,
    pub exposure: f32,
    pub transform: rt_core::output::ViewTransform,
    /// The white balance's temperature (kelvin), if any.
    pub white_balance_k: Option<f32>,
    pub zoom: f32,
    pub texture: Option<egui::TextureHandle>,
    /// (image revision, exposure, view transform, white balance, denoised) the texture was made
    /// from.
    pub texture_key: Option<(u64, f32, rt_core::output::ViewTransform, Option<f32>, bool)>,
    /// Show (and save) the denoised image instead of the raw one.
    pub show_denoised: bool,
    /// The denoised image, computed on first use.
    pub denoised: Option<Vec<[f32; 3]>>,
    /// Which denoiser made `denoised`.
    pub denoiser: Option<&'static str>,
    /// The render passes an EXR saved from this window carries as layers (as `rt-cli --aov`).
    pub passes: Vec<rt_core::passes::Pass>,
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
    /// Whether the running view traces on the CPU backend (a change of the Render panel's Device
    /// restarts it).
    pub on_cpu: bool,
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
            on_cpu: false,
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
    /// Which backend renders the render windows (the Render panel's "Device").
    pub render_device: crate::render_job::DeviceChoice,
    /// The window of the image the render windows render, `[x0, y0, x1, y1)` in pixels (the
    /// Render panel's "Region", Blender's render region): a choice of this session, not the
    /// scene's.
    pub render_region: Option<[u32; 4]>,
    /// Where the viewport was last drawn (screen points), for what places things in it.
    pub viewport_rect: Option<egui::Rect>,
}

pub struct RtApp {
    pub doc: Document,
    /// The selected object.
    pub selection: Option<usize>,
    /// The selected point, spot or directional light (exclusive with `selection`).
    pub selected_light: Option<usize>,
    /// A G/R/S gesture in progress (`transform_tool`).
    pub tool: Option<transform_tool::TransformTool>,
    /// The presets' thumbnails (rendered when the gallery is first shown).
    pub gallery: crate::gallery::Gallery,
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
        let scene = rt_io::assets::cornell_box().unwrap_or_default();
        let mut app = RtApp {
            doc: Document::new(scene, Origin::Embedded),
            selection: None,
            selected_light: None,
            tool: None,
            gallery: Default::default(),
            device: RenderDevice::new(options.adapter.clone(), options.device),
            renders: Vec::new(),
            live: LiveViewport::default(),
            ui: UiState {
                render_device: options.render_device,
                ..UiState::default()
            },
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
            crate::preview::install(render_state);
            app.preview_available = true;
            let info = render_state.adapter.get_info();
            app.display_adapter = Some(rt_gpu::context::adapter_label(&info));
            let live_on_cpu = app.ui.render_device.on_cpu(false).0;
            app.live.enabled = opens_path_traced(info.device_type, live_on_cpu);
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

    pub fn adapter_label(&self) -> String {
        self.device
            .adapter_label()
            .or_else(|| self.display_adapter.clone())
            .unwrap_or_else(|| "no adapter yet".into())
    }
}

/// Whether the viewport opens path-traced: on a discrete GPU, whose first image takes a few
/// milliseconds, and wherever the path-traced view runs on the CPU backend (`live_on_cpu`: no
/// hardware GPU, or the CPU chosen), which answers a change in ~20 ms at its coarsest step and
/// shows the render's light where the raster preview guesses it; an integrated GPU or lavapipe
/// tracing the view opens on the raster preview, which answers at once there (P switches either
/// way).
pub fn opens_path_traced(device_type: wgpu::DeviceType, live_on_cpu: bool) -> bool {
    device_type == wgpu::DeviceType::DiscreteGpu || live_on_cpu
}

impl RenderView {
    /// A viewer of `job` as it opens: exposure 0, the standard view, no white balance, 1:1.
    pub fn new(id: u64, job: RenderJob) -> Self {
        RenderView {
            id,
            job,
            open: true,
            exposure: 0.0,
            transform: Default::default(),
            white_balance_k: None,
            zoom: 1.0,
            texture: None,
            texture_key: None,
            show_denoised: false,
            denoised: None,
            denoiser: None,
            passes: Vec::new(),
        }
    }

    /// The exposure and view transform the viewer shows and saves with.
    pub fn view(&self) -> rt_core::output::View {
        rt_core::output::View {
            transform: self.transform,
            exposure_stops: self.exposure,
            white_balance_k: self.white_balance_k,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn discrete_gpus_and_the_cpu_backend_open_the_viewport_path_traced() {
        let others = [
            wgpu::DeviceType::IntegratedGpu,
            wgpu::DeviceType::Cpu,
            wgpu::DeviceType::VirtualGpu,
            wgpu::DeviceType::Other,
        ];
        assert!(opens_path_traced(wgpu::DeviceType::DiscreteGpu, false));
        for other in others {
            assert!(
                !opens_path_traced(other, false),
                "{other:?} tracing the view"
            );
            assert!(
                opens_path_traced(other, true),
                "{other:?} with the CPU backend"
            );
        }
    }
}
