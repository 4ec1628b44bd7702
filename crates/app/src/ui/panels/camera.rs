//! The Camera panel: position, rotation, projection and field of view, depth of field (aperture,
//! focus) and the framing and navigation controls.

use egui::{DragValue, Ui};

use rt_core::Camera;
use rt_core::camera::Projection;

use super::vec3_row;
use crate::app::RtApp;

pub fn camera_panel(app: &mut RtApp, ui: &mut Ui) {
    ui.heading("Camera");
    let mut camera = app.doc.scene.camera.clone();
    let size = app
        .doc
        .bounds()
        .map_or(1.0, |(lo, hi)| (hi - lo).max_element().max(1e-3));
    let before_from = camera.from;
    vec3_row(
        ui,
        "Position",
        &mut camera.from,
        size * 0.005,
        "Where the camera is",
    );
    if camera.from != before_from {
        // Moving the camera moves its target with it, keeping the view direction.
        let moved = glam::Vec3::from(camera.from) - glam::Vec3::from(before_from);
        camera.to = (glam::Vec3::from(camera.to) + moved).to_array();
    }
    let (mut yaw, mut pitch) = crate::navigation::yaw_pitch_deg(&camera);
    let (yaw0, pitch0) = (yaw, pitch);
    ui.horizontal(|ui| {
        ui.label("Rotation °")
            .on_hover_text("Yaw about the vertical axis and pitch above the horizon, in degrees");
        ui.add(DragValue::new(&mut yaw).speed(0.5).prefix("yaw "))
            .on_hover_text("Yaw in degrees");
        ui.add(
            DragValue::new(&mut pitch)
                .speed(0.5)
                .range(-89.0..=89.0)
                .prefix("pitch "),
        )
        .on_hover_text("Pitch in degrees");
    });
    if yaw != yaw0 || pitch != pitch0 {
        crate::navigation::set_yaw_pitch_deg(&mut camera, yaw, pitch);
    }
    projection_controls(ui, &mut camera, size, app.doc.bounds());
    ui.add(
        egui::Slider::new(&mut camera.aperture_radius, 0.0..=size * 0.05)
            .text("aperture")
            .clamping(egui::SliderClamping::Never),
    )
    .on_hover_text("Lens radius in scene units: 0 is a pinhole (all in focus)");
    ui.horizontal(|ui| {
        let mut auto = camera.focus_distance.is_none();
        if ui
            .checkbox(&mut auto, "focus at target")
            .on_hover_text("Focus on the point the camera looks at")
            .changed()
        {
            let distance = glam::Vec3::from(camera.from).distance(glam::Vec3::from(camera.to));
            camera.focus_distance = if auto { None } else { Some(distance) };
        }
        if let Some(d) = &mut camera.focus_distance {
            ui.add(DragValue::new(d).speed(size * 0.005).range(1e-6..=f32::MAX))
                .on_hover_text("Distance to the plane in focus");
        }
    });
    let picking = app.ui.picking_focus;
    if ui
        .selectable_label(picking, "Pick focus point")
        .on_hover_text("Then click in the viewport on what should be sharp")
        .clicked()
    {
        app.ui.picking_focus = !picking;
    }
    ui.horizontal(|ui| {
        if ui
            .button("Frame selection")
            .on_hover_text("Fit the selection (or the scene) in view (F)")
            .clicked()
        {
            app.frame_selection();
        }
        if ui
            .button("Reset view")
            .on_hover_text("The camera the scene was opened with (Home)")
            .clicked()
        {
            app.reset_view();
        }
    });
    ui.checkbox(&mut app.ui.orbit_mode, "Orbit mode")
        .on_hover_text("Right-drag orbits around the selection (O)");
    if camera != app.doc.scene.camera {
        app.doc
            .edit("change camera", "camera", |s| s.camera = camera);
    }
}

/// The projection and what sizes its view: the field of view (perspective), the view's height
/// (orthographic; unset, it follows the distance to the target as the perspective view would) or
/// the fisheye's angle.
fn projection_controls(
    ui: &mut Ui,
    camera: &mut Camera,
    size: f32,
    bounds: Option<(glam::Vec3, glam::Vec3)>,
) {
    let before = camera.projection;
    egui::ComboBox::from_label("projection")
        .selected_text(camera.projection.name())
        .show_ui(ui, |ui| {
            for p in Projection::ALL {
                ui.selectable_value(&mut camera.projection, p, p.name());
            }
        })
        .response
        .on_hover_text(
            "Perspective (a lens), orthographic (parallel rays), panorama (360° equirectangular: \
             render it 2:1) or fisheye (equidistant circle). The raster preview draws panorama \
             and fisheye as perspective; the path-traced view (P) shows them as rendered.",
        );
    if camera.projection == Projection::Orthographic && before != Projection::Orthographic {
        // Keep the framing: the height the perspective view had at the scene's centre.
        camera.ortho_height = Some(camera.ortho_height_in(bounds));
    }
    match camera.projection {
        Projection::Perspective => {
            ui.add(egui::Slider::new(&mut camera.vfov_deg, 1.0..=170.0).text("vertical FOV °"))
                .on_hover_text("Vertical field of view in degrees");
        }
        Projection::Orthographic => {
            let shown = camera.ortho_height_in(bounds);
            let mut height = shown;
            ui.horizontal(|ui| {
                ui.label("height");
                ui.add(
                    DragValue::new(&mut height)
                        .speed(size * 0.005)
                        .range(1e-6..=f32::MAX),
                )
                .on_hover_text("The view's height in scene units (the wheel zooms it)");
            });
            if height != shown {
                camera.ortho_height = Some(height);
            }
        }
        Projection::Panorama => {}
        Projection::Fisheye => {
            ui.add(
                egui::Slider::new(&mut camera.fisheye_angle_deg, 1.0..=360.0)
                    .text("fisheye angle °"),
            )
            .on_hover_text("The angle the image circle spans, in degrees");
        }
    }
}
