//! The lights, as `light.wgsl` beside it (its twin) computes them: what next-event estimation
//! samples and what a path that misses everything sees. Each kind of light is one place here:
//!
//! - **area lights** (emissive triangles): `sample_light` picks one by power through the alias
//!   table (`crate::emitters`) or by its importance at the vertex through the light tree
//!   (`super::light_tree`), then a uniform point on it: p_light = p_pick / A · |x − y|² / cosθ_y
//!   per solid angle; a BSDF-sampled ray that hits one is weighed against that pdf
//!   (`emitter_pdf`) in `shade_vertex`;
//! - **the environment** (`crate::environment`): `sample_light` draws a direction from its map
//!   with probability `frame.env_pick`; `escaped` is what a ray leaving the scene sees, weighed
//!   against that sampling (or the ambient colour without a map);
//! - **delta lights** (point, spot, sun; `crate::light` has their units): `delta_light_incidence`
//!   is where one lies from a point and the irradiance it gives there, one case per type;
//!   `delta_lights_at` sums them at a vertex (deterministic, no MIS: no BSDF ray can hit them),
//!   except, where the light tree samples, the points and spots: they are its leaves, and
//!   `sample_light` picks one as it picks an emitter, E f cosθ / p_pick with no MIS weight.
//!
//! `direct_light` is next-event estimation with the power heuristic (β = 2):
//!   L_direct = f(ωi) cosθ L_e · w_light / p_light,  w_light = p_light² / (p_light² + p_bsdf²).

/// The WGSL twin of this module, `light.wgsl` beside it (composed into the kernels by
/// `rt_gpu::shaders`).
pub const WGSL: &str = include_str!("light.wgsl");

use glam::Vec3;

use super::light_tree::{leaf_of, sample_tree, tree_normal_at, tree_pmf, unpack_normal};
use super::occluded;
use super::surface::Surface;
use super::texture::{coverage, surface_emission};
use crate::gpu_scene::GpuScene;
use crate::gpu_types::{ALPHA_BLEND, ALPHA_MASK, DeltaLight, Frame};
use crate::light_kind::LightTag;
use crate::light_tree::{DELTA_LEAF, in_tree};
use crate::math::intersect::offset_ray_origin;
use crate::math::medium::transmittance;
use crate::math::rng::Rng;
use crate::math::sampling::*;

/// Whether light arriving along `dir` reaches a vertex with geometric normal `ng` from its side:
/// above the surface, or from anywhere at a scattering in a medium (`ng` = 0, no surface).
pub fn reaches(dir: Vec3, ng: Vec3) -> bool {
    dir.dot(ng) > 0.0 || ng == Vec3::ZERO
}

/// The media a vertex's shadow rays cross (`math::medium`), by their extinction: `above` on the
/// side of the geometric normal, `below` beyond the surface (where lights shine through it); both
/// the same at a scattering in a medium. Vacuum: zero.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct ShadowMedia {
    pub above: Vec3,
    pub below: Vec3,
}

impl ShadowMedia {
    /// The transmittance of a shadow ray along `dir` over `distance`, from a vertex with normal `ng`.
    pub fn transmittance(&self, dir: Vec3, ng: Vec3, distance: f32) -> Vec3 {
        let sigma = if dir.dot(ng) < 0.0 {
            self.below
        } else {
            self.above
        };
        // Vacuum, the common case, without three exponentials.
        if sigma == Vec3::ZERO {
            return Vec3::ONE;
        }
        transmittance(sigma, distance)
    }
}

/// The power heuristic (β = 2) weight of the strategy with density `a` against one with density `b`.
pub fn power_heuristic(a: f32, b: f32) -> f32 {
    let (a2, b2) = (a * a, b * b);
    if a2 + b2 > 0.0 { a2 / (a2 + b2) } else { 0.0 }
}

/// A light sample for next-event estimation: the direction and distance to trace and L_e / p_light
/// (a point or spot light: its irradiance over the probability of picking it, and `p_light` 0).
pub struct LightSample {
    pub origin: Vec3,
    pub direction: Vec3,
    pub distance: f32,
    pub radiance_over_pdf: Vec3,
    /// The density per solid angle, or 0 for a point or spot light (a delta: no BSDF sample finds
    /// it, so its MIS weight is 1).
    pub p_light: f32,
}

/// One light sample from point `p` of a surface with geometric normal `ng`: the environment with
/// probability `frame.env_pick`, else an emitter point (an emitter by power or through the light
/// tree, then a uniform point on it) or, through the tree, a point or spot light, which also
/// reaches a surface it lights through (`lit_through`) from its other side. `None` when the
/// sample cannot reach the surface. Always draws four random numbers.
pub fn sample_light(
    scene: &GpuScene,
    frame: &Frame,
    p: Vec3,
    ng: Vec3,
    lit_through: bool,
    rng: &mut Rng,
) -> Option<LightSample> {
    let u_pick = rng.next_f32();
    let u_alias = rng.next_f32();
    let u_a = rng.next_f32();
    let u_b = rng.next_f32();
    let origin = offset_ray_origin(p, ng, frame.offset_scale);
    if u_pick < frame.env_pick {
        let (dir, le, pdf) = crate::environment::sample_env(
            &scene.env_texels,
            frame.env_width,
            frame.env_height,
            frame.env_rotation,
            [u_pick / frame.env_pick, u_alias, u_a, u_b],
        );
        let p_light = frame.env_pick * pdf;
        if !(p_light > 0.0 && reaches(dir, ng)) {
            return None;
        }
        return Some(LightSample {
            origin,
            direction: dir,
            distance: 3.0e38,
            radiance_over_pdf: le / p_light,
            p_light,
        });
    }
    let u_pick = (u_pick - frame.env_pick) / (1.0 - frame.env_pick);
    let n = frame.emitter_count as usize;
    // The emitter, and the tree's pmf for it (the power table's needs none: per unit area it is
    // the emission's luminance over the total power).
    let (chosen, tree_pmf) = if frame.light_sampler == 1 {
        let normal = unpack_normal(tree_normal_at(ng, lit_through));
        sample_tree(&scene.light_tree, origin, normal, u_pick)?
    } else {
        let chosen = crate::emitters::pick_emitter(&scene.emitters[..n], u_pick, u_alias);
        (chosen, 0.0)
    };
    if chosen & DELTA_LEAF != 0 {
        let light = &scene.delta_lights[(chosen & !DELTA_LEAF) as usize];
        let (origin, direction, distance, irradiance) =
            delta_light_toward(light, p, ng, origin, lit_through, frame.offset_scale)?;
        let pick = (1.0 - frame.env_pick) * tree_pmf;
        return Some(LightSample {
            origin,
            direction,
            distance,
            radiance_over_pdf: irradiance / pick,
            p_light: 0.0,
        });
    }
    let tri = &scene.triangles[chosen as usize];
    let (v0, v1, v2) = (Vec3::from(tri.v0), Vec3::from(tri.v1), Vec3::from(tri.v2));
    let [b0, b1, b2] = sample_triangle(u_a, u_b);
    let y = v0 * b0 + v1 * b1 + v2 * b2;
    let cross = (v1 - v0).cross(v2 - v0);
    let nl = cross.normalize();
    if (y - p).dot(nl) >= 0.0 {
        return None; // p is behind the emitter's front face
    }
    let to = offset_ray_origin(y, nl, frame.offset_scale) - origin;
    let distance = to.length();
    let dir = to / distance;
    let cos_l = -dir.dot(nl);
    if !(reaches(dir, ng) && cos_l > 0.0) {
        return None;
    }
    // Picked by the emission factor; the point's radiance is the factor times the emission image,
    // and times the coverage on a surface with holes.
    let material = &scene.materials[tri.material as usize];
    let pick_per_area = if frame.light_sampler == 1 {
        tree_pmf / (0.5 * cross.length())
    } else {
        luminance(Vec3::from(material.emission)) * frame.emitter_power_inv
    };
    let p_light = (1.0 - frame.env_pick) * pick_per_area * distance * distance / cos_l;
    let mut le = surface_emission(scene, material, tri, chosen, (b1, b2), cos_l);
    if material.flags & (ALPHA_MASK | ALPHA_BLEND) != 0 {
        le *= coverage(scene, material, tri, chosen, b1, b2);
    }
    Some(LightSample {
        origin,
        direction: dir,
        distance,
        radiance_over_pdf: le / p_light,
        p_light,
    })
}

/// The density, per solid angle, with which `sample_light` at a vertex (its shadow rays'
/// origin `origin`, its tree normal packed as `tree_normal`) picks the point at `distance` on
/// emitter triangle `triangle`, seen at cosθ_y = `cos_l`: the pdf that MIS weighs an emitter
/// found by a BSDF-sampled ray with. The tree's pmf is recomputed from the emitter's leaf.
pub fn emitter_pdf(
    scene: &GpuScene,
    frame: &Frame,
    triangle: u32,
    origin: Vec3,
    tree_normal: u32,
    distance: f32,
    cos_l: f32,
) -> f32 {
    let tri = &scene.triangles[triangle as usize];
    let pick_per_area = if frame.light_sampler == 1 {
        let emitters = &scene.emitters[..frame.emitter_count as usize];
        let leaf = leaf_of(emitters, triangle);
        let (v0, v1, v2) = (Vec3::from(tri.v0), Vec3::from(tri.v1), Vec3::from(tri.v2));
        let area = 0.5 * (v1 - v0).cross(v2 - v0).length();
        tree_pmf(&scene.light_tree, leaf, origin, unpack_normal(tree_normal)) / area
    } else {
        let material = &scene.materials[tri.material as usize];
        luminance(Vec3::from(material.emission)) * frame.emitter_power_inv
    };
    (1.0 - frame.env_pick) * pick_per_area * distance * distance / cos_l
}

/// Next-event estimation at `p`: f cosθ L_e · w_light / p_light · T for one light sample, T the
/// transmittance of the media the shadow ray crosses, or zero if it is occluded (β is applied by
/// the caller). Always draws four random numbers; adds the shadow ray it traces (if any) to `rays`.
#[allow(clippy::too_many_arguments)]
pub fn direct_light(
    scene: &GpuScene,
    frame: &Frame,
    p: Vec3,
    ng: Vec3,
    surface: &Surface,
    media: &ShadowMedia,
    rng: &mut Rng,
    rays: &mut u32,
) -> Vec3 {
    let Some(light) = sample_light(scene, frame, p, ng, surface.lit_through(), rng) else {
        return Vec3::ZERO;
    };
    let (f_cos, p_bsdf) = surface.eval(light.direction);
    if f_cos == Vec3::ZERO {
        return Vec3::ZERO;
    }
    let tr = media.transmittance(light.direction, ng, light.distance);
    if tr == Vec3::ZERO {
        return Vec3::ZERO;
    }
    *rays += 1;
    if occluded(scene, light.origin, light.direction, light.distance) {
        return Vec3::ZERO;
    }
    let w_light = if frame.nee_only == 1 || light.p_light == 0.0 {
        1.0
    } else {
        power_heuristic(light.p_light, p_bsdf)
    };
    f_cos * light.radiance_over_pdf * w_light * tr
}

/// Where a point, spot or sun light lies from `origin` (unit direction, distance) and the
/// irradiance it gives there, normal to that direction (before the surface's cosine): each light
/// type is one case here (`crate::light` has the units and the spots' falloffs).
pub fn delta_light_incidence(light: &DeltaLight, origin: Vec3) -> (Vec3, f32, Vec3) {
    if light.kind == LightTag::Directional.tag() {
        return (
            -Vec3::from(light.direction),
            3.0e38,
            Vec3::from(light.power),
        );
    }
    let to = Vec3::from(light.position) - origin;
    let d2 = to.length_squared();
    let distance = d2.sqrt();
    let dir = to / distance;
    let mut e = Vec3::from(light.power) / d2;
    let cos = (-dir).dot(Vec3::from(light.direction));
    if light.kind == LightTag::Spot.tag() {
        e *= crate::light::spot_falloff(cos, light.cos_inner, light.cos_outer);
    } else if light.kind == LightTag::SpotGltf.tag() {
        e *= crate::light::spot_falloff_gltf(cos, light.cos_inner, light.cos_outer);
    }
    (dir, distance, e)
}

/// Where point, spot or sun light `light` reaches the surface at `p` (geometric normal `ng`, shadow
/// rays leaving from `above`) from: the shadow ray's origin, direction and distance, and the
/// irradiance there. A surface it lights through (`lit_through`: rough or diffuse transmission)
/// also takes it from beyond, the shadow ray leaving from its other side: no BSDF sample can find
/// a delta light, so without this a sun behind rough glass would send nothing through it. `None`
/// where it lights neither side or gives nothing.
fn delta_light_toward(
    light: &DeltaLight,
    p: Vec3,
    ng: Vec3,
    above: Vec3,
    lit_through: bool,
    offset_scale: f32,
) -> Option<(Vec3, Vec3, f32, Vec3)> {
    // NaN (a light at the point itself) faces neither side.
    let faces = |dir: Vec3, side: std::cmp::Ordering| dir.dot(ng).partial_cmp(&0.0) == Some(side);
    let (dir, distance, irradiance) = delta_light_incidence(light, above);
    let in_medium = ng == Vec3::ZERO && distance > 0.0;
    let (origin, dir, distance, irradiance) =
        if in_medium || faces(dir, std::cmp::Ordering::Greater) {
            (above, dir, distance, irradiance)
        } else {
            if !lit_through {
                return None;
            }
            let below = offset_ray_origin(p, -ng, offset_scale);
            let (dir, distance, irradiance) = delta_light_incidence(light, below);
            if !faces(dir, std::cmp::Ordering::Less) {
                return None;
            }
            (below, dir, distance, irradiance)
        };
    (irradiance != Vec3::ZERO).then_some((origin, dir, distance, irradiance))
}

/// Point, spot and directional lights at `p`: Σ E f cosθ T over the unoccluded lights (β applied
/// by the caller), E = I/d² (times the spot falloff) or the sun's E, each from the side it reaches
/// (`delta_light_toward`), T the transmittance of the media its shadow ray crosses. Where the light
/// tree samples, it holds the points and spots, and this sums the suns alone. Adds the shadow rays
/// it traces to `rays`.
pub fn delta_lights_at(
    scene: &GpuScene,
    frame: &Frame,
    p: Vec3,
    ng: Vec3,
    surface: &Surface,
    media: &ShadowMedia,
    rays: &mut u32,
) -> Vec3 {
    let above = offset_ray_origin(p, ng, frame.offset_scale);
    let lit_through = surface.lit_through();
    let mut sum = Vec3::ZERO;
    for light in &scene.delta_lights {
        if light.kind == LightTag::None.tag() || (frame.light_sampler == 1 && in_tree(light)) {
            continue;
        }
        let Some((origin, dir, distance, irradiance)) =
            delta_light_toward(light, p, ng, above, lit_through, frame.offset_scale)
        else {
            continue;
        };
        let (f_cos, _) = surface.eval(dir);
        if f_cos == Vec3::ZERO {
            continue;
        }
        let tr = media.transmittance(dir, ng, distance);
        if tr == Vec3::ZERO {
            continue;
        }
        *rays += 1;
        if occluded(scene, origin, dir, distance) {
            continue;
        }
        sum += irradiance * f_cos * tr;
    }
    sum
}

/// The radiance a ray leaving the scene along `direction` finds, MIS-weighted against the
/// environment's next-event estimation when the last vertex sampled its BSDF with `prev_bsdf_pdf`.
pub fn escaped(scene: &GpuScene, frame: &Frame, direction: Vec3, prev_bsdf_pdf: f32) -> Vec3 {
    if frame.env_width == 0 {
        return Vec3::from(frame.ambient);
    }
    let (le, pdf) = crate::environment::env_lookup(
        &scene.env_texels,
        frame.env_width,
        frame.env_height,
        frame.env_rotation,
        direction,
    );
    let mut weight = 1.0;
    if frame.env_pick > 0.0 && prev_bsdf_pdf > 0.0 {
        weight = if frame.nee_only == 1 {
            0.0
        } else {
            power_heuristic(prev_bsdf_pdf, frame.env_pick * pdf)
        };
    }
    le * weight
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scene::{LightSampler, Object, Scene};

    /// The solid angle a triangle subtends from `x` (Van Oosterom and Strackee 1983).
    fn solid_angle(x: Vec3, v: [Vec3; 3]) -> f64 {
        let [a, b, c] = v.map(|p| (p - x).as_dvec3());
        let (la, lb, lc) = (a.length(), b.length(), c.length());
        let numerator = a.dot(b.cross(c)).abs();
        let denominator = la * lb * lc + a.dot(b) * lc + a.dot(c) * lb + b.dot(c) * la;
        2.0 * numerator.atan2(denominator)
    }

    /// A square emissive lamp (grey radiance `strength`) of side `size` at `centre`, facing
    /// `normal`.
    fn lamp(i: usize, centre: Vec3, normal: Vec3, size: f32, strength: f32) -> Object {
        Object {
            shadow_catcher: false,
            animation_node: None,
            name: format!("lamp {i}"),
            mesh: crate::shapes::quad(centre, normal, size).into(),
            material: crate::Material::Emissive {
                color: [strength; 3],
                intensity: 1.0,
            },
            transform: Default::default(),
        }
    }

    /// Chi-square of `sample_light`'s directions against the distribution its pdf describes,
    /// through the power table and through the light tree: lamps above a point, the hemisphere cut
    /// into 10 × 20 bins of equal solid angle (cos θ, φ). A bin's expected count is each lamp
    /// triangle's pick probability (from `emitter_pdf` at its centroid: p · cos θ_y / d² · area)
    /// spread over its area (a 256 × 256 grid of equal-area points, each counted in the bin of its
    /// direction where the triangle faces the point); integrating in area, not solid angle, keeps
    /// lamps seen edge-on exact. Bins expecting under 5 are pooled.
    #[test]
    fn light_sample_directions_follow_their_pdf() {
        use crate::estimator::light_tree::pack_normal;
        let mut rng = Rng::new(4, 2, 0x5c);
        let mut scene = Scene::default();
        for i in 0..8 {
            let mut u = || rng.next_f32();
            let centre = Vec3::new(u() * 3.0 - 1.5, u() * 3.0 - 1.5, 1.0 + 1.5 * u());
            let normal =
                (Vec3::new(u(), u(), u()) * 2.0 - 1.0 - Vec3::new(0.0, 0.0, 0.6)).normalize();
            let strength = 10f32.powf(1.5 * u());
            scene
                .objects
                .push(lamp(i, centre, normal, 0.6 + 0.8 * u(), strength));
        }
        let (x, n) = (Vec3::ZERO, Vec3::Z);
        let (rows, columns, grid) = (10usize, 20usize, 256usize);
        let bin_of = |d: Vec3| {
            let row = ((d.z * rows as f32) as usize).min(rows - 1);
            let phi = d.y.atan2(d.x).rem_euclid(std::f32::consts::TAU);
            let column = ((phi / std::f32::consts::TAU * columns as f32) as usize).min(columns - 1);
            row * columns + column
        };
        for sampler in [LightSampler::Power, LightSampler::Tree] {
            scene.settings.light_sampler = sampler;
            let gpu = GpuScene::build(&scene).unwrap();
            let frame = crate::frame::frame_for(&scene, &gpu).unwrap();
            let origin = offset_ray_origin(x, n, frame.offset_scale);
            let samples = 200_000u32;
            let mut expected = vec![0.0f64; rows * columns];
            for e in &gpu.emitters {
                let t = &gpu.triangles[e.triangle as usize];
                let v = [t.v0, t.v1, t.v2].map(Vec3::from);
                let cross = (v[1] - v[0]).cross(v[2] - v[0]);
                let (nl, area) = (cross.normalize(), 0.5 * cross.length());
                let to = (v[0] + v[1] + v[2]) / 3.0 - origin;
                let (d, cos) = (to.length(), -to.normalize().dot(nl));
                if cos <= 0.0 {
                    continue;
                }
                let p = emitter_pdf(&gpu, &frame, e.triangle, origin, pack_normal(n), d, cos);
                let pick = f64::from(p * cos / (d * d) * area);
                let share = pick / (grid * grid) as f64 * f64::from(samples);
                for a in 0..grid {
                    for b in 0..grid {
                        let (u_a, u_b) = (
                            (a as f32 + 0.5) / grid as f32,
                            (b as f32 + 0.5) / grid as f32,
                        );
                        let [b0, b1, b2] = sample_triangle(u_a, u_b);
                        let dir = (v[0] * b0 + v[1] * b1 + v[2] * b2 - origin).normalize();
                        if dir.dot(nl) < 0.0 && dir.z > 0.0 {
                            expected[bin_of(dir)] += share;
                        }
                    }
                }
            }
            let mut counts = vec![0u32; rows * columns];
            for i in 0..samples {
                let mut rng = Rng::new(i, 1, 0x91);
                if let Some(s) = sample_light(&gpu, &frame, x, n, false, &mut rng) {
                    counts[bin_of(s.direction)] += 1;
                }
            }
            let counts: Vec<f64> = counts.into_iter().map(f64::from).collect();
            let (chi2, dof) = crate::math::stats::pearson(&counts, &expected);
            let limit = crate::math::stats::chi2_limit(dof, 2, 1e-3);
            assert!(
                dof > 30 && chi2 < limit,
                "{sampler:?}: chi-square {chi2:.1} with {dof} degrees of freedom (limit {limit:.1})"
            );
        }
    }

    /// `sample_light`'s p_light is the density of its directions per solid angle, through the
    /// power table and through the light tree: over lamps above a point, facing every way, the
    /// mean of 1/p_light over its samples (zero where none comes back) is the solid angle of the
    /// lamps that face the point (Z-test with the samples' own variance, 4 standard errors).
    #[test]
    fn light_samples_have_their_solid_angle_density() {
        let mut rng = Rng::new(1, 2, 0x5a);
        let mut scene = Scene::default();
        for i in 0..24 {
            let mut u = || rng.next_f32();
            let centre = Vec3::new(u() * 4.0 - 2.0, u() * 4.0 - 2.0, 1.5 + 1.5 * u());
            let normal = (Vec3::new(u(), u(), u()) * 2.0 - 1.0).normalize();
            let strength = 10f32.powf(2.0 * u());
            scene
                .objects
                .push(lamp(i, centre, normal, 0.4 + 0.8 * u(), strength));
        }
        let (x, n) = (Vec3::ZERO, Vec3::Z);
        for sampler in [LightSampler::Power, LightSampler::Tree] {
            scene.settings.light_sampler = sampler;
            let gpu = GpuScene::build(&scene).unwrap();
            let frame = crate::frame::frame_for(&scene, &gpu).unwrap();
            assert_eq!(
                frame.light_sampler,
                u32::from(sampler == LightSampler::Tree)
            );
            let facing: f64 = gpu
                .emitters
                .iter()
                .map(|e| {
                    let t = &gpu.triangles[e.triangle as usize];
                    let v = [t.v0, t.v1, t.v2].map(Vec3::from);
                    let normal = (v[1] - v[0]).cross(v[2] - v[0]);
                    if (x - v[0]).dot(normal) > 0.0 {
                        solid_angle(x, v)
                    } else {
                        0.0
                    }
                })
                .sum();
            let samples = 200_000;
            let (mut sum, mut sum2) = (0.0f64, 0.0f64);
            for i in 0..samples {
                let mut rng = Rng::new(i, 0, 0x77);
                if let Some(s) = sample_light(&gpu, &frame, x, n, false, &mut rng) {
                    let w = 1.0 / f64::from(s.p_light);
                    sum += w;
                    sum2 += w * w;
                }
            }
            let mean = sum / f64::from(samples);
            let error = ((sum2 / f64::from(samples) - mean * mean) / f64::from(samples)).sqrt();
            assert!(
                (mean - facing).abs() < 4.0 * error,
                "{sampler:?}: E[1/p] = {mean} ± {error}, solid angle {facing}"
            );
            assert!(
                error < 0.05 * facing,
                "{sampler:?}: too noisy to tell: ± {error} of {facing}"
            );
        }
    }
}
