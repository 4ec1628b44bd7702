// The preview's light (composed after preview.wgsl, whose bindings and structs it reads): the
// prefiltered environment, the irradiance volume's ambient cubes and radiance maps, the shadow
// maps, the lights, and `shade`, the metallic-roughness model with its anisotropy, coat and
// sheen (the model is described at the head of preview.wgsl).

// Radiance arriving from direction d, from the environment prefiltered for `roughness`.
fn environment(d: vec3<f32>, roughness: f32) -> vec3<f32> {
    if view.ambient.a > 0.5 {
        return view.ambient.rgb;
    }
    var u = atan2(d.x, -d.z) * (0.5 / PI) - view.eye.w;
    u = u - floor(u);
    let uv = vec2<f32>(u, acos(clamp(d.y, -1.0, 1.0)) / PI);
    let sharp = textureSampleLevel(env_sharp, linear_sampler, uv, 0.0).rgb;
    let level = clamp(roughness, 0.0, 1.0) * ENV_ROUGH_LAYERS;
    if level < 1.0 {
        let blur = textureSampleLevel(env_blur, linear_sampler, uv, 0u, 0.0).rgb;
        return mix(sharp, blur, level);
    }
    let lo = u32(min(floor(level), ENV_ROUGH_LAYERS)) - 1u;
    let hi = min(lo + 1u, u32(ENV_ROUGH_LAYERS) - 1u);
    let a = textureSampleLevel(env_blur, linear_sampler, uv, lo, 0.0).rgb;
    let b = textureSampleLevel(env_blur, linear_sampler, uv, hi, 0.0).rgb;
    return mix(a, b, level - floor(level));
}

fn irradiance_over_pi(n: vec3<f32>) -> vec3<f32> {
    if view.ambient.a > 0.5 {
        return view.ambient.rgb;
    }
    var u = atan2(n.x, -n.z) * (0.5 / PI) - view.eye.w;
    u = u - floor(u);
    let uv = vec2<f32>(u, acos(clamp(n.y, -1.0, 1.0)) / PI);
    return textureSampleLevel(env_blur, linear_sampler, uv, ENV_DIFFUSE_LAYER, 0.0).rgb;
}

// The volume's probes interpolated at q, side `axis` (kept inside that side's block of texels).
fn probe(q: vec3<f32>, axis: u32) -> vec4<f32> {
    let size = vec3<f32>(textureDimensions(probes));
    let dims = vec3<f32>(size.x / 6.0, size.y, size.z);
    let extent = max(view.probe_hi.xyz - view.probe_lo.xyz, vec3<f32>(1e-6));
    let f = clamp((q - view.probe_lo.xyz) / extent, vec3<f32>(0.0), vec3<f32>(1.0)) * dims;
    let c = clamp(f, vec3<f32>(0.5), dims - vec3<f32>(0.5));
    let uvw = vec3<f32>((f32(axis) * dims.x + c.x) / size.x, c.y / size.y, c.z / size.z);
    return textureSampleLevel(probes, linear_sampler, uvw, 0.0);
}

// Lookup point q for a surface at s facing n, moved within its cell of probes so that the sampler's
// trilinear weights favour the probes in front of the surface (bounce.rs `in_front_of`): a box's
// face otherwise read the probe inside the box, which takes its lit neighbours' light. Per axis,
// the two layers of probes are weighed by `facing_weight` of their height above the surface's
// plane (linear in the probe's index, so exact for a surface facing along an axis).
fn in_front_of(q: vec3<f32>, s: vec3<f32>, n: vec3<f32>) -> vec3<f32> {
    let dims = vec3<f32>(textureDimensions(probes)) / vec3<f32>(6.0, 1.0, 1.0);
    let lo = view.probe_lo.xyz;
    let extent = max(view.probe_hi.xyz - lo, vec3<f32>(1e-6));
    let spacing = extent / dims;
    let cell = min(spacing.x, min(spacing.y, spacing.z));
    let c = clamp(clamp((q - lo) / extent, vec3<f32>(0.0), vec3<f32>(1.0)) * dims, vec3<f32>(0.5), dims - vec3<f32>(0.5));
    let base = floor(c - vec3<f32>(0.5));
    let t = c - vec3<f32>(0.5) - base;
    let height = dot(lo + c * spacing - s, n) / cell;
    let step = select(vec3<f32>(0.0), spacing * n / cell, dims > vec3<f32>(1.5));
    let below = facing_weight(vec3<f32>(height) - t * step);
    let above = facing_weight(vec3<f32>(height) + (vec3<f32>(1.0) - t) * step);
    let moved = t * above / max((vec3<f32>(1.0) - t) * below + t * above, vec3<f32>(1e-12));
    return lo + (base + vec3<f32>(0.5) + moved) * spacing;
}

// How much a probe at height h above a surface's plane counts (in units of the smallest cell
// side): fully a tenth of a cell in front, a fiftieth a tenth behind (inside the object, or beyond
// a wall); so a floor's own probes, just above it, count fully.
fn facing_weight(h: vec3<f32>) -> vec3<f32> {
    return clamp(vec3<f32>(0.5) + 5.0 * h, vec3<f32>(0.02), vec3<f32>(1.0));
}

// The bin of unit direction d in a probe's radiance map (bounce.rs `direction_bin`): its band of
// equal solid angle by height, then its sector around the vertical.
fn direction_bin(d: vec3<f32>) -> u32 {
    let band = min(u32(max((d.y + 1.0) * 0.5 * f32(BANDS), 0.0)), BANDS - 1u);
    let turn = atan2(d.z, d.x) / (2.0 * PI) + 0.5;
    let around = min(u32(max(turn * f32(AZIMUTHS), 0.0)), AZIMUTHS - 1u);
    return band * AZIMUTHS + around;
}

// The radiance the probes about p see along d: [surfaces' radiance, share of the sky], d's bin
// of the probes interpolated trilinearly (by the sampler, within the bin's block, clamped to the
// outer probes as `probe`).
fn probe_radiance_along(p: vec3<f32>, d: vec3<f32>) -> vec4<f32> {
    let size = vec3<f32>(textureDimensions(probe_radiance));
    let dims = vec3<f32>(size.x / f32(BANDS * AZIMUTHS), size.y, size.z);
    let extent = max(view.probe_hi.xyz - view.probe_lo.xyz, vec3<f32>(1e-6));
    let f = clamp((p - view.probe_lo.xyz) / extent, vec3<f32>(0.0), vec3<f32>(1.0)) * dims;
    let c = clamp(f, vec3<f32>(0.5), dims - vec3<f32>(0.5));
    let block = f32(direction_bin(d));
    let uvw = vec3<f32>((block * dims.x + c.x) / size.x, c.y / size.y, c.z / size.z);
    return textureSampleLevel(probe_radiance, linear_sampler, uvw, 0.0);
}

// Bounce irradiance/π (rgb) and sky visibility (a) towards direction d at a surface point p with
// normal n: the ambient cube's three sides facing d, weighted by d's squared components, looked up
// a quarter of a cell off the surface (`PROBE_LOOKUP_LIFT`) and moved within its cell towards the
// probes in front of the surface (`in_front_of`).
fn ambient_cube(p: vec3<f32>, n: vec3<f32>, d: vec3<f32>) -> vec4<f32> {
    let dims = vec3<f32>(textureDimensions(probes)) / vec3<f32>(6.0, 1.0, 1.0);
    let cell = (view.probe_hi.xyz - view.probe_lo.xyz) / dims;
    return cube_sides(in_front_of(p + n * PROBE_LOOKUP_LIFT * min(cell.x, min(cell.y, cell.z)), p, n), d);
}

// The three sides of the probes interpolated at q that face d, weighted by d's squared components
// (a reflection's look ahead reads them at a point off any surface).
fn cube_sides(q: vec3<f32>, d: vec3<f32>) -> vec4<f32> {
    let w = d * d;
    // Sides with no weight are not read (a wall facing along an axis reads one).
    var sum = vec4<f32>(0.0);
    if w.x > 1e-4 {
        sum += w.x * probe(q, select(1u, 0u, d.x >= 0.0));
    }
    if w.y > 1e-4 {
        sum += w.y * probe(q, select(3u, 2u, d.y >= 0.0));
    }
    if w.z > 1e-4 {
        sum += w.z * probe(q, select(5u, 4u, d.z >= 0.0));
    }
    return sum / max(w.x + w.y + w.z, 1e-6);
}

// The split-sum scale and bias (A, B) of a GGX reflector at (μ, roughness): E = F0 A + B.
fn brdf_scale_bias(mu: f32, roughness: f32) -> vec2<f32> {
    let n = f32(textureDimensions(brdf_table).x);
    let uv = vec2<f32>(clamp(mu, 0.5 / n, 1.0 - 0.5 / n), (clamp(roughness, 0.0, 1.0) * (n - 1.0) + 0.5) / n);
    return textureSampleLevel(brdf_table, linear_sampler, uv, 0.0).rg;
}

// The directional albedo of a white sheen (rt-core's `math::sheen::sheen_table`, the table's
// third channel) at (μ, sheen roughness).
fn sheen_albedo(mu: f32, roughness: f32) -> f32 {
    let n = f32(textureDimensions(brdf_table).x);
    let uv = vec2<f32>(clamp(mu, 0.5 / n, 1.0 - 0.5 / n), (clamp(roughness, 0.0, 1.0) * (n - 1.0) + 0.5) / n);
    return textureSampleLevel(brdf_table, linear_sampler, uv, 0.0).b;
}

fn ggx_d(n_h: f32, a2: f32) -> f32 {
    let k = n_h * n_h * (a2 - 1.0) + 1.0;
    return a2 / max(PI * k * k, 1e-12);
}

// D of a half vector h given in the frame of anisotropy (z the normal), widths w.x and w.y.
fn ggx_d_anisotropic(h: vec3<f32>, w: Widths) -> f32 {
    let k = h.x * h.x / (w.x * w.x) + h.y * h.y / (w.y * w.y) + h.z * h.z;
    return 1.0 / max(PI * w.x * w.y * k * k, 1e-12);
}

// smith_visibility for directions given in the frame of anisotropy.
fn smith_visibility_anisotropic(v: vec3<f32>, l: vec3<f32>, w: Widths) -> f32 {
    let gv = max(l.z, 0.0) * length(vec3<f32>(w.x * v.x, w.y * v.y, v.z));
    let gl = max(v.z, 0.0) * length(vec3<f32>(w.x * l.x, w.y * l.y, l.z));
    return 0.5 / max(gv + gl, 1e-12);
}

// G₂ / (4 cosθo cosθi), height-correlated.
fn smith_visibility(n_v: f32, n_l: f32, a2: f32) -> f32 {
    let gv = n_l * sqrt(n_v * n_v * (1.0 - a2) + a2);
    let gl = n_v * sqrt(n_l * n_l * (1.0 - a2) + a2);
    return 0.5 / max(gv + gl, 1e-12);
}

fn fresnel_schlick(f0: vec3<f32>, f90: f32, c: f32) -> vec3<f32> {
    let x = 1.0 - clamp(c, 0.0, 1.0);
    let x2 = x * x;
    return f0 + (vec3<f32>(f90) - f0) * (x2 * x2 * x);
}

// Which layer of a light's shadow map holds point p: a point light's cube face by the major axis.
fn shadow_layer(light: PreviewLight, p: vec3<f32>) -> u32 {
    if light.shadow.z < 6u {
        return light.shadow.y;
    }
    let d = p - light.position.xyz;
    let a = abs(d);
    if a.x >= a.y && a.x >= a.z {
        return light.shadow.y + select(1u, 0u, d.x > 0.0);
    }
    if a.y >= a.z {
        return light.shadow.y + select(3u, 2u, d.y > 0.0);
    }
    return light.shadow.y + select(5u, 4u, d.z > 0.0);
}

// The fraction of the light's shadow map that sees p (1: lit), pushed along the normal by about a
// texel so that a surface does not shadow itself.
fn shadow(light: PreviewLight, p: vec3<f32>, n: vec3<f32>) -> f32 {
    if light.shadow.y == NO_SHADOW {
        return 1.0;
    }
    var texel = light.cone.z;
    if light.shadow.x != LIGHT_DIRECTIONAL {
        texel *= length(p - light.position.xyz);
    }
    let q = p + n * (2.0 * texel);
    let layer = shadow_layer(light, q);
    let clip = shadow_matrices[layer] * vec4<f32>(q, 1.0);
    if clip.w <= 0.0 {
        return 1.0;
    }
    let ndc = clip.xyz / clip.w;
    if abs(ndc.x) > 1.0 || abs(ndc.y) > 1.0 || ndc.z > 1.0 {
        return 1.0;
    }
    let uv = vec2<f32>(ndc.x * 0.5 + 0.5, 0.5 - ndc.y * 0.5);
    // Four bilinear comparisons a texel apart: a 3 × 3-texel tent, at a quarter of nine taps' cost.
    let step = 0.5 / f32(textureDimensions(shadow_map).x);
    var lit = 0.0;
    for (var k = 0u; k < 4u; k++) {
        let at = uv + vec2<f32>(select(-step, step, (k & 1u) != 0u), select(-step, step, k >= 2u));
        lit += textureSampleCompareLevel(shadow_map, shadow_sampler, at, layer, ndc.z);
    }
    return lit * 0.25;
}

// A light at p on a surface facing n: `strength` times `cosine` is the irradiance it brings, `l`
// the direction towards it. For point, spot and sun lights `cosine` is n·l; for an emitter,
// E / L of a disc of its flat part's area facing its area-weighted normal and of a sphere of its
// isotropic part's cross-section (`strength` its radiance), with the horizon clipped as Frostbite
// does (Lagarde and de Rousiers 2014): a surface nearly in the plane of a lamp sees the part in
// front of it (the Cornell box's tall block, whose front face passes by the lamp's centre, got
// its direct light 36% too dim from the lamp as a point at its centre).
struct Incoming {
    strength: vec3<f32>,
    cosine: f32,
    l: vec3<f32>,
}

// E / L of a sphere or disc of angular radius σ (sin²σ given) whose centre lies at cos θ from
// the normal, the part below the horizon clipped (Frostbite's listing 7).
fn illuminance_sphere_or_disc(cos_theta: f32, sin_sigma2: f32) -> f32 {
    let s2 = clamp(sin_sigma2, 1e-12, 1.0);
    if cos_theta * cos_theta > s2 {
        return PI * s2 * max(cos_theta, 0.0);
    }
    let sin_theta = sqrt(max(1.0 - cos_theta * cos_theta, 1e-12));
    let x = sqrt(max(1.0 / s2 - 1.0, 1e-12));
    let y = clamp(-x * cos_theta / sin_theta, -1.0, 1.0);
    let sin_theta_sqrt_y = sin_theta * sqrt(max(1.0 - y * y, 0.0));
    return max((cos_theta * acos(y) - x * sin_theta_sqrt_y) * s2 + atan(sin_theta_sqrt_y / x), 0.0);
}

fn incoming(light: PreviewLight, p: vec3<f32>, n: vec3<f32>) -> Incoming {
    var out: Incoming;
    if light.shadow.x == LIGHT_DIRECTIONAL {
        out.l = -light.direction.xyz;
        out.strength = light.color.rgb;
        out.cosine = dot(n, out.l);
        return out;
    }
    let d = light.position.xyz - p;
    let d2 = max(dot(d, d), 1e-12);
    out.l = d * inverseSqrt(d2);
    let cos_theta = dot(n, out.l);
    if light.shadow.x == LIGHT_EMITTER {
        // The flat part: a disc of area |N| facing N; the rest: a sphere of cross-section
        // (A − |N|)/4 (exact far off for a flat emitter and for a sphere).
        let flat_area = length(light.direction.xyz);
        let facing = max(dot(light.direction.xyz, -out.l), 0.0) / max(flat_area, 1e-12);
        let disc = flat_area / PI;
        let sphere = light.color.a / PI;
        out.strength = light.color.rgb;
        out.cosine = illuminance_sphere_or_disc(cos_theta, disc / (disc + d2)) * facing
            + select(0.0, illuminance_sphere_or_disc(cos_theta, min(sphere / d2, 1.0)), sphere > 0.0);
        return out;
    }
    var intensity = light.color.rgb;
    if light.shadow.x == LIGHT_SPOT {
        let c = dot(-out.l, light.direction.xyz);
        let t = clamp((c - light.direction.w) / max(light.cone.x - light.direction.w, 1e-6), 0.0, 1.0);
        intensity *= select(t * t * (3.0 - 2.0 * t), t * t, light.cone.y > 0.5);
    }
    out.strength = intensity / d2;
    out.cosine = cos_theta;
    return out;
}

// What a ray meets of the frame's emitters (`emitter_along`): the nearest one's radiance, 1 where
// it meets one (else 0), and which light that is.
struct EmitterSeen {
    radiance: vec3<f32>,
    seen: f32,
    light: u32,
}

// The nearest of the frame's emitters that the ray from `origin` along `d` meets, each as
// `incoming` lights with it: a disc of area |N| facing N and a sphere of cross-section A
// (`color.a`) about its centre.
fn emitter_along(origin: vec3<f32>, d: vec3<f32>) -> EmitterSeen {
    var nearest = 3.4e38;
    var out = EmitterSeen(vec3<f32>(0.0), 0.0, 0u);
    for (var k = 0u; k < min(view.light_count, MAX_PREVIEW_LIGHTS); k++) {
        let light = view.lights[k];
        if light.shadow.x != LIGHT_EMITTER {
            continue;
        }
        let to_center = light.position.xyz - origin;
        let flat_area = length(light.direction.xyz);
        let facing = dot(d, light.direction.xyz);
        var t = 3.4e38;
        if flat_area > 0.0 && facing < 0.0 {
            let along_normal = dot(to_center, light.direction.xyz) / facing;
            let off = origin + d * along_normal - light.position.xyz;
            if along_normal > 0.0 && dot(off, off) * PI <= flat_area {
                t = along_normal;
            }
        }
        let along = dot(to_center, d);
        let miss2 = dot(to_center, to_center) - along * along;
        if light.color.a > 0.0 && along > 0.0 && miss2 * PI <= light.color.a {
            t = min(t, along);
        }
        if t < nearest {
            nearest = t;
            out = EmitterSeen(light.color.rgb, 1.0, k);
        }
    }
    return out;
}

// How much of a smooth reflector's or glass's view of an emitter is its sharp image (the rest,
// the lights' highlight through the shadow maps; the probes hold emitters blurred over a bin): 1
// for a mirror, none from roughness `MIRROR_ROUGHNESS`. Below it GGX's highlight of a lamp is
// narrower than a pixel, and pixels sampled at their centres miss it.
const MIRROR_ROUGHNESS: f32 = 0.2;
fn mirror_share(roughness: f32) -> f32 {
    return 1.0 - smoothstep(0.0, MIRROR_ROUGHNESS, roughness);
}

struct Shaded {
    radiance: vec3<f32>,
    // How much of what lies behind shows through (transmission).
    through: f32,
}

// GGX's width along a frame's x and y (the direction of anisotropy and across it), and the
// roughness whose tables stand for the pair: that of the root-mean-square width
// √((α_x² + α_y²)/2), whose directional albedo is within 6% of the stretched lobe's (at strength
// 0.8, roughness 0.35, μ from 0.3 to 0.9; the mean width √(α_x α_y) is up to 25% above it, so
// its multiple-scattering compensation fell short: a brushed can 18% too dark). The render reads
// a table of its own (`math::anisotropic_energy`).
struct Widths {
    x: f32,
    y: f32,
    roughness: f32,
}

fn widths(roughness: f32, anisotropy: f32) -> Widths {
    let a = max(roughness * roughness, 2e-3);
    var w: Widths;
    w.x = mix(a, 1.0, anisotropy * anisotropy);
    w.y = a;
    w.roughness = select(roughness, sqrt(sqrt(0.5 * (w.x * w.x + w.y * w.y))), anisotropy > 0.0);
    return w;
}

// What a reflection shows: the environment where the probes see the sky, the surfaces they see
// elsewhere (`ahead`: [surfaces' radiance, share of the sky]).
fn reflected(sky: vec3<f32>, ahead: vec4<f32>) -> vec3<f32> {
    return sky * ahead.a + ahead.rgb;
}

// What an anisotropic reflector shows: GGX's slopes along the direction of anisotropy x spread as
// p(s) ∝ (1 + s²/α_x²)^(−3/2), so the mirror directions of five normals tilted along x at that
// distribution's quantiles 0.1, 0.3, …, 0.9 (s = 0, ±0.436 α_x, ±1.333 α_x) stand for the
// stretched lobe, each showing the environment prefiltered at the narrow width and what the probes
// about `origin` see that way (`probe_radiance_along`, blended towards `broad` as a lobe widens). A
// single bent normal, as glTF's sample viewer reads, swung a brushed floor from 30% too dark to 36%
// too bright under a sky with a sun; the probes read along the mirror direction alone left a
// brushed can, whose lobe reaches down to a lit floor, 18% too dark.
fn stretched_reflection(v: vec3<f32>, n: vec3<f32>, x: vec3<f32>, w: Widths, origin: vec3<f32>, broad: vec4<f32>) -> vec3<f32> {
    let narrow = sqrt(max(w.y, 0.3 * w.x));
    var sum = vec3<f32>(0.0);
    for (var k = 0; k < 5; k++) {
        let slope = array<f32, 5>(-1.333, -0.436, 0.0, 0.436, 1.333)[k] * w.x;
        let r = reflect(-v, normalize(n - x * slope));
        // A mirror direction below the surface sees the surface itself: the horizon instead.
        let d = normalize(r - n * min(dot(r, n), 0.0));
        var along = probe_radiance_along(origin, d);
        if reads_behind && k == 2 {
            // Along the mirror direction, what the frame shows there, where it shows it, for the
            // probes' view from elsewhere (the brushed can's sunlit floor: −16% → −15%; all five
            // directions −11%, but a march costs as much as the rest of the pixel's shading).
            let drawn = behind_along(origin, d);
            let lit = select(vec3<f32>(0.0), drawn.rgb, view.max_depth >= 3u);
            along = select(along, vec4<f32>(lit, 0.0), drawn.a > 0.0);
        }
        sum += reflected(environment(d, narrow), mix(along, broad, sqrt(w.y)));
    }
    return sum * 0.2;
}

// The layers over the base (`KHR_materials_clearcoat` and `_sheen`, stacked as the render's
// `math::layers`: coat over sheen over base). Each scales what lies below it by one minus its
// directional albedo at the view and adds its own reflection; `below` is that product.
struct Layers {
    coat: f32,
    coat_a2: f32,
    coat_roughness: f32,
    coat_albedo: f32,
    sheen: vec3<f32>,
    sheen_alpha: f32,
    sheen_albedo: f32,
    below: f32,
}

fn layers_of(o: MeshVarying, n_v: f32) -> Layers {
    var l: Layers;
    l.coat = clamp(o.layers.x, 0.0, 1.0);
    l.coat_roughness = clamp(o.layers.y, 0.0, 1.0);
    let a = max(l.coat_roughness * l.coat_roughness, 2e-3);
    l.coat_a2 = a * a;
    l.below = 1.0;
    if l.coat > 0.0 {
        // The coat is glass of IOR 1.5: F0 = 0.04.
        let ab = brdf_scale_bias(n_v, l.coat_roughness);
        l.coat_albedo = l.coat * (0.04 * ab.x + ab.y);
        l.below = 1.0 - l.coat_albedo;
    }
    l.sheen = clamp(o.sheen.rgb, vec3<f32>(0.0), vec3<f32>(1.0));
    let sheen_roughness = clamp(o.layers.z, 0.07, 1.0);
    l.sheen_alpha = sheen_roughness * sheen_roughness;
    if any(l.sheen > vec3<f32>(0.0)) {
        l.sheen_albedo = sheen_albedo(n_v, o.layers.z);
        l.below *= 1.0 - max(l.sheen.r, max(l.sheen.g, l.sheen.b)) * l.sheen_albedo;
    }
    return l;
}

// f cosθ of the layers' own lobes towards a light l (h the half vector): the coat's GGX with
// Schlick's Fresnel, and the sheen's Charlie distribution with Neubelt's visibility (the render
// fits Estevez and Kulla's Λ instead) under the coat.
fn layers_lobe(l: Layers, n: vec3<f32>, v: vec3<f32>, light: vec3<f32>, h: vec3<f32>, n_v: f32, n_l: f32) -> vec3<f32> {
    var f = vec3<f32>(0.0);
    let n_h = max(dot(n, h), 0.0);
    if l.coat > 0.0 {
        f += vec3<f32>(l.coat * ggx_d(n_h, l.coat_a2) * smith_visibility(n_v, n_l, l.coat_a2)
            * fresnel_schlick(vec3<f32>(0.04), 1.0, dot(v, h)).x);
    }
    if l.sheen_albedo > 0.0 {
        let sin2 = max(1.0 - n_h * n_h, 0.0);
        let d = (2.0 + 1.0 / l.sheen_alpha) * pow(sin2, 0.5 / l.sheen_alpha) / (2.0 * PI);
        let visibility = 1.0 / (4.0 * (n_l + n_v - n_l * n_v));
        f += l.sheen * d * visibility * (1.0 - l.coat_albedo);
    }
    return f;
}

fn shade(o: MeshVarying, base: vec3<f32>, p: vec3<f32>, n_in: vec3<f32>, aniso: vec3<f32>) -> Shaded {
    let v = normalize(view.eye.xyz - p);
    var n = n_in;
    // Two-sided: shade the side that faces the camera.
    if dot(n, v) < 0.0 {
        n = -n;
    }
    let metallic = clamp(o.params.x, 0.0, 1.0);
    let transmission = clamp(o.params.z, 0.0, 1.0) * (1.0 - metallic);
    // The frame of anisotropy: x along its direction, made orthogonal to the shading normal.
    let along = aniso - n * dot(n, aniso);
    let anisotropic = o.extra.z > 0.0 && dot(along, along) > 1e-12;
    let w = widths(clamp(o.params.y, 0.0, 1.0), select(0.0, clamp(o.extra.z, 0.0, 1.0), anisotropic));
    let roughness = w.roughness;
    var frame = mat3x3<f32>(vec3<f32>(1.0, 0.0, 0.0), vec3<f32>(0.0, 1.0, 0.0), n);
    if anisotropic {
        let x = normalize(along);
        frame = mat3x3<f32>(x, cross(n, x), n);
    }
    let a2 = w.y * w.y;
    // Schlick's Fresnel from F0 to F90: glTF's `specular` scales both for a dielectric; a metal's
    // F90 is 1; a material without a specular layer (Lambertian, emitter) has neither.
    let f0 = mix(vec3<f32>(o.params.w), base, metallic);
    let f90 = mix(o.extra.y, 1.0, metallic);
    let specular = f90 > 0.0 || any(f0 > vec3<f32>(0.0));
    let n_v = max(dot(n, v), 1e-4);
    var ab = vec2<f32>(1.0, 0.0);
    if specular {
        ab = brdf_scale_bias(n_v, roughness);
    }
    let e_spec = f0 * ab.x + vec3<f32>(f90 * ab.y);
    let e_white = max(ab.x + ab.y, 1e-3);
    let compensation = vec3<f32>(1.0) + f0 * (1.0 / e_white - 1.0);
    let diffuse = (1.0 - metallic) * (1.0 - transmission) * (vec3<f32>(1.0) - e_spec) * base / PI;
    let layers = layers_of(o, n_v);
    let layered = layers.coat > 0.0 || layers.sheen_albedo > 0.0;
    // An anisotropic lobe's highlights stay the lights' (stretched).
    let mirror = select(mirror_share(roughness), 0.0, anisotropic);
    var radiance = vec3<f32>(0.0);
    for (var i = 0u; i < min(view.light_count, MAX_PREVIEW_LIGHTS); i++) {
        let light = view.lights[i];
        let inc = incoming(light, p, n);
        if inc.cosine <= 0.0 || all(inc.strength <= vec3<f32>(0.0)) {
            continue;
        }
        // A lamp's centre may lie just below the horizon of a surface that sees part of it: its
        // glossy lobes take the light from just above.
        let n_l = max(dot(n, inc.l), 1e-3);
        var f = diffuse;
        let h = normalize(inc.l + v);
        if specular {
            // An emitter's highlight on a smooth reflector is its mirror image (below).
            var lobe = select(1.0, 1.0 - mirror, light.shadow.x == LIGHT_EMITTER);
            if anisotropic {
                let to_frame = transpose(frame);
                lobe *= ggx_d_anisotropic(to_frame * h, w) * smith_visibility_anisotropic(to_frame * v, to_frame * inc.l, w);
            } else {
                lobe *= ggx_d(max(dot(n, h), 0.0), a2) * smith_visibility(n_v, n_l, a2);
            }
            f += lobe * fresnel_schlick(f0, f90, dot(v, h)) * compensation;
        }
        if layered {
            f = f * layers.below + layers_lobe(layers, n, v, inc.l, h, n_v, n_l);
        }
        radiance += f * inc.strength * inc.cosine * shadow(light, p, n);
    }
    // Image-based light, dimmed by how much of the environment the volume's probes see, and the
    // bounce light: along the mirror direction for the specular layers (a surface without one
    // skips it), from the cosine convolution for the diffuse part and the sheen.
    let around = ambient_cube(p, n, n);
    let irradiance = irradiance_over_pi(n) * around.a + around.rgb;
    var ambient = diffuse * PI * irradiance;
    // What the specular layers reflect: the environment and the light the probes see.
    var coat_reflection = vec3<f32>(0.0);
    if specular || layers.coat > 0.0 {
        let r = reflect(-v, n);
        // Read one cell out along the reflected ray: the light the reflection meets there, not
        // the light about the surface itself (which, blurred over a coarse grid, included the
        // object's own bounce: a metal sphere alone under the sun lit itself).
        let dims = vec3<f32>(textureDimensions(probes)) / vec3<f32>(6.0, 1.0, 1.0);
        let cell = (view.probe_hi.xyz - view.probe_lo.xyz) / dims;
        let broad = cube_sides(p + r * min(cell.x, min(cell.y, cell.z)), r);
        // A sharp lobe meets what lies along r (the probes' radiance maps), a rough one the
        // cosine-weighted average about it (the ambient cube): blended by the lobe's narrower
        // width (a brushed lobe blurs along its direction of anisotropy alone; across it, the
        // line between a lit floor and the sky stays sharp).
        let origin = p + n * 0.5 * min(cell.x, min(cell.y, cell.z));
        let sharp = probe_radiance_along(origin, r);
        if specular {
            var shown = reflected(environment(r, roughness), mix(sharp, broad, sqrt(w.y)));
            if anisotropic {
                shown = stretched_reflection(v, n, frame[0], w, origin, broad);
            }
            if mirror > 0.0 {
                // The emitter the mirror direction meets, where the light reaches p.
                let lamp = emitter_along(p, r);
                let visible = select(0.0, shadow(view.lights[lamp.light], p, n), lamp.seen > 0.0);
                shown = mix(shown, lamp.radiance, mirror * visible);
            }
            if reads_behind && !anisotropic && metallic >= 0.5 {
                // What the frame shows along r, where it shows it (metals: glass reflects a few
                // percent, not worth a second march): a lit surface in a mirror takes a path of
                // three segments (below max_depth 3 it only hides the sky).
                let drawn = behind_along(p, r);
                let lit = select(vec3<f32>(0.0), drawn.rgb, view.max_depth >= 3u);
                shown = mix(shown, lit, drawn.a * sharp_share(roughness));
            }
            ambient += shown * e_spec * compensation;
        }
        if layers.coat > 0.0 {
            let ahead = mix(sharp, broad, layers.coat_roughness);
            coat_reflection = reflected(environment(r, layers.coat_roughness), ahead) * layers.coat_albedo;
        }
    }
    if layered {
        ambient = ambient * layers.below
            + layers.sheen * layers.sheen_albedo * (1.0 - layers.coat_albedo) * irradiance
            + coat_reflection;
    }
    let ior = bitcast<f32>(o.flags.w);
    let refracts = transmission > 0.0 && ior > 0.0;
    if refracts {
        ambient += transmission * (vec3<f32>(1.0) - e_spec) * base * refracted(v, n, ior, p, o.volume, roughness);
    }
    radiance += ambient + o.emission.rgb;
    var out: Shaded;
    out.radiance = radiance;
    let f = fresnel_schlick(f0, f90, n_v);
    out.through = transmission * (1.0 - dot(f, vec3<f32>(1.0 / 3.0))) * dot(base, vec3<f32>(1.0 / 3.0));
    if refracts {
        out.through = 0.0;
    }
    return out;
}
