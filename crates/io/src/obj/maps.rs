//! MTL texture maps beyond `map_Kd`, onto rt's PBR material (`Pbr`), as Blender's OBJ importer
//! reads them where rt has the same slot:
//! - `norm` (the PBR extension), `map_Bump` or `bump`: a tangent-space normal map, scaled by
//!   `-bm` (Blender reads `map_Bump` as a normal map; exporters write normal maps there). A grey
//!   image there is a height map (older files): it becomes a normal map by central differences,
//!   reading the height h ∈ [0, 1] as a displacement of `-bm` × h × 0.02 in UV units (a
//!   heuristic, stated, as the MTL format gives no scale).
//! - `map_d`: coverage (its alpha channel where it has one, else its brightness), stochastic
//!   transparency (`AlphaMode::Blend`), joined to the base colour texture's alpha.
//! - `map_Ke`: multiplies the emission `Ke` (white where `Ke` is missing).
//! - `map_Pr`, `map_Pm`: roughness and metallic (brightness), multiplying `Pr` and `Pm` (1 where
//!   missing), packed into glTF's metallic-roughness image (green, blue).
//! - `map_Ns` (without `map_Pr`): a shininess image multiplying `Ns` (1000 without it), each
//!   texel's roughness by the Blinn–Phong match the MTL mapping uses for `Ns` (√α, α =
//!   √(2/(Ns+2))), in the same image's green.
//! - `map_Ks`: the specular colour image (`KHR_materials_specular`'s), multiplying `Ks` (white
//!   without it); a diffuse material gains the specular layer it then needs, its roughness from
//!   `Ns` (0.5 without).
//! - `map_Ka`, `disp`, `decal`, `refl`: no slot in rt's materials; ignored with a warning naming
//!   them.
//!
//! A material with any of the used maps becomes `Pbr`: a Lambertian one as a PBR material with no
//! specular layer (`specular` 0, so the same diffuse surface), a metal, glass or emitter as its
//! PBR equivalent. Map options are parsed (`-bm`, `-o`, `-s`, `-clamp`, …) so that file names
//! after them are found; `-o` and `-s` of `map_Kd` offset and scale the object's texture
//! coordinates (every map of a material then reads them, as in glTF's texture transform).

use rt_core::material::{AlphaMode, Material, Pbr, Rgb};
use rt_core::scene::Texture;

/// A map statement's options and file, e.g. `-bm 0.5 -s 2 2 1 brick normal.png`.
#[derive(Clone, Debug, PartialEq)]
pub struct MapStatement {
    pub file: String,
    /// `-bm`: the bump or normal map's strength.
    pub bump: f32,
    /// `-o u v`: added to the texture coordinates.
    pub offset: [f32; 2],
    /// `-s u v`: multiplies the texture coordinates.
    pub scale: [f32; 2],
}

/// Parses a map statement's value (what follows `map_Kd` and the like); `None` without a file.
pub fn parse_map(value: &str) -> Option<MapStatement> {
    let words: Vec<&str> = value.split_whitespace().collect();
    let number = |w: &str| w.parse::<f32>().ok().filter(|v| v.is_finite());
    let mut statement = MapStatement {
        file: String::new(),
        bump: 1.0,
        offset: [0.0; 2],
        scale: [1.0; 2],
    };
    let mut i = 0;
    const OPTIONS: [&str; 13] = [
        "-bm", "-boost", "-texres", "-mm", "-o", "-s", "-t", "-clamp", "-blendu", "-blendv", "-cc",
        "-imfchan", "-type",
    ];
    // Options come first; the first word that is none starts the file name.
    while i < words.len() && OPTIONS.contains(&words[i]) {
        let option = words[i];
        i += 1;
        // Numbers that follow, up to three (`-o u v w`).
        let values: Vec<f32> = words[i..].iter().take(3).map_while(|w| number(w)).collect();
        let taken = match option {
            "-bm" | "-boost" | "-texres" => values.len().min(1),
            "-mm" => values.len().min(2),
            "-o" | "-s" | "-t" => values.len(),
            _ => 1,
        };
        match option {
            "-bm" => statement.bump = values.first().copied().unwrap_or(1.0),
            "-o" => {
                statement.offset =
                    [values.first(), values.get(1)].map(|v| v.copied().unwrap_or(0.0))
            }
            "-s" => {
                statement.scale = [values.first(), values.get(1)].map(|v| v.copied().unwrap_or(1.0))
            }
            _ => {}
        }
        i += taken;
    }
    statement.file = words.get(i..).unwrap_or_default().join(" ");
    (!statement.file.is_empty()).then_some(statement)
}

/// The textures of one MTL material beyond `map_Kd`, loaded into the scene's list.
#[derive(Clone, Debug, Default)]
pub struct MaterialMaps {
    /// The normal map and its `-bm` scale (1 for one made from a height map, its strength baked).
    pub normal: Option<(usize, f32)>,
    /// The base colour texture with the coverage in its alpha (replaces `map_Kd`'s).
    pub base_with_alpha: Option<usize>,
    pub emission: Option<usize>,
    pub metallic_roughness: Option<usize>,
    pub has_roughness_map: bool,
    pub has_metallic_map: bool,
    /// `map_Ks`: the specular colour image.
    pub specular_color: Option<usize>,
}

impl MaterialMaps {
    fn any(&self) -> bool {
        self.normal.is_some()
            || self.base_with_alpha.is_some()
            || self.emission.is_some()
            || self.metallic_roughness.is_some()
            || self.specular_color.is_some()
    }
}

/// `material` (from the MTL mapping) with `maps` applied: unchanged without any, else as `Pbr`.
pub fn with_maps(material: Material, maps: &MaterialMaps, m: &tobj::Material) -> Material {
    if !maps.any() {
        return material;
    }
    let kd = m.diffuse.unwrap_or([0.8; 3]);
    let diffuse = |base_color: Rgb, texture: Option<usize>| Pbr {
        base_color,
        texture,
        roughness: 1.0,
        specular: 0.0,
        ..Default::default()
    };
    let mut pbr = match material {
        Material::Pbr(p) => *p,
        // A Lambertian texture replaces the albedo; a PBR one multiplies the base colour.
        Material::Lambertian { albedo, texture } => {
            diffuse(if texture.is_some() { [1.0; 3] } else { albedo }, texture)
        }
        Material::Metal { albedo, fuzz } => Pbr {
            base_color: albedo,
            metallic: 1.0,
            roughness: fuzz.max(0.0).sqrt(),
            ..Default::default()
        },
        Material::Dielectric { ior, tint } => Pbr {
            base_color: tint,
            transmission: 1.0,
            roughness: 0.0,
            ior,
            ..Default::default()
        },
        Material::Emissive { color, intensity } => Pbr {
            emission: color,
            emission_strength: intensity,
            ..diffuse(kd, None)
        },
    };
    if let Some((texture, scale)) = maps.normal {
        pbr.normal_texture = Some(texture);
        pbr.normal_scale = scale;
    }
    if let Some(texture) = maps.base_with_alpha {
        if pbr.texture.is_none() {
            pbr.base_color = kd;
        }
        pbr.texture = Some(texture);
        pbr.alpha_mode = AlphaMode::Blend;
    }
    if let Some(texture) = maps.emission {
        pbr.emission_texture = Some(texture);
        if pbr.emission.iter().all(|&c| c <= 0.0) {
            pbr.emission = m
                .emissive
                .filter(|e| e.iter().any(|&c| c > 0.0))
                .unwrap_or([1.0; 3]);
            pbr.emission_strength = 1.0;
        }
    }
    if let Some(texture) = maps.specular_color {
        if pbr.specular <= 0.0 {
            // A diffuse material made PBR: the specular layer the map is for, rough by Ns.
            pbr.specular = 1.0;
            pbr.roughness = m
                .shininess
                .map_or(0.5, |ns| (2.0 / (ns.max(0.0) + 2.0)).sqrt().sqrt())
                .clamp(0.0, 1.0);
        }
        pbr.specular_color = m
            .specular
            .filter(|k| k.iter().any(|&c| c > 0.0))
            .unwrap_or([1.0; 3]);
        pbr.specular_color_texture = Some(texture);
    }
    if let Some(texture) = maps.metallic_roughness {
        pbr.metallic_roughness_texture = Some(texture);
        let factor = |key: &str| {
            m.unknown_param
                .get(key)
                .and_then(|v| v.trim().parse::<f32>().ok())
        };
        if maps.has_roughness_map {
            pbr.roughness = factor("Pr").unwrap_or(1.0).clamp(0.0, 1.0);
        }
        if maps.has_metallic_map {
            pbr.metallic = factor("Pm").unwrap_or(1.0).clamp(0.0, 1.0);
        }
    }
    Material::Pbr(Box::new(pbr))
}

/// A grey image (every texel's channels within 2 of each other): a height map, not a normal map.
pub fn is_height_map(t: &Texture) -> bool {
    t.rgba8.chunks_exact(4).all(|p| {
        let (lo, hi) = (p[0].min(p[1]).min(p[2]), p[0].max(p[1]).max(p[2]));
        hi - lo <= 2
    })
}

/// UV units of displacement per unit of height at `-bm 1` (see the module's doc).
const HEIGHT_SCALE: f32 = 0.02;

/// A tangent-space normal map (+Y towards increasing v, up the image) from a height map, by
/// central differences with wrap-around.
pub fn normal_map_from_height(height: &Texture, strength: f32) -> Texture {
    let (w, h) = (height.width as usize, height.height as usize);
    let at = |x: usize, y: usize| f32::from(height.rgba8[4 * (y * w + x)]) / 255.0;
    let scale = strength * HEIGHT_SCALE;
    let mut rgba = Vec::with_capacity(4 * w * h);
    for y in 0..h {
        for x in 0..w {
            // Derivatives in UV units: texels per unit is the image's size.
            let du = (at((x + 1) % w, y) - at((x + w - 1) % w, y)) * 0.5 * w as f32;
            let dv = (at(x, (y + h - 1) % h) - at(x, (y + 1) % h)) * 0.5 * h as f32;
            let n = glam::Vec3::new(-scale * du, -scale * dv, 1.0).normalize();
            let encode = |c: f32| ((c * 0.5 + 0.5) * 255.0).round().clamp(0.0, 255.0) as u8;
            rgba.extend([encode(n.x), encode(n.y), encode(n.z), 255]);
        }
    }
    Texture {
        name: format!("{} (normal map from height)", height.name),
        width: height.width,
        height: height.height,
        rgba8: rgba.into(),
        sampler: height.sampler,
    }
}

/// A roughness image (grey) from a shininess image multiplying `ns`: each texel √α with α =
/// √(2/(Ns+2)), the Blinn–Phong match of the MTL mapping.
pub fn roughness_from_shininess(shininess: &Texture, ns: f32) -> Texture {
    let rgba: Vec<u8> = shininess
        .rgba8
        .chunks_exact(4)
        .flat_map(|p| {
            let texel_ns = ns.max(0.0) * f32::from(brightness(p)) / 255.0;
            let rough = (2.0 / (texel_ns + 2.0)).sqrt().sqrt();
            let byte = (rough * 255.0).round().clamp(0.0, 255.0) as u8;
            [byte, byte, byte, 255]
        })
        .collect();
    Texture {
        name: format!("{} (roughness from shininess)", shininess.name),
        rgba8: rgba.into(),
        ..shininess.clone()
    }
}

/// The brightness of a texel, 0–255.
fn brightness(p: &[u8]) -> u8 {
    ((u16::from(p[0]) + u16::from(p[1]) + u16::from(p[2])) / 3) as u8
}

/// The texel of `t` nearest to texel (x, y) of a `w`×`h` image.
fn nearest(t: &Texture, x: usize, y: usize, w: usize, h: usize) -> &[u8] {
    let tx = x * t.width as usize / w;
    let ty = y * t.height as usize / h;
    let i = 4 * (ty * t.width as usize + tx);
    &t.rgba8[i..i + 4]
}

/// `base`'s colours (white without one) with `coverage` as alpha: its alpha channel where it has
/// one that is not all opaque, else its brightness; at `base`'s size.
pub fn with_alpha(base: Option<&Texture>, coverage: &Texture) -> Texture {
    let (w, h) = base.map_or((coverage.width, coverage.height), |b| (b.width, b.height));
    let (w, h) = (w as usize, h as usize);
    let has_alpha = coverage.rgba8.chunks_exact(4).any(|p| p[3] < 255);
    let mut rgba = Vec::with_capacity(4 * w * h);
    for y in 0..h {
        for x in 0..w {
            let colour = base.map_or(&[255u8, 255, 255, 255][..], |b| nearest(b, x, y, w, h));
            let c = nearest(coverage, x, y, w, h);
            rgba.extend([
                colour[0],
                colour[1],
                colour[2],
                if has_alpha { c[3] } else { brightness(c) },
            ]);
        }
    }
    Texture {
        name: format!(
            "{} (alpha from {})",
            base.map_or("white", |b| b.name.as_str()),
            coverage.name
        ),
        width: w as u32,
        height: h as u32,
        rgba8: rgba.into(),
        sampler: base.map_or(coverage.sampler, |b| b.sampler),
    }
}

/// glTF's metallic-roughness image from `map_Pr` (green) and `map_Pm` (blue), each as brightness
/// (1 where missing), at the larger of their sizes.
pub fn metallic_roughness(roughness: Option<&Texture>, metallic: Option<&Texture>) -> Texture {
    let size = |t: Option<&Texture>| t.map_or((1, 1), |t| (t.width, t.height));
    let ((rw, rh), (mw, mh)) = (size(roughness), size(metallic));
    let (w, h) = (rw.max(mw) as usize, rh.max(mh) as usize);
    let channel = |t: Option<&Texture>, x, y| t.map_or(255, |t| brightness(nearest(t, x, y, w, h)));
    let mut rgba = Vec::with_capacity(4 * w * h);
    for y in 0..h {
        for x in 0..w {
            rgba.extend([0, channel(roughness, x, y), channel(metallic, x, y), 255]);
        }
    }
    let name = [roughness, metallic]
        .iter()
        .flatten()
        .map(|t| t.name.as_str())
        .collect::<Vec<_>>()
        .join(" + ");
    Texture {
        name: format!("{name} (metallic-roughness)"),
        width: w as u32,
        height: h as u32,
        rgba8: rgba.into(),
        sampler: roughness
            .or(metallic)
            .map(|t| t.sampler)
            .unwrap_or_default(),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn options_are_parsed_and_the_file_follows_them() {
        let parsed =
            parse_map("-bm 0.5 -s 2 3 1 -o 0.25 0.5 -clamp on -imfchan r my normal.png").unwrap();
        assert_eq!(
            parsed,
            MapStatement {
                file: "my normal.png".into(),
                bump: 0.5,
                offset: [0.25, 0.5],
                scale: [2.0, 3.0],
            }
        );
        assert_eq!(parse_map("tex.png").unwrap().file, "tex.png");
        assert_eq!(
            parse_map("-5.png").unwrap().file,
            "-5.png",
            "a file named like a number"
        );
        assert!(parse_map("-bm 2").is_none());
        assert!(parse_map("   ").is_none());
    }

    fn texture(width: u32, height: u32, texel: impl Fn(u32, u32) -> [u8; 4]) -> Texture {
        let mut rgba = Vec::new();
        for y in 0..height {
            for x in 0..width {
                rgba.extend(texel(x, y));
            }
        }
        Texture {
            name: "t".into(),
            width,
            height,
            rgba8: rgba.into(),
            sampler: Default::default(),
        }
    }

    #[test]
    fn a_height_ramp_tilts_the_normal_against_its_slope() {
        // Height rising to the right (+u): the surface faces left (−x) in tangent space.
        let ramp = texture(8, 4, |x, _| {
            let v = (x * 30) as u8;
            [v, v, v, 255]
        });
        assert!(is_height_map(&ramp));
        let normal = normal_map_from_height(&ramp, 1.0);
        let texel = &normal.rgba8[4 * (8 + 3)..4 * (8 + 3) + 4];
        let decode = |c: u8| f32::from(c) / 255.0 * 2.0 - 1.0;
        let n = glam::Vec3::new(decode(texel[0]), decode(texel[1]), decode(texel[2]));
        // du = 30/255 per texel × 8 texels per unit; x = −0.02 du / |…|.
        let du = 30.0 / 255.0 * 8.0;
        let expected = glam::Vec3::new(-0.02 * du, 0.0, 1.0).normalize();
        assert!((n - expected).length() < 0.01, "{n} vs {expected}");
        let flat_normal_map = texture(2, 2, |_, _| [128, 128, 255, 255]);
        assert!(!is_height_map(&flat_normal_map));
    }

    #[test]
    fn coverage_comes_from_alpha_or_brightness_at_the_base_size() {
        let base = texture(4, 2, |x, _| [x as u8 * 60, 0, 0, 255]);
        let grey = texture(2, 1, |x, _| {
            [x as u8 * 200, x as u8 * 200, x as u8 * 200, 255]
        });
        let joined = with_alpha(Some(&base), &grey);
        assert_eq!((joined.width, joined.height), (4, 2));
        let alphas: Vec<u8> = joined.rgba8.chunks_exact(4).map(|p| p[3]).collect();
        assert_eq!(alphas, [0, 0, 200, 200, 0, 0, 200, 200]);
        assert_eq!(joined.rgba8[4 * 3], 180, "base colour kept");
        let cut_out = texture(1, 1, |_, _| [255, 255, 255, 17]);
        assert_eq!(with_alpha(None, &cut_out).rgba8[..], [255, 255, 255, 17]);
    }

    #[test]
    fn roughness_and_metallic_pack_into_green_and_blue() {
        let rough = texture(2, 1, |x, _| [x as u8 * 100; 4]);
        let packed = metallic_roughness(Some(&rough), None);
        assert_eq!(packed.rgba8[..], [0, 0, 255, 255, 0, 100, 255, 255]);
    }
}
