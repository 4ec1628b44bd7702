//! Side panels: the object and light lists, the inspector (material, transform), the camera and the
//! render settings, and the status bar. Each edits a copy and commits it as one undoable edit.
//!
//! One file per panel: `objects.rs`, `lights.rs` (and the environment; `fog.rs` its fog rows), `inspector.rs` (the
//! selected object or light) with its material editing in `material.rs`, `camera.rs`,
//! `render.rs` and `status.rs`. The helpers several of them share live here.

mod camera;
mod fog;
mod inspector;
mod lights;
mod material;
mod objects;
mod render;
mod status;

use egui::{DragValue, Ui};
use rt_core::{Material, Object};

pub use camera::camera_panel;
pub use inspector::inspector_panel;
pub use lights::{add_area_light_buttons, lights_panel};
pub use objects::objects_panel;
pub use render::render_panel;
pub use status::status_bar;

/// Whether an object is a light (an emissive mesh): listed in the Lights panel, not in Objects.
fn is_light(o: &Object) -> bool {
    matches!(o.material, Material::Emissive { .. })
}

/// A labelled row of three number fields (x, y, z) dragged at `speed`.
fn vec3_row(ui: &mut Ui, label: &str, v: &mut [f32; 3], speed: f32, tip: &str) {
    ui.horizontal(|ui| {
        ui.label(label).on_hover_text(tip);
        for (c, axis) in v.iter_mut().zip(["x", "y", "z"]) {
            ui.add(DragValue::new(c).speed(speed).prefix(format!("{axis} ")))
                .on_hover_text(format!("{label} {axis}"));
        }
    });
}
