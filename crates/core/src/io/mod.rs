//! Reading scenes from files: Wavefront OBJ/MTL, camera JSON, textures.

pub mod camera_json;
mod line_reader;
pub mod obj;
pub mod texture;
