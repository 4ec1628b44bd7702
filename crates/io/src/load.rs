//! The one way rt turns a scene file into a [`Scene`], for every caller: the editor (File ▸ Open,
//! dropped files, recent files), `rt-cli` (render, info, converge, ...) and the benchmark.

use std::path::Path;

use super::{gltf, obj, ply, project, stl};
use rt_core::error::{Error, Result};
use rt_core::scene::Scene;

/// The extensions of the scene files rt reads, lowercase, without the dot.
pub const SCENE_EXTENSIONS: &[&str] = &[
    "obj",
    "gltf",
    "glb",
    "ply",
    "stl",
    project::PROJECT_EXTENSION,
];

/// What a caller may choose about loading; the default suits a user opening a file.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct LoadOptions {
    /// Seed for the colours of OBJ objects without a material (and of PLY and STL meshes).
    pub seed: u32,
    /// Which of a glTF file's scenes to load (its default scene when `None`); an error for any
    /// other kind of file.
    pub gltf_scene: Option<usize>,
    /// Smooth shading for OBJ, PLY and STL meshes that have no normals, split at edges sharper
    /// than this many degrees ([`rt_core::smooth_normals`]); `None` shades them flat, as their
    /// facets are (STL's CAD parts mean it).
    pub smooth_normals_deg: Option<u32>,
    /// The time, in seconds, at which the scene's animation places what it moves (meshes,
    /// cameras, lights: a glTF file's animations, or a project's saved from one); `None` loads
    /// the scene at rest with its animation kept. OBJ, PLY and STL have no animation.
    pub animation_time: Option<f32>,
}

/// The kinds of scene file, told apart by extension (in any case).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum SceneFormat {
    /// Wavefront OBJ with its MTL and textures.
    Obj,
    /// glTF 2.0, `.gltf` or `.glb`.
    Gltf,
    /// Stanford PLY, one mesh.
    Ply,
    /// STL (stereolithography), one mesh.
    Stl,
    /// An rt project (`.rtproj`).
    Project,
}

impl SceneFormat {
    /// The format of `path` by its extension, or an error naming the extensions rt reads.
    pub fn of(path: &Path) -> Result<SceneFormat> {
        let extension = path
            .extension()
            .map(|e| e.to_string_lossy().to_ascii_lowercase())
            .unwrap_or_default();
        match extension.as_str() {
            "obj" => Ok(SceneFormat::Obj),
            "gltf" | "glb" => Ok(SceneFormat::Gltf),
            "ply" => Ok(SceneFormat::Ply),
            "stl" => Ok(SceneFormat::Stl),
            e if e == project::PROJECT_EXTENSION => Ok(SceneFormat::Project),
            _ => {
                let what = match extension.as_str() {
                    "" => "(no extension)".to_string(),
                    e => format!("'.{e}'"),
                };
                Err(Error::File {
                    path: path.into(),
                    message: format!(
                        "unknown scene type {what}: rt reads {}",
                        scene_extensions_listed()
                    ),
                })
            }
        }
    }

    /// A model made elsewhere (OBJ, glTF, PLY, STL), as opposed to a project rt saved.
    pub fn is_model(self) -> bool {
        self != SceneFormat::Project
    }

    /// Geometry alone, with no camera or light of its own (OBJ, PLY, STL): framed for viewing on
    /// loading, and lit by the editor's studio environment.
    pub fn is_bare_geometry(self) -> bool {
        matches!(self, SceneFormat::Obj | SceneFormat::Ply | SceneFormat::Stl)
    }
}

/// ".obj, .gltf, .glb, .ply, .stl, .rtproj", for messages.
pub fn scene_extensions_listed() -> String {
    SCENE_EXTENSIONS
        .iter()
        .map(|e| format!(".{e}"))
        .collect::<Vec<_>>()
        .join(", ")
}

/// Loads the scene file at `path`, by its extension (in any case), with one policy for all
/// callers:
/// - `.obj`, `.ply`, `.stl`: the file, with `options.seed` for the colours of objects without a
///   material, framed for viewing ([`Scene::frame_for_viewing`]: the camera shows the whole
///   model, and a model without emitters gets a grey ambient), since these files have no camera
///   and no light of their own.
/// - `.gltf`, `.glb`: the scene `options.gltf_scene` (the file's default one when `None`); the
///   glTF loader frames a file without a camera and lights one without light
///   ([`gltf::load_gltf`]).
/// - `.rtproj`: the project exactly as saved; no policy applies to what a user has set up.
/// - anything else: an error naming the extensions rt reads, never a guess at the format.
///
/// Two editor choices stay out of this policy, because they would change what `rt-cli render`
/// makes of the same file: the studio environment for a model that brings no light (the CLI
/// lights it only on `--environment default`, so `--ambient 0,0,0` stays black) and a max depth
/// chosen by material (the CLI keeps the settings' default, 8, unless `--max-depth` says
/// otherwise). The editor applies them after this, to models only.
pub fn load(path: &Path, options: &LoadOptions) -> Result<Scene> {
    if path.is_dir() {
        return Err(Error::File {
            path: path.into(),
            message: format!(
                "is a directory, not a scene file ({})",
                scene_extensions_listed()
            ),
        });
    }
    let format = SceneFormat::of(path)?;
    if options.gltf_scene.is_some() && format != SceneFormat::Gltf {
        return Err(Error::File {
            path: path.into(),
            message: "a glTF scene index needs a .gltf or .glb file".into(),
        });
    }
    match format {
        SceneFormat::Obj | SceneFormat::Ply | SceneFormat::Stl => {
            let mut scene = match format {
                SceneFormat::Obj => obj::load_obj(path, options.seed)?,
                SceneFormat::Ply => ply::load_ply(path, options.seed)?,
                _ => stl::load_stl(path, options.seed)?,
            };
            if let Some(crease) = options.smooth_normals_deg {
                for object in &mut scene.objects {
                    if object.mesh.normals.is_none() {
                        object.mesh = std::sync::Arc::new(rt_core::smooth_normals::smooth_normals(
                            &object.mesh,
                            crease as f32,
                        ));
                    }
                }
            }
            scene.frame_for_viewing();
            Ok(scene)
        }
        SceneFormat::Gltf => gltf::load_gltf_at(path, options.gltf_scene, options.animation_time),
        SceneFormat::Project => {
            let scene = project::load_project(path)?;
            Ok(match options.animation_time {
                Some(time) => posed(scene, path, time),
                None => scene,
            })
        }
    }
}

/// The scene at `time` seconds of its animation (`rt_core::posing::posed_at`); a warning
/// naming the file when it has none to play.
pub(crate) fn posed(scene: Scene, path: &Path, time: f32) -> Scene {
    if scene.animation.is_none() {
        log::warn!("{}: has no animation to play", path.display());
        return scene;
    }
    rt_core::posing::posed_at(&scene, time)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_extension_in_any_case_picks_the_format() {
        for (name, format) in [
            ("a.obj", SceneFormat::Obj),
            ("b/C.OBJ", SceneFormat::Obj),
            ("d.gltf", SceneFormat::Gltf),
            ("e.GLB", SceneFormat::Gltf),
            ("f.RtProj", SceneFormat::Project),
            ("g.ply", SceneFormat::Ply),
            ("h.STL", SceneFormat::Stl),
        ] {
            assert_eq!(SceneFormat::of(Path::new(name)).unwrap(), format, "{name}");
        }
    }

    #[test]
    fn an_unknown_extension_is_an_error_naming_those_rt_reads() {
        for name in ["scene.xyz", "scene.rtlight", "render.exr", "no-extension"] {
            let message = load(Path::new(name), &LoadOptions::default())
                .unwrap_err()
                .to_string();
            assert!(
                message.starts_with(name)
                    && message.contains("unknown scene type")
                    && message.contains("rt reads .obj, .gltf, .glb, .ply, .stl, .rtproj"),
                "{message}"
            );
        }
    }

    #[test]
    fn smoothing_gives_normals_to_meshes_without_them_only_when_asked() {
        let dir = std::env::temp_dir().join(format!("rt-load-smooth-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let path = dir.join("fan.obj");
        std::fs::write(
            &path,
            "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\nf 1 2 3\nf 1 3 4\n",
        )
        .unwrap();
        let flat = load(&path, &LoadOptions::default()).unwrap();
        let options = LoadOptions {
            smooth_normals_deg: Some(100),
            ..LoadOptions::default()
        };
        let smooth = load(&path, &options).unwrap();
        std::fs::remove_dir_all(&dir).unwrap();
        assert!(flat.objects[0].mesh.normals.is_none());
        let normals = smooth.objects[0].mesh.normals.as_ref().unwrap();
        // The shared edge's vertices average the two faces (at right angles, within 100°).
        assert!(
            normals
                .iter()
                .any(|n| (n.x - n.z).abs() < 1e-6 && n.x > 0.5),
            "{normals:?}"
        );
    }

    #[test]
    fn a_gltf_scene_index_needs_a_gltf_file() {
        let options = LoadOptions {
            gltf_scene: Some(0),
            ..LoadOptions::default()
        };
        let message = load(Path::new("model.obj"), &options)
            .unwrap_err()
            .to_string();
        assert!(message.contains("needs a .gltf or .glb"), "{message}");
    }

    #[test]
    fn a_directory_is_an_error_saying_so() {
        let message = load(&std::env::temp_dir(), &LoadOptions::default())
            .unwrap_err()
            .to_string();
        assert!(message.contains("is a directory"), "{message}");
    }

    #[test]
    fn an_obj_is_framed_for_viewing() {
        let dir = std::env::temp_dir().join(format!("rt-load-test-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let path = dir.join("triangle.obj");
        std::fs::write(&path, "v 10 0 0\nv 11 0 0\nv 10 1 0\nf 1 2 3\n").unwrap();
        let loaded = load(&path, &LoadOptions::default()).unwrap();
        let mut framed = obj::load_obj(&path, 0).unwrap();
        std::fs::remove_dir_all(&dir).unwrap();
        framed.frame_for_viewing();
        assert_eq!(loaded, framed);
        assert_ne!(loaded.camera, rt_core::camera::Camera::default());
    }
}
