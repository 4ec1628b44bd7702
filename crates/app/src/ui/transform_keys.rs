//! The keys and pointer of a G/R/S gesture (`app::transform_tool`): starting one over the
//! viewport, feeding it axis keys, typed numbers and the pointer, and where its target sits on
//! screen.

use egui::{Event, Key, Modifiers};

use crate::app::RtApp;
use crate::app::transform_tool::{ScreenFrame, ToolKind, ToolTarget};
use crate::navigation;

/// Starts a gesture on G, R or S (with no text field taking the keys, and the caller checks that).
pub fn start(app: &mut RtApp, ctx: &egui::Context) {
    let pointer = ctx.input(|i| i.pointer.latest_pos());
    for (key, kind) in [
        (Key::G, ToolKind::Grab),
        (Key::R, ToolKind::Rotate),
        (Key::S, ToolKind::Scale),
    ] {
        if ctx.input_mut(|i| i.consume_key(Modifiers::NONE, key)) {
            app.start_transform(kind, pointer);
            return;
        }
    }
}

/// Feeds a gesture in progress this frame's keys and pointer and applies it; all plain keys are
/// its while it lasts.
pub fn drive(app: &mut RtApp, ctx: &egui::Context) {
    let Some(tool) = app.tool.as_mut() else {
        return;
    };
    let (events, pointer, snap) = ctx.input(|i| {
        (
            i.events.clone(),
            i.pointer.latest_pos(),
            i.modifiers.command,
        )
    });
    let mut end = None;
    for event in events {
        match event {
            Event::Key {
                key, pressed: true, ..
            } => match key {
                Key::X | Key::Y | Key::Z => {
                    let axis = [Key::X, Key::Y, Key::Z].iter().position(|k| *k == key);
                    tool.axis = if tool.axis == axis { None } else { axis };
                }
                Key::Backspace => {
                    tool.typed.pop();
                }
                Key::Enter => end = Some(true),
                Key::Escape => end = Some(false),
                _ => {}
            },
            Event::Text(text) => {
                for c in text.chars() {
                    let sign = c == '-' && tool.typed.is_empty();
                    let point = c == '.' && !tool.typed.contains('.');
                    if c.is_ascii_digit() || sign || point {
                        tool.typed.push(c);
                    }
                }
            }
            _ => {}
        }
    }
    if tool.start.is_none() {
        tool.start = pointer;
    }
    tool.pointer = pointer.or(tool.pointer);
    tool.snap = snap;
    // Nothing else takes these keys while the gesture lasts.
    ctx.input_mut(|i| {
        i.events
            .retain(|e| !matches!(e, Event::Key { .. } | Event::Text(_)))
    });
    let frame = screen_frame(app);
    if let Some(tool) = app.tool.as_mut()
        && tool.anchor.is_none()
    {
        tool.anchor = frame.centre;
    }
    app.update_transform(&frame);
    app.ui.status = app.tool.as_ref().map_or(String::new(), |t| t.describe());
    match end {
        Some(true) => app.confirm_transform(),
        Some(false) => app.cancel_transform(),
        None => {}
    }
    if app.tool.is_none() {
        app.ui.status.clear();
    }
}

/// Where the gesture's target sits on screen, and the view's scale there.
pub fn screen_frame(app: &RtApp) -> ScreenFrame {
    let scene = &app.doc.scene;
    let (Some(tool), Some(rect), Ok(basis)) =
        (&app.tool, app.ui.viewport_rect, scene.camera.basis())
    else {
        return ScreenFrame::default();
    };
    let centre = match &tool.target {
        ToolTarget::Object(i, _) => navigation::object_center(scene, *i),
        ToolTarget::Light(_, position, _) => Some(*position),
    }
    .unwrap_or(basis.origin - basis.w);
    let extent = app
        .doc
        .bounds()
        .map_or(1.0, |(lo, hi)| (hi - lo).max_element().max(1e-6));
    ScreenFrame {
        centre: tool
            .anchor
            .or_else(|| navigation::to_screen(&scene.camera, rect, centre)),
        // Behind the camera the pointer moves nothing.
        units_per_point: navigation::world_per_point(&scene.camera, rect, centre).unwrap_or(0.0),
        right: basis.u,
        up: basis.v,
        back: basis.w,
        grid_step: crate::preview::grid_step(extent),
    }
}

/// The gesture's end by the pointer: a click confirms (a handle's drag: its release), a right
/// click cancels.
pub fn pointer_ends(app: &mut RtApp, ui: &egui::Ui, response: &egui::Response) {
    let held = app.tool.as_ref().is_some_and(|t| t.held);
    if held {
        if ui.input(|i| !i.pointer.primary_down()) {
            app.confirm_transform();
        }
    } else if response.clicked_by(egui::PointerButton::Secondary) {
        app.cancel_transform();
    } else if response.clicked() {
        app.confirm_transform();
    }
}
