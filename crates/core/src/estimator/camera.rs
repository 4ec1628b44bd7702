//! Camera rays, as `camera.wgsl` beside it generates them (its twin): each pixel's jittered point
//! on the film (a render region's pixels keep their place in the whole film), mapped to a ray by the
//! frame's projection — perspective with a thin lens, orthographic, equirectangular panorama or
//! equidistant fisheye (`camera::Projection`) — and the pixel's number that seeds its random
//! numbers.

/// The WGSL twin of this module, `camera.wgsl` beside it (composed into the kernels by
/// `rt_gpu::shaders`).
pub const WGSL: &str = include_str!("camera.wgsl");

use glam::Vec3;

use crate::gpu_types::Frame;
use crate::math::rng::Rng;
use crate::math::sampling::sample_disk;

/// Image pixel (x, y)'s number in the film (`Frame::film_x`…), which seeds its random numbers:
/// a render region takes the samples the whole image takes there (the WGSL `film_pixel`).
pub fn film_pixel(frame: &Frame, x: u32, y: u32) -> u32 {
    (y + frame.film_y) * frame.film_width + x + frame.film_x
}

/// The numbers of `Frame::projection` (`crate::camera::Projection::tag`; `PROJECTION_*` in camera.wgsl).
pub const PROJECTION_ORTHOGRAPHIC: u32 = 1;
pub const PROJECTION_PANORAMA: u32 = 2;
pub const PROJECTION_FISHEYE: u32 = 3;

/// The camera ray through a jittered point of pixel (x, y): box pixel filter, the frame's
/// projection, a thin lens when `lens_radius > 0` (perspective and orthographic). A fisheye pixel
/// outside the image circle gets a zero direction: it sees nothing (`path::start_path`).
pub fn camera_ray(frame: &Frame, x: u32, y: u32, rng: &mut Rng) -> (Vec3, Vec3) {
    let jx = rng.next_f32();
    let jy = rng.next_f32();
    // The point on the film in [-1, 1]², y up.
    let px = 2.0 * ((x + frame.film_x) as f32 + jx) / frame.film_width as f32 - 1.0;
    let py = 1.0 - 2.0 * ((y + frame.film_y) as f32 + jy) / frame.film_height as f32;
    let (origin, direction) = film_ray(frame, px, py);
    if frame.lens_radius <= 0.0
        || matches!(frame.projection, PROJECTION_PANORAMA | PROJECTION_FISHEYE)
    {
        return (origin, direction);
    }
    let w = Vec3::from(frame.cam_w);
    let focus = origin + direction * (frame.focus_distance / direction.dot(-w));
    let (dx, dy) = sample_disk(rng);
    let (u, v) = (Vec3::from(frame.cam_u), Vec3::from(frame.cam_v));
    let lens_origin = origin + frame.lens_radius * (dx * u + dy * v);
    (lens_origin, (focus - lens_origin).normalize())
}

/// The ray through the centre of pixel (x, y), without a lens: where the render passes place a
/// pixel's mean depth (`crate::passes`).
pub fn pixel_centre_ray(frame: &Frame, x: u32, y: u32) -> (Vec3, Vec3) {
    let px = 2.0 * ((x + frame.film_x) as f32 + 0.5) / frame.film_width as f32 - 1.0;
    let py = 1.0 - 2.0 * ((y + frame.film_y) as f32 + 0.5) / frame.film_height as f32;
    film_ray(frame, px, py)
}

/// The pinhole ray of the frame's projection through film point (px, py) ∈ [-1, 1]².
fn film_ray(frame: &Frame, px: f32, py: f32) -> (Vec3, Vec3) {
    let (u, v, w) = (
        Vec3::from(frame.cam_u),
        Vec3::from(frame.cam_v),
        Vec3::from(frame.cam_w),
    );
    let origin = Vec3::from(frame.cam_origin);
    match frame.projection {
        PROJECTION_ORTHOGRAPHIC => {
            let h = frame.projection_scale;
            (origin + (px * h * frame.aspect) * u + (py * h) * v, -w)
        }
        PROJECTION_PANORAMA => (origin, panorama_direction(px, py, u, v, w)),
        PROJECTION_FISHEYE => (origin, fisheye_direction(frame, px, py, u, v, w)),
        _ => {
            let sx = px * frame.tan_half_vfov * frame.aspect;
            let sy = py * frame.tan_half_vfov;
            (origin, (sx * u + sy * v - w).normalize())
        }
    }
}

/// The equirectangular panorama's direction at image point (px, py) ∈ [-1, 1]²: longitude π·px
/// from the view direction (towards `u` for px > 0), latitude π/2·py.
fn panorama_direction(px: f32, py: f32, u: Vec3, v: Vec3, w: Vec3) -> Vec3 {
    let phi = px * std::f32::consts::PI;
    let theta = py * std::f32::consts::FRAC_PI_2;
    let horizontal = phi.sin() * u - phi.cos() * w;
    (theta.cos() * horizontal + theta.sin() * v).normalize()
}

/// The equidistant fisheye's direction at image point (px, py) ∈ [-1, 1]²: at distance r from
/// the centre (1 at the rim of a circle as high as the image, or as wide when it is taller), the
/// angle from the view direction is r × `projection_scale`; zero outside the circle.
fn fisheye_direction(frame: &Frame, px: f32, py: f32, u: Vec3, v: Vec3, w: Vec3) -> Vec3 {
    let short = frame.aspect.min(1.0);
    let fx = px * frame.aspect / short;
    let fy = py / short;
    let r = (fx * fx + fy * fy).sqrt();
    if r > 1.0 {
        return Vec3::ZERO;
    }
    if r <= 0.0 {
        return -w;
    }
    let theta = r * frame.projection_scale;
    let across = (fx / r) * u + (fy / r) * v;
    (theta.sin() * across - theta.cos() * w).normalize()
}
