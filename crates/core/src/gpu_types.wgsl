// GPU structs. Rust mirrors: crates/core/src/gpu_types.rs (offsets checked by tests/shaders.rs).

const MAT_LAMBERTIAN: u32 = 0u;
const MAT_METAL: u32 = 1u;
const MAT_DIELECTRIC: u32 = 2u;
const MAT_EMISSIVE: u32 = 3u;
const MAT_PBR: u32 = 4u;
const NO_TEXTURE: u32 = 0xffffffffu;
const MISS: u32 = 0xffffffffu;
const HAS_NORMALS: u32 = 1u;
const HAS_COLORS: u32 = 2u;

struct Triangle {
    v0: vec3<f32>,       // 0
    material: u32,       // 12
    v1: vec3<f32>,       // 16
    has_normals: u32,    // 28: bit 0 HAS_NORMALS, bit 1 HAS_COLORS
    v2: vec3<f32>,       // 32
    has_uvs: u32,        // 44
}

struct Shading {
    n0: vec3<f32>,       // 0
    c0: u32,             // 12: corner colours, RGBA8 sRGB (white without vertex colours)
    n1: vec3<f32>,       // 16
    c1: u32,             // 28
    n2: vec3<f32>,       // 32
    c2: u32,             // 44
    uv0: vec2<f32>,      // 48
    uv1: vec2<f32>,      // 56
    uv2: vec2<f32>,      // 64
    _pad3: vec2<f32>,    // 72
}

// Where a material's image lies in `texels` (NO_TEXTURE: none).
struct TextureSlot {
    offset: u32,             // 0
    width: u32,              // 4
    height: u32,             // 8
}

// The tag `kind` (MAT_*) selects the BSDF, which reads its parameter block from `lobe` through its
// decoder below (metal_lobe, dielectric_lobe, pbr_lobe); the rest means the same for every kind.
struct Material {
    color: vec3<f32>,        // 0: albedo, metal reflectance, glass tint or PBR base colour
    kind: u32,               // 12
    emission: vec3<f32>,     // 16
    flags: u32,              // 28: bit 0 THIN_WALLED, 1 ALPHA_MASK, 2 ALPHA_BLEND, 3 TANGENTS, 4 SHADOW_CATCHER
    lobe: array<vec4<f32>, 8>,  // 32: the kind's parameter block
    alpha: f32,              // 160: the coverage factor
    alpha_cutoff: f32,       // 164
    samplers: array<u32, 3>, // 168: SAMPLER_BITS a slot (wrap s, wrap t, nearest), 6 a word
    textures: array<TextureSlot, 16>,  // 180: by SLOT_*
    _pad: array<u32, 3>,     // 372
    medium: Medium,          // 384: inside a closed transmissive surface (zero: vacuum)
}

// gpu_types.rs `Medium`: a homogeneous participating medium (math/medium.wgsl).
struct Medium {
    sigma_t: vec3<f32>,      // 0: extinction per scene unit
    anisotropy: f32,         // 12: Henyey-Greenstein g
    sigma_s: vec3<f32>,      // 16: scattering
    _pad: f32,               // 28
}

// The kinds' parameter blocks: the words of Material.lobe in order (core::gpu_types::*Lobe).
struct MetalLobe {
    fuzz: f32,               // 0
}

struct DielectricLobe {
    ior: f32,                // 0
}

struct PbrLobe {
    metallic: f32,           // 0
    roughness: f32,          // 4
    transmission: f32,       // 8
    ior: f32,                // 12
    _pad0: vec3<f32>,        // 16: unused (the volume's absorption is Material.medium)
    normal_scale: f32,       // 28
    specular_color: vec3<f32>,  // 32: KHR_materials_specular's colour (scales F0)
    specular: f32,           // 44: its strength (scales F0 and F90)
    sheen_color: vec3<f32>,  // 48: black: no sheen
    sheen_roughness: f32,    // 60
    clearcoat: f32,          // 64: 0: no coat
    clearcoat_roughness: f32,  // 68
    clearcoat_normal_scale: f32,  // 72
    diffuse_transmission: f32,  // 76: KHR_materials_diffuse_transmission's share
    diffuse_transmission_color: vec3<f32>,  // 80
    iridescence: f32,        // 92: KHR_materials_iridescence's weight
    iridescence_ior: f32,    // 96
    iridescence_thickness_min: f32,  // 100: nm
    iridescence_thickness_max: f32,  // 104
    anisotropy: f32,         // 108: KHR_materials_anisotropy's strength
    anisotropy_rotation: f32,  // 112: radians from the tangent
    dispersion: f32,         // 116: KHR_materials_dispersion's 20 / V_d
    _pad: array<f32, 2>,     // 120
}

fn metal_lobe(m: Material) -> MetalLobe {
    return MetalLobe(m.lobe[0].x);
}

fn dielectric_lobe(m: Material) -> DielectricLobe {
    return DielectricLobe(m.lobe[0].x);
}

fn pbr_lobe(m: Material) -> PbrLobe {
    return PbrLobe(m.lobe[0].x, m.lobe[0].y, m.lobe[0].z, m.lobe[0].w, m.lobe[1].xyz, m.lobe[1].w,
                   m.lobe[2].xyz, m.lobe[2].w, m.lobe[3].xyz, m.lobe[3].w, m.lobe[4].x, m.lobe[4].y,
                   m.lobe[4].z, m.lobe[4].w, m.lobe[5].xyz, m.lobe[5].w,
                   m.lobe[6].x, m.lobe[6].y, m.lobe[6].z, m.lobe[6].w, m.lobe[7].x,
                   m.lobe[7].y, array<f32, 2>(0.0, 0.0));
}

const THIN_WALLED: u32 = 1u;
const ALPHA_MASK: u32 = 2u;
const ALPHA_BLEND: u32 = 4u;
const TANGENTS: u32 = 8u;
const SHADOW_CATCHER: u32 = 16u;
const SLOT_BASE: u32 = 0u;
const SLOT_METALLIC_ROUGHNESS: u32 = 1u;
const SLOT_NORMAL: u32 = 2u;
const SLOT_EMISSION: u32 = 3u;
const SLOT_CLEARCOAT: u32 = 4u;
const SLOT_CLEARCOAT_ROUGHNESS: u32 = 5u;
const SLOT_SHEEN_COLOR: u32 = 6u;
const SLOT_SHEEN_ROUGHNESS: u32 = 7u;
const SLOT_SPECULAR: u32 = 8u;
const SLOT_SPECULAR_COLOR: u32 = 9u;
const SLOT_CLEARCOAT_NORMAL: u32 = 10u;
const SLOT_ANISOTROPY: u32 = 11u;
const SLOT_DIFFUSE_TRANSMISSION: u32 = 12u;
const SLOT_DIFFUSE_TRANSMISSION_COLOR: u32 = 13u;
const SLOT_IRIDESCENCE: u32 = 14u;
const SLOT_IRIDESCENCE_THICKNESS: u32 = 15u;
const SAMPLER_BITS: u32 = 5u;
const SLOTS_PER_WORD: u32 = 6u;

// Slot `slot`'s sampler bits (its low SAMPLER_BITS bits; the rest are the next slots').
fn sampler_bits(m: Material, slot: u32) -> u32 {
    return m.samplers[slot / SLOTS_PER_WORD] >> (SAMPLER_BITS * (slot % SLOTS_PER_WORD));
}

// An environment texel with its alias-table entry (core::gpu_types::EnvTexel).
struct EnvTexel {
    radiance: vec3<f32>,     // 0
    pdf: f32,                // 12
    alias_index: u32,        // 16
    threshold: f32,          // 20
    _pad: vec2<u32>,         // 24
}

// Both children of an inner node; a child with count > 0 is a leaf of triangles index..index+count.
struct BvhNode {
    left_min: vec3<f32>,    // 0
    left: u32,              // 12
    left_max: vec3<f32>,    // 16
    left_count: u32,        // 28
    right_min: vec3<f32>,   // 32
    right: u32,             // 44
    right_max: vec3<f32>,   // 48
    right_count: u32,       // 60
}

// A compressed wide BVH8 node (core::gpu_types::WideBvhNode): child boxes quantised to bytes, four
// children's bytes to a word.
struct WideBvhNode {
    origin: vec3<f32>,         // 0
    exponents_imask: u32,      // 12
    child_base: u32,           // 16
    primitive_base: u32,       // 20
    slots: vec2<u32>,           // 24
    lo_x: vec2<u32>,           // 32
    hi_x: vec2<u32>,           // 40
    lo_y: vec2<u32>,           // 48
    hi_y: vec2<u32>,           // 56
    lo_z: vec2<u32>,           // 64
    hi_z: vec2<u32>,           // 72
}

struct Frame {
    cam_origin: vec3<f32>,       // 0
    lens_radius: f32,            // 12
    cam_u: vec3<f32>,            // 16
    focus_distance: f32,         // 28
    cam_v: vec3<f32>,            // 32
    tan_half_vfov: f32,          // 44
    cam_w: vec3<f32>,            // 48
    aspect: f32,                 // 60
    ambient: vec3<f32>,          // 64
    max_depth: u32,              // 76
    width: u32,                  // 80
    height: u32,                 // 84
    seed: u32,                   // 88
    sample_base: u32,            // 92
    samples_this_dispatch: u32,  // 96
    row_begin: u32,              // 100
    row_end: u32,                // 104
    emitter_count: u32,          // 108
    emitter_power_inv: f32,      // 112
    roulette_from_depth: u32,    // 116
    tile_row_begin: u32,         // 120
    tile_row_end: u32,           // 124
    sampler: u32,                // 128: 0 independent, 1 Sobol (the kernel uses the SOBOL constant)
    nee_only: u32,               // 132: 0 MIS (power heuristic), 1 next-event estimation only
    offset_scale: f32,           // 136: see offset_ray_origin
    active_begin: u32,           // 140: adaptive wavefront waves: their pixels' place in active_slots
    active_count: u32,           // 144
    env_width: u32,              // 148: 0 without an environment map
    env_height: u32,             // 152
    env_rotation: f32,           // 156: turns about +y
    env_pick: f32,               // 160: probability that next-event estimation samples the environment
    sample_offset: u32,          // 164: the render's first sample index (a shard's range start)
    clamp_max: f32,              // 168: the firefly clamp on bounced light (0: off)
    light_sampler: u32,          // 172: 0 emitters by power (alias table), 1 by the light tree
    fog: Medium,                 // 176: the medium outside closed objects (zero: vacuum)
    camera_media: u32,           // 208: the medium stack camera rays start with (path.rs media_top)
    projection: u32,             // 212: 0 perspective, 1 orthographic, 2 panorama, 3 fisheye (PROJECTION_*)
    projection_scale: f32,       // 216: orthographic half height; fisheye half angle (radians)
    film_x: u32,                 // 220: the image is a window of the film at (film_x, film_y) ...
    film_y: u32,                 // 224
    film_width: u32,             // 228: ... of the film's size (path.wgsl film_pixel)
    film_height: u32,            // 232
    transparent: u32,            // 236: 1: the background seen directly adds nothing (alpha)
}

struct Emitter {
    triangle: u32,    // 0
    alias_index: u32,       // 4
    threshold: f32,   // 8
    leaf: u32,        // 12: where it sits in the light tree: 4 x node + slot
}

// gpu_types.rs `LightNode`: a four-wide node of the light tree (light_tree.rs), one lane a slot.
struct LightNode {
    centre_x: vec4<f32>,     // 0
    centre_y: vec4<f32>,     // 16
    centre_z: vec4<f32>,     // 32
    axis_x: vec4<f32>,       // 48
    axis_y: vec4<f32>,       // 64
    axis_z: vec4<f32>,       // 80
    power: vec4<f32>,        // 96: 0 for an empty slot
    cos_theta_o: vec4<f32>,  // 112
    sin_theta_o: vec4<f32>,  // 128
    cos_theta_e: vec4<f32>,  // 144
    radius: vec4<f32>,       // 160
    child: vec4<u32>,        // 176: child node, or a leaf slot's emitter triangle
    leaves: u32,             // 192: bit i: slot i is a leaf
    parent: u32,             // 196: 4 x parent node + slot there
    _pad: vec2<u32>,         // 200
}

struct Ray {
    origin: vec3<f32>,     // 0
    t_max: f32,            // 12
    direction: vec3<f32>,  // 16
    _pad: f32,             // 28
}

struct Hit {
    t: f32,          // 0
    triangle: u32,   // 4
    b1: f32,         // 8
    b2: f32,         // 12
    instance: u32,   // 16: NO_INSTANCE (the kernels trace world-space triangles only, so far)
}

const NO_INSTANCE: u32 = 0xffffffffu;

// One placed copy of a shared mesh: rows of 3x4 affine matrices, a point p going to
// dot(r.xyz, p) + r.w per row r. Rust mirror: rt_core::instances::Instance.
struct Instance {
    to_object: array<vec4<f32>, 3>, // 0: world to the mesh's space
    to_world: array<vec4<f32>, 3>,  // 48: the mesh's space to world
    root: u32,                      // 96: its mesh's BVH root
    material: u32,                  // 100: the object it draws
    mirrored: u32,                  // 104: 1 where the transform mirrors
    first_triangle: u32,            // 108: its mesh's first triangle in `triangles`
}


// DeltaLight.kind: crates/core/src/light_kind.rs `LightTag` (tests/shaders.rs checks the values).
const LIGHT_NONE: u32 = 0u;
const LIGHT_POINT: u32 = 1u;
const LIGHT_SPOT: u32 = 2u;
const LIGHT_DIRECTIONAL: u32 = 3u;
const LIGHT_SPOT_GLTF: u32 = 4u;

// A point, spot or directional light; see crates/core/src/light.rs for the units.
struct DeltaLight {
    position: vec3<f32>,         // 0
    kind: u32,                   // 12
    direction: vec3<f32>,        // 16
    cos_inner: f32,              // 28
    power: vec3<f32>,            // 32
    cos_outer: f32,              // 44
}
