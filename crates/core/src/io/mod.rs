//! Reading scenes from files: Wavefront OBJ/MTL, camera JSON, textures, and project files.

pub mod camera_json;
mod line_reader;
pub mod obj;
pub mod project;
pub mod texture;
