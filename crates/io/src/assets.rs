//! Scenes compiled into the binaries, so `rt-cli` and the editor work with no files at hand.

use std::path::Path;

use crate::camera_json::CameraFile;
use crate::obj::load_obj_bytes;
use rt_core::error::{Error, Result};
use rt_core::scene::Scene;

const CORNELL_OBJ: &str = include_str!("../../../assets/cornell/cornell.obj");
const CORNELL_MTL: &str = include_str!("../../../assets/cornell/cornell.mtl");
const CORNELL_CAMERA: &str = include_str!("../../../assets/cornell/cornell.json");
const STUDIO_EXR: &[u8] = include_bytes!("../../../assets/environments/studio.exr");

/// The environment rt lights scenes with when they bring no light of their own: Poly Haven's
/// "studio small 01" at 1024×512 (CC0; `assets/environments/LICENSE-studio.txt`).
pub fn default_environment() -> Result<rt_core::environment::Environment> {
    let map = rt_core::environment::decode_environment(
        STUDIO_EXR,
        Path::new("<embedded>/environments/studio.exr"),
    )?;
    Ok(rt_core::environment::Environment::new(
        "studio (built in)",
        map,
    ))
}

/// The Cornell box (32 triangles, units ≈ mm) with its camera, 512×512 and max depth 8.
pub fn cornell_box() -> Result<Scene> {
    let read_file = |p: &Path| match p.file_name().and_then(|n| n.to_str()) {
        Some("cornell.mtl") => Ok(CORNELL_MTL.as_bytes().to_vec()),
        _ => Err(Error::File {
            path: p.into(),
            message: "not part of the embedded scene".into(),
        }),
    };
    let no_textures = |p: &Path| -> Result<rt_core::scene::Texture> {
        Err(Error::File {
            path: p.into(),
            message: "the embedded scene has no textures".into(),
        })
    };
    let obj_path = Path::new("<embedded>/cornell.obj");
    let mut scene = load_obj_bytes(
        obj_path,
        CORNELL_OBJ.as_bytes(),
        Path::new("<embedded>"),
        &read_file,
        &no_textures,
        0,
    )?;
    CameraFile::parse(CORNELL_CAMERA, Path::new("<embedded>/cornell.json"))?.apply(&mut scene);
    scene.settings.max_depth = 8;
    Ok(scene)
}

#[cfg(test)]
mod tests {
    #[test]
    fn the_default_environment_decodes_and_emits() {
        let env = super::default_environment().unwrap();
        assert_eq!((env.map.width, env.map.height), (1024, 512));
        assert!(rt_core::environment::build_env_texels(&env.map, 1.0).is_some());
    }
}
