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
// ambient cube per probe, bounce.rs). A thin transmitting sheet shows what lies behind through a
// blended pass (grey, unrefracted); solid glass, drawn after the opaque pass, what it drew along
// its refracted view, else the emitters, probes and environment there (preview_glass.wgsl);
// emitters show their emission.
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
    // The render's max_depth (what solid glass shows through it at that depth: `refracted`).
    max_depth: u32,
    // Scalars, not a vec3: a uniform would align it to 16 bytes.
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
    // Solid glass: rgb, its volume's attenuation per unit length; a: its bounding radius.
    volume: vec4<f32>,
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
// Each probe's radiance by direction (bounce.rs `IrradianceVolume::radiance`): BANDS × AZIMUTHS
// bins (`direction_bin`), [radiance of the surfaces seen, share of the sky], bin b of probe
// (x, y, z) at texel (b · nx + x, y, z).
@group(0) @binding(10) var probe_radiance: texture_3d<f32>;
const BANDS: u32 = 6u;
const AZIMUTHS: u32 = 8u;
// How far off a surface, in cells, `ambient_cube` looks the probes up (bounce.rs).
const PROBE_LOOKUP_LIFT: f32 = 0.25;
// The frame as drawn before solid glass and smooth metals (crates/preview/src/behind.rs), which
// their pass reads along refracted and reflected view rays; only `fs_reading` reads it
// (`reads_behind`).
@group(0) @binding(11) var behind_color: texture_2d<f32>;
@group(0) @binding(12) var behind_depth: texture_depth_2d;
var<private> reads_behind: bool = false;
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
    @location(11) @interpolate(flat) volume: vec4<f32>,
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
    out.volume = o.volume;
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

// Solid glass and smooth metals over the frame drawn before them, which they show bent through
// them (`refracted`) or mirrored (`shade`).
@fragment
fn fs_reading(in: MeshVarying) -> @location(0) vec4<f32> {
    reads_behind = true;
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
