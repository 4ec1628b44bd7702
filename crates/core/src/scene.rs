//! The scene document: objects (mesh + material + transform), textures, camera, ambient light and
//! render settings. This is what loaders produce, the editor edits and projects save.

use std::sync::Arc;

use glam::{Mat3, Mat4, Quat, Vec2, Vec3};
use serde::{Deserialize, Serialize};

use crate::camera::Camera;
use crate::material::{Material, Rgb};

/// A triangle mesh in object space. `normals` and `uvs`, when present, have one entry per position.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct Mesh {
    pub positions: Vec<Vec3>,
    pub normals: Option<Vec<Vec3>>,
    pub uvs: Option<Vec<Vec2>>,
    /// Linear RGB vertex colours (OBJ `v x y z r g b`, glTF COLOR_0); they multiply the albedo of
    /// diffuse and the base colour of PBR materials.
    #[serde(default)]
    pub colors: Option<Vec<Vec3>>,
    /// Counter-clockwise triangles (the front face), indexing `positions`.
    pub indices: Vec<[u32; 3]>,
}

/// Object-to-world transform: scale, then rotate (XYZ Euler angles in degrees), then translate.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Transform {
    pub translation: [f32; 3],
    pub rotation_deg: [f32; 3],
    pub scale: [f32; 3],
}

impl Default for Transform {
    fn default() -> Self {
        Transform {
            translation: [0.0; 3],
            rotation_deg: [0.0; 3],
            scale: [1.0; 3],
        }
    }
}

impl Transform {
    pub fn matrix(&self) -> Mat4 {
        let [rx, ry, rz] = self.rotation_deg.map(f32::to_radians);
        Mat4::from_scale_rotation_translation(
            Vec3::from(self.scale),
            Quat::from_euler(glam::EulerRot::XYZ, rx, ry, rz),
            Vec3::from(self.translation),
        )
    }

    /// The matrix that transforms normals (inverse transpose of the linear part).
    pub fn normal_matrix(&self) -> Mat3 {
        Mat3::from_mat4(self.matrix()).inverse().transpose()
    }
}

/// One renderable object.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Object {
    pub name: String,
    /// Shared, so that copies of a scene (undo history, render jobs) cost no mesh copies.
    pub mesh: Arc<Mesh>,
    pub material: Material,
    #[serde(default)]
    pub transform: Transform,
    /// A shadow catcher (Cycles' Object ▸ Shadow Catcher): on a transparent film it shows only
    /// the shadows and the reflections of other objects it receives
    /// (`estimator::shadow_catcher`); on an opaque one it renders as its material.
    #[serde(default, skip_serializing_if = "std::ops::Not::not")]
    pub shadow_catcher: bool,
    /// The node of the scene's animation that carries the object (`crate::animation`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub animation_node: Option<u32>,
}

/// An RGBA8 image in sRGB encoding, referenced by `Material::Lambertian::texture`.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Texture {
    /// Where it came from (for messages and saving).
    pub name: String,
    pub width: u32,
    pub height: u32,
    /// Shared like meshes; not serialised (project files store the image itself).
    #[serde(skip)]
    pub rgba8: Arc<[u8]>,
    /// How lookups outside [0, 1] wrap and whether texels are blended (glTF's sampler).
    #[serde(default)]
    pub sampler: TextureSampler,
}

/// What a texture coordinate outside [0, 1] reads (glTF's `wrapS`/`wrapT`, OpenGL's modes).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Wrap {
    /// The image tiles the plane.
    #[default]
    Repeat,
    /// The edge texels extend outwards.
    ClampToEdge,
    /// The image tiles the plane, every other copy mirrored.
    MirroredRepeat,
}

/// How texels between sample points blend. rt has no mipmaps, so this is glTF's magnification
/// filter: `Nearest` keeps pixel art's hard edges.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Filter {
    /// Bilinear interpolation of the four nearest texels.
    #[default]
    Linear,
    /// The texel the coordinate falls in.
    Nearest,
}

/// A texture's sampling state; the default repeats and filters bilinearly (OBJ's behaviour).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(default)]
pub struct TextureSampler {
    pub wrap_s: Wrap,
    pub wrap_t: Wrap,
    pub filter: Filter,
}

impl TextureSampler {
    /// The sampler packed as the kernels read it (`gpu_types::Material::samplers`): bits 0–1 the
    /// s wrap, 2–3 the t wrap (0 repeat, 1 clamp, 2 mirror), bit 4 nearest filtering.
    pub fn bits(&self) -> u32 {
        use crate::gpu_types::{FILTER_NEAREST, WRAP_CLAMP, WRAP_MIRROR};
        let wrap = |w: Wrap| match w {
            Wrap::Repeat => 0,
            Wrap::ClampToEdge => WRAP_CLAMP,
            Wrap::MirroredRepeat => WRAP_MIRROR,
        };
        let nearest = if self.filter == Filter::Nearest {
            FILTER_NEAREST
        } else {
            0
        };
        wrap(self.wrap_s) | wrap(self.wrap_t) << 2 | nearest
    }
}

/// Image size, sample count and path length.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct RenderSettings {
    pub width: u32,
    pub height: u32,
    pub samples_per_pixel: u32,
    /// Ray segments per path: 1 shows emitters seen directly, 2 adds direct lighting, and so on.
    pub max_depth: u32,
    pub seed: u32,
    /// Sample emitters directly at diffuse surfaces and combine with BSDF sampling by multiple
    /// importance sampling (on by default; off gives the BSDF-sampling-only estimator).
    #[serde(default = "default_true")]
    pub next_event_estimation: bool,
    /// End paths at random once their throughput is low (unbiased: survivors are re-weighted); on by
    /// default.
    #[serde(default = "default_true")]
    pub russian_roulette: bool,
    /// Firefly clamp: the most any contribution of bounced light may add per channel (biased:
    /// removes energy from rare bright paths to cut noise; directly seen emitters stay exact).
    /// `None`, the default, leaves samples alone.
    #[serde(default)]
    pub clamp: Option<f32>,
    /// Where the random numbers come from: Owen-scrambled Sobol points (the default: less noise
    /// for the same samples; `math::rng`) or independent PCG streams.
    #[serde(default)]
    pub sampler: crate::math::rng::SamplerKind,
    /// Diagnostic: with next-event estimation on, take area lights from next-event estimation alone
    /// (an emitter reached by a BSDF sample after a diffuse bounce counts zero) instead of combining
    /// both strategies by MIS. Unbiased but noisier; it exists so tests can check that the three
    /// estimators agree. Off by default.
    #[serde(default)]
    pub nee_only: bool,
    /// Adaptive sampling: once a pixel has `adaptive_min_samples` samples, it stops taking more as
    /// soon as its estimated noise (the square root of its term of the image's estimated relMSE,
    /// `metrics::pixel_rel_mse`) is at most this, and so do its neighbours', on each of its two
    /// streams of samples (`crate::adaptive`). `None`, the default, gives every pixel every sample.
    #[serde(default)]
    pub adaptive_threshold: Option<f32>,
    /// The samples every pixel takes before adaptive sampling may stop it (Cycles' Min Samples;
    /// half in each of its two streams).
    #[serde(default = "default_adaptive_min_samples")]
    pub adaptive_min_samples: u32,
    /// How next-event estimation picks an emitter: by its power alone, or by its importance at the
    /// shading point through the light tree (`crate::light_tree`, which also holds the point and
    /// spot lights); by default the tree where the scene has many lights.
    #[serde(default)]
    pub light_sampler: LightSampler,
    /// The image is this window of a larger film (a render region): the camera maps the film, the
    /// image holds `width × height` of its pixels from (`x`, `y`), and each of those pixels takes
    /// the random numbers it has in the whole film, so a region equals the same window of the
    /// full render. `None`: the image is the whole film.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub film_window: Option<FilmWindow>,
    /// A transparent film (Cycles' Film ▸ Transparent): the background seen directly adds no
    /// light, and each pixel's alpha is the share of its camera rays that met a surface (glass
    /// counts as met). The background still lights the scene.
    #[serde(default, skip_serializing_if = "std::ops::Not::not")]
    pub transparent: bool,
    /// How light is gathered: path tracing (every backend) or bidirectional path tracing (the CPU
    /// backend).
    #[serde(default, skip_serializing_if = "Integrator::is_path")]
    pub integrator: Integrator,
}

/// How a frame's light is gathered (`RenderSettings::integrator`).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Integrator {
    /// Path tracing from the camera with next-event estimation and MIS.
    #[default]
    Path,
    /// Bidirectional path tracing (`crate::bdpt`): paths from the camera and from the lights,
    /// joined every way; caustics that camera paths miss. The CPU backend only.
    Bdpt,
}

impl Integrator {
    pub fn is_path(&self) -> bool {
        *self == Integrator::Path
    }
}

impl RenderSettings {
    /// Renders only the window `[x0, y0, x1, y1)` (pixels) of the image these settings describe
    /// (Blender's render region): the image becomes the window, its pixels the samples the whole
    /// image takes there (`film_window`). An error where the region leaves the image or the
    /// settings already render a window of another.
    pub fn crop_to_region(&mut self, [x0, y0, x1, y1]: [u32; 4]) -> Result<(), String> {
        if let Some(w) = self.film_window
            && (w.x, w.y, w.film_width, w.film_height) != (0, 0, self.width, self.height)
        {
            return Err(
                "the scene already renders a region; give the region of the whole image instead"
                    .into(),
            );
        }
        let (film_width, film_height) = (self.width, self.height);
        if x0 >= x1 || y0 >= y1 {
            return Err(format!("the region {x0},{y0},{x1},{y1} is empty"));
        }
        if x1 > film_width || y1 > film_height {
            return Err(format!(
                "the region {x0},{y0},{x1},{y1} reaches past the {film_width}x{film_height} image"
            ));
        }
        self.film_window = Some(FilmWindow {
            x: x0,
            y: y0,
            film_width,
            film_height,
        });
        self.width = x1 - x0;
        self.height = y1 - y0;
        Ok(())
    }
}

/// Where an image sits in the film it is a window of (`RenderSettings::film_window`).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub struct FilmWindow {
    /// The window's top-left pixel in the film.
    pub x: u32,
    pub y: u32,
    /// The whole film's size in pixels.
    pub film_width: u32,
    pub film_height: u32,
}

/// How next-event estimation picks a light (`RenderSettings::light_sampler`).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum LightSampler {
    /// The tree where the scene has at least `AUTO_TREE_MIN_LIGHTS` emitter triangles, point and
    /// spot lights, else by power (docs/quality.md, "Many lights", has the measurements behind
    /// the threshold).
    #[default]
    Auto,
    /// An emitter triangle in proportion to its power (area × luminance of its emission),
    /// wherever the shading point is: one alias-table lookup; every point and spot light is
    /// summed at each vertex (a shadow ray each).
    Power,
    /// An emitter triangle, point or spot light by its importance at the shading point (power,
    /// distance and orientation bounds) through the light tree: far fewer wasted shadow rays
    /// where many lights lie far away or face away, and one shadow ray for all of them.
    Tree,
}

/// The fewest lights (emitter triangles, point and spot lights) for which `LightSampler::Auto`
/// takes the tree: with 2 (the Cornell box's lamp) it costs 5.8% more instructions a sample for
/// the same noise, with 8 it breaks even, with 32 it has 1.24× and with 2,048 2.7× lower error
/// in equal time.
pub const AUTO_TREE_MIN_LIGHTS: usize = 16;

impl LightSampler {
    /// Whether a scene with `lights` emitter triangles, point and spot lights samples them
    /// through the light tree.
    pub fn uses_tree(self, lights: usize) -> bool {
        match self {
            LightSampler::Auto => lights >= AUTO_TREE_MIN_LIGHTS,
            LightSampler::Power => false,
            LightSampler::Tree => true,
        }
    }
}

/// Samples every pixel takes before adaptive sampling may stop it (half in each stream): fewer let
/// a stream that has not yet met a rare bright path fire early and freeze the other at a handful
/// of samples (on the glass-caustics scene 16 gave 2.4× the relMSE of 64, docs/quality.md).
pub const ADAPTIVE_MIN_SAMPLES: u32 = 64;

fn default_adaptive_min_samples() -> u32 {
    ADAPTIVE_MIN_SAMPLES
}

fn default_true() -> bool {
    true
}

impl Default for RenderSettings {
    fn default() -> Self {
        RenderSettings {
            width: 512,
            height: 512,
            samples_per_pixel: 64,
            max_depth: 8,
            seed: 0,
            next_event_estimation: true,
            russian_roulette: true,
            clamp: None,
            sampler: Default::default(),
            nee_only: false,
            adaptive_threshold: None,
            adaptive_min_samples: ADAPTIVE_MIN_SAMPLES,
            light_sampler: LightSampler::default(),
            film_window: None,
            transparent: false,
            integrator: Integrator::Path,
        }
    }
}

/// Largest image side rt accepts (the framebuffer also has to fit the adapter's storage limits).
pub const MAX_IMAGE_SIDE: u32 = 16384;

impl RenderSettings {
    pub fn validate(&self) -> Result<(), String> {
        if self.width == 0 || self.height == 0 {
            return Err(format!(
                "image size must be at least 1x1, got {}x{}",
                self.width, self.height
            ));
        }
        if self.width > MAX_IMAGE_SIDE || self.height > MAX_IMAGE_SIDE {
            return Err(format!(
                "image size {}x{} exceeds the limit of {MAX_IMAGE_SIDE} pixels per side",
                self.width, self.height
            ));
        }
        if self.samples_per_pixel == 0 {
            return Err("samples per pixel must be at least 1".into());
        }
        if let Some(w) = self.film_window {
            let inside = |start: u32, len: u32, film: u32| {
                film > 0
                    && film <= MAX_IMAGE_SIDE
                    && start.checked_add(len).is_some_and(|e| e <= film)
            };
            if !(inside(w.x, self.width, w.film_width) && inside(w.y, self.height, w.film_height)) {
                return Err(format!(
                    "the region {}x{} at ({}, {}) does not fit in the {}x{} image",
                    self.width, self.height, w.x, w.y, w.film_width, w.film_height
                ));
            }
        }
        if let Some(c) = self.clamp
            && !(c.is_finite() && c > 0.0)
        {
            return Err(format!(
                "the firefly clamp must be a positive number, got {c}"
            ));
        }
        if let Some(t) = self.adaptive_threshold
            && !(t.is_finite() && t > 0.0)
        {
            return Err(format!(
                "the adaptive sampling threshold must be a positive number, got {t}"
            ));
        }
        if self.adaptive_min_samples < 2 {
            return Err(format!(
                "adaptive sampling needs at least 2 samples per pixel before it stops one (one \
                 in each of its two streams), got {}",
                self.adaptive_min_samples
            ));
        }
        Ok(())
    }
}

/// A whole scene.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct Scene {
    pub objects: Vec<Object>,
    pub textures: Vec<Texture>,
    pub camera: Camera,
    /// Radiance of rays that leave the scene (a constant environment).
    pub ambient: Rgb,
    pub settings: RenderSettings,
    /// Point, spot and directional lights (emissive objects are lights too).
    #[serde(default)]
    pub lights: Vec<crate::light::Light>,
    /// An environment map; it replaces `ambient` for rays that leave the scene.
    #[serde(default)]
    pub environment: Option<crate::environment::Environment>,
    /// Fog filling the space outside closed objects (`crate::fog`; off by default).
    #[serde(default)]
    pub fog: crate::fog::Fog,
    /// The nodes and channels that move objects, lights and the camera over time, at rest here
    /// (`crate::posing::posed_at` places them at a time). Shared: copies of a scene (undo
    /// history, render jobs) cost no copies of its keys.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub animation: Option<Arc<crate::animation::Animation>>,
}

impl Scene {
    pub fn triangle_count(&self) -> usize {
        self.objects.iter().map(|o| o.mesh.indices.len()).sum()
    }

    /// World-space bounds of all objects, or `None` for an empty scene.
    /// Copies of one mesh that differ only in where they stand (a grid, a crowd placed without
    /// turning) share the box of their mesh under their turn and scale, found once: an exact box
    /// at the cost of one pass over each mesh's vertices, not one over every copy's.
    pub fn bounds(&self) -> Option<(Vec3, Vec3)> {
        let mut bounds: Option<(Vec3, Vec3)> = None;
        type Turned = (*const Mesh, [u32; 9]);
        let mut placed: std::collections::HashMap<Turned, Option<(Vec3, Vec3)>> =
            std::collections::HashMap::new();
        for object in &self.objects {
            let m = object.transform.matrix();
            let linear = glam::Mat3::from_mat4(m);
            let key = (
                Arc::as_ptr(&object.mesh),
                linear.to_cols_array().map(f32::to_bits),
            );
            let unmoved = *placed.entry(key).or_insert_with(|| {
                let mut b: Option<(Vec3, Vec3)> = None;
                for p in &object.mesh.positions {
                    let p = linear * *p;
                    b = Some(b.map_or((p, p), |(lo, hi)| (lo.min(p), hi.max(p))));
                }
                b
            });
            let Some((lo, hi)) = unmoved else { continue };
            let t = m.w_axis.truncate();
            let (lo, hi) = (lo + t, hi + t);
            bounds = Some(bounds.map_or((lo, hi), |(blo, bhi)| (blo.min(lo), bhi.max(hi))));
        }
        bounds
    }

    pub fn has_emitters(&self) -> bool {
        self.objects
            .iter()
            .any(|o| matches!(o.material, Material::Emissive { .. }))
    }

    /// Points the camera at the whole scene along +z and, when nothing emits light, gives the scene
    /// a dim grey ambient so that it is not black: what a freshly loaded OBJ without a camera needs.
    pub fn frame_for_viewing(&mut self) {
        if let Some((lo, hi)) = self.bounds() {
            self.camera.from = self.camera.to;
            self.camera.from[2] += 1.0;
            self.camera.up = [0.0, 1.0, 0.0];
            self.camera.frame_bounds(lo, hi);
        }
        if !self.has_emitters() {
            self.ambient = [0.8; 3];
        }
    }
}
