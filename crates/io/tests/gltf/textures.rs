//! Textures, texture transforms, samplers, emissive textures and alpha modes.

use super::*;

/// A base colour texture (a data-URI PNG) with a `KHR_texture_transform`: the image is decoded,
/// and its offset, rotation and scale are baked into the UVs (then flipped to rt's v-up).
#[test]
fn textures_load_and_texture_transforms_bake_into_the_uvs() {
    let mut png = std::io::Cursor::new(Vec::new());
    image::RgbaImage::from_raw(2, 1, vec![255, 0, 0, 255, 0, 0, 255, 255])
        .unwrap()
        .write_to(&mut png, image::ImageFormat::Png)
        .unwrap();
    let uri = format!(
        "data:image/png;base64,{}",
        base64::engine::general_purpose::STANDARD.encode(png.get_ref())
    );
    let mut doc = document();
    doc["images"] = json!([{"uri": uri}]);
    doc["textures"] = json!([{"source": 0}]);
    doc["extensionsUsed"]
        .as_array_mut()
        .unwrap()
        .push(json!("KHR_texture_transform"));
    doc["materials"][0]["pbrMetallicRoughness"]["baseColorTexture"] = json!({"index": 0,
        "extensions": {"KHR_texture_transform": {"offset": [0.5, 0.25], "scale": [2.0, 3.0]}}});
    doc["materials"][0]["normalTexture"] = json!({"index": 0, "scale": 0.5});
    // Vertex colours: COLOR_0 as normalized u8 RGBA, a fifth buffer view.
    let mut buffer = quad_buffer();
    buffer.extend([
        255u8, 0, 0, 255, 0, 255, 0, 255, 0, 0, 255, 255, 255, 255, 255, 255,
    ]);
    doc["buffers"][0]["byteLength"] = json!(buffer.len());
    doc["bufferViews"]
        .as_array_mut()
        .unwrap()
        .push(json!({"buffer": 0, "byteOffset": 140, "byteLength": 16}));
    doc["accessors"]
        .as_array_mut()
        .unwrap()
        .push(json!({"bufferView": 4, "componentType": 5121,
        "normalized": true, "count": 4, "type": "VEC4"}));
    doc["meshes"][0]["primitives"][0]["attributes"]["COLOR_0"] = json!(4);
    doc["buffers"][0]["uri"] = json!(format!(
        "data:application/octet-stream;base64,{}",
        base64::engine::general_purpose::STANDARD.encode(&buffer)
    ));
    let scene = load(&serde_json::to_vec(&doc).unwrap(), None).unwrap();
    let colors = scene.objects[0].mesh.colors.as_ref().expect("COLOR_0 read");
    assert_eq!(colors[1], glam::Vec3::Y);
    assert_eq!(scene.textures.len(), 1, "one image, decoded once");
    assert_eq!((scene.textures[0].width, scene.textures[0].height), (2, 1));
    let Material::Pbr(p) = &scene.objects[0].material else {
        panic!()
    };
    assert_eq!(
        (p.texture, p.normal_texture, p.normal_scale),
        (Some(0), Some(0), 0.5)
    );
    // Vertex 0 has glTF uv (0, 0.25): scaled (0, 0.75), offset (0.5, 1.0), v flipped: (0.5, 0.0).
    let uv = scene.objects[0].mesh.uvs.as_ref().unwrap()[0];
    assert!((uv - glam::Vec2::new(0.5, 0.0)).length() < 1e-6, "{uv}");
    rt_core::GpuScene::build(&scene).unwrap();
}

/// `document()` with a 2×1 data-URI PNG as image 0.
fn document_with_image() -> Value {
    let mut png = std::io::Cursor::new(Vec::new());
    image::RgbaImage::from_raw(2, 1, vec![255, 0, 0, 255, 0, 0, 255, 0])
        .unwrap()
        .write_to(&mut png, image::ImageFormat::Png)
        .unwrap();
    let mut doc = document();
    doc["images"] = json!([{"uri": format!(
        "data:image/png;base64,{}",
        base64::engine::general_purpose::STANDARD.encode(png.get_ref())
    )}]);
    doc
}

/// Samplers' wrap modes and magnification filter reach the textures (one image read through two
/// samplers is two textures; through the same sampler, one); the emissive texture is an emission
/// image; MASK keeps its cutoff and BLEND the base colour factor's alpha; the occlusion texture
/// is left out.
#[test]
fn samplers_emissive_textures_and_alpha_modes_map_onto_the_material() {
    use rt_core::material::AlphaMode;
    use rt_core::{Filter, Wrap};
    let mut doc = document_with_image();
    doc["samplers"] = json!([
        {"wrapS": 33071, "wrapT": 33648, "magFilter": 9728},
        {}
    ]);
    doc["textures"] = json!([
        {"source": 0, "sampler": 0},
        {"source": 0, "sampler": 1},
        {"source": 0, "sampler": 0}
    ]);
    let m = &mut doc["materials"][0];
    m["pbrMetallicRoughness"]["baseColorTexture"] = json!({"index": 0});
    m["pbrMetallicRoughness"]["baseColorFactor"] = json!([1.0, 1.0, 1.0, 0.6]);
    m["pbrMetallicRoughness"]["metallicRoughnessTexture"] = json!({"index": 2});
    m["emissiveTexture"] = json!({"index": 1});
    m["occlusionTexture"] = json!({"index": 1});
    m["alphaMode"] = json!("MASK");
    m["alphaCutoff"] = json!(0.25);
    let scene = load(&embedded(doc.clone()), None).unwrap();
    assert_eq!(scene.textures.len(), 2, "one image through two samplers");
    let s = scene.textures[0].sampler;
    assert_eq!(
        (s.wrap_s, s.wrap_t, s.filter),
        (Wrap::ClampToEdge, Wrap::MirroredRepeat, Filter::Nearest)
    );
    assert_eq!(
        scene.textures[1].sampler,
        rt_core::TextureSampler::default()
    );
    let Material::Pbr(p) = &scene.objects[0].material else {
        panic!()
    };
    assert_eq!(
        (p.texture, p.metallic_roughness_texture, p.emission_texture),
        (Some(0), Some(0), Some(1))
    );
    assert_eq!(
        (p.alpha_mode, p.alpha, p.alpha_cutoff),
        (AlphaMode::Mask, 0.6, 0.25)
    );
    let gpu = rt_core::GpuScene::build(&scene).unwrap();
    assert!(gpu.features.alpha && gpu.features.textures);
    let g = &gpu.materials[0];
    assert_eq!(
        g.flags & rt_core::gpu_types::ALPHA_MASK,
        rt_core::gpu_types::ALPHA_MASK
    );
    // Clamp (1) on s, mirror (2) on t, nearest: 1 | 2 << 2 | 1 << 4 in the base and
    // metallic-roughness slots; the emission slot's sampler is the default (0).
    use rt_core::gpu_types::{SLOT_BASE, SLOT_EMISSION, SLOT_METALLIC_ROUGHNESS};
    assert_eq!(
        [SLOT_BASE, SLOT_METALLIC_ROUGHNESS, SLOT_EMISSION].map(|s| g.sampler_bits(s)),
        [0b11001, 0b11001, 0]
    );
    assert_ne!(
        g.texture(rt_core::gpu_types::SLOT_EMISSION).offset,
        rt_core::gpu_types::NO_TEXTURE
    );

    doc["materials"][0]["alphaMode"] = json!("BLEND");
    let scene = load(&embedded(doc.clone()), None).unwrap();
    let Material::Pbr(p) = &scene.objects[0].material else {
        panic!()
    };
    assert_eq!((p.alpha_mode, p.alpha), (AlphaMode::Blend, 0.6));
    // A project keeps samplers, the emission image and the alpha mode.
    let back = through_a_project(&scene);
    assert_eq!(back, scene);
}

/// The layers' textures (`KHR_materials_specular`'s through the gltf crate, `_clearcoat`'s and
/// `_sheen`'s from their JSON) map onto their slots and reach the GPU material; a texture index
/// that does not exist is an error naming the field.
#[test]
fn the_layers_textures_map_onto_their_slots() {
    use rt_core::gpu_types::{
        NO_TEXTURE, SLOT_CLEARCOAT, SLOT_CLEARCOAT_ROUGHNESS, SLOT_SHEEN_COLOR,
        SLOT_SHEEN_ROUGHNESS, SLOT_SPECULAR, SLOT_SPECULAR_COLOR,
    };
    let mut doc = document_with_image();
    doc["samplers"] = json!([{"magFilter": 9728}]);
    doc["textures"] = json!([{"source": 0}, {"source": 0, "sampler": 0}]);
    for ext in [
        "KHR_materials_specular",
        "KHR_materials_clearcoat",
        "KHR_materials_sheen",
    ] {
        doc["extensionsUsed"]
            .as_array_mut()
            .unwrap()
            .push(json!(ext));
    }
    let ext = doc["materials"][0]["extensions"].as_object_mut().unwrap();
    ext.insert(
        "KHR_materials_specular".into(),
        json!({"specularTexture": {"index": 0}, "specularColorTexture": {"index": 1}}),
    );
    ext.insert(
        "KHR_materials_clearcoat".into(),
        json!({"clearcoatFactor": 1.0, "clearcoatTexture": {"index": 0},
               "clearcoatRoughnessTexture": {"index": 1},
               "clearcoatNormalTexture": {"index": 0, "scale": 0.25}}),
    );
    ext.insert(
        "KHR_materials_sheen".into(),
        json!({"sheenColorFactor": [1.0, 1.0, 1.0], "sheenColorTexture": {"index": 1},
               "sheenRoughnessTexture": {"index": 0}}),
    );
    let scene = load(&embedded(doc.clone()), None).unwrap();
    let Material::Pbr(p) = &scene.objects[0].material else {
        panic!()
    };
    assert_eq!(
        [
            p.specular_texture,
            p.specular_color_texture,
            p.clearcoat_texture,
            p.clearcoat_roughness_texture,
            p.sheen_color_texture,
            p.sheen_roughness_texture
        ],
        [Some(0), Some(1), Some(0), Some(1), Some(1), Some(0)],
        "texture 1 is image 0 through the nearest sampler: a second decoding"
    );
    assert_eq!(
        (p.clearcoat_normal_texture, p.clearcoat_normal_scale),
        (Some(0), 0.25)
    );
    let gpu = rt_core::GpuScene::build(&scene).unwrap();
    let g = &gpu.materials[0];
    for slot in [
        rt_core::gpu_types::SLOT_CLEARCOAT_NORMAL,
        SLOT_CLEARCOAT,
        SLOT_CLEARCOAT_ROUGHNESS,
        SLOT_SHEEN_COLOR,
        SLOT_SHEEN_ROUGHNESS,
        SLOT_SPECULAR,
        SLOT_SPECULAR_COLOR,
    ] {
        assert_ne!(g.texture(slot).offset, NO_TEXTURE, "slot {slot}");
    }
    // Nearest filtering (bit 4) where texture 1 is bound, in both sampler words.
    assert_eq!(
        [
            SLOT_CLEARCOAT_ROUGHNESS,
            SLOT_SHEEN_COLOR,
            SLOT_SPECULAR_COLOR,
            SLOT_SPECULAR
        ]
        .map(|s| g.sampler_bits(s) & 16),
        [16, 16, 16, 0]
    );
    doc["materials"][0]["extensions"]["KHR_materials_sheen"]["sheenColorTexture"] =
        json!({"index": 7});
    let e = load(&embedded(doc), None).unwrap_err().to_string();
    assert!(e.contains("sheenColorTexture"), "{e}");
}

/// `EXT_texture_webp`, required and without a fallback image: the texture reads its WebP image.
#[test]
fn webp_textures_load() {
    let mut webp = std::io::Cursor::new(Vec::new());
    image::RgbaImage::from_raw(2, 1, vec![0, 255, 0, 255, 0, 0, 255, 255])
        .unwrap()
        .write_to(&mut webp, image::ImageFormat::WebP)
        .unwrap();
    let mut doc = document_with_image();
    doc["images"]
        .as_array_mut()
        .unwrap()
        .push(json!({"uri": format!(
            "data:image/webp;base64,{}",
            base64::engine::general_purpose::STANDARD.encode(webp.get_ref())
        )}));
    doc["textures"] = json!([{"extensions": {"EXT_texture_webp": {"source": 1}}}]);
    for list in ["extensionsUsed", "extensionsRequired"] {
        doc[list] = json!(["EXT_texture_webp"]);
    }
    doc["materials"][0]["pbrMetallicRoughness"]["baseColorTexture"] = json!({"index": 0});
    let scene = load(&embedded(doc), None).unwrap();
    assert_eq!(scene.textures.len(), 1);
    assert_eq!(
        &scene.textures[0].rgba8[..],
        &[0, 255, 0, 255, 0, 0, 255, 255]
    );
}

/// `KHR_texture_basisu`: a KTX2 (Basis Universal ETC1S) photograph transcodes to the image it was
/// encoded from (its 16×16 block means 0.6/255 off the original's on average and under 12/255 at
/// most: the codec is lossy; a flipped or channel-swapped image is tens off), in a glTF without
/// a fallback image and as a file texture alike; a damaged file is an error naming it.
#[test]
fn basis_universal_textures_transcode_to_the_encoded_image() {
    let data = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/data");
    let ktx2 = std::fs::read(data.join("kodim23.ktx2")).unwrap();
    let reference = image::open(data.join("kodim23-16x-box.png"))
        .unwrap()
        .to_rgb8();
    let check = |texture: &rt_core::scene::Texture, what: &str| {
        assert_eq!((texture.width, texture.height), (768, 512), "{what}");
        let (mut worst, mut total) = (0.0f64, 0.0f64);
        for (x, y, want) in reference.enumerate_pixels() {
            for c in 0..3 {
                let mut sum = 0u32;
                for dy in 0..16 {
                    for dx in 0..16 {
                        let i = 4 * ((y * 16 + dy) * 768 + x * 16 + dx) as usize;
                        sum += u32::from(texture.rgba8[i + c]);
                    }
                }
                let error = (f64::from(sum) / 256.0 - f64::from(want[c])).abs();
                (worst, total) = (worst.max(error), total + error);
            }
        }
        let mean = total / (3 * reference.len() / 3) as f64;
        eprintln!("{what}: block means off by {mean:.2} on average, {worst:.2} at most");
        assert!(
            mean < 1.5 && worst < 12.0,
            "{what}: block means off by {mean} on average, {worst} at most"
        );
    };

    let mut doc = document_with_image();
    doc["images"]
        .as_array_mut()
        .unwrap()
        .push(json!({"uri": format!(
            "data:image/ktx2;base64,{}",
            base64::engine::general_purpose::STANDARD.encode(&ktx2)
        )}));
    doc["textures"] = json!([{"extensions": {"KHR_texture_basisu": {"source": 1}}}]);
    for list in ["extensionsUsed", "extensionsRequired"] {
        doc[list] = json!(["KHR_texture_basisu"]);
    }
    doc["materials"][0]["pbrMetallicRoughness"]["baseColorTexture"] = json!({"index": 0});
    let scene = load(&embedded(doc), None).unwrap();
    assert_eq!(scene.textures.len(), 1);
    check(&scene.textures[0], "glTF");
    let file = rt_io::texture::load_texture(&data.join("kodim23.ktx2")).unwrap();
    check(&file, "file");

    let mut broken = ktx2.clone();
    broken.truncate(200);
    let dir = std::env::temp_dir().join(format!("rt-ktx2-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    std::fs::write(dir.join("broken.ktx2"), &broken).unwrap();
    let message = rt_io::texture::load_texture(&dir.join("broken.ktx2"))
        .unwrap_err()
        .to_string();
    std::fs::remove_dir_all(&dir).unwrap();
    assert!(
        message.contains("broken.ktx2") && message.contains("KTX2"),
        "{message}"
    );
}
