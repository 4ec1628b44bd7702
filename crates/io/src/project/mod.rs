//! Project files: a whole scene in one zip archive, so that a project can be mailed or moved
//! without breaking paths.
//!
//! Layout (format version 6; version 1 had no `lights`, versions before 3 no environment, before 4
//! no texture samplers, PBR emission textures or alpha modes, before 5 no fog, volume scattering
//! or subsurface, before 6 no animation):
//! - `project.json`: `{"format": "rt-project", "version": 1, ...}` with the camera, ambient light,
//!   render settings (all but the diagnostic `nee_only`), and per object its name, material,
//!   transform and the mesh entry it uses; per texture its name, size, sampler and image entry.
//! - `meshes/N.bin`: one mesh each, in the little-endian layout of [`encode_mesh`]; objects that
//!   share a mesh in memory share the entry.
//! - `textures/N.png`: the RGBA8 texels, lossless.
//! - `environment.bin`: the environment map's linear RGB texels as little-endian f32, row-major
//!   from the top (version 3).
//! - the animation (version 6): `project.json`'s `animation` holds the node hierarchy and its
//!   channels (`rt_core::animation`), and each object, light and the camera the node it follows.
//!
//! A lighting file (`.rtlight`) is the same container with `"format": "rt-lighting"`, holding only
//! the ambient light, the emissive objects and the point, spot and directional lights, to reuse a
//! light set across projects.
//!
//! Loading reads every entry into memory and never writes anything, so hostile entry names cannot
//! reach the file system; they are rejected anyway, and decompressed sizes are capped by reading,
//! not by trusting the sizes the archive declares.
//!
//! The parts: `manifest` (`project.json` and the format version), `archive` (a scene to and from
//! the zip), `reader` (safe entry reading and [`LoadLimits`]) and `meshes` (the mesh entries).

mod archive;
mod manifest;
mod meshes;
mod reader;

use std::path::Path;

use rt_core::error::{Error, Result};
use rt_core::material::{Material, Rgb};
use rt_core::output::write_atomically;
use rt_core::scene::{Object, Scene};

pub use archive::{decode_archive, encode_archive};
pub use manifest::{FORMAT_VERSION, LIGHTING_FORMAT, PROJECT_FORMAT};
pub use meshes::{decode_mesh, encode_mesh};
pub use reader::LoadLimits;

/// File extensions the editor offers.
pub const PROJECT_EXTENSION: &str = "rtproj";
pub const LIGHTING_EXTENSION: &str = "rtlight";

/// The ambient light and emissive objects of a lighting file.
#[derive(Clone, Debug, PartialEq)]
pub struct Lighting {
    pub ambient: Rgb,
    /// Emissive objects.
    pub lights: Vec<Object>,
    /// Point, spot and directional lights.
    pub delta_lights: Vec<rt_core::light::Light>,
    /// The fog (the Lights panel's too).
    pub fog: rt_core::fog::Fog,
}

impl Lighting {
    /// The scene's lights as they stand: a lighting file keeps no animation, so the lights lose
    /// the nodes they followed (another scene's nodes are others).
    pub fn of(scene: &Scene) -> Self {
        Lighting {
            ambient: scene.ambient,
            lights: scene
                .objects
                .iter()
                .filter(|o| matches!(o.material, Material::Emissive { .. }))
                .map(|o| Object {
                    animation_node: None,
                    ..o.clone()
                })
                .collect(),
            delta_lights: (scene.lights.iter())
                .map(|l| rt_core::light::Light {
                    animation_node: None,
                    ..l.clone()
                })
                .collect(),
            fog: scene.fog,
        }
    }

    /// Replaces the scene's ambient light, emissive objects, lights and fog with these.
    pub fn apply(&self, scene: &mut Scene) {
        scene
            .objects
            .retain(|o| !matches!(o.material, Material::Emissive { .. }));
        scene.objects.extend(self.lights.iter().cloned());
        scene.lights = self.delta_lights.clone();
        scene.ambient = self.ambient;
        scene.fog = self.fog;
    }
}

/// Saves `scene` as a project file, atomically.
pub fn save_project(scene: &Scene, path: &Path) -> Result<()> {
    let bytes = encode_archive(scene, PROJECT_FORMAT, path)?;
    write_atomically(path, &bytes)
}

/// Loads a project file with the default [`LoadLimits`].
pub fn load_project(path: &Path) -> Result<Scene> {
    let bytes = read_file(path)?;
    decode_archive(&bytes, path, PROJECT_FORMAT, &LoadLimits::default())
}

/// Saves the scene's ambient light and emissive objects, atomically.
pub fn save_lighting(lighting: &Lighting, path: &Path) -> Result<()> {
    let scene = Scene {
        objects: lighting.lights.clone(),
        ambient: lighting.ambient,
        lights: lighting.delta_lights.clone(),
        fog: lighting.fog,
        ..Scene::default()
    };
    let bytes = encode_archive(&scene, LIGHTING_FORMAT, path)?;
    write_atomically(path, &bytes)
}

pub fn load_lighting(path: &Path) -> Result<Lighting> {
    let bytes = read_file(path)?;
    let scene = decode_archive(&bytes, path, LIGHTING_FORMAT, &LoadLimits::default())?;
    if let Some(o) = scene
        .objects
        .iter()
        .find(|o| !matches!(o.material, Material::Emissive { .. }))
    {
        return Err(Error::File {
            path: path.into(),
            message: format!("object '{}' of a lighting file is not emissive", o.name),
        });
    }
    Ok(Lighting {
        ambient: scene.ambient,
        lights: scene.objects,
        delta_lights: scene.lights,
        fog: scene.fog,
    })
}

fn read_file(path: &Path) -> Result<Vec<u8>> {
    if path.is_dir() {
        return Err(Error::File {
            path: path.into(),
            message: "is a directory, not a project file".into(),
        });
    }
    std::fs::read(path).map_err(|source| Error::Io {
        path: path.into(),
        source,
    })
}
