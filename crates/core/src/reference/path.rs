//! One path's radiance, vertex by vertex, as `shaders/shared/path.wgsl` computes it (its twin):
//! camera rays, texture lookups, next-event estimation with MIS, delta lights, BSDF sampling and
//! Russian roulette, drawing the same random numbers in the same order.

use glam::{Vec2, Vec3};

use super::bvh::{MISS, occluded, trace};
use crate::gpu_scene::GpuScene;
use crate::gpu_types::{Frame, NO_TEXTURE, material_kind};
use crate::math::intersect::offset_ray_origin;
use crate::math::rng::{self, Rng};
use crate::math::sampling::*;

/// The power heuristic (β = 2) weight of the strategy with density `a` against one with density `b`.
pub fn power_heuristic(a: f32, b: f32) -> f32 {
    let (a2, b2) = (a * a, b * b);
    if a2 + b2 > 0.0 { a2 / (a2 + b2) } else { 0.0 }
}

/// Next-event estimation at diffuse point `p`: L_e cosθ/π · w_light / p_light for one sampled
/// emitter point (the albedo and β are applied by the caller). Always draws four random numbers.
pub fn direct_light(
    scene: &GpuScene,
    frame: &Frame,
    p: Vec3,
    ng: Vec3,
    ns: Vec3,
    rng: &mut Rng,
) -> Vec3 {
    let u_pick = rng.next_f32();
    let u_alias = rng.next_f32();
    let u_a = rng.next_f32();
    let u_b = rng.next_f32();
    let n = frame.emitter_count as usize;
    let chosen = crate::emitters::pick_emitter(&scene.emitters[..n], u_pick, u_alias);
    let tri = &scene.triangles[chosen as usize];
    let (v0, v1, v2) = (Vec3::from(tri.v0), Vec3::from(tri.v1), Vec3::from(tri.v2));
    let [b0, b1, b2] = sample_triangle(u_a, u_b);
    let y = v0 * b0 + v1 * b1 + v2 * b2;
    let nl = (v1 - v0).cross(v2 - v0).normalize();
    if (y - p).dot(nl) >= 0.0 {
        return Vec3::ZERO; // p is behind the emitter's front face
    }
    let origin = offset_ray_origin(p, ng, frame.offset_scale);
    let to = offset_ray_origin(y, nl, frame.offset_scale) - origin;
    let distance = to.length();
    let dir = to / distance;
    let (cos_x, cos_l) = (dir.dot(ns), -dir.dot(nl));
    if !(cos_x > 0.0 && dir.dot(ng) > 0.0 && cos_l > 0.0) || occluded(scene, origin, dir, distance)
    {
        return Vec3::ZERO;
    }
    let le = Vec3::from(scene.materials[tri.material as usize].emission);
    let p_light = luminance(le) * frame.emitter_power_inv * distance * distance / cos_l;
    let p_bsdf = cos_x * std::f32::consts::FRAC_1_PI;
    let w_light = if frame.light_strategy == 1 {
        1.0
    } else {
        power_heuristic(p_light, p_bsdf)
    };
    le * (p_bsdf * w_light / p_light)
}

/// Point, spot and directional lights at diffuse point `p`: Σ E cosθ/π over the unoccluded lights
/// (albedo and β applied by the caller), E = I/d² (times the spot falloff) or the sun's E.
pub fn delta_lights_at(scene: &GpuScene, frame: &Frame, p: Vec3, ng: Vec3, ns: Vec3) -> Vec3 {
    use crate::gpu_types::light_kind;
    let origin = offset_ray_origin(p, ng, frame.offset_scale);
    let mut sum = Vec3::ZERO;
    for light in &scene.delta_lights {
        if light.kind == 0 {
            continue;
        }
        let (dir, distance, irradiance) = if light.kind == light_kind::DIRECTIONAL {
            (
                -Vec3::from(light.direction),
                3.0e38,
                Vec3::from(light.power),
            )
        } else {
            let to = Vec3::from(light.position) - origin;
            let d2 = to.length_squared();
            let distance = d2.sqrt();
            let dir = to / distance;
            let mut e = Vec3::from(light.power) / d2;
            if light.kind == light_kind::SPOT {
                e *= crate::light::spot_falloff(
                    (-dir).dot(Vec3::from(light.direction)),
                    light.cos_inner,
                    light.cos_outer,
                );
            }
            (dir, distance, e)
        };
        let cos_x = dir.dot(ns);
        if !(cos_x > 0.0 && dir.dot(ng) > 0.0) || irradiance == Vec3::ZERO {
            continue;
        }
        if occluded(scene, origin, dir, distance) {
            continue;
        }
        sum += irradiance * (cos_x / std::f32::consts::PI);
    }
    sum
}

/// The camera ray through a jittered point of pixel (x, y): box pixel filter, thin lens when
/// `lens_radius > 0`.
pub fn camera_ray(frame: &Frame, x: u32, y: u32, rng: &mut Rng) -> (Vec3, Vec3) {
    let jx = rng.next_f32();
    let jy = rng.next_f32();
    let sx =
        (2.0 * (x as f32 + jx) / frame.width as f32 - 1.0) * frame.tan_half_vfov * frame.aspect;
    let sy = (1.0 - 2.0 * (y as f32 + jy) / frame.height as f32) * frame.tan_half_vfov;
    let (u, v, w) = (
        Vec3::from(frame.cam_u),
        Vec3::from(frame.cam_v),
        Vec3::from(frame.cam_w),
    );
    let origin = Vec3::from(frame.cam_origin);
    let direction = (sx * u + sy * v - w).normalize();
    if frame.lens_radius <= 0.0 {
        return (origin, direction);
    }
    let focus = origin + direction * (frame.focus_distance / direction.dot(-w));
    let (dx, dy) = sample_disk(rng);
    let lens_origin = origin + frame.lens_radius * (dx * u + dy * v);
    (lens_origin, (focus - lens_origin).normalize())
}

fn texel(scene: &GpuScene, offset: u32, w: u32, h: u32, x: i32, y: i32) -> Vec3 {
    let xi = x.rem_euclid(w as i32) as u32;
    let yi = y.rem_euclid(h as i32) as u32;
    let p = scene.texels[(offset + yi * w + xi) as usize].to_le_bytes();
    Vec3::new(
        srgb_to_linear(p[0] as f32 / 255.0),
        srgb_to_linear(p[1] as f32 / 255.0),
        srgb_to_linear(p[2] as f32 / 255.0),
    )
}

/// Bilinear, repeating texture lookup; `uv.y` = 0 is the bottom row of the image (OBJ convention).
pub fn sample_texture(scene: &GpuScene, offset: u32, w: u32, h: u32, uv: Vec2) -> Vec3 {
    let x = uv.x * w as f32 - 0.5;
    let y = (1.0 - uv.y) * h as f32 - 0.5;
    let (x0, y0) = (x.floor(), y.floor());
    let (fx, fy) = (x - x0, y - y0);
    let (xi, yi) = (x0 as i32, y0 as i32);
    let top = texel(scene, offset, w, h, xi, yi).lerp(texel(scene, offset, w, h, xi + 1, yi), fx);
    let bottom =
        texel(scene, offset, w, h, xi, yi + 1).lerp(texel(scene, offset, w, h, xi + 1, yi + 1), fx);
    top.lerp(bottom, fy)
}

/// One path's radiance estimate for pixel (x, y), sample `sample`.
pub fn radiance(scene: &GpuScene, frame: &Frame, x: u32, y: u32, sample: u32) -> Vec3 {
    let kind = if frame.sampler == 1 {
        rng::SamplerKind::Sobol
    } else {
        rng::SamplerKind::Independent
    };
    let mut rng = Rng::with_sampler(y * frame.width + x, sample, frame.seed, kind);
    let (mut origin, mut direction) = camera_ray(frame, x, y, &mut rng);
    let mut beta = Vec3::ONE;
    let mut radiance = Vec3::ZERO;
    // Density of the BSDF sample that led here, 0 after the camera or a specular bounce.
    let mut prev_bsdf_pdf = 0.0f32;
    for depth in 0..frame.max_depth {
        let hit = trace(scene, origin, direction, f32::MAX);
        if hit.triangle == MISS {
            radiance += beta * Vec3::from(frame.ambient);
            break;
        }
        let tri = &scene.triangles[hit.triangle as usize];
        let material = &scene.materials[tri.material as usize];
        let (v0, v1, v2) = (Vec3::from(tri.v0), Vec3::from(tri.v1), Vec3::from(tri.v2));
        let ng_raw = (v1 - v0).cross(v2 - v0);
        let front = direction.dot(ng_raw) < 0.0;
        if front {
            let le = Vec3::from(material.emission);
            let mut weight = 1.0;
            if frame.emitter_count > 0 && prev_bsdf_pdf > 0.0 && le != Vec3::ZERO {
                let cos_l = -direction.dot(ng_raw.normalize());
                let p_light = luminance(le) * frame.emitter_power_inv * hit.t * hit.t / cos_l;
                weight = if frame.light_strategy == 1 {
                    0.0
                } else {
                    power_heuristic(prev_bsdf_pdf, p_light)
                };
            }
            radiance += beta * le * weight;
        }
        if material.kind == material_kind::EMISSIVE || depth + 1 >= frame.max_depth {
            break;
        }
        let b0 = 1.0 - hit.b1 - hit.b2;
        let p = v0 * b0 + v1 * hit.b1 + v2 * hit.b2;
        let ng = if front {
            ng_raw.normalize()
        } else {
            -ng_raw.normalize()
        };
        let mut ns = ng;
        if tri.has_normals != 0 {
            let shading = &scene.shading[hit.triangle as usize];
            let n = Vec3::from(shading.n0) * b0
                + Vec3::from(shading.n1) * hit.b1
                + Vec3::from(shading.n2) * hit.b2;
            let n = n.normalize();
            ns = if n.dot(ng) < 0.0 { -n } else { n };
        }
        let albedo = if material.texture_offset != NO_TEXTURE && tri.has_uvs != 0 {
            let shading = &scene.shading[hit.triangle as usize];
            let uv = Vec2::from(shading.uv0) * b0
                + Vec2::from(shading.uv1) * hit.b1
                + Vec2::from(shading.uv2) * hit.b2;
            sample_texture(
                scene,
                material.texture_offset,
                material.texture_width,
                material.texture_height,
                uv,
            )
        } else {
            Vec3::from(material.albedo)
        };
        prev_bsdf_pdf = 0.0;
        let next = match material.kind {
            material_kind::METAL => {
                beta *= albedo;
                sample_metal(direction, ns, material.param, &mut rng)
            }
            material_kind::DIELECTRIC => {
                let eta = if front {
                    material.param
                } else {
                    1.0 / material.param
                };
                let (d, refracted) = sample_dielectric(direction, ns, eta, &mut rng);
                if refracted {
                    beta *= albedo / (eta * eta);
                }
                d
            }
            _ => {
                if frame.emitter_count > 0 {
                    radiance += beta * albedo * direct_light(scene, frame, p, ng, ns, &mut rng);
                }
                radiance += beta * albedo * delta_lights_at(scene, frame, p, ng, ns);
                beta *= albedo;
                let d = sample_cosine_hemisphere(ns, &mut rng);
                prev_bsdf_pdf = d.dot(ns).max(0.0) * std::f32::consts::FRAC_1_PI;
                d
            }
        };
        let side = next.dot(ng);
        if side == 0.0 || !next.is_finite() {
            break;
        }
        // Transmission continues below the surface, reflection above it.
        let transmitted = side < 0.0;
        if transmitted && material.kind != material_kind::DIELECTRIC {
            break;
        }
        if frame.roulette_from_depth > 0 && depth >= frame.roulette_from_depth {
            let survive = beta.max_element().min(1.0);
            if rng.next_f32() >= survive {
                break;
            }
            beta /= survive;
        }
        origin = offset_ray_origin(p, if transmitted { -ng } else { ng }, frame.offset_scale);
        direction = next;
    }
    radiance
}
