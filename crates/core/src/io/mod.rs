//! Reading scenes from files: Wavefront OBJ/MTL, glTF 2.0, camera JSON, textures, and project files.

pub mod camera_json;
pub mod gltf;
mod line_reader;
pub mod obj;
pub mod project;
pub mod texture;
