//! The Render panel: image size, samples, depth, sampling options, and starting, cancelling and
//! following renders.

use egui::{DragValue, Ui};

use crate::app::RtApp;

/// A setting that is off (`None`) or a number: a checkbox, and the value beside it when on.
struct OptionalSetting {
    label: &'static str,
    tip: &'static str,
    value_tip: &'static str,
    /// The value when the checkbox turns it on.
    default: f32,
    speed: f64,
    range: std::ops::RangeInclusive<f32>,
}

fn optional_setting(ui: &mut Ui, value: &mut Option<f32>, setting: OptionalSetting) {
    ui.horizontal(|ui| {
        let mut on = value.is_some();
        if ui
            .checkbox(&mut on, setting.label)
            .on_hover_text(setting.tip)
            .changed()
        {
            *value = on.then_some(setting.default);
        }
        if let Some(v) = value {
            ui.add(DragValue::new(v).speed(setting.speed).range(setting.range))
                .on_hover_text(setting.value_tip);
        }
    });
}

pub fn render_panel(app: &mut RtApp, ui: &mut Ui) {
    ui.heading("Render");
    device_choice(app, ui);
    let mut settings = app.doc.scene.settings.clone();
    egui::Grid::new("render settings").show(ui, |ui| {
        ui.label("Width");
        ui.add(DragValue::new(&mut settings.width).range(1..=rt_core::scene::MAX_IMAGE_SIDE))
            .on_hover_text("Image width in pixels");
        ui.end_row();
        ui.label("Height");
        ui.add(DragValue::new(&mut settings.height).range(1..=rt_core::scene::MAX_IMAGE_SIDE))
            .on_hover_text("Image height in pixels");
        ui.end_row();
        ui.label("Samples/pixel");
        ui.add(DragValue::new(&mut settings.samples_per_pixel).range(1..=1_000_000))
            .on_hover_text("More samples, less noise: noise falls as 1/sqrt(samples)");
        ui.end_row();
        ui.label("Max depth");
        ui.add(DragValue::new(&mut settings.max_depth).range(0..=64))
            .on_hover_text("Ray segments per path: ~5 for diffuse scenes, ~10 with metal or glass");
        ui.end_row();
    });
    if app.doc.has_metal_or_glass() && settings.max_depth < 10 {
        ui.weak("Metal or glass in the scene: a max depth of 10 is recommended.");
    }
    integrator_choice(ui, &mut settings.integrator);
    ui.checkbox(&mut settings.next_event_estimation, "Light sampling (NEE)")
        .on_hover_text("Sample lights directly: far less noise with small lights");
    ui.checkbox(&mut settings.russian_roulette, "Russian roulette")
        .on_hover_text("End dim paths early at random (unbiased, faster)");
    ui.checkbox(&mut settings.transparent, "Transparent background")
        .on_hover_text(
            "Leave the background out of the image (it still lights the scene) and save PNG or \
             EXR with alpha, as Cycles' Film > Transparent",
        );
    ui.horizontal(|ui| {
        use rt_core::math::rng::SamplerKind;
        ui.label("Sampler")
            .on_hover_text("Where the random numbers come from");
        ui.selectable_value(
            &mut settings.sampler,
            SamplerKind::Independent,
            "Independent",
        )
        .on_hover_text("Independent random numbers (PCG)");
        ui.selectable_value(&mut settings.sampler, SamplerKind::Sobol, "Sobol")
            .on_hover_text(
                "Owen-scrambled Sobol points: evenly spread samples, less noise on smooth lighting",
            );
    });
    optional_setting(
        ui,
        &mut settings.clamp,
        OptionalSetting {
            label: "Firefly clamp",
            tip: "Limit each sample's brightness: removes bright speckles at the cost of some \
                  energy (biased; off by default)",
            value_tip: "The most any bounce of light may contribute per colour channel",
            default: 10.0,
            speed: 0.1,
            range: 0.01..=1e6,
        },
    );
    optional_setting(
        ui,
        &mut settings.adaptive_threshold,
        OptionalSetting {
            label: "Adaptive sampling",
            tip: "Stop sampling pixels whose noise is already low (after 64 samples), so the \
                  samples go where the noise is",
            value_tip: "The noise at which a pixel stops: the square root of its relative \
                        mean squared error, e.g. 0.02",
            default: 0.02,
            speed: 0.001,
            range: 0.001..=1.0,
        },
    );
    let size = [settings.width, settings.height];
    if settings != app.doc.scene.settings {
        app.doc.edit("change render settings", "settings", |s| {
            s.settings = settings
        });
    }
    region_choice(ui, &mut app.ui.render_region, size);
    ui.horizontal(|ui| {
        if ui
            .button("Render image")
            .on_hover_text("Render an image on a background thread (F12)")
            .clicked()
        {
            app.start_render();
        }
        if ui
            .add_enabled(app.is_rendering(), egui::Button::new("Cancel render"))
            .on_hover_text("Stop rendering and keep the samples so far (Esc)")
            .clicked()
        {
            app.cancel_renders();
        }
    });
    for r in app.renders.iter().filter(|r| r.job.is_running()) {
        let p = r.job.progress;
        let eta = p.eta().map_or("…".to_string(), |d| {
            format!("{:.0} s left", d.as_secs_f32())
        });
        let noise = p
            .noise
            .map_or(String::new(), |n| format!(", noise {:.1}%", n * 100.0));
        ui.add(egui::ProgressBar::new(p.fraction()).text(format!(
            "{}/{} spp, {eta}{noise}",
            p.samples_done, p.samples_total
        )))
        .on_hover_text("Samples per pixel done, estimated time left and relative noise");
    }
}

/// The render region (Blender's): render windows then render only that window of the image,
/// `[x0, y0, x1, y1)` in pixels, kept inside the image.
fn region_choice(ui: &mut Ui, region: &mut Option<[u32; 4]>, [width, height]: [u32; 2]) {
    ui.horizontal(|ui| {
        let mut on = region.is_some();
        if ui
            .checkbox(&mut on, "Region")
            .on_hover_text(
                "Render only a window of the image (pixels from the top left; the right and \
                 bottom edges excluded): its pixels are those the whole image would have",
            )
            .changed()
        {
            *region = on.then_some([width / 4, height / 4, width * 3 / 4, height * 3 / 4]);
        }
        if let Some([x0, y0, x1, y1]) = region.as_mut() {
            *x1 = (*x1).clamp(1, width.max(1));
            *y1 = (*y1).clamp(1, height.max(1));
            ui.add(DragValue::new(x0).range(0..=*x1 - 1).prefix("x "));
            ui.add(DragValue::new(y0).range(0..=*y1 - 1).prefix("y "));
            ui.add(DragValue::new(x1).range(*x0 + 1..=width).prefix("to x "));
            ui.add(DragValue::new(y1).range(*y0 + 1..=height).prefix("y "));
        }
    });
}

/// How the render windows gather light: path tracing, or bidirectional path tracing for caustics.
fn integrator_choice(ui: &mut Ui, integrator: &mut rt_core::Integrator) {
    use rt_core::Integrator;
    ui.horizontal(|ui| {
        ui.label("Light paths")
            .on_hover_text("How light is found: from the camera, or from the camera and the lights");
        ui.selectable_value(integrator, Integrator::Path, "Path tracing")
            .on_hover_text("Paths from the camera, lights sampled at each bounce: fast, the default");
        ui.selectable_value(integrator, Integrator::Bdpt, "Bidirectional")
            .on_hover_text(
                "Paths from the lights too, joined to the camera's: caustics (light focused through \
                 glass or off mirrors onto surfaces) that path tracing finds slowly or not at all. \
                 Renders on the CPU whatever the device; no fog, adaptive sampling or firefly \
                 clamp",
            );
    });
}

/// Which backend renders the render windows: the GPU, rt's native CPU backend, or Auto (a
/// hardware GPU when there is one, else the CPU backend; lavapipe does not count).
fn device_choice(app: &mut RtApp, ui: &mut Ui) {
    use crate::render_job::DeviceChoice;
    ui.horizontal(|ui| {
        ui.label("Device").on_hover_text(
            "What renders: the GPU, the CPU (rt's native backend, on every core), or Auto (a \
             hardware GPU when there is one, else the CPU, which is faster than a software GPU)",
        );
        for choice in [DeviceChoice::Auto, DeviceChoice::Gpu, DeviceChoice::Cpu] {
            let label = crate::render_job::device_label(choice);
            ui.selectable_value(&mut app.ui.render_device, choice, label);
        }
    });
}
