//! Supported features map onto the scene model: .glb and .gltf, external buffers, projects,
//! accessors without bounds.

use super::*;
use std::sync::Arc;

use base64::Engine as _;

use rt_core::light::{LightKind, SpotFalloff};

fn close(a: [f32; 3], b: [f32; 3]) -> bool {
    a.iter().zip(b).all(|(x, y)| (x - y).abs() < 1e-4)
}

#[test]
fn every_supported_feature_maps_onto_the_scene_model() {
    let scene = load(&embedded(document()), None).unwrap();
    assert_eq!(scene.objects.len(), 2);
    let (a, b) = (&scene.objects[0], &scene.objects[1]);
    assert_eq!((a.name.as_str(), b.name.as_str()), ("quad A", "quad B"));
    assert!(Arc::ptr_eq(&a.mesh, &b.mesh), "instances share their mesh");
    assert!(close(a.transform.translation, [1.0, 2.0, 3.0]));
    assert!(close(a.transform.scale, [2.0; 3]));
    assert!(
        close(b.transform.translation, [5.0, 0.0, 0.0]),
        "{:?}",
        b.transform
    );
    assert!(
        close(b.transform.rotation_deg, [0.0, 90.0, 0.0]),
        "{:?}",
        b.transform
    );
    let mesh = &a.mesh;
    assert_eq!(mesh.indices, vec![[0, 1, 2], [0, 2, 3]]);
    assert_eq!(mesh.normals.as_ref().unwrap()[0], glam::Vec3::Y);
    assert_eq!(
        mesh.uvs.as_ref().unwrap()[0],
        glam::Vec2::new(0.0, 0.75),
        "v flipped to rt's convention"
    );
    let Material::Pbr(p) = &a.material else {
        panic!("PBR expected")
    };
    assert_eq!(p.base_color, [0.5, 0.6, 0.7]);
    assert_eq!((p.metallic, p.roughness), (0.25, 0.75));
    assert_eq!((p.emission, p.emission_strength), ([1.0, 0.5, 0.25], 4.0));
    assert_eq!((p.transmission, p.ior), (0.5, 1.33));
    assert_eq!(
        (p.attenuation_color, p.attenuation_distance),
        ([0.5, 0.5, 1.0], Some(2.0))
    );
    let c = &scene.camera;
    assert!(close(c.from, [0.0, 1.0, 10.0]) && close(c.to, [0.0, 1.0, 9.0]));
    assert!((c.vfov_deg - 0.7f32.to_degrees()).abs() < 1e-4);
    assert_eq!(
        scene.settings.height,
        scene.settings.width / 2,
        "aspect ratio 2"
    );
    assert_eq!(scene.lights.len(), 2);
    let (bulb, spot) = (&scene.lights[0], &scene.lights[1]);
    assert_eq!(bulb.kind, LightKind::Point);
    assert!((bulb.intensity - 1.0).abs() < 1e-6, "683 cd = 1 W/sr");
    assert_eq!(bulb.color, [1.0, 0.5, 0.25]);
    assert!(close(bulb.position, [0.0, 5.0, 0.0]));
    assert_eq!(
        (spot.kind, spot.falloff),
        (LightKind::Spot, SpotFalloff::Gltf)
    );
    assert!((spot.intensity - 2.0).abs() < 1e-6);
    assert!(
        close(spot.direction, [0.0, -1.0, 0.0]),
        "{:?}",
        spot.direction
    );
    assert!((spot.inner_angle_deg - 0.2f32.to_degrees()).abs() < 1e-4);
    assert!((spot.outer_angle_deg - 0.6f32.to_degrees()).abs() < 1e-4);
    assert!(scene.environment.is_none(), "the file brings its lights");
    assert!(!p.thin_walled, "transmission with a volume refracts");
    let mut doc = document();
    let ext = doc["materials"][0]["extensions"].as_object_mut().unwrap();
    ext.remove("KHR_materials_volume");
    let thin = load(&embedded(doc), None).unwrap();
    let Material::Pbr(p) = &thin.objects[0].material else {
        panic!()
    };
    assert!(
        p.thin_walled,
        "transmission without a volume is thin-walled"
    );
    rt_core::GpuScene::build(&scene).unwrap();
}

#[test]
fn glb_and_embedded_gltf_agree_and_scenes_are_chosen() {
    let mut doc = document();
    let from_gltf = load(&embedded(doc.clone()), None).unwrap();
    let from_glb = load(&glb(&doc), None).unwrap();
    assert_eq!(from_gltf, from_glb);
    let second = load(&embedded(doc.clone()), Some(1)).unwrap();
    assert_eq!(second.objects.len(), 1);
    assert!(second.lights.is_empty());
    assert!(
        second.environment.is_none(),
        "its emissive material lights it"
    );
    let mut dark = doc.clone();
    dark["materials"][0]["emissiveFactor"] = json!([0, 0, 0]);
    let second = load(&embedded(dark), Some(1)).unwrap();
    assert!(
        second.environment.is_some(),
        "no light at all: the default environment"
    );
    let e = load(&embedded(doc.clone()), Some(7))
        .unwrap_err()
        .to_string();
    assert!(e.contains("no scene 7"), "{e}");
    // Without a camera: framed automatically.
    doc["scenes"][0]["nodes"] = json!([0]);
    let framed = load(&embedded(doc), None).unwrap();
    assert_ne!(framed.camera, rt_core::Camera::default());
}

#[test]
fn a_file_with_a_separate_bin_and_percent_encoded_name_loads_from_disk() {
    let dir = std::env::temp_dir().join(format!("rt-gltf-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    std::fs::write(dir.join("my quad.bin"), quad_buffer()).unwrap();
    let mut doc = document();
    doc["buffers"][0]["uri"] = json!("my%20quad.bin");
    let path = dir.join("scene.gltf");
    std::fs::write(&path, serde_json::to_vec(&doc).unwrap()).unwrap();
    assert_eq!(load_gltf(&path, None).unwrap().objects.len(), 2);
    std::fs::remove_file(dir.join("my quad.bin")).unwrap();
    let e = load_gltf(&path, None).unwrap_err().to_string();
    assert!(e.contains("my quad.bin"), "{e}");
    std::fs::remove_dir_all(&dir).ok();
}

/// A glTF scene saved as a project reloads as the same scene (materials, lights, camera, shared
/// meshes).
#[test]
fn a_gltf_scene_round_trips_through_a_project() {
    let scene = load(&embedded(document()), None).unwrap();
    let back = through_a_project(&scene);
    assert_eq!(back, scene);
    assert!(Arc::ptr_eq(&back.objects[0].mesh, &back.objects[1].mesh));
}

/// An orthographic glTF camera becomes rt's orthographic projection: its height is 2 × ymag (in
/// the camera node's scale), the image's aspect xmag / ymag; it survives a project's round trip.
#[test]
fn an_orthographic_gltf_camera_is_honoured() {
    let mut doc = document();
    doc["cameras"][0] = json!({"type": "orthographic",
        "orthographic": {"xmag": 3.0, "ymag": 1.5, "znear": 0.1, "zfar": 100.0}});
    doc["nodes"][3]["scale"] = json!([2.0, 2.0, 2.0]);
    let scene = load(&embedded(doc), None).unwrap();
    let c = &scene.camera;
    assert_eq!(c.projection, rt_core::camera::Projection::Orthographic);
    let height = c.ortho_height.expect("the file's height");
    assert!((height - 6.0).abs() < 1e-5, "2 × ymag × scale 2: {height}");
    assert_eq!(scene.settings.height, scene.settings.width / 2, "aspect 2");
    assert!(close(c.from, [0.0, 1.0, 10.0]));
    let back = through_a_project(&scene);
    assert_eq!(back.camera, scene.camera);
}

/// A glTF animation moves what its nodes carry: at time t a linearly animated mesh node stands
/// where its keys put it, a camera keyed with STEP holds until its next key; without a time the
/// nodes stand as the file places them.
#[test]
fn animations_move_meshes_and_cameras_at_the_time_asked_for() {
    let mut doc = document();
    let mut data = Vec::new();
    let floats = [
        0.0f32, 2.0, 1.0, 2.0, 3.0, 5.0, 2.0, 3.0, 0.0, 1.0, 10.0, 0.0, 1.0, 20.0,
    ];
    floats.iter().for_each(|f| data.extend(f.to_le_bytes()));
    let uri = base64::engine::general_purpose::STANDARD.encode(&data);
    doc["buffers"].as_array_mut().unwrap().push(json!({
        "byteLength": data.len(),
        "uri": format!("data:application/octet-stream;base64,{uri}")
    }));
    let views = doc["bufferViews"].as_array_mut().unwrap();
    let first_view = views.len();
    views.push(json!({"buffer": 1, "byteOffset": 0, "byteLength": 8}));
    views.push(json!({"buffer": 1, "byteOffset": 8, "byteLength": 24}));
    views.push(json!({"buffer": 1, "byteOffset": 32, "byteLength": 24}));
    let accessors = doc["accessors"].as_array_mut().unwrap();
    let first = accessors.len();
    accessors.push(
        json!({"bufferView": first_view, "componentType": 5126, "count": 2,
        "type": "SCALAR", "min": [0.0], "max": [2.0]}),
    );
    accessors.push(
        json!({"bufferView": first_view + 1, "componentType": 5126, "count": 2, "type": "VEC3"}),
    );
    accessors.push(
        json!({"bufferView": first_view + 2, "componentType": 5126, "count": 2, "type": "VEC3"}),
    );
    doc["animations"] = json!([{
        "samplers": [
            {"input": first, "output": first + 1, "interpolation": "LINEAR"},
            {"input": first, "output": first + 2, "interpolation": "STEP"}
        ],
        "channels": [
            {"sampler": 0, "target": {"node": 0, "path": "translation"}},
            {"sampler": 1, "target": {"node": 3, "path": "translation"}}
        ]
    }]);
    let bytes = embedded(doc);
    let at = |time: Option<f32>| {
        rt_io::gltf::load_gltf_bytes_at(
            &bytes,
            Path::new("test.gltf"),
            Path::new("."),
            &no_files,
            None,
            time,
        )
        .unwrap()
    };
    let still = at(None);
    assert!(close(
        still.objects[0].transform.translation,
        [1.0, 2.0, 3.0]
    ));
    let mid = at(Some(1.0));
    assert!(
        close(mid.objects[0].transform.translation, [3.0, 2.0, 3.0]),
        "{:?}",
        mid.objects[0].transform
    );
    assert!(
        close(mid.objects[0].transform.scale, [2.0; 3]),
        "scale kept from the node"
    );
    assert!(
        close(mid.camera.from, [0.0, 1.0, 10.0]),
        "STEP holds the first key"
    );
    let end = at(Some(5.0));
    assert!(close(end.objects[0].transform.translation, [5.0, 2.0, 3.0]));
    assert!(close(end.camera.from, [0.0, 1.0, 20.0]));
    assert!(
        close(end.objects[1].transform.translation, [5.0, 0.0, 0.0]),
        "not animated"
    );
    // The animation is kept with the scene at rest, and a project saved from it plays the same.
    let animation = still.animation.as_deref().expect("the animation is kept");
    assert_eq!(animation.channels.len(), 2);
    assert_eq!(still.objects[0].animation_node, Some(0));
    let project = through_a_project(&still);
    assert_eq!(project.animation, still.animation);
    for time in [1.0, 5.0] {
        let from_file = at(Some(time));
        let from_project = rt_core::posing::posed_at(&project, time);
        assert_eq!(from_project.objects, from_file.objects, "t = {time}");
        assert_eq!(from_project.camera, from_file.camera, "t = {time}");
    }
}

/// A project whose animation cannot play, or whose objects follow nodes it does not have, is
/// refused with the field named (a hand-edited or damaged file).
#[test]
fn projects_with_broken_animations_are_refused() {
    use rt_core::animation::{Animation, Node};
    use rt_io::project::{PROJECT_FORMAT, decode_archive, encode_archive};
    let mut scene = load(&embedded(document()), None).unwrap();
    let node = |parent| Node {
        parent,
        translation: [0.0; 3],
        rotation: [0.0, 0.0, 0.0, 1.0],
        scale: [1.0; 3],
    };
    scene.animation = Some(std::sync::Arc::new(Animation {
        nodes: vec![node(Some(1)), node(Some(0))],
        channels: Vec::new(),
    }));
    let path = Path::new("broken.rtproj");
    let decode = |scene: &Scene| {
        let bytes = encode_archive(scene, PROJECT_FORMAT, path).unwrap();
        decode_archive(&bytes, path, PROJECT_FORMAT, &Default::default())
            .unwrap_err()
            .to_string()
    };
    let circle = decode(&scene);
    assert!(
        circle.contains("animation node 0") && circle.contains("circle"),
        "{circle}"
    );
    scene.animation = Some(std::sync::Arc::new(Animation {
        nodes: vec![node(None)],
        channels: Vec::new(),
    }));
    scene.objects[0].animation_node = Some(4);
    let missing = decode(&scene);
    assert!(
        missing.contains("objects[0]") && missing.contains("node 4 does not exist"),
        "{missing}"
    );
}

/// The spec requires POSITION's min and max, and the gltf crate refuses files without them, but
/// exporters leave them out: rt computes its own bounds and opens such files (and ones whose
/// bounds are malformed) with the same geometry.
#[test]
fn position_accessors_without_min_and_max_still_load() {
    let full = load(&embedded(document()), None).unwrap();
    for bounds in [json!(null), json!("nonsense"), json!([1, 2])] {
        let mut doc = document();
        let accessor = doc["accessors"][0].as_object_mut().unwrap();
        if bounds.is_null() {
            accessor.remove("min");
            accessor.remove("max");
        } else {
            accessor.insert("min".into(), bounds.clone());
        }
        let scene = load(&embedded(doc), None).unwrap_or_else(|e| panic!("bounds {bounds}: {e}"));
        assert_eq!(scene.objects[0].mesh, full.objects[0].mesh);
    }
}

/// `KHR_materials_specular`, `_clearcoat`, `_sheen`, `_diffuse_transmission`, `_iridescence` and
/// `_anisotropy` map onto the material, even when the file
/// requires them; out-of-range factors are clamped and absent ones take glTF's defaults.
#[test]
fn specular_clearcoat_and_sheen_map_onto_the_layers() {
    let mut doc = document();
    let next = [
        "KHR_materials_specular",
        "KHR_materials_clearcoat",
        "KHR_materials_sheen",
        "KHR_materials_diffuse_transmission",
        "KHR_materials_iridescence",
        "KHR_materials_anisotropy",
        "KHR_materials_dispersion",
    ];
    for ext in next {
        doc["extensionsUsed"]
            .as_array_mut()
            .unwrap()
            .push(json!(ext));
    }
    doc["extensionsRequired"] = json!(next);
    let ext = doc["materials"][0]["extensions"].as_object_mut().unwrap();
    ext.insert(
        "KHR_materials_specular".into(),
        json!({"specularFactor": 0.5, "specularColorFactor": [1.5, 0.5, 0.25]}),
    );
    ext.insert(
        "KHR_materials_clearcoat".into(),
        json!({"clearcoatFactor": 0.8, "clearcoatRoughnessFactor": 1.5}),
    );
    ext.insert(
        "KHR_materials_sheen".into(),
        json!({"sheenColorFactor": [0.9, 0.2, -1.0], "sheenRoughnessFactor": 0.4}),
    );
    ext.insert(
        "KHR_materials_iridescence".into(),
        json!({"iridescenceFactor": 0.75, "iridescenceIor": 1.4,
               "iridescenceThicknessMaximum": 520.0}),
    );
    ext.insert(
        "KHR_materials_dispersion".into(),
        json!({"dispersion": 0.35}),
    );
    ext.insert(
        "KHR_materials_anisotropy".into(),
        json!({"anisotropyStrength": 1.5, "anisotropyRotation": 0.75}),
    );
    ext.insert(
        "KHR_materials_diffuse_transmission".into(),
        json!({"diffuseTransmissionFactor": 0.25, "diffuseTransmissionColorFactor": [0.5, 1.0, 0.0]}),
    );
    // Diffuse transmission alone, without a volume: a thin sheet (a leaf, paper), no medium
    // behind it.
    let mut sheet = doc.clone();
    let e = sheet["materials"][0]["extensions"].as_object_mut().unwrap();
    e.remove("KHR_materials_volume");
    e.remove("KHR_materials_transmission");
    let sheet = load(&embedded(sheet), None).unwrap();
    let Material::Pbr(p) = &sheet.objects[0].material else {
        panic!("PBR expected")
    };
    assert!(p.diffuse_transmission > 0.0 && p.transmission == 0.0 && p.thin_walled);
    let scene = load(&embedded(doc), None).unwrap();
    let Material::Pbr(p) = &scene.objects[0].material else {
        panic!("PBR expected")
    };
    assert_eq!((p.specular, p.specular_color), (0.5, [1.5, 0.5, 0.25]));
    assert_eq!((p.clearcoat, p.clearcoat_roughness), (0.8, 1.0), "clamped");
    assert_eq!((p.sheen_color, p.sheen_roughness), ([0.9, 0.2, 0.0], 0.4));
    assert_eq!(
        (p.diffuse_transmission, p.diffuse_transmission_color),
        (0.25, [0.5, 1.0, 0.0])
    );
    assert!(!p.thin_walled, "with a volume, transmission leads into it");
    assert_eq!(
        (
            p.iridescence,
            p.iridescence_ior,
            p.iridescence_thickness_min,
            p.iridescence_thickness_max
        ),
        (0.75, 1.4, 100.0, 520.0),
        "the minimum thickness defaults to 100 nm"
    );
    assert_eq!(
        (p.anisotropy, p.anisotropy_rotation),
        (1.0, 0.75),
        "strength clamped"
    );
    assert_eq!(p.dispersion, 0.35);
    let gpu = rt_core::GpuScene::build(&scene).unwrap();
    assert!(
        gpu.materials[0].flags & rt_core::gpu_types::TANGENTS != 0
            && gpu.tangents.len() == 3 * gpu.triangles.len(),
        "the direction of anisotropy brings the mesh's tangents"
    );
    let plain = load(&embedded(document()), None).unwrap();
    let Material::Pbr(p) = &plain.objects[0].material else {
        panic!()
    };
    assert_eq!((p.specular, p.specular_color), (1.0, [1.0; 3]));
    assert_eq!((p.clearcoat, p.sheen_color), (0.0, [0.0; 3]));
    assert_eq!(p.anisotropy, 0.0);
}

/// `KHR_mesh_quantization`: positions as 16-bit integers (scaled by the node), normals as
/// normalized bytes and UVs as normalized 16-bit integers read as the float quad they encode.
#[test]
fn quantized_attributes_read_as_the_floats_they_encode() {
    let mut buffer = Vec::new();
    for p in [[-1i16, 0, 1], [1, 0, 1], [1, 0, -1], [-1, 0, -1]] {
        p.iter().for_each(|c| buffer.extend(c.to_le_bytes()));
        buffer.extend([0u8; 2]); // stride 8
    }
    for _ in 0..4 {
        buffer.extend([0u8, 127, 0, 0]); // (0, 1, 0), stride 4
    }
    for uv in [[0u16, 16384], [65535, 16384], [65535, 65535], [0, 65535]] {
        uv.iter().for_each(|c| buffer.extend(c.to_le_bytes()));
    }
    for i in [0u16, 1, 2, 0, 2, 3] {
        buffer.extend(i.to_le_bytes());
    }
    let mut doc = document();
    for list in ["extensionsUsed", "extensionsRequired"] {
        doc[list] = json!(["KHR_mesh_quantization"]);
    }
    doc["accessors"] = json!([
        {"bufferView": 0, "componentType": 5122, "count": 4, "type": "VEC3",
         "min": [-1, 0, -1], "max": [1, 0, 1]},
        {"bufferView": 1, "componentType": 5120, "normalized": true, "count": 4, "type": "VEC3"},
        {"bufferView": 2, "componentType": 5123, "normalized": true, "count": 4, "type": "VEC2"},
        {"bufferView": 3, "componentType": 5123, "count": 6, "type": "SCALAR"}
    ]);
    doc["bufferViews"] = json!([
        {"buffer": 0, "byteOffset": 0, "byteLength": 32, "byteStride": 8},
        {"buffer": 0, "byteOffset": 32, "byteLength": 16, "byteStride": 4},
        {"buffer": 0, "byteOffset": 48, "byteLength": 16},
        {"buffer": 0, "byteOffset": 64, "byteLength": 12}
    ]);
    doc["buffers"] = json!([{"byteLength": buffer.len(), "uri": format!(
        "data:application/octet-stream;base64,{}",
        base64::engine::general_purpose::STANDARD.encode(&buffer)
    )}]);
    let quantized = load(&serde_json::to_vec(&doc).unwrap(), None).unwrap();
    let float = load(&embedded(document()), None).unwrap();
    let (q, f) = (&quantized.objects[0], &float.objects[0]);
    assert_eq!(q.mesh.positions, f.mesh.positions);
    assert_eq!(q.mesh.normals, f.mesh.normals);
    assert_eq!(q.mesh.indices, f.mesh.indices);
    assert_eq!(q.transform, f.transform);
    for (a, b) in q
        .mesh
        .uvs
        .as_ref()
        .unwrap()
        .iter()
        .zip(f.mesh.uvs.as_ref().unwrap())
    {
        assert!((*a - *b).abs().max_element() < 1e-4, "{a} vs {b}");
    }
}

/// `EXT_meshopt_compression`: the quad's attributes (mode ATTRIBUTES) and indices (TRIANGLES)
/// compressed by meshoptimizer into one buffer, the views' own buffer a fallback without data:
/// the same mesh as the plain file.
#[test]
fn meshopt_compressed_views_load_as_the_plain_ones() {
    let plain_bytes = quad_buffer();
    let floats = |range: std::ops::Range<usize>| -> Vec<f32> {
        plain_bytes[range]
            .chunks(4)
            .map(|c| f32::from_le_bytes([c[0], c[1], c[2], c[3]]))
            .collect()
    };
    let vec3 = |v: Vec<f32>| {
        v.chunks(3)
            .map(|c| [c[0], c[1], c[2]])
            .collect::<Vec<[f32; 3]>>()
    };
    let positions = meshopt::encode_vertex_buffer(&vec3(floats(0..48))).unwrap();
    let normals = meshopt::encode_vertex_buffer(&vec3(floats(48..96))).unwrap();
    let uv_floats = floats(96..128);
    let uvs: Vec<[f32; 2]> = uv_floats.chunks(2).map(|c| [c[0], c[1]]).collect();
    let uvs = meshopt::encode_vertex_buffer(&uvs).unwrap();
    let indices = meshopt::encode_index_buffer(&[0, 1, 2, 0, 2, 3], 4).unwrap();
    let mut compressed = Vec::new();
    let mut views = Vec::new();
    for (stream, (offset, length, stride, count, mode)) in [
        (&positions, (0, 48, 12, 4, "ATTRIBUTES")),
        (&normals, (48, 48, 12, 4, "ATTRIBUTES")),
        (&uvs, (96, 32, 8, 4, "ATTRIBUTES")),
        (&indices, (128, 12, 2, 6, "TRIANGLES")),
    ] {
        views.push(
            json!({"buffer": 1, "byteOffset": offset, "byteLength": length,
            "extensions": {"EXT_meshopt_compression": {"buffer": 0,
                "byteOffset": compressed.len(), "byteLength": stream.len(),
                "byteStride": stride, "count": count, "mode": mode}}}),
        );
        compressed.extend_from_slice(stream);
    }
    let mut doc = document();
    for list in ["extensionsUsed", "extensionsRequired"] {
        doc[list] = json!(["EXT_meshopt_compression"]);
    }
    doc["bufferViews"] = json!(views);
    doc["buffers"] = json!([
        {"byteLength": compressed.len(), "uri": format!("data:application/octet-stream;base64,{}",
            base64::engine::general_purpose::STANDARD.encode(&compressed))},
        {"byteLength": 140, "extensions": {"EXT_meshopt_compression": {"fallback": true}}}
    ]);
    let scene = load(&serde_json::to_vec(&doc).unwrap(), None).unwrap();
    let plain = load(&embedded(document()), None).unwrap();
    for (a, b) in scene.objects.iter().zip(&plain.objects) {
        assert_eq!(a.mesh.positions, b.mesh.positions);
        assert_eq!(a.mesh.normals, b.mesh.normals);
        assert_eq!(a.mesh.uvs, b.mesh.uvs);
        let turned = |t: &[u32; 3]| {
            let first = (0..3).min_by_key(|&i| t[i]).unwrap_or(0);
            [t[first], t[(first + 1) % 3], t[(first + 2) % 3]]
        };
        let (ta, tb): (Vec<_>, Vec<_>) = (
            a.mesh.indices.iter().map(turned).collect(),
            b.mesh.indices.iter().map(turned).collect(),
        );
        assert_eq!(ta, tb, "the same triangles, each with its winding");
    }
}

/// `KHR_draco_mesh_compression`: a sphere compressed by Draco's edgebreaker (positions to 14
/// bits, normals and UVs to 12, as exporters quantize them) loads as the same surface: as many
/// triangles, every corner within the quantization step of a vertex of the original, with that
/// vertex's normal and UV; a stream that is not Draco is an error naming the primitive.
#[test]
fn draco_compressed_primitives_load_as_the_surface_encoded() {
    use draco_core::draco_types::DataType;
    use draco_core::encoder_buffer::EncoderBuffer;
    use draco_core::encoder_options::EncoderOptions;
    use draco_core::geometry_attribute::{GeometryAttributeType, PointAttribute};
    use draco_core::geometry_indices::PointIndex;

    let sphere = rt_core::shapes::uv_sphere(1.0, 8, 16);
    let normals = sphere.normals.clone().unwrap();
    let uvs: Vec<[f32; 2]> = sphere
        .positions
        .iter()
        .map(|p| [0.5 + 0.5 * p.x, 0.5 + 0.5 * p.z])
        .collect();
    let mut mesh = draco_core::mesh::Mesh::new();
    let attribute = |kind, values: Vec<f32>, components: usize| {
        let mut a = PointAttribute::new();
        a.init(
            kind,
            components as u8,
            DataType::Float32,
            false,
            values.len() / components,
        );
        for (i, v) in values.iter().enumerate() {
            a.buffer_mut().write(4 * i, &v.to_le_bytes());
        }
        a
    };
    let flat3 = |v: &[glam::Vec3]| v.iter().flat_map(|p| p.to_array()).collect::<Vec<f32>>();
    let position_id = mesh.add_attribute(attribute(
        GeometryAttributeType::Position,
        flat3(&sphere.positions),
        3,
    ));
    let normal_id =
        mesh.add_attribute(attribute(GeometryAttributeType::Normal, flat3(&normals), 3));
    let uv_id = mesh.add_attribute(attribute(GeometryAttributeType::TexCoord, uvs.concat(), 2));
    for t in &sphere.indices {
        mesh.add_face(t.map(PointIndex));
    }
    let mut encoder = draco_core::mesh_encoder::MeshEncoder::new();
    encoder.set_mesh(mesh);
    let mut options = EncoderOptions::new();
    options.set_global_int("encoding_method", 1); // edgebreaker
    for (id, bits) in [(position_id, 14), (normal_id, 12), (uv_id, 12)] {
        options.set_attribute_int(id, "quantization_bits", bits);
    }
    let mut encoded = EncoderBuffer::new();
    encoder.encode(&options, &mut encoded).unwrap();
    let stream = encoded.data().to_vec();

    let document_with = |stream: &[u8]| {
        let mut doc = document();
        for list in ["extensionsUsed", "extensionsRequired"] {
            doc[list] = json!(["KHR_draco_mesh_compression"]);
        }
        let count = sphere.positions.len();
        doc["accessors"] = json!([
            {"componentType": 5126, "count": count, "type": "VEC3", "min": [-1, -1, -1], "max": [1, 1, 1]},
            {"componentType": 5126, "count": count, "type": "VEC3"},
            {"componentType": 5126, "count": count, "type": "VEC2"},
            {"componentType": 5125, "count": 3 * sphere.indices.len(), "type": "SCALAR"}
        ]);
        doc["meshes"][0]["primitives"][0]["extensions"] = json!({"KHR_draco_mesh_compression": {
            "bufferView": 0,
            "attributes": {"POSITION": position_id, "NORMAL": normal_id, "TEXCOORD_0": uv_id}}});
        doc["bufferViews"] = json!([{"buffer": 0, "byteOffset": 0, "byteLength": stream.len()}]);
        doc["buffers"] = json!([{"byteLength": stream.len(), "uri": format!(
            "data:application/octet-stream;base64,{}",
            base64::engine::general_purpose::STANDARD.encode(stream))}]);
        serde_json::to_vec(&doc).unwrap()
    };
    let scene = load(&document_with(&stream), None).unwrap();
    let loaded = &scene.objects[0].mesh;
    assert_eq!(loaded.indices.len(), sphere.indices.len());
    let (normals_read, uvs_read) = (
        loaded.normals.as_ref().unwrap(),
        loaded.uvs.as_ref().unwrap(),
    );
    for t in &loaded.indices {
        for &i in t {
            let p = loaded.positions[i as usize];
            let (nearest, distance) = sphere
                .positions
                .iter()
                .enumerate()
                .map(|(j, q)| (j, (*q - p).length()))
                .min_by(|a, b| a.1.total_cmp(&b.1))
                .unwrap();
            assert!(
                distance < 2.0 * 2.0 / 16384.0,
                "corner {p} is {distance} from the sphere's vertices"
            );
            // Vertices that coincide (the seam, the poles) may carry either's attributes.
            let matches_one = sphere.positions.iter().enumerate().any(|(j, q)| {
                (*q - p).length() <= distance + 1e-6
                    && (normals[j] - normals_read[i as usize]).length() < 0.01
                    && (glam::Vec2::new(uvs[j][0], 1.0 - uvs[j][1]) - uvs_read[i as usize]).length()
                        < 0.01
            });
            assert!(
                matches_one,
                "corner {p} (nearest vertex {nearest}): its normal or UV differs"
            );
        }
    }
    let message = load(&document_with(b"not a draco stream at all"), None)
        .unwrap_err()
        .to_string();
    assert!(
        message.contains("mesh 0 primitive 0 (KHR_draco_mesh_compression)"),
        "{message}"
    );
}

/// A node scaled to nothing shows nothing: in a file without animation its mesh is left out (a
/// still scene's singular transform would be an error), the others load as before; in an animated
/// file it is kept, with finite numbers, for the frames that grow it.
#[test]
fn nodes_scaled_to_nothing_are_left_out_of_still_files() {
    let full = load(&embedded(document()), None).unwrap();
    let mut doc = document();
    doc["nodes"][0]["scale"] = json!([0, 0, 0]);
    let still = load(&embedded(doc.clone()), None).unwrap();
    assert_eq!(still.objects.len(), full.objects.len() - 1);
    assert!(still.objects.iter().all(|o| o.name != full.objects[0].name));
    rt_core::GpuScene::build(&still).expect("the rest renders");
    doc["animations"] = json!([]);
    let mut data = Vec::new();
    [0.0f32, 1.0, 0.0, 0.0, 0.0, 1.0, 1.0, 1.0]
        .iter()
        .for_each(|f| data.extend(f.to_le_bytes()));
    let uri = base64::engine::general_purpose::STANDARD.encode(&data);
    doc["buffers"].as_array_mut().unwrap().push(json!({
        "byteLength": data.len(),
        "uri": format!("data:application/octet-stream;base64,{uri}")
    }));
    let buffer = doc["buffers"].as_array().unwrap().len() - 1;
    let views = doc["bufferViews"].as_array_mut().unwrap();
    views.push(json!({"buffer": buffer, "byteOffset": 0, "byteLength": 8}));
    views.push(json!({"buffer": buffer, "byteOffset": 8, "byteLength": 24}));
    let view = views.len() - 2;
    let accessors = doc["accessors"].as_array_mut().unwrap();
    accessors.push(
        json!({"bufferView": view, "componentType": 5126, "count": 2,
        "type": "SCALAR", "min": [0.0], "max": [1.0]}),
    );
    accessors
        .push(json!({"bufferView": view + 1, "componentType": 5126, "count": 2, "type": "VEC3"}));
    let first = accessors.len() - 2;
    doc["animations"] = json!([{
        "samplers": [{"input": first, "output": first + 1, "interpolation": "LINEAR"}],
        "channels": [{"sampler": 0, "target": {"node": 0, "path": "scale"}}]
    }]);
    let grows = load(&embedded(doc), None).unwrap();
    assert_eq!(grows.objects.len(), full.objects.len());
    let t = &grows.objects[0].transform;
    let numbers = t.translation.iter().chain(&t.rotation_deg).chain(&t.scale);
    assert!(numbers.into_iter().all(|v| v.is_finite()), "{t:?}");
    let hidden = rt_core::GpuScene::build(&grows).expect("hidden at rest, the scene builds");
    let quad = full.objects[0].mesh.indices.len();
    let all = rt_core::GpuScene::build(&full).unwrap().triangles.len();
    assert_eq!(
        hidden.triangles.len(),
        all - quad,
        "the vanished quad has no triangles"
    );
    let grown = rt_core::posing::posed_at(&grows, 1.0);
    assert!(close(grown.objects[0].transform.scale, [1.0; 3]));
    assert!(!grown.objects[0].mesh.indices.is_empty());
    assert!(
        rt_core::posing::posed_at(&grows, 0.0).objects[0]
            .mesh
            .indices
            .is_empty()
    );
}
