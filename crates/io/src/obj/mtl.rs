//! MTL materials through `tobj`, mapped onto rt's materials (first rule that applies):
//! 1. `Ke` with a non-zero component → `Emissive { color: Ke, intensity: 1 }`.
//! 2. `illum` 4, 6 or 7, or `d` < 1, or `Tf` → `Dielectric { ior: Ni (1.5 if absent), tint: Tf (white) }`,
//!    or with `Pr` > 0 rough glass: `Pbr { base_color: Tf (white), roughness: Pr, ior: Ni (1.5),
//!    transmission: 1 }`.
//! 3. `Pr`, `Pm`, `Pc`, `Ps` or `aniso` (the PBR extension of MTL) → `Pbr { base_color: Kd (or Ks if
//!    non-zero, for a metal), texture: map_Kd, metallic: Pm (1 with `illum 3`, else 0), roughness:
//!    Pr, else √α with α = √(2/(Ns+2)) (Walter's Blinn–Phong match), else 0.5, ior: Ni (1.5),
//!    clearcoat: Pc, clearcoat_roughness: Pcr, sheen_color: Ps (one value: grey), anisotropy:
//!    aniso, anisotropy_rotation: 2π anisor (a fraction of a turn, as Blender reads it) }`, the
//!    layer values clamped to [0, 1].
//! 4. `illum 3` → `Metal { albedo: Ks if non-zero else Kd, fuzz: √(2/(Ns+2)) (0 without Ns) }`.
//! 5. otherwise → `Lambertian { albedo: Kd (0.8 grey if absent), texture: map_Kd }`.

use std::path::Path;

use super::super::line_reader::LineCountingReader;
use super::super::parse_guard::guard_parser;
use super::text::{decode_text, name_unnamed_materials, normalize_mtl_colors};
use rt_core::error::{Error, Result};
use rt_core::material::{Material, Rgb};

/// What tobj returns for an MTL file (its map type depends on tobj's features).
pub type MtlData = <tobj::MTLLoadResult as IntoIterator>::Item;

/// Parses an MTL file: decoded forgivingly ([`decode_text`]), unnamed materials named, colours
/// checked.
pub fn parse_mtl(path: &Path, bytes: &[u8]) -> Result<MtlData> {
    let text = decode_text(path, bytes)?;
    let text = normalize_mtl_colors(path, &name_unnamed_materials(&text, "newmtl"))?;
    let mut reader = LineCountingReader::new(text.as_bytes());
    let result = guard_parser(path, "OBJ/MTL", || tobj::load_mtl_buf(&mut reader))?;
    result.map_err(|e| Error::Parse {
        path: path.into(),
        line: reader.current_line(),
        message: e.to_string(),
    })
}

fn param(m: &tobj::Material, key: &str) -> Option<Vec<f32>> {
    let text = m.unknown_param.get(key)?;
    let values: Option<Vec<f32>> = text.split_whitespace().map(|w| w.parse().ok()).collect();
    values.filter(|v| !v.is_empty())
}

fn rgb_param(m: &tobj::Material, key: &str) -> Option<Rgb> {
    let v = param(m, key)?;
    Some(match v.as_slice() {
        [g] => [*g; 3],
        [r, g, b, ..] => [*r, *g, *b],
        _ => return None,
    })
}

/// `v` clamped to [0, 1] (0 if not finite).
fn unit(v: f32) -> f32 {
    if v.is_finite() {
        v.clamp(0.0, 1.0)
    } else {
        0.0
    }
}

fn is_nonzero(c: &Rgb) -> bool {
    c.iter().any(|&v| v > 0.0)
}

/// Applies the MTL mapping documented at the top of this module.
pub fn material_from_mtl(m: &tobj::Material, texture: Option<usize>) -> Material {
    let emissive = m.emissive.or_else(|| rgb_param(m, "Ke"));
    if let Some(ke) = emissive.filter(is_nonzero) {
        return Material::Emissive {
            color: ke,
            intensity: 1.0,
        };
    }
    let illum = m.illumination_model.unwrap_or(2);
    let tf = rgb_param(m, "Tf");
    if matches!(illum, 4 | 6 | 7) || m.dissolve.is_some_and(|d| d < 1.0) || tf.is_some() {
        if let Some(pr) = param(m, "Pr").map(|v| v[0]).filter(|r| *r > 0.0) {
            return Material::Pbr(Box::new(rt_core::material::Pbr {
                base_color: tf.unwrap_or([1.0; 3]),
                roughness: pr.clamp(0.0, 1.0),
                ior: m.optical_density.filter(|n| *n >= 1.0).unwrap_or(1.5),
                transmission: 1.0,
                ..Default::default()
            }));
        }
        return Material::Dielectric {
            ior: m.optical_density.unwrap_or(1.5),
            tint: tf.unwrap_or([1.0; 3]),
        };
    }
    let kd = m.diffuse.unwrap_or([0.8; 3]);
    let blinn_alpha = m.shininess.map(|ns| (2.0 / (ns.max(0.0) + 2.0)).sqrt());
    let (pm, pr) = (param(m, "Pm").map(|v| v[0]), param(m, "Pr").map(|v| v[0]));
    let (pc, ps) = (param(m, "Pc").map(|v| v[0]), rgb_param(m, "Ps"));
    let aniso = param(m, "aniso").map(|v| v[0]);
    if pm.is_some() || pr.is_some() || pc.is_some() || ps.is_some() || aniso.is_some() {
        let metallic = pm
            .unwrap_or(if illum == 3 { 1.0 } else { 0.0 })
            .clamp(0.0, 1.0);
        let base_color = if metallic > 0.0 {
            m.specular.filter(is_nonzero).unwrap_or(kd)
        } else {
            kd
        };
        let roughness = pr.or(blinn_alpha.map(f32::sqrt)).unwrap_or(0.5);
        return Material::Pbr(Box::new(rt_core::material::Pbr {
            base_color,
            texture,
            metallic,
            roughness: roughness.clamp(0.0, 1.0),
            ior: m.optical_density.filter(|n| *n >= 1.0).unwrap_or(1.5),
            clearcoat: unit(pc.unwrap_or(0.0)),
            clearcoat_roughness: unit(param(m, "Pcr").map_or(0.0, |v| v[0])),
            sheen_color: ps.unwrap_or([0.0; 3]).map(unit),
            anisotropy: unit(aniso.unwrap_or(0.0)),
            anisotropy_rotation: param(m, "anisor")
                .map(|v| v[0])
                .filter(|v| v.is_finite())
                .map_or(0.0, |v| {
                    (v * std::f32::consts::TAU).rem_euclid(std::f32::consts::TAU)
                }),
            ..Default::default()
        }));
    }
    if illum == 3 {
        let albedo = m.specular.filter(is_nonzero).unwrap_or(kd);
        return Material::Metal {
            albedo,
            fuzz: blinn_alpha.unwrap_or(0.0).clamp(0.0, 1.0),
        };
    }
    Material::Lambertian {
        albedo: kd,
        texture,
    }
}
