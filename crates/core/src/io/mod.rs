//! Reading scenes from files: Wavefront OBJ/MTL, glTF 2.0, camera JSON, textures, and project files.
//! [`load()`] is the one entry point for a scene file, whatever its kind; the per-format modules are
//! its parts (and the tests').

pub mod camera_json;
pub mod gltf;
mod line_reader;
mod load;
pub mod obj;
pub mod project;
pub mod texture;

pub use load::{LoadOptions, SCENE_EXTENSIONS, SceneFormat, load, scene_extensions_listed};
