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
use rt_core::{Camera, LightKind, Material, Mesh, Scene};

use super::bounce::{IrradianceVolume, irradiance_volume};
use super::shadows::{ShadowPlan, plan_shadows};
use super::surfaces::{emitter_shape, material_params};
use super::types::{
    GridVertex, MAX_PREVIEW_LIGHTS, NO_SHADOW, PreviewLight, PreviewObject, PreviewView, light_kind,
};

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
    let proj = glam::camera::rh::proj::directx::perspective(
        camera.vfov_deg.clamp(0.01, 179.0).to_radians(),
        aspect.max(1e-6),
        near,
        far,
    );
    proj * view
}

fn luminance(c: Vec3) -> f32 {
    c.dot(Vec3::new(0.2126, 0.7152, 0.0722))
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
        LightKind::Directional => (light_kind::SUN, std::f32::consts::PI * radius * radius),
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
            position: Vec3::from(light.position).extend(1.0).to_array(),
            color: strength.extend(0.0).to_array(),
            direction: axis.extend(cos_outer).to_array(),
            cone: [cos_inner, gltf, 0.0, 0.0],
            shadow: [kind, NO_SHADOW, 0, 0],
        },
        power: luminance(strength) * power,
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
    let mut last = LAST.lock().unwrap_or_else(|e| e.into_inner());
    let mean = match last.as_ref() {
        Some((map, mean)) if Arc::ptr_eq(map, &env.map) => *mean,
        _ => {
            let mean = mean_radiance(&env.map);
            *last = Some((env.map.clone(), mean));
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
            PreviewEnvironment {
                map: Some(env.map.clone()),
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

    let mut ranked: Vec<Ranked> = scene
        .objects
        .iter()
        .enumerate()
        .filter_map(|(i, o)| emitter_light(i, o))
        .chain(scene.lights.iter().map(|l| scene_light(l, radius)))
        .filter(|r| r.power.is_finite() && r.power > 0.0)
        .collect();
    ranked.sort_by(|a, b| b.power.total_cmp(&a.power));
    ranked.truncate(MAX_PREVIEW_LIGHTS);
    let mut lights: Vec<PreviewLight> = ranked.into_iter().map(|r| r.light).collect();
    let shadows = plan_shadows(&mut lights, scene, center, radius);
    let (volume, settling) = irradiance_volume(scene, &lights, bounds, sky_radiance(scene), wait);

    // Fog: what it glows with where it is thick, single scattering of the irradiance at the scene's
    // centre, evenly (albedo · E / 4π); the shader blends it in by exp(−σ_t d).
    let fog = &scene.fog;
    let glow = if fog.is_on() {
        let mut irradiance = std::f32::consts::PI * luminance(Vec3::from(scene.ambient));
        for light in &lights {
            let color = luminance(Vec3::from_slice(&light.color[..3]));
            irradiance += if light.shadow[0] == light_kind::SUN {
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
    };
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
        _pad0: 0,
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
        let model = object.transform.matrix();
        let normal_matrix = Mat4::from_mat3(Mat3::from_mat4(model).inverse().transpose());
        // An alpha mask cuts its holes in the preview too: a fragment whose image alpha is below
        // cutoff / alpha-factor is discarded (0: nothing is cut).
        let mask = match &object.material {
            Material::Pbr(p) if p.alpha_mode == AlphaMode::Mask => {
                p.alpha_cutoff / p.alpha.max(1e-6)
            }
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
        blended.push(alpha < 1.0 || (params[2] > 0.0 && params[0] < 1.0));
        objects.push(PreviewObject {
            model: model.to_cols_array_2d(),
            normal_matrix: normal_matrix.to_cols_array_2d(),
            base_color: Vec3::from(base).extend(mask).to_array(),
            emission: emission.extend(alpha).to_array(),
            params,
            extra: [normal_scale, f90, 0.0, 0.0],
            flags: [
                u32::from(selection == Some(i)),
                images,
                u32::from(object.mesh.normals.is_some()),
                0,
            ],
        });
        meshes.push(object.mesh.clone());
        textures.push(MaterialTextures { slots: maps });
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
mod tests {
    use super::*;
    use crate::preview::types::light_kind;

    #[test]
    fn the_cornell_frame_has_its_light_and_a_sane_exposure() {
        let scene = rt_core::assets::cornell_box().expect("embedded scene");
        let frame = build_frame(&scene, &scene.camera, scene.bounds(), Some(0), [400, 300]);
        assert_eq!(frame.objects.len(), scene.objects.len());
        assert_eq!(frame.view.light_count, 1);
        assert_eq!(frame.view.lights[0].shadow[0], light_kind::EMITTER);
        assert_eq!(frame.objects[0].flags[0], 1, "selection flagged");
        assert_eq!(frame.objects[1].flags[0], 0);
        // The light's centre lies under the ceiling, inside the box.
        let y = frame.view.lights[0].position[1];
        assert!(y > 400.0 && y < 560.0, "{y}");
        assert!(!frame.grid.is_empty() && frame.grid.len().is_multiple_of(2));
    }

    /// The grid lies just below the scene's lowest point (a floor there hides it rather than
    /// fighting it for depth), opaque at its centre and faded out at its rim.
    #[test]
    fn the_grid_lies_just_under_the_floor_and_fades_to_its_rim() {
        let scene = rt_core::assets::cornell_box().expect("embedded scene");
        let (lo, hi) = scene.bounds().unwrap();
        let frame = build_frame(&scene, &scene.camera, Some((lo, hi)), None, [400, 300]);
        let extent = (hi - lo).max_element();
        for v in &frame.grid {
            let below = lo.y - v.position[1];
            assert!(below > 1e-3 * extent && below < 1e-2 * extent, "{below}");
        }
        let alphas: Vec<f32> = frame.grid.iter().map(|v| v.color[3]).collect();
        let max = alphas.iter().copied().fold(0.0, f32::max);
        let min = alphas.iter().copied().fold(1.0, f32::min);
        assert!(max > 0.95 && min == 0.0, "alpha from {min} to {max}");
    }

    /// A PBR material's emission makes a preview light as an emissive material does, and a spot
    /// keeps its axis and cones (the other lights have none).
    #[test]
    fn pbr_emitters_light_the_preview_and_spots_keep_their_cones() {
        let mut scene = rt_core::assets::cornell_box().expect("embedded scene");
        scene
            .objects
            .retain(|o| !matches!(o.material, Material::Emissive { .. }));
        scene.objects[0].material = Material::Pbr(Box::new(rt_core::material::Pbr {
            emission: [1.0, 0.5, 0.2],
            emission_strength: 3.0,
            ..Default::default()
        }));
        let mut spot = rt_core::Light::new(rt_core::LightKind::Spot, "spot");
        spot.direction = [0.0, -2.0, 0.0];
        spot.inner_angle_deg = 20.0;
        spot.outer_angle_deg = 30.0;
        scene.lights = vec![spot];
        let frame = build_frame(&scene, &scene.camera, scene.bounds(), None, [400, 300]);
        assert_eq!(frame.view.light_count, 2);
        let lights = &frame.view.lights[..2];
        let spot = lights
            .iter()
            .find(|l| l.shadow[0] == light_kind::SPOT)
            .unwrap();
        assert_eq!(spot.direction[..3], [0.0, -1.0, 0.0]);
        assert!((spot.direction[3] - 30f32.to_radians().cos()).abs() < 1e-6);
        assert!((spot.cone[0] - 20f32.to_radians().cos()).abs() < 1e-6);
        let emitter = lights
            .iter()
            .find(|l| l.shadow[0] == light_kind::EMITTER)
            .unwrap();
        // The emitter's radiance, as the render gives it.
        let radiance = Vec3::from_slice(&emitter.color[..3]);
        assert!((radiance - Vec3::new(3.0, 1.5, 0.6)).length() < 1e-5);
        assert!(
            emitter.shadow[3] == 1,
            "its own object, which its shadow map leaves out"
        );
    }

    /// Bounce light: in the Cornell box a probe gets more from below (the lit floor) than from
    /// above (the ceiling, lit only by bounces), sees the sky only through the open front, and
    /// with black walls gets none.
    #[test]
    fn a_closed_room_fills_with_bounce_light_and_a_black_one_does_not() {
        let scene = rt_core::assets::cornell_box().expect("embedded scene");
        let frame = build_frame(&scene, &scene.camera, scene.bounds(), None, [64, 64]);
        let v = &frame.volume;
        assert_eq!(v.dims, [4, 4, 4]);
        let (below, above) = (v.at([1, 2, 2], 3), v.at([1, 2, 2], 2));
        eprintln!("bounce from below {below:?}, from above {above:?}");
        assert!(below[0] > above[0] && above[0] > 0.0, "{below:?} {above:?}");
        // The box is open towards −z (the camera): its back wall hides the sky from every probe,
        // and the front row sees the opening.
        for z in 0..4 {
            for y in 0..4 {
                for x in 0..4 {
                    let (back, front) = (v.at([x, y, z], 4)[3], v.at([x, y, 0], 5)[3]);
                    assert!(
                        back < 0.05 && front > 0.3,
                        "sky {back} behind, {front} in front"
                    );
                }
            }
        }
        let mut black = scene.clone();
        for o in &mut black.objects {
            if !matches!(o.material, Material::Emissive { .. }) {
                o.material = Material::Lambertian {
                    albedo: [0.0; 3],
                    texture: None,
                };
            }
        }
        let frame = build_frame(&black, &black.camera, black.bounds(), None, [64, 64]);
        assert!(frame.volume.texels.iter().all(|t| t[0] == 0.0));
    }

    /// An interactive frame of a large scene shows the last bounce light while a thread builds the
    /// new one, and says so; a later frame gets the new one.
    #[test]
    fn a_large_scenes_bounce_light_is_built_on_a_thread() {
        let mut scene = rt_core::assets::cornell_box().expect("embedded scene");
        let mut ball = scene.objects[0].clone();
        ball.name = "ball".into();
        ball.mesh = rt_core::shapes::uv_sphere(80.0, 120, 200).into();
        ball.transform.translation = [280.0, 300.0, 280.0];
        scene.objects.push(ball);
        assert!(scene.triangle_count() > crate::preview::bounce::SYNC_TRIANGLES);
        let frame = |scene: &Scene| {
            build_interactive_frame(scene, &scene.camera, scene.bounds(), None, [64, 64])
        };
        assert!(frame(&scene).settling, "the first frame does not wait");
        let started = std::time::Instant::now();
        let done = loop {
            let f = frame(&scene);
            if !f.settling {
                break f;
            }
            assert!(started.elapsed().as_secs() < 60, "the volume never arrived");
            std::thread::sleep(std::time::Duration::from_millis(20));
        };
        assert_eq!(done.volume.dims, [4, 4, 4]);
    }

    /// A flat emitter's light is all along its normal; a closed one's is isotropic.
    #[test]
    fn an_emitters_projected_area_follows_its_shape() {
        let flat = rt_core::Object {
            name: "quad".into(),
            mesh: rt_core::shapes::quad(Vec3::ZERO, Vec3::NEG_Y, 2.0).into(),
            material: Material::Emissive {
                color: [1.0; 3],
                intensity: 1.0,
            },
            transform: Default::default(),
        };
        let (area, _, normal) = emitter_shape(&flat);
        assert!((area - 4.0).abs() < 1e-4 && (normal - Vec3::new(0.0, -4.0, 0.0)).length() < 1e-4);
        let ball = rt_core::Object {
            mesh: rt_core::shapes::uv_sphere(1.0, 32, 64).into(),
            ..flat
        };
        let (area, center, normal) = emitter_shape(&ball);
        assert!((area - 4.0 * std::f32::consts::PI).abs() < 0.05, "{area}");
        assert!(normal.length() < 1e-3 && center.length() < 1e-3);
    }

    #[test]
    fn the_scene_centre_projects_to_the_middle_of_the_view() {
        let scene = rt_core::assets::cornell_box().expect("embedded scene");
        let m = view_projection(&scene.camera, 1.0, scene.bounds());
        let (lo, hi) = scene.bounds().unwrap();
        let from = Vec3::from(scene.camera.from);
        let dir = (Vec3::from(scene.camera.to) - from).normalize();
        let p = m.project_point3(from + dir * ((lo + hi) * 0.5 - from).dot(dir));
        assert!(p.x.abs() < 1e-4 && p.y.abs() < 1e-4, "{p}");
        assert!((0.0..=1.0).contains(&p.z), "inside the depth range: {p}");
    }
}
