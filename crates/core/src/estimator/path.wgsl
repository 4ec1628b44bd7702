// One path vertex at a time: the estimator shared by the megakernel (trace.wgsl, which loops over
// a path's vertices in one invocation) and the wavefront kernels (wavefront.wgsl, which run each
// stage for a queue of paths). Needs gpu_scene.wgsl and a BVH traversal.
//
// Estimator: see crates/core/src/estimator/ (path.rs, the twin of this file), which implements the same one on the CPU.
//   L = sum_{k < max_depth} beta_k Le(x_k),  beta_{k+1} = beta_k f cos / pdf = beta_k * albedo
// with Le the front-face emission (or the ambient radiance on a miss); with next-event estimation,
// diffuse vertices also sample an emitter point, and both strategies are weighted by the power
// heuristic (emitters seen from the camera or through specular bounces keep weight 1). With
// frame.nee_only == 1 (a diagnostic) next-event estimation takes weight 1 and BSDF-sampled
// hits on emitters after a diffuse bounce weight 0.

// Features a scene does not use are compiled out by these pipeline constants (the material
// kinds' in surface.wgsl, the lights' in light.wgsl).
override HAS_TEXTURES: bool = true;
override HAS_THIN_LENS: bool = true;
override COUNT_RAYS: bool = false;
override HAS_NORMAL_MAPS: bool = true;
// Also record the first hit's albedo, normal and directly seen light (for the denoiser).
override WRITE_AOVS: bool = false;
// Fog or a material's interior medium (math/medium.wgsl).
override HAS_MEDIA: bool = true;

// A path between vertices: the ray to trace next and what the path carries.
struct PathState {
    origin: vec3<f32>,
    depth: u32,
    direction: vec3<f32>,
    // Density of the BSDF sample that led here, for MIS; 0 after the camera, a specular bounce or
    // a transmission (surface_sample).
    prev_bsdf_pdf: f32,
    beta: vec3<f32>,
    // The hero channel (math/dispersion.wgsl): 0 none yet, 1–3 red, green, blue.
    channel: u32,
    radiance: vec3<f32>,
    // The last vertex's normal as the light tree weighs lights with it (light_tree.wgsl tree_normal_at).
    tree_normal: u32,
    // The media the path is in (path.rs `media_top`): two 16-bit ids, the innermost low.
    media: u32,
    // The product of eta^2 over the interfaces refracted through (path.rs `eta_scale`), which
    // Russian roulette undoes.
    eta_scale: f32,
    // 1 while the path has met only shadow catchers since the camera (path.rs `matte`).
    matte: u32,
}

// A next-event estimation ray: `contribution` reaches the path's radiance if nothing lies within
// `distance`. `distance` <= 0: no ray (the sampled point faces away or lies below the surface).
struct ShadowRay {
    origin: vec3<f32>,
    distance: f32,
    direction: vec3<f32>,
    // The path it belongs to (wavefront only).
    path: u32,
    contribution: vec3<f32>,
}

// The current sample's first-hit albedo and normal (zero when the camera ray escapes).
var<private> aov_albedo: vec3<f32>;
var<private> aov_normal: vec3<f32>;
var<private> aov_emission: vec3<f32>;
// The current sample's camera ray: (1 if it met a surface or scattered in a medium, else 0; the
// distance to that; the object hit + 1, 0 for none): the w channels of the three means below.
var<private> aov_hit: vec3<f32>;
// Where the camera ray met a shadow catcher: (1, the irradiance there with and without shadows).
var<private> aov_caught: vec3<f32>;

// Running means of a pixel's first-hit albedo, normal and directly seen light (the denoiser's
// guides) and of what it caught in shadow catchers, kept at [AOV_VECS slot + k] of the entry
// file's `aovs` binding.
struct AovMeans {
    albedo: vec4<f32>,
    normal: vec4<f32>,
    emission: vec4<f32>,
    caught: vec4<f32>,
}

// The vec4s of AovMeans (outputs.rs `AOV_BYTES_PER_PIXEL` / 16).
const AOV_VECS: u32 = 4u;

fn load_aov_means(slot: u32) -> AovMeans {
    if (frame.sample_base == 0u) {
        return AovMeans(vec4(0.0), vec4(0.0), vec4(0.0), vec4(0.0));
    }
    let i = AOV_VECS * slot;
    return AovMeans(aovs[i], aovs[i + 1u], aovs[i + 2u], aovs[i + 3u]);
}

// Folds in the `n`-th sample's values: running means, except emission.w (the object id), which
// keeps the first sample's (an id is never averaged).
fn add_aov_sample(m: ptr<function, AovMeans>, values: AovMeans, n: f32) {
    (*m).albedo += (values.albedo - (*m).albedo) / n;
    (*m).normal += (values.normal - (*m).normal) / n;
    let object = select((*m).emission.w, values.emission.w, n == 1.0);
    (*m).emission += (values.emission - (*m).emission) / n;
    (*m).emission.w = object;
    (*m).caught += (values.caught - (*m).caught) / n;
}

// A sample's guides as the means take them (`aov_*` and `aov_hit` in the w channels).
fn aov_sample_values() -> AovMeans {
    return AovMeans(vec4(aov_albedo, aov_hit.x), vec4(aov_normal, aov_hit.y), vec4(aov_emission, aov_hit.z), vec4(aov_caught, 0.0));
}

fn reset_aov_sample() {
    aov_albedo = vec3(0.0);
    aov_normal = vec3(0.0);
    aov_emission = vec3(0.0);
    aov_hit = vec3(0.0);
    aov_caught = vec3(0.0);
}

fn store_aov_means(slot: u32, m: AovMeans) {
    let i = AOV_VECS * slot;
    aovs[i] = m.albedo;
    aovs[i + 1u] = m.normal;
    aovs[i + 2u] = m.emission;
    aovs[i + 3u] = m.caught;
}

// Firefly clamp (`frame.clamp_max`, 0 off): each contribution of light that has bounced at least
// once (next-event estimates, emitters and sky reached after a bounce) is scaled down so its largest
// channel is at most the clamp; emitters and sky seen directly stay exact. Biased (it removes
// energy); off by default.
fn clamp_bounced(c: vec3<f32>) -> vec3<f32> {
    let clamp_max = frame.clamp_max;
    if (clamp_max > 0.0) {
        let peak = max(c.x, max(c.y, c.z));
        if (peak > clamp_max) {
            return c * (clamp_max / peak);
        }
    }
    return c;
}

fn is_finite3(v: vec3<f32>) -> bool {
    // Exponent all ones means Inf or NaN; tested on the bits so fast-math cannot fold it away.
    let e = bitcast<vec3<u32>>(v) & vec3(0x7f800000u);
    return all(e != vec3(0x7f800000u));
}

// A new path through pixel (x, y): its camera ray.
fn start_path(x: u32, y: u32, rng: ptr<function, Sampler>) -> PathState {
    let cam = camera_ray_origin_dir(x, y, rng);
    if (all(cam[1] == vec3(0.0))) {
        // Sees nothing (outside a fisheye's circle): a path that ends at once with zero weight.
        return PathState(cam[0], frame.max_depth, -frame.cam_w, 0.0, vec3(0.0), 0u, vec3(0.0), 0u, frame.camera_media, 1.0, 0u);
    }
    return PathState(cam[0], 0u, cam[1], 0.0, vec3(1.0), 0u, vec3(0.0), 0u, frame.camera_media, 1.0, 0u);
}

// The light a scattering vertex at p (normal ng, 0 in a medium) receives directly (path.rs
// `add_light_at`): next-event estimation (its ray left in `shadow` when deferred) and the delta
// lights, times the throughput.
fn add_light_at(path: ptr<function, PathState>, p: vec3<f32>, ng: vec3<f32>, surface: Surface, media: ShadowMedia,
                rng: ptr<function, Sampler>, shadow: ptr<function, ShadowRay>, defer_shadow: bool, rays: ptr<function, u32>) {
    if (HAS_NEE || (HAS_ENVIRONMENT && frame.env_pick > 0.0)) {
        if (defer_shadow) {
            *shadow = sample_direct(p, ng, surface, media, rng);
            (*shadow).contribution = clamp_bounced((*path).beta * (*shadow).contribution);
        } else {
            (*path).radiance += clamp_bounced((*path).beta * direct_light(p, ng, surface, media, rng, rays));
        }
    }
    if (HAS_DELTA_LIGHTS) {
        (*path).radiance += clamp_bounced((*path).beta * delta_lights_at(p, ng, surface, media, rays));
    }
}

// Russian roulette: continue with probability q = min(1, max(beta * eta_scale)), re-weighted by 1/q
// (path.rs `survives_roulette`).
fn survives_roulette(path: ptr<function, PathState>, rng: ptr<function, Sampler>) -> bool {
    if (frame.roulette_from_depth > 0u && (*path).depth >= frame.roulette_from_depth) {
        let beta = (*path).beta;
        let judged = beta * (*path).eta_scale;
        let survive = min(max(max(judged.x, judged.y), judged.z), 1.0);
        if (rng_next(rng) >= survive) {
            return false;
        }
        (*path).beta = beta / survive;
    }
    return true;
}

// A scattering in `medium` at p, where the path's free flight ended (path.rs `scatter_in_medium`).
fn scatter_in_medium(path: ptr<function, PathState>, p: vec3<f32>, medium: Medium, rng: ptr<function, Sampler>,
                     shadow: ptr<function, ShadowRay>, defer_shadow: bool, rays: ptr<function, u32>) -> bool {
    if (WRITE_AOVS && (*path).depth == 0u) {
        aov_albedo = scattering_albedo(medium);
        aov_normal = -(*path).direction;
        aov_hit = vec3(1.0, length(p - (*path).origin), 0.0);
    }
    // A medium is no shadow catcher: what it scatters counts (a matte path's reflection of it).
    (*path).matte = 0u;
    if ((*path).depth + 1u >= frame.max_depth) {
        return false;
    }
    let phase = phase_surface((*path).direction, medium.anisotropy);
    if (HAS_LIGHT_TREE && frame.light_sampler == 1u) {
        (*path).tree_normal = tree_normal_at(vec3(0.0), true);
    }
    add_light_at(path, p, vec3(0.0), phase, ShadowMedia(medium.sigma_t, medium.sigma_t), rng, shadow, defer_shadow, rays);
    let sample = surface_sample(phase, (*path).direction, vec3(0.0), rng);
    (*path).beta *= sample.weight;
    (*path).prev_bsdf_pdf = sample.pdf;
    if (!is_finite3(sample.direction) || !survives_roulette(path, rng)) {
        return false;
    }
    (*path).origin = p;
    (*path).direction = sample.direction;
    (*path).depth += 1u;
    return true;
}

// The light a front face at `hit` emits toward the path (path.rs `add_emission`), weighted by
// multiple importance sampling against next-event estimation where that could have found it,
// added to the path's radiance (and to the first hit's emission).
fn add_emission(path: ptr<function, PathState>, hit: Hit, tri: Triangle, material: Material, ng_raw: vec3<f32>) {
    let depth = (*path).depth;
    let direction = (*path).direction;
    var weight = 1.0;
    if (HAS_NEE && frame.emitter_count > 0u && (*path).prev_bsdf_pdf > 0.0 && any(material.emission != vec3(0.0))) {
        let cos_l = -dot(direction, normalize(ng_raw));
        let p_light = emitter_pdf(hit.triangle, (*path).origin, (*path).tree_normal, hit.t, cos_l);
        weight = select(power_heuristic((*path).prev_bsdf_pdf, p_light), 0.0, frame.nee_only == 1u);
    }
    let cos_out = -dot(direction, normalize(ng_raw));
    let emitted = (*path).beta * surface_emission(material, tri, hit.triangle, hit.b1, hit.b2, cos_out) * weight;
    (*path).radiance += select(clamp_bounced(emitted), emitted, depth == 0u);
    if (WRITE_AOVS && depth == 0u) {
        aov_emission = emitted;
    }
}

// The PBR material's inputs at `hit` (path.rs `pbr_inputs_at`): its textures, its normal maps
// (`ns`, the shading normal, follows the base's), the channel a dispersive volume keeps, and the
// tangent its anisotropy turns about.
fn pbr_inputs_at(material: Material, tri: Triangle, hit: Hit, uv: vec2<f32>, n_interpolated: vec3<f32>,
                 ng: vec3<f32>, ns: ptr<function, vec3<f32>>, path: ptr<function, PathState>,
                 rng: ptr<function, Sampler>) -> PbrInputs {
    let b0 = 1.0 - hit.b1 - hit.b2;
    let lobe = pbr_lobe(material);
    var inputs = pbr_inputs_of_lobe(lobe);
    // The coat ignores the base's normal map (glTF): its own map, else the smooth normal.
    inputs.coat_normal = *ns;
    if (HAS_TEXTURES && tri.has_uvs != 0u) {
        inputs = textured_pbr_inputs(material, uv);
        inputs.coat_normal = *ns;
        if (HAS_NORMAL_MAPS && (tri.has_normals & HAS_NORMALS) != 0u) {
            let c = hit_tangents(hit);
            let bary = vec3(b0, hit.b1, hit.b2);
            if (material.textures[SLOT_CLEARCOAT_NORMAL].offset != NO_TEXTURE) {
                let t = material_texture(material, SLOT_CLEARCOAT_NORMAL, uv, false).rgb;
                let mapped = normal_mapped(n_interpolated, c[0], c[1], c[2], bary, t, lobe.clearcoat_normal_scale);
                inputs.coat_normal = select(mapped, -mapped, dot(mapped, ng) < 0.0);
            }
            if (material.textures[SLOT_NORMAL].offset != NO_TEXTURE) {
                let t = material_texture(material, SLOT_NORMAL, uv, false).rgb;
                let mapped = normal_mapped(n_interpolated, c[0], c[1], c[2], bary, t, lobe.normal_scale);
                *ns = select(mapped, -mapped, dot(mapped, ng) < 0.0);
            }
        }
    }
    // A dispersive volume: the path keeps one channel, refracting at its wavelength.
    if (lobe.dispersion > 0.0 && lobe.transmission > 0.0 && (material.flags & THIN_WALLED) == 0u) {
        if ((*path).channel == 0u) {
            (*path).channel = pick_channel(rng_next(rng));
            (*path).beta *= channel_mask((*path).channel);
        }
        inputs.ior = channel_ior(lobe.ior, lobe.dispersion, (*path).channel);
    }
    if (inputs.anisotropy > 0.0) {
        var d = vec3(0.0);
        if (HAS_NORMAL_MAPS && (material.flags & TANGENTS) != 0u && (tri.has_normals & HAS_NORMALS) != 0u) {
            let c = hit_tangents(hit);
            d = anisotropy_tangent(*ns, c[0], c[1], c[2], vec3(b0, hit.b1, hit.b2), inputs.anisotropy_direction);
        }
        inputs.anisotropy_direction = d;
    }
    return inputs;
}

// Past a surface vertex at `p` (path.rs `continue_from_surface`): samples the next direction
// from `surface`, updates the throughput (and the relative index roulette undoes), plays Russian
// roulette, follows the medium stack through a closed surface (`material_index`'s interior), and
// sets the next ray. Returns whether the path goes on.
fn continue_from_surface(path: ptr<function, PathState>, surface: Surface, p: vec3<f32>, ng: vec3<f32>,
                         front: bool, thin: bool, material_index: u32, rng: ptr<function, Sampler>) -> bool {
    let direction = (*path).direction;
    let sample = surface_sample(surface, direction, ng, rng);
    if (!sample.valid) {
        return false;
    }
    (*path).beta *= sample.weight;
    (*path).prev_bsdf_pdf = sample.pdf;
    let next = sample.direction;
    let side = dot(next, ng);
    let transmitted = side < 0.0;
    // A direction that is not finite (a degenerate normal or sample) ends the path, as in the Rust
    // twin, rather than sending NaN into the traversal and the sums.
    if (side == 0.0 || !is_finite3(next) || (transmitted && !surface_transmits(surface))) {
        return false;
    }
    if (transmitted && !thin) {
        let eta = surface_relative_eta(surface);
        (*path).eta_scale *= eta * eta;
    }
    if (!survives_roulette(path, rng)) {
        return false;
    }
    if (HAS_MEDIA && transmitted && !thin) {
        (*path).media = select(media_leave((*path).media, material_index), media_enter((*path).media, material_index), front);
    }
    (*path).origin = offset_ray_origin(p, select(ng, -ng, transmitted), frame.offset_scale);
    (*path).direction = next;
    (*path).depth = (*path).depth + 1u;
    return true;
}

// The vertex where `path`'s ray found `hit`: adds the light it sees there, samples the next
// direction, and returns whether the path goes on (with `path` then holding the next ray). The
// next-event estimation ray is traced here unless `defer_shadow`: then it is left in `shadow` for
// the caller (its `distance` <= 0 when there is none), whose contribution the caller adds before
// the path's next vertex, so without point, spot or sun lights the sums come out in the same order
// either way (with them, their sum is added before the next-event estimate instead of after).
fn shade_vertex(path: ptr<function, PathState>, found: Hit, rng: ptr<function, Sampler>,
                shadow: ptr<function, ShadowRay>, defer_shadow: bool, rays: ptr<function, u32>) -> bool {
    var hit = found;
    (*shadow).distance = -1.0;
    let depth = (*path).depth;
    let direction = (*path).direction;
    // The segment just traced crossed the medium the path is in: free flight decides whether it
    // scattered on the way or reached the hit, dimmed.
    let inside = media_top((*path).media);
    var medium: Medium;
    if (HAS_MEDIA) {
        medium = medium_of(inside);
        if (!is_vacuum(medium)) {
            let flight = free_flight(medium, select(hit.t, MEDIUM_FAR, hit.triangle == MISS), rng);
            (*path).beta *= flight.weight;
            if (flight.scattered) {
                return scatter_in_medium(path, (*path).origin + direction * flight.t, medium, rng, shadow, defer_shadow, rays);
            }
        }
    }
    if (hit.triangle == MISS) {
        // A transparent film: the background seen directly adds nothing (alpha says where it is),
        // nor does it reflected in a shadow catcher.
        let transparent = (depth == 0u && frame.transparent != 0u) || (*path).matte != 0u;
        let sky = select((*path).beta * escaped(direction, (*path).prev_bsdf_pdf), vec3(0.0), transparent);
        (*path).radiance += select(clamp_bounced(sky), sky, depth == 0u);
        if (WRITE_AOVS && depth == 0u) {
            aov_emission = sky;
        }
        return false;
    }
    // The triangle in world space (instances.rs `hit_triangle`). Triangles without normals, UVs or
    // colours have no shading record (the buffer may be a placeholder).
    var tri = triangles[hit.triangle];
    var sh: Shading;
    if (tri.has_normals != 0u || tri.has_uvs != 0u) {
        sh = stored_shading(hit.triangle);
    }
    if (HAS_INSTANCES && hit.instance != NO_INSTANCE) {
        let inst = instances[hit.instance];
        place_triangle(inst, &tri, &sh);
        if (inst.mirrored != 0u) {
            hit = Hit(hit.t, hit.triangle, hit.b2, hit.b1, hit.instance);
        }
    }
    let material = materials[tri.material];
    let ng_raw = cross(tri.v1 - tri.v0, tri.v2 - tri.v0);
    let front = dot(direction, ng_raw) < 0.0;
    if (WRITE_AOVS && depth == 0u) {
        let n = normalize(ng_raw);
        aov_normal = select(-n, n, front);
        aov_hit = vec3(1.0, hit.t, f32(tri.material + 1u));
        if (material.kind == MAT_EMISSIVE) {
            let e = material.emission;
            aov_albedo = e / max(max(e.x, max(e.y, e.z)), 1e-6);
        } else {
            var a = material.color;
            if (HAS_TEXTURES && material.textures[SLOT_BASE].offset != NO_TEXTURE && tri.has_uvs != 0u) {
                let c0 = 1.0 - hit.b1 - hit.b2;
                a = base_color_texture(material, sh.uv0 * c0 + sh.uv1 * hit.b1 + sh.uv2 * hit.b2);
            }
            if ((tri.has_normals & HAS_COLORS) != 0u) {
                a *= vertex_color(sh, vec3(1.0 - hit.b1 - hit.b2, hit.b1, hit.b2));
            }
            aov_albedo = a;
        }
    }
    // A matte path (camera, then catchers) leaves out the light an emitter sends it: a catcher's
    // direct light is in its shadow ratio.
    let matte = (*path).matte != 0u;
    let catcher = catches_shadows(material.flags) && (depth == 0u || matte);
    (*path).matte = select(0u, 1u, catcher);
    if (front && !matte && !catcher) {
        add_emission(path, hit, tri, material, ng_raw);
    }
    if (material.kind == MAT_EMISSIVE || depth + 1u >= frame.max_depth) {
        return false;
    }
    let b0 = 1.0 - hit.b1 - hit.b2;
    let p = tri.v0 * b0 + tri.v1 * hit.b1 + tri.v2 * hit.b2;
    let ng = select(-1.0, 1.0, front) * normalize(ng_raw);
    var ns = ng;
    var n_interpolated = ng;
    if ((tri.has_normals & HAS_NORMALS) != 0u) {
        n_interpolated = normalize(sh.n0 * b0 + sh.n1 * hit.b1 + sh.n2 * hit.b2);
        ns = select(n_interpolated, -n_interpolated, dot(n_interpolated, ng) < 0.0);
    }
    let uv = sh.uv0 * b0 + sh.uv1 * hit.b1 + sh.uv2 * hit.b2;
    var color = material.color;
    if (HAS_TEXTURES && material.textures[SLOT_BASE].offset != NO_TEXTURE && tri.has_uvs != 0u) {
        color = base_color_texture(material, uv);
    }
    if ((tri.has_normals & HAS_COLORS) != 0u) {
        color *= vertex_color(sh, vec3(b0, hit.b1, hit.b2));
    }
    var inputs: PbrInputs;
    if (HAS_PBR && material.kind == MAT_PBR) {
        inputs = pbr_inputs_at(material, tri, hit, uv, n_interpolated, ng, &ns, path, rng);
    }
    let surface = material_surface(material, color, inputs, direction, ng, ns, front);
    if (HAS_LIGHT_TREE && frame.light_sampler == 1u) {
        (*path).tree_normal = tree_normal_at(ng, surface_lit_through(surface));
    }
    // Beyond a closed surface lies its interior (entered from the front) or what the path was in
    // before it (left from the back); a thin sheet has the same medium on both sides.
    let thin = (material.flags & THIN_WALLED) != 0u;
    var media = ShadowMedia(vec3(0.0), vec3(0.0));
    if (HAS_MEDIA) {
        var beyond = inside;
        if (!thin) {
            beyond = select(media_top(media_leave((*path).media, tri.material)), tri.material + 1u, front);
        }
        media = ShadowMedia(medium.sigma_t, medium_of(beyond).sigma_t);
    }
    if (catcher) {
        if (WRITE_AOVS && depth == 0u) {
            let e = catcher_irradiance(p, ng, rng, rays);
            aov_caught = vec3(1.0, e.lit, e.free);
        }
    } else if (!surface_is_delta(surface)) {
        add_light_at(path, p, ng, surface, media, rng, shadow, defer_shadow, rays);
    }
    return continue_from_surface(path, surface, p, ng, front, thin, tri.material, rng);
}
