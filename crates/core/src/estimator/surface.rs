//! The BSDF at a path vertex, dispatched on the material kind, as `surface.wgsl` beside it (its
//! twin) computes it. The lobes: Lambert (here), fuzzy metal and smooth glass (`math::sampling`),
//! glTF metallic-roughness under its coat and sheen (`math::layers` over `math::bsdf`). Metal and glass are delta-like: lights are not sampled
//! at them, and their samples carry pdf 0, so an emitter they reach counts fully (MIS weight 1).
//!
//! Lambert: f = albedo/π, sampled cosine-weighted, so f cosθ / p = albedo and p = cosθ/π.

/// The WGSL twin of this module, `surface.wgsl` beside it (composed into the kernels by
/// `rt_gpu::shaders`).
pub const WGSL: &str = include_str!("surface.wgsl");

use glam::{Mat3, Vec3};

use crate::gpu_scene::GpuScene;
use crate::gpu_types::{DielectricLobe, Material, MetalLobe, PbrLobe, THIN_WALLED};
use crate::material_kind::MaterialKind;
use crate::math::anisotropic_energy::anisotropic_energy;
use crate::math::bsdf::Pbr;
use crate::math::glass_energy::glass_energy;
use crate::math::layers::{
    ANISOTROPIC_OFFSET, Layered, Layers, TABLE_CONDUCTOR, TABLE_GLASS, albedo_lookup,
};
use crate::math::medium::{hg_phase, sample_hg};
use crate::math::microfacet::{ENERGY_SIDE, anisotropic_alpha, equivalent_roughness};
use crate::math::rng::Rng;
use crate::math::sampling::{onb, sample_cosine_hemisphere, sample_dielectric, sample_metal};

/// The smallest GGX width of a glass lobe that point, spot and sun lights beyond the surface light
/// through (`Surface::lit_through`; `LIT_THROUGH_MIN_ALPHA` in `surface.wgsl`).
pub const LIT_THROUGH_MIN_ALPHA: f32 = 0.01;

/// How a surface point scatters: its lobe and that lobe's parameters.
// A value on the stack of each path vertex: boxing the large PBR variant would allocate per vertex
// on the CPU backend's hot path.
#[allow(clippy::large_enum_variant)]
#[derive(Clone, Copy, Debug)]
pub enum Surface {
    /// f = albedo/π about `ns`.
    Lambert { albedo: Vec3, ns: Vec3 },
    /// The mirror direction about `ns` perturbed within a ball of radius `fuzz`, weight `albedo`.
    Metal { albedo: Vec3, ns: Vec3, fuzz: f32 },
    /// Smooth glass about `ns` with η = n_transmitted / n_incident; refraction weighs `tint`/η².
    Dielectric { tint: Vec3, ns: Vec3, eta: f32 },
    /// The PBR BSDF (its layers over its base) in the frame (t, b, n), with ωo there.
    Pbr {
        bsdf: Layered,
        frame: [Vec3; 3],
        wo: Vec3,
    },
    /// A scattering in a medium (`math::medium`): the Henyey–Greenstein phase function with
    /// anisotropy `g` about the direction the path travelled, f = p (no cosine), sampled exactly.
    /// Such a vertex has no normal (the callers pass `ng` = 0) and sees lights on every side.
    Phase { direction: Vec3, g: f32 },
}

/// The PBR material's inputs at a hit: its lobe's factors times their textures
/// (`texture::textured_pbr_inputs`).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct PbrInputs {
    pub metallic: f32,
    pub roughness: f32,
    pub specular: f32,
    pub specular_color: Vec3,
    pub clearcoat: f32,
    pub clearcoat_roughness: f32,
    pub sheen_color: Vec3,
    pub sheen_roughness: f32,
    /// The clear coat's shading normal (world space, facing the ray; zero: the base's): glTF's
    /// coat ignores the base's normal map and may have its own.
    pub coat_normal: Vec3,
    pub diffuse_transmission: f32,
    pub diffuse_transmission_color: Vec3,
    pub iridescence: f32,
    pub iridescence_ior: f32,
    /// The film's thickness (nm).
    pub iridescence_thickness: f32,
    /// The index of refraction here: the material's, or its hero channel's under dispersion
    /// (`math::dispersion`, set by `shade_vertex`).
    pub ior: f32,
    /// `KHR_materials_anisotropy`'s strength (after its image).
    pub anisotropy: f32,
    /// The direction of anisotropy: (cos, sin, 0) in the tangent frame as the material gives it,
    /// in world space once `shade_vertex` has turned it by the hit's tangents (`anisotropy_tangent`;
    /// zero where there are none: the shading frame's own x).
    pub anisotropy_direction: Vec3,
}

impl PbrInputs {
    /// The factors alone.
    pub fn of_lobe(l: &PbrLobe) -> Self {
        PbrInputs {
            metallic: l.metallic,
            roughness: l.roughness,
            specular: l.specular,
            specular_color: Vec3::from(l.specular_color),
            clearcoat: l.clearcoat,
            clearcoat_roughness: l.clearcoat_roughness,
            sheen_color: Vec3::from(l.sheen_color),
            sheen_roughness: l.sheen_roughness,
            coat_normal: Vec3::ZERO,
            diffuse_transmission: l.diffuse_transmission,
            diffuse_transmission_color: Vec3::from(l.diffuse_transmission_color),
            iridescence: l.iridescence,
            iridescence_ior: l.iridescence_ior,
            iridescence_thickness: l.iridescence_thickness_max,
            ior: l.ior,
            anisotropy: l.anisotropy,
            anisotropy_direction: Vec3::new(
                l.anisotropy_rotation.cos(),
                l.anisotropy_rotation.sin(),
                0.0,
            ),
        }
    }
}

/// A direction drawn from a surface's lobe.
#[derive(Clone, Copy, Debug)]
pub struct SurfaceSample {
    pub direction: Vec3,
    /// f |cosθ| / pdf: what the path throughput is multiplied by.
    pub weight: Vec3,
    /// The pdf MIS weighs an emitter reached along `direction` with: 0 for the delta lobes and
    /// for a PBR sample below the geometric surface.
    pub pdf: f32,
}

impl Surface {
    /// The BSDF of `material` where a ray travelling along `direction` hit it: `color` is its
    /// colour after textures and vertex colours, `inputs` the PBR inputs after theirs (unused by
    /// the other kinds), `ng` the geometric and `ns` the shading normal (both facing the ray),
    /// `front` the side it hit.
    #[allow(clippy::too_many_arguments)]
    pub fn of_material(
        scene: &GpuScene,
        material: &Material,
        color: Vec3,
        inputs: &PbrInputs,
        direction: Vec3,
        ng: Vec3,
        ns: Vec3,
        front: bool,
    ) -> Surface {
        match MaterialKind::from_tag(material.kind) {
            Some(MaterialKind::Metal) => Surface::Metal {
                albedo: color,
                ns,
                fuzz: material.lobe_of::<MetalLobe>().fuzz,
            },
            Some(MaterialKind::Dielectric) => {
                let ior = material.lobe_of::<DielectricLobe>().ior;
                Surface::Dielectric {
                    tint: color,
                    ns,
                    eta: if front { ior } else { 1.0 / ior },
                }
            }
            Some(MaterialKind::Pbr) => {
                pbr_surface(scene, material, color, inputs, -direction, ng, ns, front)
            }
            _ => Surface::Lambert { albedo: color, ns },
        }
    }

    /// Whether the lobe is sampled only (no light sampling, zero pdf).
    pub fn is_delta(&self) -> bool {
        matches!(self, Surface::Metal { .. } | Surface::Dielectric { .. })
    }

    /// Whether the lobe may send a path below the geometric surface.
    pub fn transmits(&self) -> bool {
        match self {
            Surface::Dielectric { .. } | Surface::Phase { .. } => true,
            Surface::Pbr { bsdf, .. } => {
                bsdf.base.transmission > 0.0 || bsdf.base.diffuse_transmission > 0.0
            }
            _ => false,
        }
    }

    /// Whether point, spot and sun lights beyond the surface light it through its transmission: a
    /// diffuse transmission, or a glass lobe rough enough to resolve them (α ≥
    /// `LIT_THROUGH_MIN_ALPHA`, glTF roughness 0.1). Through a near-smooth one a delta light is a
    /// spike that single samples catch at random (fireflies that moved a test image's mean by
    /// 1.5%), where Cycles, taking such a lobe as singular, shows nothing.
    pub fn lit_through(&self) -> bool {
        match self {
            Surface::Phase { .. } => true,
            Surface::Pbr { bsdf, .. } => {
                let b = &bsdf.base;
                b.diffuse_transmission > 0.0
                    || (b.transmission > 0.0 && b.alpha.min_element() >= LIT_THROUGH_MIN_ALPHA)
            }
            _ => false,
        }
    }

    /// η = n_transmitted / n_incident of the refraction this surface's transmission makes (1 where
    /// it refracts nothing): what scales a refracted path's radiance by 1/η².
    pub fn relative_eta(&self) -> f32 {
        match self {
            Surface::Dielectric { eta, .. } => *eta,
            Surface::Pbr { bsdf, .. } if bsdf.base.transmission > 0.0 => bsdf.base.eta,
            _ => 1.0,
        }
    }

    /// f · |cosθ| towards world direction `wi` and the BSDF-sampling pdf of `wi` (zero for the
    /// delta lobes, which are never asked).
    pub fn eval(&self, wi: Vec3) -> (Vec3, f32) {
        match self {
            Surface::Lambert { albedo, ns } => {
                let c = wi.dot(*ns);
                if c > 0.0 {
                    let p = c * std::f32::consts::FRAC_1_PI;
                    (*albedo * p, p)
                } else {
                    (Vec3::ZERO, 0.0)
                }
            }
            Surface::Pbr { bsdf, frame, wo } => {
                let local = Vec3::new(wi.dot(frame[0]), wi.dot(frame[1]), wi.dot(frame[2]));
                bsdf.eval(*wo, local)
            }
            Surface::Phase { direction, g } => {
                let p = hg_phase(direction.dot(wi), *g);
                (Vec3::splat(p), p)
            }
            Surface::Metal { .. } | Surface::Dielectric { .. } => (Vec3::ZERO, 0.0),
        }
    }

    /// The next direction of a path that arrived along `direction` (`ng` the geometric normal
    /// facing it); `None` ends the path.
    pub fn sample(&self, direction: Vec3, ng: Vec3, rng: &mut Rng) -> Option<SurfaceSample> {
        Some(match *self {
            Surface::Metal { albedo, ns, fuzz } => SurfaceSample {
                direction: sample_metal(direction, ns, fuzz, rng),
                weight: albedo,
                pdf: 0.0,
            },
            Surface::Dielectric { tint, ns, eta } => {
                let (d, refracted) = sample_dielectric(direction, ns, eta, rng);
                SurfaceSample {
                    direction: d,
                    // Refraction scales radiance by 1/η²; reflection (probability F) keeps it.
                    weight: if refracted {
                        tint / (eta * eta)
                    } else {
                        Vec3::ONE
                    },
                    pdf: 0.0,
                }
            }
            Surface::Pbr { bsdf, frame, wo } => {
                let (u_lobe, u1, u2) = (rng.next_f32(), rng.next_f32(), rng.next_f32());
                let s = bsdf.sample(wo, u_lobe, u1, u2)?;
                let d = (frame[0] * s.wi.x + frame[1] * s.wi.y + frame[2] * s.wi.z).normalize();
                SurfaceSample {
                    direction: d,
                    weight: s.weight,
                    pdf: if d.dot(ng) > 0.0 { s.pdf } else { 0.0 },
                }
            }
            Surface::Phase { direction, g } => {
                let (u1, u2) = (rng.next_f32(), rng.next_f32());
                let d = sample_hg(direction, g, u1, u2);
                SurfaceSample {
                    direction: d,
                    weight: Vec3::ONE,
                    pdf: hg_phase(direction.dot(d), g),
                }
            }
            Surface::Lambert { albedo, ns } => {
                let d = sample_cosine_hemisphere(ns, rng);
                SurfaceSample {
                    direction: d,
                    weight: albedo,
                    pdf: d.dot(ns).max(0.0) * std::f32::consts::FRAC_1_PI,
                }
            }
        })
    }
}

/// The tangent and bitangent of the shading frame about `n`: along the direction of anisotropy
/// (made orthogonal to `n`) where the surface is anisotropic and has one, else `onb`'s.
fn shading_frame(n: Vec3, inputs: &PbrInputs) -> (Vec3, Vec3) {
    let d = inputs.anisotropy_direction;
    let t = (d - n * n.dot(d)).normalize_or_zero();
    if inputs.anisotropy > 0.0 && t != Vec3::ZERO {
        (t, n.cross(t))
    } else {
        onb(n)
    }
}

/// The PBR surface at a hit seen from `wo` (world, pointing away): its shading frame is `ns`
/// unless `wo` lies below it (an interpolated normal at a silhouette), then the true normal.
#[allow(clippy::too_many_arguments)]
fn pbr_surface(
    scene: &GpuScene,
    material: &Material,
    base: Vec3,
    inputs: &PbrInputs,
    wo: Vec3,
    ng: Vec3,
    ns: Vec3,
    front: bool,
) -> Surface {
    let lobe = material.lobe_of::<PbrLobe>();
    let n = if wo.dot(ns) > 0.0 { ns } else { ng };
    let (t, b) = shading_frame(n, inputs);
    let wo_local = Vec3::new(wo.dot(t), wo.dot(b), wo.dot(n));
    // A thin sheet looks the same from both sides.
    let thin = material.flags & THIN_WALLED != 0;
    let eta = if front || thin {
        inputs.ior
    } else {
        1.0 / inputs.ior
    };
    let tables = &scene.albedo_tables;
    let alpha = anisotropic_alpha(inputs.roughness, inputs.anisotropy);
    // An anisotropic conductor has a table of its own; glass reads its isotropic tables at the
    // mean width.
    let (roughness, energy) = if inputs.anisotropy > 0.0 {
        let table = &tables[ANISOTROPIC_OFFSET..];
        (
            equivalent_roughness(alpha),
            anisotropic_energy(table, wo_local, inputs.roughness, inputs.anisotropy),
        )
    } else {
        let r = inputs.roughness;
        (r, albedo_lookup(tables, TABLE_CONDUCTOR, wo_local.z, r))
    };
    let base = Pbr::new(
        base,
        inputs.metallic,
        roughness,
        eta,
        lobe.transmission,
        wo_local.z,
        energy,
    )
    .anisotropic(alpha)
    .with_specular(inputs.specular_color, inputs.specular, wo_local.z)
    .with_diffuse_transmission(
        inputs.diffuse_transmission,
        inputs.diffuse_transmission_color,
    )
    .with_iridescence(
        inputs.iridescence,
        inputs.iridescence_ior,
        inputs.iridescence_thickness,
    )
    .thin_walled(thin);
    // Rough glass keeps its energy (a thin sheet's transmission is a mirrored conductor lobe).
    let base = if lobe.transmission <= 0.0 {
        base
    } else if thin {
        base.with_glass_energy(energy)
    } else {
        let glass = &tables[TABLE_GLASS * ENERGY_SIDE * ENERGY_SIDE..];
        base.with_glass_energy(glass_energy(glass, wo_local.z, roughness, eta))
    };
    let layers = Layers {
        clearcoat: inputs.clearcoat,
        clearcoat_roughness: inputs.clearcoat_roughness,
        sheen_color: inputs.sheen_color,
        sheen_roughness: inputs.sheen_roughness,
        coat_frame: coat_frame(inputs, wo, ng, [t, b, n]),
    };
    Surface::Pbr {
        bsdf: Layered::new(base, &layers, tables, wo_local),
        frame: [t, b, n],
        wo: wo_local,
    }
}

/// The coat's frame in the base's (`Layers::coat_frame`): about the coat's normal (the true
/// normal where `wo` lies below it), `None` where that is the base's normal or there is no coat.
fn coat_frame(inputs: &PbrInputs, wo: Vec3, ng: Vec3, base: [Vec3; 3]) -> Option<Mat3> {
    let nc = inputs.coat_normal;
    if inputs.clearcoat <= 0.0 || nc == Vec3::ZERO || nc == base[2] {
        return None;
    }
    let nc = if wo.dot(nc) > 0.0 { nc } else { ng };
    if nc == base[2] {
        return None;
    }
    let (tc, bc) = onb(nc);
    // Rows: the coat's axes in the base's frame.
    let row = |a: Vec3| Vec3::new(a.dot(base[0]), a.dot(base[1]), a.dot(base[2]));
    Some(Mat3::from_cols(row(tc), row(bc), row(nc)).transpose())
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A phase function's sample carries the density its evaluation gives that direction (so MIS
    /// weighs a light it finds by the same pdf next-event estimation uses), f equals that density
    /// (f/p = 1: the weight is exactly 1), and it sees lights on every side.
    #[test]
    fn phase_samples_carry_their_evaluated_pdf() {
        let mut rng = Rng::new(5, 0, 1);
        let direction = Vec3::new(0.2, -0.9, 0.4).normalize();
        for g in [-0.8, 0.0, 0.6, 0.95] {
            let s = Surface::Phase { direction, g };
            assert!(s.lit_through() && !s.is_delta());
            for _ in 0..1000 {
                let sample = s.sample(direction, Vec3::ZERO, &mut rng).expect("a sample");
                let (f, pdf) = s.eval(sample.direction);
                assert!((sample.pdf - pdf).abs() <= 1e-5 * pdf.max(1.0), "g {g}");
                assert_eq!(f, Vec3::splat(pdf));
                assert_eq!(sample.weight, Vec3::ONE);
            }
        }
    }
}
