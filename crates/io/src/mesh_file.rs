//! What the single-mesh formats (PLY, STL) share: one object named after the file with the
//! default material of a bare OBJ object.

use std::path::Path;
use std::sync::Arc;

use super::obj::distinct_color;
use super::parse_guard::guard_parser;
use rt_core::error::{Error, Result};
use rt_core::material::Material;
use rt_core::scene::{Mesh, Object, Scene};

pub use rt_core::math::sampling::srgb_to_linear;

/// Loads a single-mesh file: its bytes read by `read` (guarded against a parser's panic), the
/// mesh made into a scene by [`mesh_object_scene`].
pub fn load_mesh_file(
    path: &Path,
    seed: u32,
    format: &str,
    read: fn(&Path, &[u8]) -> Result<Mesh>,
) -> Result<Scene> {
    let bytes = std::fs::read(path).map_err(|source| Error::Io {
        path: path.into(),
        source,
    })?;
    let mesh = guard_parser(path, format, || read(path, &bytes))??;
    Ok(mesh_object_scene(path, mesh, seed))
}

/// A scene of `mesh` alone, named after the file, with the material an OBJ object without one
/// gets: a distinct colour from `seed`, or MTL's default grey (0.8) where vertex colours carry
/// the colour (they multiply the albedo). [`crate::load`] frames it for viewing, as an OBJ.
pub fn mesh_object_scene(path: &Path, mesh: Mesh, seed: u32) -> Scene {
    let albedo = if mesh.colors.is_some() {
        [0.8; 3]
    } else {
        distinct_color(seed, 0)
    };
    let name = path
        .file_stem()
        .map_or_else(|| "mesh".to_string(), |s| s.to_string_lossy().into_owned());
    let mut scene = Scene::default();
    scene.objects.push(Object {
        shadow_catcher: false,
        animation_node: None,
        name,
        mesh: Arc::new(mesh),
        material: Material::lambertian(albedo),
        transform: Default::default(),
    });
    scene
}
