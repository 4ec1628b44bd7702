//! The scene's fog: a homogeneous medium filling all space outside closed objects, the camera
//! included, as Mitsuba's `volpath` renders a scene whose sensor and surfaces all sit in one
//! homogeneous medium (and Cycles a world volume). Its light is the path tracer's
//! (`math::medium`, `estimator::path`): it dims what lies behind it, scatters light into the view
//! (god rays past a window, halos round lamps) and counts a scattering as a path vertex.
//!
//! Lights at infinity — the sun and the environment — lie behind an infinite depth of it and send
//! no light through it, as in Mitsuba and Cycles; light a foggy scene with lamps, emitters or
//! point and spot lights, or put the fog in an object (a box with a volume material).

use serde::{Deserialize, Serialize};

use crate::gpu_types::Medium;
use crate::material::Rgb;

/// Fog's parameters (`rt-cli --fog-density/--fog-albedo/--fog-anisotropy`, the editor's Lights
/// panel, projects' `fog`).
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct Fog {
    /// Extinction σ_t per scene unit (light travels 1/σ_t on average before it meets the fog);
    /// 0: no fog.
    pub density: f32,
    /// The single-scattering albedo σ_s/σ_t per channel in [0, 1]: 1 scatters all, 0 only
    /// absorbs (smoke).
    pub albedo: Rgb,
    /// The Henyey–Greenstein g in (−1, 1): > 0 scatters forward (haze round a lamp), 0 evenly.
    pub anisotropy: f32,
}

impl Default for Fog {
    fn default() -> Self {
        Fog {
            density: 0.0,
            albedo: [1.0; 3],
            anisotropy: 0.0,
        }
    }
}

impl Fog {
    /// Whether there is any fog.
    pub fn is_on(&self) -> bool {
        self.density > 0.0
    }

    /// The medium the kernels trace (`Frame::fog`); vacuum without fog.
    pub fn medium(&self) -> Medium {
        if !self.is_on() {
            return Medium::default();
        }
        Medium {
            sigma_t: [self.density; 3],
            anisotropy: self.anisotropy,
            sigma_s: self.albedo.map(|a| a * self.density),
            _pad: 0.0,
        }
    }

    /// Names the first parameter out of range.
    pub fn validate(&self) -> Result<(), String> {
        if !(self.density.is_finite() && self.density >= 0.0) {
            return Err(format!(
                "fog density must be finite and >= 0 (extinction per scene unit), got {}",
                self.density
            ));
        }
        if !self.albedo.iter().all(|a| (0.0..=1.0).contains(a)) {
            return Err(format!(
                "fog albedo must lie in [0, 1] per channel, got {:?}",
                self.albedo
            ));
        }
        if self.anisotropy.is_nan() || self.anisotropy.abs() >= 1.0 {
            return Err(format!(
                "fog anisotropy must lie in (-1, 1), got {}",
                self.anisotropy
            ));
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn bad_fog_is_refused_by_name() {
        let bad = [
            Fog {
                density: -1.0,
                ..Fog::default()
            },
            Fog {
                density: f32::NAN,
                ..Fog::default()
            },
            Fog {
                albedo: [1.5, 0.0, 0.0],
                ..Fog::default()
            },
            Fog {
                anisotropy: 1.0,
                ..Fog::default()
            },
            Fog {
                anisotropy: f32::NAN,
                ..Fog::default()
            },
        ];
        for (fog, word) in
            bad.iter()
                .zip(["density", "density", "albedo", "anisotropy", "anisotropy"])
        {
            let e = fog.validate().expect_err("refused");
            assert!(e.contains(word), "{e}");
        }
        assert!(Fog::default().validate().is_ok());
        assert_eq!(Fog::default().medium(), Medium::default());
        let m = Fog {
            density: 2.0,
            albedo: [0.5, 1.0, 0.0],
            anisotropy: 0.3,
        }
        .medium();
        assert_eq!(
            (m.sigma_t, m.sigma_s, m.anisotropy),
            ([2.0; 3], [1.0, 2.0, 0.0], 0.3)
        );
    }
}
