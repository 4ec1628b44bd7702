//! Transform handles on the selection, a constant size on screen, X red, Y green, Z blue: arrows
//! along the world axes from its centre (move), rings about them (turn) and squares beyond the
//! arrows' tips (scale). Dragging one changes the selection along or about that axis: a G, R or S
//! gesture held to the axis (`app::transform_tool`), driven by the pointer until it is released,
//! one undo step. Lights take the handles that apply to them (a point or spot moves, a spot turns).

use egui::{Color32, Pos2, Rect, Stroke};
use glam::Vec3;

use crate::app::RtApp;
use crate::app::transform_tool::ToolKind;
use crate::navigation;

/// An arrow's length and a ring's radius on screen (points), where the scale squares sit (in
/// arrow lengths) and their half-side, and how near a handle a press must come.
const LENGTH: f32 = 70.0;
const RING: f32 = 52.0;
const BOX_AT: f32 = 1.25;
const BOX: f32 = 4.5;
const GRAB: f32 = 7.0;
const COLOURS: [Color32; 3] = [
    Color32::from_rgb(230, 70, 70),
    Color32::from_rgb(90, 200, 90),
    Color32::from_rgb(80, 130, 240),
];
const AXES: [Vec3; 3] = [Vec3::X, Vec3::Y, Vec3::Z];

/// The selection's centre (an object's, or a point or spot light's position).
fn centre(app: &RtApp) -> Option<Vec3> {
    if let Some(i) = app.selection {
        return navigation::object_center(&app.doc.scene, i);
    }
    let light = app.doc.scene.lights.get(app.selected_light?)?;
    (light.kind != rt_core::LightKind::Directional).then(|| Vec3::from(light.position))
}

fn to_screen(app: &RtApp, rect: Rect, point: Vec3) -> Option<Pos2> {
    navigation::to_screen(&app.doc.scene.camera, rect, point)
}

/// The selection's centre and the world length of one screen point there.
fn centre_and_scale(app: &RtApp, rect: Rect) -> Option<(Vec3, f32)> {
    let centre = centre(app)?;
    Some((
        centre,
        navigation::world_per_point(&app.doc.scene.camera, rect, centre)?,
    ))
}

/// Which gestures the selection takes: a light only those that mean something for it.
fn takes(app: &RtApp, kind: ToolKind) -> bool {
    let Some(light) = app.selected_light.and_then(|i| app.doc.scene.lights.get(i)) else {
        return app.selection.is_some();
    };
    match kind {
        ToolKind::Grab => light.kind != rt_core::LightKind::Directional,
        ToolKind::Rotate => light.kind == rt_core::LightKind::Spot,
        ToolKind::Scale => false,
    }
}

/// The three arrows on screen: their axis, base and tip (an axis seen end-on has a short arrow).
pub fn handles(app: &RtApp, rect: Rect) -> Vec<(usize, Pos2, Pos2)> {
    let Some((centre, unit)) = centre_and_scale(app, rect) else {
        return Vec::new();
    };
    let Some(base) = to_screen(app, rect, centre).filter(|_| takes(app, ToolKind::Grab)) else {
        return Vec::new();
    };
    (0..3)
        .filter_map(|axis| {
            let tip = to_screen(app, rect, centre + AXES[axis] * LENGTH * unit)?;
            Some((axis, base, tip))
        })
        .collect()
}

/// The three rings on screen (closed polylines), about each axis.
pub fn rings(app: &RtApp, rect: Rect) -> Vec<(usize, Vec<Pos2>)> {
    let Some((centre, unit)) = centre_and_scale(app, rect) else {
        return Vec::new();
    };
    if !takes(app, ToolKind::Rotate) {
        return Vec::new();
    }
    (0..3)
        .map(|axis| {
            let (u, v) = (AXES[(axis + 1) % 3], AXES[(axis + 2) % 3]);
            let points = (0..=48)
                .filter_map(|k| {
                    let a = k as f32 / 48.0 * std::f32::consts::TAU;
                    to_screen(
                        app,
                        rect,
                        centre + (u * a.cos() + v * a.sin()) * RING * unit,
                    )
                })
                .collect();
            (axis, points)
        })
        .collect()
}

/// The three scale squares' centres on screen, beyond the arrows' tips.
pub fn boxes(app: &RtApp, rect: Rect) -> Vec<(usize, Pos2)> {
    let Some((centre, unit)) = centre_and_scale(app, rect) else {
        return Vec::new();
    };
    if !takes(app, ToolKind::Scale) {
        return Vec::new();
    }
    (0..3)
        .filter_map(|axis| {
            let at = to_screen(app, rect, centre + AXES[axis] * BOX_AT * LENGTH * unit)?;
            Some((axis, at))
        })
        .collect()
}

/// The distance from `p` to the segment `a`–`b`, and where along it (0 at `a`, 1 at `b`).
fn to_segment(p: Pos2, a: Pos2, b: Pos2) -> (f32, f32) {
    let along = b - a;
    let t = ((p - a).dot(along) / along.length_sq().max(1e-6)).clamp(0.0, 1.0);
    (p.distance(a + along * t), t)
}

/// Draws the handles over the viewport (the one being dragged brighter).
pub fn paint(app: &RtApp, painter: &egui::Painter, rect: Rect) {
    let active = app
        .tool
        .as_ref()
        .filter(|t| t.held)
        .and_then(|t| Some((t.kind, t.axis?)));
    let colour = |kind, axis: usize| {
        if active == Some((kind, axis)) {
            Color32::from_rgb(255, 230, 120)
        } else {
            COLOURS[axis]
        }
    };
    for (axis, points) in rings(app, rect) {
        let stroke = Stroke::new(1.5, colour(ToolKind::Rotate, axis).gamma_multiply(0.8));
        painter.add(egui::Shape::line(points, stroke));
    }
    for (axis, base, tip) in handles(app, rect) {
        painter.arrow(
            base,
            tip - base,
            Stroke::new(2.5, colour(ToolKind::Grab, axis)),
        );
    }
    for (axis, at) in boxes(app, rect) {
        let square = Rect::from_center_size(at, egui::vec2(2.0 * BOX, 2.0 * BOX));
        painter.rect_filled(square, 1.0, colour(ToolKind::Scale, axis));
    }
}

/// The nearest of `found` (axis, distance) within `GRAB`.
fn nearest(found: impl Iterator<Item = (usize, f32)>) -> Option<usize> {
    found
        .filter(|(_, d)| *d <= GRAB)
        .min_by(|a, b| a.1.total_cmp(&b.1))
        .map(|(axis, _)| axis)
}

/// The handle a press at `pos` lands on: a scale square, else an arrow's shaft (not its shared
/// base), else a ring.
pub fn hit(app: &RtApp, rect: Rect, pos: Pos2) -> Option<(ToolKind, usize)> {
    let squares = boxes(app, rect);
    if let Some(axis) = nearest(squares.iter().map(|(a, at)| (*a, at.distance(pos) - BOX))) {
        return Some((ToolKind::Scale, axis));
    }
    let shafts = handles(app, rect)
        .into_iter()
        .filter_map(|(axis, base, tip)| {
            let (d, t) = to_segment(pos, base, tip);
            (t > 0.2).then_some((axis, d))
        });
    if let Some(axis) = nearest(shafts) {
        return Some((ToolKind::Grab, axis));
    }
    let rims = rings(app, rect).into_iter().map(|(axis, points)| {
        let d = (points.windows(2))
            .map(|w| to_segment(pos, w[0], w[1]).0)
            .fold(f32::MAX, f32::min);
        (axis, d)
    });
    nearest(rims).map(|axis| (ToolKind::Rotate, axis))
}

/// Starts the gesture of the handle a drag beginning at `pos` grabbed; whether one was grabbed.
pub fn grab(app: &mut RtApp, rect: Rect, pos: Pos2) -> bool {
    let Some((kind, axis)) = hit(app, rect, pos) else {
        return false;
    };
    app.start_transform(kind, Some(pos));
    if let Some(tool) = app.tool.as_mut() {
        tool.axis = Some(axis);
        tool.held = true;
    }
    app.tool.is_some()
}
