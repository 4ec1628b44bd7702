//! What one preview frame draws ([`PreviewFrame`], built from the scene on the calling thread; cheap:
//! meshes, texels and the environment are shared): the camera, the lights in the render's units
//! with their shadow maps' views, each object's material as the shader's metallic-roughness
//! parameters, the environment to prefilter, and the ground grid.

use std::hash::{Hash, Hasher};
use std::sync::Arc;

use glam::{Mat3, Mat4, Vec3};
use rt_core::environment::EnvironmentMap;
use rt_core::light::SpotFalloff;
use rt_core::material::AlphaMode;
use rt_core::math::sampling::luminance;
use rt_core::{Camera, LightKind, Material, Mesh, Scene};

use super::bounce::{IrradianceVolume, Sky};
use super::shadows::{ShadowPlan, plan_shadows};
use super::surfaces::{emitter_shape, layer_params, material_params};
use super::types::{
    GridVertex, MAX_PREVIEW_LIGHTS, NO_SHADOW, PreviewLight, PreviewObject, PreviewView, light_kind,
};
use super::volume_cache::irradiance_volume;

/// A texture's texels, shared with the scene.
#[derive(Clone)]
pub struct TextureRef {
    pub texels: Arc<[u8]>,
    pub width: u32,
    pub height: u32,
}

/// A material's images: base colour, metallic-roughness, normal map, emission (`None`: the slot's
/// neutral default: white, or a flat normal).
#[derive(Clone, Default)]
pub struct MaterialTextures {
    pub slots: [Option<TextureRef>; 4],
}

/// The light from outside the scene: the environment map (times `strength`) or the constant
/// ambient radiance. `key` names it for the renderer's cache of its prefiltered copies.
#[derive(Clone)]
pub struct PreviewEnvironment {
    pub map: Option<Arc<EnvironmentMap>>,
    pub strength: f32,
    pub ambient: [f32; 3],
    pub key: u64,
}

/// Everything one preview frame draws.
#[derive(Clone)]
pub struct PreviewFrame {
    pub size_px: [u32; 2],
    pub view: PreviewView,
    pub objects: Vec<PreviewObject>,
    pub meshes: Vec<Arc<Mesh>>,
    pub textures: Vec<MaterialTextures>,
    /// Objects drawn after the opaque ones, over what they cover (transmission, alpha blending).
    pub blended: Vec<bool>,
    pub grid: Vec<GridVertex>,
    pub shadows: ShadowPlan,
    pub environment: PreviewEnvironment,
    /// Bounce light (`bounce.rs`).
    pub volume: Arc<IrradianceVolume>,
    /// The bounce light is still being rebuilt on a thread (`build_interactive_frame`).
    pub settling: bool,
}

/// The projection the preview uses for `camera` at `aspect`, with depth range fitted to the scene.
pub fn view_projection(camera: &Camera, aspect: f32, bounds: Option<(Vec3, Vec3)>) -> Mat4 {
    let eye = Vec3::from(camera.from);
    let (center, radius) = match bounds {
        Some((lo, hi)) => ((lo + hi) * 0.5, ((hi - lo).length() * 0.5).max(1e-6)),
        None => (Vec3::from(camera.to), 1.0),
    };
    let distance = (eye - center).length();
    let far = (distance + radius * 2.0).max(1e-4);
    let near = ((distance - radius) * 0.9).max(far * 1e-4);
    let up = Vec3::from(camera.up);
    // wgpu clip space: depth in [0, 1], y up (the "directx" convention).
    let view = glam::camera::rh::view::look_at_mat4(eye, Vec3::from(camera.to), up);
    let aspect = aspect.max(1e-6);
    // Panorama and fisheye have no matrix: the raster preview draws them as the perspective
    // view (the path-traced view shows them as rendered).
    let proj = if camera.projection == rt_core::camera::Projection::Orthographic {
        let half_h = camera.ortho_height_in(bounds) * 0.5;
        let half_w = half_h * aspect;
        let near = ((distance - radius) * 0.9).max(0.0);
        glam::camera::rh::proj::directx::orthographic(-half_w, half_w, -half_h, half_h, near, far)
    } else {
        glam::camera::rh::proj::directx::perspective(
            camera.vfov_deg.clamp(0.01, 179.0).to_radians(),
            aspect,
            near,
            far,
        )
    };
    proj * view
}

/// A light and how much power it sends into the scene (which lights the preview keeps).
struct Ranked {
    light: PreviewLight,
    power: f32,
}

fn emitter_light(index: usize, object: &rt_core::Object) -> Option<Ranked> {
    let radiance = match &object.material {
        Material::Emissive { color, intensity } => Vec3::from(*color) * *intensity,
        Material::Pbr(p) => Vec3::from(p.emission) * p.emission_strength,
        _ => return None,
    };
    if luminance(radiance) <= 0.0 || !radiance.is_finite() {
        return None;
    }
    let (area, center, normal) = emitter_shape(object);
    let isotropic = ((area - normal.length()) * 0.25).max(0.0);
    Some(Ranked {
        light: PreviewLight {
            position: center.extend(1.0).to_array(),
            color: radiance.extend(isotropic).to_array(),
            direction: normal.extend(0.0).to_array(),
            cone: [0.0; 4],
            shadow: [light_kind::EMITTER, NO_SHADOW, 0, index as u32 + 1],
        },
        power: luminance(radiance) * std::f32::consts::PI * area,
    })
}

fn scene_light(light: &rt_core::Light, radius: f32) -> Ranked {
    let strength = Vec3::from(light.color) * light.intensity;
    let axis = Vec3::from(light.direction).normalize_or(Vec3::NEG_Y);
    let (kind, power) = match light.kind {
        LightKind::Point => (light_kind::POINT, 4.0 * std::f32::consts::PI),
        LightKind::Spot => {
            let cos_outer = light.outer_angle_deg.to_radians().cos();
            (light_kind::SPOT, std::f32::consts::TAU * (1.0 - cos_outer))
        }
        LightKind::Directional => (
            light_kind::DIRECTIONAL,
            std::f32::consts::PI * radius * radius,
        ),
    };
    let (cos_inner, cos_outer) = match light.kind {
        LightKind::Spot => (
            light.inner_angle_deg.to_radians().cos(),
            light.outer_angle_deg.to_radians().cos(),
        ),
        _ => (1.0, -1.0),
    };
    let gltf = f32::from(u8::from(light.falloff == SpotFalloff::Gltf));
    Ranked {
        light: PreviewLight {
            position: Vec3::from(light.position).extend(0.0).to_array(),
            color: strength.extend(0.0).to_array(),
            direction: axis.extend(cos_outer).to_array(),
            cone: [cos_inner, gltf, 0.0, 0.0],
            shadow: [kind, NO_SHADOW, 0, 0],
        },
        power: luminance(strength) * power,
    }
}

/// The environment's sun as a directional light (`sun.rs`), if it has one.
fn environment_sun(scene: &Scene, radius: f32) -> Option<Ranked> {
    let env = scene.environment.as_ref()?;
    let sun = crate::sun::of(&env.map)?;
    let strength = env.strength.max(0.0);
    let mut light = rt_core::Light::new(LightKind::Directional, "environment sun");
    light.direction = (-sun.world_direction(env.rotation_deg)).to_array();
    light.color = (sun.irradiance * strength).to_array();
    light.intensity = 1.0;
    let mut ranked = scene_light(&light, radius);
    // Glass sees the sun's disc through it (`refracted` in the shader): its size.
    ranked.light.position[3] = sun.solid_angle;
    Some(ranked)
}

/// The environment as the irradiance volume sees it: without its sun (a light of its own), turned.
fn sky(scene: &Scene) -> Sky {
    let Some(env) = &scene.environment else {
        return Sky::uniform(Vec3::from(scene.ambient));
    };
    Sky {
        mean: sky_radiance(scene),
        map: Some(crate::sun::sky_of(&env.map)),
        turns: env.rotation_deg / 360.0,
    }
}

/// The environment's mean radiance (what a surface open to all of it receives over π), or the
/// ambient colour; an environment's is kept for the next frames (a large image takes milliseconds).
fn sky_radiance(scene: &Scene) -> Vec3 {
    // Holding the map keeps its address, the key, from being reused.
    type Last = Option<(Arc<EnvironmentMap>, Vec3)>;
    static LAST: std::sync::Mutex<Last> = std::sync::Mutex::new(None);
    let Some(env) = &scene.environment else {
        return Vec3::from(scene.ambient);
    };
    // The sun's light comes from its own light.
    let map = crate::sun::sky_of(&env.map);
    let mut last = LAST.lock().unwrap_or_else(|e| e.into_inner());
    let mean = match last.as_ref() {
        Some((kept, mean)) if Arc::ptr_eq(kept, &map) => *mean,
        _ => {
            let mean = mean_radiance(&map);
            *last = Some((map.clone(), mean));
            mean
        }
    };
    mean * env.strength.max(0.0)
}

/// An environment map's mean radiance over the sphere (rows weighted by their solid angle).
fn mean_radiance(map: &EnvironmentMap) -> Vec3 {
    let (mut sum, mut weight) = (Vec3::ZERO, 0.0f32);
    for (i, t) in map.texels.iter().enumerate() {
        let row = (i as u32 / map.width.max(1)) as f32;
        let w = (std::f32::consts::PI * (row + 0.5) / map.height.max(1) as f32).sin();
        sum += Vec3::from(*t) * w;
        weight += w;
    }
    if weight > 0.0 {
        sum / weight
    } else {
        Vec3::ZERO
    }
}

/// The environment's cache key: the map's address and strength, or the ambient radiance.
fn environment(scene: &Scene) -> PreviewEnvironment {
    let mut hasher = std::collections::hash_map::DefaultHasher::new();
    match &scene.environment {
        Some(env) => {
            (Arc::as_ptr(&env.map) as usize).hash(&mut hasher);
            env.strength.to_bits().hash(&mut hasher);
            // Without its sun, which lights the preview as a light of its own (`sun.rs`).
            let map = crate::sun::sky_of(&env.map);
            PreviewEnvironment {
                map: Some(map),
                strength: env.strength,
                ambient: [0.0; 3],
                key: hasher.finish(),
            }
        }
        None => {
            scene.ambient.map(f32::to_bits).hash(&mut hasher);
            PreviewEnvironment {
                map: None,
                strength: 1.0,
                ambient: scene.ambient,
                key: hasher.finish(),
            }
        }
    }
}

/// Builds the frame for `scene` (whose bounds are given) seen by `camera` in a viewport of
/// `size_px` pixels, with everything it draws complete (`rt-cli preview`, tests, benchmarks).
pub fn build_frame(
    scene: &Scene,
    camera: &Camera,
    bounds: Option<(Vec3, Vec3)>,
    selection: Option<usize>,
    size_px: [u32; 2],
) -> PreviewFrame {
    frame_with(scene, camera, bounds, selection, size_px, true)
}

/// As `build_frame`, for an interactive view: a large scene's bounce light is rebuilt on a thread
/// after a change, and until it is ready the frame shows the last one and is `settling` (draw
/// again soon).
pub fn build_interactive_frame(
    scene: &Scene,
    camera: &Camera,
    bounds: Option<(Vec3, Vec3)>,
    selection: Option<usize>,
    size_px: [u32; 2],
) -> PreviewFrame {
    frame_with(scene, camera, bounds, selection, size_px, false)
}

fn frame_with(
    scene: &Scene,
    camera: &Camera,
    bounds: Option<(Vec3, Vec3)>,
    selection: Option<usize>,
    size_px: [u32; 2],
    wait: bool,
) -> PreviewFrame {
    let aspect = size_px[0].max(1) as f32 / size_px[1].max(1) as f32;
    let view_proj = view_projection(camera, aspect, bounds);
    let (center, radius) = bounds.map_or((Vec3::ZERO, 1.0), |(lo, hi)| {
        ((lo + hi) * 0.5, ((hi - lo).length() * 0.5).max(1e-6))
    });

    let mut lights = preview_lights(scene, radius);
    let shadows = plan_shadows(&mut lights, scene, center, radius);
    let (mut volume, settling) = irradiance_volume(scene, &lights, bounds, &sky(scene), wait);
    if scene.settings.max_depth <= 2 {
        volume = Arc::new(volume.direct_only());
    }

    let glow = fog_glow(scene, &lights, center, radius);
    let fog = &scene.fog;
    let rotation = scene
        .environment
        .as_ref()
        .map_or(0.0, |e| e.rotation_deg / 360.0);
    let mut view = PreviewView {
        view_proj: view_proj.to_cols_array_2d(),
        inverse_view_proj: view_proj.inverse().to_cols_array_2d(),
        eye: Vec3::from(camera.from).extend(rotation).to_array(),
        fog: glow
            .extend(if fog.is_on() { fog.density } else { 0.0 })
            .to_array(),
        ambient: match &scene.environment {
            Some(_) => [0.0; 4],
            None => Vec3::from(scene.ambient).extend(1.0).to_array(),
        },
        probe_lo: volume.lo.extend(0.0).to_array(),
        probe_hi: volume.hi.extend(0.0).to_array(),
        light_count: lights.len() as u32,
        max_depth: scene.settings.max_depth,
        _pad1: 0,
        _pad2: 0,
        lights: [PreviewLight::default(); MAX_PREVIEW_LIGHTS],
    };
    view.lights[..lights.len()].copy_from_slice(&lights);

    let count = scene.objects.len();
    let mut objects = Vec::with_capacity(count);
    let mut meshes = Vec::with_capacity(count);
    let mut textures = Vec::with_capacity(count);
    let mut blended = Vec::with_capacity(count);
    for (i, object) in scene.objects.iter().enumerate() {
        let (record, maps, is_blended) = preview_object(scene, object, selection == Some(i));
        blended.push(is_blended);
        objects.push(record);
        meshes.push(object.mesh.clone());
        textures.push(maps);
    }
    let grid = bounds.map_or_else(
        || grid_lines(Vec3::ZERO, 1.0),
        |(lo, hi)| {
            let extent = (hi - lo).max_element();
            // Just below the lowest surface, not in its plane: a floor there hides the grid
            // instead of fighting it for depth (rows of dashes across the floor).
            let y = lo.y - GRID_DROP * extent;
            grid_lines(Vec3::new(center.x, y, center.z), extent)
        },
    );
    PreviewFrame {
        size_px,
        view,
        objects,
        meshes,
        textures,
        blended,
        grid,
        shadows,
        environment: environment(scene),
        volume,
        settling,
    }
}

/// The scene's lights as the preview draws them: emitters and delta lights, the most powerful
/// `MAX_PREVIEW_LIGHTS`.
fn preview_lights(scene: &Scene, radius: f32) -> Vec<PreviewLight> {
    let mut ranked: Vec<Ranked> = scene
        .objects
        .iter()
        .enumerate()
        .filter_map(|(i, o)| emitter_light(i, o))
        .chain(scene.lights.iter().map(|l| scene_light(l, radius)))
        .chain(environment_sun(scene, radius))
        .filter(|r| r.power.is_finite() && r.power > 0.0)
        .collect();
    ranked.sort_by(|a, b| b.power.total_cmp(&a.power));
    ranked.truncate(MAX_PREVIEW_LIGHTS);
    ranked.into_iter().map(|r| r.light).collect()
}

/// Fog: what it glows with where it is thick, single scattering of the irradiance at the scene's
/// centre, evenly (albedo · E / 4π); the shader blends it in by exp(−σ_t d).
fn fog_glow(scene: &Scene, lights: &[PreviewLight], center: Vec3, radius: f32) -> Vec3 {
    let fog = &scene.fog;
    if fog.is_on() {
        let mut irradiance = std::f32::consts::PI * luminance(Vec3::from(scene.ambient));
        for light in lights {
            let color = luminance(Vec3::from_slice(&light.color[..3]));
            irradiance += if light.shadow[0] == light_kind::DIRECTIONAL {
                color
            } else {
                let d2 = (Vec3::from_slice(&light.position[..3]) - center)
                    .length_squared()
                    .max((radius * 0.1).powi(2));
                let scale = if light.shadow[0] == light_kind::EMITTER {
                    Vec3::from_slice(&light.direction[..3]).length() + light.color[3]
                } else {
                    1.0
                };
                color * scale / d2
            };
        }
        Vec3::from(fog.albedo) * irradiance / (4.0 * std::f32::consts::PI)
    } else {
        Vec3::ZERO
    }
}

/// Solid glass's attenuation per unit length, σ = −ln(colour) / distance (Beer–Lambert, as the
/// render's medium behind the surface); zero where the material has no such volume.
fn glass_attenuation(material: &Material) -> Vec3 {
    match material {
        Material::Pbr(p) if p.transmission > 0.0 && !p.thin_walled => {
            match p.attenuation_distance {
                Some(d) if d > 0.0 => {
                    Vec3::from(p.attenuation_color)
                        .max(Vec3::splat(1e-6))
                        .map(f32::ln)
                        * (-1.0 / d)
                }
                _ => Vec3::ZERO,
            }
        }
        _ => Vec3::ZERO,
    }
}

/// Half the diagonal of the box around `mesh`'s vertices turned and scaled by `linear`: how far a
/// view refracted into solid glass travels through it. A frame is built for every frame the
/// viewport draws, so each (mesh, turn and scale) is measured once and remembered (a million
/// vertices took milliseconds a frame); a mesh dropped and another allocated where it was is
/// measured anew (the entry holds the mesh weakly).
fn glass_radius(mesh: &Arc<rt_core::Mesh>, linear: Mat3) -> f32 {
    type Key = (usize, [u32; 9]);
    thread_local! {
        static MEASURED: std::cell::RefCell<std::collections::HashMap<Key, (std::sync::Weak<rt_core::Mesh>, f32)>> =
            Default::default();
    }
    let key = (
        Arc::as_ptr(mesh) as usize,
        linear.to_cols_array().map(f32::to_bits),
    );
    let known = MEASURED.with_borrow(|m| {
        m.get(&key)
            .filter(|(weak, _)| weak.upgrade().is_some_and(|m| Arc::ptr_eq(&m, mesh)))
            .map(|(_, r)| *r)
    });
    if let Some(radius) = known {
        return radius;
    }
    let (lo, hi) = mesh.positions.iter().fold(
        (Vec3::splat(f32::MAX), Vec3::splat(f32::MIN)),
        |(lo, hi), p| (lo.min(linear * *p), hi.max(linear * *p)),
    );
    let radius = if lo.x <= hi.x {
        0.5 * (hi - lo).length()
    } else {
        0.0
    };
    MEASURED.with_borrow_mut(|m| {
        // Forget what was measured before it piles up (a dragged object leaves a trail of turns).
        if m.len() >= 256 {
            m.clear();
        }
        m.insert(key, (Arc::downgrade(mesh), radius));
    });
    radius
}

/// An object's record, its material's images, and whether it is drawn blended (transmission or
/// alpha).
fn preview_object(
    scene: &Scene,
    object: &rt_core::Object,
    selected: bool,
) -> (PreviewObject, MaterialTextures, bool) {
    let model = object.transform.matrix();
    let normal_matrix = Mat4::from_mat3(Mat3::from_mat4(model).inverse().transpose());
    // An alpha mask cuts its holes in the preview too: a fragment whose image alpha is below
    // cutoff / alpha-factor is discarded (0: nothing is cut).
    let mask = match &object.material {
        Material::Pbr(p) if p.alpha_mode == AlphaMode::Mask => p.alpha_cutoff / p.alpha.max(1e-6),
        _ => 0.0,
    };
    let (base, emission, params, alpha, texture) = material_params(&object.material);
    let image = |slot: Option<usize>| {
        slot.and_then(|t| scene.textures.get(t))
            .map(|t| TextureRef {
                texels: t.rgba8.clone(),
                width: t.width,
                height: t.height,
            })
    };
    // The dielectric layer's F90: glTF's `specular` scales it with F0; glass and metals (whose
    // own F90, 1, the shader takes) have one at full strength; Lambertians and emitters none.
    let f90 = match &object.material {
        Material::Pbr(p) => p.specular.clamp(0.0, 1.0),
        Material::Dielectric { .. } | Material::Metal { .. } => 1.0,
        Material::Lambertian { .. } | Material::Emissive { .. } => 0.0,
    };
    let (layers, sheen, anisotropy) = layer_params(&object.material, &scene.textures);
    // Solid glass refracts what lies beyond it (the shader bends the view through it); a thin
    // sheet, as alpha, shows what lies behind unbent.
    let refracting_ior = match &object.material {
        Material::Dielectric { ior, .. } => *ior,
        Material::Pbr(p) if p.transmission > 0.0 && !p.thin_walled => p.ior,
        _ => 0.0,
    };
    // How far a refracted view travels through it: the radius of its bounding sphere.
    let glass_radius = if refracting_ior > 0.0 {
        glass_radius(&object.mesh, Mat3::from_mat4(model))
    } else {
        0.0
    };
    let (maps, normal_scale) = match &object.material {
        Material::Pbr(p) => (
            [
                image(p.texture),
                image(p.metallic_roughness_texture),
                image(p.normal_texture),
                image(p.emission_texture),
            ],
            p.normal_scale,
        ),
        _ => ([image(texture), None, None, None], 1.0),
    };
    // Bit k: slot k holds an image; a normal map needs the interpolated normals it tilts (the
    // render's rule too).
    let images = maps
        .iter()
        .enumerate()
        .filter(|(slot, map)| map.is_some() && (*slot != 2 || object.mesh.normals.is_some()))
        .fold(0, |bits, (slot, _)| bits | 1 << slot);
    // Solid glass draws as opaque: what it shows is bent through it (the shader's `refracted`),
    // and the depth test keeps its far side from drawing over its near one.
    let blended = alpha < 1.0 || (params[2] > 0.0 && params[0] < 1.0 && refracting_ior == 0.0);
    let record = PreviewObject {
        model: model.to_cols_array_2d(),
        normal_matrix: normal_matrix.to_cols_array_2d(),
        base_color: Vec3::from(base).extend(mask).to_array(),
        emission: emission.extend(alpha).to_array(),
        params,
        extra: [normal_scale, f90, anisotropy[0], anisotropy[1]],
        flags: [
            u32::from(selected),
            images,
            u32::from(object.mesh.normals.is_some()),
            refracting_ior.max(0.0).to_bits(),
        ],
        layers,
        sheen: sheen.extend(0.0).to_array(),
        volume: glass_attenuation(&object.material)
            .extend(glass_radius)
            .to_array(),
    };
    (record, MaterialTextures { slots: maps }, blended)
}

/// How far below the scene's lowest point the grid lies, in scene extents: beyond the depth
/// buffer's resolution there (24 bits, near plane at 1e-4 of the far one at worst) yet invisible.
const GRID_DROP: f32 = 2e-3;

/// The grid's spacing for a scene `extent` across: a power of ten, ten-ish cells across it (also
/// what a move snaps to).
pub fn grid_step(extent: f32) -> f32 {
    10f32.powf((extent / 5.0).log10().floor())
}

/// Segments per grid line: the fade towards the rim is interpolated along them.
const GRID_SEGMENTS: i32 = 8;

/// A ground grid under the scene: ten-ish cells across its extent, at a round spacing, fading
/// out towards its rim (alpha 1 − (r/reach)², per segment end) as Blender's does into the
/// distance, so that it has no hard edge across the view.
pub fn grid_lines(center: Vec3, extent: f32) -> Vec<GridVertex> {
    let extent = if extent.is_finite() && extent > 0.0 {
        extent
    } else {
        1.0
    };
    let step = grid_step(extent);
    let half_cells = ((extent / step).ceil() as i32).clamp(1, 50);
    let snap = |v: f32| (v / step).round() * step;
    let (cx, cz) = (snap(center.x), snap(center.z));
    let y = center.y;
    let reach = half_cells as f32 * step;
    let mut lines = Vec::new();
    for k in -half_cells..=half_cells {
        let offset = k as f32 * step;
        let axis_x = (cz + offset).abs() < step * 0.5;
        let axis_z = (cx + offset).abs() < step * 0.5;
        let grey = [0.35, 0.35, 0.38, 1.0];
        let along_x = if axis_x {
            [0.75, 0.25, 0.25, 1.0]
        } else {
            grey
        };
        let along_z = if axis_z { [0.25, 0.35, 0.8, 1.0] } else { grey };
        let mut vertex = |x: f32, z: f32, [r, g, b, _]: [f32; 4]| {
            let t = Vec3::new(x - cx, 0.0, z - cz).length() / reach;
            lines.push(GridVertex {
                position: [x, y, z],
                color: [r, g, b, (1.0 - t * t).max(0.0)],
            });
        };
        for s in -GRID_SEGMENTS..GRID_SEGMENTS {
            let (a, b) = (
                reach * s as f32 / GRID_SEGMENTS as f32,
                reach * (s + 1) as f32 / GRID_SEGMENTS as f32,
            );
            vertex(cx + a, cz + offset, along_x);
            vertex(cx + b, cz + offset, along_x);
            vertex(cx + offset, cz + a, along_z);
            vertex(cx + offset, cz + b, along_z);
        }
    }
    lines
}

#[cfg(test)]
mod tests;
