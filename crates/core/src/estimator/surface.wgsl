// The BSDF at a path vertex, dispatched on the material kind (MAT_*); mirrors
// crates/core/src/estimator/surface.rs. The lobes: Lambert (here), fuzzy metal and smooth glass
// (math/sampling.wgsl), glTF metallic-roughness under its coat and sheen (math/layers.wgsl over
// math/bsdf.wgsl). Metal and glass are delta-like
// lobes: lights are not sampled at them, and the pdf their samples carry is 0, so an emitter they
// reach counts fully.

// The kinds a scene lacks are compiled out (core::MaterialKind::pipeline_switch names these).
override HAS_METAL: bool = true;
override HAS_DIELECTRIC: bool = true;
override HAS_PBR: bool = true;

struct Surface {
    kind: u32,
    // Lambert albedo, metal reflectance or glass tint (PBR keeps its base colour in `bsdf`).
    color: vec3<f32>,
    // The shading frame (t, b, n) and wo in it (PBR); the other lobes use n only.
    t: vec3<f32>,
    b: vec3<f32>,
    n: vec3<f32>,
    wo: vec3<f32>,
    // Metal: the fuzz ball's radius.
    fuzz: f32,
    // Glass: n_transmitted / n_incident.
    eta: f32,
    // A phase function (SURFACE_PHASE): its Henyey-Greenstein anisotropy, about the direction of
    // travel held in `wo`.
    g: f32,
    bsdf: Layered,
}

// A scattering in a medium (surface.rs `Surface::Phase`): no material kind, so a tag beyond them.
const SURFACE_PHASE: u32 = 0xffffu;

fn phase_surface(direction: vec3<f32>, g: f32) -> Surface {
    var s: Surface;
    s.kind = SURFACE_PHASE;
    s.wo = direction;
    s.g = g;
    return s;
}

// The PBR material's inputs at a hit: its lobe's factors times their textures
// (textured_pbr_inputs).
struct PbrInputs {
    metallic: f32,
    roughness: f32,
    specular: f32,
    specular_color: vec3<f32>,
    clearcoat: f32,
    clearcoat_roughness: f32,
    sheen_color: vec3<f32>,
    sheen_roughness: f32,
    // The clear coat's shading normal (world space, facing the ray; zero: the base's).
    coat_normal: vec3<f32>,
    diffuse_transmission: f32,
    diffuse_transmission_color: vec3<f32>,
    iridescence: f32,
    iridescence_ior: f32,
    // The film's thickness (nm).
    iridescence_thickness: f32,
    // The index of refraction here: the material's, or its hero channel's under dispersion.
    ior: f32,
    // KHR_materials_anisotropy's strength, and its direction: (cos, sin, 0) in the tangent frame,
    // in world space once shade_vertex has turned it (zero without tangents: the frame's own x).
    anisotropy: f32,
    anisotropy_direction: vec3<f32>,
}

// The factors alone.
fn pbr_inputs_of_lobe(l: PbrLobe) -> PbrInputs {
    return PbrInputs(l.metallic, l.roughness, l.specular, l.specular_color, l.clearcoat,
                     l.clearcoat_roughness, l.sheen_color, l.sheen_roughness, vec3(0.0),
                     l.diffuse_transmission, l.diffuse_transmission_color, l.iridescence,
                     l.iridescence_ior, l.iridescence_thickness_max, l.ior, l.anisotropy,
                     vec3(cos(l.anisotropy_rotation), sin(l.anisotropy_rotation), 0.0));
}

// The shading frame's tangent about n (surface.rs `shading_frame`): along the direction of
// anisotropy where the surface has one, else onb's.
fn shading_frame(n: vec3<f32>, inputs: PbrInputs) -> Basis {
    let d = inputs.anisotropy_direction;
    let o = d - n * dot(n, d);
    let len2 = dot(o, o);
    if (inputs.anisotropy > 0.0 && len2 > 0.0) {
        let t = o * inverseSqrt(len2);
        return Basis(t, cross(n, t));
    }
    return onb(n);
}

// The coat's frame (coat_frame in surface.rs): whether it has one of its own (about its normal,
// the true normal where wo lies below it), and the matrix taking the base's frame (t, b, n) to it.
struct CoatFrame {
    own: bool,
    m: mat3x3<f32>,
}

fn coat_frame(inputs: PbrInputs, wo: vec3<f32>, ng: vec3<f32>, t: vec3<f32>, b: vec3<f32>, n: vec3<f32>) -> CoatFrame {
    var out: CoatFrame;
    out.own = false;
    var nc = inputs.coat_normal;
    if (inputs.clearcoat <= 0.0 || all(nc == vec3(0.0)) || all(nc == n)) {
        return out;
    }
    nc = select(ng, nc, dot(wo, nc) > 0.0);
    if (all(nc == n)) {
        return out;
    }
    let basis = onb(nc);
    // Rows: the coat's axes in the base's frame (WGSL's constructor takes columns).
    let r0 = vec3(dot(basis.t, t), dot(basis.t, b), dot(basis.t, n));
    let r1 = vec3(dot(basis.b, t), dot(basis.b, b), dot(basis.b, n));
    let r2 = vec3(dot(nc, t), dot(nc, b), dot(nc, n));
    out.own = true;
    out.m = transpose(mat3x3(r0, r1, r2));
    return out;
}

// The PBR surface at a hit seen from wo: shading frame ns unless wo lies below it, then ng.
fn pbr_surface(material: Material, base: vec3<f32>, inputs: PbrInputs, wo: vec3<f32>, ng: vec3<f32>, ns: vec3<f32>, front: bool) -> Surface {
    let lobe = pbr_lobe(material);
    let n = select(ng, ns, dot(wo, ns) > 0.0);
    let basis = shading_frame(n, inputs);
    let wo_local = vec3(dot(wo, basis.t), dot(wo, basis.b), dot(wo, n));
    // A thin sheet looks the same from both sides.
    let thin = (material.flags & THIN_WALLED) != 0u;
    let eta = select(1.0 / inputs.ior, inputs.ior, front || thin);
    let alpha = anisotropic_alpha(inputs.roughness, inputs.anisotropy);
    // An anisotropic conductor has a table of its own; glass reads its isotropic tables at the
    // mean width.
    var roughness = inputs.roughness;
    var energy = 0.0;
    if (inputs.anisotropy > 0.0) {
        roughness = equivalent_roughness(alpha);
        energy = anisotropic_energy(wo_local, inputs.roughness, inputs.anisotropy);
    } else {
        energy = albedo_lookup(TABLE_CONDUCTOR, wo_local.z, roughness);
    }
    var s: Surface;
    s.kind = MAT_PBR;
    s.t = basis.t;
    s.b = basis.b;
    s.n = n;
    s.wo = wo_local;
    var b = pbr_bsdf(base, inputs.metallic, roughness, eta, lobe.transmission, wo_local.z, energy);
    b = pbr_anisotropic(b, alpha);
    b = pbr_with_specular(b, inputs.specular_color, inputs.specular, wo_local.z);
    b = pbr_with_diffuse_transmission(b, inputs.diffuse_transmission, inputs.diffuse_transmission_color);
    b = pbr_with_iridescence(b, inputs.iridescence, inputs.iridescence_ior, inputs.iridescence_thickness);
    b.thin = thin;
    // Rough glass keeps its energy (a thin sheet's transmission is a mirrored conductor lobe).
    if (lobe.transmission > 0.0) {
        b = pbr_with_glass_energy(b, select(glass_energy(wo_local.z, roughness, eta), energy, thin));
    }
    let cf = coat_frame(inputs, wo, ng, basis.t, basis.b, n);
    s.bsdf = layered_bsdf(b, inputs.clearcoat, inputs.clearcoat_roughness, inputs.sheen_color,
                          inputs.sheen_roughness, wo_local, cf.own, cf.m);
    return s;
}

// The BSDF of `material` where a ray travelling along `direction` hit it: `color` is its colour
// after textures and vertex colours, `inputs` the PBR inputs after theirs (unused by the other
// kinds), ng the geometric normal and ns the shading normal (both facing the ray), `front` the side
// it hit. A kind whose lobe the kernel has compiled out scatters as Lambert.
fn material_surface(material: Material, color: vec3<f32>, inputs: PbrInputs,
                    direction: vec3<f32>, ng: vec3<f32>, ns: vec3<f32>, front: bool) -> Surface {
    var s: Surface;
    s.kind = MAT_LAMBERTIAN;
    s.color = color;
    s.n = ns;
    if (HAS_METAL && material.kind == MAT_METAL) {
        s.kind = MAT_METAL;
        s.fuzz = metal_lobe(material).fuzz;
    } else if (HAS_DIELECTRIC && material.kind == MAT_DIELECTRIC) {
        let ior = dielectric_lobe(material).ior;
        s.kind = MAT_DIELECTRIC;
        s.eta = select(1.0 / ior, ior, front);
    } else if (HAS_PBR && material.kind == MAT_PBR) {
        s = pbr_surface(material, color, inputs, -direction, ng, ns, front);
    }
    return s;
}

// Whether the lobe is sampled only (no light sampling, zero pdf).
fn surface_is_delta(s: Surface) -> bool {
    return s.kind == MAT_METAL || s.kind == MAT_DIELECTRIC;
}

// Whether point, spot and sun lights beyond the surface light it through its transmission: a
// diffuse transmission, or a glass lobe rough enough to resolve them (surface.rs `lit_through`
// says why).
const LIT_THROUGH_MIN_ALPHA: f32 = 0.01;

fn surface_lit_through(s: Surface) -> bool {
    return s.kind == SURFACE_PHASE || (HAS_PBR && s.kind == MAT_PBR && (s.bsdf.base.diffuse_transmission > 0.0
        || (s.bsdf.base.transmission > 0.0 && min(s.bsdf.base.alpha.x, s.bsdf.base.alpha.y) >= LIT_THROUGH_MIN_ALPHA)));
}

// n_transmitted / n_incident of the refraction the surface's transmission makes, 1 where it refracts
// nothing (surface.rs `relative_eta`).
fn surface_relative_eta(s: Surface) -> f32 {
    if (HAS_DIELECTRIC && s.kind == MAT_DIELECTRIC) {
        return s.eta;
    }
    if (HAS_PBR && s.kind == MAT_PBR && s.bsdf.base.transmission > 0.0) {
        return s.bsdf.base.eta;
    }
    return 1.0;
}

// Whether the lobe may send a path below the geometric surface.
fn surface_transmits(s: Surface) -> bool {
    return s.kind == MAT_DIELECTRIC || s.kind == SURFACE_PHASE || (HAS_PBR && s.kind == MAT_PBR
        && (s.bsdf.base.transmission > 0.0 || s.bsdf.base.diffuse_transmission > 0.0));
}

// f |cos θ| towards world direction wi (xyz) and the BSDF-sampling pdf of wi (w); zero for the
// delta lobes (never asked).
fn surface_eval(s: Surface, wi: vec3<f32>) -> vec4<f32> {
    if (HAS_MEDIA && s.kind == SURFACE_PHASE) {
        return vec4(hg_phase(dot(s.wo, wi), s.g));
    }
    if (HAS_PBR && s.kind == MAT_PBR) {
        return layered_eval(s.bsdf, s.wo, vec3(dot(wi, s.t), dot(wi, s.b), dot(wi, s.n)));
    }
    let c = dot(wi, s.n);
    if (s.kind == MAT_LAMBERTIAN && c > 0.0) {
        let p = c * (1.0 / PI);
        return vec4(s.color * p, p);
    }
    return vec4(0.0);
}

struct SurfaceSample {
    direction: vec3<f32>,
    // f |cos θ| / pdf: what the path throughput is multiplied by.
    weight: vec3<f32>,
    // The pdf MIS weighs an emitter reached along `direction` with: 0 for the delta lobes and for
    // a PBR sample below the geometric surface.
    pdf: f32,
    // false: no sample (the path ends).
    valid: bool,
}

// The next direction of a path that arrived along `direction`, drawn from the surface's lobe.
fn surface_sample(s: Surface, direction: vec3<f32>, ng: vec3<f32>, rng: ptr<function, Sampler>) -> SurfaceSample {
    var out: SurfaceSample;
    out.valid = true;
    if (HAS_MEDIA && s.kind == SURFACE_PHASE) {
        let u1 = rng_next(rng);
        let u2 = rng_next(rng);
        out.direction = sample_hg(s.wo, s.g, u1, u2);
        out.weight = vec3(1.0);
        out.pdf = hg_phase(dot(s.wo, out.direction), s.g);
        return out;
    }
    if (HAS_METAL && s.kind == MAT_METAL) {
        out.direction = sample_metal(direction, s.n, s.fuzz, rng);
        out.weight = s.color;
        return out;
    }
    if (HAS_DIELECTRIC && s.kind == MAT_DIELECTRIC) {
        let d = sample_dielectric(direction, s.n, s.eta, rng);
        out.direction = d.direction;
        // Refraction scales radiance by 1/η²; reflection (probability F) keeps it.
        out.weight = select(vec3(1.0), s.color / (s.eta * s.eta), d.refracted);
        return out;
    }
    if (HAS_PBR && s.kind == MAT_PBR) {
        let u_lobe = rng_next(rng);
        let u1 = rng_next(rng);
        let u2 = rng_next(rng);
        let b = layered_sample(s.bsdf, s.wo, u_lobe, u1, u2);
        if (!b.valid) {
            out.valid = false;
            return out;
        }
        out.weight = b.weight;
        out.direction = normalize(s.t * b.wi.x + s.b * b.wi.y + s.n * b.wi.z);
        out.pdf = select(0.0, b.pdf, dot(out.direction, ng) > 0.0);
        return out;
    }
    out.direction = sample_cosine_hemisphere(s.n, rng);
    out.weight = s.color;
    out.pdf = max(dot(out.direction, s.n), 0.0) * (1.0 / PI);
    return out;
}
