//! The menu bar and the file dialogs it opens.

use rt_io::SCENE_EXTENSIONS;
use rt_io::project::{LIGHTING_EXTENSION, PROJECT_EXTENSION};

use crate::app::RtApp;

fn scene_dialog() -> rfd::FileDialog {
    rfd::FileDialog::new()
        .add_filter(
            "Scenes and projects",
            &[SCENE_EXTENSIONS, &[LIGHTING_EXTENSION]].concat(),
        )
        .add_filter("rt project", &[PROJECT_EXTENSION])
        .add_filter("Wavefront OBJ", &["obj"])
        .add_filter("glTF 2.0", &["gltf", "glb"])
        .add_filter("rt lighting", &[LIGHTING_EXTENSION])
        .add_filter(
            "Rendered image (EXR: merged parts open with their samples)",
            &["exr"],
        )
}

pub fn open_dialog(app: &mut RtApp) {
    if let Some(path) = scene_dialog().pick_file() {
        app.open_path(&path);
    }
}

pub fn save_project(app: &mut RtApp) {
    match app.doc.project_path().map(|p| p.to_path_buf()) {
        Some(path) => {
            app.save_project_to(&path);
        }
        None => save_project_as(app),
    }
}

pub fn save_project_as(app: &mut RtApp) {
    if let Some(path) = rfd::FileDialog::new()
        .add_filter("rt project", &[PROJECT_EXTENSION])
        .set_file_name(format!("scene.{PROJECT_EXTENSION}"))
        .save_file()
    {
        app.save_project_to(&path);
    }
}

pub fn menu_bar(app: &mut RtApp, ui: &mut egui::Ui) {
    egui::MenuBar::new().ui(ui, |ui| {
        ui.menu_button("File", |ui| file_menu(app, ui));
        ui.menu_button("Edit", |ui| edit_menu(app, ui));
        ui.menu_button("View", |ui| view_menu(app, ui));
        ui.menu_button("Render", |ui| {
            if ui
                .button("Render image (F12)")
                .on_hover_text("Render with the settings in the Render panel")
                .clicked()
            {
                app.start_render();
            }
            if ui
                .add_enabled(
                    app.is_rendering(),
                    egui::Button::new("Cancel renders (Esc)"),
                )
                .on_hover_text("Stop every running render, keeping what it has")
                .clicked()
            {
                app.cancel_renders();
            }
        });
        ui.menu_button("Help", |ui| {
            ui.label(CONTROLS);
        });
    });
}

const CONTROLS: &str = "Viewport: left-drag pans, right-drag turns the camera (orbits the \
selection in orbit mode, O), middle-drag orbits, the wheel dollies, a click selects (a light \
by its mark).\n\
Move, rotate, scale the selection: G, R, S, then the pointer (X, Y or Z holds an axis; a typed \
number sets the amount; Ctrl snaps); a click or Enter confirms, Esc or a right click cancels. \
Dragging the selection's arrows, rings or squares moves, turns or scales it on that axis.\n\
Keys: Ctrl+O open, Ctrl+S save, Ctrl+Shift+S save as, Ctrl+Z undo, Ctrl+Shift+Z redo, \
F12 render, Esc cancel, Delete delete, Alt+D duplicate as instance, F frame selection, Home reset \
view, P path-traced viewport, L add a light. Files can be dropped on the window.";

fn file_menu(app: &mut RtApp, ui: &mut egui::Ui) {
    if ui
        .button("New scene")
        .on_hover_text("Start from an empty scene")
        .clicked()
    {
        app.new_scene();
    }
    if ui
        .button("Open… (Ctrl+O)")
        .on_hover_text("Open a Wavefront OBJ, an rt project or an rt lighting file")
        .clicked()
    {
        open_dialog(app);
    }
    ui.menu_button("Open recent", |ui| {
        if app.recent.paths.is_empty() {
            ui.label("(none yet)");
        }
        for path in app.recent.paths.clone() {
            if ui
                .button(path.display().to_string())
                .on_hover_text("Open this file again")
                .clicked()
                && !app.open_path(&path)
                && !path.exists()
            {
                app.recent.remove(&path);
            }
        }
    });
    if ui
        .button("Open the Cornell box")
        .on_hover_text("The built-in example scene")
        .clicked()
        && let Ok(scene) = rt_io::assets::cornell_box()
    {
        app.doc = crate::document::Document::new(scene, crate::document::Origin::Embedded);
        app.select_object(None);
    }
    ui.separator();
    if ui
        .button("Save project (Ctrl+S)")
        .on_hover_text("Save the whole scene, with meshes and textures, in one .rtproj file")
        .clicked()
    {
        save_project(app);
    }
    if ui
        .button("Save project as… (Ctrl+Shift+S)")
        .on_hover_text("Save the project under a new name")
        .clicked()
    {
        save_project_as(app);
    }
    ui.separator();
    if ui
        .button("Load lighting…")
        .on_hover_text(
            "Replace the ambient light, all lights and the fog with those of a .rtlight file",
        )
        .clicked()
        && let Some(path) = rfd::FileDialog::new()
            .add_filter("rt lighting", &[LIGHTING_EXTENSION])
            .pick_file()
    {
        app.open_path(&path);
    }
    if ui
        .button("Save lighting…")
        .on_hover_text("Save the ambient light, all lights and the fog to reuse in other projects")
        .clicked()
        && let Some(path) = rfd::FileDialog::new()
            .add_filter("rt lighting", &[LIGHTING_EXTENSION])
            .set_file_name(format!("lighting.{LIGHTING_EXTENSION}"))
            .save_file()
    {
        app.save_lighting_to(&path);
    }
    ui.separator();
    if ui.button("Quit").on_hover_text("Close rt").clicked() {
        ui.ctx().send_viewport_cmd(egui::ViewportCommand::Close);
    }
}

fn edit_menu(app: &mut RtApp, ui: &mut egui::Ui) {
    let undo = app
        .doc
        .undo_label()
        .map_or("Undo".to_string(), |l| format!("Undo {l}"));
    if ui
        .add_enabled(app.doc.undo_label().is_some(), egui::Button::new(undo))
        .on_hover_text("Ctrl+Z")
        .clicked()
    {
        app.undo();
    }
    let redo = app
        .doc
        .redo_label()
        .map_or("Redo".to_string(), |l| format!("Redo {l}"));
    if ui
        .add_enabled(app.doc.redo_label().is_some(), egui::Button::new(redo))
        .on_hover_text("Ctrl+Shift+Z")
        .clicked()
    {
        app.redo();
    }
    ui.separator();
    super::panels::add_area_light_buttons(app, ui, "Add quad light (L)");
    if ui
        .add_enabled(
            app.selection.is_some(),
            egui::Button::new("Duplicate as instance (Alt+D)"),
        )
        .on_hover_text(
            "A copy of the selected object that shares its mesh: stored once, however many copies",
        )
        .clicked()
        && let Some(index) = app.selection
    {
        app.duplicate_as_instance(index);
    }
    if ui
        .add_enabled(
            app.selection.is_some(),
            egui::Button::new("Delete selected (Del)"),
        )
        .on_hover_text("Delete the selected object (asks first)")
        .clicked()
    {
        app.ui.pending_delete = app.selection;
    }
}

fn view_menu(app: &mut RtApp, ui: &mut egui::Ui) {
    ui.checkbox(&mut app.live.enabled, "Path-traced viewport (P)")
        .on_hover_text(
            "Render the viewport progressively with the path tracer: coarse pixels at once after \
             a change, then finer, denoised",
        );
    ui.add_enabled(
        app.live.enabled,
        egui::Checkbox::new(&mut app.live.show_denoised, "Denoise the path-traced view"),
    )
    .on_hover_text("Show the denoised image (on) or the raw samples (off)");
    ui.checkbox(&mut app.ui.orbit_mode, "Orbit mode (O)")
        .on_hover_text("Right-drag orbits around the selection instead of turning the camera");
    if ui
        .button("Frame selection (F)")
        .on_hover_text("Move the camera so the selection (or the scene) fills the view")
        .clicked()
    {
        app.frame_selection();
    }
    if ui
        .button("Reset view (Home)")
        .on_hover_text("Return to the camera the scene was opened with")
        .clicked()
    {
        app.reset_view();
    }
}
