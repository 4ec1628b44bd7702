//! Where light subpaths start, and the lights that strategy s = 1 connects to: an emitter
//! triangle (picked by power, as the path tracer's power table picks it, then a uniform point on
//! it), the environment map (a direction by its importance table; a subpath starts from a disk
//! across the scene's bounding sphere, as a sun's), or a point, spot or sun light, each chosen in
//! proportion to its flux (an environment's: that of its light above its mean,
//! `environment_excess`; a uniform ambient light starts none).

use glam::Vec3;

use crate::emitters::pick_emitter;
use crate::environment::{env_lookup, sample_env};
use crate::estimator::texture::{coverage, surface_emission};
use crate::gpu_scene::GpuScene;
use crate::gpu_types::{ALPHA_BLEND, ALPHA_MASK, DeltaLight, Frame};
use crate::light_kind::LightTag;
use crate::math::rng::Rng;
use crate::math::sampling::{luminance, onb, sample_disk, sample_triangle};

/// How a light is chosen: the emitter table with probability `area`, the environment with
/// probability `environment`, else delta light `i` with probability `delta[i]`.
#[derive(Clone, Debug)]
pub struct LightChoice {
    pub area: f32,
    pub environment: f32,
    pub delta: Vec<f32>,
    /// The sphere bounding the scene, which a sun's light subpaths start from.
    pub centre: Vec3,
    pub radius: f32,
}

/// A light picked for a subpath's start or a connection.
#[derive(Clone, Copy, Debug)]
pub enum Picked {
    /// Emitter triangle `index`, at barycentrics (b1, b2); `per_area` is the density of this
    /// point per unit area (pick probability times the table's).
    Triangle {
        index: u32,
        b: (f32, f32),
        per_area: f32,
    },
    /// The environment, picked with probability `pick`; `u` the four numbers its direction is
    /// drawn with.
    Environment { u: [f32; 4], pick: f32 },
    /// Delta light `index`, picked with probability `pick`.
    Delta { index: usize, pick: f32 },
}

impl LightChoice {
    pub fn new(scene: &GpuScene, frame: &Frame) -> LightChoice {
        let (lo, hi) = scene.world_box;
        let centre = 0.5 * (lo + hi);
        let radius = (0.5 * (hi - lo).length()).max(1e-3) * 1.01;
        let area_flux = if frame.emitter_count > 0 && frame.emitter_power_inv > 0.0 {
            std::f32::consts::PI / frame.emitter_power_inv
        } else {
            0.0
        };
        let environment_flux =
            std::f32::consts::PI * radius * radius * environment_excess(scene, frame);
        let flux: Vec<f32> = scene
            .delta_lights
            .iter()
            .map(|l| delta_flux(l, radius))
            .collect();
        let total = area_flux + environment_flux + flux.iter().sum::<f32>();
        if !(total > 0.0 && total.is_finite()) {
            return LightChoice {
                area: 0.0,
                environment: 0.0,
                delta: vec![0.0; flux.len()],
                centre,
                radius,
            };
        }
        LightChoice {
            area: area_flux / total,
            environment: environment_flux / total,
            delta: flux.iter().map(|f| f / total).collect(),
            centre,
            radius,
        }
    }

    /// Whether there is any light to start from.
    pub fn any(&self) -> bool {
        self.area > 0.0 || self.environment > 0.0 || self.delta.iter().any(|&p| p > 0.0)
    }

    /// Picks a light and, on an emitter, a point: four random numbers.
    pub fn pick(&self, scene: &GpuScene, frame: &Frame, rng: &mut Rng) -> Option<Picked> {
        let (u, u_alias, u_a, u_b) = (
            rng.next_f32(),
            rng.next_f32(),
            rng.next_f32(),
            rng.next_f32(),
        );
        if u < self.area {
            let n = frame.emitter_count as usize;
            let index = pick_emitter(&scene.emitters[..n], u / self.area, u_alias);
            let [_, b1, b2] = sample_triangle(u_a, u_b);
            return Some(Picked::Triangle {
                index,
                b: (b1, b2),
                per_area: self.per_area(scene, frame, index),
            });
        }
        let mut rest = u - self.area;
        let environment = Picked::Environment {
            u: [
                (rest / self.environment).min(1.0 - f32::EPSILON),
                u_alias,
                u_a,
                u_b,
            ],
            pick: self.environment,
        };
        if rest < self.environment {
            return Some(environment);
        }
        rest -= self.environment;
        for (index, &pick) in self.delta.iter().enumerate() {
            if rest < pick {
                return Some(Picked::Delta { index, pick });
            }
            rest -= pick;
        }
        // Rounding past the last: the last light with any flux.
        match self.delta.iter().rposition(|&p| p > 0.0) {
            Some(index) => Some(Picked::Delta {
                index,
                pick: self.delta[index],
            }),
            None => (self.environment > 0.0).then_some(environment),
        }
    }

    /// The density per unit area with which `pick` chooses a point on emitter triangle `index`.
    pub fn per_area(&self, scene: &GpuScene, frame: &Frame, index: u32) -> f32 {
        let material = &scene.materials[scene.triangles[index as usize].material as usize];
        self.area * luminance(Vec3::from(material.emission)) * frame.emitter_power_inv
    }
}

/// How much of the environment map's light light subpaths should carry: ∫ max(0, L(ω) − L̄) dω
/// in luminance, L̄ the map's mean. The uniform part of an environment lights every direction
/// alike, and camera paths find it as readily by their own sampling (through glass too); what they
/// miss is light concentrated in a small solid angle, a sun. So a sky's sun starts light subpaths,
/// a uniform ambient light none (camera paths that escape to it are then its only strategy).
/// Texel (x, y) spans 2π²/(w·h) · sinθ of solid angle (θ at its row's centre).
pub(super) fn environment_excess(scene: &GpuScene, frame: &Frame) -> f32 {
    let (w, h) = (frame.env_width as usize, frame.env_height as usize);
    if w == 0 || h == 0 || scene.env_texels.len() < w * h {
        return 0.0;
    }
    let texel = 2.0 * std::f64::consts::PI.powi(2) / (w * h) as f64;
    let rows = || {
        scene
            .env_texels
            .chunks_exact(w)
            .take(h)
            .enumerate()
            .map(|(y, row)| {
                let sin_theta = (std::f64::consts::PI * (y as f64 + 0.5) / h as f64).sin();
                let lum = row
                    .iter()
                    .map(|t| f64::from(luminance(Vec3::from(t.radiance)).max(0.0)));
                (sin_theta * texel, lum)
            })
    };
    let (mut integral, mut solid_angle) = (0.0, 0.0);
    for (d_omega, lum) in rows() {
        for l in lum {
            integral += l * d_omega;
            solid_angle += d_omega;
        }
    }
    let mean = integral / solid_angle.max(f64::MIN_POSITIVE);
    let excess: f64 = rows()
        .map(|(d_omega, lum)| lum.map(|l| (l - mean).max(0.0)).sum::<f64>() * d_omega)
        .sum();
    excess as f32
}

/// A direction towards the environment map for four uniform numbers, by its importance table:
/// (direction, radiance arriving along it, density per solid angle); a zero density without a map.
pub fn sample_environment(scene: &GpuScene, frame: &Frame, u: [f32; 4]) -> (Vec3, Vec3, f32) {
    let (w, h, rotation) = (frame.env_width, frame.env_height, frame.env_rotation);
    if w == 0 {
        return (Vec3::Y, Vec3::ZERO, 0.0);
    }
    sample_env(&scene.env_texels, w, h, rotation, u)
}

/// The density per solid angle of `sample_environment` drawing unit `toward`.
pub fn environment_pdf(scene: &GpuScene, frame: &Frame, toward: Vec3) -> f32 {
    let (w, h, rotation) = (frame.env_width, frame.env_height, frame.env_rotation);
    if w == 0 {
        return 0.0;
    }
    env_lookup(&scene.env_texels, w, h, rotation, toward).1
}

/// A point on the disk of radius r across the scene's bounding sphere, facing `dir` (the way the
/// light travels) from its far side, where light from infinitely far along −`dir` starts, and
/// the density per unit area of drawing it.
pub fn disk_origin(choice: &LightChoice, dir: Vec3, rng: &mut Rng) -> (Vec3, f32) {
    let (t, b) = onb(dir);
    let (dx, dy) = sample_disk(rng);
    let r = choice.radius;
    let origin = choice.centre - dir * r + r * (dx * t + dy * b);
    (origin, 1.0 / (std::f32::consts::PI * r * r))
}

/// A delta light's flux (its luminance), by which it is picked.
fn delta_flux(light: &DeltaLight, radius: f32) -> f32 {
    let power = luminance(Vec3::from(light.power)).max(0.0);
    let tau = std::f32::consts::TAU;
    match LightTag::from_tag(light.kind) {
        Some(LightTag::Point) => 2.0 * tau * power,
        Some(LightTag::Spot | LightTag::SpotGltf) => {
            tau * (1.0 - 0.5 * (light.cos_inner + light.cos_outer)).max(1e-4) * power
        }
        Some(LightTag::Directional) => std::f32::consts::PI * radius * radius * power,
        _ => 0.0,
    }
}

/// The point of emitter triangle `index` at barycentrics `b`, its unit front normal, and the
/// radiance it sends along unit `w` (times its coverage on a surface with holes).
pub fn emitter_point(scene: &GpuScene, index: u32, b: (f32, f32), w: Vec3) -> (Vec3, Vec3, Vec3) {
    let tri = &scene.triangles[index as usize];
    let (v0, v1, v2) = (Vec3::from(tri.v0), Vec3::from(tri.v1), Vec3::from(tri.v2));
    let y = v0 * (1.0 - b.0 - b.1) + v1 * b.0 + v2 * b.1;
    let n = (v1 - v0).cross(v2 - v0).normalize();
    let cos = w.dot(n);
    if cos <= 0.0 {
        return (y, n, Vec3::ZERO);
    }
    let material = &scene.materials[tri.material as usize];
    let mut le = surface_emission(scene, material, tri, index, b, cos);
    if material.flags & (ALPHA_MASK | ALPHA_BLEND) != 0 {
        le *= coverage(scene, material, tri, index, b.0, b.1);
    }
    (y, n, le)
}

/// The intensity (W/sr) point or spot light `light` sends along unit `w`.
pub fn intensity(light: &DeltaLight, w: Vec3) -> Vec3 {
    let cos = w.dot(Vec3::from(light.direction));
    let falloff = match LightTag::from_tag(light.kind) {
        Some(LightTag::Spot) => crate::light::spot_falloff(cos, light.cos_inner, light.cos_outer),
        Some(LightTag::SpotGltf) => {
            crate::light::spot_falloff_gltf(cos, light.cos_inner, light.cos_outer)
        }
        _ => 1.0,
    };
    Vec3::from(light.power) * falloff
}

/// Whether `light` is a sun (a direction, no position).
pub fn is_sun(light: &DeltaLight) -> bool {
    light.kind == LightTag::Directional.tag()
}

/// A direction for a point or spot light's subpath and its density per solid angle: uniform over
/// the sphere, or over the spot's outer cone.
pub fn delta_direction(light: &DeltaLight, rng: &mut Rng) -> (Vec3, f32) {
    let (u1, u2) = (rng.next_f32(), rng.next_f32());
    let cos_max = match LightTag::from_tag(light.kind) {
        Some(LightTag::Spot | LightTag::SpotGltf) => light.cos_outer.clamp(-1.0, 1.0),
        _ => -1.0,
    };
    let cos = 1.0 - u1 * (1.0 - cos_max);
    let sin = (1.0 - cos * cos).max(0.0).sqrt();
    let phi = std::f32::consts::TAU * u2;
    let axis = if cos_max > -1.0 {
        Vec3::from(light.direction)
    } else {
        Vec3::Z
    };
    let (t, b) = onb(axis);
    let w = (t * (sin * phi.cos()) + b * (sin * phi.sin()) + axis * cos).normalize();
    (w, delta_direction_pdf(light, w))
}

/// The density per solid angle of `delta_direction` drawing unit `w`.
pub fn delta_direction_pdf(light: &DeltaLight, w: Vec3) -> f32 {
    match LightTag::from_tag(light.kind) {
        Some(LightTag::Spot | LightTag::SpotGltf) => {
            let cos_max = light.cos_outer.clamp(-1.0, 1.0);
            if w.dot(Vec3::from(light.direction)) < cos_max {
                0.0
            } else {
                1.0 / (std::f32::consts::TAU * (1.0 - cos_max).max(1e-7))
            }
        }
        Some(LightTag::Point) => 1.0 / (4.0 * std::f32::consts::PI),
        _ => 0.0,
    }
}
