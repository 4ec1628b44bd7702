//! The node hierarchy: each node's world transform, its mesh primitives as objects, the first
//! perspective camera and its punctual light.

use glam::{Mat4, Vec3};

use super::Loader;
use super::lights::light_of;
use rt_core::posing::placed;
use rt_core::scene::Object;

// Node trees deeper than this are refused (real files nest a few dozen levels).
use rt_core::animation::MAX_NODE_DEPTH;

impl Loader<'_> {
    pub(super) fn visit(
        &mut self,
        node: &gltf::Node,
        parent: Mat4,
        stack: &mut Vec<usize>,
    ) -> std::result::Result<(), String> {
        if stack.contains(&node.index()) {
            return Err(format!("node {} is its own ancestor", node.index()));
        }
        if stack.len() >= MAX_NODE_DEPTH {
            return Err(format!("nodes nest deeper than {MAX_NODE_DEPTH} levels"));
        }
        let local = Mat4::from_cols_array_2d(&node.transform().matrix());
        let animation_node = self.animated.then_some(node.index() as u32);
        let world = parent * local;
        if !world.is_finite() {
            return Err(format!(
                "node {}: its transform is not finite",
                node.index()
            ));
        }
        stack.push(node.index());
        let name = node
            .name()
            .map(str::to_string)
            .unwrap_or_else(|| format!("node {}", node.index()));
        // A mesh scaled to nothing shows nothing, and no animation of the file can grow it: left
        // out with a warning (a still scene's singular transform is an error naming the object).
        let vanished = !self.animated && world.determinant() == 0.0;
        if let Some(mesh) = node.mesh().filter(|_| !vanished) {
            for primitive in mesh.primitives() {
                use gltf::mesh::Mode;
                if !matches!(
                    primitive.mode(),
                    Mode::Triangles | Mode::TriangleStrip | Mode::TriangleFan
                ) {
                    self.skipped_primitives += 1;
                    continue;
                }
                let m = self.mesh(&mesh, &primitive)?;
                let material = self.material(&primitive.material())?;
                let object_name = if mesh.primitives().len() > 1 {
                    format!("{name} ({})", primitive.index())
                } else {
                    name.clone()
                };
                let (mesh, transform) = placed(m, world);
                self.objects.push(Object {
                    shadow_catcher: false,
                    animation_node,
                    name: object_name,
                    mesh,
                    material,
                    transform,
                });
            }
        }
        if vanished && node.mesh().is_some() {
            log::warn!(
                "node {} ('{name}') is scaled to nothing: left out",
                node.index()
            );
        }
        if let Some(camera) = node.camera()
            && self.camera.is_none()
        {
            let from = world.transform_point3(Vec3::ZERO);
            let forward = world.transform_vector3(Vec3::NEG_Z).normalize_or_zero();
            let up = world.transform_vector3(Vec3::Y).normalize_or_zero();
            let placed = rt_core::camera::Camera {
                from: from.to_array(),
                to: (from + forward).to_array(),
                up: up.to_array(),
                animation_node,
                ..Default::default()
            };
            self.camera = Some(match camera.projection() {
                gltf::camera::Projection::Perspective(p) => (
                    rt_core::camera::Camera {
                        vfov_deg: p.yfov().to_degrees(),
                        ..placed
                    },
                    p.aspect_ratio(),
                ),
                // xmag and ymag are half the view's width and height (glTF 2.0 §3.10.3), in
                // the camera node's units: its world scale along y maps them to the scene's.
                gltf::camera::Projection::Orthographic(o) => {
                    let scale = world.transform_vector3(Vec3::Y).length();
                    let height = 2.0 * o.ymag().abs() * scale;
                    let aspect = (o.ymag() != 0.0).then(|| (o.xmag() / o.ymag()).abs());
                    (
                        rt_core::camera::Camera {
                            projection: rt_core::camera::Projection::Orthographic,
                            ortho_height: (height.is_finite() && height > 0.0).then_some(height),
                            ..placed
                        },
                        aspect.filter(|a| a.is_finite() && *a > 0.0),
                    )
                }
            });
        }
        if let Some(light) = node.light() {
            self.lights.push(rt_core::light::Light {
                animation_node,
                ..light_of(&light, world, &name)
            });
        }
        for child in node.children() {
            self.visit(&child, world, stack)?;
        }
        stack.pop();
        Ok(())
    }
}
