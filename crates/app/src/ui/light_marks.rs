//! Marks for the point, spot and sun lights in the viewport, which have no surface to see or
//! click: a point is a small star, a spot the same with the outline of its outer cone, a sun an
//! arrow falling onto the scene along its direction (drawn from above the scene's centre). A click
//! on a mark selects its light.

use egui::{Color32, Pos2, Rect, Stroke};
use glam::Vec3;
use rt_core::{Light, LightKind};

use crate::app::RtApp;
use crate::navigation;

/// How close (points) a click must come to a mark's anchor to select its light.
pub const PICK_RADIUS: f32 = 10.0;

const COLOUR: Color32 = Color32::from_rgb(255, 220, 80);
const SELECTED: Color32 = Color32::from_rgb(255, 140, 26);

/// One light's mark in world space: the point a click selects it at, and lines to draw.
pub struct LightMark {
    pub light: usize,
    pub anchor: Vec3,
    pub lines: Vec<[Vec3; 2]>,
}

/// The marks of the scene's delta lights, sized by the scene's extent `size` about `centre`.
pub fn light_marks(lights: &[Light], centre: Vec3, size: f32) -> Vec<LightMark> {
    lights
        .iter()
        .enumerate()
        .map(|(light, l)| {
            let axis = Vec3::from(l.direction).normalize_or(Vec3::NEG_Y);
            match l.kind {
                LightKind::Point => LightMark {
                    light,
                    anchor: Vec3::from(l.position),
                    lines: Vec::new(),
                },
                LightKind::Spot => {
                    let apex = Vec3::from(l.position);
                    let length = 0.2 * size;
                    let radius = length * l.outer_angle_deg.clamp(0.0, 89.0).to_radians().tan();
                    let (u, v) = axis.any_orthonormal_pair();
                    let rim = |k: usize| {
                        let a = k as f32 / 16.0 * std::f32::consts::TAU;
                        apex + axis * length + (u * a.cos() + v * a.sin()) * radius
                    };
                    let mut lines: Vec<[Vec3; 2]> = (0..16).map(|k| [rim(k), rim(k + 1)]).collect();
                    lines.extend((0..4).map(|k| [apex, rim(4 * k)]));
                    LightMark {
                        light,
                        anchor: apex,
                        lines,
                    }
                }
                LightKind::Directional => {
                    let anchor = centre - axis * (0.6 * size);
                    let tip = anchor + axis * (0.25 * size);
                    let (u, _) = axis.any_orthonormal_pair();
                    let barb = 0.05 * size;
                    LightMark {
                        light,
                        anchor,
                        lines: vec![
                            [anchor, tip],
                            [tip, tip - axis * barb + u * barb],
                            [tip, tip - axis * barb - u * barb],
                        ],
                    }
                }
            }
        })
        .collect()
}

/// The marks of `app`'s scene.
fn marks(app: &RtApp) -> Vec<LightMark> {
    let (centre, size) = app.doc.bounds().map_or((Vec3::ZERO, 1.0), |(lo, hi)| {
        ((lo + hi) * 0.5, (hi - lo).max_element().max(1e-3))
    });
    light_marks(&app.doc.scene.lights, centre, size)
}

fn to_screen(app: &RtApp, rect: Rect, point: Vec3) -> Option<Pos2> {
    navigation::to_screen(&app.doc.scene.camera, rect, point)
}

/// Where light `light`'s mark is anchored in the viewport `rect` (what a click selects it at).
pub fn anchor_on_screen(app: &RtApp, rect: Rect, light: usize) -> Option<Pos2> {
    let mark = marks(app).into_iter().find(|m| m.light == light)?;
    to_screen(app, rect, mark.anchor)
}

/// Draws the marks over the viewport `rect`.
pub fn paint(app: &RtApp, painter: &egui::Painter, rect: Rect) {
    for mark in marks(app) {
        let selected = app.selected_light == Some(mark.light);
        let colour = if selected { SELECTED } else { COLOUR };
        let stroke = Stroke::new(if selected { 2.0 } else { 1.5 }, colour);
        for [a, b] in &mark.lines {
            if let (Some(a), Some(b)) = (to_screen(app, rect, *a), to_screen(app, rect, *b)) {
                painter.line_segment([a, b], stroke);
            }
        }
        if let Some(p) = to_screen(app, rect, mark.anchor) {
            painter.circle(p, 5.0, colour, Stroke::new(1.0, Color32::BLACK));
            for k in 0..8 {
                let a = k as f32 / 8.0 * std::f32::consts::TAU;
                let d = egui::vec2(a.cos(), a.sin());
                painter.line_segment([p + d * 7.0, p + d * 11.0], stroke);
            }
        }
    }
}

/// The light whose mark a click at `pos` in the viewport `rect` lands on (the nearest within
/// `PICK_RADIUS`).
pub fn pick(app: &RtApp, rect: Rect, pos: Pos2) -> Option<usize> {
    marks(app)
        .iter()
        .filter_map(|m| Some((m.light, to_screen(app, rect, m.anchor)?.distance(pos))))
        .filter(|(_, d)| *d <= PICK_RADIUS)
        .min_by(|a, b| a.1.total_cmp(&b.1))
        .map(|(light, _)| light)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Every light has a mark anchored where it is (a sun: above the scene, against its
    /// direction); a spot's rim lies at its outer angle from its axis.
    #[test]
    fn marks_sit_on_their_lights_and_outline_a_spots_cone() {
        let mut point = Light::new(LightKind::Point, "point");
        point.position = [1.0, 2.0, 3.0];
        let mut spot = Light::new(LightKind::Spot, "spot");
        spot.position = [0.0, 4.0, 0.0];
        spot.direction = [0.0, -1.0, 0.0];
        spot.outer_angle_deg = 30.0;
        let mut sun = Light::new(LightKind::Directional, "sun");
        sun.direction = [0.0, -1.0, 0.0];
        let marks = light_marks(&[point, spot, sun], Vec3::ZERO, 10.0);
        assert_eq!(marks.len(), 3);
        assert_eq!(marks[0].anchor, Vec3::new(1.0, 2.0, 3.0));
        let apex = marks[1].anchor;
        for [a, _] in &marks[1].lines[..16] {
            let angle = (*a - apex).angle_between(Vec3::NEG_Y).to_degrees();
            assert!((angle - 30.0).abs() < 0.01, "{angle}");
        }
        assert!(
            marks[2].anchor.y > 5.0,
            "the sun's mark hangs above the scene"
        );
    }
}
