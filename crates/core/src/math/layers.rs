//! The `Pbr` material's layer stack, mirrored one-to-one in `layers.wgsl` beside it: a clear coat
//! (`math::coat`) over a sheen (`math::sheen`) over the base (`math::bsdf`), as glTF orders
//! `KHR_materials_clearcoat` and `KHR_materials_sheen`. Each layer passes down what it does not
//! reflect, by its directional albedo at ωo (the albedo-scaling of Kulla and Conty 2017, as the
//! glTF extensions and Cycles' Principled BSDF layer):
//!
//! f cosθi = c f_coat + (1 − c E_coat(μo)) [s_c f_sheen + (1 − max(s_c) E_sheen(μo)) f_base]
//!
//! with c the coat weight and s_c the sheen colour. A white furnace gets back c E_coat + (1 − c
//! E_coat)(max(s_c) E_sheen + (1 − max(s_c) E_sheen) E_base) ≤ 1 whenever the base keeps E_base ≤ 1.
//! The base's transmission passes through both scalings.
//!
//! The coat has a shading frame of its own (glTF: it ignores the base's normal map and may have
//! its own): `coat_frame` rotates the base's frame into it, and f_coat and E_coat read ωo and ωi
//! there.
//!
//! Sampling picks the coat with q_c = c E_coat(μo), the sheen with q_s = (1 − q_c) max(s_c)
//! E_sheen(μo), the base otherwise (its own lobes then), and weighs by the whole f cosθi over the
//! mixture's pdf q_c p_coat + q_s p_sheen + (1 − q_c − q_s) p_base.

/// The WGSL twin of this module, `layers.wgsl` beside it (composed into the kernels by
/// `rt_gpu::shaders`).
pub const WGSL: &str = include_str!("layers.wgsl");

use glam::{Mat3, Vec3};

use super::anisotropic_energy::{ANISOTROPIC_TABLE, anisotropic_table};
use super::bsdf::{BsdfSample, Pbr};
use super::coat::{coat_eval, coat_table, sample_coat};
use super::glass_energy::{GLASS_TABLE, glass_table};
use super::microfacet::{ENERGY_SIDE, alpha_of_roughness, energy_lookup, energy_table};
use super::sheen::{sample_sheen, sheen_alpha, sheen_eval, sheen_table};
use crate::gpu_types::{Material, PbrLobe};
use crate::material_kind::MaterialKind;

/// Where each table of `albedo_tables` starts, in units of `ENERGY_SIDE²` entries.
pub const TABLE_CONDUCTOR: usize = 0;
pub const TABLE_COAT: usize = 1;
pub const TABLE_SHEEN: usize = 2;
/// Rough glass's two tables (`math::glass_energy`), entering then leaving.
pub const TABLE_GLASS: usize = 3;
const UNIT: usize = ENERGY_SIDE * ENERGY_SIDE;

/// The directional-albedo tables the kernels read (binding `albedo_tables`), one after another:
/// the white GGX conductor's (`microfacet::energy_table`), the coat's, the white sheen's, rough
/// glass's (entering, leaving) and the anisotropic conductor's (`math::anisotropic_energy`).
pub fn albedo_tables() -> Vec<f32> {
    [
        energy_table(),
        coat_table(),
        sheen_table(),
        glass_table(),
        anisotropic_table(),
    ]
    .concat()
}

/// Where the anisotropic conductor's table starts in `albedo_tables`.
pub const ANISOTROPIC_OFFSET: usize = TABLE_GLASS * UNIT + 2 * GLASS_TABLE;

/// `albedo_tables` with only the tables `materials` read filled in (the rest zero, never read):
/// each table costs a fraction of a second to build on first use.
pub fn albedo_tables_for(materials: &[Material]) -> Vec<f32> {
    let mut out = vec![0.0; ANISOTROPIC_OFFSET + ANISOTROPIC_TABLE];
    let lobes = materials
        .iter()
        .filter(|m| m.kind == MaterialKind::Pbr.tag())
        .map(Material::lobe_of::<PbrLobe>);
    let (mut pbr, mut coat, mut sheen, mut glass, mut anisotropic) =
        (false, false, false, false, false);
    for l in lobes {
        pbr = true;
        anisotropic |= l.anisotropy > 0.0;
        coat |= l.clearcoat > 0.0;
        sheen |= l.sheen_color.iter().any(|&c| c > 0.0);
        glass |= l.transmission > 0.0;
    }
    let mut put = |unit: usize, table: &[f32]| {
        out[unit * UNIT..unit * UNIT + table.len()].copy_from_slice(table);
    };
    if pbr {
        put(TABLE_CONDUCTOR, energy_table());
    }
    if coat {
        put(TABLE_COAT, coat_table());
    }
    if sheen {
        put(TABLE_SHEEN, sheen_table());
    }
    if glass {
        put(TABLE_GLASS, glass_table());
    }
    if anisotropic {
        out[ANISOTROPIC_OFFSET..].copy_from_slice(anisotropic_table());
    }
    out
}

/// Bilinear lookup of table `table` of `albedo_tables`.
pub fn albedo_lookup(tables: &[f32], table: usize, mu: f32, roughness: f32) -> f32 {
    energy_lookup(&tables[table * ENERGY_SIDE * ENERGY_SIDE..], mu, roughness)
}

/// The coat and sheen parameters of a `Pbr` material at a shading point.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Layers {
    pub clearcoat: f32,
    pub clearcoat_roughness: f32,
    pub sheen_color: Vec3,
    pub sheen_roughness: f32,
    /// The coat's frame, as the matrix taking a direction in the base's frame to the coat's
    /// (`None`: the base's).
    pub coat_frame: Option<Mat3>,
}

/// The layered BSDF at one shading point, as seen from one `wo`.
#[derive(Clone, Copy, Debug)]
pub struct Layered {
    pub base: Pbr,
    pub coat: f32,
    pub coat_alpha: f32,
    pub sheen: Vec3,
    pub sheen_alpha: f32,
    /// 1 − c E_coat(μo): what passes the coat.
    pub below_coat: f32,
    /// 1 − max(s_c) E_sheen(μo): what passes the sheen.
    pub below_sheen: f32,
    pub q_coat: f32,
    pub q_sheen: f32,
    pub coat_frame: Option<Mat3>,
}

impl Layered {
    /// `base` under `layers`, seen from `wo` (in the base's frame; tables: `albedo_tables`).
    pub fn new(base: Pbr, layers: &Layers, tables: &[f32], wo: Vec3) -> Self {
        let cos_o = wo.z;
        let mut l = Layered {
            base,
            coat: layers.clearcoat,
            coat_alpha: alpha_of_roughness(layers.clearcoat_roughness),
            sheen: layers.sheen_color,
            sheen_alpha: sheen_alpha(layers.sheen_roughness),
            below_coat: 1.0,
            below_sheen: 1.0,
            q_coat: 0.0,
            q_sheen: 0.0,
            coat_frame: layers.coat_frame,
        };
        if l.coat > 0.0 {
            let cos_coat = l.in_coat_frame(wo).z.max(0.0);
            l.q_coat =
                l.coat * albedo_lookup(tables, TABLE_COAT, cos_coat, layers.clearcoat_roughness);
            l.below_coat = 1.0 - l.q_coat;
        }
        let s = l.sheen.max_element();
        if s > 0.0 {
            let e = s * albedo_lookup(tables, TABLE_SHEEN, cos_o, layers.sheen_roughness);
            l.below_sheen = 1.0 - e;
            l.q_sheen = l.below_coat * e;
        }
        l
    }

    fn q_base(&self) -> f32 {
        (1.0 - self.q_coat - self.q_sheen).max(0.0)
    }

    /// A direction of the base's frame in the coat's.
    fn in_coat_frame(&self, w: Vec3) -> Vec3 {
        match self.coat_frame {
            Some(m) => m * w,
            None => w,
        }
    }

    /// f · |cosθi| and the pdf of `sample` at `wi`.
    pub fn eval(&self, wo: Vec3, wi: Vec3) -> (Vec3, f32) {
        let (fb, pb) = self.base.eval(wo, wi);
        let mut f = fb * (self.below_coat * self.below_sheen);
        let mut pdf = self.q_base() * pb;
        if self.coat > 0.0 {
            let (fc, pc) = coat_eval(
                self.in_coat_frame(wo),
                self.in_coat_frame(wi),
                self.coat_alpha,
            );
            f += Vec3::splat(self.coat * fc);
            pdf += self.q_coat * pc;
        }
        if self.q_sheen > 0.0 && wi.z > 0.0 {
            f += self.sheen * (self.below_coat * sheen_eval(wo, wi, self.sheen_alpha));
            pdf += self.q_sheen * (0.5 * std::f32::consts::FRAC_1_PI);
        }
        (f, pdf)
    }

    /// A direction for three uniform numbers, or `None` where the sample carries nothing.
    pub fn sample(&self, wo: Vec3, u_lobe: f32, u1: f32, u2: f32) -> Option<BsdfSample> {
        let wi = if u_lobe < self.q_coat {
            let wi = sample_coat(self.in_coat_frame(wo), self.coat_alpha, u1, u2)?;
            match self.coat_frame {
                // Back to the base's frame: the rotation's inverse is its transpose.
                Some(m) => m.transpose() * wi,
                None => wi,
            }
        } else if u_lobe < self.q_coat + self.q_sheen {
            sample_sheen(u1, u2)
        } else {
            // The base's own lobe choice, from what is left of u_lobe.
            let u = ((u_lobe - self.q_coat - self.q_sheen) / self.q_base()).min(1.0 - f32::EPSILON);
            self.base.sample_direction(wo, u, u1, u2)?
        };
        let (f, pdf) = self.eval(wo, wi);
        let weight = f / pdf;
        (pdf > 0.0 && weight.is_finite()).then_some(BsdfSample { wi, weight, pdf })
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::math::stats::{check_sphere_sampling, estimate};

    fn wo_at(cos_o: f32) -> Vec3 {
        Vec3::new((1.0 - cos_o * cos_o).sqrt(), 0.0, cos_o)
    }

    /// A base (colour, metallic, roughness, transmission, η, specular) under `layers` at `cos_o`.
    fn stack(
        (color, metallic, roughness, transmission, eta, specular): (Vec3, f32, f32, f32, f32, f32),
        layers: Layers,
        cos_o: f32,
    ) -> Layered {
        let tables = albedo_tables();
        let e = albedo_lookup(&tables, TABLE_CONDUCTOR, cos_o, roughness);
        let base = Pbr::new(color, metallic, roughness, eta, transmission, cos_o, e).with_specular(
            Vec3::ONE,
            specular,
            cos_o,
        );
        Layered::new(base, &layers, &tables, wo_at(cos_o))
    }

    fn coat(clearcoat: f32, clearcoat_roughness: f32) -> Layers {
        Layers {
            clearcoat,
            clearcoat_roughness,
            ..Default::default()
        }
    }

    fn sheen(sheen_color: Vec3, sheen_roughness: f32) -> Layers {
        Layers {
            sheen_color,
            sheen_roughness,
            ..Default::default()
        }
    }

    /// White-furnace albedo along `wo` (refraction's 1/η² radiance scaling undone).
    fn albedo(l: &Layered, wo: Vec3, channel: usize) -> (f64, f64) {
        estimate(200_000, 5, |a, u1, u2| match l.sample(wo, a, u1, u2) {
            Some(s) if s.wi.z < 0.0 => f64::from(s.weight[channel] * l.base.eta * l.base.eta),
            Some(s) => f64::from(s.weight[channel]),
            None => 0.0,
        })
    }

    /// Every layer combination draws directions as its pdf says (chi-square over the sphere).
    #[test]
    fn layered_samples_follow_their_pdf() {
        let plastic = (Vec3::new(0.8, 0.3, 0.2), 0.0, 0.6, 0.0, 1.5, 1.0);
        let metal = (Vec3::new(0.9, 0.6, 0.3), 1.0, 0.4, 0.0, 1.5, 1.0);
        let glass = (Vec3::ONE, 0.0, 0.5, 1.0, 1.5, 0.7);
        let every = Layers {
            clearcoat: 0.5,
            clearcoat_roughness: 0.4,
            sheen_color: Vec3::new(0.6, 0.4, 0.2),
            sheen_roughness: 0.3,
            coat_frame: None,
        };
        // A coat whose normal leans 0.4 rad away from the base's (its own normal map).
        let tilted = Layers {
            coat_frame: Some(Mat3::from_rotation_x(0.4)),
            ..coat(1.0, 0.2)
        };
        let cases = [
            (
                "coat over plastic",
                stack(plastic, coat(1.0, 0.3), 0.7),
                0.7,
            ),
            (
                "rough coat over metal",
                stack(metal, coat(0.7, 0.8), 0.4),
                0.4,
            ),
            (
                "sheen over plastic",
                stack(plastic, sheen(Vec3::new(1.0, 0.5, 0.2), 0.5), 0.6),
                0.6,
            ),
            (
                "sharp sheen at grazing",
                stack(plastic, sheen(Vec3::ONE, 0.1), 0.2),
                0.2,
            ),
            (
                "every layer over rough glass",
                stack(glass, every, 0.8),
                0.8,
            ),
            (
                "a tilted coat over plastic",
                stack(plastic, tilted, 0.6),
                0.6,
            ),
        ];
        for (k, (what, l, cos_o)) in cases.iter().enumerate() {
            let wo = wo_at(*cos_o);
            check_sphere_sampling(
                what,
                400_000,
                cases.len(),
                k as u32,
                |a, u1, u2| l.sample(wo, a, u1, u2).map(|s| s.wi),
                |wi| l.eval(wo, wi).1,
            );
        }
    }

    /// Over a black base (no reflection: specular 0) each layer returns exactly its table's
    /// albedo, c E_coat or max(s_c) E_sheen; the tables agree with an independent uniform-direction
    /// estimate of ∫ f cos; and a coat and a white sheen over a white diffuse base that keeps
    /// everything (specular 0) keep everything. Tolerances: four standard errors plus 3e-3 for
    /// the tables' bilinear interpolation.
    #[test]
    fn white_furnace_per_layer_and_for_the_stack() {
        let black = (Vec3::ZERO, 0.0, 0.5, 0.0, 1.5, 0.0);
        let white = (Vec3::ONE, 0.0, 0.5, 0.0, 1.5, 0.0);
        let tables = albedo_tables();
        for cos_o in [0.1, 0.4, 0.8, 1.0] {
            let wo = wo_at(cos_o);
            for r in [0.0, 0.3, 0.7, 1.0] {
                let e_coat = f64::from(albedo_lookup(&tables, TABLE_COAT, cos_o, r));
                let (e, se) = albedo(&stack(black, coat(0.8, r), cos_o), wo, 0);
                assert!(
                    (e - 0.8 * e_coat).abs() <= 4.0 * se + 3e-3,
                    "coat r {r} cos {cos_o}: {e:.4} ± {se:.4}, table {:.4}",
                    0.8 * e_coat
                );
                let e_sheen = f64::from(albedo_lookup(&tables, TABLE_SHEEN, cos_o, r));
                let (e, se) = albedo(&stack(black, sheen(Vec3::ONE, r), cos_o), wo, 0);
                assert!(
                    (e - e_sheen).abs() <= 4.0 * se + 3e-3,
                    "sheen r {r} cos {cos_o}: {e:.4} ± {se:.4}, table {e_sheen:.4}"
                );
                // Uniform directions, not the lobes' own sampling (rough coats only: a sharp
                // one's variance would need millions of samples).
                let (u, use_) = estimate(200_000, 9, |_, u1, u2| {
                    let wi = sample_sheen(u1, u2);
                    f64::from(sheen_eval(wo, wi, sheen_alpha(r))) * std::f64::consts::TAU
                });
                assert!(
                    (u - e_sheen).abs() <= 4.0 * use_ + 3e-3,
                    "sheen table r {r} cos {cos_o}: {e_sheen:.4}, uniform {u:.4} ± {use_:.4}"
                );
                if r >= 0.3 {
                    let alpha = alpha_of_roughness(r);
                    let (u, use_) = estimate(400_000, 9, |_, u1, u2| {
                        let wi = sample_sheen(u1, u2);
                        f64::from(coat_eval(wo, wi, alpha).0) * std::f64::consts::TAU
                    });
                    assert!(
                        (u - e_coat).abs() <= 4.0 * use_ + 3e-3,
                        "coat table r {r} cos {cos_o}: {e_coat:.4}, uniform {u:.4} ± {use_:.4}"
                    );
                }
                let all = Layers {
                    clearcoat: 1.0,
                    clearcoat_roughness: r,
                    sheen_color: Vec3::ONE,
                    sheen_roughness: r,
                    coat_frame: None,
                };
                let (e, se) = albedo(&stack(white, all, cos_o), wo, 0);
                eprintln!("coat and sheen over white, r {r} cos {cos_o}: {e:.4} ± {se:.4}");
                assert!(
                    e <= 1.0 + 4.0 * se + 1e-3 && e >= 0.98 - 4.0 * se,
                    "coat and sheen over white, r {r} cos {cos_o}: {e:.4} ± {se:.4}"
                );
            }
        }
    }

    /// The coat and the sheen are reciprocal: f(ωo, ωi) = f(ωi, ωo) (their `eval` returns f cosθi).
    #[test]
    fn coat_and_sheen_are_reciprocal() {
        let mut rng = crate::math::rng::Rng::new(1, 2, 3);
        for _ in 0..1000 {
            let mut dir = || {
                let (u1, u2) = (rng.next_f32(), rng.next_f32());
                sample_sheen(u1.max(0.05), u2)
            };
            let (a, b) = (dir(), dir());
            let r = rng.next_f32();
            let coat_ab = coat_eval(a, b, alpha_of_roughness(r)).0 / b.z;
            let coat_ba = coat_eval(b, a, alpha_of_roughness(r)).0 / a.z;
            assert!((coat_ab - coat_ba).abs() <= 1e-4 * coat_ab.abs().max(1e-3));
            let sheen_ab = sheen_eval(a, b, sheen_alpha(r)) / b.z;
            let sheen_ba = sheen_eval(b, a, sheen_alpha(r)) / a.z;
            assert!((sheen_ab - sheen_ba).abs() <= 1e-4 * sheen_ab.abs().max(1e-3));
        }
    }
}
