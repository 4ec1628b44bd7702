//! Light that bounces, for the preview: an irradiance volume (as Blender's Eevee bakes one) built on
//! the CPU with rt-core's BVH and traversal, once per change of the geometry, materials or lights.
//!
//! A grid of probes over the scene's bounds (about four cells across its largest side); from each,
//! `PROBE_RAYS` rays in a Fibonacci spiral. A ray that meets a surface takes that surface's
//! outgoing radiance lit once: its diffuse albedo/π times the preview lights' irradiance there (each
//! with a shadow ray), plus its albedo times the environment's mean radiance; a ray that leaves the
//! scene counts towards the probe's view of the sky. Per probe and per axis (+x, −x, +y, −y, +z, −z,
//! an "ambient cube") the volume keeps the bounce irradiance over π from that side,
//! Σ L_i max(a·d_i, 0) · 4/N, times 1/(1 − ρ̄) for the later bounces (ρ̄ the scene's mean albedo
//! times how enclosed it is), and the cosine-weighted share of rays that escape, which dims the
//! image-based light where the scene hides the sky. Probes inside closed objects (most of their
//! rays meet back faces) take their valid neighbours' values.
//!
//! Emission is left out: emitters light the preview directly, as lights. Scenes of more than
//! `MAX_TRIANGLES` triangles get one probe, the uniform ambient term of progressive radiosity
//! (`uniform_bounce`), which costs nothing to build.

use std::f32::consts::PI;
use std::hash::{Hash, Hasher};
use std::sync::{Arc, Mutex};

use glam::Vec3;
use rt_core::math::sampling::luminance;
use rt_core::{Material, Scene};

use super::surfaces::{emitter_shape, material_params};
use super::types::{CUBE_SIDES, PreviewLight, light_kind};

/// Rays per probe.
pub const PROBE_RAYS: usize = 128;
/// Largest scene that gets a grid (its BVH and rays take tens of milliseconds at this size).
pub const MAX_TRIANGLES: usize = 100_000;
/// Probes along the scene's largest side.
const PROBES_ACROSS: f32 = 4.0;

/// The probes, laid out as the shader's 3D texture: texel (axis · nx + ix, iy, iz) holds
/// [bounce irradiance/π (rgb), sky visibility] of probe (ix, iy, iz) from side `axis`.
#[derive(Clone, Debug, PartialEq)]
pub struct IrradianceVolume {
    pub dims: [u32; 3],
    pub lo: Vec3,
    pub hi: Vec3,
    pub texels: Vec<[f32; 4]>,
}

impl IrradianceVolume {
    /// One probe everywhere: `bounce` from every side, the sky fully seen.
    pub fn uniform(bounce: Vec3) -> Self {
        IrradianceVolume {
            dims: [1, 1, 1],
            lo: Vec3::ZERO,
            hi: Vec3::ONE,
            texels: vec![bounce.extend(1.0).to_array(); 6],
        }
    }

    fn index(&self, [x, y, z]: [u32; 3], axis: usize) -> usize {
        let [nx, ny, _] = self.dims;
        ((z * ny + y) * 6 * nx + axis as u32 * nx + x) as usize
    }

    /// This volume without its bounce light, keeping how much of the sky each probe sees: the
    /// preview of a render whose paths end after their first surface (`max_depth` ≤ 2, light
    /// straight from the lights and the environment).
    pub fn direct_only(&self) -> Self {
        IrradianceVolume {
            texels: self.texels.iter().map(|t| [0.0, 0.0, 0.0, t[3]]).collect(),
            ..self.clone()
        }
    }

    /// The probe at `cell`, side `axis`.
    pub fn at(&self, cell: [u32; 3], axis: usize) -> [f32; 4] {
        self.texels[self.index(cell, axis)]
    }
}

/// The scene's area-weighted mean albedo times how enclosed it is, its surface area, and how
/// enclosed it is (surface area over its bounding box's, at most 1: a room keeps its light, a floor
/// under the sky lets most of it go).
fn mean_albedo(scene: &Scene, bounds: (Vec3, Vec3)) -> (Vec3, f32, f32) {
    let size = (bounds.1 - bounds.0).max(Vec3::splat((bounds.1 - bounds.0).max_element() * 1e-3));
    let box_area = 2.0 * (size.x * size.y + size.y * size.z + size.z * size.x);
    let (mut area, mut reflected) = (0.0f32, Vec3::ZERO);
    let means = texture_means(scene);
    for object in &scene.objects {
        if matches!(object.material, Material::Emissive { .. }) {
            continue;
        }
        let a = emitter_shape(object).0;
        area += a;
        reflected += diffuse_albedo(&object.material, &means) * a;
    }
    if area <= 0.0 || !area.is_finite() {
        return (Vec3::ZERO, 0.0, 0.0);
    }
    let enclosure = (area / box_area).min(1.0);
    (reflected / area * enclosure, area, enclosure)
}

/// What a surface sends on of the light it gets, in all directions: its base colour (times its
/// image's mean, `texture_means`) unless it transmits (a metal's colour counts: it reflects as
/// much, only not diffusely).
fn diffuse_albedo(material: &Material, texture_means: &[Vec3]) -> Vec3 {
    let (base, _, params, _, texture) = material_params(material);
    let image = texture
        .and_then(|t| texture_means.get(t).copied())
        .unwrap_or(Vec3::ONE);
    Vec3::from(base) * image * (1.0 - params[2] * (1.0 - params[0]))
}

/// Each texture's mean linear colour (over at most 2^16 texels, evenly strided): a checkered
/// floor sends on its squares' mean, not white's.
fn texture_means(scene: &Scene) -> Vec<Vec3> {
    let to_linear: Vec<f32> = (0..=255u8)
        .map(|v| rt_core::math::sampling::srgb_to_linear(f32::from(v) / 255.0))
        .collect();
    scene
        .textures
        .iter()
        .map(|t| {
            let texels = t.rgba8.len() / 4;
            let stride = (texels / 65536).max(1);
            let mut sum = Vec3::ZERO;
            let mut count = 0u32;
            for texel in t.rgba8.chunks_exact(4).step_by(stride) {
                sum += Vec3::new(
                    to_linear[texel[0] as usize],
                    to_linear[texel[1] as usize],
                    to_linear[texel[2] as usize],
                );
                count += 1;
            }
            if count == 0 {
                Vec3::ONE
            } else {
                sum / count as f32
            }
        })
        .collect()
}

/// The ambient term of progressive radiosity (Cohen et al. 1988), for scenes too large for a grid:
/// L = ρ/(1 − ρ̄) · Φ / (π A), Φ the lights' power that reaches the scene, A its surface area.
pub fn uniform_bounce(scene: &Scene, lights: &[PreviewLight], bounds: (Vec3, Vec3)) -> Vec3 {
    let (albedo, area, enclosure) = mean_albedo(scene, bounds);
    if area <= 0.0 {
        return Vec3::ZERO;
    }
    let size = bounds.1 - bounds.0;
    let mut power = Vec3::ZERO;
    for light in lights {
        let color = Vec3::from_slice(&light.color[..3]);
        power += match light.shadow[0] {
            light_kind::EMITTER => {
                let normal = Vec3::from_slice(&light.direction[..3]).length();
                color * PI * (normal + 4.0 * light.color[3])
            }
            light_kind::DIRECTIONAL => {
                let d = Vec3::from_slice(&light.direction[..3]).abs();
                color * (d.x * size.y * size.z + d.y * size.z * size.x + d.z * size.x * size.y)
            }
            // Of a point or spot light's power, what an enclosure catches.
            light_kind::SPOT => {
                color * std::f32::consts::TAU * (1.0 - light.direction[3]) * enclosure
            }
            _ => color * 4.0 * PI * enclosure,
        };
    }
    albedo / (1.0 - luminance(albedo).min(0.95)) * power / (PI * area)
}

/// Direct irradiance from `light` on a surface at `p` facing `n`, with a shadow ray.
fn direct(gpu: &rt_core::GpuScene, light: &PreviewLight, p: Vec3, n: Vec3) -> Vec3 {
    let color = Vec3::from_slice(&light.color[..3]);
    let (l, strength, reach) = if light.shadow[0] == light_kind::DIRECTIONAL {
        (-Vec3::from_slice(&light.direction[..3]), color, f32::MAX)
    } else {
        let d = Vec3::from_slice(&light.position[..3]) - p;
        let d2 = d.length_squared().max(1e-12);
        let l = d / d2.sqrt();
        let mut intensity = color;
        match light.shadow[0] {
            light_kind::SPOT => {
                let c = (-l).dot(Vec3::from_slice(&light.direction[..3]));
                let (cos_outer, cos_inner) = (light.direction[3], light.cone[0]);
                let t = ((c - cos_outer) / (cos_inner - cos_outer).max(1e-6)).clamp(0.0, 1.0);
                intensity *= if light.cone[1] > 0.5 {
                    t * t
                } else {
                    t * t * (3.0 - 2.0 * t)
                };
            }
            light_kind::EMITTER => {
                intensity *=
                    Vec3::from_slice(&light.direction[..3]).dot(-l).max(0.0) + light.color[3];
            }
            _ => {}
        }
        (l, intensity / d2, d2.sqrt() * 0.999)
    };
    let cos = n.dot(l);
    if cos <= 0.0 || strength.max_element() <= 0.0 {
        return Vec3::ZERO;
    }
    let mut hit = rt_core::estimator::trace(gpu, p, l, reach);
    // An emitter's light starts on its own surface: what the shadow ray meets there is the
    // emitter itself, not an occluder.
    let material = |hit: &mut rt_core::gpu_types::Hit| {
        let mut placed = None;
        rt_core::estimator::instances::hit_triangle(gpu, hit, &mut placed)
            .tri
            .material
    };
    let blocked = hit.triangle != u32::MAX
        && (light.shadow[0] != light_kind::EMITTER || material(&mut hit) + 1 != light.shadow[3]);
    if blocked { Vec3::ZERO } else { strength * cos }
}

/// Directions spread evenly over the sphere (a Fibonacci spiral).
fn directions() -> Vec<Vec3> {
    let golden = PI * (3.0 - 5f32.sqrt());
    (0..PROBE_RAYS)
        .map(|i| {
            let z = 1.0 - (2.0 * i as f32 + 1.0) / PROBE_RAYS as f32;
            let r = (1.0 - z * z).max(0.0).sqrt();
            let phi = golden * i as f32;
            Vec3::new(r * phi.cos(), z, r * phi.sin())
        })
        .collect()
}

/// Computes the volume of `scene` under `lights`, the environment's mean radiance `sky`.
fn compute(
    scene: &Scene,
    lights: &[PreviewLight],
    bounds: (Vec3, Vec3),
    sky: Vec3,
) -> IrradianceVolume {
    let fallback = || IrradianceVolume::uniform(uniform_bounce(scene, lights, bounds));
    if scene.triangle_count() > MAX_TRIANGLES {
        return fallback();
    }
    let Ok(gpu) = rt_core::GpuScene::build(scene) else {
        return fallback();
    };
    let (lo, hi) = bounds;
    let size = (hi - lo).max(Vec3::splat((hi - lo).max_element() * 1e-3));
    let cell = size.max_element() / PROBES_ACROSS;
    let dims = (size / cell)
        .ceil()
        .clamp(Vec3::ONE, Vec3::splat(8.0))
        .as_uvec3()
        .to_array();
    let means = texture_means(scene);
    let albedo_of: Vec<Vec3> = scene
        .objects
        .iter()
        .map(|o| diffuse_albedo(&o.material, &means))
        .collect();
    let later_bounces = 1.0 / (1.0 - luminance(mean_albedo(scene, bounds).0).min(0.95));
    let rays = directions();
    let epsilon = size.max_element() * 1e-4;
    let mut volume = IrradianceVolume {
        dims,
        lo,
        hi,
        texels: vec![[0.0; 4]; 6 * (dims[0] * dims[1] * dims[2]) as usize],
    };
    let mut valid = Vec::new();
    for z in 0..dims[2] {
        for y in 0..dims[1] {
            for x in 0..dims[0] {
                let c = lo
                    + (Vec3::new(x as f32, y as f32, z as f32) + 0.5)
                        / Vec3::from(dims.map(|d| d as f32))
                        * size;
                let mut bounce = [Vec3::ZERO; 6];
                let mut sky_seen = [0.0f32; 6];
                let mut weight = [0.0f32; 6];
                let mut back = 0;
                for &d in &rays {
                    let mut hit = rt_core::estimator::trace(&gpu, c, d, f32::MAX);
                    let cosines = CUBE_SIDES.map(|a| a.dot(d).max(0.0));
                    for k in 0..6 {
                        weight[k] += cosines[k];
                    }
                    if hit.triangle == u32::MAX {
                        for k in 0..6 {
                            sky_seen[k] += cosines[k];
                        }
                        continue;
                    }
                    let mut placed = None;
                    let tri =
                        rt_core::estimator::instances::hit_triangle(&gpu, &mut hit, &mut placed)
                            .tri;
                    let [v0, v1, v2] = [tri.v0, tri.v1, tri.v2].map(Vec3::from);
                    let mut n = (v1 - v0).cross(v2 - v0).normalize_or_zero();
                    if n.dot(d) > 0.0 {
                        back += 1;
                        n = -n;
                    }
                    let albedo = albedo_of
                        .get(tri.material as usize)
                        .copied()
                        .unwrap_or(Vec3::ZERO);
                    if albedo.max_element() <= 0.0 {
                        continue;
                    }
                    let p = c + d * hit.t + n * epsilon;
                    let irradiance: Vec3 = lights.iter().map(|l| direct(&gpu, l, p, n)).sum();
                    let radiance = albedo / PI * irradiance + albedo * sky;
                    for k in 0..6 {
                        bounce[k] += radiance * cosines[k];
                    }
                }
                valid.push(back * 2 < rays.len());
                for k in 0..6 {
                    let i = volume.index([x, y, z], k);
                    // E/π = Σ L max(a·d, 0) · (4π/N) / π.
                    let e = bounce[k] * (4.0 / rays.len() as f32) * later_bounces;
                    volume.texels[i] = e.extend(sky_seen[k] / weight[k].max(1e-6)).to_array();
                }
            }
        }
    }
    dilate(&mut volume, &valid);
    volume
}

/// Gives probes inside closed objects their valid neighbours' mean (repeatedly), or the mean of
/// all valid probes where none is near.
fn dilate(volume: &mut IrradianceVolume, valid: &[bool]) {
    let [nx, ny, nz] = volume.dims;
    let cell = |i: usize| {
        let i = i as u32;
        [i % nx, (i / nx) % ny, i / (nx * ny)]
    };
    let mut valid = valid.to_vec();
    for _ in 0..4 {
        let mut next = valid.clone();
        for i in 0..valid.len() {
            if valid[i] {
                continue;
            }
            let [x, y, z] = cell(i);
            let mut sum = [[0.0f32; 4]; 6];
            let mut count = 0.0;
            for (dx, dy, dz) in [
                (1, 0, 0),
                (-1, 0, 0),
                (0, 1, 0),
                (0, -1, 0),
                (0, 0, 1),
                (0, 0, -1),
            ] {
                let (a, b, c) = (x as i32 + dx, y as i32 + dy, z as i32 + dz);
                if a < 0 || b < 0 || c < 0 || a >= nx as i32 || b >= ny as i32 || c >= nz as i32 {
                    continue;
                }
                let j = ((c as u32 * ny + b as u32) * nx + a as u32) as usize;
                if valid[j] {
                    for (k, s) in sum.iter_mut().enumerate() {
                        let t = volume.at([a as u32, b as u32, c as u32], k);
                        for (s, t) in s.iter_mut().zip(t) {
                            *s += t;
                        }
                    }
                    count += 1.0;
                }
            }
            if count > 0.0 {
                for (k, s) in sum.iter().enumerate() {
                    let index = volume.index([x, y, z], k);
                    volume.texels[index] = s.map(|v| v / count);
                }
                next[i] = true;
            }
        }
        valid = next;
    }
}

/// Scenes up to this many triangles have their volume built at once even in the editor (a few
/// milliseconds); larger ones on a thread while the last volume stands in.
pub const SYNC_TRIANGLES: usize = 20_000;

/// The last volume built, and the one being built on a thread (for its key).
struct Cache {
    key: u64,
    volume: Arc<IrradianceVolume>,
    building: Option<(u64, std::thread::JoinHandle<IrradianceVolume>)>,
}

fn key_of(scene: &Scene, lights: &[PreviewLight], sky: Vec3) -> u64 {
    let mut hasher = std::collections::hash_map::DefaultHasher::new();
    for object in &scene.objects {
        (Arc::as_ptr(&object.mesh) as usize).hash(&mut hasher);
        object
            .transform
            .matrix()
            .to_cols_array()
            .map(f32::to_bits)
            .hash(&mut hasher);
        diffuse_albedo(&object.material, &[])
            .to_array()
            .map(f32::to_bits)
            .hash(&mut hasher);
    }
    bytemuck::cast_slice::<PreviewLight, u32>(lights).hash(&mut hasher);
    sky.to_array().map(f32::to_bits).hash(&mut hasher);
    hasher.finish()
}

/// The volume of the frame's scene, rebuilt when its geometry, materials, lights or sky changed
/// and kept otherwise (one scene at a time: the editor's). With `wait`, or for a scene of at most
/// `SYNC_TRIANGLES` triangles, it is built before this returns; otherwise on a thread, and until it
/// is ready the last volume (or radiosity's uniform term) stands in and the second value is true:
/// the caller draws again soon.
pub fn irradiance_volume(
    scene: &Scene,
    lights: &[PreviewLight],
    bounds: Option<(Vec3, Vec3)>,
    sky: Vec3,
    wait: bool,
) -> (Arc<IrradianceVolume>, bool) {
    static CACHE: Mutex<Option<Cache>> = Mutex::new(None);
    let Some(bounds) = bounds else {
        return (Arc::new(IrradianceVolume::uniform(Vec3::ZERO)), false);
    };
    let key = key_of(scene, lights, sky);
    let mut guard = CACHE.lock().unwrap_or_else(|e| e.into_inner());
    // A finished build becomes the current volume.
    if let Some(cache) = guard.as_mut()
        && cache
            .building
            .as_ref()
            .is_some_and(|(_, job)| job.is_finished())
        && let Some((built, job)) = cache.building.take()
        && let Ok(volume) = job.join()
    {
        cache.key = built;
        cache.volume = Arc::new(volume);
    }
    if let Some(cache) = guard.as_ref()
        && cache.key == key
    {
        return (cache.volume.clone(), false);
    }
    if wait || scene.triangle_count() <= SYNC_TRIANGLES {
        let volume = Arc::new(compute(scene, lights, bounds, sky));
        let building = guard.take().and_then(|c| c.building);
        *guard = Some(Cache {
            key,
            volume: volume.clone(),
            building,
        });
        return (volume, false);
    }
    let cache = guard.get_or_insert_with(|| Cache {
        key: 0,
        volume: Arc::new(IrradianceVolume::uniform(uniform_bounce(
            scene, lights, bounds,
        ))),
        building: None,
    });
    if cache.building.is_none() {
        let (scene, lights) = (scene.clone(), lights.to_vec());
        cache.building = Some((
            key,
            std::thread::spawn(move || compute(&scene, &lights, bounds, sky)),
        ));
    }
    (cache.volume.clone(), true)
}
