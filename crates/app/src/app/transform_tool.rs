//! Blender's modal transforms: G grabs (moves), R rotates, S scales the selected object (G moves a
//! point or spot light, R turns a spot or sun). The pointer drives the change until a click
//! confirms it (a right click or Esc cancels); X, Y or Z holds it to that world axis (again: free);
//! a typed number sets it exactly (a distance in scene units, degrees, a factor; without an axis
//! a move goes along X and a turn about the view axis); Ctrl snaps it (the preview grid's step,
//! 5°, tenths). The whole gesture is one undo step. This file is the state and the arithmetic;
//! `ui/mod.rs` and `ui/viewport.rs` feed it keys and the pointer.

use glam::{EulerRot, Quat, Vec2, Vec3};
use rt_core::{LightKind, Scene, Transform};

use super::RtApp;

/// The undo key of a gesture's edits (they merge into one step).
const KEY: &str = "transform tool";

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ToolKind {
    Grab,
    Rotate,
    Scale,
}

/// What a gesture changes, and how it was before.
#[derive(Clone, Debug, PartialEq)]
pub enum ToolTarget {
    Object(usize, Transform),
    /// A light: its index, position and direction.
    Light(usize, Vec3, Vec3),
}

/// A gesture in progress.
#[derive(Clone, Debug, PartialEq)]
pub struct TransformTool {
    pub kind: ToolKind,
    pub target: ToolTarget,
    /// World axis (0 X, 1 Y, 2 Z) the change is held to.
    pub axis: Option<usize>,
    /// The number typed so far.
    pub typed: String,
    /// The pointer (screen points) when the gesture began, and now.
    pub start: Option<egui::Pos2>,
    pub pointer: Option<egui::Pos2>,
    pub snap: bool,
    /// Begun by dragging a handle (`ui::gizmo`): it ends when the pointer is released.
    pub held: bool,
    /// The target's centre on screen when the gesture began: turns and scalings measure the
    /// pointer from it (the target's own centre moves when it turns about its origin).
    pub anchor: Option<egui::Pos2>,
}

impl TransformTool {
    /// The status line: what is changing and how.
    pub fn describe(&self) -> String {
        let what = match self.kind {
            ToolKind::Grab => "Move",
            ToolKind::Rotate => "Rotate",
            ToolKind::Scale => "Scale",
        };
        let axis = self
            .axis
            .map_or(String::new(), |a| format!(" along {}", ["X", "Y", "Z"][a]));
        let typed = if self.typed.is_empty() {
            String::new()
        } else {
            format!(": {}", self.typed)
        };
        format!(
            "{what}{axis}{typed} (click or Enter confirms, Esc cancels; X/Y/Z axis, Ctrl snaps)"
        )
    }
}

/// The change the pointer or the typed number asks for, given where things are on screen.
#[derive(Clone, Copy, Debug, Default)]
pub struct ScreenFrame {
    /// The target's centre on screen (points).
    pub centre: Option<egui::Pos2>,
    /// World units per screen point at the target's depth, and the camera's right, up and
    /// backward axes.
    pub units_per_point: f32,
    pub right: Vec3,
    pub up: Vec3,
    pub back: Vec3,
    /// The snapping step of a move (the preview grid's).
    pub grid_step: f32,
}

fn axis_vector(axis: usize) -> Vec3 {
    [Vec3::X, Vec3::Y, Vec3::Z][axis]
}

fn snap_to(value: f32, step: f32, snap: bool) -> f32 {
    if snap && step > 0.0 {
        (value / step).round() * step
    } else {
        value
    }
}

impl TransformTool {
    fn typed_value(&self) -> Option<f32> {
        self.typed.parse::<f32>().ok().filter(|v| v.is_finite())
    }

    /// The displacement of a move.
    pub fn offset(&self, frame: &ScreenFrame) -> Vec3 {
        if let Some(v) = self.typed_value() {
            return axis_vector(self.axis.unwrap_or(0)) * v;
        }
        let (Some(a), Some(b)) = (self.start, self.pointer) else {
            return Vec3::ZERO;
        };
        let d = b - a;
        let free = (frame.right * d.x - frame.up * d.y) * frame.units_per_point;
        let offset = match self.axis {
            Some(axis) => axis_vector(axis) * free.dot(axis_vector(axis)),
            None => free,
        };
        Vec3::from_array(
            offset
                .to_array()
                .map(|c| snap_to(c, frame.grid_step, self.snap)),
        )
    }

    /// The rotation of a turn: about the held axis, else about the view axis.
    pub fn rotation(&self, frame: &ScreenFrame) -> Quat {
        let axis = self.axis.map_or(frame.back, axis_vector);
        let degrees = match self.typed_value() {
            Some(v) => v,
            None => {
                let (Some(c), Some(a), Some(b)) = (frame.centre, self.start, self.pointer) else {
                    return Quat::IDENTITY;
                };
                let angle = |p: egui::Pos2| (-(p.y - c.y)).atan2(p.x - c.x);
                let mut turn = (angle(b) - angle(a)).to_degrees();
                // Seen down an axis pointing away from the camera, screen angles turn backwards.
                if axis.dot(frame.back) < 0.0 {
                    turn = -turn;
                }
                snap_to(turn, 5.0, self.snap)
            }
        };
        Quat::from_axis_angle(axis, degrees.to_radians())
    }

    /// The factor of a scaling.
    pub fn factor(&self, frame: &ScreenFrame) -> f32 {
        if let Some(v) = self.typed_value() {
            return v;
        }
        let (Some(c), Some(a), Some(b)) = (frame.centre, self.start, self.pointer) else {
            return 1.0;
        };
        let (ra, rb) = (
            Vec2::new(a.x - c.x, a.y - c.y),
            Vec2::new(b.x - c.x, b.y - c.y),
        );
        if ra.length() < 1.0 {
            return 1.0;
        }
        snap_to(rb.length() / ra.length(), 0.1, self.snap)
    }

    /// Sets the target in `scene` to its original state changed by this gesture.
    pub fn apply(&self, scene: &mut Scene, frame: &ScreenFrame) {
        match &self.target {
            ToolTarget::Object(i, original) => {
                let Some(object) = scene.objects.get_mut(*i) else {
                    return;
                };
                let mut t = original.clone();
                match self.kind {
                    ToolKind::Grab => {
                        t.translation = (Vec3::from(t.translation) + self.offset(frame)).to_array();
                    }
                    ToolKind::Rotate => {
                        let [x, y, z] = t.rotation_deg.map(f32::to_radians);
                        let q = self.rotation(frame) * Quat::from_euler(EulerRot::XYZ, x, y, z);
                        let (x, y, z) = q.to_euler(EulerRot::XYZ);
                        t.rotation_deg = [x, y, z].map(f32::to_degrees);
                    }
                    ToolKind::Scale => {
                        let f = self.factor(frame);
                        match self.axis {
                            Some(axis) => t.scale[axis] *= f,
                            None => t.scale = t.scale.map(|s| s * f),
                        }
                    }
                }
                object.transform = t;
            }
            ToolTarget::Light(i, position, direction) => {
                let Some(light) = scene.lights.get_mut(*i) else {
                    return;
                };
                match self.kind {
                    ToolKind::Grab => light.position = (*position + self.offset(frame)).to_array(),
                    ToolKind::Rotate => {
                        light.direction = (self.rotation(frame) * *direction).to_array();
                    }
                    ToolKind::Scale => {}
                }
            }
        }
    }
}

impl RtApp {
    /// Starts gesture `kind` on the selection (nothing happens without one, or for a change the
    /// selected light has no use for), the pointer at `pointer`.
    pub fn start_transform(&mut self, kind: ToolKind, pointer: Option<egui::Pos2>) {
        let target = if let Some(i) = self.selection {
            let object = self.doc.scene.objects.get(i);
            object.map(|o| ToolTarget::Object(i, o.transform.clone()))
        } else if let Some(i) = self.selected_light {
            let light = self.doc.scene.lights.get(i);
            light
                .filter(|l| match kind {
                    ToolKind::Grab => l.kind != LightKind::Directional,
                    ToolKind::Rotate => l.kind != LightKind::Point,
                    ToolKind::Scale => false,
                })
                .map(|l| ToolTarget::Light(i, Vec3::from(l.position), Vec3::from(l.direction)))
        } else {
            None
        };
        self.doc.seal();
        self.tool = target.map(|target| TransformTool {
            kind,
            target,
            axis: None,
            typed: String::new(),
            start: pointer,
            pointer,
            snap: false,
            held: false,
            anchor: None,
        });
    }

    /// Applies the gesture as it stands (one undo step with its earlier changes).
    pub fn update_transform(&mut self, frame: &ScreenFrame) {
        let Some(tool) = self.tool.clone() else {
            return;
        };
        let label = match tool.kind {
            ToolKind::Grab => "move",
            ToolKind::Rotate => "rotate",
            ToolKind::Scale => "scale",
        };
        self.doc.edit(label, KEY, |s| tool.apply(s, frame));
    }

    /// Ends the gesture, keeping its change as one undo step.
    pub fn confirm_transform(&mut self) {
        if self.tool.take().is_some() {
            self.doc.seal();
        }
    }

    /// Ends the gesture, putting the target back as it was (no undo step remains).
    pub fn cancel_transform(&mut self) {
        if self.tool.take().is_some() {
            self.doc.abandon(KEY);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn tool(kind: ToolKind, axis: Option<usize>, typed: &str) -> TransformTool {
        TransformTool {
            kind,
            target: ToolTarget::Object(0, Transform::default()),
            axis,
            typed: typed.into(),
            start: Some(egui::pos2(100.0, 100.0)),
            pointer: Some(egui::pos2(100.0, 100.0)),
            snap: false,
            held: false,
            anchor: None,
        }
    }

    fn frame() -> ScreenFrame {
        ScreenFrame {
            centre: Some(egui::pos2(100.0, 100.0)),
            units_per_point: 0.01,
            right: Vec3::X,
            up: Vec3::Y,
            back: Vec3::Z,
            grid_step: 0.5,
        }
    }

    /// A typed number moves along the held axis (X without one), turns about it (the view axis
    /// without one) or scales along it (uniformly without one).
    #[test]
    fn typed_numbers_move_turn_and_scale_exactly() {
        let f = frame();
        assert_eq!(
            tool(ToolKind::Grab, Some(1), "2").offset(&f),
            Vec3::new(0.0, 2.0, 0.0)
        );
        assert_eq!(
            tool(ToolKind::Grab, None, "-1.5").offset(&f),
            Vec3::new(-1.5, 0.0, 0.0)
        );
        let q = tool(ToolKind::Rotate, Some(2), "90").rotation(&f);
        assert!((q * Vec3::X - Vec3::Y).length() < 1e-6);
        let mut scene = Scene::default();
        scene.objects.push(rt_core::Object {
            shadow_catcher: false,
            animation_node: None,
            name: "box".into(),
            mesh: rt_core::shapes::cuboid(Vec3::ZERO, Vec3::ONE, false).into(),
            material: rt_core::Material::lambertian([0.5; 3]),
            transform: Default::default(),
        });
        tool(ToolKind::Scale, Some(0), "3").apply(&mut scene, &f);
        assert_eq!(scene.objects[0].transform.scale, [3.0, 1.0, 1.0]);
        tool(ToolKind::Rotate, Some(1), "30").apply(&mut scene, &f);
        let r = scene.objects[0].transform.rotation_deg;
        assert!((r[1] - 30.0).abs() < 1e-4 && r[0].abs() < 1e-4, "{r:?}");
    }

    /// The pointer moves in the view plane at the target's depth (held to an axis: its share
    /// along it), snapping to the grid with Ctrl; it turns by its angle about the centre and
    /// scales by its distance from it.
    #[test]
    fn the_pointer_moves_turns_and_scales() {
        let f = frame();
        let mut t = tool(ToolKind::Grab, None, "");
        t.pointer = Some(egui::pos2(160.0, 70.0));
        assert!((t.offset(&f) - Vec3::new(0.6, 0.3, 0.0)).length() < 1e-6);
        t.axis = Some(0);
        assert!((t.offset(&f) - Vec3::new(0.6, 0.0, 0.0)).length() < 1e-6);
        t.snap = true;
        assert!((t.offset(&f) - Vec3::new(0.5, 0.0, 0.0)).length() < 1e-6);
        let mut r = tool(ToolKind::Rotate, None, "");
        r.start = Some(egui::pos2(150.0, 100.0));
        r.pointer = Some(egui::pos2(100.0, 50.0));
        // A quarter turn counter-clockwise on screen, about the view axis.
        assert!((r.rotation(&f) * Vec3::X - Vec3::Y).length() < 1e-5);
        let mut s = tool(ToolKind::Scale, None, "");
        s.start = Some(egui::pos2(110.0, 100.0));
        s.pointer = Some(egui::pos2(125.0, 100.0));
        assert!((s.factor(&f) - 2.5).abs() < 1e-6);
    }
}
