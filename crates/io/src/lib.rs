//! rt's scene files: reading scenes from Wavefront OBJ/MTL, PLY, STL, glTF 2.0, camera JSON, textures and
//! project files into rt-core's scene model, saving projects, and the scenes compiled into the
//! binaries (`assets`). [`load()`] is the one entry point for a scene file, whatever its kind; the
//! per-format modules are its parts (and the tests'). A crate of its own so that the estimator
//! (rt-core) does not rebuild for an edit to a loader, nor link what only loading needs.

pub mod assets;
pub mod camera_json;
pub mod gltf;
mod line_reader;
mod load;
mod mesh_file;
pub mod obj;
mod parse_guard;
pub mod ply;
pub mod project;
pub mod stl;
pub mod texture;

pub use load::{LoadOptions, SCENE_EXTENSIONS, SceneFormat, load, scene_extensions_listed};
