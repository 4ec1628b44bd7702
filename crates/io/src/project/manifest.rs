//! `project.json`, the archive's manifest: the format names and version, the entries serde reads
//! and writes, and the render settings a project leaves out.

use serde::{Deserialize, Serialize};

use rt_core::camera::Camera;
use rt_core::error::Result;
use rt_core::material::{Material, Rgb};
use rt_core::scene::{RenderSettings, Transform};

/// The format version this build writes; it reads this and every earlier one. Version 2 added
/// point, spot and directional lights (`lights`); version 3 the PBR material and environment maps;
/// version 5 the fog and scattering and subsurface volumes; version 6 the animation (`animation`,
/// and the node each object, light and the camera follows).
pub const FORMAT_VERSION: u32 = 6;
pub const PROJECT_FORMAT: &str = "rt-project";
pub const LIGHTING_FORMAT: &str = "rt-lighting";

pub(super) const MANIFEST: &str = "project.json";

#[derive(Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct Manifest {
    pub(super) format: String,
    pub(super) version: u32,
    #[serde(default)]
    pub(super) camera: Option<Camera>,
    pub(super) ambient: Rgb,
    #[serde(default, serialize_with = "serialize_project_settings")]
    pub(super) settings: Option<RenderSettings>,
    pub(super) objects: Vec<ObjectEntry>,
    #[serde(default)]
    pub(super) textures: Vec<TextureEntry>,
    #[serde(default)]
    pub(super) lights: Vec<rt_core::light::Light>,
    #[serde(default)]
    pub(super) environment: Option<EnvironmentEntry>,
    /// The scene's fog (`rt_core::fog`), left out when there is none.
    #[serde(default, skip_serializing_if = "no_fog")]
    pub(super) fog: rt_core::fog::Fog,
    /// The scene's animation (`rt_core::animation`), left out when there is none.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub(super) animation: Option<rt_core::animation::Animation>,
}

fn no_fog(fog: &rt_core::fog::Fog) -> bool {
    *fog == rt_core::fog::Fog::default()
}

#[derive(Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct EnvironmentEntry {
    pub(super) source: String,
    pub(super) rotation_deg: f32,
    pub(super) strength: f32,
    pub(super) file: String,
    pub(super) width: u32,
    pub(super) height: u32,
}

pub(super) const ENVIRONMENT_ENTRY: &str = "environment.bin";

/// Render settings a project leaves out: `nee_only` is a diagnostic estimator for tests and
/// `rt-cli --nee-only`, not a property of a scene, so a project never turns it on. `RenderSettings`
/// itself keeps serialising it (no `#[serde(skip)]`): a render part's settings hash
/// (`part::scene_hashes`) must tell the estimators apart.
const SETTINGS_NOT_SAVED: &[&str] = &["nee_only"];

/// Writes the settings without [`SETTINGS_NOT_SAVED`].
fn serialize_project_settings<S: serde::Serializer>(
    settings: &Option<RenderSettings>,
    serializer: S,
) -> Result<S::Ok, S::Error> {
    use serde::ser::Error as _;
    // Through JSON text rather than `serde_json::to_value`, which widens an f32 to f64 and would
    // write a clamp of 0.1 as 0.10000000149011612 (the same f32 when read, but not what was set).
    let json = serde_json::to_string(settings).map_err(S::Error::custom)?;
    let mut value: serde_json::Value = serde_json::from_str(&json).map_err(S::Error::custom)?;
    if let Some(fields) = value.as_object_mut() {
        fields.retain(|name, _| !SETTINGS_NOT_SAVED.contains(&name.as_str()));
    }
    value.serialize(serializer)
}

/// The settings a project's scene starts with: files written before [`SETTINGS_NOT_SAVED`] may
/// hold `nee_only`; they still load, with it off, as a file written now.
pub(super) fn project_settings(saved: Option<RenderSettings>) -> RenderSettings {
    RenderSettings {
        nee_only: false,
        ..saved.unwrap_or_default()
    }
}

#[derive(Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct ObjectEntry {
    pub(super) name: String,
    pub(super) mesh: String,
    pub(super) material: Material,
    #[serde(default)]
    pub(super) transform: Transform,
    #[serde(default, skip_serializing_if = "std::ops::Not::not")]
    pub(super) shadow_catcher: bool,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub(super) animation_node: Option<u32>,
}

#[derive(Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct TextureEntry {
    pub(super) name: String,
    pub(super) file: String,
    pub(super) width: u32,
    pub(super) height: u32,
    /// Absent in files of earlier versions: repeat, bilinear.
    #[serde(default)]
    pub(super) sampler: rt_core::scene::TextureSampler,
}

/// Just the version fields, read first so that a future file gets a version error rather than a
/// confusing field error.
#[derive(Deserialize)]
pub(super) struct Header {
    pub(super) format: String,
    pub(super) version: u32,
}
