//! Camera files: `{"from": [x,y,z], "to": [...], "up": [...], "vfov": deg, "width": w, "height": h,
//! "background": [r,g,b]}` as in `assets/cornell/cornell.json`, and optionally `"projection":
//! "perspective" | "orthographic" | "panorama" | "fisheye"`, `"ortho_height"` (scene units) and
//! `"fisheye_angle"` (degrees). Only `from` and `to` are required.

use std::path::Path;

use serde::Deserialize;

use rt_core::error::{Error, Result};
use rt_core::scene::Scene;

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct CameraFile {
    pub from: [f32; 3],
    pub to: [f32; 3],
    pub up: Option<[f32; 3]>,
    pub vfov: Option<f32>,
    pub aperture_radius: Option<f32>,
    pub focus_distance: Option<f32>,
    pub width: Option<u32>,
    pub height: Option<u32>,
    pub background: Option<[f32; 3]>,
    pub projection: Option<rt_core::camera::Projection>,
    pub ortho_height: Option<f32>,
    pub fisheye_angle: Option<f32>,
}

impl CameraFile {
    pub fn parse(text: &str, path: &Path) -> Result<Self> {
        serde_json::from_str(text).map_err(|e| Error::Parse {
            path: path.to_path_buf(),
            line: e.line(),
            message: e.to_string(),
        })
    }

    pub fn load(path: &Path) -> Result<Self> {
        let text = std::fs::read_to_string(path).map_err(|source| Error::Io {
            path: path.to_path_buf(),
            source,
        })?;
        Self::parse(&text, path)
    }

    /// Overrides the scene's camera, image size and ambient light with what the file sets.
    pub fn apply(&self, scene: &mut Scene) {
        scene.camera.from = self.from;
        scene.camera.to = self.to;
        if let Some(up) = self.up {
            scene.camera.up = up;
        }
        if let Some(vfov) = self.vfov {
            scene.camera.vfov_deg = vfov;
        }
        if let Some(a) = self.aperture_radius {
            scene.camera.aperture_radius = a;
        }
        if self.focus_distance.is_some() {
            scene.camera.focus_distance = self.focus_distance;
        }
        if let Some(w) = self.width {
            scene.settings.width = w;
        }
        if let Some(h) = self.height {
            scene.settings.height = h;
        }
        if let Some(bg) = self.background {
            scene.ambient = bg;
        }
        if let Some(projection) = self.projection {
            scene.camera.projection = projection;
        }
        if self.ortho_height.is_some() {
            scene.camera.ortho_height = self.ortho_height;
        }
        if let Some(angle) = self.fisheye_angle {
            scene.camera.fisheye_angle_deg = angle;
        }
    }
}
