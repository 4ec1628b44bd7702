//! Materials onto `Material::Pbr`: metallic-roughness, normal maps, emission, transmission, IOR,
//! volume and alpha, with their textures (decoded once per image and sampler) and the
//! `KHR_texture_transform` rt can honour; `KHR_materials_specular`, `KHR_materials_clearcoat`,
//! `KHR_materials_sheen`, `KHR_materials_anisotropy`, `KHR_materials_diffuse_transmission` and
//! `KHR_materials_iridescence` with their textures (the coat's own normal map included), and
//! `KHR_materials_dispersion`, and the draft `KHR_materials_volume_scatter`.

use super::Loader;
use super::buffers::read_uri;
use rt_core::material::{AlphaMode, Material, Pbr};
use rt_core::scene::{Filter, Texture, TextureSampler, Wrap};

impl Loader<'_> {
    /// rt's texture for a glTF texture: its image decoded once for each sampler that reads it.
    fn texture(&mut self, texture: &gltf::Texture) -> std::result::Result<usize, String> {
        let image = texture.source();
        let sampler = sampler_of(&texture.sampler());
        if let Some(&i) = self.texture_of_image.get(&(image.index(), sampler)) {
            return Ok(i);
        }
        let bytes = match image.source() {
            gltf::image::Source::View { view, .. } => {
                let buffer = &self.buffers[view.buffer().index()];
                let end = view.offset() as u64 + view.length() as u64;
                if end > buffer.len() as u64 {
                    return Err(format!(
                        "image {}: its view ends past its buffer",
                        image.index()
                    ));
                }
                buffer[view.offset()..end as usize].to_vec()
            }
            gltf::image::Source::Uri { uri, .. } => read_uri(uri, self.base, self.read_file)
                .map_err(|e| format!("image {}: {e}", image.index()))?,
        };
        let name = image
            .name()
            .map(str::to_string)
            .unwrap_or_else(|| format!("{} image {}", self.path.display(), image.index()));
        let decoded =
            decode_texture(&bytes).map_err(|e| format!("image {}: {e}", image.index()))?;
        let index = self.textures.len();
        self.textures.push(Texture {
            sampler,
            name,
            width: decoded.width(),
            height: decoded.height(),
            rgba8: decoded.into_raw().into(),
        });
        self.texture_of_image
            .insert((image.index(), sampler), index);
        Ok(index)
    }

    /// The texture of one material slot; `transform` is the slot's `KHR_texture_transform` and
    /// `baked` the one baked into the mesh's UVs (the base colour texture's).
    fn slot(
        &mut self,
        info: Option<SlotInfo>,
        baked: Option<UvTransform>,
        what: &str,
    ) -> std::result::Result<Option<usize>, String> {
        let Some((texture, tex_coord, transform)) = info else {
            return Ok(None);
        };
        if tex_coord != 0 {
            log::warn!(
                "{}: the {what} uses UV set {tex_coord}; rt reads only the first: ignoring it",
                self.path.display()
            );
            return Ok(None);
        }
        if transform.is_some() && transform != baked {
            log::warn!(
                "{}: the {what}'s KHR_texture_transform differs from the base colour texture's \
                 and is not applied (rt bakes the base colour texture's into the UVs, which every \
                 texture of the material then uses)",
                self.path.display()
            );
        }
        self.texture(&texture).map(Some)
    }

    pub(super) fn material(&mut self, m: &gltf::Material) -> std::result::Result<Material, String> {
        let pbr = m.pbr_metallic_roughness();
        let base_color = pbr.base_color_factor();
        let base_info = info(pbr.base_color_texture());
        let baked = base_info.as_ref().and_then(|i| i.2);
        let texture = self.slot(base_info, baked, "base colour texture")?;
        let metallic_roughness_texture = self.slot(
            info(pbr.metallic_roughness_texture()),
            baked,
            "metallic-roughness texture",
        )?;
        let normal = m.normal_texture();
        let normal_scale = normal.as_ref().map_or(1.0, |n| n.scale());
        let normal_texture = self.slot(
            normal.map(|n| (n.texture(), n.tex_coord(), None)),
            baked,
            "normal map",
        )?;
        let emission_texture = self.slot(info(m.emissive_texture()), baked, "emissive texture")?;
        if m.occlusion_texture().is_some() {
            log::info!(
                "{}: material {}: the occlusion texture is not used (the path tracer computes \
                 occlusion itself, as Cycles does)",
                self.path.display(),
                m.index().map_or("default".into(), |i| i.to_string())
            );
        }
        let alpha_mode = match m.alpha_mode() {
            gltf::material::AlphaMode::Opaque => AlphaMode::Opaque,
            gltf::material::AlphaMode::Mask => AlphaMode::Mask,
            gltf::material::AlphaMode::Blend => AlphaMode::Blend,
        };
        let cutoff = m.alpha_cutoff().unwrap_or(0.5);
        let transmission = m.transmission().map_or(0.0, |t| t.transmission_factor());
        let volume = m.volume();
        let (attenuation_color, attenuation_distance) =
            volume.as_ref().map_or(([1.0; 3], None), |v| {
                let d = v.attenuation_distance();
                (
                    v.attenuation_color(),
                    (d.is_finite() && d > 0.0).then_some(d),
                )
            });
        let clamp01 = |v: f32| {
            if v.is_finite() {
                v.clamp(0.0, 1.0)
            } else {
                0.0
            }
        };
        let colour = |c: [f32; 3]| c.map(|v| if v.is_finite() { v.max(0.0) } else { 0.0 });
        let layers = self.layers(m, baked)?;
        let ior = m
            .ior()
            .filter(|i| i.is_finite() && *i >= 1.0)
            .unwrap_or(1.5);
        Ok(Material::Pbr(Box::new(Pbr {
            base_color: colour([base_color[0], base_color[1], base_color[2]]),
            texture,
            metallic_roughness_texture,
            normal_texture,
            normal_scale: if normal_scale.is_finite() {
                normal_scale
            } else {
                1.0
            },
            metallic: clamp01(pbr.metallic_factor()),
            roughness: clamp01(pbr.roughness_factor()),
            ior,
            transmission: clamp01(transmission),
            // glTF: transmission (specular or diffuse) without a volume is a thin-walled surface
            // (no medium behind it: a leaf or a sheet of paper does not swallow the fog).
            thin_walled: volume.is_none()
                && (transmission > 0.0 || layers.diffuse_transmission > 0.0),
            attenuation_color: colour(attenuation_color).map(|c| c.min(1.0)),
            attenuation_distance,
            emission: colour(m.emissive_factor()),
            emission_strength: m
                .emissive_strength()
                .filter(|s| s.is_finite() && *s >= 0.0)
                .unwrap_or(1.0),
            emission_texture,
            alpha_mode,
            alpha: clamp01(base_color[3]),
            alpha_cutoff: if cutoff.is_finite() { cutoff } else { 0.5 },
            ..layers
        })))
    }

    /// `KHR_materials_specular`, `_clearcoat` and `_sheen`: their factors (glTF's defaults where
    /// absent or malformed, clamped to their ranges) and textures (`baked`: the base colour
    /// texture's transform, see `slot`).
    fn layers(
        &mut self,
        m: &gltf::Material,
        baked: Option<UvTransform>,
    ) -> std::result::Result<Pbr, String> {
        let unit = |v: f32, default: f32| {
            if v.is_finite() {
                v.clamp(0.0, 1.0)
            } else {
                default
            }
        };
        let mut out = Pbr::default();
        if let Some(s) = m.specular() {
            out.specular = unit(s.specular_factor(), 1.0);
            out.specular_color = s
                .specular_color_factor()
                .map(|c| if c.is_finite() { c.max(0.0) } else { 1.0 });
            out.specular_texture =
                self.slot(info(s.specular_texture()), baked, "specular texture")?;
            out.specular_color_texture = self.slot(
                info(s.specular_color_texture()),
                baked,
                "specular colour texture",
            )?;
        }
        let number = |v: &gltf::json::Value, key: &str, default: f32| {
            v.get(key)
                .and_then(gltf::json::Value::as_f64)
                .map_or(default, |x| unit(x as f32, default))
        };
        if let Some(c) = m.extension_value("KHR_materials_clearcoat") {
            out.clearcoat = number(c, "clearcoatFactor", 0.0);
            out.clearcoat_roughness = number(c, "clearcoatRoughnessFactor", 0.0);
            out.clearcoat_texture = self.json_slot(c, "clearcoatTexture", baked)?;
            out.clearcoat_roughness_texture =
                self.json_slot(c, "clearcoatRoughnessTexture", baked)?;
            out.clearcoat_normal_texture = self.json_slot(c, "clearcoatNormalTexture", baked)?;
            out.clearcoat_normal_scale = c
                .get("clearcoatNormalTexture")
                .and_then(|t| t.get("scale"))
                .and_then(gltf::json::Value::as_f64)
                .map_or(1.0, |x| x as f32)
                .clamp(-1e3, 1e3);
        }
        if let Some(s) = m.extension_value("KHR_materials_sheen") {
            if let Some(c) = s.get("sheenColorFactor").and_then(|c| c.as_array())
                && c.len() == 3
            {
                for (out, v) in out.sheen_color.iter_mut().zip(c) {
                    *out = v.as_f64().map_or(0.0, |x| unit(x as f32, 0.0));
                }
            }
            out.sheen_roughness = number(s, "sheenRoughnessFactor", 0.0);
            out.sheen_color_texture = self.json_slot(s, "sheenColorTexture", baked)?;
            out.sheen_roughness_texture = self.json_slot(s, "sheenRoughnessTexture", baked)?;
        }
        if let Some(i) = m.extension_value("KHR_materials_iridescence") {
            out.iridescence = number(i, "iridescenceFactor", 0.0);
            let positive = |key: &str, default: f32| {
                i.get(key)
                    .and_then(gltf::json::Value::as_f64)
                    .filter(|x| x.is_finite())
                    .map_or(default, |x| (x as f32).max(0.0))
            };
            out.iridescence_ior = positive("iridescenceIor", 1.3).max(1.0);
            out.iridescence_thickness_min = positive("iridescenceThicknessMinimum", 100.0);
            out.iridescence_thickness_max = positive("iridescenceThicknessMaximum", 400.0);
            out.iridescence_texture = self.json_slot(i, "iridescenceTexture", baked)?;
            out.iridescence_thickness_texture =
                self.json_slot(i, "iridescenceThicknessTexture", baked)?;
        }
        if let Some(a) = m.extension_value("KHR_materials_anisotropy") {
            out.anisotropy = number(a, "anisotropyStrength", 0.0);
            out.anisotropy_rotation = a
                .get("anisotropyRotation")
                .and_then(gltf::json::Value::as_f64)
                .filter(|x| x.is_finite())
                .map_or(0.0, |x| (x % std::f64::consts::TAU) as f32);
            out.anisotropy_texture = self.json_slot(a, "anisotropyTexture", baked)?;
        }
        if let Some(d) = m.extension_value("KHR_materials_dispersion") {
            out.dispersion = d
                .get("dispersion")
                .and_then(gltf::json::Value::as_f64)
                .filter(|x| x.is_finite())
                .map_or(0.0, |x| (x as f32).max(0.0));
        }
        if let Some(d) = m.extension_value("KHR_materials_diffuse_transmission") {
            out.diffuse_transmission = number(d, "diffuseTransmissionFactor", 0.0);
            if let Some(c) = d
                .get("diffuseTransmissionColorFactor")
                .and_then(|c| c.as_array())
                && c.len() == 3
            {
                for (out, v) in out.diffuse_transmission_color.iter_mut().zip(c) {
                    *out = v
                        .as_f64()
                        .filter(|x| x.is_finite())
                        .map_or(1.0, |x| (x as f32).max(0.0));
                }
            }
            out.diffuse_transmission_texture =
                self.json_slot(d, "diffuseTransmissionTexture", baked)?;
            out.diffuse_transmission_color_texture =
                self.json_slot(d, "diffuseTransmissionColorTexture", baked)?;
        }
        // The draft `KHR_materials_volume_scatter` (glTF PR 2453): the colour the volume takes
        // after scattering many times, and its phase function's anisotropy.
        if let Some(v) = m.extension_value("KHR_materials_volume_scatter") {
            if let Some(c) = v.get("multiscatterColor").and_then(|c| c.as_array())
                && c.len() == 3
            {
                for (out, v) in out.multiscatter_color.iter_mut().zip(c) {
                    *out = v.as_f64().map_or(0.0, |x| unit(x as f32, 0.0));
                }
            }
            out.scatter_anisotropy = v
                .get("scatterAnisotropy")
                .and_then(gltf::json::Value::as_f64)
                .filter(|x| x.is_finite())
                .map_or(0.0, |x| (x as f32).clamp(-0.99, 0.99));
        }
        Ok(out)
    }

    /// The texture an extension's `textureInfo` at `key` names (its index, UV set and
    /// `KHR_texture_transform`); a malformed one is an error naming it.
    fn json_slot(
        &mut self,
        extension: &gltf::json::Value,
        key: &str,
        baked: Option<UvTransform>,
    ) -> std::result::Result<Option<usize>, String> {
        let Some(v) = extension.get(key) else {
            return Ok(None);
        };
        let index = v.get("index").and_then(gltf::json::Value::as_u64);
        let texture = index.and_then(|i| self.document.textures().nth(i as usize));
        let Some(texture) = texture else {
            return Err(format!("{key}: no texture {index:?} in the file"));
        };
        let tex_coord = v
            .get("texCoord")
            .and_then(gltf::json::Value::as_u64)
            .unwrap_or(0) as u32;
        let transform = v
            .get("extensions")
            .and_then(|e| e.get("KHR_texture_transform"))
            .map(|t| {
                let pair = |key: &str, default: [f32; 2]| {
                    t.get(key)
                        .and_then(|p| p.as_array())
                        .filter(|p| p.len() == 2)
                        .map_or(default, |p| {
                            [0, 1].map(|i| p[i].as_f64().map_or(default[i], |x| x as f32))
                        })
                };
                UvTransform {
                    offset: pair("offset", [0.0, 0.0]),
                    rotation: t
                        .get("rotation")
                        .and_then(gltf::json::Value::as_f64)
                        .unwrap_or(0.0) as f32,
                    scale: pair("scale", [1.0, 1.0]),
                }
            });
        self.slot(Some((texture, tex_coord, transform)), baked, key)
    }
}

/// A texture slot as `Loader::slot` takes it: the texture, its UV set and its transform.
type SlotInfo<'a> = (gltf::Texture<'a>, u32, Option<UvTransform>);

fn info(i: Option<gltf::texture::Info<'_>>) -> Option<SlotInfo<'_>> {
    i.map(|i| {
        let t = i.texture_transform().map(|t| UvTransform {
            offset: t.offset(),
            rotation: t.rotation(),
            scale: t.scale(),
        });
        (i.texture(), i.tex_coord(), t)
    })
}

/// A `KHR_texture_transform`: offset, rotation (radians) and scale.
#[derive(Clone, Copy, Debug, PartialEq)]
struct UvTransform {
    offset: [f32; 2],
    rotation: f32,
    scale: [f32; 2],
}

/// rt's sampler for a glTF sampler: its wraps and its magnification filter (rt has no mipmaps).
fn sampler_of(sampler: &gltf::texture::Sampler) -> TextureSampler {
    use gltf::texture::{MagFilter, WrappingMode};
    let wrap = |w: WrappingMode| match w {
        WrappingMode::ClampToEdge => Wrap::ClampToEdge,
        WrappingMode::MirroredRepeat => Wrap::MirroredRepeat,
        WrappingMode::Repeat => Wrap::Repeat,
    };
    TextureSampler {
        wrap_s: wrap(sampler.wrap_s()),
        wrap_t: wrap(sampler.wrap_t()),
        filter: match sampler.mag_filter() {
            Some(MagFilter::Nearest) => Filter::Nearest,
            _ => Filter::Linear,
        },
    }
}

fn decode_texture(bytes: &[u8]) -> std::result::Result<image::RgbaImage, String> {
    if crate::texture::is_ktx2(bytes) {
        return crate::texture::transcode_basis(bytes);
    }
    let reader = image::ImageReader::new(std::io::Cursor::new(bytes))
        .with_guessed_format()
        .map_err(|e| e.to_string())?;
    let (w, h) = reader
        .into_dimensions()
        .map_err(|e| format!("unreadable image: {e}"))?;
    let limit = crate::texture::MAX_TEXTURE_SIDE;
    if w > limit || h > limit {
        return Err(format!("{w}x{h}; the limit is {limit} per side"));
    }
    image::ImageReader::new(std::io::Cursor::new(bytes))
        .with_guessed_format()
        .map_err(|e| e.to_string())?
        .decode()
        .map(|i| i.to_rgba8())
        .map_err(|e| format!("unreadable image: {e}"))
}
