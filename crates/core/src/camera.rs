//! The pinhole / thin-lens camera and its orthonormal basis.

use glam::Vec3;
use serde::{Deserialize, Serialize};

/// A camera looking from `from` towards `to`. Right-handed, with the seed project's convention
/// `w = normalize(from − to)`, `u = normalize(up × w)`, `v = w × u`; the image plane spans `u` (right)
/// and `v` (up), and the view direction is `−w`.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Camera {
    pub from: [f32; 3],
    pub to: [f32; 3],
    pub up: [f32; 3],
    /// Vertical field of view in degrees, in (0, 180).
    pub vfov_deg: f32,
    /// Thin-lens aperture radius in scene units; 0 is a pinhole.
    #[serde(default)]
    pub aperture_radius: f32,
    /// Distance from `from` to the plane in focus; `None` focuses at `to`.
    #[serde(default)]
    pub focus_distance: Option<f32>,
}

/// The camera's derived frame.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct CameraBasis {
    pub origin: Vec3,
    pub u: Vec3,
    pub v: Vec3,
    pub w: Vec3,
    pub tan_half_vfov: f32,
    pub focus_distance: f32,
}

impl Default for Camera {
    fn default() -> Self {
        Camera {
            from: [0.0, 0.0, 5.0],
            to: [0.0, 0.0, 0.0],
            up: [0.0, 1.0, 0.0],
            vfov_deg: 40.0,
            aperture_radius: 0.0,
            focus_distance: None,
        }
    }
}

impl Camera {
    /// The orthonormal basis, or a message saying which parameter makes it undefined.
    pub fn basis(&self) -> Result<CameraBasis, String> {
        let from = Vec3::from(self.from);
        let to = Vec3::from(self.to);
        let up = Vec3::from(self.up);
        if !(from.is_finite() && to.is_finite() && up.is_finite()) {
            return Err("camera from/to/up must be finite".into());
        }
        if !(self.vfov_deg > 0.0 && self.vfov_deg < 180.0) {
            return Err(format!(
                "camera vfov must be in (0, 180) degrees, got {}",
                self.vfov_deg
            ));
        }
        if !(self.aperture_radius.is_finite() && self.aperture_radius >= 0.0) {
            return Err(format!(
                "camera aperture must be >= 0, got {}",
                self.aperture_radius
            ));
        }
        let view = from - to;
        if view.length_squared() <= f32::MIN_POSITIVE {
            return Err("camera 'from' and 'to' are the same point".into());
        }
        let w = view.normalize();
        let side = up.cross(w);
        if side.length_squared() <= 1e-12 * up.length_squared().max(f32::MIN_POSITIVE) {
            return Err("camera 'up' is parallel to the view direction".into());
        }
        let u = side.normalize();
        let v = w.cross(u);
        let focus_distance = self.focus_distance.unwrap_or(view.length());
        if !(focus_distance.is_finite() && focus_distance > 0.0) {
            return Err(format!(
                "camera focus distance must be > 0, got {focus_distance}"
            ));
        }
        Ok(CameraBasis {
            origin: from,
            u,
            v,
            w,
            tan_half_vfov: (self.vfov_deg.to_radians() * 0.5).tan(),
            focus_distance,
        })
    }

    /// Moves the camera along its current view direction so that the sphere around the box
    /// `lo..hi` fills the vertical field of view, looking at the box's centre.
    pub fn frame_bounds(&mut self, lo: Vec3, hi: Vec3) {
        let center = (lo + hi) * 0.5;
        let radius = ((hi - lo).length() * 0.5).max(1e-6);
        let view = Vec3::from(self.from) - Vec3::from(self.to);
        let direction = if view.is_finite() && view.length_squared() > 0.0 {
            view.normalize()
        } else {
            Vec3::Z
        };
        let half_fov = (self.vfov_deg.clamp(1.0, 179.0).to_radians() * 0.5).sin();
        let distance = radius / half_fov;
        self.to = center.to_array();
        self.from = (center + direction * distance).to_array();
        self.focus_distance = None;
    }
}
