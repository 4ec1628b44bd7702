//! Editing actions of the editor: undo and redo, selection, adding and deleting objects and lights,
//! and framing or resetting the view. Each change is an undoable edit of the document.

use std::sync::Arc;

use glam::Vec3;
use rt_core::{Material, Object, Transform};

use super::{LightShape, RtApp};

impl RtApp {
    pub fn undo(&mut self) {
        if self.doc.undo() {
            self.clamp_selection();
        }
    }

    pub fn redo(&mut self) {
        if self.doc.redo() {
            self.clamp_selection();
        }
    }

    fn clamp_selection(&mut self) {
        if self
            .selection
            .is_some_and(|s| s >= self.doc.scene.objects.len())
        {
            self.selection = None;
        }
        if self
            .selected_light
            .is_some_and(|s| s >= self.doc.scene.lights.len())
        {
            self.selected_light = None;
        }
    }

    pub fn select_object(&mut self, index: Option<usize>) {
        self.selection = index;
        self.selected_light = None;
    }

    pub fn select_light(&mut self, index: Option<usize>) {
        self.selected_light = index;
        self.selection = None;
    }

    /// Adds a point, spot or directional light, placed and sized for the scene, and selects it.
    /// Point and spot lights go above the scene's centre by its size, pointing down, with an
    /// intensity that lights the centre about as brightly as a sky of radiance 1 would.
    pub fn add_delta_light(&mut self, kind: rt_core::LightKind) {
        let (center, size) = match self.doc.bounds() {
            Some((lo, hi)) => ((lo + hi) * 0.5, (hi - lo).max_element().max(1e-3)),
            None => (Vec3::ZERO, 1.0),
        };
        let count = self
            .doc
            .scene
            .lights
            .iter()
            .filter(|l| l.kind == kind)
            .count();
        let mut light = rt_core::Light::new(kind, &format!("{} {}", kind.noun(), count + 1));
        light.position = (center + Vec3::Y * size * 0.45).to_array();
        // E = I/h² below the light; a sky of radiance 1 gives E = π.
        let h = size * 0.45;
        light.intensity = match kind {
            rt_core::LightKind::Directional => std::f32::consts::PI,
            _ => std::f32::consts::PI * h * h,
        };
        if kind == rt_core::LightKind::Directional {
            light.direction = Vec3::new(0.3, -1.0, 0.2).normalize().to_array();
        }
        self.doc
            .edit("add light", "add light", |s| s.lights.push(light));
        self.doc.seal();
        self.select_light(Some(self.doc.scene.lights.len() - 1));
    }

    pub fn delete_delta_light(&mut self, index: usize) {
        if index >= self.doc.scene.lights.len() {
            return;
        }
        self.doc.edit("delete light", "delete light", |s| {
            s.lights.remove(index);
        });
        self.doc.seal();
        self.selected_light = None;
    }

    /// Adds an emissive box or quad at the centre of the scene (the origin in an empty scene),
    /// sized to a tenth of the scene, and selects it.
    pub fn add_light(&mut self, shape: LightShape) {
        let (center, size) = match self.doc.bounds() {
            Some((lo, hi)) => ((lo + hi) * 0.5, (hi - lo).max_element().max(1e-3) * 0.1),
            None => (Vec3::ZERO, 1.0),
        };
        let (name, mesh) = match shape {
            // Unit shapes; the transform places and sizes them so the fields read naturally.
            LightShape::Box => (
                "box light",
                rt_core::shapes::cuboid(Vec3::splat(-0.5), Vec3::splat(0.5), false),
            ),
            // Facing down: a ceiling panel.
            LightShape::Quad => (
                "quad light",
                rt_core::shapes::quad(Vec3::ZERO, Vec3::NEG_Y, 1.0),
            ),
        };
        let count = self
            .doc
            .scene
            .objects
            .iter()
            .filter(|o| matches!(o.material, Material::Emissive { .. }))
            .count();
        let object = Object {
            shadow_catcher: false,
            animation_node: None,
            name: format!("{name} {}", count + 1),
            mesh: Arc::new(mesh),
            material: Material::Emissive {
                color: [1.0; 3],
                intensity: 10.0,
            },
            transform: Transform {
                translation: center.to_array(),
                rotation_deg: [0.0; 3],
                scale: [size; 3],
            },
        };
        self.doc
            .edit("add light", "add light", |s| s.objects.push(object));
        self.doc.seal();
        self.select_object(Some(self.doc.scene.objects.len() - 1));
    }

    /// Adds a copy of object `index` that shares its mesh (Blender's linked duplicate, Alt+D): an
    /// instance, whose triangles are stored once however many copies there are. It stands a
    /// tenth of the scene to the side (+x) and is selected, for the gizmo to move on.
    pub fn duplicate_as_instance(&mut self, index: usize) {
        let Some(original) = self.doc.scene.objects.get(index) else {
            return;
        };
        let step = self
            .doc
            .bounds()
            .map_or(1.0, |(lo, hi)| (hi - lo).max_element().max(1e-3) * 0.1);
        let mut copy = original.clone();
        copy.transform.translation[0] += step;
        let sharing = (self.doc.scene.objects.iter())
            .filter(|o| Arc::ptr_eq(&o.mesh, &original.mesh))
            .count();
        copy.name = format!("{} {}", original.name, sharing + 1);
        self.doc
            .edit("duplicate as instance", "duplicate as instance", |s| {
                s.objects.push(copy)
            });
        self.doc.seal();
        self.select_object(Some(self.doc.scene.objects.len() - 1));
    }

    pub fn delete_object(&mut self, index: usize) {
        if index >= self.doc.scene.objects.len() {
            return;
        }
        self.doc.edit("delete object", "delete object", |s| {
            s.objects.remove(index);
        });
        self.doc.seal();
        self.selection = None;
    }

    /// Points the camera at the selection (or the whole scene), keeping the view direction.
    pub fn frame_selection(&mut self) {
        let bounds = match self.selection {
            Some(i) => crate::navigation::object_bounds(&self.doc.scene, i),
            None => self.doc.bounds(),
        };
        if let Some((lo, hi)) = bounds {
            self.doc.edit("frame selection", "frame selection", |s| {
                s.camera.frame_bounds(lo, hi)
            });
            self.doc.seal();
        }
    }

    pub fn reset_view(&mut self) {
        let camera = self.doc.initial_camera.clone();
        self.doc
            .edit("reset view", "reset view", |s| s.camera = camera);
        self.doc.seal();
    }
}
