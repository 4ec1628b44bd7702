//! Move handles on the selection: three arrows along the world axes (X red, Y green, Z blue) from
//! its centre, a constant size on screen. Dragging one moves the selection along that axis: a
//! G gesture held to the axis (`app::transform_tool`), driven by the pointer until it is
//! released, one undo step.

use egui::{Color32, Pos2, Rect, Stroke};
use glam::Vec3;

use crate::app::RtApp;
use crate::app::transform_tool::ToolKind;
use crate::navigation;

/// An arrow's length on screen (points), and how near its shaft a press must come.
const LENGTH: f32 = 70.0;
const GRAB: f32 = 7.0;
const COLOURS: [Color32; 3] = [
    Color32::from_rgb(230, 70, 70),
    Color32::from_rgb(90, 200, 90),
    Color32::from_rgb(80, 130, 240),
];

/// The selection's centre (an object's, or a point or spot light's position).
fn centre(app: &RtApp) -> Option<Vec3> {
    if let Some(i) = app.selection {
        return navigation::object_center(&app.doc.scene, i);
    }
    let light = app.doc.scene.lights.get(app.selected_light?)?;
    (light.kind != rt_core::LightKind::Directional).then(|| Vec3::from(light.position))
}

/// Where the world point lies in `rect`.
fn to_screen(app: &RtApp, rect: Rect, point: Vec3) -> Option<Pos2> {
    let aspect = rect.width() / rect.height().max(1.0);
    let uv = navigation::project(&app.doc.scene.camera, aspect, point)?;
    Some(rect.min + egui::vec2(uv.x * rect.width(), uv.y * rect.height()))
}

/// The three arrows on screen: their axis, base and tip (an axis seen end-on has a short arrow).
pub fn handles(app: &RtApp, rect: Rect) -> Vec<(usize, Pos2, Pos2)> {
    let (Some(centre), Ok(basis)) = (centre(app), app.doc.scene.camera.basis()) else {
        return Vec::new();
    };
    let depth = (centre - basis.origin).dot(-basis.w);
    if depth <= 0.0 {
        return Vec::new();
    }
    let units = LENGTH * 2.0 * depth * basis.tan_half_vfov / rect.height().max(1.0);
    let Some(base) = to_screen(app, rect, centre) else {
        return Vec::new();
    };
    (0..3)
        .filter_map(|axis| {
            let tip = to_screen(
                app,
                rect,
                centre + [Vec3::X, Vec3::Y, Vec3::Z][axis] * units,
            )?;
            Some((axis, base, tip))
        })
        .collect()
}

/// Draws the arrows over the viewport (the one being dragged brighter).
pub fn paint(app: &RtApp, painter: &egui::Painter, rect: Rect) {
    let active = app.tool.as_ref().filter(|t| t.held).and_then(|t| t.axis);
    for (axis, base, tip) in handles(app, rect) {
        let colour = if active == Some(axis) {
            Color32::from_rgb(255, 230, 120)
        } else {
            COLOURS[axis]
        };
        painter.arrow(base, tip - base, Stroke::new(2.5, colour));
    }
}

/// The axis of the arrow a press at `pos` lands on (the nearest shaft within `GRAB`).
pub fn hit(app: &RtApp, rect: Rect, pos: Pos2) -> Option<usize> {
    handles(app, rect)
        .into_iter()
        .filter_map(|(axis, base, tip)| {
            let along = tip - base;
            let t = ((pos - base).dot(along) / along.length_sq().max(1e-6)).clamp(0.0, 1.0);
            let distance = pos.distance(base + along * t);
            // Not the shared base: that would pick an axis at random.
            (t > 0.2 && distance <= GRAB).then_some((axis, distance))
        })
        .min_by(|a, b| a.1.total_cmp(&b.1))
        .map(|(axis, _)| axis)
}

/// Starts a move along the arrow a drag beginning at `pos` grabbed; whether one was grabbed.
pub fn grab(app: &mut RtApp, rect: Rect, pos: Pos2) -> bool {
    let Some(axis) = hit(app, rect, pos) else {
        return false;
    };
    app.start_transform(ToolKind::Grab, Some(pos));
    if let Some(tool) = app.tool.as_mut() {
        tool.axis = Some(axis);
        tool.held = true;
    }
    app.tool.is_some()
}
