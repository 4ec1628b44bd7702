//! The editor's UI: one function per panel over [`RtApp`]'s state.

mod dialogs;
pub mod gizmo;
pub mod light_marks;
mod menu;
mod panels;
pub mod renders;
mod transform_keys;
mod viewport;

use egui::{Key, KeyboardShortcut, Modifiers};

use crate::app::{LightShape, RtApp};

pub use renders::{save as renders_save, tone_mapped};

impl eframe::App for RtApp {
    fn ui(&mut self, ui: &mut egui::Ui, _frame: &mut eframe::Frame) {
        self.draw(ui);
    }
}

impl RtApp {
    /// Draws one frame of the whole editor into `ui` (the window's root).
    pub fn draw(&mut self, ui: &mut egui::Ui) {
        let ctx = ui.ctx().clone();
        self.poll_jobs();
        self.handle_input(&ctx);
        // Only on change: each viewport command makes the window draw another frame, so sending
        // it every frame kept the editor redrawing continuously.
        let title = format!("rt — {}", self.doc.title());
        if self.ui.window_title.as_deref() != Some(title.as_str()) {
            ctx.send_viewport_cmd(egui::ViewportCommand::Title(title.clone()));
            self.ui.window_title = Some(title);
        }

        egui::Panel::top("menu").show(ui, |ui| menu::menu_bar(self, ui));
        egui::Panel::bottom("status").show(ui, |ui| panels::status_bar(self, ui));
        egui::Panel::left("scene")
            .resizable(true)
            .default_size(220.0)
            .show(ui, |ui| {
                egui::ScrollArea::vertical().show(ui, |ui| {
                    panels::objects_panel(self, ui);
                    ui.separator();
                    panels::lights_panel(self, ui);
                });
            });
        egui::Panel::right("inspector")
            .resizable(true)
            .default_size(300.0)
            .show(ui, |ui| {
                egui::ScrollArea::vertical().show(ui, |ui| {
                    panels::inspector_panel(self, ui);
                    ui.separator();
                    panels::camera_panel(self, ui);
                    ui.separator();
                    panels::render_panel(self, ui);
                });
            });
        egui::CentralPanel::default().show(ui, |ui| viewport::viewport(self, ui));

        renders::render_windows(self, &ctx);
        dialogs::dialogs(self, &ctx);

        if self.is_rendering() {
            ctx.request_repaint_after(std::time::Duration::from_millis(100));
        }
    }

    fn handle_input(&mut self, ctx: &egui::Context) {
        // One undo step per gesture: a drag or a typed value ends when the pointer is released or
        // Enter/Tab is pressed (a G/R/S gesture ends by its own rules).
        if self.tool.is_none()
            && ctx.input(|i| {
                i.pointer.any_released() || i.key_pressed(Key::Enter) || i.key_pressed(Key::Tab)
            })
        {
            self.doc.seal();
        }
        let dropped: Vec<_> = ctx.input(|i| i.raw.dropped_files.clone());
        if let Some(path) = dropped
            .iter()
            .find_map(|f| Some(f.path().to_path_buf()).filter(|p| !p.as_os_str().is_empty()))
        {
            self.open_path(&path);
        }

        let shortcut = |modifiers, key| {
            ctx.input_mut(|i| i.consume_shortcut(&KeyboardShortcut::new(modifiers, key)))
        };
        let command_shift = Modifiers::COMMAND | Modifiers::SHIFT;
        // Shifted shortcuts first: Ctrl+Shift+Z also matches Ctrl+Z.
        if shortcut(command_shift, Key::Z) || shortcut(Modifiers::COMMAND, Key::Y) {
            self.redo();
        }
        if shortcut(command_shift, Key::S) {
            menu::save_project_as(self);
        }
        if shortcut(Modifiers::COMMAND, Key::Z) {
            self.undo();
        }
        if shortcut(Modifiers::COMMAND, Key::S) {
            menu::save_project(self);
        }
        if shortcut(Modifiers::COMMAND, Key::O) {
            menu::open_dialog(self);
        }
        if shortcut(Modifiers::COMMAND, Key::R) || shortcut(Modifiers::NONE, Key::F12) {
            self.start_render();
        }
        // A G/R/S gesture takes the plain keys while it lasts.
        if self.tool.is_some() {
            transform_keys::drive(self, ctx);
            return;
        }
        // Plain keys only when no text field wants them.
        if ctx.egui_wants_keyboard_input() {
            return;
        }
        transform_keys::start(self, ctx);
        if self.tool.is_some() {
            return;
        }
        if shortcut(Modifiers::NONE, Key::Escape) {
            self.cancel_renders();
            self.ui.picking_focus = false;
        }
        if shortcut(Modifiers::NONE, Key::Delete) {
            self.ui.pending_delete = self.selection;
        }
        if shortcut(Modifiers::ALT, Key::D)
            && let Some(index) = self.selection
        {
            self.duplicate_as_instance(index);
        }
        if shortcut(Modifiers::NONE, Key::F) {
            self.frame_selection();
        }
        if shortcut(Modifiers::NONE, Key::Home) {
            self.reset_view();
        }
        if shortcut(Modifiers::NONE, Key::P) {
            self.live.enabled = !self.live.enabled;
        }
        if shortcut(Modifiers::NONE, Key::O) {
            self.ui.orbit_mode = !self.ui.orbit_mode;
        }
        if shortcut(Modifiers::NONE, Key::L) {
            self.add_light(LightShape::Quad);
        }
    }
}
