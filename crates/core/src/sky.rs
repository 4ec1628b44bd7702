//! A physical sun and sky as an environment map: the clear-sky model of Preetham, Shirley and
//! Smits (1999, "A Practical Analytic Model for Daylight") for the sky, the sun's disk with the
//! beam illuminance of the ESRA clear-sky model (Rigollier, Bauer and Wald 2000) and a grey
//! Lambertian ground. Everything else (importance sampling, MIS, rotation, strength) is the
//! environment map's.
//!
//! Sky: luminance Y and chromaticity (x, y) of a view at zenith angle θ and angle γ from the sun,
//!   Y(θ, γ) = Y_z · F(θ, γ) / F(0, θ_s),  F(θ, γ) = (1 + A e^(B / cos θ)) (1 + C e^(D γ) + E cos² γ),
//! with the Perez coefficients A–E linear in the turbidity T and the zenith values Y_z (kcd/m²),
//! x_z, y_z from the paper's fits; xyY → XYZ → linear sRGB (D65).
//!
//! Sun: a disk of angular radius 0.2667° whose illuminance on a surface facing it is the
//! extraterrestrial 128 klx attenuated by the ESRA beam transmittance
//!   τ = exp(−0.8662 · T · m · δ_R(m)),
//! m the Kasten–Young air mass and δ_R the Rayleigh optical thickness, taking T as the Linke
//! turbidity. Its colour reddens with the air mass (a Rayleigh λ⁻⁴ extinction per channel,
//! normalised to keep the luminance). The disk's texels share its illuminance exactly, whatever
//! the resolution.
//!
//! Ground (below the horizon): radiance ρ E_h / π, E_h the horizontal illuminance of sky and sun,
//! ρ = 0.2. Photometric values become rt's radiometric units at 683 lm/W, as glTF's lights do.

use glam::Vec3;

use crate::environment::{EnvironmentMap, env_direction, env_uv};
use crate::math::sampling::luminance;

/// The sun's angular radius (radians).
pub const SUN_ANGULAR_RADIUS: f32 = 0.2667 * std::f32::consts::PI / 180.0;
/// Extraterrestrial solar illuminance (lux).
const SOLAR_LUX: f32 = 128_000.0;
/// Lumens per watt: photometric to rt's radiometric units.
const LUMENS_PER_WATT: f32 = 683.0;
const GROUND_ALBEDO: f32 = 0.2;
/// The strength a sun and sky environment starts at: 1/32 (−5 stops), so that daylight (a white
/// surface in the sun is about 40 in rt's units) lands in the display range as a camera's exposure
/// would put it; strength 1 is the physical value.
pub const DAYLIGHT_STRENGTH: f32 = 1.0 / 32.0;

/// A clear sky: the sun's elevation above the horizon and the atmosphere's turbidity (2 very
/// clear, 3 clear, 6 hazy; the model holds for 2 to 10). The sun stands at −z before the
/// environment's rotation.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SunSky {
    pub elevation_deg: f32,
    pub turbidity: f32,
}

impl SunSky {
    /// Checks the ranges the model is fitted for.
    pub fn validate(&self) -> Result<(), String> {
        if !(self.elevation_deg.is_finite() && (0.5..=90.0).contains(&self.elevation_deg)) {
            return Err(format!(
                "sun elevation must lie in [0.5, 90] degrees, got {}",
                self.elevation_deg
            ));
        }
        if !(self.turbidity.is_finite() && (2.0..=10.0).contains(&self.turbidity)) {
            return Err(format!(
                "turbidity must lie in [2, 10], got {}",
                self.turbidity
            ));
        }
        Ok(())
    }

    /// Reads `sky`, `sky:ELEVATION` or `sky:ELEVATION,TURBIDITY` (degrees; defaults 35° and 3);
    /// `None` for anything that does not start with `sky`.
    pub fn parse(spec: &str) -> Option<Result<SunSky, String>> {
        let rest = spec.strip_prefix("sky")?;
        let mut sky = SunSky {
            elevation_deg: 35.0,
            turbidity: 3.0,
        };
        if rest.is_empty() {
            return Some(Ok(sky));
        }
        let values = rest.strip_prefix(':')?;
        let numbers: Vec<&str> = values.split(',').collect();
        let parse = |v: &str, what: &str| {
            v.trim()
                .parse::<f32>()
                .map_err(|_| format!("'{spec}': the {what} '{v}' is not a number"))
        };
        Some((|| {
            match numbers.as_slice() {
                [e] => sky.elevation_deg = parse(e, "sun elevation")?,
                [e, t] => {
                    sky.elevation_deg = parse(e, "sun elevation")?;
                    sky.turbidity = parse(t, "turbidity")?;
                }
                _ => return Err(format!("'{spec}': expected sky:ELEVATION[,TURBIDITY]")),
            }
            sky.validate().map_err(|e| format!("'{spec}': {e}"))?;
            Ok(sky)
        })())
    }

    /// The sun and sky as a scene environment (2048 × 1024) at strength `DAYLIGHT_STRENGTH`.
    pub fn environment(&self) -> crate::environment::Environment {
        let mut env = crate::environment::Environment::new(
            format!(
                "sun and sky (elevation {}°, turbidity {})",
                self.elevation_deg, self.turbidity
            ),
            self.map(
                crate::environment::MAX_ENV_WIDTH,
                crate::environment::MAX_ENV_HEIGHT,
            ),
        );
        env.strength = DAYLIGHT_STRENGTH;
        env
    }

    /// Unit vector towards the sun.
    pub fn sun_direction(&self) -> Vec3 {
        let e = self.elevation_deg.to_radians();
        Vec3::new(0.0, e.sin(), -e.cos())
    }

    /// Sky radiance (rt units, linear sRGB) seen along unit `d` above the horizon, without the sun.
    pub fn sky_radiance(&self, d: Vec3) -> Vec3 {
        let t = self.turbidity;
        let theta_s = (90.0 - self.elevation_deg).to_radians();
        let cos_theta = d.y.max(1e-3);
        let gamma = d.dot(self.sun_direction()).clamp(-1.0, 1.0).acos();
        let perez = |[a, b, c, dd, e]: [f32; 5], theta_cos: f32, g: f32| {
            (1.0 + a * (b / theta_cos).exp()) * (1.0 + c * (dd * g).exp() + e * g.cos().powi(2))
        };
        let relative = |k: [f32; 5]| perez(k, cos_theta, gamma) / perez(k, 1.0, theta_s);
        let (y_coef, x_coef, yc_coef) = perez_coefficients(t);
        let (yz, xz, ycz) = zenith(t, theta_s);
        let lum = yz * relative(y_coef) * 1000.0 / LUMENS_PER_WATT;
        let x = xz * relative(x_coef);
        let y = ycz * relative(yc_coef);
        xyy_to_linear_srgb(x, y, lum)
    }

    /// The sun's illuminance on a surface facing it (rt units: lux / 683) and its colour of unit
    /// luminance.
    pub fn sun_irradiance(&self) -> (f32, Vec3) {
        let zenith_deg = 90.0 - self.elevation_deg;
        let m =
            1.0 / (zenith_deg.to_radians().cos() + 0.50572 * (96.07995 - zenith_deg).powf(-1.6364));
        let rayleigh =
            1.0 / (6.6296 + 1.7513 * m - 0.1202 * m * m + 0.0065 * m.powi(3) - 0.00013 * m.powi(4));
        let tau = (-0.8662 * self.turbidity * m * rayleigh).exp();
        // Reddening: extinction ∝ λ⁻⁴ at 610, 550 and 465 nm, its green part already in τ.
        let k = -(tau.ln());
        let colour = Vec3::new(
            (-k * ((550.0f32 / 610.0).powi(4) - 1.0)).exp(),
            1.0,
            (-k * ((550.0f32 / 465.0).powi(4) - 1.0)).exp(),
        );
        (
            SOLAR_LUX * tau / LUMENS_PER_WATT,
            colour / luminance(colour),
        )
    }

    /// The sun, sky and ground as a `width` × `height` environment map.
    pub fn map(&self, width: u32, height: u32) -> EnvironmentMap {
        let (w, h) = (width as usize, height as usize);
        // The centre of texel (col, row), as the environment lookup maps it (no rotation).
        let direction = |col: usize, row: usize| {
            env_direction(
                (col as f32 + 0.5) / w as f32,
                (row as f32 + 0.5) / h as f32,
                0.0,
            )
        };
        // A texel's solid angle: (2π / W)(π / H) sin θ at its centre.
        let texel_solid_angle = |row: usize| {
            let theta = std::f32::consts::PI * (row as f32 + 0.5) / h as f32;
            std::f32::consts::TAU / w as f32 * std::f32::consts::PI / h as f32 * theta.sin()
        };
        let mut texels = vec![[0.0f32; 3]; w * h];
        let mut horizontal = 0.0f64;
        for row in 0..h / 2 {
            for col in 0..w {
                let d = direction(col, row);
                let l = self.sky_radiance(d);
                texels[row * w + col] = l.to_array();
                horizontal += f64::from(luminance(l) * d.y * texel_solid_angle(row));
            }
        }
        let sun = self.sun_direction();
        let (e_sun, colour) = self.sun_irradiance();
        horizontal += f64::from(e_sun * sun.y);
        // The disk: the texels whose centres it covers share its illuminance (or, when it covers
        // none, the texel its centre falls in takes it all).
        let cos_disk = SUN_ANGULAR_RADIUS.cos();
        let mut disk: Vec<(usize, f32)> = Vec::new();
        let rows = (SUN_ANGULAR_RADIUS / std::f32::consts::PI * h as f32).ceil() as usize + 1;
        let (sun_u, sun_v) = env_uv(sun, 0.0);
        let sun_row = (sun_v * h as f32) as usize;
        for row in sun_row.saturating_sub(rows)..(sun_row + rows + 1).min(h) {
            for col in 0..w {
                let d = direction(col, row);
                if d.dot(sun) >= cos_disk {
                    disk.push((row * w + col, texel_solid_angle(row) * d.dot(sun)));
                }
            }
        }
        if disk.is_empty() {
            let col = ((sun_u * w as f32) as usize).min(w - 1);
            let row = sun_row.min(h - 1);
            let d = direction(col, row);
            disk.push((row * w + col, texel_solid_angle(row) * d.dot(sun).max(1e-6)));
        }
        // Σ L · Ω · cos over the disk's texels equals the sun's illuminance.
        let projected: f32 = disk.iter().map(|(_, a)| a).sum();
        let radiance = colour * (e_sun / projected);
        for (i, _) in &disk {
            texels[*i] = (Vec3::from(texels[*i]) + radiance).to_array();
        }
        let ground = Vec3::splat(GROUND_ALBEDO * horizontal as f32 / std::f32::consts::PI);
        for t in texels.iter_mut().skip(h / 2 * w) {
            *t = ground.to_array();
        }
        EnvironmentMap::from_texels(width, height, texels).0
    }
}

/// Perez coefficients A–E of luminance Y and chromaticities x, y for turbidity `t` (Preetham
/// 1999, appendix A.2).
fn perez_coefficients(t: f32) -> ([f32; 5], [f32; 5], [f32; 5]) {
    (
        [
            0.1787 * t - 1.4630,
            -0.3554 * t + 0.4275,
            -0.0227 * t + 5.3251,
            0.1206 * t - 2.5771,
            -0.0670 * t + 0.3703,
        ],
        [
            -0.0193 * t - 0.2592,
            -0.0665 * t + 0.0008,
            -0.0004 * t + 0.2125,
            -0.0641 * t - 0.8989,
            -0.0033 * t + 0.0452,
        ],
        [
            -0.0167 * t - 0.2608,
            -0.0950 * t + 0.0092,
            -0.0079 * t + 0.2102,
            -0.0441 * t - 1.6537,
            -0.0109 * t + 0.0529,
        ],
    )
}

/// Zenith luminance (kcd/m²) and chromaticity for turbidity `t` and the sun's zenith angle
/// `theta_s` (Preetham 1999, appendix A.2).
fn zenith(t: f32, theta_s: f32) -> (f32, f32, f32) {
    let chi = (4.0 / 9.0 - t / 120.0) * (std::f32::consts::PI - 2.0 * theta_s);
    let yz = (4.0453 * t - 4.9710) * chi.tan() - 0.2155 * t + 2.4192;
    let poly = |rows: [[f32; 4]; 3]| {
        let th = [theta_s.powi(3), theta_s.powi(2), theta_s, 1.0];
        let row = |r: [f32; 4]| r.iter().zip(th).map(|(a, b)| a * b).sum::<f32>();
        t * t * row(rows[0]) + t * row(rows[1]) + row(rows[2])
    };
    let xz = poly([
        [0.00166, -0.00375, 0.00209, 0.0],
        [-0.02903, 0.06377, -0.03202, 0.00394],
        [0.11693, -0.21196, 0.06052, 0.25886],
    ]);
    let ycz = poly([
        [0.00275, -0.00610, 0.00317, 0.0],
        [-0.04214, 0.08970, -0.04153, 0.00516],
        [0.15346, -0.26756, 0.06670, 0.26688],
    ]);
    (yz.max(0.0), xz, ycz)
}

/// CIE xyY to linear sRGB (D65 primaries), negative channels clipped.
fn xyy_to_linear_srgb(x: f32, y: f32, lum: f32) -> Vec3 {
    if !(y > 0.0 && lum > 0.0) {
        return Vec3::ZERO;
    }
    let (cx, cz) = (x / y * lum, (1.0 - x - y) / y * lum);
    Vec3::new(
        3.2406 * cx - 1.5372 * lum - 0.4986 * cz,
        -0.9689 * cx + 1.8758 * lum + 0.0415 * cz,
        0.0557 * cx - 0.2040 * lum + 1.0570 * cz,
    )
    .max(Vec3::ZERO)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn sky() -> SunSky {
        SunSky {
            elevation_deg: 35.0,
            turbidity: 3.0,
        }
    }

    /// The zenith's luminance is the paper's Y_z (F's ratio is 1 there), and a clear sky's zenith
    /// is bluish: blue above red.
    #[test]
    fn the_zenith_has_the_papers_luminance_and_is_blue() {
        let s = sky();
        let l = s.sky_radiance(Vec3::Y);
        let (yz, _, _) = zenith(3.0, 55f32.to_radians());
        let expected = yz * 1000.0 / LUMENS_PER_WATT;
        // The sRGB matrix's luminance row is the CIE Y row to 4 digits.
        assert!(
            (luminance(l) / expected - 1.0).abs() < 2e-3,
            "{} vs {expected}",
            luminance(l)
        );
        assert!(l.z > l.x, "zenith {l}");
        // Published values: Y_z about 5–10 kcd/m² for T = 3 with the sun 35° up.
        assert!((4.0..12.0).contains(&yz), "Y_z {yz}");
    }

    /// Brighter towards the sun than at right angles to it, and at the horizon than at the zenith
    /// away from the sun (the circumsolar and horizon brightening the model is known for).
    #[test]
    fn the_sky_brightens_towards_the_sun_and_the_horizon() {
        let s = sky();
        let e = 25f32.to_radians();
        let near_sun = Vec3::new(0.0, e.sin(), -e.cos()).normalize();
        let across = Vec3::new(e.cos(), e.sin(), 0.0);
        assert!(luminance(s.sky_radiance(near_sun)) > 2.0 * luminance(s.sky_radiance(across)));
        let low_away = Vec3::new(0.0, 0.05, 1.0).normalize();
        assert!(luminance(s.sky_radiance(low_away)) > luminance(s.sky_radiance(Vec3::Y)) * 0.8);
    }

    /// The map's disk texels give the sun's illuminance exactly (Σ L Ω cos), at any resolution,
    /// and the sun is brighter and whiter high than low.
    #[test]
    fn the_sun_disk_carries_its_illuminance_at_any_resolution() {
        for (w, h) in [(2048u32, 1024u32), (256, 128), (32, 16)] {
            let s = sky();
            let map = s.map(w, h);
            let sky_only = |i: usize, row: usize| {
                let d = env_direction(
                    ((i % w as usize) as f32 + 0.5) / w as f32,
                    (row as f32 + 0.5) / h as f32,
                    0.0,
                );
                (d, s.sky_radiance(d))
            };
            let sun = s.sun_direction();
            let mut e = 0.0f64;
            for (i, t) in map.texels.iter().enumerate() {
                let row = i / w as usize;
                if row >= h as usize / 2 {
                    continue;
                }
                let (d, sky) = sky_only(i, row);
                let extra = luminance(Vec3::from(*t) - sky);
                if extra > 0.0 {
                    let theta = std::f32::consts::PI * (row as f32 + 0.5) / h as f32;
                    let omega = std::f32::consts::TAU / w as f32 * std::f32::consts::PI / h as f32
                        * theta.sin();
                    e += f64::from(extra * omega * d.dot(sun));
                }
            }
            let (e_sun, _) = s.sun_irradiance();
            assert!(
                (e as f32 / e_sun - 1.0).abs() < 1e-3,
                "{w}x{h}: disk gives {e}, the sun {e_sun}"
            );
        }
        let (high, white) = SunSky {
            elevation_deg: 80.0,
            turbidity: 3.0,
        }
        .sun_irradiance();
        let (low, red) = SunSky {
            elevation_deg: 5.0,
            turbidity: 3.0,
        }
        .sun_irradiance();
        assert!(high > 3.0 * low, "{high} vs {low}");
        assert!(red.x / red.z > white.x / white.z && red.x > red.z);
        // Roughly 100 klx of direct sun at 80° in a clear sky (ESRA: 90–110 klx).
        assert!(
            (80_000.0..115_000.0).contains(&(high * LUMENS_PER_WATT)),
            "{high}"
        );
    }

    #[test]
    fn sky_specs_parse_or_name_what_is_wrong() {
        let ok = |s: &str| SunSky::parse(s).unwrap().unwrap();
        assert_eq!(ok("sky"), sky());
        assert_eq!(ok("sky:20").elevation_deg, 20.0);
        assert_eq!(ok("sky:20,6").turbidity, 6.0);
        for bad in [
            "sky:",
            "sky:abc",
            "sky:20,x",
            "sky:1,2,3",
            "sky:95",
            "sky:30,1",
        ] {
            let e = SunSky::parse(bad).unwrap().unwrap_err();
            assert!(e.contains(bad), "{bad}: {e}");
        }
        assert!(SunSky::parse("studio.hdr").is_none());
        assert!(SunSky::parse("skyline.hdr").is_none());
    }

    #[test]
    fn out_of_range_parameters_are_refused() {
        for (e, t) in [
            (-5.0, 3.0),
            (95.0, 3.0),
            (30.0, 1.0),
            (30.0, 12.0),
            (f32::NAN, 3.0),
        ] {
            let s = SunSky {
                elevation_deg: e,
                turbidity: t,
            };
            assert!(s.validate().is_err(), "{e}, {t}");
        }
        assert!(sky().validate().is_ok());
    }
}
