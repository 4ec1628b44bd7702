//! The central viewport: the raster preview (or the path-traced view), mouse navigation and
//! picking.

use std::sync::Arc;

use egui::{PointerButton, Sense, Ui};
use glam::{Vec2, Vec3};

use super::{gizmo, light_marks};
use crate::app::RtApp;
use crate::navigation;
use crate::preview::{PreviewCallback, build_interactive_frame};

pub fn viewport(app: &mut RtApp, ui: &mut Ui) {
    let (rect, response) = ui.allocate_exact_size(ui.available_size(), Sense::click_and_drag());
    app.ui.viewport_rect = Some(rect);
    let response = response.on_hover_text_at_pointer(
        "Left-drag pans, right-drag turns (orbits in orbit mode), middle-drag orbits, wheel \
         dollies, click selects (an object, or a light by its mark), dragging a handle moves, turns \
         or scales the selection",
    );
    let ppp = ui.ctx().pixels_per_point();
    let size_px = [
        (rect.width() * ppp).round().max(1.0) as u32,
        (rect.height() * ppp).round().max(1.0) as u32,
    ];
    navigate(app, ui, &response, rect);

    // The path-traced view renders at point resolution: 1/ppp² of the pixels, same framing.
    let live_size = [
        rect.width().round().max(1.0) as u32,
        rect.height().round().max(1.0) as u32,
    ];
    let interacting = response.dragged()
        || app.ui.scripted_drag
        || ui.ctx().input(|i| i.smooth_scroll_delta.y != 0.0);
    app.update_live_view(live_size, interacting);
    let painter = ui.painter_at(rect);
    if app.live.enabled {
        update_live_texture(app, ui.ctx());
    }
    match (&app.live.texture, app.live.enabled) {
        (Some(texture), true) => {
            let view = app.live.view.as_ref();
            let current = view.and_then(|v| v.display());
            let shown = current.or_else(|| view.and_then(|v| v.previous()));
            // The rendered image is rounded up to whole big pixels: show the part the view covers.
            let uv = shown.map_or(egui::vec2(1.0, 1.0), |f| {
                egui::vec2(
                    live_size[0] as f32 / (f.width * f.pixel_size) as f32,
                    live_size[1] as f32 / (f.height * f.pixel_size) as f32,
                )
            });
            let tint = if current.is_some() {
                egui::Color32::WHITE
            } else {
                egui::Color32::from_gray(150)
            };
            painter.image(
                texture.id(),
                rect,
                egui::Rect::from_min_max(egui::pos2(0.0, 0.0), uv.to_pos2()),
                tint,
            );
            painter.text(
                rect.left_top() + egui::vec2(8.0, 8.0),
                egui::Align2::LEFT_TOP,
                live_overlay(current),
                egui::FontId::proportional(13.0),
                egui::Color32::WHITE,
            );
            let toggle = egui::Rect::from_min_size(
                rect.right_top() + egui::vec2(-110.0, 6.0),
                egui::vec2(104.0, 20.0),
            );
            ui.put(
                toggle,
                egui::Checkbox::new(&mut app.live.show_denoised, "denoised"),
            )
            .on_hover_text("Show the denoised image (on) or the raw samples (off)");
        }
        (None, true) => {
            painter.text(
                rect.center(),
                egui::Align2::CENTER_CENTER,
                "Starting the path-traced view…",
                egui::FontId::proportional(14.0),
                egui::Color32::GRAY,
            );
        }
        _ if app.preview_available => {
            let frame = build_interactive_frame(
                &app.doc.scene,
                &app.doc.scene.camera,
                app.doc.bounds(),
                app.selection,
                size_px,
            );
            if frame.settling {
                // A large scene's bounce light is being rebuilt: look again soon.
                ui.ctx()
                    .request_repaint_after(std::time::Duration::from_millis(50));
            }
            painter.add(egui_wgpu::Callback::new_paint_callback(
                rect,
                PreviewCallback(Arc::new(frame)),
            ));
        }
        _ => {
            painter.text(
                rect.center(),
                egui::Align2::CENTER_CENTER,
                "The raster preview needs egui on wgpu; turn on the path-traced viewport (P).",
                egui::FontId::proportional(14.0),
                egui::Color32::GRAY,
            );
        }
    }
    render_region(app, &painter, rect);
    // The marks over the handles: a selected light's mark stays visible at the arrows' base.
    gizmo::paint(app, &painter, rect);
    light_marks::paint(app, &painter, rect);
    if app.ui.picking_focus {
        painter.text(
            rect.center_top() + egui::vec2(0.0, 8.0),
            egui::Align2::CENTER_TOP,
            "Click on the point to focus on (Esc cancels)",
            egui::FontId::proportional(14.0),
            egui::Color32::YELLOW,
        );
    }
}

/// Outlines the part of the view the final image covers (same vertical field of view, the
/// render's aspect ratio).
fn render_region(app: &RtApp, painter: &egui::Painter, rect: egui::Rect) {
    let s = &app.doc.scene.settings;
    let aspect = s.width as f32 / s.height.max(1) as f32;
    let width = rect.height() * aspect;
    if width < rect.width() - 1.0 {
        let region = egui::Rect::from_center_size(rect.center(), egui::vec2(width, rect.height()));
        painter.rect_stroke(
            region,
            0.0,
            egui::Stroke::new(1.0, egui::Color32::from_white_alpha(90)),
            egui::StrokeKind::Inside,
        );
    }
}

fn navigate(app: &mut RtApp, ui: &Ui, response: &egui::Response, rect: egui::Rect) {
    // A G/R/S gesture owns the pointer: a click ends it, nothing navigates or picks.
    if app.tool.is_some() {
        super::transform_keys::pointer_ends(app, ui, response);
        return;
    }
    // A drag that begins on a handle moves, turns or scales the selection on its axis.
    if response.drag_started_by(PointerButton::Primary)
        && let Some(origin) = ui.input(|i| i.pointer.press_origin())
        && gizmo::grab(app, rect, origin)
    {
        return;
    }
    let mut camera = app.doc.scene.camera.clone();
    let distance = navigation::view_distance(app.doc.bounds(), &camera);
    let delta = response.drag_delta();
    let drag = Vec2::new(delta.x, delta.y);
    if drag != Vec2::ZERO {
        if response.dragged_by(PointerButton::Primary) {
            navigation::pan(&mut camera, drag, rect.height(), distance);
        } else if response.dragged_by(PointerButton::Secondary) {
            if app.ui.orbit_mode {
                navigation::orbit(&mut camera, orbit_pivot(app), drag);
            } else {
                navigation::rotate(&mut camera, drag);
            }
        } else if response.dragged_by(PointerButton::Middle) {
            navigation::orbit(&mut camera, orbit_pivot(app), drag);
        }
    }
    if response.hovered() {
        let scroll = ui.ctx().input(|i| i.smooth_scroll_delta.y);
        if scroll != 0.0 {
            navigation::dolly(&mut camera, scroll, distance);
        }
    }
    if camera != app.doc.scene.camera {
        app.doc.edit("move camera", "camera", |s| s.camera = camera);
    }
    if response.clicked()
        && let Some(pos) = response.interact_pointer_pos()
    {
        let uv = Vec2::new(
            (pos.x - rect.left()) / rect.width().max(1.0),
            (pos.y - rect.top()) / rect.height().max(1.0),
        );
        let aspect = rect.width() / rect.height().max(1.0);
        let hit = navigation::camera_ray(&app.doc.scene.camera, aspect, uv)
            .and_then(|(o, d)| navigation::pick(&app.doc.scene, o, d).map(|h| (h, d)));
        if app.ui.picking_focus {
            if let Some(((_, t), direction)) = hit {
                // Focus distance is measured along the view axis, as the thin lens uses it.
                let axis = (Vec3::from(app.doc.scene.camera.to)
                    - Vec3::from(app.doc.scene.camera.from))
                .normalize_or(Vec3::NEG_Z);
                let distance = t * direction.dot(axis);
                app.doc.edit("set focus", "set focus", |s| {
                    s.camera.focus_distance = Some(distance.max(1e-6))
                });
                app.doc.seal();
            }
            app.ui.picking_focus = false;
        } else if let Some(light) = light_marks::pick(app, rect, pos) {
            app.select_light(Some(light));
        } else {
            app.select_object(hit.map(|((i, _), _)| i));
        }
    }
}

fn orbit_pivot(app: &RtApp) -> Vec3 {
    app.selection
        .and_then(|i| navigation::object_center(&app.doc.scene, i))
        .or_else(|| {
            let (lo, hi) = app.doc.bounds()?;
            Some((lo + hi) * 0.5)
        })
        .unwrap_or_else(|| Vec3::from(app.doc.scene.camera.to))
}

/// The path-traced view's status line: samples, time since the change, noise, resolution step and
/// denoiser.
fn live_overlay(frame: Option<&rt_gpu::live::LiveFrame>) -> String {
    let Some(f) = frame else {
        return "path traced: updating…".into();
    };
    let mut line = format!(
        "path traced: {} spp, {:.1} s",
        f.samples,
        f.elapsed.as_secs_f64()
    );
    if let Some(noise) = f.noise {
        line += &format!(", noise {:.1}%", noise * 100.0);
    }
    if f.pixel_size > 1 {
        line += &format!(", 1/{} resolution", f.pixel_size);
    }
    match f.denoiser {
        Some(d) => line += &format!(", denoised ({})", d.name()),
        None => line += ", raw",
    }
    if f.while_compiling {
        line += ", on the CPU while the GPU kernel compiles";
    }
    line
}

fn update_live_texture(app: &mut RtApp, ctx: &egui::Context) {
    let Some(view) = &app.live.view else { return };
    let Some(frame) = view.display().or_else(|| view.previous()) else {
        return;
    };
    let key = (
        frame.generation,
        frame.samples,
        frame.pixel_size,
        frame.denoiser.is_some(),
    );
    if app.live.texture.is_some() && app.live.texture_key == Some(key) {
        return;
    }
    let color = egui::ColorImage::from_rgba_unmultiplied(
        [frame.width as usize, frame.height as usize],
        &frame.rgba8,
    );
    // Big pixels stay sharp squares; full resolution is filtered as usual.
    let options = if frame.pixel_size > 1 {
        egui::TextureOptions::NEAREST
    } else {
        egui::TextureOptions::LINEAR
    };
    match &mut app.live.texture {
        Some(texture) => texture.set(color, options),
        None => {
            app.live.texture = Some(ctx.load_texture("path-traced view", color, options));
        }
    }
    app.live.texture_key = Some(key);
}
