// The lights; mirrors crates/core/src/estimator/light.rs (which documents each kind and the
// estimator): area lights and the environment sampled for next-event estimation (sample_light,
// sample_direct, direct_light), the delta lights (delta_light_incidence, delta_lights_at), and
// what a ray leaving the scene sees (escaped), and the MIS weight they share (power_heuristic).

// Lights a scene lacks are compiled out.
override HAS_NEE: bool = true;
override HAS_LIGHT_TREE: bool = true;
override HAS_DELTA_LIGHTS: bool = true;
override HAS_ENVIRONMENT: bool = true;

// Whether light arriving along dir reaches a vertex with geometric normal ng from its side: above
// the surface, or from anywhere at a scattering in a medium (ng = 0; light.rs `reaches`).
fn reaches(dir: vec3<f32>, ng: vec3<f32>) -> bool {
    return dot(dir, ng) > 0.0 || all(ng == vec3(0.0));
}

// The extinction of the media a vertex's shadow rays cross: `above` on the side of ng, `below`
// beyond the surface (light.rs `ShadowMedia`).
struct ShadowMedia {
    above: vec3<f32>,
    below: vec3<f32>,
}

fn shadow_transmittance(media: ShadowMedia, dir: vec3<f32>, ng: vec3<f32>, distance: f32) -> vec3<f32> {
    if (!HAS_MEDIA) {
        return vec3(1.0);
    }
    let sigma = select(media.above, media.below, dot(dir, ng) < 0.0);
    // Vacuum, the common case, without three exponentials.
    if (all(sigma == vec3(0.0))) {
        return vec3(1.0);
    }
    return transmittance(sigma, distance);
}

// The power heuristic (beta = 2) weight of the strategy with density a against one with density b:
// how next-event estimation and BSDF sampling share the light they both find.
fn power_heuristic(a: f32, b: f32) -> f32 {
    let a2 = a * a;
    let b2 = b * b;
    return select(0.0, a2 / (a2 + b2), a2 + b2 > 0.0);
}

// One light sample from p (light.rs `sample_light`): the environment with probability
// frame.env_pick, else an emitter point or, through the tree, a point or spot light (p_light 0: a
// delta). `distance` <= 0: none. Always draws four random numbers.
struct LightSample {
    origin: vec3<f32>,
    distance: f32,
    direction: vec3<f32>,
    p_light: f32,
    radiance_over_pdf: vec3<f32>,
}

fn sample_light(p: vec3<f32>, ng: vec3<f32>, lit_through: bool, rng: ptr<function, Sampler>) -> LightSample {
    var none: LightSample;
    none.distance = -1.0;
    let u_pick = rng_next(rng);
    let u_alias = rng_next(rng);
    let u_a = rng_next(rng);
    let u_b = rng_next(rng);
    let origin = offset_ray_origin(p, ng, frame.offset_scale);
    if (HAS_ENVIRONMENT && u_pick < frame.env_pick) {
        let e = sample_env(u_pick / frame.env_pick, u_alias, u_a, u_b);
        let p_light = frame.env_pick * e.pdf;
        if (!(p_light > 0.0 && reaches(e.direction, ng))) {
            return none;
        }
        return LightSample(origin, 3.0e38, e.direction, p_light, e.radiance / p_light);
    }
    if (!HAS_NEE) {
        return none;
    }
    let u_emitter = (u_pick - frame.env_pick) / (1.0 - frame.env_pick);
    var chosen: u32;
    var tree_pmf = 0.0;
    if (HAS_LIGHT_TREE && frame.light_sampler == 1u) {
        let t = sample_tree(origin, unpack_normal(tree_normal_at(ng, lit_through)), u_emitter);
        if (!(t.pmf > 0.0)) {
            return none;
        }
        if (HAS_DELTA_LIGHTS && (t.light & DELTA_LEAF) != 0u) {
            let d = delta_light_toward(delta_lights[t.light & ~DELTA_LEAF], p, ng, origin, lit_through);
            if (!(d.distance > 0.0)) {
                return none;
            }
            let pick = (1.0 - frame.env_pick) * t.pmf;
            return LightSample(d.origin, d.distance, d.dir, 0.0, d.irradiance / pick);
        }
        chosen = t.light;
        tree_pmf = t.pmf;
    } else {
        let n = frame.emitter_count;
        let slot = emitters[min(u32(u_emitter * f32(n)), n - 1u)];
        chosen = select(emitters[slot.alias_index].triangle, slot.triangle, u_alias < slot.threshold);
    }
    let tri = triangles[chosen];
    let b = sample_triangle(u_a, u_b);
    let y = tri.v0 * b.x + tri.v1 * b.y + tri.v2 * b.z;
    let edges = cross(tri.v1 - tri.v0, tri.v2 - tri.v0);
    let nl = normalize(edges);
    if (dot(y - p, nl) >= 0.0) {
        return none;
    }
    let to = offset_ray_origin(y, nl, frame.offset_scale) - origin;
    let distance = length(to);
    let dir = to / distance;
    let cos_l = -dot(dir, nl);
    if (!(reaches(dir, ng) && cos_l > 0.0)) {
        return none;
    }
    // The table picks emitters by their emission factor; the point's own radiance is the factor
    // times the emission image, and, on a surface with holes, times its coverage (the light that
    // BSDF sampling finds there on average).
    let material = materials[tri.material];
    let pick_per_area = select(luminance(material.emission) * frame.emitter_power_inv, tree_pmf / (0.5 * length(edges)), HAS_LIGHT_TREE && frame.light_sampler == 1u);
    let p_light = (1.0 - frame.env_pick) * pick_per_area * distance * distance / cos_l;
    var le = surface_emission(material, tri, chosen, b.y, b.z, cos_l);
    if (HAS_ALPHA && (material.flags & (ALPHA_MASK | ALPHA_BLEND)) != 0u) {
        le *= coverage(material, tri, chosen, b.y, b.z);
    }
    return LightSample(origin, distance, dir, p_light, le / p_light);
}

// The solid-angle density with which sample_light at a vertex (its shadow rays' origin, its tree
// normal packed) picks the point at `distance` on emitter `triangle` seen at cos_l: what MIS
// weighs an emitter found by a BSDF sample with (light.rs `emitter_pdf`).
fn emitter_pdf(triangle: u32, origin: vec3<f32>, tree_normal: u32, distance: f32, cos_l: f32) -> f32 {
    let tri = triangles[triangle];
    var pick_per_area: f32;
    if (HAS_LIGHT_TREE && frame.light_sampler == 1u) {
        let area = 0.5 * length(cross(tri.v1 - tri.v0, tri.v2 - tri.v0));
        pick_per_area = tree_pmf(leaf_of(triangle), origin, unpack_normal(tree_normal)) / area;
    } else {
        pick_per_area = luminance(materials[tri.material].emission) * frame.emitter_power_inv;
    }
    return (1.0 - frame.env_pick) * pick_per_area * distance * distance / cos_l;
}

// Next-event estimation at p for `surface`: the shadow ray and, should it arrive,
// f cos Le * w_light / p_light * T, T the media's transmittance along it (beta applied by the
// caller). Always draws four random numbers.
fn sample_direct(p: vec3<f32>, ng: vec3<f32>, surface: Surface, media: ShadowMedia, rng: ptr<function, Sampler>) -> ShadowRay {
    var none: ShadowRay;
    none.distance = -1.0;
    let light = sample_light(p, ng, surface_lit_through(surface), rng);
    if (!(light.distance > 0.0)) {
        return none;
    }
    let e = surface_eval(surface, light.direction);
    if (all(e.xyz == vec3(0.0))) {
        return none;
    }
    let tr = shadow_transmittance(media, light.direction, ng, light.distance);
    if (all(tr == vec3(0.0))) {
        return none;
    }
    let w_light = select(power_heuristic(light.p_light, e.w), 1.0, frame.nee_only == 1u || light.p_light == 0.0);
    return ShadowRay(light.origin, light.distance, light.direction, 0u, e.xyz * light.radiance_over_pdf * w_light * tr);
}

// `sample_direct` with its ray traced here: the contribution, or zero if occluded.
fn direct_light(p: vec3<f32>, ng: vec3<f32>, surface: Surface, media: ShadowMedia, rng: ptr<function, Sampler>, rays: ptr<function, u32>) -> vec3<f32> {
    let shadow = sample_direct(p, ng, surface, media, rng);
    if (!(shadow.distance > 0.0)) {
        return vec3(0.0);
    }
    *rays += 1u;
    if (intersect_scene(shadow.origin, shadow.direction, shadow.distance, true).triangle != MISS) {
        return vec3(0.0);
    }
    return shadow.contribution;
}

// Where a point, spot or sun light lies from `origin` and the irradiance it gives there (normal to
// `dir`, before the surface's cosine): each light type is one case here (light.rs
// `delta_light_incidence`; light.rs has the units and the spots' falloffs).
struct DeltaIncidence {
    dir: vec3<f32>,
    distance: f32,
    irradiance: vec3<f32>,
}

fn delta_light_incidence(light: DeltaLight, origin: vec3<f32>) -> DeltaIncidence {
    if (light.kind == LIGHT_DIRECTIONAL) {
        return DeltaIncidence(-light.direction, 3.0e38, light.power);
    }
    let to = light.position - origin;
    let d2 = dot(to, to);
    let distance = sqrt(d2);
    let dir = to / distance;
    var irradiance = light.power / d2;
    if (light.kind == LIGHT_SPOT) {
        let t = clamp((dot(-dir, light.direction) - light.cos_outer) / max(light.cos_inner - light.cos_outer, 1e-6), 0.0, 1.0);
        irradiance *= t * t * (3.0 - 2.0 * t);
    } else if (light.kind == LIGHT_SPOT_GLTF) {
        let t = clamp((dot(-dir, light.direction) - light.cos_outer) / max(light.cos_inner - light.cos_outer, 1e-3), 0.0, 1.0);
        irradiance *= t * t;
    }
    return DeltaIncidence(dir, distance, irradiance);
}

// Where a delta light reaches the surface at p (normal ng, shadow rays from `above`) from: the
// shadow ray and the irradiance, from the other side too where the surface lets it through
// (light.rs `delta_light_toward`). `distance` <= 0: neither side, or nothing.
struct DeltaToward {
    origin: vec3<f32>,
    distance: f32,
    dir: vec3<f32>,
    irradiance: vec3<f32>,
}

fn delta_light_toward(light: DeltaLight, p: vec3<f32>, ng: vec3<f32>, above: vec3<f32>, lit_through: bool) -> DeltaToward {
    var none: DeltaToward;
    none.distance = -1.0;
    var origin = above;
    var incidence = delta_light_incidence(light, above);
    let in_medium = all(ng == vec3(0.0)) && incidence.distance > 0.0;
    if (!in_medium && !(dot(incidence.dir, ng) > 0.0)) {
        if (!lit_through) {
            return none;
        }
        // The other side's origin only where a light lies beyond a surface it lights through.
        origin = offset_ray_origin(p, -ng, frame.offset_scale);
        incidence = delta_light_incidence(light, origin);
        if (!(dot(incidence.dir, ng) < 0.0)) {
            return none;
        }
    }
    if (all(incidence.irradiance == vec3(0.0))) {
        return none;
    }
    return DeltaToward(origin, incidence.distance, incidence.dir, incidence.irradiance);
}

// Whether the light tree holds a delta light when it samples (light_tree.rs `in_tree`): points
// and spots; suns are summed.
fn in_light_tree(light: DeltaLight) -> bool {
    return light.kind == LIGHT_POINT || light.kind == LIGHT_SPOT || light.kind == LIGHT_SPOT_GLTF;
}

// Point, spot and directional lights at p: sum over lights of E f cos, E the irradiance from the
// light (I/d^2, falloff for spots; E for the sun), if unoccluded (beta applied by the caller), each
// from the side it reaches (delta_light_toward). Where the light tree samples, it holds the points
// and spots, and this sums the suns alone. Deterministic: draws no random numbers.
fn delta_lights_at(p: vec3<f32>, ng: vec3<f32>, surface: Surface, media: ShadowMedia, rays: ptr<function, u32>) -> vec3<f32> {
    var sum = vec3(0.0);
    let above = offset_ray_origin(p, ng, frame.offset_scale);
    let lit_through = surface_lit_through(surface);
    let tree = HAS_LIGHT_TREE && frame.light_sampler == 1u;
    for (var i = 0u; i < arrayLength(&delta_lights); i++) {
        let light = delta_lights[i];
        if (light.kind == LIGHT_NONE || (tree && in_light_tree(light))) {
            continue;
        }
        let d = delta_light_toward(light, p, ng, above, lit_through);
        if (!(d.distance > 0.0)) {
            continue;
        }
        let f_cos = surface_eval(surface, d.dir).xyz;
        if (all(f_cos == vec3(0.0))) {
            continue;
        }
        let tr = shadow_transmittance(media, d.dir, ng, d.distance);
        if (all(tr == vec3(0.0))) {
            continue;
        }
        *rays += 1u;
        if (intersect_scene(d.origin, d.dir, d.distance, true).triangle != MISS) {
            continue;
        }
        sum += d.irradiance * f_cos * tr;
    }
    return sum;
}

// The light a ray leaving the scene finds, MIS-weighted against the environment's next-event
// estimation when the last vertex sampled its BSDF with density prev_bsdf_pdf.
fn escaped(direction: vec3<f32>, prev_bsdf_pdf: f32) -> vec3<f32> {
    if (!HAS_ENVIRONMENT || frame.env_width == 0u) {
        return frame.ambient;
    }
    let e = env_lookup(direction);
    var weight = 1.0;
    if (frame.env_pick > 0.0 && prev_bsdf_pdf > 0.0) {
        weight = select(power_heuristic(prev_bsdf_pdf, frame.env_pick * e.w), 0.0, frame.nee_only == 1u);
    }
    return e.xyz * weight;
}
