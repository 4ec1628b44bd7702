//! Texture lookups and alpha coverage, the twin of `texture.wgsl` beside it: each texture slot
//! is (offset, width, height) in `GpuScene::texels` with its sampler's bits
//! (`scene::TextureSampler::bits`).

/// The WGSL twin of this module, `texture.wgsl` beside it (composed into the kernels by
/// `rt_gpu::shaders`).
pub const WGSL: &str = include_str!("texture.wgsl");

use glam::{Vec2, Vec3, Vec4};

use super::surface::PbrInputs;
use crate::gpu_scene::GpuScene;
use crate::gpu_types::{
    ALPHA_BLEND, ALPHA_MASK, FILTER_NEAREST, Material, PbrLobe, SLOT_ANISOTROPY, SLOT_BASE,
    SLOT_CLEARCOAT, SLOT_CLEARCOAT_ROUGHNESS, SLOT_DIFFUSE_TRANSMISSION,
    SLOT_DIFFUSE_TRANSMISSION_COLOR, SLOT_EMISSION, SLOT_IRIDESCENCE, SLOT_IRIDESCENCE_THICKNESS,
    SLOT_METALLIC_ROUGHNESS, SLOT_SHEEN_COLOR, SLOT_SHEEN_ROUGHNESS, SLOT_SPECULAR,
    SLOT_SPECULAR_COLOR, Triangle, WRAP_CLAMP, WRAP_MIRROR,
};
use crate::material_kind::MaterialKind;
use crate::math::intersect::PreparedRay;
use crate::math::layers::{TABLE_COAT, albedo_lookup};
use crate::math::sampling::srgb_to_linear;

/// A texel index on an axis of `n` texels after the wrap mode (repeat, clamp or mirror).
pub fn wrap_index(i: i32, n: i32, mode: u32) -> u32 {
    match mode {
        WRAP_CLAMP => i.clamp(0, n - 1) as u32,
        WRAP_MIRROR => {
            let m = i.rem_euclid(2 * n);
            (if m >= n { 2 * n - 1 - m } else { m }) as u32
        }
        _ => i.rem_euclid(n) as u32,
    }
}

/// A texture slot: where its texels start, its size and its sampler's bits.
#[derive(Clone, Copy, Debug)]
pub struct Slot {
    pub offset: u32,
    pub width: u32,
    pub height: u32,
    pub bits: u32,
}

impl Slot {
    fn texel(&self, scene: &GpuScene, x: i32, y: i32, srgb: bool) -> Vec4 {
        let xi = wrap_index(x, self.width as i32, self.bits & 3);
        let yi = wrap_index(y, self.height as i32, (self.bits >> 2) & 3);
        let p = scene.texels[(self.offset + yi * self.width + xi) as usize].to_le_bytes();
        let v = Vec4::new(p[0] as f32, p[1] as f32, p[2] as f32, p[3] as f32) / 255.0;
        if srgb {
            Vec4::new(
                srgb_to_linear(v.x),
                srgb_to_linear(v.y),
                srgb_to_linear(v.z),
                v.w,
            )
        } else {
            v
        }
    }

    /// The slot at `uv` (`uv.y` = 0 the image's bottom row): bilinear over decoded texels, or the
    /// nearest texel; `srgb` decodes the colour channels.
    pub fn sample(&self, scene: &GpuScene, uv: Vec2, srgb: bool) -> Vec4 {
        let x = uv.x * self.width as f32;
        let y = (1.0 - uv.y) * self.height as f32;
        if self.bits & FILTER_NEAREST != 0 {
            return self.texel(scene, x.floor() as i32, y.floor() as i32, srgb);
        }
        let (x0, y0) = ((x - 0.5).floor(), (y - 0.5).floor());
        let (fx, fy) = (x - 0.5 - x0, y - 0.5 - y0);
        let (xi, yi) = (x0 as i32, y0 as i32);
        let t = |dx: i32, dy: i32| self.texel(scene, xi + dx, yi + dy, srgb);
        let top = t(0, 0).lerp(t(1, 0), fx);
        let bottom = t(0, 1).lerp(t(1, 1), fx);
        top.lerp(bottom, fy)
    }
}

impl Slot {
    /// Material `m`'s texture slot `slot` (`SLOT_*`) with its sampler.
    pub fn of(m: &Material, slot: u32) -> Slot {
        let t = m.texture(slot);
        Slot {
            offset: t.offset,
            width: t.width,
            height: t.height,
            bits: m.sampler_bits(slot),
        }
    }
}

/// The PBR inputs at `uv`: the lobe's factors times their images (metallic-roughness: blue and
/// green; clear coat: red; its roughness: green; sheen colour: sRGB; its roughness: alpha;
/// specular: alpha; specular colour: sRGB; anisotropy: red-green direction, blue strength;
/// diffuse transmission: alpha; its colour: sRGB; thin film: red; its thickness: green between the
/// minimum and the maximum), as glTF reads them.
pub fn textured_pbr_inputs(scene: &GpuScene, m: &Material, uv: Vec2) -> PbrInputs {
    let mut p = PbrInputs::of_lobe(&m.lobe_of::<PbrLobe>());
    let texel = |slot: u32, srgb: bool| {
        (!m.texture(slot).is_empty()).then(|| Slot::of(m, slot).sample(scene, uv, srgb))
    };
    if let Some(t) = texel(SLOT_METALLIC_ROUGHNESS, false) {
        p.roughness *= t.y;
        p.metallic *= t.z;
    }
    if let Some(t) = texel(SLOT_CLEARCOAT, false) {
        p.clearcoat *= t.x;
    }
    if let Some(t) = texel(SLOT_CLEARCOAT_ROUGHNESS, false) {
        p.clearcoat_roughness *= t.y;
    }
    if let Some(t) = texel(SLOT_SHEEN_COLOR, true) {
        p.sheen_color *= t.truncate();
    }
    if let Some(t) = texel(SLOT_SHEEN_ROUGHNESS, false) {
        p.sheen_roughness *= t.w;
    }
    if let Some(t) = texel(SLOT_SPECULAR, false) {
        p.specular *= t.w;
    }
    if let Some(t) = texel(SLOT_SPECULAR_COLOR, true) {
        p.specular_color *= t.truncate();
    }
    if let Some(t) = texel(SLOT_DIFFUSE_TRANSMISSION, false) {
        p.diffuse_transmission *= t.w;
    }
    if let Some(t) = texel(SLOT_DIFFUSE_TRANSMISSION_COLOR, true) {
        p.diffuse_transmission_color *= t.truncate();
    }
    if let Some(t) = texel(SLOT_IRIDESCENCE, false) {
        p.iridescence *= t.x;
    }
    if let Some(t) = texel(SLOT_IRIDESCENCE_THICKNESS, false) {
        let l = m.lobe_of::<PbrLobe>();
        p.iridescence_thickness = l.iridescence_thickness_min
            + (l.iridescence_thickness_max - l.iridescence_thickness_min) * t.y;
    }
    if let Some(t) = texel(SLOT_ANISOTROPY, false) {
        p.anisotropy *= t.z;
        p.anisotropy_direction = rotate_direction(p.anisotropy_direction, t.x, t.y);
    }
    p
}

/// The direction of anisotropy `rotated` (cos, sin of the material's rotation) applied to an
/// anisotropy image's direction (2r − 1, 2g − 1); an image direction of length zero reads as the
/// tangent's, (1, 0).
pub fn rotate_direction(rotated: Vec3, r: f32, g: f32) -> Vec3 {
    let d = Vec2::new(2.0 * r - 1.0, 2.0 * g - 1.0);
    let d = if d.length_squared() > 0.0 {
        d.normalize()
    } else {
        Vec2::X
    };
    Vec3::new(
        rotated.x * d.x - rotated.y * d.y,
        rotated.y * d.x + rotated.x * d.y,
        0.0,
    )
}

/// The base colour image (sRGB) times PBR's factor (a Lambertian texture replaces the albedo).
pub fn base_color_texture(scene: &GpuScene, m: &Material, uv: Vec2) -> Vec3 {
    let t = Slot::of(m, SLOT_BASE).sample(scene, uv, true).truncate();
    if m.kind == MaterialKind::Pbr.tag() {
        t * Vec3::from(m.color)
    } else {
        t
    }
}

/// The light a surface emits at the barycentrics (b1, b2) of triangle `i` towards a direction at
/// cosine `cos` to its normal: the material's emission times its emission image, under a clear
/// coat times what the coat lets through, 1 − c E_coat(cos) (glTF: emission is attenuated by the
/// coat; E_coat the coat's albedo from `math::coat`, by reciprocity what it reflects of light
/// arriving from that direction is what it keeps of light leaving towards it).
pub fn surface_emission(
    scene: &GpuScene,
    m: &Material,
    tri: &Triangle,
    i: u32,
    (b1, b2): (f32, f32),
    cos: f32,
) -> Vec3 {
    let mut e = Vec3::from(m.emission);
    if !m.texture(SLOT_EMISSION).is_empty() && tri.has_uvs != 0 {
        e *= Slot::of(m, SLOT_EMISSION)
            .sample(scene, scene.stored_uv(i, b1, b2), true)
            .truncate();
    }
    if m.kind == MaterialKind::Pbr.tag() {
        let lobe = m.lobe_of::<PbrLobe>();
        if lobe.clearcoat > 0.0 {
            let coat = albedo_lookup(
                &scene.albedo_tables,
                TABLE_COAT,
                cos,
                lobe.clearcoat_roughness,
            );
            e *= 1.0 - lobe.clearcoat * coat;
        }
    }
    e
}

/// The coverage at (b1, b2) of triangle `i`: the base colour's alpha (factor times image); with
/// `ALPHA_MASK` 1 at or above the cutoff, else 0.
pub fn coverage(scene: &GpuScene, m: &Material, tri: &Triangle, i: u32, b1: f32, b2: f32) -> f32 {
    let mut a = m.alpha;
    if !m.texture(SLOT_BASE).is_empty() && tri.has_uvs != 0 {
        a *= Slot::of(m, SLOT_BASE)
            .sample(scene, scene.stored_uv(i, b1, b2), false)
            .w;
    }
    if m.flags & ALPHA_MASK != 0 {
        return if a >= m.alpha_cutoff { 1.0 } else { 0.0 };
    }
    a
}

/// Wellons' lowbias32 integer hash.
fn hash_u32(x: u32) -> u32 {
    let mut h = x;
    h ^= h >> 16;
    h = h.wrapping_mul(0x7feb_352d);
    h ^= h >> 15;
    h = h.wrapping_mul(0x846c_a68b);
    h ^= h >> 16;
    h
}

/// Stochastic transparency's coin for `ray` meeting triangle `i`, uniform in [0, 1), from the
/// ray's exact bits (so rounding elsewhere, a driver's hit point, flips it: blending agrees with
/// the kernels in distribution, not in lockstep).
pub fn alpha_coin(ray: &PreparedRay, i: u32) -> f32 {
    let mut h = hash_u32(i);
    for v in [
        ray.origin.x,
        ray.origin.y,
        ray.origin.z,
        ray.inv_direction.x,
        ray.inv_direction.y,
        ray.inv_direction.z,
    ] {
        h = hash_u32(h ^ v.to_bits());
    }
    (h >> 8) as f32 * (1.0 / 16_777_216.0)
}

/// Whether `ray`'s hit on triangle `i` at (b1, b2) stops it: always on opaque materials, where the
/// coverage is 1 on masked ones, with probability equal to the coverage on blended ones.
pub fn stops_ray(
    scene: &GpuScene,
    ray: &PreparedRay,
    tri: &Triangle,
    i: u32,
    b1: f32,
    b2: f32,
) -> bool {
    let m = &scene.materials[tri.material as usize];
    if m.flags & (ALPHA_MASK | ALPHA_BLEND) == 0 {
        return true;
    }
    let a = coverage(scene, m, tri, i, b1, b2);
    if m.flags & ALPHA_MASK != 0 {
        a > 0.5
    } else {
        a > alpha_coin(ray, i)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn wrap_modes_fold_indices_as_opengl_does() {
        let n = 4;
        let repeat: Vec<u32> = (-5..9).map(|i| wrap_index(i, n, 0)).collect();
        assert_eq!(repeat, [3, 0, 1, 2, 3, 0, 1, 2, 3, 0, 1, 2, 3, 0]);
        let clamp: Vec<u32> = (-2..6).map(|i| wrap_index(i, n, WRAP_CLAMP)).collect();
        assert_eq!(clamp, [0, 0, 0, 1, 2, 3, 3, 3]);
        // Mirrored repeat: 0 1 2 3 | 3 2 1 0 | 0 1 2 3, and mirrored to the left of 0 too.
        let mirror: Vec<u32> = (-4..12).map(|i| wrap_index(i, n, WRAP_MIRROR)).collect();
        assert_eq!(mirror, [3, 2, 1, 0, 0, 1, 2, 3, 3, 2, 1, 0, 0, 1, 2, 3]);
    }

    #[test]
    fn the_alpha_coin_is_uniform() {
        // 20 equal bins over rays with nearby origins: a chi-square at 1e-4.
        let mut bins = [0u32; 20];
        let n = 20_000;
        for k in 0..n {
            let o = Vec3::new(k as f32 * 1e-3, 0.25, -1.0);
            let ray = PreparedRay::new(o, Vec3::new(0.3, -0.2, 1.0).normalize());
            let u = alpha_coin(&ray, 7);
            assert!((0.0..1.0).contains(&u));
            bins[(u * 20.0) as usize] += 1;
        }
        let expected = n as f64 / 20.0;
        let chi2: f64 = bins
            .iter()
            .map(|&b| (b as f64 - expected).powi(2) / expected)
            .sum();
        let limit = crate::math::stats::chi2_limit(19, 1, 1e-4);
        assert!(
            chi2 < limit,
            "chi-square {chi2:.1} over 19 dof exceeds {limit:.1}"
        );
    }
}
