//! The per-render kernel parameters (`gpu_types::Frame`) derived from a scene's camera and settings.

use crate::error::{Error, Result};
use crate::gpu_scene::GpuScene;
use crate::gpu_types::Frame;
use crate::scene::Scene;

/// Russian roulette starts at the fifth vertex (segment index 4), as in Mitsuba 3: the paths it
/// would cut earlier carry caustics and light through glass, whose error it multiplies in open
/// scenes for little time saved; closed rooms keep most of the saving (docs/quality.md, "Russian
/// roulette", measured over six scenes).
pub const ROULETTE_FROM_DEPTH: u32 = 4;

/// Checks the settings, camera and ambient light (what can be checked before building anything).
pub fn validate(scene: &Scene) -> Result<()> {
    scene.settings.validate().map_err(Error::Scene)?;
    scene.camera.basis().map_err(Error::Scene)?;
    if !scene.ambient.iter().all(|c| c.is_finite() && *c >= 0.0) {
        return Err(Error::Scene(format!(
            "ambient colour must be finite and >= 0, got {:?}",
            scene.ambient
        )));
    }
    scene.fog.validate().map_err(Error::Scene)?;
    Ok(())
}

/// Camera, image, path-length and emitter parameters; the renderer fills in the per-dispatch fields.
pub fn frame_for(scene: &Scene, gpu_scene: &GpuScene) -> Result<Frame> {
    let settings = &scene.settings;
    validate(scene)?;
    let basis = camera_with_height(scene).basis().map_err(Error::Scene)?;
    let window = settings.film_window.unwrap_or(crate::scene::FilmWindow {
        x: 0,
        y: 0,
        film_width: settings.width,
        film_height: settings.height,
    });
    let (film_x, film_y, film_width, film_height) =
        (window.x, window.y, window.film_width, window.film_height);
    Ok(Frame {
        cam_origin: basis.origin.to_array(),
        lens_radius: scene.camera.aperture_radius,
        cam_u: basis.u.to_array(),
        focus_distance: basis.focus_distance,
        cam_v: basis.v.to_array(),
        tan_half_vfov: basis.tan_half_vfov,
        cam_w: basis.w.to_array(),
        aspect: film_width as f32 / film_height as f32,
        ambient: scene.ambient,
        max_depth: settings.max_depth,
        width: settings.width,
        height: settings.height,
        seed: settings.seed,
        sample_base: 0,
        samples_this_dispatch: 0,
        row_begin: 0,
        row_end: settings.height,
        emitter_count: if gpu_scene.features.nee {
            gpu_scene.emitters.len() as u32
        } else {
            0
        },
        emitter_power_inv: if gpu_scene.emitter_power > 0.0 {
            1.0 / gpu_scene.emitter_power
        } else {
            0.0
        },
        roulette_from_depth: if settings.russian_roulette {
            ROULETTE_FROM_DEPTH
        } else {
            0
        },
        tile_row_begin: 0,
        tile_row_end: settings.height,
        sampler: u32::from(settings.sampler == crate::math::rng::SamplerKind::Sobol),
        nee_only: u32::from(settings.nee_only),
        offset_scale: gpu_scene.extent.clamp(1e-30, 1.0),
        active_begin: 0,
        active_count: 0,
        env_width: gpu_scene.env_width,
        env_height: gpu_scene.env_height,
        env_rotation: gpu_scene.env_rotation,
        // Fog hides the environment behind an infinite depth of it: sampling it would be wasted.
        env_pick: match (
            gpu_scene.env_width > 0 && !scene.fog.is_on(),
            gpu_scene.features.nee,
        ) {
            (false, _) => 0.0,
            (true, false) => 1.0,
            (true, true) => 0.5,
        },
        sample_offset: 0,
        clamp_max: clamp_max(settings.clamp),
        light_sampler: u32::from(!gpu_scene.light_tree.is_empty()),
        fog: scene.fog.medium(),
        camera_media: camera_media(gpu_scene, basis.origin),
        projection: basis.projection.tag(),
        projection_scale: basis.projection_scale,
        film_x,
        film_y,
        film_width,
        film_height,
        transparent: u32::from(settings.transparent),
    })
}

/// The scene's camera, an orthographic one given the height it shows in this scene when it has
/// none of its own (`Camera::ortho_height_in`).
fn camera_with_height(scene: &Scene) -> std::borrow::Cow<'_, crate::camera::Camera> {
    let camera = &scene.camera;
    if camera.projection == crate::camera::Projection::Orthographic && camera.ortho_height.is_none()
    {
        let mut resolved = camera.clone();
        resolved.ortho_height = Some(camera.ortho_height_in(scene.bounds()));
        std::borrow::Cow::Owned(resolved)
    } else {
        std::borrow::Cow::Borrowed(camera)
    }
}

/// The medium stack a camera at `origin` starts in: the closed volume it sits inside (glass,
/// water, a scattering object: a material that transmits into a volume), found by probe rays that
/// must all first meet that material's inside; else empty (the fog, or vacuum). Three probes, so a
/// camera behind one open face is not taken to be inside.
pub fn camera_media(gpu_scene: &GpuScene, origin: glam::Vec3) -> u32 {
    use crate::gpu_types::{DielectricLobe, PbrLobe, THIN_WALLED};
    use crate::material_kind::MaterialKind;
    if gpu_scene.triangles.is_empty() {
        return 0;
    }
    let probes = [
        glam::Vec3::new(0.267, 0.803, 0.533),
        glam::Vec3::new(-0.577, -0.408, 0.707),
        glam::Vec3::new(0.408, -0.577, -0.707),
    ];
    let mut inside = None;
    for d in probes {
        let d = d.normalize();
        let mut hit = crate::estimator::trace(gpu_scene, origin, d, f32::MAX);
        if hit.triangle == u32::MAX {
            return 0;
        }
        let mut placed = None;
        let tri = crate::estimator::instances::hit_triangle(gpu_scene, &mut hit, &mut placed).tri;
        let (v0, v1, v2) = (
            glam::Vec3::from(tri.v0),
            glam::Vec3::from(tri.v1),
            glam::Vec3::from(tri.v2),
        );
        let from_inside = d.dot((v1 - v0).cross(v2 - v0)) > 0.0;
        let material = &gpu_scene.materials[tri.material as usize];
        let volume = material.flags & THIN_WALLED == 0
            && match MaterialKind::from_tag(material.kind) {
                Some(MaterialKind::Dielectric) => material.lobe_of::<DielectricLobe>().ior > 0.0,
                Some(MaterialKind::Pbr) => {
                    let lobe = material.lobe_of::<PbrLobe>();
                    lobe.transmission > 0.0 || lobe.diffuse_transmission > 0.0
                }
                _ => false,
            };
        if !(from_inside && volume) || inside.is_some_and(|m| m != tri.material) {
            return 0;
        }
        inside = Some(tri.material);
    }
    inside.map_or(0, |m| crate::estimator::media::media_enter(0, m))
}

/// The firefly clamp as the kernels read it (`Frame::clamp_max`): the value where it is a positive
/// finite number, else 0 (off).
pub fn clamp_max(clamp: Option<f32>) -> f32 {
    clamp.filter(|c| c.is_finite() && *c > 0.0).unwrap_or(0.0)
}
