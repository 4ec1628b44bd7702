//! The raster preview: what to draw ([`PreviewFrame`], built from the scene on the UI thread) and
//! how ([`gpu`], an `egui_wgpu` paint callback that renders offscreen with depth, then copies the
//! image into egui's pass).

pub mod gpu;
pub mod types;

use std::sync::Arc;

use glam::{Mat3, Mat4, Vec3};
use rt_core::{Camera, Material, Mesh, Scene};

use types::{
    GridVertex, MAX_PREVIEW_LIGHTS, NO_CONE, PreviewLight, PreviewObject, PreviewView, look,
};

/// A texture's texels, shared with the scene.
#[derive(Clone)]
pub struct TextureRef {
    pub texels: Arc<[u8]>,
    pub width: u32,
    pub height: u32,
}

/// Everything one preview frame draws; cheap to build (meshes and texels are shared).
#[derive(Clone)]
pub struct PreviewFrame {
    pub size_px: [u32; 2],
    pub view: PreviewView,
    pub objects: Vec<PreviewObject>,
    pub meshes: Vec<Arc<Mesh>>,
    pub textures: Vec<Option<TextureRef>>,
    pub grid: Vec<GridVertex>,
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

/// World-space area and centre of an object's mesh.
fn area_and_center(object: &rt_core::Object) -> (f32, Vec3) {
    let m = object.transform.matrix();
    let mesh = &object.mesh;
    let mut area = 0.0;
    let mut weighted = Vec3::ZERO;
    for tri in &mesh.indices {
        let [a, b, c] = tri.map(|i| {
            mesh.positions
                .get(i as usize)
                .map_or(Vec3::ZERO, |p| m.transform_point3(*p))
        });
        let tri_area = (b - a).cross(c - a).length() * 0.5;
        area += tri_area;
        weighted += (a + b + c) / 3.0 * tri_area;
    }
    let center = if area > 0.0 {
        weighted / area
    } else {
        m.transform_point3(Vec3::ZERO)
    };
    (area, center)
}

/// Builds the frame for `scene` (whose bounds are given) seen by `camera` in a viewport of
/// `size_px` pixels.
pub fn build_frame(
    scene: &Scene,
    camera: &Camera,
    bounds: Option<(Vec3, Vec3)>,
    selection: Option<usize>,
    size_px: [u32; 2],
) -> PreviewFrame {
    let aspect = size_px[0].max(1) as f32 / size_px[1].max(1) as f32;
    let view_proj = view_projection(camera, aspect, bounds);
    let (center, radius) = bounds.map_or((Vec3::ZERO, 1.0), |(lo, hi)| {
        ((lo + hi) * 0.5, ((hi - lo).length() * 0.5).max(1e-6))
    });

    // Emitters (an emissive material, or a PBR one's emission) as point lights. A Lambertian
    // emitter of radiance Le and area A has on-axis intensity Le·A; Le·A/2 stands in for its
    // orientation. The shader wants intensity/π.
    let mut lights: Vec<PreviewLight> = scene
        .objects
        .iter()
        .filter_map(|o| {
            let radiance = match &o.material {
                Material::Emissive { color, intensity } => Vec3::from(*color) * *intensity,
                Material::Pbr(p) => Vec3::from(p.emission) * p.emission_strength,
                _ => return None,
            };
            if luminance(radiance) <= 0.0 {
                return None;
            }
            let (area, position) = area_and_center(o);
            let power = radiance * area * 0.5 / std::f32::consts::PI;
            Some(PreviewLight {
                position: position.extend(1.0).to_array(),
                intensity: power.extend(0.0).to_array(),
                direction: [0.0, 0.0, 0.0, NO_CONE],
            })
        })
        .collect();
    // Point lights as they are, spots with their cones; the sun as a point light so far away that
    // its light is parallel, bright enough to give its irradiance.
    for light in &scene.lights {
        let power = Vec3::from(light.color) * light.intensity / std::f32::consts::PI;
        let axis = Vec3::from(light.direction).normalize_or(Vec3::NEG_Y);
        let (position, intensity) = match light.kind {
            rt_core::LightKind::Directional => {
                let far = radius * 1000.0;
                (center - axis * far, power * far * far)
            }
            _ => (Vec3::from(light.position), power),
        };
        let (cos_inner, cos_outer) = match light.kind {
            rt_core::LightKind::Spot => (
                light.inner_angle_deg.to_radians().cos(),
                light.outer_angle_deg.to_radians().cos(),
            ),
            _ => (0.0, NO_CONE),
        };
        lights.push(PreviewLight {
            position: position.extend(1.0).to_array(),
            intensity: intensity.extend(cos_inner).to_array(),
            direction: axis.extend(cos_outer).to_array(),
        });
    }
    lights.sort_by(|a, b| {
        let la = luminance(Vec3::from_slice(&a.intensity[..3]));
        let lb = luminance(Vec3::from_slice(&b.intensity[..3]));
        lb.total_cmp(&la)
    });
    lights.truncate(MAX_PREVIEW_LIGHTS);

    // Exposure: map the radiance of a mid-grey surface at the scene's centre to mid-grey.
    let mut reference = luminance(Vec3::from(scene.ambient));
    for light in &lights {
        let d2 = (Vec3::from_slice(&light.position[..3]) - center)
            .length_squared()
            .max((radius * 0.1).powi(2));
        reference += luminance(Vec3::from_slice(&light.intensity[..3])) / d2;
    }
    let exposure = if reference > 0.0 && reference.is_finite() {
        2.0 / reference
    } else {
        1.0
    };
    // Fog: what it glows with where it is thick, single scattering of the irradiance at the scene's
    // centre, evenly (albedo · E / 4π); the shader blends it in by exp(−σ_t d).
    let fog = &scene.fog;
    let glow = if fog.is_on() {
        Vec3::from(fog.albedo) * reference / (4.0 * std::f32::consts::PI)
    } else {
        Vec3::ZERO
    };
    let mut view = PreviewView {
        view_proj: view_proj.to_cols_array_2d(),
        eye: Vec3::from(camera.from).extend(exposure).to_array(),
        ambient: Vec3::from(scene.ambient)
            .extend(if fog.is_on() { fog.density } else { 0.0 })
            .to_array(),
        light_count: lights.len() as u32,
        fog_r: glow.x,
        fog_g: glow.y,
        fog_b: glow.z,
        lights: [PreviewLight::default(); MAX_PREVIEW_LIGHTS],
    };
    view.lights[..lights.len()].copy_from_slice(&lights);

    let mut objects = Vec::with_capacity(scene.objects.len());
    let mut meshes = Vec::with_capacity(scene.objects.len());
    let mut textures = Vec::with_capacity(scene.objects.len());
    for (i, object) in scene.objects.iter().enumerate() {
        let model = object.transform.matrix();
        let normal_matrix = Mat4::from_mat3(Mat3::from_mat4(model).inverse().transpose());
        let roughness = match &object.material {
            Material::Pbr(p) => p.roughness,
            _ => -1.0,
        };
        // An alpha mask cuts its holes in the preview too: a fragment whose image alpha is below
        // cutoff / alpha-factor is discarded (0: nothing is cut; blending is drawn opaque).
        let mask = match &object.material {
            Material::Pbr(p) if p.alpha_mode == rt_core::material::AlphaMode::Mask => {
                p.alpha_cutoff / p.alpha.max(1e-6)
            }
            _ => 0.0,
        };
        let (color, emission, look, texture) = match &object.material {
            Material::Lambertian { albedo, texture } => (
                *albedo,
                [0.0; 3],
                look::DIFFUSE,
                texture.and_then(|t| scene.textures.get(t)),
            ),
            Material::Metal { albedo, .. } => (*albedo, [0.0; 3], look::METAL, None),
            Material::Dielectric { tint, .. } => (*tint, [0.0; 3], look::GLASS, None),
            Material::Emissive { color, intensity } => (
                [0.0; 3],
                (Vec3::from(*color) * *intensity).to_array(),
                look::EMITTER,
                None,
            ),
            Material::Pbr(p) => (
                p.base_color,
                (Vec3::from(p.emission) * p.emission_strength).to_array(),
                if p.transmission > 0.5 {
                    look::GLASS
                } else if p.metallic > 0.5 {
                    look::METAL
                } else {
                    look::DIFFUSE
                },
                p.texture.and_then(|t| scene.textures.get(t)),
            ),
        };
        objects.push(PreviewObject {
            model: model.to_cols_array_2d(),
            normal_matrix: normal_matrix.to_cols_array_2d(),
            color: Vec3::from(color).extend(mask).to_array(),
            emission: Vec3::from(emission).extend(roughness).to_array(),
            flags: [
                u32::from(selection == Some(i)),
                u32::from(texture.is_some()),
                u32::from(object.mesh.normals.is_some()),
                look,
            ],
        });
        meshes.push(object.mesh.clone());
        textures.push(texture.map(|t| TextureRef {
            texels: t.rgba8.clone(),
            width: t.width,
            height: t.height,
        }));
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
        grid,
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

    #[test]
    fn the_cornell_frame_has_its_light_and_a_sane_exposure() {
        let scene = rt_core::assets::cornell_box().expect("embedded scene");
        let frame = build_frame(&scene, &scene.camera, scene.bounds(), Some(0), [400, 300]);
        assert_eq!(frame.objects.len(), scene.objects.len());
        assert_eq!(frame.view.light_count, 1);
        assert!(frame.view.eye[3].is_finite() && frame.view.eye[3] > 0.0);
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
        let spot = lights.iter().find(|l| l.direction[3] != NO_CONE).unwrap();
        assert_eq!(spot.direction[..3], [0.0, -1.0, 0.0]);
        assert!((spot.direction[3] - 30f32.to_radians().cos()).abs() < 1e-6);
        assert!((spot.intensity[3] - 20f32.to_radians().cos()).abs() < 1e-6);
        let emitter = lights.iter().find(|l| l.direction[3] == NO_CONE).unwrap();
        assert!(emitter.intensity[0] > emitter.intensity[1] && emitter.intensity[2] > 0.0);
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
