//! The camera's importance for light tracing (t = 1) and the density with which it sends camera
//! rays: the perspective camera, a pinhole or a thin lens (Veach's W_e; pbrt-v4's
//! `PerspectiveCamera::We`). With A the film's area at unit distance from the lens and θ the
//! angle to the view direction, camera rays leave a pinhole with density p(ω) = 1/(A cos³θ) over
//! the whole film, and W_e = 1/(A · A_lens · cos⁴θ).

use glam::Vec3;

use crate::gpu_types::Frame;
use crate::math::rng::Rng;
use crate::math::sampling::sample_disk;

/// The film's area at unit distance from the lens.
fn film_area(frame: &Frame) -> f32 {
    4.0 * frame.tan_half_vfov * frame.tan_half_vfov * frame.aspect
}

/// The cosine of unit `w` to the view direction.
fn cos_to_view(frame: &Frame, w: Vec3) -> f32 {
    -w.dot(Vec3::from(frame.cam_w))
}

/// Where a ray from the lens point `lens` along unit `w` lands on the film, in pixels (x right,
/// y down, whole pixels from 0), or `None` off the film or behind the camera.
pub fn raster(frame: &Frame, lens: Vec3, w: Vec3) -> Option<(f32, f32)> {
    let cos = cos_to_view(frame, w);
    if cos <= 0.0 {
        return None;
    }
    let origin = Vec3::from(frame.cam_origin);
    // Through a thin lens, the point in focus along w, seen from the lens's centre.
    let d = if frame.lens_radius > 0.0 {
        let focus = lens + w * (frame.focus_distance / cos);
        focus - origin
    } else {
        w
    };
    let depth = -d.dot(Vec3::from(frame.cam_w));
    if depth <= 0.0 {
        return None;
    }
    let sx = d.dot(Vec3::from(frame.cam_u)) / depth;
    let sy = d.dot(Vec3::from(frame.cam_v)) / depth;
    let px = sx / (frame.tan_half_vfov * frame.aspect);
    let py = sy / frame.tan_half_vfov;
    let x = (px + 1.0) * 0.5 * frame.width as f32;
    let y = (1.0 - py) * 0.5 * frame.height as f32;
    let inside = (0.0..frame.width as f32).contains(&x) && (0.0..frame.height as f32).contains(&y);
    inside.then_some((x, y))
}

/// The density per solid angle with which the camera sends a ray along unit `w` from `lens`
/// (over the whole film), zero off the film.
pub fn direction_pdf(frame: &Frame, lens: Vec3, w: Vec3) -> f32 {
    if raster(frame, lens, w).is_none() {
        return 0.0;
    }
    let cos = cos_to_view(frame, w);
    1.0 / (film_area(frame) * cos * cos * cos)
}

/// A point on the lens for a connection to the camera: the pinhole, or a uniform point on the
/// thin lens (two random numbers either way).
pub fn lens_point(frame: &Frame, rng: &mut Rng) -> Vec3 {
    let (dx, dy) = sample_disk(rng);
    let origin = Vec3::from(frame.cam_origin);
    if frame.lens_radius <= 0.0 {
        return origin;
    }
    origin + frame.lens_radius * (dx * Vec3::from(frame.cam_u) + dy * Vec3::from(frame.cam_v))
}

/// W_e / p for the lens point `lens` connected to a point at distance `distance` along unit `w`
/// from it: W_e = 1/(A A_lens cos⁴θ) over the lens point's density per solid angle seen from
/// there, p = d²/(A_lens cosθ): 1/(A cos³θ d²), the lens area cancelling.
pub fn importance_over_pdf(frame: &Frame, w: Vec3, distance: f32) -> f32 {
    let cos = cos_to_view(frame, w);
    if cos <= 0.0 {
        return 0.0;
    }
    1.0 / (film_area(frame) * cos * cos * cos * distance * distance)
}
