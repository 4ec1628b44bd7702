//! The camera: where it stands, how it maps the image to directions (perspective with a thin lens,
//! orthographic, equirectangular panorama, equidistant fisheye) and its orthonormal basis.

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
    /// How the image maps to directions (perspective unless said otherwise).
    #[serde(default, skip_serializing_if = "Projection::is_perspective")]
    pub projection: Projection,
    /// The orthographic view's height in scene units; `None` takes the height the perspective
    /// view has at the scene's centre (`ortho_height_in`), so switching projection keeps the
    /// framing.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub ortho_height: Option<f32>,
    /// The angle the fisheye's image circle spans, in degrees, in (0, 360].
    #[serde(
        default = "default_fisheye_angle",
        skip_serializing_if = "is_default_fisheye_angle"
    )]
    pub fisheye_angle_deg: f32,
    /// The node of the scene's animation that carries the camera (`crate::animation`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub animation_node: Option<u32>,
}

/// How a camera maps the image to directions (`Frame::projection`, the same numbers in WGSL).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Projection {
    /// A pinhole or thin lens: `vfov_deg` is the vertical field of view.
    #[default]
    Perspective,
    /// Parallel rays along the view direction over a window `ortho_height` high.
    Orthographic,
    /// Equirectangular: longitude across the image (the view direction in its centre, behind the
    /// camera at both edges), latitude from the nadir at the bottom to the zenith at the top.
    Panorama,
    /// Equidistant fisheye: the angle from the view direction grows linearly with the distance
    /// from the centre, out to `fisheye_angle_deg / 2` at the rim of a circle as high as the image
    /// (as wide, when the image is taller); pixels outside it are black.
    Fisheye,
}

impl Projection {
    pub const ALL: [Projection; 4] = [
        Projection::Perspective,
        Projection::Orthographic,
        Projection::Panorama,
        Projection::Fisheye,
    ];

    /// Its number in `Frame::projection` (`PROJECTION_*` in path.wgsl).
    pub fn tag(self) -> u32 {
        self as u32
    }

    /// The word users and the command line use.
    pub fn name(self) -> &'static str {
        match self {
            Projection::Perspective => "perspective",
            Projection::Orthographic => "orthographic",
            Projection::Panorama => "panorama",
            Projection::Fisheye => "fisheye",
        }
    }

    pub fn is_perspective(&self) -> bool {
        *self == Projection::Perspective
    }
}

impl std::str::FromStr for Projection {
    type Err = String;
    fn from_str(s: &str) -> Result<Self, String> {
        Projection::ALL
            .into_iter()
            .find(|p| p.name().eq_ignore_ascii_case(s))
            .ok_or_else(|| {
                format!("unknown projection '{s}': expected perspective, orthographic, panorama or fisheye")
            })
    }
}

fn default_fisheye_angle() -> f32 {
    180.0
}

fn is_default_fisheye_angle(angle: &f32) -> bool {
    *angle == default_fisheye_angle()
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
    pub projection: Projection,
    /// Orthographic: half the view's height in scene units; fisheye: half its angle in radians;
    /// else unused (`Frame::projection_scale`).
    pub projection_scale: f32,
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
            projection: Projection::Perspective,
            ortho_height: None,
            fisheye_angle_deg: default_fisheye_angle(),
            animation_node: None,
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
        let tan_half_vfov = (self.vfov_deg.to_radians() * 0.5).tan();
        let projection_scale = match self.projection {
            Projection::Orthographic => {
                let height = self.ortho_height_in(None);
                if !(height.is_finite() && height > 0.0) {
                    return Err(format!(
                        "camera orthographic height must be > 0, got {height}"
                    ));
                }
                height * 0.5
            }
            Projection::Fisheye => {
                let angle = self.fisheye_angle_deg;
                if !(angle > 0.0 && angle <= 360.0) {
                    return Err(format!(
                        "camera fisheye angle must be in (0, 360] degrees, got {angle}"
                    ));
                }
                angle.to_radians() * 0.5
            }
            Projection::Perspective | Projection::Panorama => 0.0,
        };
        Ok(CameraBasis {
            origin: from,
            u,
            v,
            w,
            tan_half_vfov,
            focus_distance,
            projection: self.projection,
            projection_scale,
        })
    }

    /// The orthographic height this camera shows: its own, or the height the perspective view has
    /// at the depth of the scene's centre (`bounds`), or at the target without bounds or when the
    /// centre lies behind the camera (a glTF camera's target is one unit ahead: a poor guide).
    pub fn ortho_height_in(&self, bounds: Option<(Vec3, Vec3)>) -> f32 {
        if let Some(h) = self.ortho_height {
            return h;
        }
        let from = Vec3::from(self.from);
        let view = Vec3::from(self.to) - from;
        let depth = bounds
            .map(|(lo, hi)| ((lo + hi) * 0.5 - from).dot(view.normalize_or_zero()))
            .filter(|d| d.is_finite() && *d > 0.0)
            .unwrap_or(view.length());
        2.0 * depth * (self.vfov_deg.to_radians() * 0.5).tan()
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
        if self.ortho_height.is_some() {
            self.ortho_height = Some(2.0 * radius);
        }
    }
}
