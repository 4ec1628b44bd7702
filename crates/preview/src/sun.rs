//! The sun of an environment map, taken out as a light (as Eevee's sun extraction does): a sky's
//! sun is a tiny disc holding most of its light, which image-based light cannot shadow. Blurred
//! into the prefiltered environment it lit the shaded sides of objects and the ground under them
//! alike (outdoors under rt's `sky:40`: ground +14%, a sphere −27%). Taken out, it is a directional
//! light with a shadow map, and the environment keeps the sky.
//!
//! The sun is the environment's brightest texel and the texels within `SUN_CONE_DEG` of it
//! brighter than `SUN_THRESHOLD` times the map's mean radiance, when they hold at least
//! `SUN_SHARE` of the map's light (else the environment stays as it is: an overcast sky or an
//! interior has no sun). The light's irradiance is their ∫ L dω, its direction their
//! power-weighted mean; their texels take the mean radiance of the other texels within the cone
//! (the sky about the sun).

use std::sync::{Arc, Mutex};

use glam::Vec3;
use rt_core::environment::{EnvironmentMap, env_direction, env_uv};
use rt_core::math::sampling::luminance;

/// A texel brighter than this many times the map's mean radiance may be part of the sun.
pub const SUN_THRESHOLD: f32 = 50.0;
/// How far from the brightest texel the sun's texels may lie (the sky's sun is 0.53° across; an
/// image's may be blurred or larger).
pub const SUN_CONE_DEG: f32 = 10.0;
/// The least share of the map's light the sun holds to be taken out.
pub const SUN_SHARE: f32 = 0.1;

/// The sun taken out of a map.
#[derive(Clone, Debug)]
pub struct Sun {
    /// Towards the sun, in the map's own frame (unturned).
    pub direction: Vec3,
    /// ∫ L dω over the sun's texels, at strength 1.
    pub irradiance: Vec3,
    /// The solid angle its texels cover (sr): what a view refracted or reflected towards it sees
    /// is its irradiance over this.
    pub solid_angle: f32,
    /// The map without the sun.
    pub sky: Arc<EnvironmentMap>,
}

impl Sun {
    /// Towards the sun in the world, for an environment turned by `rotation_deg`.
    pub fn world_direction(&self, rotation_deg: f32) -> Vec3 {
        let (u, v) = env_uv(self.direction, 0.0);
        env_direction(u, v, rotation_deg / 360.0)
    }
}

/// Each texel's direction and solid angle (unturned).
fn texel_directions(map: &EnvironmentMap) -> impl Iterator<Item = (Vec3, f32)> + '_ {
    let (w, h) = (map.width.max(1), map.height.max(1));
    let cell = 2.0 * std::f32::consts::PI * std::f32::consts::PI / (w * h) as f32;
    (0..w * h).map(move |i| {
        let (u, v) = ((i % w) as f32 + 0.5, (i / w) as f32 + 0.5);
        let (u, v) = (u / w as f32, v / h as f32);
        (
            env_direction(u, v, 0.0),
            cell * (std::f32::consts::PI * v).sin(),
        )
    })
}

/// The sun of `map`, if it has one (see the module's rule).
pub fn find(map: &EnvironmentMap) -> Option<Sun> {
    let texels: Vec<(Vec3, f32, f32)> = texel_directions(map)
        .zip(&map.texels)
        .map(|((d, omega), t)| (d, omega, luminance(Vec3::from(*t))))
        .collect();
    let total: f32 = texels.iter().map(|(_, omega, l)| l * omega).sum();
    if !(total.is_finite() && total > 0.0) {
        return None;
    }
    let threshold = SUN_THRESHOLD * total / (4.0 * std::f32::consts::PI);
    let (brightest, _) = texels
        .iter()
        .enumerate()
        .max_by(|a, b| a.1.2.total_cmp(&b.1.2))?;
    let center = texels[brightest].0;
    let cos_cone = SUN_CONE_DEG.to_radians().cos();
    let in_cone = |d: Vec3| d.dot(center) >= cos_cone;
    let in_sun = |&(d, _, l): &(Vec3, f32, f32)| l > threshold && in_cone(d);
    let (mut irradiance, mut weighted, mut power) = (Vec3::ZERO, Vec3::ZERO, 0.0);
    let mut solid_angle = 0.0;
    let (mut around, mut around_weight) = (Vec3::ZERO, 0.0);
    for (texel, radiance) in texels.iter().zip(&map.texels) {
        let (d, omega, l) = *texel;
        if in_sun(texel) {
            irradiance += Vec3::from(*radiance) * omega;
            solid_angle += omega;
            weighted += d * l * omega;
            power += l * omega;
        } else if in_cone(d) {
            around += Vec3::from(*radiance) * omega;
            around_weight += omega;
        }
    }
    if power < SUN_SHARE * total {
        return None;
    }
    let sky_about = if around_weight > 0.0 {
        around / around_weight
    } else {
        Vec3::ZERO
    };
    let sky = EnvironmentMap {
        width: map.width,
        height: map.height,
        texels: texels
            .iter()
            .zip(&map.texels)
            .map(|(texel, radiance)| {
                if in_sun(texel) {
                    sky_about.to_array()
                } else {
                    *radiance
                }
            })
            .collect(),
    };
    Some(Sun {
        direction: weighted.normalize_or(center),
        irradiance,
        solid_angle,
        sky: Arc::new(sky),
    })
}

/// `find` for the map behind `map`, kept for the next frames (a 2048 × 1024 sky takes tens of
/// milliseconds): one map at a time, the editor's.
pub fn of(map: &Arc<EnvironmentMap>) -> Option<Arc<Sun>> {
    // Holding the map keeps its address, the key, from being reused.
    type Last = Option<(Arc<EnvironmentMap>, Option<Arc<Sun>>)>;
    static LAST: Mutex<Last> = Mutex::new(None);
    let mut last = LAST.lock().unwrap_or_else(|e| e.into_inner());
    if let Some((kept, sun)) = last.as_ref()
        && Arc::ptr_eq(kept, map)
    {
        return sun.clone();
    }
    let sun = find(map).map(Arc::new);
    *last = Some((map.clone(), sun.clone()));
    sun
}

/// The map the environment lights the preview with: `map` without its sun where it has one (the
/// sun lights it as a light of its own).
pub fn sky_of(map: &Arc<EnvironmentMap>) -> Arc<EnvironmentMap> {
    of(map).map_or_else(|| map.clone(), |sun| sun.sky.clone())
}

#[cfg(test)]
mod tests {
    use super::*;

    fn sky_with_sun(sun: [f32; 3]) -> EnvironmentMap {
        let (w, h) = (64u32, 32u32);
        let texels = (0..w * h)
            .map(|i| {
                if i == 9 * w + 40 {
                    sun
                } else {
                    [0.3, 0.4, 0.6]
                }
            })
            .collect();
        EnvironmentMap::from_texels(w, h, texels).0
    }

    /// A bright texel is taken out whole: the light's irradiance is its ∫ L dω, its direction
    /// the texel's, and the sky keeps the rest of the map's light exactly.
    #[test]
    fn a_bright_texel_becomes_a_sun_and_the_sky_keeps_the_rest() {
        let map = sky_with_sun([4000.0, 3500.0, 3000.0]);
        let sun = find(&map).expect("a sun");
        let texels: Vec<(Vec3, f32)> = texel_directions(&map).collect();
        let (d, omega) = texels[9 * 64 + 40];
        assert!(
            sun.direction.dot(d) > 0.9999,
            "{:?} vs {d:?}",
            sun.direction
        );
        let expected = Vec3::new(4000.0, 3500.0, 3000.0) * omega;
        assert!((sun.irradiance - expected).abs().max_element() < 1e-3 * expected.x);
        let light = |m: &EnvironmentMap| -> Vec3 {
            texel_directions(m)
                .zip(&m.texels)
                .map(|((_, o), t)| Vec3::from(*t) * o)
                .sum()
        };
        let kept = light(&sun.sky) + sun.irradiance - Vec3::new(0.3, 0.4, 0.6) * omega;
        assert!((kept - light(&map)).abs().max_element() < 1e-3 * light(&map).x);
        // Turned by a quarter turn, the sun turns with the map.
        let turned = sun.world_direction(90.0);
        let (u, v) = env_uv(sun.direction, 0.0);
        assert!(turned.dot(env_direction(u, v, 0.25)) > 0.9999);
    }

    /// A map without a compact bright spot (an overcast sky, an even interior) keeps its light.
    #[test]
    fn an_even_sky_has_no_sun() {
        assert!(find(&sky_with_sun([0.3, 0.4, 0.6])).is_none());
        assert!(find(&sky_with_sun([3.0, 3.0, 3.0])).is_none());
        assert!(find(&EnvironmentMap::uniform([1.0; 3])).is_none());
    }
}
