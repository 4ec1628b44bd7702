// Camera rays (camera.rs beside it is the Rust twin): a pixel's jittered point on the film, mapped
// by the frame's projection (perspective with a thin lens, orthographic, equirectangular panorama,
// equidistant fisheye), and the pixel's number in the film that seeds its random numbers.

// Image pixel (x, y)'s number in the film, which seeds its random numbers (camera.rs `film_pixel`).
fn film_pixel(x: u32, y: u32) -> u32 {
    return (y + frame.film_y) * frame.film_width + x + frame.film_x;
}

const PROJECTION_ORTHOGRAPHIC: u32 = 1u;
const PROJECTION_PANORAMA: u32 = 2u;
const PROJECTION_FISHEYE: u32 = 3u;

// The camera ray through a jittered point of pixel (x, y) (camera.rs `camera_ray`): box filter, the
// frame's projection, a thin lens (perspective and orthographic); a fisheye pixel outside the image
// circle gets a zero direction.
fn camera_ray_origin_dir(x: u32, y: u32, rng: ptr<function, Sampler>) -> array<vec3<f32>, 2> {
    let jx = rng_next(rng);
    let jy = rng_next(rng);
    let px = 2.0 * (f32(x + frame.film_x) + jx) / f32(frame.film_width) - 1.0;
    let py = 1.0 - 2.0 * (f32(y + frame.film_y) + jy) / f32(frame.film_height);
    var origin = frame.cam_origin;
    var direction: vec3<f32>;
    if (frame.projection == PROJECTION_ORTHOGRAPHIC) {
        let h = frame.projection_scale;
        origin = origin + (px * h * frame.aspect) * frame.cam_u + (py * h) * frame.cam_v;
        direction = -frame.cam_w;
    } else if (frame.projection == PROJECTION_PANORAMA) {
        return array(origin, panorama_direction(px, py));
    } else if (frame.projection == PROJECTION_FISHEYE) {
        return array(origin, fisheye_direction(px, py));
    } else {
        let sx = px * frame.tan_half_vfov * frame.aspect;
        let sy = py * frame.tan_half_vfov;
        direction = normalize(sx * frame.cam_u + sy * frame.cam_v - frame.cam_w);
    }
    if (!HAS_THIN_LENS || frame.lens_radius <= 0.0) {
        return array(origin, direction);
    }
    let focus = origin + direction * (frame.focus_distance / dot(direction, -frame.cam_w));
    let d = sample_disk(rng);
    let lens_origin = origin + frame.lens_radius * (d.x * frame.cam_u + d.y * frame.cam_v);
    return array(lens_origin, normalize(focus - lens_origin));
}

// The equirectangular panorama's direction at image point (px, py) in [-1, 1]^2 (camera.rs).
fn panorama_direction(px: f32, py: f32) -> vec3<f32> {
    let phi = px * PI;
    let theta = py * (0.5 * PI);
    let horizontal = sin(phi) * frame.cam_u - cos(phi) * frame.cam_w;
    return normalize(cos(theta) * horizontal + sin(theta) * frame.cam_v);
}

// The equidistant fisheye's direction at image point (px, py) (camera.rs): zero outside the circle.
fn fisheye_direction(px: f32, py: f32) -> vec3<f32> {
    let short = min(frame.aspect, 1.0);
    let fx = px * frame.aspect / short;
    let fy = py / short;
    let r = sqrt(fx * fx + fy * fy);
    if (r > 1.0) {
        return vec3(0.0);
    }
    if (r <= 0.0) {
        return -frame.cam_w;
    }
    let theta = r * frame.projection_scale;
    let across = (fx / r) * frame.cam_u + (fy / r) * frame.cam_v;
    return normalize(sin(theta) * across - cos(theta) * frame.cam_w);
}
