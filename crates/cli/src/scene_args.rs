//! Scene selection and the camera / settings overrides shared by the subcommands.

use std::path::PathBuf;

use anyhow::{Context, Result};
use clap::Args;
use rt_core::Scene;
use rt_io::camera_json::CameraFile;
use rt_io::{LoadOptions, SceneFormat};

/// Parses "x,y,z" into three finite floats.
pub fn parse_vec3(s: &str) -> Result<[f32; 3], String> {
    let parts: Vec<&str> = s.split(',').map(str::trim).collect();
    let [x, y, z] = parts.as_slice() else {
        return Err(format!(
            "expected three comma-separated numbers like 1,2.5,-3, got '{s}'"
        ));
    };
    let num = |t: &str| match t.parse::<f32>() {
        Ok(v) if v.is_finite() => Ok(v),
        _ => Err(format!("'{t}' is not a finite number (in '{s}')")),
    };
    Ok([num(x)?, num(y)?, num(z)?])
}

#[derive(Args, Debug, Clone)]
pub struct SceneArgs {
    /// Wavefront OBJ, glTF 2.0 (.gltf, .glb), PLY, STL or rt project (.rtproj); the embedded Cornell
    /// box when omitted.
    pub scene: Option<PathBuf>,
    /// Which of a glTF file's scenes to load (its default scene otherwise).
    #[arg(long, value_name = "N")]
    pub gltf_scene: Option<usize>,
    /// Smooth shading for OBJ, PLY and STL meshes without normals (flat otherwise), split at edges
    /// sharper than DEGREES (30 when not given, as Blender's Auto Smooth).
    #[arg(long, value_name = "DEGREES", num_args = 0..=1, require_equals = true, default_missing_value = "30")]
    pub smooth_normals: Option<u32>,
    /// Camera JSON file ({"from","to","up","vfov","width","height","background"}).
    #[arg(long)]
    pub camera: Option<PathBuf>,
    #[arg(long, value_name = "X,Y,Z", value_parser = parse_vec3, allow_hyphen_values = true)]
    pub camera_from: Option<[f32; 3]>,
    #[arg(long, value_name = "X,Y,Z", value_parser = parse_vec3, allow_hyphen_values = true)]
    pub camera_to: Option<[f32; 3]>,
    #[arg(long, value_name = "X,Y,Z", value_parser = parse_vec3, allow_hyphen_values = true)]
    pub camera_up: Option<[f32; 3]>,
    /// Vertical field of view in degrees (the perspective projection's).
    #[arg(long)]
    pub vfov: Option<f32>,
    /// How the image maps to directions: perspective (a pinhole or thin lens), orthographic
    /// (parallel rays), panorama (equirectangular, 360° × 180°: render it 2:1) or fisheye
    /// (equidistant, an image circle as high as the image).
    #[arg(long, value_name = "perspective|orthographic|panorama|fisheye")]
    pub projection: Option<rt_core::camera::Projection>,
    /// The orthographic view's height in scene units (default: the perspective view's height at
    /// the point the camera looks at).
    #[arg(long, value_name = "H")]
    pub ortho_height: Option<f32>,
    /// The angle the fisheye's image circle spans, in degrees (default 180).
    #[arg(long, value_name = "DEGREES")]
    pub fisheye_angle: Option<f32>,
    /// Radiance of rays that leave the scene.
    #[arg(long, value_name = "R,G,B", value_parser = parse_vec3)]
    pub ambient: Option<[f32; 3]>,
    /// Seed for the random numbers (and for the colours of objects without a material).
    #[arg(long)]
    pub seed: Option<u32>,
    /// Equirectangular environment map (.hdr, .exr, or any image) lighting the scene in place of
    /// the ambient colour; `default` is the studio environment rt ships, `none` removes one;
    /// `sky[:ELEVATION[,TURBIDITY]]` a physical sun and clear sky (Preetham; defaults 35° and 3;
    /// the sun stands at −z, turned by --env-rotation; strength 1/32, −5 stops, unless
    /// --env-strength says otherwise: 1 is physical).
    #[arg(long, value_name = "FILE|default|none|sky[:ELEV[,TURB]]")]
    pub environment: Option<String>,
    /// Rotation of the environment about the up axis, in degrees.
    #[arg(long, value_name = "DEGREES", allow_hyphen_values = true)]
    pub env_rotation: Option<f32>,
    /// Radiance scale of the environment.
    #[arg(long, value_name = "X", allow_hyphen_values = true)]
    pub env_strength: Option<f32>,
    /// Fog filling the space outside closed objects: its extinction σ_t per scene unit (light
    /// travels 1/σ_t on average before it meets the fog; 0 removes it). Lights at infinity (the
    /// sun, the environment) do not reach through it.
    #[arg(long, value_name = "SIGMA_T", allow_hyphen_values = true)]
    pub fog_density: Option<f32>,
    /// The fog's single-scattering albedo per channel, in [0, 1] (default 1,1,1: scatters all).
    #[arg(long, value_name = "R,G,B", value_parser = parse_vec3)]
    pub fog_albedo: Option<[f32; 3]>,
    /// The fog's Henyey–Greenstein anisotropy g in (−1, 1): > 0 scatters forward (default 0).
    #[arg(long, value_name = "G", allow_hyphen_values = true)]
    pub fog_anisotropy: Option<f32>,
    /// Makes the named object a shadow catcher (repeatable; Cycles' Object ▸ Shadow Catcher): on
    /// a transparent film it shows only the shadows and the reflections of other objects it
    /// receives, to composite renders over a photograph (alpha is 1 − the shadowed irradiance
    /// ratio there). `render` makes its film transparent for it. Names as `rt-cli info` lists them.
    #[arg(long, value_name = "OBJECT")]
    pub shadow_catcher: Vec<String>,
    /// Set per frame by an animation (`render --frames`, `--turntable`), not a flag: the time at
    /// which a glTF file's animations place its nodes.
    #[arg(skip)]
    pub animation_time: Option<f32>,
    /// Set per frame by `render --turntable`: how far round (in turns) the camera has orbited
    /// the vertical axis through the scene's centre.
    #[arg(skip)]
    pub turntable_turns: Option<f32>,
}

impl SceneArgs {
    /// Loads the scene and applies the overrides, in order: file, camera file, flags.
    pub fn load(&self) -> Result<Scene> {
        if self.gltf_scene.is_some() && !self.scene.as_deref().is_some_and(is_gltf) {
            anyhow::bail!("--gltf-scene needs a .gltf or .glb scene");
        }
        let mut scene = match &self.scene {
            Some(path) => rt_io::load(path, &self.load_options())?,
            None => rt_io::assets::cornell_box().context("loading the embedded Cornell box")?,
        };
        if let Some(path) = &self.camera {
            CameraFile::load(path)?.apply(&mut scene);
        }
        let camera = &mut scene.camera;
        camera.from = self.camera_from.unwrap_or(camera.from);
        camera.to = self.camera_to.unwrap_or(camera.to);
        camera.up = self.camera_up.unwrap_or(camera.up);
        camera.vfov_deg = self.vfov.unwrap_or(camera.vfov_deg);
        camera.projection = self.projection.unwrap_or(camera.projection);
        if self.ortho_height.is_some() {
            camera.ortho_height = self.ortho_height;
        }
        camera.fisheye_angle_deg = self.fisheye_angle.unwrap_or(camera.fisheye_angle_deg);
        if let Some(turns) = self.turntable_turns {
            orbit_vertically(&mut scene, turns);
        }
        scene.ambient = self.ambient.unwrap_or(scene.ambient);
        scene.settings.seed = self.seed.unwrap_or(scene.settings.seed);
        match self.environment.as_deref() {
            None => {}
            Some("none") => scene.environment = None,
            Some("default") => scene.environment = Some(rt_io::assets::default_environment()?),
            Some(spec) => match rt_core::sky::SunSky::parse(spec) {
                Some(sky) => {
                    let sky = sky.map_err(|e| anyhow::anyhow!("--environment {e}"))?;
                    scene.environment = Some(sky.environment());
                }
                None => {
                    let map = rt_core::environment::load_environment(std::path::Path::new(spec))?;
                    scene.environment = Some(rt_core::Environment::new(spec, map));
                }
            },
        }
        if let Some(env) = scene.environment.as_mut() {
            env.rotation_deg = self.env_rotation.unwrap_or(env.rotation_deg);
            env.strength = self.env_strength.unwrap_or(env.strength);
            env.validate().map_err(anyhow::Error::msg)?;
        } else if self.env_rotation.is_some() || self.env_strength.is_some() {
            anyhow::bail!("--env-rotation and --env-strength need an environment (--environment)");
        }
        for name in &self.shadow_catcher {
            mark_shadow_catcher(&mut scene, name)?;
        }
        let fog = &mut scene.fog;
        fog.density = self.fog_density.unwrap_or(fog.density);
        fog.albedo = self.fog_albedo.unwrap_or(fog.albedo);
        fog.anisotropy = self.fog_anisotropy.unwrap_or(fog.anisotropy);
        fog.validate()
            .map_err(|e| anyhow::anyhow!("--fog-density/--fog-albedo/--fog-anisotropy: {e}"))?;
        Ok(scene)
    }

    /// What the flags choose about reading the file; the rest is `rt_io::load`'s policy,
    /// the editor's too.
    fn load_options(&self) -> LoadOptions {
        LoadOptions {
            seed: self.seed.unwrap_or(0),
            gltf_scene: self.gltf_scene,
            smooth_normals_deg: self.smooth_normals,
            animation_time: self.animation_time,
        }
    }
}

/// Turns the camera (position and target) by `turns` about the vertical axis (+y) through the
/// scene's centre: a turntable keeps the camera's distance and elevation.
fn orbit_vertically(scene: &mut Scene, turns: f32) {
    let Some((lo, hi)) = scene.bounds() else {
        return;
    };
    let centre = (lo + hi) * 0.5;
    let turn = glam::Quat::from_rotation_y(turns * std::f32::consts::TAU);
    let about = |p: [f32; 3]| (centre + turn * (glam::Vec3::from(p) - centre)).to_array();
    let camera = &mut scene.camera;
    camera.from = about(camera.from);
    camera.to = about(camera.to);
}

/// Makes every object named `name` a shadow catcher; an error lists the names there are.
fn mark_shadow_catcher(scene: &mut Scene, name: &str) -> Result<()> {
    let mut found = false;
    for object in scene.objects.iter_mut().filter(|o| o.name == name) {
        object.shadow_catcher = true;
        found = true;
    }
    if !found {
        let names: Vec<&str> = scene.objects.iter().map(|o| o.name.as_str()).collect();
        let more = names.len().saturating_sub(12);
        anyhow::bail!(
            "--shadow-catcher {name}: the scene has no object of that name; it has {}{}",
            names[..names.len().min(12)].join(", "),
            if more > 0 {
                format!(" and {more} more")
            } else {
                String::new()
            }
        );
    }
    Ok(())
}

fn is_gltf(path: &std::path::Path) -> bool {
    matches!(SceneFormat::of(path), Ok(SceneFormat::Gltf))
}
