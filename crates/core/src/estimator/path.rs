//! One path's radiance, vertex by vertex, as `path.wgsl` beside it computes it (its twin):
//! starting from a camera ray (`camera.rs`), texture lookups, the light at each vertex (`light.rs`), BSDF sampling
//! (`surface.rs`) and Russian roulette, drawing the same random numbers in the same order.

/// The WGSL twin of this module, `path.wgsl` beside it (composed into the kernels by
/// `rt_gpu::shaders`).
pub const WGSL: &str = include_str!("path.wgsl");

use glam::{Vec2, Vec3};

mod hit_shading;
pub(crate) use hit_shading::{Shading, shading_at};

use super::camera::{camera_ray, film_pixel};
use super::hit::MISS;
use super::light::{
    ShadowMedia, delta_lights_at, direct_light, emitter_pdf, escaped, power_heuristic,
};
use super::light_tree::tree_normal_at;
use super::media::{media_enter, media_leave, media_top, medium_of};
use super::shading::{anisotropy_tangent, normal_mapped, vertex_color};
use super::shadow_catcher::{catcher_irradiance, catches_shadows};
use super::surface::{PbrInputs, Surface};
use super::texture::{Slot, base_color_texture, surface_emission, textured_pbr_inputs};
use super::trace;
use crate::gpu_scene::GpuScene;
use crate::gpu_types::{
    Frame, Hit, Medium, PbrLobe, SLOT_BASE, SLOT_CLEARCOAT_NORMAL, SLOT_NORMAL, THIN_WALLED,
};
use crate::material_kind::MaterialKind;
use crate::math::dispersion::{channel_ior, pick_channel};
use crate::math::intersect::offset_ray_origin;
use crate::math::medium::{FAR, free_flight, is_vacuum, scattering_albedo};
use crate::math::rng::{self, Rng};

/// The firefly clamp (`frame.clamp_max`, 0 off): light reaching the camera after `bounces`
/// scatterings, if any, is scaled down so that its largest channel is at most the clamp; light
/// seen directly (no bounce) stays exact. Biased: it removes energy.
fn clamp_bounced(c: Vec3, frame: &Frame, bounces: u32) -> Vec3 {
    let peak = c.x.max(c.y.max(c.z));
    if bounces > 0 && frame.clamp_max > 0.0 && peak > frame.clamp_max {
        c * (frame.clamp_max / peak)
    } else {
        c
    }
}

/// One path's radiance estimate for pixel (x, y), sample `sample`.
pub fn radiance(scene: &GpuScene, frame: &Frame, x: u32, y: u32, sample: u32) -> Vec3 {
    trace_path(scene, frame, x, y, sample, false).radiance
}

/// Pixel (x, y)'s path of sample `sample`, traced to its end: its radiance in `radiance` and,
/// with `guides` (the WGSL's `WRITE_AOVS`), what it hit first in `first_hit`.
pub fn trace_path(
    scene: &GpuScene,
    frame: &Frame,
    x: u32,
    y: u32,
    sample: u32,
    guides: bool,
) -> PathState {
    let mut path = start_path(frame, x, y, sample);
    path.first_hit = guides.then(FirstHit::default);
    while path.depth < frame.max_depth {
        let hit = trace(scene, path.origin, path.direction, f32::MAX);
        path.rays += 1;
        if !shade_vertex(scene, frame, &mut path, hit) {
            break;
        }
    }
    path
}

/// A path between two vertices: what `shade_vertex` reads and updates (the WGSL `PathState`,
/// with the path's random numbers).
#[derive(Clone, Copy, Debug)]
pub struct PathState {
    pub origin: Vec3,
    pub direction: Vec3,
    /// The throughput: the product of f·cosθ/p over the vertices so far.
    pub beta: Vec3,
    /// The hero channel a dispersive surface chose (`math::dispersion`): 0 none yet, 1–3 red,
    /// green, blue; the path then carries that channel alone.
    pub channel: u32,
    pub radiance: Vec3,
    /// Density of the BSDF sample that led here, for the MIS weight of the light it finds: 0
    /// after the camera, a specular bounce or a transmission (`Surface::sample`: next-event
    /// estimation takes only lights above the surface).
    pub prev_bsdf_pdf: f32,
    /// The last vertex's normal as the light tree weighs lights with it
    /// (`light_tree::tree_normal_at`).
    pub tree_normal: u32,
    /// The media the path is in (`media_top`, `media_enter`, `media_leave`).
    pub media: u32,
    /// The product of η² over the interfaces the path refracted through: refraction scales
    /// radiance by 1/η², which moves radiance without losing energy, so Russian roulette judges
    /// β · `eta_scale` (a path inside glass is not dimmer than it carries).
    pub eta_scale: f32,
    /// Segments traced so far (0: the camera ray).
    pub depth: u32,
    /// Whether the path has met only shadow catchers since the camera (`super::shadow_catcher`):
    /// it then adds no light until it meets another object.
    pub matte: bool,
    pub rng: Rng,
    /// The denoiser's guides of this sample, set at the first vertex when recorded (`Some`; the
    /// WGSL `aov_*` under `WRITE_AOVS`): the first hit's albedo and normal (facing the camera),
    /// and the light seen directly there. Zero where the camera ray escapes (the sky it sees is
    /// the emission).
    pub first_hit: Option<FirstHit>,
    /// Rays traced so far, extension and shadow rays (the kernels' `COUNT_RAYS` tally).
    pub rays: u32,
}

/// What the camera ray finds first, for the denoiser's guides.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct FirstHit {
    pub albedo: Vec3,
    pub normal: Vec3,
    pub emission: Vec3,
    /// 1 when the camera ray met a surface (or scattered in a medium), else 0: alpha's sample.
    pub coverage: f32,
    /// The distance along the camera ray to what it met (0 when it met nothing).
    pub depth: f32,
    /// The object it met, plus one (0: none): `Object` index in the scene.
    pub object: u32,
    /// Where it met a shadow catcher: 1, and the irradiance there with and without shadows
    /// (`shadow_catcher::catcher_irradiance`); zeros elsewhere.
    pub caught: [f32; 3],
}

/// The camera ray of pixel (x, y), sample `sample` (the WGSL `start_path`).
pub fn start_path(frame: &Frame, x: u32, y: u32, sample: u32) -> PathState {
    let kind = if frame.sampler == 1 {
        rng::SamplerKind::Sobol
    } else {
        rng::SamplerKind::Independent
    };
    let mut rng = Rng::with_sampler(film_pixel(frame, x, y), sample, frame.seed, kind);
    let (origin, direction) = camera_ray(frame, x, y, &mut rng);
    // A pixel that sees nothing (outside a fisheye's circle) is a path that ends at once with
    // zero weight: black, no ray traced (the kernels' wavefront traces one that adds nothing).
    let sees = direction != Vec3::ZERO;
    PathState {
        origin,
        direction: if sees {
            direction
        } else {
            -Vec3::from(frame.cam_w)
        },
        beta: if sees { Vec3::ONE } else { Vec3::ZERO },
        channel: 0,
        radiance: Vec3::ZERO,
        prev_bsdf_pdf: 0.0,
        tree_normal: 0,
        media: frame.camera_media,
        eta_scale: 1.0,
        depth: if sees { 0 } else { frame.max_depth },
        matte: false,
        rng,
        first_hit: None,
        rays: 0,
    }
}

/// One path vertex at `hit` (the WGSL `shade_vertex`): the light reaching the camera from there
/// (emission, or the sky on a miss; next-event estimation and the delta lights at a scattering
/// vertex) added to `path.radiance`, then the next direction sampled, the throughput updated and
/// Russian roulette played. Returns whether the path goes on.
pub fn shade_vertex(scene: &GpuScene, frame: &Frame, path: &mut PathState, hit: Hit) -> bool {
    let mut hit = hit;
    let lights_sampled =
        frame.emitter_count > 0 || frame.env_pick > 0.0 || frame.light_sampler == 1;
    // Whether the scene has media at all (the kernels' `HAS_MEDIA`): without, none of their
    // bookkeeping is done.
    let media_on = scene.features.media || !is_vacuum(&frame.fog);
    // The segment just traced crossed the medium the path is in: free flight decides whether it
    // scattered on the way (a vertex in the medium) or reached the hit, dimmed.
    let inside = media_top(path.media);
    let medium = if media_on {
        medium_of(scene, frame, inside)
    } else {
        Medium::default()
    };
    if media_on && !is_vacuum(&medium) {
        let t_max = if hit.triangle == MISS { FAR } else { hit.t };
        let flight = free_flight(&medium, t_max, &mut path.rng);
        path.beta *= flight.weight;
        if flight.scattered {
            let p = path.origin + path.direction * flight.t;
            return scatter_in_medium(scene, frame, path, p, &medium, lights_sampled);
        }
    }
    if hit.triangle == MISS {
        // A transparent film: the background seen directly adds nothing (alpha says where it is),
        // nor does it reflected in a shadow catcher.
        let sky = if (path.depth == 0 && frame.transparent != 0) || path.matte {
            Vec3::ZERO
        } else {
            path.beta * escaped(scene, frame, path.direction, path.prev_bsdf_pdf)
        };
        path.radiance += clamp_bounced(sky, frame, path.depth);
        if path.depth == 0
            && let Some(f) = path.first_hit.as_mut()
        {
            f.emission = sky;
        }
        return false;
    }
    let mut placed = None;
    let surface_triangle = super::instances::hit_triangle(scene, &mut hit, &mut placed);
    let tri = surface_triangle.tri;
    let material = &scene.materials[tri.material as usize];
    let (v0, v1, v2) = (Vec3::from(tri.v0), Vec3::from(tri.v1), Vec3::from(tri.v2));
    let ng_raw = (v1 - v0).cross(v2 - v0);
    let front = path.direction.dot(ng_raw) < 0.0;
    // A matte path (camera, then catchers) leaves out the light an emitter sends it: a catcher's
    // direct light is in its shadow ratio.
    let catcher = catches_shadows(frame, material.flags);
    let matte = path.matte;
    path.matte = catcher && (path.depth == 0 || matte);
    if front && !matte && !path.matte {
        add_emission(scene, frame, path, hit, tri, ng_raw);
    }
    if path.depth == 0
        && let Some(f) = path.first_hit.as_mut()
    {
        f.albedo = first_hit_albedo(scene, material, &surface_triangle, hit);
        let n = ng_raw.normalize();
        f.normal = if front { n } else { -n };
        (f.coverage, f.depth, f.object) = (1.0, hit.t, tri.material + 1);
    }
    if material.kind == MaterialKind::Emissive.tag() || path.depth + 1 >= frame.max_depth {
        return false;
    }
    let Shading {
        p,
        ng,
        ns,
        color,
        inputs,
    } = shading_at(scene, &surface_triangle, hit, ng_raw, front, path);
    let surface = Surface::of_material(
        scene,
        material,
        color,
        &inputs,
        path.direction,
        ng,
        ns,
        front,
    );
    if frame.light_sampler == 1 {
        path.tree_normal = tree_normal_at(ng, surface.lit_through());
    }
    // Beyond a closed surface lies its interior (entered from the front) or what the path was in
    // before it (left from the back); a thin sheet has the same medium on both sides.
    let thin = material.flags & THIN_WALLED != 0;
    let mut media = ShadowMedia::default();
    if media_on {
        let beyond = if thin {
            inside
        } else if front {
            tri.material + 1
        } else {
            media_top(media_leave(path.media, tri.material))
        };
        media = ShadowMedia {
            above: Vec3::from(medium.sigma_t),
            below: Vec3::from(medium_of(scene, frame, beyond).sigma_t),
        };
    }
    if path.matte {
        if path.depth == 0
            && let Some(f) = path.first_hit.as_mut()
        {
            let [lit, free] =
                catcher_irradiance(scene, frame, p, ng, &mut path.rng, &mut path.rays);
            f.caught = [1.0, lit, free];
        }
    } else if !surface.is_delta() {
        add_light_at(scene, frame, path, p, ng, &surface, &media, lights_sampled);
    }
    let next = NextVertex {
        p,
        ng,
        front,
        thin,
        material: tri.material,
    };
    continue_from_surface(frame, path, &surface, next, media_on)
}

/// The light a front face at `hit` emits toward the path (the WGSL `add_emission`), weighted by
/// multiple importance sampling against next-event estimation where that could have found it,
/// added to the path's radiance (and to the first hit's emission).
fn add_emission(
    scene: &GpuScene,
    frame: &Frame,
    path: &mut PathState,
    hit: Hit,
    tri: &crate::gpu_types::Triangle,
    ng_raw: Vec3,
) {
    let material = &scene.materials[tri.material as usize];
    let cos_out = -path.direction.dot(ng_raw.normalize());
    let le = surface_emission(
        scene,
        material,
        tri,
        hit.triangle,
        (hit.b1, hit.b2),
        cos_out,
    );
    let mut weight = 1.0;
    if frame.emitter_count > 0 && path.prev_bsdf_pdf > 0.0 && le != Vec3::ZERO {
        let cos_l = -path.direction.dot(ng_raw.normalize());
        // Next-event estimation's pdf, from the same origin (a reflected ray leaves from
        // where the shadow rays left), by the emission factor whatever the image.
        let p_light = emitter_pdf(
            scene,
            frame,
            hit.triangle,
            path.origin,
            path.tree_normal,
            hit.t,
            cos_l,
        );
        weight = if frame.nee_only == 1 {
            0.0
        } else {
            power_heuristic(path.prev_bsdf_pdf, p_light)
        };
    }
    let emitted = path.beta * le * weight;
    path.radiance += clamp_bounced(emitted, frame, path.depth);
    if path.depth == 0
        && let Some(f) = path.first_hit.as_mut()
    {
        f.emission = emitted;
    }
}

/// The PBR material's inputs at `hit` (the WGSL `pbr_inputs_at`): its textures, its normal maps
/// (`ns`, the shading normal, follows the base's), the channel a dispersive volume keeps, and the
/// tangent its anisotropy turns about.
#[allow(clippy::too_many_arguments)]
fn pbr_inputs_at(
    scene: &GpuScene,
    material: &crate::gpu_types::Material,
    surface_triangle: &super::instances::HitTriangle<'_>,
    hit: Hit,
    uv: Option<Vec2>,
    n_interpolated: Vec3,
    ng: Vec3,
    ns: &mut Vec3,
    path: &mut PathState,
) -> PbrInputs {
    let tri = surface_triangle.tri;
    let b0 = 1.0 - hit.b1 - hit.b2;
    let lobe = material.lobe_of::<PbrLobe>();
    let mut inputs = match uv {
        Some(uv) => textured_pbr_inputs(scene, material, uv),
        None => PbrInputs::of_lobe(&lobe),
    };
    // The normal a tangent-space map in `slot` gives, facing the ray.
    let mapped = |slot: u32, scale: f32| {
        let uv = uv?;
        if material.texture(slot).is_empty() || tri.has_normals & crate::gpu_types::HAS_NORMALS == 0
        {
            return None;
        }
        let t = Slot::of(material, slot).sample(scene, uv, false).truncate();
        let corners = *surface_triangle.tangents;
        let n = normal_mapped(n_interpolated, corners, [b0, hit.b1, hit.b2], t, scale);
        Some(if n.dot(ng) < 0.0 { -n } else { n })
    };
    // The coat ignores the base's normal map (glTF): its own map, else the smooth normal.
    inputs.coat_normal = mapped(SLOT_CLEARCOAT_NORMAL, lobe.clearcoat_normal_scale).unwrap_or(*ns);
    if let Some(n) = mapped(SLOT_NORMAL, lobe.normal_scale) {
        *ns = n;
    }
    // A dispersive volume: the path keeps one channel, refracting at its wavelength.
    if lobe.dispersion > 0.0
        && lobe.transmission > 0.0
        && material.flags & crate::gpu_types::THIN_WALLED == 0
    {
        if path.channel == 0 {
            let (channel, mask) = pick_channel(path.rng.next_f32());
            path.channel = channel;
            path.beta *= mask;
        }
        inputs.ior = channel_ior(lobe.ior, lobe.dispersion, path.channel);
    }
    if inputs.anisotropy > 0.0 {
        inputs.anisotropy_direction = if material.flags & crate::gpu_types::TANGENTS != 0
            && tri.has_normals & crate::gpu_types::HAS_NORMALS != 0
        {
            let corners = *surface_triangle.tangents;
            anisotropy_tangent(
                *ns,
                corners,
                [b0, hit.b1, hit.b2],
                inputs.anisotropy_direction,
            )
        } else {
            Vec3::ZERO
        };
    }
    inputs
}

/// Where a surface vertex lies (for the step past it): the point, the normal facing the ray,
/// which face was hit, whether the surface is a thin sheet, and its material's index (the medium
/// it closes).
struct NextVertex {
    p: Vec3,
    ng: Vec3,
    front: bool,
    thin: bool,
    material: u32,
}

/// Past a surface vertex `at` (the WGSL `continue_from_surface`): samples the next direction from
/// `surface`, updates the throughput (and the relative index roulette undoes), plays Russian
/// roulette, follows the medium stack through a closed surface, and sets the next ray. Returns
/// whether the path goes on.
fn continue_from_surface(
    frame: &Frame,
    path: &mut PathState,
    surface: &Surface,
    at: NextVertex,
    media_on: bool,
) -> bool {
    let Some(sample) = surface.sample(path.direction, at.ng, &mut path.rng) else {
        return false;
    };
    path.beta *= sample.weight;
    path.prev_bsdf_pdf = sample.pdf;
    let next = sample.direction;
    let side = next.dot(at.ng);
    if side == 0.0 || !next.is_finite() {
        return false;
    }
    // Transmission continues below the surface, reflection above it.
    let transmitted = side < 0.0;
    if transmitted && !surface.transmits() {
        return false;
    }
    if transmitted && !at.thin {
        let eta = surface.relative_eta();
        path.eta_scale *= eta * eta;
    }
    if !survives_roulette(frame, path) {
        return false;
    }
    if media_on && transmitted && !at.thin {
        path.media = if at.front {
            media_enter(path.media, at.material)
        } else {
            media_leave(path.media, at.material)
        };
    }
    path.origin = offset_ray_origin(
        at.p,
        if transmitted { -at.ng } else { at.ng },
        frame.offset_scale,
    );
    path.direction = next;
    path.depth += 1;
    true
}

/// The light a scattering vertex at `p` (normal `ng`, 0 in a medium) receives directly: next-event
/// estimation and the delta lights, times the path's throughput, added to its radiance.
#[allow(clippy::too_many_arguments)]
fn add_light_at(
    scene: &GpuScene,
    frame: &Frame,
    path: &mut PathState,
    p: Vec3,
    ng: Vec3,
    surface: &Surface,
    media: &ShadowMedia,
    lights_sampled: bool,
) {
    if lights_sampled {
        let direct = path.beta
            * direct_light(
                scene,
                frame,
                p,
                ng,
                surface,
                media,
                &mut path.rng,
                &mut path.rays,
            );
        path.radiance += clamp_bounced(direct, frame, path.depth + 1);
    }
    let delta = path.beta * delta_lights_at(scene, frame, p, ng, surface, media, &mut path.rays);
    path.radiance += clamp_bounced(delta, frame, path.depth + 1);
}

/// Russian roulette: the path continues with probability q = min(1, max(β · η²)), re-weighted by
/// 1/q (unbiased for any q > 0; `eta_scale` undoes refraction's 1/η², as pbrt-v4 and Mitsuba 3
/// do, so that paths inside glass are not killed for a dimming they will undo on the way out).
fn survives_roulette(frame: &Frame, path: &mut PathState) -> bool {
    if frame.roulette_from_depth > 0 && path.depth >= frame.roulette_from_depth {
        let survive = (path.beta * path.eta_scale).max_element().min(1.0);
        if path.rng.next_f32() >= survive {
            return false;
        }
        path.beta /= survive;
    }
    true
}

/// A scattering in `medium` at `p`, where the path's free flight ended (`math::medium`): the light
/// arriving there directly (the phase function for BSDF, shadow rays dimmed by the medium), then a
/// direction drawn from the phase function. Counts as a vertex for `max_depth`, as in Mitsuba's
/// `volpath`. Returns whether the path goes on.
fn scatter_in_medium(
    scene: &GpuScene,
    frame: &Frame,
    path: &mut PathState,
    p: Vec3,
    medium: &Medium,
    lights_sampled: bool,
) -> bool {
    // The denoiser's guides where the camera ray scatters first: the medium's albedo, and a normal
    // facing back along the ray.
    if path.depth == 0
        && let Some(f) = path.first_hit.as_mut()
    {
        f.albedo = scattering_albedo(medium);
        f.normal = -path.direction;
        (f.coverage, f.depth, f.object) = (1.0, (p - path.origin).length(), 0);
    }
    // A medium is no shadow catcher: what it scatters counts (a matte path's reflection of it).
    path.matte = false;
    if path.depth + 1 >= frame.max_depth {
        return false;
    }
    let phase = Surface::Phase {
        direction: path.direction,
        g: medium.anisotropy,
    };
    // No normal: lights on every side, none favoured by the tree.
    if frame.light_sampler == 1 {
        path.tree_normal = tree_normal_at(Vec3::ZERO, true);
    }
    let sigma = Vec3::from(medium.sigma_t);
    let media = ShadowMedia {
        above: sigma,
        below: sigma,
    };
    add_light_at(
        scene,
        frame,
        path,
        p,
        Vec3::ZERO,
        &phase,
        &media,
        lights_sampled,
    );
    let Some(sample) = phase.sample(path.direction, Vec3::ZERO, &mut path.rng) else {
        return false;
    };
    path.beta *= sample.weight;
    path.prev_bsdf_pdf = sample.pdf;
    if !sample.direction.is_finite() || !survives_roulette(frame, path) {
        return false;
    }
    path.origin = p;
    path.direction = sample.direction;
    path.depth += 1;
    true
}

/// The denoiser's albedo guide at a first hit: an emitter's colour scaled to a peak of 1, else the
/// surface's colour with its base colour image and vertex colours.
pub(crate) fn first_hit_albedo(
    scene: &GpuScene,
    material: &crate::gpu_types::Material,
    surface_triangle: &super::instances::HitTriangle<'_>,
    hit: Hit,
) -> Vec3 {
    if material.kind == MaterialKind::Emissive.tag() {
        let e = Vec3::from(material.emission);
        return e / e.max_element().max(1e-6);
    }
    let (tri, shading) = (surface_triangle.tri, || surface_triangle.shading());
    let b = [1.0 - hit.b1 - hit.b2, hit.b1, hit.b2];
    let mut a = Vec3::from(material.color);
    if !material.texture(SLOT_BASE).is_empty() && tri.has_uvs != 0 {
        let s = shading();
        let uv = Vec2::from(s.uv0) * b[0] + Vec2::from(s.uv1) * b[1] + Vec2::from(s.uv2) * b[2];
        a = base_color_texture(scene, material, uv);
    }
    if tri.has_normals & crate::gpu_types::HAS_COLORS != 0 {
        a *= vertex_color(&shading(), b);
    }
    a
}
