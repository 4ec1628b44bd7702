//! One window per render: progress and Cancel while it runs, then the image with zoom, pan, an
//! exposure slider and Save as PNG / JPEG / PPM / EXR.

use rt_core::output::{View, ViewTransform};
use rt_gpu::Image;

use crate::app::{RenderView, RtApp};
use crate::render_job::JobState;

/// The image as 8-bit sRGB for display through `view` (exposure and view transform, as the
/// PNG output).
pub fn tone_mapped(image: &Image, view: impl Into<View>) -> egui::ColorImage {
    tone_mapped_rgb(&image.rgb(), image.width, image.height, view)
}

pub fn tone_mapped_rgb(
    rgb: &[[f32; 3]],
    width: u32,
    height: u32,
    view: impl Into<View>,
) -> egui::ColorImage {
    let bytes = view.into().to_rgba8(rgb);
    egui::ColorImage::from_rgba_unmultiplied([width as usize, height as usize], &bytes)
}

/// A transparent film's render (`rgb` premultiplied by `alpha`) over a grey checkerboard, as
/// Blender shows one: where a shadow catcher or the background lets the board show through.
pub fn over_checkerboard(
    rgb: &[[f32; 3]],
    alpha: &[f32],
    width: u32,
    height: u32,
    view: View,
) -> egui::ColorImage {
    let mut bytes = Vec::with_capacity(rgb.len() * 4);
    for (i, (&c, &a)) in rgb.iter().zip(alpha).enumerate() {
        let (x, y) = (i as u32 % width.max(1), i as u32 / width.max(1));
        let board: f32 = if (x / 8 + y / 8) % 2 == 0 {
            102.0
        } else {
            153.0
        };
        let [r, g, b, a8] = view.straight_rgba8(c, a);
        let a = f32::from(a8) / 255.0;
        let blend = |v: u8| (f32::from(v) * a + board * (1.0 - a) + 0.5) as u8;
        bytes.extend([blend(r), blend(g), blend(b), 255]);
    }
    egui::ColorImage::from_rgba_unmultiplied([width as usize, height as usize], &bytes)
}

/// The denoised image of a finished render (computed once).
fn denoised(view: &mut RenderView) -> Option<&Vec<[f32; 3]>> {
    if view.denoised.is_none() {
        let (image, aovs) = (view.job.image.as_ref()?, view.job.aovs.as_ref()?);
        let result = image
            .denoised(aovs, rt_core::denoiser::DenoiserChoice::Auto)
            .ok()?;
        view.denoiser = Some(result.denoiser.name());
        view.denoised = Some(result.pixels);
    }
    view.denoised.as_ref()
}

pub fn render_windows(app: &mut RtApp, ctx: &egui::Context) {
    let mut errors = Vec::new();
    for view in &mut app.renders {
        let mut open = view.open;
        let title = format!(
            "Render {} — {}×{}",
            view.id, view.job.scene.settings.width, view.job.scene.settings.height
        );
        egui::Window::new(title)
            .id(egui::Id::unique(("render", view.id)))
            .open(&mut open)
            .default_size([520.0, 560.0])
            .resizable(true)
            .show(ctx, |ui| {
                if let Some(e) = render_window(view, ui) {
                    errors.push(e);
                }
            });
        if !open {
            view.job.cancel();
        }
        view.open = open;
    }
    if let Some(e) = errors.pop() {
        app.show_error(e);
    }
}

/// Draws one render's window; returns an error message to show, if any.
fn render_window(view: &mut RenderView, ui: &mut egui::Ui) -> Option<String> {
    job_status(view, ui);
    display_controls(view, ui);
    let error = save_row(view, ui);
    if view.show_denoised && view.job.aovs.is_some() {
        let _ = denoised(view);
    }
    render_image(view, ui);
    error
}

/// The job's progress (with Cancel) or how it ended.
fn job_status(view: &mut RenderView, ui: &mut egui::Ui) {
    let p = view.job.progress;
    match &view.job.state {
        JobState::Running => {
            ui.horizontal(|ui| {
                let eta = p.eta().map_or("estimating…".to_string(), |d| {
                    format!("{:.0} s left", d.as_secs_f32())
                });
                ui.add(
                    egui::ProgressBar::new(p.fraction())
                        .desired_width(260.0)
                        .text(format!("{}/{} spp, {eta}", p.samples_done, p.samples_total)),
                );
                if ui
                    .button("Cancel")
                    .on_hover_text("Stop and keep the samples so far")
                    .clicked()
                {
                    view.job.cancel();
                }
            });
        }
        JobState::Finished | JobState::Cancelled => {
            let what = if view.job.state == JobState::Cancelled {
                "cancelled at"
            } else {
                "done:"
            };
            let noise = p
                .noise
                .map_or(String::new(), |n| format!(", noise ~{:.1}%", n * 100.0));
            ui.label(format!(
                "{what} {} spp in {:.2} s{noise}",
                p.samples_done,
                p.elapsed.as_secs_f32()
            ));
        }
        JobState::Failed(message) => {
            // What was read back before the failure can still be looked at and saved.
            ui.colored_label(
                egui::Color32::LIGHT_RED,
                format!("failed after {} spp: {message}", p.samples_done),
            );
        }
    }
}

/// Exposure, view transform, white balance, zoom and the denoised toggle.
fn display_controls(view: &mut RenderView, ui: &mut egui::Ui) {
    ui.horizontal(|ui| {
        ui.add(egui::Slider::new(&mut view.exposure, -8.0..=8.0).text("exposure (stops)"))
            .on_hover_text("Brighten or darken the display and the PNG/JPEG/PPM you save");
        egui::ComboBox::from_id_salt(("view transform", view.id))
            .selected_text(view.transform.label())
            .show_ui(ui, |ui| {
                for (transform, hint) in [
                    (
                        ViewTransform::Standard,
                        "Clamp at 1: exact colours, clipped highlights",
                    ),
                    (
                        ViewTransform::KhronosPbrNeutral,
                        "Highlights roll off to white; colours below 0.76 are kept",
                    ),
                    (
                        ViewTransform::Agx,
                        "Blender's default: wide latitude, highlights desaturate towards white",
                    ),
                ] {
                    ui.selectable_value(&mut view.transform, transform, transform.label())
                        .on_hover_text(hint);
                }
            })
            .response
            .on_hover_text("How radiance becomes display colours (EXR saves stay linear)");
        white_balance_control(ui, &mut view.white_balance_k);
        ui.add(
            egui::Slider::new(&mut view.zoom, 0.1..=8.0)
                .logarithmic(true)
                .text("zoom"),
        )
        .on_hover_text("Zoom; drag the scroll bars (or scroll) to pan");
        if view.job.aovs.is_some() {
            let label = match view.denoiser.filter(|_| view.show_denoised) {
                Some(name) => format!("denoised ({name})"),
                None => "denoised".to_string(),
            };
            ui.checkbox(&mut view.show_denoised, label).on_hover_text(
                "Show and save the denoised image (smoother, slightly biased): Open Image Denoise \
                 where it is installed (scripts/ensure-oidn), else rt's À-Trous filter; the raw \
                 render is kept",
            );
        }
    });
}

/// "Save as…" and the passes an EXR carries, once the render has stopped; an error message where
/// saving failed.
fn save_row(view: &mut RenderView, ui: &mut egui::Ui) -> Option<String> {
    let mut error = None;
    if view.job.image.is_some() && !view.job.is_running() {
        ui.horizontal(|ui| {
            if ui
                .button("Save as…")
                .on_hover_text("PNG, JPEG or PPM (8-bit, with the exposure) or EXR (linear HDR)")
                .clicked()
                && let Some(path) = rfd::FileDialog::new()
                    .add_filter("PNG", &["png"])
                    .add_filter("JPEG", &["jpg", "jpeg"])
                    .add_filter("PPM", &["ppm"])
                    .add_filter("OpenEXR (HDR)", &["exr"])
                    .set_file_name(format!("render-{}.png", view.id))
                    .save_file()
                && let Err(e) = save(view, &path)
            {
                error = Some(format!("Could not save the image:\n{e}"));
            }
            if view.job.aovs.is_some() {
                pass_choice(ui, &mut view.passes);
            }
        });
    }
    error
}

/// The image as displayed (re-tone-mapped only when its settings change), or a spinner until the
/// first one arrives.
fn render_image(view: &mut RenderView, ui: &mut egui::Ui) {
    if let Some(image) = &view.job.image {
        let show_denoised = view.show_denoised && view.denoised.is_some();
        let key = (
            view.job.image_revision,
            view.exposure,
            view.transform,
            view.white_balance_k,
            show_denoised,
        );
        if view.texture_key != Some(key) {
            let rgb = match (&view.denoised, show_denoised) {
                (Some(d), true) => d.clone(),
                _ => image.rgb(),
            };
            let alpha = view
                .job
                .aovs
                .as_ref()
                .filter(|_| view.job.scene.settings.transparent)
                .map(|a| a.hits.alphas())
                .filter(|a| a.len() == rgb.len());
            let (w, h) = (image.width, image.height);
            let color = match alpha {
                Some(alpha) => over_checkerboard(&rgb, &alpha, w, h, view.view()),
                None => tone_mapped_rgb(&rgb, w, h, view.view()),
            };
            match &mut view.texture {
                Some(t) => t.set(color, egui::TextureOptions::NEAREST),
                None => {
                    view.texture = Some(ui.ctx().load_texture(
                        format!("render {}", view.id),
                        color,
                        egui::TextureOptions::NEAREST,
                    ))
                }
            }
            view.texture_key = Some(key);
        }
        if let Some(texture) = &view.texture {
            let size = egui::vec2(image.width as f32, image.height as f32) * view.zoom;
            egui::ScrollArea::both().show(ui, |ui| {
                ui.add(egui::Image::new((texture.id(), size)));
            });
        }
    } else {
        ui.spinner();
    }
}

/// Which render passes an EXR saved from the window carries (as `rt-cli --aov`).
fn pass_choice(ui: &mut egui::Ui, passes: &mut Vec<rt_core::passes::Pass>) {
    let label = match passes.len() {
        0 => "Passes".to_string(),
        n => format!("Passes ({n})"),
    };
    ui.menu_button(label, |ui| {
        for pass in rt_core::passes::Pass::ALL {
            let mut on = passes.contains(&pass);
            if ui.checkbox(&mut on, pass.name()).changed() {
                passes.retain(|p| *p != pass);
                if on {
                    passes.push(pass);
                }
            }
        }
    })
    .response
    .on_hover_text(
        "Render passes saved as layers of an EXR beside the image, as Blender names them: depth, \
         normal, albedo, position, object and material ids, and Cryptomatte's object mattes",
    );
}

/// The layers of the passes the view asks for (`rt_core::passes`), from the render's first hits,
/// and the header metadata Cryptomatte's need.
type PassLayers = (
    Vec<rt_core::output::ExrChannel>,
    Vec<rt_core::output::ExrAttribute>,
);

fn pass_layers(view: &RenderView) -> rt_core::Result<PassLayers> {
    let (job, passes) = (&view.job, &view.passes);
    let Some(aovs) = job.aovs.as_ref().filter(|_| !passes.is_empty()) else {
        return Ok(Default::default());
    };
    use rt_core::passes::Pass;
    let needs_scene = passes.contains(&Pass::Position) || passes.contains(&Pass::Cryptomatte);
    let built;
    let gpu_scene = match (&job.gpu_scene, needs_scene) {
        (Some(g), _) => Some(g.as_ref()),
        (None, true) => {
            built = rt_core::GpuScene::build(&job.scene)?;
            Some(&built)
        }
        (None, false) => None,
    };
    let position = match gpu_scene.filter(|_| passes.contains(&Pass::Position)) {
        Some(gpu_scene) => {
            let frame = rt_core::frame::frame_for(&job.scene, gpu_scene)?;
            rt_core::passes::positions(&frame, &aovs.hits)
        }
        None => Vec::new(),
    };
    let material_ids = rt_core::passes::material_ids(&job.scene);
    let inputs = rt_core::passes::PassInputs {
        albedo: &aovs.albedo,
        normal: &aovs.normal,
        hits: &aovs.hits,
        position: &position,
        material_ids: &material_ids,
    };
    let mut channels = rt_core::passes::pass_channels(passes, &inputs);
    let mut metadata = Vec::new();
    if let (Some(gpu_scene), Some(image)) = (gpu_scene, &job.image) {
        let samples = image.samples_per_pixel;
        let (crypto, meta) =
            rt_core::passes::cryptomatte_layers(passes, &job.scene, gpu_scene, samples)?;
        channels.extend(crypto);
        metadata = meta;
    }
    Ok((channels, metadata))
}

/// Saves the view's image; the format follows the extension.
pub fn save(view: &RenderView, path: &std::path::Path) -> rt_core::Result<()> {
    let Some(image) = &view.job.image else {
        return Err(rt_core::Error::Scene("nothing rendered yet".into()));
    };
    if view.show_denoised
        && let Some(denoised) = &view.denoised
    {
        return rt_core::output::save_image(path, image.width, image.height, denoised, view.view());
    }
    let format = rt_core::output::ImageFormat::from_path(path)?;
    let (passes, metadata) = match format {
        rt_core::output::ImageFormat::Exr => pass_layers(view)?,
        _ => Default::default(),
    };
    let alpha = view.job.aovs.as_ref().map(|a| a.hits.alphas());
    let size = [image.width, image.height];
    if view.job.scene.settings.transparent
        && let Some(alpha) = alpha.filter(|c| c.len() == image.pixels.len())
    {
        let bytes = rt_core::output::encode_with_alpha(
            format,
            size,
            &image.pixels,
            image.counts(),
            &alpha,
            (&passes, &metadata),
            view.view(),
        )?;
        return rt_core::output::write_atomically(path, &bytes);
    }
    if !passes.is_empty() {
        let [w, h] = size;
        let counts = image.counts();
        let bytes =
            rt_core::output::encode_exr_layers(w, h, &image.pixels, counts, &passes, &metadata)?;
        return rt_core::output::write_atomically(path, &bytes);
    }
    rt_core::output::save_render(
        path,
        image.width,
        image.height,
        &image.pixels,
        image.counts(),
        view.view(),
    )
}

/// A white balance: off, or the colour temperature (kelvin) of the light that should look white.
fn white_balance_control(ui: &mut egui::Ui, kelvin: &mut Option<f32>) {
    let mut on = kelvin.is_some();
    if ui
        .checkbox(&mut on, "white balance")
        .on_hover_text("Make light of a colour temperature look white (display and PNG/JPEG only)")
        .changed()
    {
        *kelvin = on.then_some(rt_core::display::NEUTRAL_KELVIN);
    }
    if let Some(k) = kelvin {
        ui.add(
            egui::DragValue::new(k)
                .range(1667.0..=25000.0)
                .speed(20.0)
                .suffix(" K"),
        )
        .on_hover_text("3200 K neutralises tungsten light; 6500 K changes nothing");
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A transparent render shows over a checkerboard: the board where alpha is 0, the colour as
    /// the opaque view shows it where alpha is 1.
    #[test]
    fn transparent_renders_show_over_a_checkerboard() {
        let view = View::default();
        let rgb = [[0.5, 0.25, 0.1], [0.0; 3], [0.0; 3]];
        let shown = over_checkerboard(&rgb, &[1.0, 0.0, 0.0], 3, 1, view);
        let opaque = tone_mapped_rgb(&rgb, 3, 1, view);
        assert_eq!(shown.pixels[0], opaque.pixels[0]);
        assert_eq!(shown.pixels[1], egui::Color32::from_gray(102));
        let far = over_checkerboard(&[[0.0; 3]; 9], &[0.0; 9], 9, 1, view);
        assert_eq!(
            far.pixels[8],
            egui::Color32::from_gray(153),
            "the next square"
        );
    }

    /// A render of a transparent scene saves its alpha: PNG RGBA with straight colour, EXR with
    /// an `A` channel; an opaque one saves RGB as before.
    #[test]
    fn transparent_renders_save_their_alpha() {
        let image = rt_gpu::Image::from_rgb(2, 1, &[[0.25, 0.25, 0.25], [0.0; 3]]);
        let aovs = rt_gpu::Aovs {
            hits: rt_core::first_hits::FirstHits {
                coverage: vec![0.5, 0.0],
                ..rt_core::first_hits::FirstHits::new(2)
            },
            ..Default::default()
        };
        let mut job = crate::render_job::RenderJob::finished(image, Some(aovs), None);
        job.scene.settings.transparent = true;
        let view = RenderView::new(1, job);
        let dir = std::env::temp_dir().join(format!("rt-alpha-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let png = dir.join("a.png");
        save(&view, &png).unwrap();
        let read = image::open(&png).unwrap().to_rgba8();
        // 0.25 premultiplied by alpha 0.5 is 0.5 straight: sRGB 188.
        assert_eq!(read.get_pixel(0, 0).0, [188, 188, 188, 128]);
        assert_eq!(read.get_pixel(1, 0).0[3], 0);
        let exr = dir.join("a.exr");
        save(&view, &exr).unwrap();
        let read = image::open(&exr).unwrap().to_rgba32f();
        assert_eq!(read.get_pixel(0, 0).0, [0.25, 0.25, 0.25, 0.5]);
        std::fs::remove_dir_all(&dir).unwrap();
    }
}
