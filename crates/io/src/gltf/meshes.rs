//! Mesh primitives onto shared meshes: triangles, strips and fans, positions, normals, the first UV
//! set (with the base colour texture's transform baked in) and vertex colours.

use std::sync::Arc;

use glam::{Vec2, Vec3};

use super::Loader;
use super::buffers::{Expect, check_accessor, read_floats};
use rt_core::scene::Mesh;

impl Loader<'_> {
    pub(super) fn mesh(
        &mut self,
        mesh: &gltf::Mesh,
        primitive: &gltf::Primitive,
    ) -> std::result::Result<Arc<Mesh>, String> {
        let key = (mesh.index(), primitive.index());
        if let Some(m) = self.meshes.get(&key) {
            return Ok(m.clone());
        }
        let at = format!("mesh {} primitive {}", mesh.index(), primitive.index());
        use gltf::mesh::Mode;
        let mode = primitive.mode();
        if !matches!(
            mode,
            Mode::Triangles | Mode::TriangleStrip | Mode::TriangleFan
        ) {
            return Err(format!(
                "{at}: primitive mode {mode:?} is not made of triangles (rt renders surfaces)"
            ));
        }
        if let Some(draco) = primitive.extension_value("KHR_draco_mesh_compression") {
            let mesh = Arc::new(self.draco_mesh(&at, primitive, draco)?);
            self.meshes.insert(key, mesh.clone());
            return Ok(mesh);
        }
        let positions_accessor = primitive
            .get(&gltf::Semantic::Positions)
            .ok_or_else(|| format!("{at} has no POSITION attribute"))?;
        check_accessor(&positions_accessor, self.buffers, Expect::Position)
            .map_err(|e| format!("{at}: {e}"))?;
        for (semantic, expect) in [
            (gltf::Semantic::Normals, Expect::Normal),
            (gltf::Semantic::TexCoords(0), Expect::Uv),
            (gltf::Semantic::Colors(0), Expect::Color),
        ] {
            if let Some(a) = primitive.get(&semantic) {
                check_accessor(&a, self.buffers, expect).map_err(|e| format!("{at}: {e}"))?;
            }
        }
        if let Some(a) = primitive.indices() {
            check_accessor(&a, self.buffers, Expect::Indices).map_err(|e| format!("{at}: {e}"))?;
        }
        let reader = primitive.reader(|b| self.buffers.get(b.index()).map(Vec::as_slice));
        let positions: Vec<Vec3> = read_floats::<3>(&positions_accessor, self.buffers)
            .into_iter()
            .map(Vec3::from)
            .collect();
        if let Some(bad) = positions.iter().position(|p| !p.is_finite()) {
            return Err(format!("{at}: vertex {bad} is not finite"));
        }
        let n = positions.len();
        let normals: Option<Vec<Vec3>> = primitive
            .get(&gltf::Semantic::Normals)
            .map(|a| {
                // Quantized normals are only roughly unit length; float ones are kept as written.
                let quantized = a.data_type() != gltf::accessor::DataType::F32;
                read_floats::<3>(&a, self.buffers)
                    .into_iter()
                    .map(|n| {
                        let n = Vec3::from(n);
                        if quantized { n.normalize_or_zero() } else { n }
                    })
                    .collect::<Vec<_>>()
            })
            .filter(|v| v.len() == n && v.iter().all(|x| x.is_finite()));
        let uv_transform = uv_transform_of(&primitive.material());
        let uvs: Option<Vec<Vec2>> = primitive
            .get(&gltf::Semantic::TexCoords(0))
            .map(|a| {
                read_floats::<2>(&a, self.buffers)
                    .into_iter()
                    .map(|uv| {
                        let [u, v] = uv_transform(uv);
                        Vec2::new(u, 1.0 - v)
                    })
                    .collect::<Vec<_>>()
            })
            .filter(|v| v.len() == n && v.iter().all(|x| x.is_finite()));
        let colors: Option<Vec<Vec3>> = reader
            .read_colors(0)
            .map(|c| c.into_rgb_f32().map(Vec3::from).collect::<Vec<_>>())
            .filter(|v| v.len() == n && v.iter().all(|x| x.is_finite()));
        let flat: Vec<u32> = match reader.read_indices() {
            Some(i) => i.into_u32().collect(),
            None => (0..n as u32).collect(),
        };
        if let Some(bad) = flat.iter().find(|&&i| i as usize >= n) {
            return Err(format!("{at}: index {bad} is past its {n} vertices"));
        }
        let indices: Vec<[u32; 3]> = match mode {
            Mode::Triangles => flat.chunks_exact(3).map(|c| [c[0], c[1], c[2]]).collect(),
            Mode::TriangleStrip => (2..flat.len())
                .map(|i| {
                    if i % 2 == 0 {
                        [flat[i - 2], flat[i - 1], flat[i]]
                    } else {
                        [flat[i - 1], flat[i - 2], flat[i]]
                    }
                })
                .collect(),
            _ => (2..flat.len())
                .map(|i| [flat[0], flat[i - 1], flat[i]])
                .collect(),
        };
        let mesh = Arc::new(Mesh {
            positions,
            normals,
            uvs,
            colors,
            indices,
        });
        self.meshes.insert(key, mesh.clone());
        Ok(mesh)
    }
}

impl Loader<'_> {
    /// A `KHR_draco_mesh_compression` primitive's mesh, from its Draco stream.
    fn draco_mesh(
        &self,
        at: &str,
        primitive: &gltf::Primitive,
        extension: &serde_json::Value,
    ) -> std::result::Result<Mesh, String> {
        let at = format!("{at} (KHR_draco_mesh_compression)");
        let view = extension["bufferView"]
            .as_u64()
            .and_then(|i| self.document.views().nth(i as usize))
            .ok_or_else(|| format!("{at}: no such bufferView"))?;
        let bytes = self.buffers[view.buffer().index()]
            .get(view.offset()..view.offset() + view.length())
            .ok_or_else(|| format!("{at}: its bufferView lies past its buffer"))?;
        let ids = extension["attributes"]
            .as_object()
            .ok_or_else(|| format!("{at}: no attributes"))?;
        let decoded = super::draco::decode(bytes, ids).map_err(|e| format!("{at}: {e}"))?;
        let positions: Vec<Vec3> = decoded
            .attribute::<3>("POSITION")
            .ok_or_else(|| format!("{at}: no POSITION of 3 components"))?
            .into_iter()
            .map(Vec3::from)
            .collect();
        if let Some(bad) = positions.iter().position(|p| !p.is_finite()) {
            return Err(format!("{at}: vertex {bad} is not finite"));
        }
        let finite3 = |v: Vec<[f32; 3]>| {
            let v: Vec<Vec3> = v.into_iter().map(Vec3::from).collect();
            v.iter().all(|x| x.is_finite()).then_some(v)
        };
        let normals = decoded.attribute::<3>("NORMAL").and_then(finite3);
        let uv_transform = uv_transform_of(&primitive.material());
        let uvs = decoded
            .attribute::<2>("TEXCOORD_0")
            .map(|uvs| {
                uvs.into_iter()
                    .map(|uv| {
                        let [u, v] = uv_transform(uv);
                        Vec2::new(u, 1.0 - v)
                    })
                    .collect::<Vec<_>>()
            })
            .filter(|v| v.iter().all(|x| x.is_finite()));
        let colors = decoded
            .attribute::<3>("COLOR_0")
            .or_else(|| {
                decoded
                    .attribute::<4>("COLOR_0")
                    .map(|c| c.into_iter().map(|[r, g, b, _]| [r, g, b]).collect())
            })
            .and_then(finite3);
        Ok(Mesh {
            positions,
            normals,
            uvs,
            colors,
            indices: decoded
                .indices
                .chunks_exact(3)
                .map(|c| [c[0], c[1], c[2]])
                .collect(),
        })
    }
}

/// The base colour texture's `KHR_texture_transform` (glTF's uv' = T·R·S·uv, in glTF's v-down
/// space), baked into the mesh's UVs: rt's textures share one UV set per mesh.
fn uv_transform_of(m: &gltf::Material) -> impl Fn([f32; 2]) -> [f32; 2] + use<> {
    let t = m
        .pbr_metallic_roughness()
        .base_color_texture()
        .and_then(|i| i.texture_transform())
        .map(|t| (t.offset(), t.rotation(), t.scale()));
    move |[u, v]| match t {
        Some((offset, rotation, scale))
            if offset.iter().chain(&scale).all(|x| x.is_finite()) && rotation.is_finite() =>
        {
            let (su, sv) = (u * scale[0], v * scale[1]);
            let (s, c) = rotation.sin_cos();
            [c * su + s * sv + offset[0], -s * su + c * sv + offset[1]]
        }
        _ => [u, v],
    }
}
