// Shadow catchers; mirrors crates/core/src/estimator/shadow_catcher.rs (which documents the
// estimator): a camera ray meeting a catcher first records the irradiance there with and without
// the scene's shadows, and the path goes on from it as a matte path (path.wgsl).

// Whether a surface with material flags `flags` catches shadows on this frame's film
// (shadow_catcher.rs `catches_shadows`).
fn catches_shadows(flags: u32) -> bool {
    return frame.transparent != 0u && (flags & SHADOW_CATCHER) != 0u;
}

struct CatcherIrradiance {
    lit: f32,
    free: f32,
}

fn add_catcher_light(e: ptr<function, CatcherIrradiance>, irradiance: f32, origin: vec3<f32>, dir: vec3<f32>,
                     distance: f32, rays: ptr<function, u32>) {
    *rays += 1u;
    (*e).free += irradiance;
    if (intersect_scene(origin, dir, distance, true).triangle == MISS) {
        (*e).lit += irradiance;
    }
}

// The irradiance luminance at p (geometric normal ng, facing the camera) with and without the
// scene's shadows, one sample (shadow_catcher.rs `catcher_irradiance`): one light sample, the
// delta lights, and a cosine-sampled direction under a uniform ambient light.
fn catcher_irradiance(p: vec3<f32>, ng: vec3<f32>, rng: ptr<function, Sampler>, rays: ptr<function, u32>) -> CatcherIrradiance {
    var e = CatcherIrradiance(0.0, 0.0);
    let lights_sampled = frame.emitter_count > 0u || frame.env_pick > 0.0 || frame.light_sampler == 1u;
    if (lights_sampled) {
        let light = sample_light(p, ng, false, rng);
        if (light.distance > 0.0) {
            let cos = dot(light.direction, ng);
            let irradiance = luminance(light.radiance_over_pdf) * cos;
            if (cos > 0.0 && irradiance > 0.0) {
                add_catcher_light(&e, irradiance, light.origin, light.direction, light.distance, rays);
            }
        }
    }
    let above = offset_ray_origin(p, ng, frame.offset_scale);
    if (HAS_DELTA_LIGHTS) {
        let tree = HAS_LIGHT_TREE && frame.light_sampler == 1u;
        for (var i = 0u; i < arrayLength(&delta_lights); i++) {
            let light = delta_lights[i];
            if (light.kind == LIGHT_NONE || (tree && in_light_tree(light))) {
                continue;
            }
            let d = delta_light_incidence(light, above);
            let cos = dot(d.dir, ng);
            let irradiance = luminance(d.irradiance) * cos;
            if (cos > 0.0 && irradiance > 0.0) {
                add_catcher_light(&e, irradiance, above, d.dir, d.distance, rays);
            }
        }
    }
    // A uniform ambient light L: E = pi L, a cosine-distributed direction's estimate.
    let ambient = luminance(frame.ambient);
    if ((!HAS_ENVIRONMENT || frame.env_width == 0u) && ambient > 0.0) {
        let dir = sample_cosine_hemisphere(ng, rng);
        if (dot(dir, ng) > 0.0) {
            add_catcher_light(&e, PI * ambient, above, dir, 3.0e38, rays);
        }
    }
    return e;
}
