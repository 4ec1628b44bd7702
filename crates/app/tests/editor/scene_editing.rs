//! Opening, selecting, editing materials and lights, undo and redo, and the editor's defaults.

use super::*;
use egui_kittest::kittest::Queryable;
use rt_core::Material;

#[test]
fn the_cornell_box_opens_listed_and_previewed() {
    if !have_gpu() {
        return;
    }
    let mut harness = harness();
    harness.run_ok();
    assert!(harness.state().preview_available, "egui runs on wgpu");
    for name in ["floor", "tall_block", "short_block"] {
        harness.get_by_label(name);
    }
    harness.get_by_label("light");

    let image = harness.render().unwrap();
    let dir = std::path::Path::new(env!("CARGO_TARGET_TMPDIR"));
    image.save(dir.join("editor-cornell.png")).unwrap();
    // The viewport (between the side panels) shows the box: the red and green walls are there.
    let (w, h) = image.dimensions();
    let mut red = 0;
    let mut green = 0;
    for y in (h / 5..h * 4 / 5).step_by(4) {
        for x in (w / 4..w * 3 / 4).step_by(4) {
            let [r, g, b, _] = image.get_pixel(x, y).0;
            let (r, g, b) = (i32::from(r), i32::from(g), i32::from(b));
            if r > g + 40 && r > b + 40 {
                red += 1;
            }
            // The green wall takes the warm lamp's bounce light too, as in the render.
            if g > r + 15 && g > b + 40 {
                green += 1;
            }
        }
    }
    assert!(
        red > 50 && green > 50,
        "the preview should show the red and green walls: {red} red, {green} green samples \
         (screenshot in {})",
        dir.display()
    );
}

#[test]
fn select_change_material_undo_and_redo() {
    if !have_gpu() {
        return;
    }
    let mut harness = harness();
    harness.run_ok();
    harness.get_by_label("tall_block").click();
    harness.run_ok();
    let index = index_of(harness.state(), "tall_block");
    assert_eq!(harness.state().selection, Some(index));
    let original = harness.state().doc.scene.objects[index].material.clone();

    harness.get_by_label("Metal").click();
    harness.run_ok();
    assert!(matches!(
        harness.state().doc.scene.objects[index].material,
        Material::Metal { .. }
    ));

    harness.key_press_modifiers(egui::Modifiers::COMMAND, egui::Key::Z);
    harness.run_ok();
    assert_eq!(
        harness.state().doc.scene.objects[index].material,
        original,
        "Ctrl+Z restores the material"
    );
    harness.key_press_modifiers(
        egui::Modifiers::COMMAND | egui::Modifiers::SHIFT,
        egui::Key::Z,
    );
    harness.run_ok();
    assert!(matches!(
        harness.state().doc.scene.objects[index].material,
        Material::Metal { .. }
    ));

    harness.get_by_label("Glass").click();
    harness.run_ok();
    assert!(matches!(
        harness.state().doc.scene.objects[index].material,
        Material::Dielectric { .. }
    ));
}

#[test]
fn alt_d_duplicates_the_selection_as_an_instance_of_its_mesh() {
    if !have_gpu() {
        return;
    }
    let mut harness = harness();
    harness.run_ok();
    harness.get_by_label("tall_block").click();
    harness.run_ok();
    let index = index_of(harness.state(), "tall_block");
    let before = harness.state().doc.scene.objects.len();
    harness.key_press_modifiers(egui::Modifiers::ALT, egui::Key::D);
    harness.run_ok();
    let app = harness.state();
    assert_eq!(app.doc.scene.objects.len(), before + 1);
    let (original, copy) = (
        &app.doc.scene.objects[index],
        &app.doc.scene.objects[before],
    );
    assert!(std::sync::Arc::ptr_eq(&original.mesh, &copy.mesh));
    assert_ne!(original.transform, copy.transform, "the copy stands aside");
    assert_eq!(app.selection, Some(before), "the copy is selected");
    harness.get_by_label("mesh shared by 2 objects");
    harness.key_press_modifiers(egui::Modifiers::COMMAND, egui::Key::Z);
    harness.run_ok();
    assert_eq!(
        harness.state().doc.scene.objects.len(),
        before,
        "undo removes it"
    );
}

#[test]
fn add_a_light_then_delete_it_after_confirming() {
    if !have_gpu() {
        return;
    }
    let mut harness = harness();
    harness.run_ok();
    let before = harness.state().doc.scene.objects.len();
    harness.get_by_label("Add quad light").click();
    harness.run_ok();
    let app = harness.state();
    assert_eq!(app.doc.scene.objects.len(), before + 1);
    let added = app.doc.scene.objects.last().unwrap();
    assert!(matches!(added.material, Material::Emissive { .. }));
    assert_eq!(app.selection, Some(before), "the new light is selected");
    let name = added.name.clone();
    harness.get_by_label(&name);

    harness.get_by_label("Delete…").click();
    harness.run_ok();
    harness.get_by_label("Cancel").click();
    harness.run_ok();
    assert_eq!(
        harness.state().doc.scene.objects.len(),
        before + 1,
        "cancel keeps it"
    );

    harness.get_by_label("Delete…").click();
    harness.run_ok();
    harness.get_by_label("Delete").click();
    harness.run_ok();
    assert_eq!(harness.state().doc.scene.objects.len(), before);
    assert!(harness.query_by_label(&name).is_none());

    harness.key_press_modifiers(egui::Modifiers::COMMAND, egui::Key::Z);
    harness.run_ok();
    assert_eq!(
        harness.state().doc.scene.objects.len(),
        before + 1,
        "undo restores it"
    );
}

#[test]
fn add_edit_and_delete_point_spot_and_sun_lights() {
    if !have_gpu() {
        return;
    }
    let mut harness = harness();
    harness.run_ok();
    for (button, kind) in [
        ("Add point light", rt_core::LightKind::Point),
        ("Add spot light", rt_core::LightKind::Spot),
        ("Add sun", rt_core::LightKind::Directional),
    ] {
        harness.get_by_label(button).click();
        harness.run_ok();
        let app = harness.state();
        let light = app.doc.scene.lights.last().unwrap();
        assert_eq!(light.kind, kind);
        assert_eq!(app.selected_light, Some(app.doc.scene.lights.len() - 1));
        assert_eq!(app.selection, None, "selecting a light deselects objects");
        light.validate().unwrap();
    }
    assert_eq!(harness.state().doc.scene.lights.len(), 3);
    // The inspector edits the selected light (the sun): switch it to a point light.
    harness.get_by_label("Point").click();
    harness.run_ok();
    assert_eq!(
        harness.state().doc.scene.lights[2].kind,
        rt_core::LightKind::Point
    );
    harness.get_by_label("Delete light").click();
    harness.run_ok();
    assert_eq!(harness.state().doc.scene.lights.len(), 2);
    harness.key_press_modifiers(egui::Modifiers::COMMAND, egui::Key::Z);
    harness.run_ok();
    assert_eq!(
        harness.state().doc.scene.lights.len(),
        3,
        "undo brings it back"
    );
    // Lights render: a final render with them finishes.
    harness.state_mut().doc.edit("small", "small", |s| {
        s.settings.width = 16;
        s.settings.height = 16;
        s.settings.samples_per_pixel = 2;
    });
    harness.state_mut().start_render();
    step_until(&mut harness, "the render with delta lights", |app| {
        !app.is_rendering()
    });
    assert_eq!(harness.state().renders[0].job.state, JobState::Finished);
}

#[test]
fn a_physically_based_material_and_the_studio_environment_from_the_panels() {
    if !have_gpu() {
        return;
    }
    let mut harness = harness();
    harness.run_ok();
    harness.get_by_label("tall_block").click();
    harness.run_ok();
    let index = index_of(harness.state(), "tall_block");
    harness.get_by_label("Physically based").click();
    harness.run_ok();
    let Material::Pbr(p) = &harness.state().doc.scene.objects[index].material else {
        panic!("a PBR material expected")
    };
    assert_eq!(p.roughness, 0.5, "the default roughness");
    assert!(harness.state().doc.scene.environment.is_none());
    harness.get_by_label("Studio").click();
    harness.run_ok();
    let env = harness
        .state()
        .doc
        .scene
        .environment
        .as_ref()
        .expect("environment set");
    assert_eq!((env.map.width, env.map.height), (1024, 512));
    harness.get_by_label("None").click();
    harness.run_ok();
    assert!(harness.state().doc.scene.environment.is_none());
    harness.key_press_modifiers(egui::Modifiers::COMMAND, egui::Key::Z);
    harness.run_ok();
    assert!(
        harness.state().doc.scene.environment.is_some(),
        "removing the environment undoes"
    );
    harness.get_by_label("Sun and sky").click();
    harness.run_ok();
    let env = harness.state().doc.scene.environment.as_ref().unwrap();
    assert!(env.source.starts_with("sun and sky"), "{}", env.source);
    assert_eq!(env.strength, rt_core::sky::DAYLIGHT_STRENGTH);
}

/// The Lights panel's fog: "Add fog" fills the Cornell box with one mean free path across it
/// (saved with the scene's other light, undone in one step), and the render it starts has it.
#[test]
fn fog_from_the_lights_panel_and_undone() {
    if !have_gpu() {
        return;
    }
    let mut harness = harness();
    harness.run_ok();
    assert!(!harness.state().doc.scene.fog.is_on());
    harness.get_by_label("Add fog").click();
    harness.run_ok();
    let fog = harness.state().doc.scene.fog;
    let (lo, hi) = harness.state().doc.scene.bounds().unwrap();
    assert!(
        (fog.density * (hi - lo).max_element() - 1.0).abs() < 1e-4,
        "{fog:?}"
    );
    assert!(fog.validate().is_ok());
    harness.get_by_label_contains("light travels");
    harness.key_press_modifiers(egui::Modifiers::COMMAND, egui::Key::Z);
    harness.run_ok();
    assert!(!harness.state().doc.scene.fog.is_on(), "adding fog undoes");
}

#[test]
fn a_bare_model_is_lit_by_the_default_environment() {
    let mut scene = rt_core::Scene::default();
    rt_app::app::light_with_the_default_environment(&mut scene);
    assert!(scene.environment.is_some());
    let mut lit = rt_io::assets::cornell_box().unwrap();
    rt_app::app::light_with_the_default_environment(&mut lit);
    assert!(
        lit.environment.is_none(),
        "a scene with emitters keeps its own light"
    );
}

/// The editor's own defaults, on top of the loader all callers share, apply to models only: an OBJ
/// without light gets the studio and a max depth from its materials, a glTF (whose loader decides
/// its light) only the depth, and a project stays exactly as saved.
#[test]
fn editor_defaults_apply_to_models_not_projects() {
    use rt_app::app::apply_editor_defaults;
    use rt_io::SceneFormat;
    let bare = rt_core::Scene::default();
    assert_eq!(bare.settings.max_depth, 8);
    let mut obj = bare.clone();
    apply_editor_defaults(&mut obj, SceneFormat::Obj);
    assert!(obj.environment.is_some());
    assert_eq!(obj.settings.max_depth, 5, "diffuse (here: nothing) needs 5");
    let mut gltf = bare.clone();
    apply_editor_defaults(&mut gltf, SceneFormat::Gltf);
    assert!(gltf.environment.is_none());
    assert_eq!(gltf.settings.max_depth, 5);
    let mut project = bare.clone();
    apply_editor_defaults(&mut project, SceneFormat::Project);
    assert_eq!(project, bare);
}

/// Blender's keys: G, X and a typed 120 move the selected block 120 along X, one undo step that
/// Ctrl+Z takes back; R, Y, 90 turns it a quarter about Y; S, 2 doubles it; G, Z, 50 and Esc
/// leave it where it was with nothing to undo; G then the pointer moves it in the view plane, as
/// far as the pointer went at the block's depth, and a click puts it down (selecting nothing else).
#[test]
fn g_r_and_s_keys_move_turn_and_scale_the_selection() {
    use egui::Key;
    if !have_gpu() {
        return;
    }
    let mut harness = harness();
    harness.run_ok();
    harness.get_by_label("tall_block").click();
    harness.run_ok();
    let index = index_of(harness.state(), "tall_block");
    let original = harness.state().doc.scene.objects[index].transform.clone();
    let transform = |h: &Harness<'_, RtApp>| h.state().doc.scene.objects[index].transform.clone();
    let gesture = |h: &mut Harness<'_, RtApp>, keys: &[Key], typed: &str, end: Key| {
        for key in keys {
            h.key_press(*key);
            h.step();
        }
        h.event(egui::Event::Text(typed.into()));
        h.step();
        h.key_press(end);
        h.run_ok();
    };

    gesture(&mut harness, &[Key::G, Key::X], "120", Key::Enter);
    let moved = transform(&harness);
    assert_eq!(moved.translation[0], original.translation[0] + 120.0);
    assert_eq!(moved.translation[1..], original.translation[1..]);
    assert!(harness.state().tool.is_none());
    assert_eq!(harness.state().doc.undo_label(), Some("move"));
    harness.key_press_modifiers(egui::Modifiers::COMMAND, Key::Z);
    harness.run_ok();
    assert_eq!(
        transform(&harness),
        original,
        "one undo step takes the move back"
    );

    gesture(&mut harness, &[Key::R, Key::Y], "90", Key::Enter);
    let turned = transform(&harness).rotation_deg;
    assert!(
        (turned[1] - (original.rotation_deg[1] + 90.0)).abs() < 1e-3,
        "{turned:?}"
    );
    gesture(&mut harness, &[Key::S], "2", Key::Enter);
    assert_eq!(transform(&harness).scale, original.scale.map(|s| s * 2.0));
    let before = transform(&harness);
    let undo_label = harness.state().doc.undo_label().map(str::to_owned);
    gesture(&mut harness, &[Key::G, Key::Z], "50", Key::Escape);
    assert_eq!(transform(&harness), before, "Esc cancels");
    assert_eq!(
        harness.state().doc.undo_label().map(str::to_owned),
        undo_label
    );

    // The turn and the scaling were about the block's origin (the world's: its vertices are
    // placed in the box), which took it out of view; undo both.
    for _ in 0..2 {
        harness.key_press_modifiers(egui::Modifiers::COMMAND, Key::Z);
        harness.run_ok();
    }
    let before = transform(&harness);
    assert_eq!(before, original);

    // By the pointer: over the viewport, G, then 80 points to the right, then a click.
    let rect = harness
        .state()
        .ui
        .viewport_rect
        .expect("the viewport was drawn");
    let start = rect.center();
    harness.hover_at(start);
    harness.step();
    harness.key_press(Key::G);
    harness.step();
    let end = start + egui::vec2(80.0, 0.0);
    harness.hover_at(end);
    harness.step();

    harness.drag_at(end);
    harness.step();
    harness.drop_at(end);
    harness.run_ok();
    assert!(harness.state().tool.is_none());
    assert_eq!(
        harness.state().selection,
        Some(index),
        "the click only put it down"
    );
    let dragged = transform(&harness);
    let camera = &harness.state().doc.scene.camera;
    let right = camera.basis().unwrap().u;
    let shift = glam::Vec3::from(dragged.translation) - glam::Vec3::from(before.translation);
    // 80 points at the block's depth: 80 × 2 d tan(fov/2) / the viewport's height.
    let basis = camera.basis().unwrap();
    let centre = rt_app::navigation::object_center(&harness.state().doc.scene, index).unwrap();
    let depth = (centre - basis.origin).dot(-basis.w);
    let expected = 80.0 * 2.0 * depth * basis.tan_half_vfov / rect.height();
    assert!(
        (shift.dot(right) - expected).abs() < 0.02 * expected
            && shift.dot(right) > 0.999 * shift.length(),
        "the block follows the pointer to the right: {shift}, expected {expected} along {right}"
    );
}

/// The handles: dragging the selected block's X arrow moves it along X only, toward where the
/// arrow points, without moving the camera; its X square stretches it along X; its Y ring turns
/// it about Y; Ctrl+Z takes each back.
#[test]
fn dragging_a_move_handle_moves_the_selection_along_its_axis() {
    if !have_gpu() {
        return;
    }
    let mut harness = harness();
    harness.run_ok();
    harness.get_by_label("short_block").click();
    harness.run_ok();
    let index = index_of(harness.state(), "short_block");
    let original = harness.state().doc.scene.objects[index].transform.clone();
    let camera = harness.state().doc.scene.camera.clone();
    let rect = harness
        .state()
        .ui
        .viewport_rect
        .expect("the viewport was drawn");
    let handles = rt_app::ui::gizmo::handles(harness.state(), rect);
    assert_eq!(handles.len(), 3, "three arrows on the selection");
    let (_, base, tip) = handles[0];
    let grab = base + (tip - base) * 0.7;
    let image = harness.render().unwrap();
    image
        .save(std::path::Path::new(env!("CARGO_TARGET_TMPDIR")).join("editor-move-handles.png"))
        .unwrap();
    let [r, g, b, _] = image
        .get_pixel(grab.x.round() as u32, grab.y.round() as u32)
        .0;
    assert!(
        r > 180 && g < 120 && b < 120,
        "the X arrow is drawn red: {r} {g} {b}"
    );
    let step = (tip - base).normalized() * 10.0;
    harness.drag_at(grab);
    harness.step();
    for k in 1..=5 {
        harness.hover_at(grab + step * k as f32);
        harness.step();
    }
    harness.drop_at(grab + step * 5.0);
    harness.run_ok();
    assert!(harness.state().tool.is_none(), "the release ends the move");
    let moved = harness.state().doc.scene.objects[index].transform.clone();
    assert!(
        moved.translation[0] > original.translation[0] + 1.0,
        "{:?} -> {:?}",
        original.translation,
        moved.translation
    );
    assert_eq!(moved.translation[1..], original.translation[1..]);
    assert_eq!(harness.state().doc.scene.camera, camera, "no pan");
    harness.key_press_modifiers(egui::Modifiers::COMMAND, egui::Key::Z);
    harness.run_ok();
    assert_eq!(harness.state().doc.scene.objects[index].transform, original);

    // The X scale square, dragged outwards, stretches it along X alone.
    let drag = |harness: &mut Harness<'_, RtApp>, from: egui::Pos2, by: egui::Vec2| {
        harness.drag_at(from);
        harness.step();
        for k in 1..=4 {
            harness.hover_at(from + by * (k as f32 / 4.0));
            harness.step();
        }
        harness.drop_at(from + by);
        harness.run_ok();
    };
    let (_, square) = rt_app::ui::gizmo::boxes(harness.state(), rect)[0];
    drag(&mut harness, square, (square - base).normalized() * 40.0);
    let scaled = harness.state().doc.scene.objects[index].transform.scale;
    assert!(scaled[0] > 1.2 && scaled[1..] == [1.0, 1.0], "{scaled:?}");
    harness.key_press_modifiers(egui::Modifiers::COMMAND, egui::Key::Z);
    harness.run_ok();

    // The Y ring, dragged along itself, turns it about Y alone.
    let ring = rt_app::ui::gizmo::rings(harness.state(), rect)
        .into_iter()
        .find(|(axis, _)| *axis == 1)
        .unwrap()
        .1;
    let (k, from) = (ring.iter().enumerate())
        .find(|(_, p)| {
            rt_app::ui::gizmo::hit(harness.state(), rect, **p)
                == Some((rt_app::app::transform_tool::ToolKind::Rotate, 1))
                && p.distance(base) > 30.0
        })
        .map(|(k, p)| (k, *p))
        .expect("a point of the Y ring grabs it");
    let along = (ring[(k + 3) % ring.len()] - ring[k]).normalized() * 30.0;
    drag(&mut harness, from, along);
    let turned = harness.state().doc.scene.objects[index]
        .transform
        .rotation_deg;
    assert!(
        turned[1].abs() > 5.0 && turned[0].abs() < 1e-3 && turned[2].abs() < 1e-3,
        "{turned:?}"
    );
    harness.key_press_modifiers(egui::Modifiers::COMMAND, egui::Key::Z);
    harness.run_ok();
    assert_eq!(harness.state().doc.scene.objects[index].transform, original);
}

/// The material gallery: opened, it shows the presets' thumbnails as rt renders them; clicking
/// Gold gives the selected block the gold preset, one undo step.
#[test]
fn picking_a_preset_from_the_gallery() {
    if !have_gpu() {
        return;
    }
    let mut harness = harness();
    harness.run_ok();
    harness.get_by_label("tall_block").click();
    harness.run_ok();
    let index = index_of(harness.state(), "tall_block");
    let original = harness.state().doc.scene.objects[index].material.clone();
    harness.get_by_label("Gallery").click();
    harness.run_ok();
    step_until(&mut harness, "the thumbnails", |app| {
        app.gallery.ready() == rt_app::presets::PRESETS.len()
    });
    harness.run_ok();
    // Below the material's sections: clicked as a screen reader would, wherever it has scrolled.
    harness.get_by_label("Gold").click_accesskit();
    harness.run_ok();
    let gold = rt_app::presets::PRESETS
        .iter()
        .find(|p| p.name == "Gold")
        .unwrap();
    // The colour field hands the albedo back through its own conversion: equal to 1e-5.
    let (Material::Metal { albedo, fuzz }, Material::Metal { albedo: a, fuzz: f }) = (
        harness.state().doc.scene.objects[index].material.clone(),
        (gold.material)(),
    ) else {
        panic!("gold is a metal")
    };
    assert!((0..3).all(|c| (albedo[c] - a[c]).abs() < 1e-5) && fuzz == f);
    harness.key_press_modifiers(egui::Modifiers::COMMAND, egui::Key::Z);
    harness.run_ok();
    assert_eq!(harness.state().doc.scene.objects[index].material, original);
    let image = harness.render().unwrap();
    image
        .save(std::path::Path::new(env!("CARGO_TARGET_TMPDIR")).join("editor-gallery.png"))
        .unwrap();
}

/// The Inspector shows one physically based material in sections whatever the kind; looking at a
/// Lambertian object leaves it Lambertian, and the old kinds are presets to start from.
#[test]
fn the_inspector_shows_one_sectioned_material_and_presets() {
    if !have_gpu() {
        return;
    }
    let mut harness = harness();
    harness.run_ok();
    harness.get_by_label("tall_block").click();
    harness.run_ok();
    let index = index_of(harness.state(), "tall_block");
    let before = harness.state().doc.scene.objects[index].material.clone();
    assert!(matches!(before, Material::Lambertian { .. }));
    for section in [
        "Base",
        "Specular",
        "Transmission",
        "Coat",
        "Sheen",
        "Emission",
        "Alpha",
    ] {
        harness.get_by_label(section);
    }
    harness.get_by_label("Start from");
    harness.run_ok();
    assert_eq!(
        harness.state().doc.scene.objects[index].material,
        before,
        "showing a material does not change it"
    );
    // Opening a section shows its fields.
    harness.get_by_label("Coat").click();
    harness.run_ok();
    assert!(harness.get_all_by_label("clear coat").next().is_some());
    // An edit makes the material physically based, keeping the colour, in one undo step.
    let Material::Lambertian { albedo, .. } = before else {
        unreachable!()
    };
    harness
        .get_by_role_and_label(egui::accesskit::Role::Slider, "roughness")
        .set_value_accesskit(0.3);
    harness.run_ok();
    let Material::Pbr(p) = &harness.state().doc.scene.objects[index].material else {
        panic!("a physically based material after the edit")
    };
    assert_eq!((p.roughness, p.base_color, p.specular), (0.3, albedo, 0.0));
    harness.key_press_modifiers(egui::Modifiers::COMMAND, egui::Key::Z);
    harness.run_ok();
    assert_eq!(harness.state().doc.scene.objects[index].material, before);
}
