//! The scene being edited, where it came from, and its undo history.
//!
//! Every edit goes through [`Document::edit`], which snapshots the scene first. Snapshots are cheap
//! because meshes and texels are shared (`Arc`), so undo covers every kind of edit uniformly.

use std::cell::Cell;
use std::path::{Path, PathBuf};

use glam::Vec3;

use rt_core::{Material, Scene};

/// World-space axis-aligned bounds; `None` for an empty scene.
pub type Bounds = Option<(Vec3, Vec3)>;

/// How many edits can be undone.
const HISTORY_LIMIT: usize = 200;

struct Step {
    label: String,
    /// Edits with the same key merge into one step until the step is sealed (a drag of a slider is
    /// one undo step, not one per frame).
    key: String,
    before: Scene,
}

/// What was loaded or saved last.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum Origin {
    /// The scene compiled into the binary.
    Embedded,
    /// A model file: OBJ, glTF, PLY or STL (saving writes a project elsewhere).
    Obj(PathBuf),
    /// A project file (saving writes back to it).
    Project(PathBuf),
    /// Built from nothing.
    New,
}

pub struct Document {
    pub scene: Scene,
    pub origin: Origin,
    /// The camera the scene was opened with ("reset view" returns to it).
    pub initial_camera: rt_core::Camera,
    /// Bumped by every change, so that views can tell when to refresh (the path-traced viewport
    /// restarts on it).
    revision: u64,
    /// Bumped only when objects change: bounds and other geometry-derived values are cached on it
    /// (camera moves, the most frequent edit, leave it alone).
    geometry_revision: u64,
    bounds_cache: Cell<Option<(u64, Bounds)>>,
    saved_revision: u64,
    undo: Vec<Step>,
    redo: Vec<Step>,
    sealed: bool,
}

impl Document {
    pub fn new(scene: Scene, origin: Origin) -> Self {
        Document {
            initial_camera: scene.camera.clone(),
            scene,
            origin,
            revision: 0,
            geometry_revision: 0,
            bounds_cache: Cell::new(None),
            saved_revision: 0,
            undo: Vec::new(),
            redo: Vec::new(),
            sealed: true,
        }
    }

    pub fn revision(&self) -> u64 {
        self.revision
    }

    /// World-space bounds of the scene, cached until an object changes.
    pub fn bounds(&self) -> Bounds {
        if let Some((revision, bounds)) = self.bounds_cache.get()
            && revision == self.geometry_revision
        {
            return bounds;
        }
        let bounds = self.scene.bounds();
        self.bounds_cache
            .set(Some((self.geometry_revision, bounds)));
        bounds
    }

    pub fn geometry_revision(&self) -> u64 {
        self.geometry_revision
    }

    pub fn is_dirty(&self) -> bool {
        self.revision != self.saved_revision
    }

    pub fn mark_saved(&mut self, origin: Origin) {
        self.origin = origin;
        self.saved_revision = self.revision;
    }

    pub fn project_path(&self) -> Option<&Path> {
        match &self.origin {
            Origin::Project(p) => Some(p),
            _ => None,
        }
    }

    pub fn title(&self) -> String {
        let name = match &self.origin {
            Origin::Embedded => "Cornell box (built in)".to_string(),
            Origin::New => "untitled".to_string(),
            Origin::Obj(p) | Origin::Project(p) => p
                .file_name()
                .map(|n| n.to_string_lossy().into_owned())
                .unwrap_or_else(|| p.display().to_string()),
        };
        if self.is_dirty() {
            format!("{name} *")
        } else {
            name
        }
    }

    /// Applies `change` as an undoable step named `label`. Consecutive edits with the same `key`
    /// merge until [`Document::seal`]; a change that leaves the scene as it was records nothing.
    pub fn edit(&mut self, label: &str, key: &str, change: impl FnOnce(&mut Scene)) {
        let before = self.scene.clone();
        change(&mut self.scene);
        if same_scene(&self.scene, &before) {
            return;
        }
        // The environment's texels and sampling table live in the GPU scene as the lights do.
        if !same_objects(&self.scene, &before)
            || self.scene.lights != before.lights
            || !same_environment(&self.scene, &before)
        {
            self.geometry_revision += 1;
        }
        let merges = !self.sealed && self.undo.last().is_some_and(|s| s.key == key);
        if !merges {
            self.undo.push(Step {
                label: label.to_string(),
                key: key.to_string(),
                before,
            });
            if self.undo.len() > HISTORY_LIMIT {
                self.undo.remove(0);
            }
        }
        self.redo.clear();
        self.sealed = false;
        self.revision += 1;
    }

    /// Drops the open (unsealed) step of edits with `key`, if it is the last, restoring the scene
    /// from before it: a cancelled gesture leaves no trace.
    pub fn abandon(&mut self, key: &str) {
        if self.sealed || self.undo.last().is_none_or(|s| s.key != key) {
            return;
        }
        if let Some(step) = self.undo.pop() {
            self.scene = step.before;
            self.sealed = true;
            self.revision += 1;
            self.geometry_revision += 1;
        }
    }

    /// Ends the current merge group: the next edit starts a new undo step.
    pub fn seal(&mut self) {
        self.sealed = true;
    }

    pub fn undo_label(&self) -> Option<&str> {
        self.undo.last().map(|s| s.label.as_str())
    }

    pub fn redo_label(&self) -> Option<&str> {
        self.redo.last().map(|s| s.label.as_str())
    }

    pub fn undo(&mut self) -> bool {
        let Some(step) = self.undo.pop() else {
            return false;
        };
        let after = std::mem::replace(&mut self.scene, step.before);
        self.redo.push(Step {
            before: after,
            ..step
        });
        self.sealed = true;
        self.revision += 1;
        self.geometry_revision += 1;
        true
    }

    pub fn redo(&mut self) -> bool {
        let Some(step) = self.redo.pop() else {
            return false;
        };
        let before = std::mem::replace(&mut self.scene, step.before);
        self.undo.push(Step { before, ..step });
        self.sealed = true;
        self.revision += 1;
        self.geometry_revision += 1;
        true
    }

    pub fn has_metal_or_glass(&self) -> bool {
        self.scene.objects.iter().any(|o| {
            matches!(
                o.material,
                Material::Metal { .. } | Material::Dielectric { .. }
            )
        })
    }
}

/// Scene equality that compares shared meshes and texels by identity: edits never change a mesh
/// in place, and comparing a million-triangle mesh on every slider move would stall the UI.
fn same_scene(a: &Scene, b: &Scene) -> bool {
    let same_textures = a.textures.len() == b.textures.len()
        && a.textures
            .iter()
            .zip(&b.textures)
            .all(|(x, y)| x.name == y.name && std::sync::Arc::ptr_eq(&x.rgba8, &y.rgba8));
    same_objects(a, b)
        && same_textures
        && a.camera == b.camera
        && a.ambient == b.ambient
        && a.fog == b.fog
        && a.settings == b.settings
        && a.lights == b.lights
        && same_environment(a, b)
}

/// Same file, rotation and strength, and the same texels in memory (not compared texel by texel).
fn same_environment(a: &Scene, b: &Scene) -> bool {
    match (&a.environment, &b.environment) {
        (None, None) => true,
        (Some(x), Some(y)) => {
            x.source == y.source
                && x.rotation_deg == y.rotation_deg
                && x.strength == y.strength
                && std::sync::Arc::ptr_eq(&x.map, &y.map)
        }
        _ => false,
    }
}

fn same_objects(a: &Scene, b: &Scene) -> bool {
    a.objects.len() == b.objects.len()
        && a.objects.iter().zip(&b.objects).all(|(x, y)| {
            // Every field named, so that one added to `Object` cannot be left out of the
            // comparison (an edit of it would record no undo step and reach no view).
            let rt_core::Object {
                name,
                mesh,
                material,
                transform,
                shadow_catcher,
                animation_node,
            } = x;
            *name == y.name
                && *animation_node == y.animation_node
                && *material == y.material
                && *transform == y.transform
                && *shadow_catcher == y.shadow_catcher
                && std::sync::Arc::ptr_eq(mesh, &y.mesh)
        })
}

/// The path length the seed project recommended: 5 for diffuse scenes, 10 with metal or glass,
/// whose specular chains need more bounces.
pub fn recommended_max_depth(scene: &Scene) -> u32 {
    let specular = scene.objects.iter().any(|o| {
        matches!(
            o.material,
            Material::Metal { .. } | Material::Dielectric { .. }
        )
    });
    if specular { 10 } else { 5 }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn doc() -> Document {
        Document::new(
            rt_io::assets::cornell_box().expect("embedded scene"),
            Origin::Embedded,
        )
    }

    #[test]
    fn edits_undo_and_redo_exactly() {
        let mut doc = doc();
        let original = doc.scene.clone();
        doc.edit("ambient", "ambient", |s| s.ambient = [1.0, 0.0, 0.0]);
        doc.seal();
        doc.edit("rename", "name#0", |s| s.objects[0].name = "x".into());
        let edited = doc.scene.clone();
        assert!(doc.is_dirty());
        assert!(doc.undo());
        assert_eq!(doc.scene.objects[0].name, original.objects[0].name);
        assert_eq!(doc.scene.ambient, [1.0, 0.0, 0.0]);
        assert!(doc.undo());
        assert_eq!(doc.scene, original);
        assert!(!doc.undo(), "nothing left to undo");
        assert!(doc.redo() && doc.redo());
        assert_eq!(doc.scene, edited);
        assert!(!doc.redo());
    }

    #[test]
    fn every_part_of_the_scene_is_undoable() {
        let mut doc = doc();
        let original = doc.scene.clone();
        let light = rt_core::Light::new(rt_core::LightKind::Point, "p");
        doc.edit("light", "light", |s| s.lights.push(light));
        doc.seal();
        doc.edit("clamp", "clamp", |s| s.settings.clamp = Some(2.0));
        doc.seal();
        doc.edit("lens", "lens", |s| s.camera.aperture_radius = 1.0);
        assert_eq!(doc.undo_label(), Some("lens"));
        assert!(doc.undo() && doc.undo() && doc.undo());
        assert_eq!(doc.scene, original);
    }

    #[test]
    fn same_key_edits_merge_until_sealed() {
        let mut doc = doc();
        let original = doc.scene.clone();
        for i in 0..10 {
            doc.edit("move", "translate#0", |s| {
                s.objects[0].transform.translation[0] = i as f32 + 1.0
            });
        }
        doc.seal();
        doc.edit("move", "translate#0", |s| {
            s.objects[0].transform.translation[0] = 50.0
        });
        assert!(doc.undo());
        assert_eq!(doc.scene.objects[0].transform.translation[0], 10.0);
        assert!(doc.undo());
        assert_eq!(doc.scene, original);
    }

    #[test]
    fn a_new_edit_clears_redo_and_no_op_edits_record_nothing() {
        let mut doc = doc();
        doc.edit("noop", "noop", |_| {});
        assert!(doc.undo_label().is_none());
        assert!(!doc.is_dirty());
        doc.edit("a", "a", |s| s.ambient = [0.5; 3]);
        doc.undo();
        assert_eq!(doc.redo_label(), Some("a"));
        doc.edit("b", "b", |s| s.ambient = [0.25; 3]);
        assert!(doc.redo_label().is_none());
    }
}
