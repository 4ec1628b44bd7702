//! How the irradiance volume's probes are lit (`bounce.rs` holds the volume): rays from each
//! probe, the surfaces they meet lit once by the preview's lights (with shadow rays) and the sky,
//! then a second bounce gathered from the first, and the later ones as a series.

use std::f32::consts::PI;

use glam::Vec3;
use rt_core::Scene;
use rt_core::math::sampling::luminance;

use super::bounce::{
    BINS, IrradianceVolume, MAX_TRIANGLES, PROBE_RAYS, PROBES_ACROSS, Sky, bin_centre,
    diffuse_albedo, direction_bin, texture_means, uniform_bounce,
};
use super::surfaces::emitter_shape;
use super::types::{CUBE_SIDES, PreviewLight, light_kind};

/// E / L of a sphere or disc of angular radius σ (sin²σ given) whose centre lies at cos θ from the
/// normal, the part below the horizon clipped (Frostbite's listing 7; `illuminance_sphere_or_disc`
/// in preview_shading.wgsl).
fn illuminance_sphere_or_disc(cos_theta: f32, sin_sigma2: f32) -> f32 {
    let s2 = sin_sigma2.clamp(1e-12, 1.0);
    if cos_theta * cos_theta > s2 {
        return PI * s2 * cos_theta.max(0.0);
    }
    let sin_theta = (1.0 - cos_theta * cos_theta).max(1e-12).sqrt();
    let x = (1.0 / s2 - 1.0).max(1e-12).sqrt();
    let y = (-x * cos_theta / sin_theta).clamp(-1.0, 1.0);
    let sin_theta_sqrt_y = sin_theta * (1.0 - y * y).max(0.0).sqrt();
    ((cos_theta * y.acos() - x * sin_theta_sqrt_y) * s2 + (sin_theta_sqrt_y / x).atan()).max(0.0)
}

/// Direct irradiance from `light` on a surface at `p` facing `n`, with a shadow ray: the
/// shader's `incoming` (an emitter as a disc and a sphere, the horizon clipped).
fn direct(gpu: &rt_core::GpuScene, light: &PreviewLight, p: Vec3, n: Vec3) -> Vec3 {
    let color = Vec3::from_slice(&light.color[..3]);
    let (l, irradiance, reach) = if light.shadow[0] == light_kind::DIRECTIONAL {
        let l = -Vec3::from_slice(&light.direction[..3]);
        (l, color * n.dot(l), f32::MAX)
    } else {
        let d = Vec3::from_slice(&light.position[..3]) - p;
        let d2 = d.length_squared().max(1e-12);
        let l = d / d2.sqrt();
        let cos = n.dot(l);
        let irradiance = match light.shadow[0] {
            light_kind::SPOT => {
                let c = (-l).dot(Vec3::from_slice(&light.direction[..3]));
                let (cos_outer, cos_inner) = (light.direction[3], light.cone[0]);
                let t = ((c - cos_outer) / (cos_inner - cos_outer).max(1e-6)).clamp(0.0, 1.0);
                let falloff = if light.cone[1] > 0.5 {
                    t * t
                } else {
                    t * t * (3.0 - 2.0 * t)
                };
                color * falloff / d2 * cos
            }
            light_kind::EMITTER => {
                let normal = Vec3::from_slice(&light.direction[..3]);
                let flat_area = normal.length();
                let facing = normal.dot(-l).max(0.0) / flat_area.max(1e-12);
                let (disc, sphere) = (flat_area / PI, light.color[3] / PI);
                let mut scale = illuminance_sphere_or_disc(cos, disc / (disc + d2)) * facing;
                if sphere > 0.0 {
                    scale += illuminance_sphere_or_disc(cos, (sphere / d2).min(1.0));
                }
                color * scale
            }
            _ => color / d2 * cos,
        };
        (l, irradiance, d2.sqrt() * 0.999)
    };
    if irradiance.max_element() <= 0.0 {
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
    if blocked { Vec3::ZERO } else { irradiance }
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

/// Where the probes go: the scene's bounds, or, where one flat object (a ground, a floor, a stage)
/// holds most of the scene's surface, the bounds of everything else (enlarged by a quarter of
/// their size each way, within the scene's). Bounce light changes most about the objects (the
/// shade a box casts on the ground beside it); four probes across a 30 m ground stood metres
/// from a 1.5 m box and lit its shaded side with the sunlit ground (outdoors: +89% bounce).
/// Beyond the probes a lookup takes the nearest ones.
fn probe_bounds(scene: &Scene, bounds: (Vec3, Vec3)) -> (Vec3, Vec3) {
    let boxes: Vec<(f32, Vec3, Vec3)> = scene
        .objects
        .iter()
        .map(|o| {
            let m = o.transform.matrix();
            let (lo, hi) = o.mesh.positions.iter().fold(
                (Vec3::splat(f32::MAX), Vec3::splat(f32::MIN)),
                |(lo, hi), p| {
                    let p = m.transform_point3(*p);
                    (lo.min(p), hi.max(p))
                },
            );
            (emitter_shape(o).0, lo, hi)
        })
        .collect();
    let total: f32 = boxes.iter().map(|b| b.0).sum();
    let flat_backdrop = |&(area, lo, hi): &(f32, Vec3, Vec3)| {
        let size = hi - lo;
        area >= 0.5 * total && size.min_element() <= 1e-3 * size.max_element()
    };
    let (lo, hi) = boxes
        .iter()
        .filter(|b| !flat_backdrop(b) && b.1.cmple(b.2).all())
        .fold(
            (Vec3::splat(f32::MAX), Vec3::splat(f32::MIN)),
            |(lo, hi), b| (lo.min(b.1), hi.max(b.2)),
        );
    if boxes.iter().all(|b| !flat_backdrop(b)) || !lo.cmple(hi).all() {
        return bounds;
    }
    let margin = (hi - lo).max_element() * 0.25;
    let (lo, hi) = (
        (lo - Vec3::splat(margin)).max(bounds.0),
        (hi + Vec3::splat(margin)).min(bounds.1),
    );
    if lo.cmple(hi).all() { (lo, hi) } else { bounds }
}

/// One probe ray's hit on a surface that reflects: where, facing the probe, and its albedo.
struct RayHit {
    p: Vec3,
    n: Vec3,
    albedo: Vec3,
    /// The radiance it sends, lit once.
    first: Vec3,
}

/// The probes' centres, x fastest.
fn probe_centres(lo: Vec3, size: Vec3, dims: [u32; 3]) -> Vec<Vec3> {
    let cells = Vec3::from(dims.map(|d| d as f32));
    (0..dims[2])
        .flat_map(|z| (0..dims[1]).flat_map(move |y| (0..dims[0]).map(move |x| [x, y, z])))
        .map(|[x, y, z]| lo + (Vec3::new(x as f32, y as f32, z as f32) + 0.5) / cells * size)
        .collect()
}

/// Computes the volume of `scene` under `lights` and `sky`: the first bounce traced
/// (`first_bounce`), the later ones gathered from it (`later_bounces`), then the probes' radiance
/// maps.
pub(crate) fn compute(
    scene: &Scene,
    lights: &[PreviewLight],
    bounds: (Vec3, Vec3),
    sky: &Sky,
) -> IrradianceVolume {
    let fallback = || IrradianceVolume::uniform(uniform_bounce(scene, lights, bounds));
    if scene.triangle_count() > MAX_TRIANGLES {
        return fallback();
    }
    let Ok(gpu) = rt_core::GpuScene::build(scene) else {
        return fallback();
    };
    let (lo, hi) = probe_bounds(scene, bounds);
    let size = (hi - lo).max(Vec3::splat((hi - lo).max_element() * 1e-3));
    let cell = size.max_element() / PROBES_ACROSS;
    // At least two layers along every axis the scene spans: a single layer of probes above a
    // floor sees it from too high (a reflection looking down from a can's side found the floor's
    // edge, and the sky beyond, where the can itself meets the floor nearby).
    let spans = size.cmpgt(Vec3::splat(size.max_element() * 0.05));
    let dims = Vec3::select(
        spans,
        (size / cell).ceil().max(Vec3::splat(2.0)),
        (size / cell).ceil(),
    )
    .clamp(Vec3::ONE, Vec3::splat(8.0))
    .as_uvec3()
    .to_array();
    let (lo, hi) = outer_probes_at_the_bounds(lo, hi, size, dims);
    let size = hi - lo;
    let mut volume = IrradianceVolume {
        dims,
        lo,
        hi,
        texels: vec![[0.0; 4]; 6 * (dims[0] * dims[1] * dims[2]) as usize],
        radiance: vec![[0.0; 4]; (BINS * dims[0] * dims[1] * dims[2]) as usize],
    };
    let rays = directions();
    let centres = probe_centres(lo, size, dims);
    let (valid, hits) = first_bounce(&mut volume, &gpu, scene, lights, sky, &centres, &rays);
    dilate(&mut volume, &valid);
    let bounces = scene.settings.max_depth.saturating_sub(2);
    later_bounces(&mut volume, &hits, &rays, &valid, bounces);
    dilate(&mut volume, &valid);
    volume.radiance = radiance_maps(&volume, &hits, &rays, &valid, bounces);
    volume
}

/// The volume's corners such that its outer probes (at cell centres) lie just inside `lo` and
/// `hi` along each axis with two or more probes: a probe a metre above a floor saw a lamp's bright
/// patch on the ceiling over it (1/d²) nearer than the floor does, and lit the floor with it.
fn outer_probes_at_the_bounds(lo: Vec3, hi: Vec3, size: Vec3, dims: [u32; 3]) -> (Vec3, Vec3) {
    let n = Vec3::from(dims.map(|d| d as f32));
    let inset = size / n * PROBE_INSET;
    let spacing = (size - 2.0 * inset) / (n - 1.0).max(Vec3::ONE);
    let several = n.cmpgt(Vec3::ONE);
    (
        Vec3::select(several, lo + inset - 0.5 * spacing, lo),
        Vec3::select(several, hi - inset + 0.5 * spacing, hi),
    )
}

/// How far inside the bounds the outer probes lie, in cells.
const PROBE_INSET: f32 = 0.1;

/// E/π = Σ L max(a·d, 0) · (4π/N) / π: the weight of one of N rays.
fn per_ray(rays: &[Vec3]) -> f32 {
    4.0 / rays.len() as f32
}

/// Traces `rays` from each probe at `centres` and fills the volume's ambient cubes with the first
/// bounce and the sky's visibility; returns which probes lie outside objects and every ray's hit.
fn first_bounce(
    volume: &mut IrradianceVolume,
    gpu: &rt_core::GpuScene,
    scene: &Scene,
    lights: &[PreviewLight],
    sky: &Sky,
    centres: &[Vec3],
    rays: &[Vec3],
) -> (Vec<bool>, Vec<Option<RayHit>>) {
    let means = texture_means(scene);
    let albedo_of: Vec<Vec3> = scene
        .objects
        .iter()
        .map(|o| diffuse_albedo(&o.material, &means))
        .collect();
    let epsilon = (volume.hi - volume.lo).max_element() * 1e-4;
    let mut valid = Vec::with_capacity(centres.len());
    let mut hits: Vec<Option<RayHit>> = Vec::with_capacity(centres.len() * rays.len());
    for (probe, &c) in centres.iter().enumerate() {
        let mut bounce = [Vec3::ZERO; 6];
        // The sky's light each side sees, and what it would see unhidden: their ratio dims the
        // image-based light (a wall outdoors sees the bright upper half of the sky, not half of
        // the whole of it).
        let mut sky_seen = [0.0f32; 6];
        let mut sky_all = [0.0f32; 6];
        let mut back = 0;
        for &d in rays {
            let mut hit = rt_core::estimator::trace(gpu, c, d, f32::MAX);
            let cosines = CUBE_SIDES.map(|a| a.dot(d).max(0.0));
            let light = sky.luminance(d);
            for k in 0..6 {
                sky_all[k] += cosines[k] * light;
            }
            if hit.triangle == u32::MAX {
                for k in 0..6 {
                    sky_seen[k] += cosines[k] * light;
                }
                hits.push(None);
                continue;
            }
            let mut placed = None;
            let tri = rt_core::estimator::instances::hit_triangle(gpu, &mut hit, &mut placed).tri;
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
            let p = c + d * hit.t + n * epsilon;
            // Black (or an emitter, which lights the preview as a light) sends nothing on but
            // hides the sky.
            let radiance = if albedo.max_element() > 0.0 {
                let irradiance: Vec3 = lights.iter().map(|l| direct(gpu, l, p, n)).sum();
                albedo / PI * irradiance + albedo * sky.mean
            } else {
                Vec3::ZERO
            };
            for k in 0..6 {
                bounce[k] += radiance * cosines[k];
            }
            hits.push(Some(RayHit {
                p,
                n,
                albedo,
                first: radiance,
            }));
        }
        valid.push(back * 2 < rays.len());
        for k in 0..6 {
            let seen = if sky_all[k] > 0.0 {
                sky_seen[k] / sky_all[k]
            } else {
                0.0
            };
            let index = volume.index(volume.cell_of(probe), k);
            volume.texels[index] = (bounce[k] * per_ray(rays)).extend(seen).to_array();
        }
    }
    (valid, hits)
}

/// Adds the later bounces to a volume that holds the first: the second gathered at the first's
/// hits from the first, the rest as a geometric series of the ratio the second bears to the first
/// (measured at the hits, at most 0.9), as many times as the render's paths bounce (`bounces`;
/// none leaves no bounce light at all). A guess from the mean albedo alone overstated the later
/// bounces: the Cornell box's ceiling, lit by bounce alone, came out 89% too bright.
fn later_bounces(
    volume: &mut IrradianceVolume,
    hits: &[Option<RayHit>],
    rays: &[Vec3],
    valid: &[bool],
    bounces: u32,
) {
    let first = volume.clone();
    let (mut first_total, mut second_total) = (0.0f32, 0.0f32);
    for (probe, hits) in hits.chunks(rays.len()).enumerate() {
        // A probe inside an object (its rays meet the inside, lit by nothing) takes its
        // neighbours' values; its hits would read them back as light.
        if !valid[probe] {
            continue;
        }
        let mut second = [Vec3::ZERO; 6];
        for (hit, &d) in hits.iter().zip(rays) {
            let Some(hit) = hit else { continue };
            let radiance = hit.albedo * first.ambient_cube(hit.p, hit.n, hit.n).truncate();
            first_total += luminance(hit.first);
            second_total += luminance(radiance);
            for (k, side) in CUBE_SIDES.iter().enumerate() {
                second[k] += radiance * side.dot(d).max(0.0);
            }
        }
        let cell = volume.cell_of(probe);
        for (k, s) in second.into_iter().enumerate() {
            let index = volume.index(cell, k);
            let later = s * per_ray(rays);
            for c in 0..3 {
                volume.texels[index][c] += later[c];
            }
        }
    }
    let ratio = if first_total > 0.0 {
        (second_total / first_total).clamp(0.0, 0.9)
    } else {
        0.0
    };
    // 1 + r + … + r^(bounces − 2): the second bounce and those after it.
    let series: f32 = (0..bounces.saturating_sub(1).min(64))
        .map(|j| ratio.powi(j as i32))
        .sum();
    for (texel, first) in volume.texels.iter_mut().zip(&first.texels) {
        for c in 0..3 {
            let second = texel[c] - first[c];
            texel[c] = if bounces == 0 {
                0.0
            } else {
                first[c] + second * series
            };
        }
    }
}

/// Each probe's radiance by direction (`IrradianceVolume::radiance`): per bin, the mean over its
/// rays of the radiance of the surface met (lit once, plus what the volume's bounce light adds
/// there once the render's paths are long enough) and the share of its rays that leave. A bin
/// no ray fell in takes the nearest bin's; a probe inside an object takes the mean of the valid
/// probes'.
fn radiance_maps(
    volume: &IrradianceVolume,
    hits: &[Option<RayHit>],
    rays: &[Vec3],
    valid: &[bool],
    bounces: u32,
) -> Vec<[f32; 4]> {
    let bins = BINS as usize;
    let bin_of: Vec<usize> = rays.iter().map(|&d| direction_bin(d) as usize).collect();
    let mut maps: Vec<Vec<[f32; 4]>> = Vec::with_capacity(valid.len());
    for hits in hits.chunks(rays.len()) {
        let mut sum = vec![[0.0f32; 4]; bins];
        let mut count = vec![0u32; bins];
        for (hit, &bin) in hits.iter().zip(&bin_of) {
            let (radiance, sky) = match hit {
                None => (Vec3::ZERO, 1.0),
                Some(_) if bounces == 0 => (Vec3::ZERO, 0.0),
                Some(hit) if bounces == 1 => (hit.first, 0.0),
                Some(hit) => {
                    let around = volume.ambient_cube(hit.p, hit.n, hit.n).truncate();
                    (hit.first + hit.albedo * around, 0.0)
                }
            };
            let texel = &mut sum[bin];
            for c in 0..3 {
                texel[c] += radiance[c];
            }
            texel[3] += sky;
            count[bin] += 1;
        }
        let filled: Vec<usize> = (0..bins).filter(|&b| count[b] > 0).collect();
        let mean: Vec<[f32; 4]> = (0..bins)
            .map(|b| sum[b].map(|v| v / count[b].max(1) as f32))
            .collect();
        let map = (0..bins)
            .map(|b| {
                if count[b] > 0 || filled.is_empty() {
                    return mean[b];
                }
                // The nearest bin with rays.
                let here = bin_centre(b as u32);
                let towards = |x: usize| here.dot(bin_centre(x as u32));
                let nearest = filled
                    .iter()
                    .max_by(|&&x, &&y| towards(x).total_cmp(&towards(y)))
                    .copied()
                    .unwrap_or(b);
                mean[nearest]
            })
            .collect();
        maps.push(map);
    }
    let valid_mean: Vec<[f32; 4]> = (0..bins)
        .map(|b| {
            let (mut sum, mut n) = ([0.0f32; 4], 0.0f32);
            for (map, _) in maps.iter().zip(valid).filter(|(_, v)| **v) {
                for c in 0..4 {
                    sum[c] += map[b][c];
                }
                n += 1.0;
            }
            sum.map(|v| if n > 0.0 { v / n } else { 0.0 })
        })
        .collect();
    let mut radiance = vec![[0.0f32; 4]; volume.radiance.len()];
    for (probe, map) in maps.iter().enumerate() {
        let cell = volume.cell_of(probe);
        for b in 0..bins {
            radiance[volume.radiance_index(cell, b as u32)] =
                if valid[probe] { map[b] } else { valid_mean[b] };
        }
    }
    radiance
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

#[cfg(test)]
mod tests {
    use super::*;

    /// Far off, a disc's E / L is its solid angle times cos θ; facing the normal with the disc
    /// above the horizon, Lambert's exact sin²σ; half below the horizon (cos θ = 0), a disc still
    /// lights the surface with what stands above it (a positive share, below the whole disc's).
    #[test]
    fn a_disc_lights_a_surface_beyond_its_horizon() {
        let s2 = 1e-4;
        for cos in [0.2f32, 0.5, 1.0] {
            let e = illuminance_sphere_or_disc(cos, s2);
            assert!(
                (e - PI * s2 * cos).abs() <= 1e-6 * e.max(1e-12),
                "{cos}: {e}"
            );
        }
        let s2 = 0.25;
        assert!((illuminance_sphere_or_disc(1.0, s2) - PI * s2).abs() < 1e-5);
        let edge = illuminance_sphere_or_disc(0.0, s2);
        assert!(edge > 0.0 && edge < PI * s2 * 0.5, "{edge}");
        assert_eq!(illuminance_sphere_or_disc(-0.9, s2), 0.0);
    }

    /// The outer probes stand a tenth of a cell inside the bounds along every axis with two or
    /// more of them, evenly spaced between; an axis with one keeps it in the middle.
    #[test]
    fn the_outer_probes_stand_just_inside_the_bounds() {
        let (lo, hi) = (Vec3::new(-4.0, 0.0, -1.0), Vec3::new(4.0, 3.0, 1.0));
        let dims = [4, 2, 1];
        let (vlo, vhi) = outer_probes_at_the_bounds(lo, hi, hi - lo, dims);
        let centres = probe_centres(vlo, vhi - vlo, dims);
        let (first, last) = (centres[0], centres[centres.len() - 1]);
        let cell = (hi - lo) / Vec3::new(4.0, 2.0, 1.0);
        assert!((first.x - (lo.x + 0.1 * cell.x)).abs() < 1e-5, "{first}");
        assert!((last.x - (hi.x - 0.1 * cell.x)).abs() < 1e-5, "{last}");
        assert!((first.y - (lo.y + 0.1 * cell.y)).abs() < 1e-5, "{first}");
        assert!((last.y - (hi.y - 0.1 * cell.y)).abs() < 1e-5, "{last}");
        assert_eq!(first.z, 0.0);
        let step = centres[1].x - centres[0].x;
        assert!((centres[2].x - centres[1].x - step).abs() < 1e-5);
    }
}
