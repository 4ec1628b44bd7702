//! Mouse navigation and picking in the viewport, as pure functions of the camera so they can be
//! tested: left-drag pans, right-drag rotates in place (the seed's scheme) or orbits a pivot, the
//! wheel dollies.

use glam::{Mat4, Quat, Vec2, Vec3};
use rt_core::camera::Projection;
use rt_core::{Camera, Scene};

/// Radians of rotation per pixel dragged.
const ROTATE_PER_PIXEL: f32 = 0.005;

fn eye_target(camera: &Camera) -> (Vec3, Vec3, Vec3) {
    (
        Vec3::from(camera.from),
        Vec3::from(camera.to),
        Vec3::from(camera.up).normalize_or(Vec3::Y),
    )
}

/// How far away what the user looks at is: the target, or the scene's centre along the view when
/// the target is a mere direction (scene files often put it one unit ahead). Pan and dolly speeds
/// scale with it.
pub fn view_distance(bounds: Option<(Vec3, Vec3)>, camera: &Camera) -> f32 {
    let (from, to, _) = eye_target(camera);
    let target = (to - from).length();
    let Some((lo, hi)) = bounds else {
        return target.max(1e-3);
    };
    let size = (hi - lo).length().max(1e-3);
    let along = ((lo + hi) * 0.5 - from).dot((to - from).normalize_or(Vec3::NEG_Z));
    target.max(along).max(size * 0.01)
}

/// Moves camera and target in the image plane so that a point `distance` away follows the cursor.
pub fn pan(camera: &mut Camera, drag_px: Vec2, viewport_height_px: f32, distance: f32) {
    let (from, to, _) = eye_target(camera);
    let Ok(basis) = camera.basis() else { return };
    let half_height = ortho_half_height(camera).unwrap_or(distance * basis.tan_half_vfov);
    let per_pixel = 2.0 * half_height / viewport_height_px.max(1.0);
    let shift = (-basis.u * drag_px.x + basis.v * drag_px.y) * per_pixel;
    camera.from = (from + shift).to_array();
    camera.to = (to + shift).to_array();
}

/// Turns the view direction about the camera position (yaw about `up`, pitch about the camera's
/// right axis), keeping the distance to the target.
pub fn rotate(camera: &mut Camera, drag_px: Vec2) {
    let (from, to, up) = eye_target(camera);
    let rotated = turn(to - from, up, drag_px);
    camera.to = (from + rotated).to_array();
}

/// Orbits the camera about `pivot`, looking at it.
pub fn orbit(camera: &mut Camera, pivot: Vec3, drag_px: Vec2) {
    let (from, _, up) = eye_target(camera);
    let offset = from - pivot;
    let rotated = turn(-offset, up, drag_px);
    camera.from = (pivot - rotated).to_array();
    camera.to = pivot.to_array();
}

fn turn(direction: Vec3, up: Vec3, drag_px: Vec2) -> Vec3 {
    let yaw = Quat::from_axis_angle(up, -drag_px.x * ROTATE_PER_PIXEL);
    let d = yaw * direction;
    let right = d.cross(up);
    if right.length_squared() < 1e-12 {
        return d;
    }
    let pitched = Quat::from_axis_angle(right.normalize(), -drag_px.y * ROTATE_PER_PIXEL) * d;
    // Stop short of looking straight along `up`, where the basis is undefined.
    if pitched.normalize().dot(up).abs() > 0.995 {
        d
    } else {
        pitched
    }
}

/// Moves camera and target along the view so that the distance to what is `distance` away shrinks
/// (scroll up) or grows by a factor per wheel step; it never passes that point.
pub fn dolly(camera: &mut Camera, scroll: f32, distance: f32) {
    let (from, to, _) = eye_target(camera);
    let factor = (-scroll * 0.002).exp().clamp(0.2, 5.0);
    if let Some(height) = camera.ortho_height.as_mut()
        && camera.projection == Projection::Orthographic
    {
        // Moving an orthographic camera changes nothing it shows: the wheel zooms instead.
        *height *= factor;
        return;
    }
    let step = (to - from).normalize_or(Vec3::NEG_Z) * distance * (1.0 - factor);
    camera.from = (from + step).to_array();
    camera.to = (to + step).to_array();
}

/// The camera's rotation as (yaw, pitch) in degrees: yaw about +y from the −z axis, pitch up from
/// the horizon.
pub fn yaw_pitch_deg(camera: &Camera) -> (f32, f32) {
    let (from, to, _) = eye_target(camera);
    let d = (to - from).normalize_or(Vec3::NEG_Z);
    (
        d.x.atan2(-d.z).to_degrees(),
        d.y.clamp(-1.0, 1.0).asin().to_degrees(),
    )
}

/// Points the camera in the direction given by yaw and pitch (degrees), keeping its position and
/// distance to the target.
pub fn set_yaw_pitch_deg(camera: &mut Camera, yaw: f32, pitch: f32) {
    let (from, to, _) = eye_target(camera);
    let distance = (to - from).length().max(1e-6);
    let (yaw, pitch) = (yaw.to_radians(), pitch.clamp(-89.0, 89.0).to_radians());
    let d = Vec3::new(
        yaw.sin() * pitch.cos(),
        pitch.sin(),
        -yaw.cos() * pitch.cos(),
    );
    camera.to = (from + d * distance).to_array();
    camera.up = [0.0, 1.0, 0.0];
}

/// Half the view's height in scene units when the camera is orthographic (the viewport draws
/// panorama and fisheye cameras as perspective ones, as the raster preview does). The editor gives
/// an orthographic camera its height when it is chosen (`ui::panels::camera`).
fn ortho_half_height(camera: &Camera) -> Option<f32> {
    (camera.projection == Projection::Orthographic).then(|| camera.ortho_height_in(None) * 0.5)
}

/// The world-space ray through a point of the viewport given in [0, 1]² (y down), as the renderer
/// generates it for a pinhole (or orthographic) camera.
pub fn camera_ray(camera: &Camera, aspect: f32, uv: Vec2) -> Option<(Vec3, Vec3)> {
    let basis = camera.basis().ok()?;
    let (px, py) = (2.0 * uv.x - 1.0, 1.0 - 2.0 * uv.y);
    if let Some(h) = ortho_half_height(camera) {
        let origin = basis.origin + basis.u * (px * h * aspect) + basis.v * (py * h);
        return Some((origin, -basis.w));
    }
    let x = px * basis.tan_half_vfov * aspect;
    let y = py * basis.tan_half_vfov;
    let direction = (basis.u * x + basis.v * y - basis.w).normalize();
    Some((basis.origin, direction))
}

/// Where a world point appears in the viewport, in [0, 1]² (y down; outside it beyond the edges):
/// `camera_ray`'s inverse. `None` behind the camera.
pub fn project(camera: &Camera, aspect: f32, point: Vec3) -> Option<Vec2> {
    let basis = camera.basis().ok()?;
    let d = point - basis.origin;
    // Behind the camera, or NaN: nothing to place.
    let depth = -d.dot(basis.w);
    if depth.partial_cmp(&0.0) != Some(std::cmp::Ordering::Greater) {
        return None;
    }
    let (x, y) = match ortho_half_height(camera) {
        Some(h) => (d.dot(basis.u) / (h * aspect), d.dot(basis.v) / h),
        None => (
            d.dot(basis.u) / (depth * basis.tan_half_vfov * aspect),
            d.dot(basis.v) / (depth * basis.tan_half_vfov),
        ),
    };
    Some(Vec2::new(0.5 * (x + 1.0), 0.5 * (1.0 - y)))
}

/// Where a world point appears in the viewport `rect` (screen points), if in front of the camera.
pub fn to_screen(camera: &Camera, rect: egui::Rect, point: Vec3) -> Option<egui::Pos2> {
    let uv = project(camera, rect.width() / rect.height().max(1.0), point)?;
    Some(rect.min + egui::vec2(uv.x * rect.width(), uv.y * rect.height()))
}

/// The world length one screen point of the viewport `rect` spans at `point`'s depth, if in
/// front of the camera.
pub fn world_per_point(camera: &Camera, rect: egui::Rect, point: Vec3) -> Option<f32> {
    let basis = camera.basis().ok()?;
    let depth = (point - basis.origin).dot(-basis.w);
    let half_height = ortho_half_height(camera).unwrap_or(depth * basis.tan_half_vfov);
    (depth > 0.0).then(|| 2.0 * half_height / rect.height().max(1.0))
}

/// The nearest object hit by a ray, and the distance to it.
pub fn pick(scene: &Scene, origin: Vec3, direction: Vec3) -> Option<(usize, f32)> {
    let mut best: Option<(usize, f32)> = None;
    for (index, object) in scene.objects.iter().enumerate() {
        let model = object.transform.matrix();
        let inverse: Mat4 = model.inverse();
        if !inverse.is_finite() {
            continue;
        }
        // Intersect in object space; t is the same parameter along the world ray.
        let o = inverse.transform_point3(origin);
        let d = inverse.transform_vector3(direction);
        let mesh = &object.mesh;
        for tri in &mesh.indices {
            let Some([a, b, c]) = tri
                .iter()
                .map(|&i| mesh.positions.get(i as usize).copied())
                .collect::<Option<Vec<_>>>()
                .and_then(|v| <[Vec3; 3]>::try_from(v).ok())
            else {
                continue;
            };
            if let Some(t) = intersect_triangle(o, d, a, b, c)
                && best.is_none_or(|(_, bt)| t < bt)
            {
                best = Some((index, t));
            }
        }
    }
    best
}

/// Möller–Trumbore, both faces.
fn intersect_triangle(o: Vec3, d: Vec3, a: Vec3, b: Vec3, c: Vec3) -> Option<f32> {
    let e1 = b - a;
    let e2 = c - a;
    let p = d.cross(e2);
    let det = e1.dot(p);
    if det.abs() < 1e-20 {
        return None;
    }
    let inv = 1.0 / det;
    let s = o - a;
    let u = s.dot(p) * inv;
    if !(0.0..=1.0).contains(&u) {
        return None;
    }
    let q = s.cross(e1);
    let v = d.dot(q) * inv;
    if v < 0.0 || u + v > 1.0 {
        return None;
    }
    let t = e2.dot(q) * inv;
    (t > 0.0 && t.is_finite()).then_some(t)
}

/// The centre of an object's world-space bounds.
pub fn object_center(scene: &Scene, index: usize) -> Option<Vec3> {
    let (lo, hi) = object_bounds(scene, index)?;
    Some((lo + hi) * 0.5)
}

pub fn object_bounds(scene: &Scene, index: usize) -> Option<(Vec3, Vec3)> {
    let object = scene.objects.get(index)?;
    let m = object.transform.matrix();
    let mut points = object.mesh.positions.iter().map(|p| m.transform_point3(*p));
    let first = points.next()?;
    Some(points.fold((first, first), |(lo, hi), p| (lo.min(p), hi.max(p))))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn cornell() -> Scene {
        rt_io::assets::cornell_box().expect("embedded scene")
    }

    #[test]
    fn the_centre_ray_picks_the_back_wall_and_a_corner_ray_misses_nothing_inside() {
        let scene = cornell();
        let (o, d) = camera_ray(&scene.camera, 1.0, Vec2::splat(0.5)).unwrap();
        let (hit, t) = pick(&scene, o, d).expect("the box fills the view");
        let name = &scene.objects[hit].name;
        assert!(
            name == "back_wall" || name.contains("block"),
            "centre ray hit {name}"
        );
        assert!(t > 0.0);
        let (o, d) = camera_ray(&scene.camera, 1.0, Vec2::new(0.5, 0.02)).unwrap();
        let (hit, _) = pick(&scene, o, d).unwrap();
        assert_eq!(scene.objects[hit].name, "ceiling");
        let away = pick(&scene, o, -d);
        assert!(away.is_none(), "behind the camera is empty");
    }

    /// `project` inverts `camera_ray`: a point along the ray through a viewport position
    /// projects back to that position, and a point behind the camera does not project.
    #[test]
    fn project_inverts_camera_ray() {
        let mut scene = cornell();
        for projection in [Projection::Perspective, Projection::Orthographic] {
            scene.camera.projection = projection;
            for uv in [
                Vec2::new(0.5, 0.5),
                Vec2::new(0.1, 0.8),
                Vec2::new(0.95, 0.05),
            ] {
                let (o, d) = camera_ray(&scene.camera, 1.5, uv).unwrap();
                let back = project(&scene.camera, 1.5, o + d * 300.0).unwrap();
                assert!(
                    (back - uv).length() < 1e-4,
                    "{projection:?}: {uv} -> {back}"
                );
                assert!(project(&scene.camera, 1.5, o - d * 300.0).is_none());
            }
        }
    }

    /// The orthographic viewport's rays are parallel and span the renderer's window: the corner
    /// ray starts half the view's height (times the aspect) off the axis.
    #[test]
    fn orthographic_rays_are_parallel_over_the_views_height() {
        let mut camera = cornell().camera;
        camera.projection = Projection::Orthographic;
        camera.ortho_height = Some(10.0);
        let basis = camera.basis().unwrap();
        let (o0, d0) = camera_ray(&camera, 2.0, Vec2::ZERO).unwrap();
        let (o1, d1) = camera_ray(&camera, 2.0, Vec2::ONE).unwrap();
        assert_eq!(d0, d1);
        let offset = o1 - o0;
        assert!((offset.dot(basis.u) - 20.0).abs() < 1e-3, "{offset}");
        assert!((offset.dot(basis.v) + 10.0).abs() < 1e-3, "{offset}");
    }

    #[test]
    fn pan_dolly_rotate_and_orbit_move_the_camera_as_expected() {
        let scene = cornell();
        let start = scene.camera.clone();
        let distance = |c: &Camera| (Vec3::from(c.from) - Vec3::from(c.to)).length();

        let d = view_distance(scene.bounds(), &start);
        assert!(
            d > 500.0,
            "the Cornell target is one unit ahead; the box is ~1000 away: {d}"
        );
        let mut c = start.clone();
        pan(&mut c, Vec2::new(10.0, 0.0), 500.0, d);
        let shift = Vec3::from(c.from) - Vec3::from(start.from);
        assert!(
            (distance(&c) - distance(&start)).abs() < 1e-2,
            "pan keeps the distance"
        );
        assert!(
            shift.length() > 5.0,
            "ten pixels pan a visible distance: {shift}"
        );

        let mut c = start.clone();
        dolly(&mut c, 100.0, d);
        assert!(
            view_distance(scene.bounds(), &c) < d * 0.9,
            "wheel up moves closer to the scene"
        );
        assert!((distance(&c) - distance(&start)).abs() < 1e-3);

        let mut c = start.clone();
        rotate(&mut c, Vec2::new(50.0, 20.0));
        assert_eq!(c.from, start.from, "rotating keeps the position");
        assert!((distance(&c) - distance(&start)).abs() < 1e-2);

        let mut c = start.clone();
        let pivot = Vec3::from(start.to);
        orbit(&mut c, pivot, Vec2::new(80.0, 0.0));
        assert!(
            (distance(&c) - distance(&start)).abs() < 1e-2,
            "orbit keeps the distance to the pivot"
        );
        assert!(c.basis().is_ok());
    }

    #[test]
    fn yaw_and_pitch_round_trip() {
        let mut c = Camera::default();
        set_yaw_pitch_deg(&mut c, 30.0, -10.0);
        let (yaw, pitch) = yaw_pitch_deg(&c);
        assert!((yaw - 30.0).abs() < 1e-3 && (pitch + 10.0).abs() < 1e-3);
    }
}
