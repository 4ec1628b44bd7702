// The raster preview (the editor's first view and `rt-cli preview`): each object shaded with the
// render's metallic-roughness model in the render's units, written as linear radiance for the
// render's view transform to display.
//
// Per light, L = (f_diffuse + f_specular) E, E = I cosθ / d² (point, spot; an emitter's I follows
// its projected area) or the sun's irradiance × cosθ, dimmed by the light's shadow map (four
// bilinear comparisons). f_specular = D G₂ F / (4 cosθo cosθi) (GGX, height-correlated Smith,
// Schlick's Fresnel from F0 to F90) scaled by 1 + F0 (1/E(μo) − 1) for the energy multiple
// scattering keeps, as the render's tables do; f_diffuse = (1 − metallic)(1 − transmission)(1 − E_spec(μo)) base/π.
// Image-based light (Karis' split sum): the environment prefiltered per roughness (`env_blur`,
// built on the CPU by `environment.rs`) times F0 A + B from the BRDF table (A + B = rt-core's GGX
// albedo table), and the cosine-convolved environment times the diffuse albedo, both dimmed by the
// share of the sky an irradiance volume's probes see; bounce light from the same probes (an
// ambient cube per probe, bounce.rs). Transmission shows what lies behind through a blended pass
// (grey, unrefracted); emitters show their emission.
// An approximation for placing things: the path tracer is the truth.

const MAX_PREVIEW_LIGHTS: u32 = 8u;
// Shadow-map layers at most (crates/preview/src/shadows.rs `MAX_SHADOW_LAYERS`).
const MAX_SHADOW_LAYERS: u32 = 14u;
const PI: f32 = 3.14159265358979;
// PreviewLight.shadow.x: crates/core/src/light_kind.rs `LightTag` (checked by the preview's tests).
const LIGHT_POINT: u32 = 1u;
const LIGHT_SPOT: u32 = 2u;
const LIGHT_DIRECTIONAL: u32 = 3u;
const LIGHT_EMITTER: u32 = 5u;
// PreviewObject.flags.y: which of the material's images it has (types.rs `image_slot`).
const TEX_BASE: u32 = 1u;
const TEX_METAL_ROUGH: u32 = 2u;
const TEX_NORMAL: u32 = 4u;
const TEX_EMISSION: u32 = 8u;
// PreviewLight.shadow.y of a light without a shadow map.
const NO_SHADOW: u32 = 0xffffffffu;
// Layers of `env_blur`: GGX-prefiltered at roughness 0.25, 0.5, 0.75, 1, then cosine-convolved.
const ENV_ROUGH_LAYERS: f32 = 4.0;
const ENV_DIFFUSE_LAYER: u32 = 4u;

struct PreviewLight {
    position: vec4<f32>,
    // rgb: W/sr (point, spot), W/m² (sun) or an emitter's radiance; a: an emitter's isotropic area.
    color: vec4<f32>,
    // xyz: spot axis, sun travel direction, or an emitter's area-weighted normal; w: cos(outer).
    direction: vec4<f32>,
    // x: cos(inner); y: 1 for glTF's squared falloff; z: a shadow-map texel's size per unit of
    // distance (a sun's: in all).
    cone: vec4<f32>,
    // x: kind; y: first shadow layer; z: layer count; w: emitting object + 1.
    shadow: vec4<u32>,
}

struct PreviewView {
    view_proj: mat4x4<f32>,
    inverse_view_proj: mat4x4<f32>,
    // xyz: camera position; w: the environment's rotation in turns.
    eye: vec4<f32>,
    // rgb: the fog's glow; a: its density.
    fog: vec4<f32>,
    // rgb: a constant environment's radiance; a: 1 when the environment is constant (no lookups).
    ambient: vec4<f32>,
    // The irradiance volume's bounds (xyz; bounce.rs).
    probe_lo: vec4<f32>,
    probe_hi: vec4<f32>,
    light_count: u32,
    // Scalars, not a vec3: a uniform would align it to 16 bytes.
    _pad0: u32,
    _pad1: u32,
    _pad2: u32,
    lights: array<PreviewLight, 8>,
}

struct PreviewObject {
    model: mat4x4<f32>,
    // Columns 0..2: the inverse transpose of the model's linear part.
    normal_matrix: mat4x4<f32>,
    // rgb: base colour; a: an alpha mask's threshold on the image's alpha.
    base_color: vec4<f32>,
    // rgb: emitted radiance; a: the material's alpha.
    emission: vec4<f32>,
    // metallic, roughness, transmission, dielectric F0.
    params: vec4<f32>,
    // x: the normal map's strength; y: the dielectric layer's F90 (glTF's `specular`; 0 without one).
    extra: vec4<f32>,
    // x: selected (outlined by outline.rs), y: its images (TEX_*), z: has vertex normals.
    flags: vec4<u32>,
    // x: the clear coat's weight, y: its roughness; z: the sheen's roughness.
    layers: vec4<f32>,
    // rgb: the sheen's colour (black: none).
    sheen: vec4<f32>,
}

@group(0) @binding(0) var<uniform> view: PreviewView;
@group(0) @binding(1) var<storage, read> objects: array<PreviewObject>;
// Each shadow-map layer's view (a uniform: read per fragment, and lavapipe loads storage one lane
// at a time).
@group(0) @binding(2) var<uniform> shadow_matrices: array<mat4x4<f32>, MAX_SHADOW_LAYERS>;
@group(0) @binding(3) var shadow_map: texture_depth_2d_array;
@group(0) @binding(4) var shadow_sampler: sampler_comparison;
@group(0) @binding(5) var env_sharp: texture_2d<f32>;
@group(0) @binding(6) var env_blur: texture_2d_array<f32>;
@group(0) @binding(7) var brdf_table: texture_2d<f32>;
@group(0) @binding(8) var linear_sampler: sampler;
// The irradiance volume: texel (axis · nx + x, y, z) holds probe (x, y, z)'s bounce irradiance/π
// (rgb) and sky visibility (a) from side axis (+x, −x, +y, −y, +z, −z).
@group(0) @binding(9) var probes: texture_3d<f32>;
// Each probe's radiance by direction (bounce.rs `IrradianceVolume::radiance`): OCT × OCT bins of
// an octahedral map, [radiance of the surfaces seen, share of the sky], probe (x, y, z)'s bin
// (i, j) at texel (x · OCT + i, (z · ny + y) · OCT + j).
@group(0) @binding(10) var probe_radiance: texture_2d<f32>;
const OCT: u32 = 6u;
// A material's images (white, or a flat normal, where it has none).
@group(1) @binding(0) var albedo_texture: texture_2d<f32>;
@group(1) @binding(1) var albedo_sampler: sampler;
@group(1) @binding(2) var metal_rough_texture: texture_2d<f32>;
@group(1) @binding(3) var normal_texture: texture_2d<f32>;
@group(1) @binding(4) var emission_texture: texture_2d<f32>;

struct MeshVertex {
    @location(0) position: vec3<f32>,
    @location(1) normal: vec3<f32>,
    @location(2) uv: vec2<f32>,
    @location(3) color: vec3<f32>,
}

// The object's material travels as flat varyings: a fragment reads no storage (lavapipe loads
// storage one lane at a time).
struct MeshVarying {
    // Invariant: the selection mask (outline.rs) draws the selected mesh again and must land on
    // the very depths the frame's pass left.
    @builtin(position) @invariant clip: vec4<f32>,
    @location(0) world: vec3<f32>,
    @location(1) normal: vec3<f32>,
    @location(2) uv: vec2<f32>,
    @location(3) @interpolate(flat) base_color: vec4<f32>,
    @location(4) @interpolate(flat) emission: vec4<f32>,
    @location(5) @interpolate(flat) params: vec4<f32>,
    @location(6) @interpolate(flat) flags: vec4<u32>,
    @location(7) color: vec3<f32>,
    @location(8) @interpolate(flat) extra: vec4<f32>,
    @location(9) @interpolate(flat) layers: vec4<f32>,
    @location(10) @interpolate(flat) sheen: vec4<f32>,
}

@vertex
fn vs_mesh(v: MeshVertex, @builtin(instance_index) object: u32) -> MeshVarying {
    let o = objects[object];
    let world = (o.model * vec4<f32>(v.position, 1.0)).xyz;
    var out: MeshVarying;
    out.clip = view.view_proj * vec4<f32>(world, 1.0);
    out.world = world;
    out.normal = mat3x3<f32>(o.normal_matrix[0].xyz, o.normal_matrix[1].xyz, o.normal_matrix[2].xyz) * v.normal;
    out.uv = v.uv;
    out.base_color = o.base_color;
    out.emission = o.emission;
    out.params = o.params;
    out.flags = o.flags;
    out.color = v.color;
    out.extra = o.extra;
    out.layers = o.layers;
    out.sheen = o.sheen;
    return out;
}

// The shadow pass: instance = layer × (objects' capacity) + object.
@vertex
fn vs_shadow(v: MeshVertex, @builtin(instance_index) instance: u32) -> @builtin(position) vec4<f32> {
    let capacity = arrayLength(&objects);
    let o = objects[instance % capacity];
    let world = o.model * vec4<f32>(v.position, 1.0);
    return shadow_matrices[instance / capacity] * world;
}

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

// The volume's probes interpolated at p, side `axis` (kept inside that side's block of texels).
fn probe(p: vec3<f32>, axis: u32) -> vec4<f32> {
    let size = vec3<f32>(textureDimensions(probes));
    let dims = vec3<f32>(size.x / 6.0, size.y, size.z);
    let extent = max(view.probe_hi.xyz - view.probe_lo.xyz, vec3<f32>(1e-6));
    let f = clamp((p - view.probe_lo.xyz) / extent, vec3<f32>(0.0), vec3<f32>(1.0)) * dims;
    let c = clamp(f, vec3<f32>(0.5), dims - vec3<f32>(0.5));
    let uvw = vec3<f32>((f32(axis) * dims.x + c.x) / size.x, c.y / size.y, c.z / size.z);
    return textureSampleLevel(probes, linear_sampler, uvw, 0.0);
}

// The bin of direction d in a probe's octahedral map (bounce.rs `oct_bin`, bit for bit).
fn oct_bin(d: vec3<f32>) -> vec2<u32> {
    let n = d / max(abs(d.x) + abs(d.y) + abs(d.z), 1e-20);
    var uv = n.xz;
    if n.y < 0.0 {
        uv = (vec2<f32>(1.0) - abs(n.zx)) * select(vec2<f32>(-1.0), vec2<f32>(1.0), n.xz >= vec2<f32>(0.0));
    }
    return min(vec2<u32>((uv * 0.5 + 0.5) * f32(OCT)), vec2<u32>(OCT - 1u));
}

// The radiance the probes about p see along d: [surfaces' radiance, share of the sky], the
// eight nearest probes' bins of d weighed trilinearly (clamped to the outer probes, as `probe`).
fn probe_radiance_along(p: vec3<f32>, d: vec3<f32>) -> vec4<f32> {
    let size = vec3<f32>(textureDimensions(probes));
    let dims = vec3<f32>(size.x / 6.0, size.y, size.z);
    let extent = max(view.probe_hi.xyz - view.probe_lo.xyz, vec3<f32>(1e-6));
    let f = clamp((p - view.probe_lo.xyz) / extent, vec3<f32>(0.0), vec3<f32>(1.0)) * dims;
    let c = clamp(f, vec3<f32>(0.5), dims - vec3<f32>(0.5)) - vec3<f32>(0.5);
    let base = vec3<u32>(floor(c));
    let t = c - floor(c);
    let last = vec3<u32>(dims) - vec3<u32>(1u);
    let bin = oct_bin(d);
    let ny = u32(dims.y);
    var sum = vec4<f32>(0.0);
    for (var k = 0u; k < 8u; k++) {
        let offset = vec3<u32>(k & 1u, (k >> 1u) & 1u, k >> 2u);
        let at = min(base + offset, last);
        let w = select(vec3<f32>(1.0) - t, t, offset == vec3<u32>(1u));
        let texel = vec2<u32>(at.x * OCT + bin.x, (at.z * ny + at.y) * OCT + bin.y);
        sum += textureLoad(probe_radiance, texel, 0) * (w.x * w.y * w.z);
    }
    return sum;
}

// Bounce irradiance/π (rgb) and sky visibility (a) towards direction d at a surface point p with
// normal n: the ambient cube's three sides facing d, weighted by d's squared components, looked up
// half a cell off the surface (so a wall's probes behind it, inside an object, weigh less).
fn ambient_cube(p: vec3<f32>, n: vec3<f32>, d: vec3<f32>) -> vec4<f32> {
    let dims = vec3<f32>(textureDimensions(probes)) / vec3<f32>(6.0, 1.0, 1.0);
    let cell = (view.probe_hi.xyz - view.probe_lo.xyz) / dims;
    let q = p + n * 0.5 * min(cell.x, min(cell.y, cell.z));
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

// Irradiance-like factor of a light at p: what multiplies (f cosθ) in L (E / cosθ), and the
// direction towards it.
struct Incoming {
    strength: vec3<f32>,
    l: vec3<f32>,
}

fn incoming(light: PreviewLight, p: vec3<f32>) -> Incoming {
    var out: Incoming;
    if light.shadow.x == LIGHT_DIRECTIONAL {
        out.l = -light.direction.xyz;
        out.strength = light.color.rgb;
        return out;
    }
    let d = light.position.xyz - p;
    let d2 = max(dot(d, d), 1e-12);
    out.l = d * inverseSqrt(d2);
    var intensity = light.color.rgb;
    if light.shadow.x == LIGHT_SPOT {
        let c = dot(-out.l, light.direction.xyz);
        let t = clamp((c - light.direction.w) / max(light.cone.x - light.direction.w, 1e-6), 0.0, 1.0);
        intensity *= select(t * t * (3.0 - 2.0 * t), t * t, light.cone.y > 0.5);
    } else if light.shadow.x == LIGHT_EMITTER {
        // Radiance × projected area towards p: the area-weighted normal's part plus an isotropic
        // part (exact for a flat emitter and for a sphere).
        intensity *= max(dot(light.direction.xyz, -out.l), 0.0) + light.color.a;
    }
    out.strength = intensity / d2;
    return out;
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

// The environment an anisotropic reflector shows: GGX's slopes along the direction of
// anisotropy x spread as p(s) ∝ (1 + s²/α_x²)^(−3/2), so the mirror directions of five normals
// tilted along x at that distribution's quantiles 0.1, 0.3, …, 0.9 (s = 0, ±0.436 α_x,
// ±1.333 α_x), each prefiltered at the narrow width, stand for the stretched lobe (a single
// bent normal, as glTF's sample viewer reads, swung a brushed floor from 30% too dark to 36% too
// bright under a sky with a sun).
fn stretched_environment(v: vec3<f32>, n: vec3<f32>, x: vec3<f32>, w: Widths) -> vec3<f32> {
    let narrow = sqrt(max(w.y, 0.3 * w.x));
    var sum = vec3<f32>(0.0);
    for (var k = 0; k < 5; k++) {
        let slope = array<f32, 5>(-1.333, -0.436, 0.0, 0.436, 1.333)[k] * w.x;
        let r = reflect(-v, normalize(n - x * slope));
        // A mirror direction below the surface sees the surface itself: the horizon instead.
        sum += environment(normalize(r - n * min(dot(r, n), 0.0)), narrow);
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
    var radiance = vec3<f32>(0.0);
    for (var i = 0u; i < min(view.light_count, MAX_PREVIEW_LIGHTS); i++) {
        let light = view.lights[i];
        let inc = incoming(light, p);
        let n_l = dot(n, inc.l);
        if n_l <= 0.0 || all(inc.strength <= vec3<f32>(0.0)) {
            continue;
        }
        var f = diffuse;
        let h = normalize(inc.l + v);
        if specular {
            var lobe = 0.0;
            if anisotropic {
                let to_frame = transpose(frame);
                lobe = ggx_d_anisotropic(to_frame * h, w) * smith_visibility_anisotropic(to_frame * v, to_frame * inc.l, w);
            } else {
                lobe = ggx_d(max(dot(n, h), 0.0), a2) * smith_visibility(n_v, n_l, a2);
            }
            f += lobe * fresnel_schlick(f0, f90, dot(v, h)) * compensation;
        }
        if layered {
            f = f * layers.below + layers_lobe(layers, n, v, inc.l, h, n_v, n_l);
        }
        radiance += f * inc.strength * n_l * shadow(light, p, n);
    }
    // Image-based light, dimmed by how much of the environment the volume's probes see, and the
    // bounce light: along the mirror direction for the specular layers (a surface without one
    // skips it), from the cosine convolution for the diffuse part and the sheen.
    let around = ambient_cube(p, n, n);
    let irradiance = irradiance_over_pi(n) * around.a + around.rgb;
    var ambient = diffuse * PI * irradiance;
    let r = reflect(-v, n);
    // Read one cell out along the reflected ray: the light the reflection meets there, not the
    // light about the surface itself (which, blurred over a coarse grid, included the object's
    // own bounce: a metal sphere alone under the sun lit itself).
    let dims = vec3<f32>(textureDimensions(probes)) / vec3<f32>(6.0, 1.0, 1.0);
    let cell = (view.probe_hi.xyz - view.probe_lo.xyz) / dims;
    let broad = ambient_cube(p + r * min(cell.x, min(cell.y, cell.z)), r, r);
    // A sharp lobe meets what lies along r (the probes' radiance maps), a rough one the
    // cosine-weighted average about it (the ambient cube): blended by the lobe's narrower width
    // (a brushed lobe blurs along its direction of anisotropy alone; across it, the line
    // between a lit floor and the sky stays sharp).
    let sharp = probe_radiance_along(p + n * 0.5 * min(cell.x, min(cell.y, cell.z)), r);
    let ahead = mix(sharp, broad, sqrt(w.y));
    if specular {
        var sky = environment(r, roughness);
        if anisotropic {
            sky = stretched_environment(v, n, frame[0], w);
        }
        ambient += reflected(sky, ahead) * e_spec * compensation;
    }
    if layered {
        ambient = ambient * layers.below
            + layers.sheen * layers.sheen_albedo * (1.0 - layers.coat_albedo) * irradiance
            + reflected(environment(r, layers.coat_roughness), mix(sharp, broad, layers.coat_roughness)) * layers.coat_albedo;
    }
    radiance += ambient + o.emission.rgb;
    var out: Shaded;
    out.radiance = radiance;
    let f = fresnel_schlick(f0, f90, n_v);
    out.through = transmission * (1.0 - dot(f, vec3<f32>(1.0 / 3.0))) * dot(base, vec3<f32>(1.0 / 3.0));
    return out;
}

// The fog between the eye and p: what lies behind dims by exp(−σ_t d) and the fog glows in its place.
fn fogged(radiance: vec3<f32>, p: vec3<f32>) -> vec3<f32> {
    let density = view.fog.a;
    if density <= 0.0 {
        return radiance;
    }
    let t = exp(-density * length(view.eye.xyz - p));
    return radiance * t + view.fog.rgb * (1.0 - t);
}

// ∂p/∂u and ∂p/∂v about n from the screen-space derivatives of p and the UVs (Schüler's cotangent
// frame, unnormalised; zero where the UVs do not vary).
fn uv_frame(n: vec3<f32>, dp: mat2x3<f32>, duv: mat2x2<f32>) -> mat2x3<f32> {
    let dp2perp = cross(dp[1], n);
    let dp1perp = cross(n, dp[0]);
    return mat2x3<f32>(dp2perp * duv[0].x + dp1perp * duv[1].x, dp2perp * duv[0].y + dp1perp * duv[1].y);
}

// The direction of anisotropy about n (`KHR_materials_anisotropy`): the tangent turned by the
// material's rotation towards the bitangent, in the frame of `normal_mapped` (the render's
// MikkTSpace tangents point along ∂p/∂u too); zero where the UVs do not vary, which shades
// isotropically.
fn anisotropy_direction(n: vec3<f32>, rotation: f32, dp: mat2x3<f32>, duv: mat2x2<f32>) -> vec3<f32> {
    let frame = uv_frame(n, dp, duv);
    let t = frame[0] - n * dot(n, frame[0]);
    let b = frame[1] - n * dot(n, frame[1]);
    if dot(t, t) <= 0.0 || dot(b, b) <= 0.0 {
        return vec3<f32>(0.0);
    }
    let d = normalize(t) * cos(rotation) + normalize(b) * sin(rotation);
    return select(vec3<f32>(0.0), normalize(d), dot(d, d) > 1e-12);
}

// A tangent-space normal map's normal (x, y scaled by `strength`) in the frame of the UVs'
// screen-space derivatives about n (Schüler's cotangent frame: no tangents stored; v up, as the
// render's MikkTSpace frame).
fn normal_mapped(n: vec3<f32>, texel: vec3<f32>, strength: f32, dp: mat2x3<f32>, duv: mat2x2<f32>) -> vec3<f32> {
    let frame = uv_frame(n, dp, duv);
    let t = frame[0];
    let b = frame[1];
    let scale = max(dot(t, t), dot(b, b));
    if scale <= 0.0 {
        return n;
    }
    let m = (texel * 2.0 - vec3<f32>(1.0)) * vec3<f32>(strength, strength, 1.0);
    let mapped = (t * m.x + b * m.y) * inverseSqrt(scale) + n * m.z;
    return select(n, normalize(mapped), dot(mapped, mapped) > 0.0);
}

fn surface(in: MeshVarying) -> vec4<f32> {
    // Derivatives and texture sampling need uniform control flow: take them first.
    let dp = mat2x3<f32>(dpdx(in.world), dpdy(in.world));
    let duv = mat2x2<f32>(dpdx(in.uv), dpdy(in.uv));
    let face = cross(dp[0], dp[1]);
    var o = in;
    // The images have one level each: sampled at it, only where the material has them (a texture
    // lookup is a good part of a fragment's cost on lavapipe).
    var sampled = vec4<f32>(1.0);
    if (o.flags.y & TEX_BASE) != 0u {
        sampled = textureSampleLevel(albedo_texture, albedo_sampler, in.uv, 0.0);
    }
    var metal_rough = vec4<f32>(1.0);
    if (o.flags.y & TEX_METAL_ROUGH) != 0u {
        metal_rough = textureSampleLevel(metal_rough_texture, albedo_sampler, in.uv, 0.0);
    }
    var glow = vec3<f32>(1.0);
    if (o.flags.y & TEX_EMISSION) != 0u {
        glow = textureSampleLevel(emission_texture, albedo_sampler, in.uv, 0.0).rgb;
    }
    if sampled.a < o.base_color.a {
        discard;
    }
    var n = normalize(face);
    if o.flags.z != 0u && dot(in.normal, in.normal) > 0.0 {
        n = normalize(in.normal);
    }
    let to_eye = normalize(view.eye.xyz - in.world);
    if (o.flags.y & TEX_NORMAL) != 0u {
        // Tilted about the side that faces the camera, as the render's two-sided shading sees it.
        let bump = textureSampleLevel(normal_texture, albedo_sampler, in.uv, 0.0).rgb;
        let facing = select(-n, n, dot(n, to_eye) >= 0.0);
        n = normal_mapped(facing, bump, o.extra.x, dp, duv);
    }
    // glTF's factors times their images: base colour (and the vertex colour), roughness in green
    // and metallic in blue, emission.
    let base = o.base_color.rgb * sampled.rgb * in.color;
    o.params.x *= metal_rough.b;
    o.params.y *= metal_rough.g;
    o.emission = vec4<f32>(o.emission.rgb * glow, o.emission.a);
    var aniso = vec3<f32>(0.0);
    if o.extra.z > 0.0 {
        aniso = anisotropy_direction(n, o.extra.w, dp, duv);
    }
    let shaded = shade(o, base, in.world, n, aniso);
    let radiance = fogged(shaded.radiance, in.world);
    // Premultiplied by the material's alpha; the blended pass keeps 1 − a of what lies behind.
    let alpha = o.emission.a * sampled.a;
    return vec4<f32>(radiance * alpha, alpha * (1.0 - shaded.through));
}

@fragment
fn fs_mesh(in: MeshVarying) -> @location(0) vec4<f32> {
    return surface(in);
}

// The selection mask (outline.rs): 1 where the selected object is the nearest surface.
@fragment
fn fs_mask(in: MeshVarying) -> @location(0) vec4<f32> {
    return vec4<f32>(1.0);
}

// The background: the environment seen along each pixel's view ray (a full-screen triangle at the
// far plane).
struct BackgroundVarying {
    @builtin(position) clip: vec4<f32>,
    @location(0) ndc: vec2<f32>,
}

@vertex
fn vs_background(@builtin(vertex_index) index: u32) -> BackgroundVarying {
    let x = f32((index << 1u) & 2u) * 2.0 - 1.0;
    let y = f32(index & 2u) * 2.0 - 1.0;
    var out: BackgroundVarying;
    out.clip = vec4<f32>(x, y, 1.0, 1.0);
    out.ndc = vec2<f32>(x, y);
    return out;
}

@fragment
fn fs_background(in: BackgroundVarying) -> @location(0) vec4<f32> {
    let far = view.inverse_view_proj * vec4<f32>(in.ndc, 1.0, 1.0);
    let near = view.inverse_view_proj * vec4<f32>(in.ndc, 0.0, 1.0);
    let d = normalize(far.xyz / far.w - near.xyz / near.w);
    var radiance = environment(d, 0.0);
    if view.fog.a > 0.0 {
        // Rays that leave the scene travel on through the fog: all glow.
        radiance = view.fog.rgb;
    }
    return vec4<f32>(radiance, 1.0);
}

struct GridVertex {
    @location(0) position: vec3<f32>,
    @location(1) color: vec4<f32>,
}

struct GridVarying {
    @builtin(position) clip: vec4<f32>,
    @location(0) color: vec4<f32>,
}

fn srgb_decode(c: vec3<f32>) -> vec3<f32> {
    let lo = c / 12.92;
    let hi = pow((c + 0.055) / 1.055, vec3<f32>(2.4));
    return select(hi, lo, c <= vec3<f32>(0.04045));
}

@vertex
fn vs_grid(v: GridVertex) -> GridVarying {
    var out: GridVarying;
    out.clip = view.view_proj * vec4<f32>(v.position, 1.0);
    out.color = vec4<f32>(srgb_decode(v.color.rgb), v.color.a);
    return out;
}

@fragment
fn fs_grid(in: GridVarying) -> @location(0) vec4<f32> {
    return vec4<f32>(in.color.rgb * in.color.a, in.color.a);
}
