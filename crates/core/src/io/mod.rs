//! Reading scenes from files: Wavefront OBJ/MTL, camera JSON, textures.

pub mod camera_json;
pub mod obj;
mod line_reader;
pub mod texture;
