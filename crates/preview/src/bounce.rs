//! Light that bounces, for the preview: an irradiance volume (as Blender's Eevee bakes one) built on
//! the CPU with rt-core's BVH and traversal, once per change of the geometry, materials or lights
//! (`probes.rs` lights the probes, `volume_cache.rs` keeps the volume, `probe_textures.rs` uploads
//! it).
//!
//! A grid of probes over the scene (about four cells across, at least two along each axis it
//! spans; over the objects where a flat backdrop holds most of its surface); from each,
//! `PROBE_RAYS` rays in a Fibonacci spiral. A ray that meets a surface takes that surface's
//! outgoing radiance lit once: its diffuse albedo/π times the preview lights' irradiance there (each
//! with a shadow ray), plus its albedo times the sky's mean radiance; a ray that leaves the scene
//! counts towards the probe's view of the sky, weighed by the sky's light that way. The second
//! bounce is gathered at the same hits from the first, the later ones follow as a series (as many
//! as the render's `max_depth` allows). Per probe and per axis (+x, −x, +y, −y, +z, −z, an
//! "ambient cube") the volume keeps the bounce irradiance over π from that side,
//! Σ L_i max(a·d_i, 0) · 4/N, and the share of the sky's light that side sees, which dims the
//! image-based light where the scene hides the sky; and per probe its radiance by direction, for
//! glossy reflections. Probes inside closed objects (most of their rays meet back faces) take their
//! valid neighbours' values.
//!
//! Emission is left out: emitters light the preview directly, as lights. Scenes of more than
//! `MAX_TRIANGLES` triangles get one probe, the uniform ambient term of progressive radiosity
//! (`uniform_bounce`), which costs nothing to build.

use std::f32::consts::PI;
use std::sync::Arc;

use glam::{UVec3, Vec3, Vec4};
use rt_core::environment::{EnvironmentMap, env_texel_index, env_uv};
use rt_core::math::sampling::luminance;
use rt_core::{Material, Scene};

use super::surfaces::{emitter_shape, material_params};
use super::types::{PreviewLight, light_kind};

/// Rays per probe.
pub const PROBE_RAYS: usize = 128;
/// How far off a surface, in cells, the ambient cube is looked up (the shader's
/// `PROBE_LOOKUP_LIFT`): far enough that probes behind a wall weigh less, near enough that a floor
/// reads the probes just above it (half a cell made the Cornell box's floor 14% too bright and a
/// dark room's walls 10%; a tenth made its ceiling 14% too dark).
pub const PROBE_LOOKUP_LIFT: f32 = 0.25;
/// Largest scene that gets a grid (its BVH and rays take tens of milliseconds at this size).
pub const MAX_TRIANGLES: usize = 100_000;
/// Probes along the scene's largest side.
pub(crate) const PROBES_ACROSS: f32 = 4.0;

/// A probe's radiance map: `BANDS` bands of equal solid angle by height (the horizon a boundary
/// between two) times `AZIMUTHS` sectors around the vertical, `BINS` bins (`direction_bin`).
pub const BANDS: u32 = 6;
pub const AZIMUTHS: u32 = 8;
pub const BINS: u32 = BANDS * AZIMUTHS;

/// The probes, laid out as the shader's 3D texture: texel (axis · nx + ix, iy, iz) holds
/// [bounce irradiance/π (rgb), sky visibility] of probe (ix, iy, iz) from side `axis`. Beside it,
/// what glossy reflections read: each probe's radiance by direction in `BINS` bins
/// (`direction_bin`), [radiance of the surfaces seen (rgb, zero where the sky is seen), share of
/// the sky], bin b of probe (ix, iy, iz) at texel (b · nx + ix, iy, iz) of a second 3D texture
/// (laid out as the first, so one filtered lookup interpolates the probes). Six cosine-weighted
/// sides cannot tell a floor just below the horizon from the sky above it: a brushed can whose
/// reflections all looked down at a lit floor read half sky from its sideways cube faces (39% too
/// dark); nor can bins that straddle the horizon (an octahedral map's do).
#[derive(Clone, Debug, PartialEq)]
pub struct IrradianceVolume {
    pub dims: [u32; 3],
    pub lo: Vec3,
    pub hi: Vec3,
    pub texels: Vec<[f32; 4]>,
    pub radiance: Vec<[f32; 4]>,
}

/// The bin of unit direction `d` in a probe's radiance map (the WGSL's `direction_bin` in
/// preview_shading.wgsl): its band by height, then its sector around the vertical.
pub fn direction_bin(d: Vec3) -> u32 {
    let band = (((d.y + 1.0) * 0.5 * BANDS as f32).max(0.0) as u32).min(BANDS - 1);
    let turn = d.z.atan2(d.x) / std::f32::consts::TAU + 0.5;
    let around = ((turn * AZIMUTHS as f32).max(0.0) as u32).min(AZIMUTHS - 1);
    band * AZIMUTHS + around
}

/// The direction at the middle of bin `b`.
pub fn bin_centre(b: u32) -> Vec3 {
    let (band, around) = (b / AZIMUTHS, b % AZIMUTHS);
    let y = -1.0 + (band as f32 + 0.5) * 2.0 / BANDS as f32;
    let phi = ((around as f32 + 0.5) / AZIMUTHS as f32 - 0.5) * std::f32::consts::TAU;
    let r = (1.0 - y * y).max(0.0).sqrt();
    Vec3::new(r * phi.cos(), y, r * phi.sin())
}

impl IrradianceVolume {
    /// One probe everywhere: `bounce` from every side, the sky fully seen.
    pub fn uniform(bounce: Vec3) -> Self {
        IrradianceVolume {
            dims: [1, 1, 1],
            lo: Vec3::ZERO,
            hi: Vec3::ONE,
            texels: vec![bounce.extend(1.0).to_array(); 6],
            radiance: vec![bounce.extend(1.0).to_array(); BINS as usize],
        }
    }

    /// The index of probe `cell`'s bin `bin` in `radiance`.
    pub(crate) fn radiance_index(&self, [x, y, z]: [u32; 3], bin: u32) -> usize {
        let [nx, ny, _] = self.dims;
        ((z * ny + y) * BINS * nx + bin * nx + x) as usize
    }

    pub(crate) fn index(&self, [x, y, z]: [u32; 3], axis: usize) -> usize {
        let [nx, ny, _] = self.dims;
        ((z * ny + y) * 6 * nx + axis as u32 * nx + x) as usize
    }

    /// This volume without its bounce light, keeping how much of the sky each probe sees: the
    /// preview of a render whose paths end after their first surface (`max_depth` ≤ 2, light
    /// straight from the lights and the environment).
    pub fn direct_only(&self) -> Self {
        IrradianceVolume {
            texels: self.texels.iter().map(|t| [0.0, 0.0, 0.0, t[3]]).collect(),
            radiance: self
                .radiance
                .iter()
                .map(|t| [0.0, 0.0, 0.0, t[3]])
                .collect(),
            ..self.clone()
        }
    }

    /// The cell of the `i`th probe (x fastest).
    pub(crate) fn cell_of(&self, i: usize) -> [u32; 3] {
        let [nx, ny, _] = self.dims;
        let i = i as u32;
        [i % nx, (i / nx) % ny, i / (nx * ny)]
    }

    /// The probes interpolated trilinearly at `q`, side `axis`, clamped to the outer probes
    /// (the shader's `probe`, whose texture sampler does the same).
    fn probe(&self, q: Vec3, axis: usize) -> Vec4 {
        let dims = Vec3::from(self.dims.map(|d| d as f32));
        let extent = (self.hi - self.lo).max(Vec3::splat(1e-6));
        let f = ((q - self.lo) / extent).clamp(Vec3::ZERO, Vec3::ONE) * dims;
        let c = f.clamp(Vec3::splat(0.5), dims - 0.5) - 0.5;
        let base = c.floor();
        let t = c - base;
        let mut sum = Vec4::ZERO;
        for corner in 0..8u32 {
            let offset = UVec3::new(corner & 1, (corner >> 1) & 1, corner >> 2);
            let at = (base.as_uvec3() + offset).min(UVec3::from(self.dims) - 1);
            let w = Vec3::select(offset.cmpeq(UVec3::ZERO), 1.0 - t, t);
            sum += Vec4::from(self.at(at.to_array(), axis)) * w.x * w.y * w.z;
        }
        sum
    }

    /// Lookup point `q` for a surface at `s` facing `n`, moved within its cell of probes so that
    /// the trilinear weights favour the probes in front of the surface (the shader's
    /// `in_front_of`): a box's face otherwise read the probe inside the box, which takes its lit
    /// neighbours' light. Per axis, the two layers of probes are weighed by `facing_weight` of
    /// their height above the surface's plane (linear in the probe's index, so exact for a surface
    /// facing along an axis).
    fn in_front_of(&self, q: Vec3, s: Vec3, n: Vec3) -> Vec3 {
        let dims = Vec3::from(self.dims.map(|d| d as f32));
        let extent = (self.hi - self.lo).max(Vec3::splat(1e-6));
        let spacing = extent / dims;
        let cell = spacing.min_element();
        let c = (((q - self.lo) / extent).clamp(Vec3::ZERO, Vec3::ONE) * dims)
            .clamp(Vec3::splat(0.5), dims - 0.5);
        let base = (c - 0.5).floor();
        let t = c - 0.5 - base;
        let height = (self.lo + c * spacing - s).dot(n) / cell;
        let step = Vec3::select(dims.cmpgt(Vec3::splat(1.5)), spacing * n / cell, Vec3::ZERO);
        let below = facing_weight(Vec3::splat(height) - t * step);
        let above = facing_weight(Vec3::splat(height) + (1.0 - t) * step);
        let moved = t * above / ((1.0 - t) * below + t * above).max(Vec3::splat(1e-12));
        self.lo + (base + 0.5 + moved) * spacing
    }

    /// Bounce irradiance/π (xyz) and sky visibility (w) towards `d` at a surface point `p` facing
    /// `n`: the shader's `ambient_cube`, on the CPU (the second bounce reads the first with it).
    pub(crate) fn ambient_cube(&self, p: Vec3, n: Vec3, d: Vec3) -> Vec4 {
        let cell = (self.hi - self.lo) / Vec3::from(self.dims.map(|d| d as f32));
        let q = self.in_front_of(p + n * PROBE_LOOKUP_LIFT * cell.min_element(), p, n);
        let w = d * d;
        let mut sum = Vec4::ZERO;
        for (axis, weight, positive) in [
            (0, w.x, d.x >= 0.0),
            (2, w.y, d.y >= 0.0),
            (4, w.z, d.z >= 0.0),
        ] {
            if weight > 1e-4 {
                sum += self.probe(q, if positive { axis } else { axis + 1 }) * weight;
            }
        }
        sum / (w.x + w.y + w.z).max(1e-6)
    }

    /// The probe at `cell`, side `axis`.
    pub fn at(&self, cell: [u32; 3], axis: usize) -> [f32; 4] {
        self.texels[self.index(cell, axis)]
    }
}

/// How much a probe at height `h` above a surface's plane counts, in units of the smallest cell
/// side (the shader's `facing_weight`): fully a tenth of a cell in front, a fiftieth a tenth
/// behind (inside the object, or beyond a wall); so a floor's own probes, just above it, count
/// fully.
fn facing_weight(h: Vec3) -> Vec3 {
    (0.5 + 5.0 * h).clamp(Vec3::splat(0.02), Vec3::ONE)
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
pub(crate) fn diffuse_albedo(material: &Material, texture_means: &[Vec3]) -> Vec3 {
    let (base, _, params, _, texture) = material_params(material);
    let image = texture
        .and_then(|t| texture_means.get(t).copied())
        .unwrap_or(Vec3::ONE);
    Vec3::from(base) * image * (1.0 - params[2] * (1.0 - params[0]))
}

/// Each texture's mean linear colour (over at most 2^16 texels, evenly strided): a checkered
/// floor sends on its squares' mean, not white's.
pub(crate) fn texture_means(scene: &Scene) -> Vec<Vec3> {
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

/// The environment as the volume sees it: its mean radiance (what surfaces reflect of it), and
/// the map (turned by `turns`) whose luminance by direction weighs each probe's view of the sky.
#[derive(Clone, Debug, Default)]
pub struct Sky {
    pub mean: Vec3,
    pub map: Option<Arc<EnvironmentMap>>,
    pub turns: f32,
}

impl Sky {
    /// A constant environment (an ambient colour).
    pub fn uniform(radiance: Vec3) -> Self {
        Sky {
            mean: radiance,
            ..Default::default()
        }
    }

    pub(crate) fn luminance(&self, d: Vec3) -> f32 {
        self.map.as_ref().map_or(1.0, |map| {
            let (u, v) = env_uv(d, self.turns);
            let texel = env_texel_index(u, v, map.width.max(1), map.height.max(1)) as usize;
            map.texels
                .get(texel)
                .map_or(0.0, |t| luminance(Vec3::from(*t)))
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Two layers of probes along x, the near one lit and the far one dark: a wall between them
    /// facing −x (the dark probes behind it, inside an object) reads the lit probes it faces, and
    /// the wall facing +x reads the dark ones; the weights fall smoothly across the wall's plane,
    /// so a surface level with a layer of probes still reads it.
    #[test]
    fn a_lookup_reads_the_probes_in_front_of_the_surface() {
        let dims = [2, 1, 1];
        let mut volume = IrradianceVolume {
            dims,
            lo: Vec3::ZERO,
            hi: Vec3::new(2.0, 1.0, 1.0),
            texels: vec![[0.0; 4]; 12],
            radiance: Vec::new(),
        };
        for axis in 0..6 {
            let i = volume.index([0, 0, 0], axis);
            volume.texels[i] = [1.0, 1.0, 1.0, 0.0];
        }
        // The probes stand at x = 0.5 (lit) and 1.5 (dark); walls at x = 1.
        let facing_lit = volume.ambient_cube(Vec3::new(1.0, 0.5, 0.5), -Vec3::X, -Vec3::X);
        assert!(facing_lit.x > 0.97, "{facing_lit}");
        let facing_dark = volume.ambient_cube(Vec3::new(1.0, 0.5, 0.5), Vec3::X, Vec3::X);
        assert!(facing_dark.x < 0.03, "{facing_dark}");
        // Facing along y, both layers lie in the wall's plane: plain trilinear, half and half.
        let level = volume.ambient_cube(Vec3::new(1.0, 0.5, 0.5), Vec3::Y, Vec3::Y);
        assert!((level.x - 0.5).abs() < 1e-5, "{level}");
        // A wall at x = 1.75 facing −x has both layers in front: the lookup is not moved.
        let q = Vec3::new(1.25, 0.5, 0.5);
        assert_eq!(
            volume.in_front_of(q, Vec3::new(1.75, 0.5, 0.5), -Vec3::X),
            q
        );
    }
}
