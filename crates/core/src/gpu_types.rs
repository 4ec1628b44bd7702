//! Plain-old-data mirrors of the WGSL structs in `gpu_types.wgsl` beside it.
//!
//! Every type here is uploaded byte-for-byte, so each field carries its byte offset as a comment and
//! `tests/shaders.rs` checks size, alignment, member names and offsets against what naga reports.

/// The WGSL twin of this module, `gpu_types.wgsl` beside it (composed into the kernels by
/// `rt_gpu::shaders`).
pub const WGSL: &str = include_str!("gpu_types.wgsl");

use bytemuck::{Pod, Zeroable};

mod layouts;
pub(crate) use layouts::gpu_struct;
pub use layouts::{GpuStruct, StructLayout, layouts};

/// `Triangle.has_normals` bits.
pub const HAS_NORMALS: u32 = 1;
pub const HAS_COLORS: u32 = 2;

/// Words in one vertex's shading record in `GpuScene::shading` (`crate::corner_records`): normal
/// x, y, z, colour, u, v.
pub const CORNER_WORDS: usize = 6;

/// A triangle's corner words in `GpuScene::shading` where it has no shading attributes.
pub const NO_RECORD: u32 = u32::MAX;

/// A linear RGB colour packed as the kernels read vertex colours: sRGB-encoded bytes, A = 255.
pub fn pack_color(c: [f32; 3]) -> u32 {
    let b = c.map(|v| (crate::output::linear_to_srgb(v.clamp(0.0, 1.0)) * 255.0 + 0.5) as u32);
    b[0] | (b[1] << 8) | (b[2] << 16) | (255 << 24)
}

/// `TextureSlot::offset` of an empty slot.
pub const NO_TEXTURE: u32 = u32::MAX;

gpu_struct! {
/// One triangle's vertices in world space, in BVH leaf order.
#[repr(C, align(16))]
#[derive(Clone, Copy, Debug, Default, PartialEq, Pod, Zeroable)]
pub struct Triangle {
    pub v0: [f32; 3],  // 0
    pub material: u32, // 12
    pub v1: [f32; 3],  // 16
    /// Bit 0 (`HAS_NORMALS`): `Shading` holds vertex normals (flat shading without);
    /// bit 1 (`HAS_COLORS`): it holds vertex colours.
    pub has_normals: u32, // 28
    pub v2: [f32; 3],  // 32
    /// 1 when `Shading` holds texture coordinates.
    pub has_uvs: u32, // 44
}
}

gpu_struct! {
/// Per-vertex shading attributes of the triangle with the same index.
#[repr(C, align(16))]
#[derive(Clone, Copy, Debug, Default, PartialEq, Pod, Zeroable)]
pub struct Shading {
    pub n0: [f32; 3], // 0
    /// Corner 0's vertex colour, RGBA8 sRGB-encoded (R in the low byte), white without colours.
    pub c0: u32, // 12
    pub n1: [f32; 3], // 16
    pub c1: u32,      // 28
    pub n2: [f32; 3], // 32
    pub c2: u32,      // 44
    pub uv0: [f32; 2], // 48
    pub uv1: [f32; 2], // 56
    pub uv2: [f32; 2], // 64
    pub _pad3: [f32; 2], // 72
}
}

gpu_struct! {
/// Where one of a material's images lies in the texel buffer; `offset` is `NO_TEXTURE` when the
/// slot is empty.
#[repr(C)]
#[derive(Clone, Copy, Debug, PartialEq, Pod, Zeroable)]
pub struct TextureSlot {
    pub offset: u32, // 0
    pub width: u32,  // 4
    pub height: u32, // 8
}
}

impl TextureSlot {
    pub const NONE: TextureSlot = TextureSlot {
        offset: NO_TEXTURE,
        width: 0,
        height: 0,
    };

    pub fn is_empty(&self) -> bool {
        self.offset == NO_TEXTURE
    }
}

impl Default for TextureSlot {
    fn default() -> Self {
        TextureSlot::NONE
    }
}

gpu_struct! {
/// A material as the kernel sees it: the tag `kind` (`MaterialKind::tag`) selects the BSDF, which
/// reads its parameters from `lobe` through its own block type (`MetalLobe`, `DielectricLobe`,
/// `PbrLobe`); the rest means the same for every kind.
#[repr(C, align(16))]
#[derive(Clone, Copy, Debug, PartialEq, Pod, Zeroable)]
pub struct Material {
    /// The colour the surface scatters with (times the base colour image and vertex colours): the
    /// Lambertian albedo, the metal's reflectance, the glass's transmission tint, the PBR base colour.
    pub color: [f32; 3], // 0
    pub kind: u32, // 12
    /// Radiance emitted from the front face (any kind may emit; `Emissive` also absorbs), times the
    /// emission image.
    pub emission: [f32; 3], // 16
    /// Bit 0 (`THIN_WALLED`) thin-walled transmission; bits 1–2 (`ALPHA_MASK`, `ALPHA_BLEND`) the
    /// alpha mode; bit 3 (`TANGENTS`) its triangles carry tangents (`GpuScene::tangents`); bit 4
    /// (`SHADOW_CATCHER`) it catches shadows.
    pub flags: u32, // 28
    /// The kind's parameter block, written and read only as that kind's block type (`lobe_of`).
    pub lobe: [[f32; 4]; LOBE_VEC4S], // 32
    /// The coverage factor (times the base colour image's alpha).
    pub alpha: f32, // 160
    /// With `ALPHA_MASK`: coverage below this is a hole.
    pub alpha_cutoff: f32, // 164
    /// Each texture slot's sampler (`TextureSampler::bits`), 5 bits a slot, six slots a word:
    /// slot `i` at bit `5 (i mod 6)` of word `i / 6`.
    pub samplers: [u32; 3], // 168
    /// The images, indexed by `SLOT_*`: base colour (sRGB), metallic-roughness (B metal, G rough;
    /// linear), tangent-space normals (linear), emission (sRGB), then the layers' (`SLOT_*` says
    /// which channel each reads).
    pub textures: [TextureSlot; SLOTS], // 180
    pub _pad: [u32; 3], // 372
    /// The medium inside a closed surface that transmits (entered on transmission through its
    /// front face, left through its back face; `estimator::path`): glTF's volume attenuation and
    /// scattering. Zero: vacuum.
    pub medium: Medium, // 384
}
}

gpu_struct! {
/// A homogeneous participating medium (`math::medium`): per scene unit, its extinction
/// σ_t = σ_a + σ_s and scattering σ_s per channel, and the Henyey–Greenstein anisotropy g of its
/// phase function. All zero: vacuum.
#[repr(C, align(16))]
#[derive(Clone, Copy, Debug, Default, PartialEq, Pod, Zeroable)]
pub struct Medium {
    pub sigma_t: [f32; 3], // 0
    pub anisotropy: f32,   // 12
    pub sigma_s: [f32; 3], // 16
    pub _pad: f32,         // 28
}
}

/// How many texture slots a material has.
pub const SLOTS: usize = 16;

/// The size of `Material::lobe` in 16-byte words: the largest kind's block (`PbrLobe`).
pub const LOBE_VEC4S: usize = 8;

impl Default for Material {
    fn default() -> Self {
        Material {
            color: [0.0; 3],
            kind: 0,
            emission: [0.0; 3],
            flags: 0,
            lobe: [[0.0; 4]; LOBE_VEC4S],
            alpha: 1.0,
            alpha_cutoff: 0.0,
            samplers: [0; 3],
            textures: [TextureSlot::NONE; SLOTS],
            _pad: [0; 3],
            medium: Medium::default(),
        }
    }
}

impl Material {
    /// The material's texture slot `slot` (`SLOT_*`).
    pub fn texture(&self, slot: u32) -> TextureSlot {
        self.textures[slot as usize]
    }

    /// Slot `slot`'s sampler bits.
    pub fn sampler_bits(&self, slot: u32) -> u32 {
        (self.samplers[(slot / SLOTS_PER_WORD) as usize]
            >> (SAMPLER_BITS * (slot % SLOTS_PER_WORD)))
            & ((1 << SAMPLER_BITS) - 1)
    }

    /// Sets slot `slot`'s sampler bits.
    pub fn set_sampler_bits(&mut self, slot: u32, bits: u32) {
        self.samplers[(slot / SLOTS_PER_WORD) as usize] |=
            bits << (SAMPLER_BITS * (slot % SLOTS_PER_WORD));
    }

    /// The parameter block of this material's kind, as `L` lays it out (the WGSL reads the same
    /// words in the same order: `pbr_lobe` and its siblings in `gpu_types.wgsl`).
    pub fn lobe_of<L: Lobe>(&self) -> L {
        bytemuck::pod_read_unaligned(&bytemuck::bytes_of(&self.lobe)[..size_of::<L>()])
    }

    /// Writes `lobe` as this material's parameter block.
    pub fn set_lobe<L: Lobe>(&mut self, lobe: L) {
        self.lobe = [[0.0; 4]; LOBE_VEC4S];
        bytemuck::bytes_of_mut(&mut self.lobe)[..size_of::<L>()]
            .copy_from_slice(bytemuck::bytes_of(&lobe));
    }
}

/// A kind's parameter block in `Material::lobe` (at most its `16 LOBE_VEC4S` bytes, all `f32`s).
pub trait Lobe: Pod {}

const _: () = assert!(
    size_of::<MetalLobe>() <= 16 * LOBE_VEC4S
        && size_of::<DielectricLobe>() <= 16 * LOBE_VEC4S
        && size_of::<PbrLobe>() <= 16 * LOBE_VEC4S
);

gpu_struct! {
/// `MaterialKind::Metal`'s parameters.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, Pod, Zeroable)]
pub struct MetalLobe {
    /// The radius of the ball perturbing the mirror direction, in [0, 1].
    pub fuzz: f32, // 0
}
}
impl Lobe for MetalLobe {}

gpu_struct! {
/// `MaterialKind::Dielectric`'s parameters.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, Pod, Zeroable)]
pub struct DielectricLobe {
    pub ior: f32, // 0
}
}
impl Lobe for DielectricLobe {}

gpu_struct! {
/// `MaterialKind::Pbr`'s parameters (`math::bsdf`).
#[repr(C, align(16))]
#[derive(Clone, Copy, Debug, Default, PartialEq, Pod, Zeroable)]
pub struct PbrLobe {
    /// In [0, 1], times the metallic-roughness image's blue.
    pub metallic: f32, // 0
    /// In [0, 1] (α = roughness²), times the metallic-roughness image's green.
    pub roughness: f32, // 4
    /// Specular transmission in [0, 1].
    pub transmission: f32, // 8
    pub ior: f32, // 12
    /// Unused (the volume's absorption is `Material::medium`).
    pub _pad0: [f32; 3], // 16
    /// The normal map's xy scale.
    pub normal_scale: f32, // 28
    /// `KHR_materials_specular`'s colour: scales the dielectric F0 (which stays ≤ 1).
    pub specular_color: [f32; 3], // 32
    /// `KHR_materials_specular`'s strength in [0, 1]: scales the dielectric F0 and F90.
    pub specular: f32, // 44
    /// The sheen layer's colour (`math::sheen`; black: no sheen).
    pub sheen_color: [f32; 3], // 48
    /// The sheen's roughness in [0, 1] (α = roughness²).
    pub sheen_roughness: f32, // 60
    /// The clear coat's weight in [0, 1] (`math::coat`; 0: no coat).
    pub clearcoat: f32, // 64
    /// The clear coat's roughness in [0, 1] (α = roughness²).
    pub clearcoat_roughness: f32, // 68
    /// The coat's normal map's xy scale.
    pub clearcoat_normal_scale: f32, // 72
    /// `KHR_materials_diffuse_transmission`: the share of the diffuse lobe sent through to the
    /// other side, in [0, 1].
    pub diffuse_transmission: f32, // 76
    /// The colour of the diffusely transmitted light.
    pub diffuse_transmission_color: [f32; 3], // 80
    /// `KHR_materials_iridescence`'s weight in [0, 1] (`math::iridescence`).
    pub iridescence: f32, // 92
    /// The thin film's index of refraction.
    pub iridescence_ior: f32, // 96
    /// The film's thickness in nanometres (its image's green picks between these two).
    pub iridescence_thickness_min: f32, // 100
    pub iridescence_thickness_max: f32, // 104
    /// `KHR_materials_anisotropy`'s strength in [0, 1] (`microfacet::anisotropic_alpha`), times
    /// its image's blue.
    pub anisotropy: f32, // 108
    /// The direction of anisotropy: radians counter-clockwise from the tangent (after its image's
    /// direction).
    pub anisotropy_rotation: f32, // 112
    /// `KHR_materials_dispersion`'s 20 / V_d (`math::dispersion`; 0: none).
    pub dispersion: f32, // 116
    pub _pad: [f32; 2], // 120
}
}
impl Lobe for PbrLobe {}

/// `Material.flags` bits.
pub const THIN_WALLED: u32 = 1;
/// The surface is a hole where its coverage is below `alpha_cutoff` (glTF's MASK).
pub const ALPHA_MASK: u32 = 2;
/// The surface stops a ray with probability equal to its coverage (glTF's BLEND, rendered as
/// stochastic transparency: a hashed coin per ray and triangle).
pub const ALPHA_BLEND: u32 = 4;
/// The material's triangles have MikkTSpace tangents (normal maps, anisotropy).
pub const TANGENTS: u32 = 8;
/// The object is a shadow catcher (`Object::shadow_catcher`; `estimator::shadow_catcher`).
pub const SHADOW_CATCHER: u32 = 16;

/// The texture slots: indices into `Material::textures` (`Material::sampler_bits` finds each one's
/// sampler).
pub const SLOT_BASE: u32 = 0;
pub const SLOT_METALLIC_ROUGHNESS: u32 = 1;
pub const SLOT_NORMAL: u32 = 2;
pub const SLOT_EMISSION: u32 = 3;
/// Red scales the clear coat's weight (linear).
pub const SLOT_CLEARCOAT: u32 = 4;
/// Green scales the clear coat's roughness (linear).
pub const SLOT_CLEARCOAT_ROUGHNESS: u32 = 5;
/// RGB scales the sheen's colour (sRGB).
pub const SLOT_SHEEN_COLOR: u32 = 6;
/// Alpha scales the sheen's roughness (linear).
pub const SLOT_SHEEN_ROUGHNESS: u32 = 7;
/// Alpha scales the specular strength (linear).
pub const SLOT_SPECULAR: u32 = 8;
/// RGB scales the specular colour (sRGB).
pub const SLOT_SPECULAR_COLOR: u32 = 9;
/// The clear coat's own tangent-space normal map (linear).
pub const SLOT_CLEARCOAT_NORMAL: u32 = 10;
/// Red and green: the direction of anisotropy in the tangent frame ((2r − 1, 2g − 1)); blue scales
/// its strength (linear).
pub const SLOT_ANISOTROPY: u32 = 11;
/// Alpha scales the diffuse transmission (linear).
pub const SLOT_DIFFUSE_TRANSMISSION: u32 = 12;
/// RGB scales the diffusely transmitted colour (sRGB).
pub const SLOT_DIFFUSE_TRANSMISSION_COLOR: u32 = 13;
/// Red scales the thin film's weight (linear).
pub const SLOT_IRIDESCENCE: u32 = 14;
/// Green picks the film's thickness between its minimum and maximum (linear).
pub const SLOT_IRIDESCENCE_THICKNESS: u32 = 15;
pub const SAMPLER_BITS: u32 = 5;
/// Slots whose sampler bits share one word of `Material::samplers`.
pub const SLOTS_PER_WORD: u32 = 6;
/// A slot's sampler bits (`scene::TextureSampler::bits`): wrap s in bits 0–1 and t in 2–3
/// (0 repeat, these two otherwise), bit 4 nearest filtering.
pub const WRAP_CLAMP: u32 = 1;
pub const WRAP_MIRROR: u32 = 2;
pub const FILTER_NEAREST: u32 = 16;

gpu_struct! {
/// One texel of the environment map with its importance-sampling record (`crate::environment`).
#[repr(C, align(16))]
#[derive(Clone, Copy, Debug, Default, PartialEq, Pod, Zeroable)]
pub struct EnvTexel {
    /// Radiance × strength.
    pub radiance: [f32; 3], // 0
    /// P_i · W H / (2π²): the solid-angle pdf is this over sin θ.
    pub pdf: f32, // 12
    pub alias_index: u32, // 16
    pub threshold: f32,   // 20
    pub _pad: [u32; 2],   // 24
}
}

gpu_struct! {
/// An inner node of the BVH2 holding the boxes of both its children, so one load per traversal step
/// decides which children to visit. A child with `*_count > 0` is a leaf of triangles
/// `left..left + left_count` (resp. right); otherwise `left` (resp. `right`) is the child's node index.
/// An empty child has an inverted box (min > max) that no ray enters.
#[repr(C, align(16))]
#[derive(Clone, Copy, Debug, Default, PartialEq, Pod, Zeroable)]
pub struct BvhNode {
    pub left_min: [f32; 3],  // 0
    pub left: u32,           // 12
    pub left_max: [f32; 3],  // 16
    pub left_count: u32,     // 28
    pub right_min: [f32; 3], // 32
    pub right: u32,          // 44
    pub right_max: [f32; 3], // 48
    pub right_count: u32,    // 60
}
}

gpu_struct! {
/// A node of the compressed wide BVH (CWBVH, Ylitie, Karras and Laine 2017) as obvhs builds it: up
/// to eight children whose boxes are quantised to 8 bits per plane on a grid with origin `origin`
/// and power-of-two cell sizes. Byte-for-byte `obvhs::cwbvh::node::CwBvhNode`, with its byte arrays
/// read as little-endian words (WGSL has no 8-bit types; it unpacks them with `unpack4xU8`).
#[repr(C, align(16))]
#[derive(Clone, Copy, Debug, Default, PartialEq, Pod, Zeroable)]
pub struct WideBvhNode {
    pub origin: [f32; 3], // 0
    /// Bytes 0..3: biased exponents of the x, y and z cell sizes; byte 3: which children are inner.
    pub exponents_imask: u32, // 12
    /// Index of the first inner child; inner children are stored consecutively in slot order.
    pub child_base: u32, // 16
    /// Index of the first triangle of the leaf children.
    pub primitive_base: u32, // 20
    /// Per child slot, one byte: 0 empty; inner: 0b001 << 5 | (24 + slot); leaf: its triangle count in
    /// unary in the top 3 bits and its first triangle's offset from `primitive_base` in the low 5.
    pub slots: [u32; 2], // 24
    pub lo_x: [u32; 2],   // 32
    pub hi_x: [u32; 2],   // 40
    pub lo_y: [u32; 2],   // 48
    pub hi_y: [u32; 2],   // 56
    pub lo_z: [u32; 2],   // 64
    pub hi_z: [u32; 2],   // 72
}
}

gpu_struct! {
/// Per-dispatch parameters: camera, image and the slice of work this dispatch does.
#[repr(C, align(16))]
#[derive(Clone, Copy, Debug, Default, PartialEq, Pod, Zeroable)]
pub struct Frame {
    pub cam_origin: [f32; 3], // 0
    pub lens_radius: f32,     // 12
    pub cam_u: [f32; 3],      // 16
    pub focus_distance: f32,  // 28
    pub cam_v: [f32; 3],      // 32
    pub tan_half_vfov: f32,   // 44
    pub cam_w: [f32; 3],      // 48
    pub aspect: f32,          // 60
    pub ambient: [f32; 3],    // 64
    pub max_depth: u32,       // 76
    pub width: u32,           // 80
    pub height: u32,          // 84
    pub seed: u32,            // 88
    /// Index of the first sample this dispatch adds (samples already accumulated).
    pub sample_base: u32, // 92
    pub samples_this_dispatch: u32, // 96
    /// This dispatch covers image rows `row_begin..row_end`.
    pub row_begin: u32, // 100
    pub row_end: u32,         // 104
    /// Emitter triangles sampled by next-event estimation; 0 turns it off.
    pub emitter_count: u32, // 108
    /// 1 / Σ (area × luminance of emission) over the emitters: the area pdf of a point on an emitter
    /// of emission `Le` is `luminance(Le) × emitter_power_inv`.
    pub emitter_power_inv: f32, // 112
    /// Russian roulette applies after the scattering at this segment index and later; 0 turns it off.
    pub roulette_from_depth: u32, // 116
    /// The accumulation buffer holds image rows `tile_row_begin..tile_row_end` (the whole image
    /// unless it is rendered in tiles to fit the adapter's buffer limits).
    pub tile_row_begin: u32, // 120
    pub tile_row_end: u32,    // 124
    /// 0: independent PCG sampler; 1: Owen-scrambled Sobol (`math::rng`).
    pub sampler: u32, // 128
    /// How emitters found by BSDF sampling and by next-event estimation are combined: 0 the power
    /// heuristic (MIS); 1 next-event estimation only (emitters reached by a diffuse bounce count
    /// zero; a diagnostic estimator for tests, `RenderSettings::nee_only`).
    pub nee_only: u32, // 132
    /// Size of the zone around the origin where ray origins move by a fixed distance instead of by
    /// ULPs of their coordinates: the scene's largest extent, at most 1 (`offset_ray_origin`).
    pub offset_scale: f32, // 136
    /// Adaptive sampling with the wavefront kernels: a wave covers the pixels still sampling at
    /// `active_begin..active_begin + active_count` of the renderer's list of them, rather than
    /// whole rows (so a wave holds only paths that count).
    pub active_begin: u32, // 140
    pub active_count: u32,    // 144
    /// The environment map's size (0 without one: rays that leave see `ambient`).
    pub env_width: u32, // 148
    pub env_height: u32,      // 152
    /// Its rotation about +y, in turns.
    pub env_rotation: f32, // 156
    /// Probability that next-event estimation samples the environment rather than an emitter.
    pub env_pick: f32, // 160
    /// The render's first sample index: a shard of a larger render starts past zero (the random
    /// numbers of sample k are those of sample `sample_offset + k` of the whole image).
    pub sample_offset: u32, // 164
    /// The firefly clamp: the most a contribution of bounced light may add per channel (0: off).
    /// A value, not a pipeline constant, so one pipeline serves every clamp.
    pub clamp_max: f32, // 168
    /// How next-event estimation picks an emitter triangle: 0 by power (the alias table), 1 by
    /// its importance at the shading point (the light tree, `crate::light_tree`).
    pub light_sampler: u32, // 172
    /// The medium filling all space outside closed objects (the scene's fog; zero: vacuum), where
    /// the camera is.
    pub fog: Medium, // 176
    /// The medium stack a camera ray starts with (`estimator::media::media_top`): empty (the fog)
    /// unless the camera sits inside a closed volume (`frame::camera_media`).
    pub camera_media: u32, // 208
    /// How camera rays leave the camera (`camera::Projection::tag`): 0 perspective, 1
    /// orthographic, 2 panorama, 3 fisheye.
    pub projection: u32, // 212
    /// Orthographic: half the view's height in scene units; fisheye: half its angle in radians.
    pub projection_scale: f32, // 216
    /// The image is a window of a film `film_width × film_height` at (`film_x`, `film_y`)
    /// (`RenderSettings::film_window`; the whole film: 0, 0, width, height): the camera maps the
    /// film, and a pixel's random numbers are those of its place in the film.
    pub film_x: u32, // 220
    pub film_y: u32,          // 224
    pub film_width: u32,      // 228
    pub film_height: u32,     // 232
    /// 1: a transparent film (`RenderSettings::transparent`): the background seen directly adds
    /// nothing; the guides' coverage gives each pixel's alpha.
    pub transparent: u32, // 236
}
}

gpu_struct! {
/// One emitter triangle in the alias table that picks emitters in proportion to their power
/// (area × luminance of emission): draw `i` uniformly, keep it when u < `threshold`, else take `alias_index`.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, Pod, Zeroable)]
pub struct Emitter {
    /// Index into the (BVH-ordered) triangle array.
    pub triangle: u32, // 0
    pub alias_index: u32, // 4
    pub threshold: f32,   // 8
    /// Where this emitter sits in the light tree: 4 × node + slot (`GpuScene::light_tree`; 0
    /// without a tree).
    pub leaf: u32, // 12
}
}

gpu_struct! {
/// One node of the light tree (`crate::light_tree`), four-wide: per slot (a lane of each array)
/// the bounds of the emitters below it (a sphere, the cone of their normals, the angle they emit
/// into past a normal, their power), and a child node or the slot's emitter. Lanes, so that the
/// four slots' importances are computed side by side (SIMD on the CPU, vec4 in WGSL).
#[repr(C, align(16))]
#[derive(Clone, Copy, Debug, Default, PartialEq, Pod, Zeroable)]
pub struct LightNode {
    /// The centres of the slots' boxes (their bounding spheres' centres), x, y and z.
    pub centre_x: [f32; 4], // 0
    pub centre_y: [f32; 4], // 16
    pub centre_z: [f32; 4], // 32
    /// The axes of the cones holding the normals below each slot.
    pub axis_x: [f32; 4], // 48
    pub axis_y: [f32; 4],   // 64
    pub axis_z: [f32; 4],   // 80
    /// Σ area × luminance(emission) below each slot (a point or spot light: the luminance of its
    /// intensity); 0 for an empty slot.
    pub power: [f32; 4], // 96
    /// Cosine and sine of each cone's half-angle.
    pub cos_theta_o: [f32; 4], // 112
    pub sin_theta_o: [f32; 4], // 128
    /// Cosine of how far past its normal an emitter below emits (π/2: one-sided diffuse).
    pub cos_theta_e: [f32; 4], // 144
    /// The bounding spheres' radii (half the boxes' diagonals).
    pub radius: [f32; 4], // 160
    /// Per slot: the child node, or for a leaf slot its emitter triangle or, with
    /// `light_tree::DELTA_LEAF` set, its point or spot light.
    pub child: [u32; 4], // 176
    /// Bit i set: slot i is a leaf (one emitter).
    pub leaves: u32, // 192
    /// Where this node hangs: 4 × its parent node + its slot there (the root's is 0).
    pub parent: u32, // 196
    pub _pad: [u32; 2],     // 200
}
}

gpu_struct! {
/// A point, spot or directional light (see `crate::light` for the units).
#[repr(C, align(16))]
#[derive(Clone, Copy, Debug, Default, PartialEq, Pod, Zeroable)]
pub struct DeltaLight {
    pub position: [f32; 3], // 0
    /// `LightTag` (`crate::light_kind`); `LightTag::None` marks the padding record of a scene
    /// without delta lights.
    pub kind: u32, // 12
    /// Unit direction the light travels (spot axis, sun direction).
    pub direction: [f32; 3], // 16
    pub cos_inner: f32,     // 28
    /// color × intensity: W/sr (point, spot) or W/m² (directional).
    pub power: [f32; 3], // 32
    pub cos_outer: f32,     // 44
}
}

gpu_struct! {
/// A ray for the `trace_rays` test kernel.
#[repr(C, align(16))]
#[derive(Clone, Copy, Debug, Default, PartialEq, Pod, Zeroable)]
pub struct Ray {
    pub origin: [f32; 3],    // 0
    pub t_max: f32,          // 12
    pub direction: [f32; 3], // 16
    pub _pad: f32,           // 28
}
}

gpu_struct! {
/// The nearest hit of a `Ray`; `triangle == u32::MAX` for a miss.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, Pod, Zeroable)]
pub struct Hit {
    pub t: f32,        // 0
    pub triangle: u32, // 4
    pub b1: f32,       // 8
    pub b2: f32,       // 12
    /// The instance whose mesh holds `triangle` (`GpuScene::instances`), or `NO_INSTANCE` for a
    /// triangle stored in world space.
    pub instance: u32, // 16
}
}

/// `Hit::instance` of a triangle stored in world space.
pub const NO_INSTANCE: u32 = u32::MAX;
