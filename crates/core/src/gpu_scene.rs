//! Flattens a `Scene` into the arrays the kernel reads: world-space triangles in BVH order, their
//! shading attributes, one material per object, texels and BVH nodes.

use std::time::Duration;

use glam::{Vec2, Vec3};

use crate::bvh::{BvhLayout, BvhQuality, build_bvh, build_wide_bvh};
use crate::error::{Error, Result};
use crate::gpu_types::{self, BvhNode, NO_TEXTURE, Shading, Triangle, WideBvhNode, material_kind};
use crate::material::{AlphaMode, Material};
use crate::scene::Scene;

/// Which optional kernel features a scene needs; the pipeline compiles the others out.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub struct SceneFeatures {
    pub textures: bool,
    pub metal: bool,
    pub dielectric: bool,
    pub thin_lens: bool,
    /// Next-event estimation (the scene has emitters and the settings ask for it).
    pub nee: bool,
    /// Point, spot or directional lights (always sampled directly).
    pub delta_lights: bool,
    /// The PBR material.
    pub pbr: bool,
    /// PBR normal maps (the kernel reads `GpuScene::tangents`).
    pub normal_maps: bool,
    /// An environment map (sampled directly, and by MIS with the BSDF).
    pub environment: bool,
    /// Alpha-masked or blended surfaces (the traversal reads their coverage at each hit).
    pub alpha: bool,
}

/// Everything the GPU needs for a scene, as plain arrays.
#[derive(Clone, Debug, Default)]
pub struct GpuScene {
    pub triangles: Vec<Triangle>,
    /// Per-triangle attributes, empty when no triangle has normals or UVs.
    pub shading: Vec<Shading>,
    pub materials: Vec<gpu_types::Material>,
    /// RGBA8 sRGB texels of all textures, one `u32` each (R in the low byte).
    pub texels: Vec<u32>,
    /// Which of `nodes` and `wide_nodes` the kernel traverses; the other is empty.
    pub layout: BvhLayout,
    pub nodes: Vec<BvhNode>,
    pub wide_nodes: Vec<WideBvhNode>,
    /// Emitter triangles for next-event estimation, as an alias table.
    pub emitters: Vec<gpu_types::Emitter>,
    /// Σ area × luminance(emission) over `emitters`.
    pub emitter_power: f32,
    /// Point, spot and directional lights.
    pub delta_lights: Vec<gpu_types::DeltaLight>,
    /// The environment map's texels and sampling records (empty without one).
    pub env_texels: Vec<gpu_types::EnvTexel>,
    pub env_width: u32,
    pub env_height: u32,
    /// Turns about +y.
    pub env_rotation: f32,
    /// The white GGX conductor's albedo table (`math::microfacet::energy_table`).
    pub ggx_energy: Vec<f32>,
    /// Per triangle (BVH order) three corner tangents (xyz, w the bitangent's sign), MikkTSpace,
    /// in world space; empty unless some normal-mapped object needs them.
    pub tangents: Vec<[f32; 4]>,
    pub features: SceneFeatures,
    /// The largest side of the triangles' bounding box (0 without triangles).
    pub extent: f32,
    pub bvh_depth: usize,
    pub bvh_build_time: Duration,
}

/// An object's GPU material (texture slots resolved against `texture_offsets`) and, with a normal
/// map, its MikkTSpace tangents (three per triangle, in the mesh's order); notes the features it
/// uses in `features`.
fn object_material(
    scene: &Scene,
    object: &crate::Object,
    texture_offsets: &[u32],
    features: &mut SceneFeatures,
) -> Result<(gpu_types::Material, Option<Vec<[f32; 4]>>)> {
    let mesh = &object.mesh;
    let label = || format!("object '{}'", object.name);
    object.material.validate(&label()).map_err(Error::Scene)?;
    let mut material = gpu_material(&object.material);
    let texture = match &object.material {
        Material::Lambertian { texture, .. } => *texture,
        Material::Pbr(p) => p.texture,
        _ => None,
    };
    if let Some(t) = texture {
        let texture = scene.textures.get(t).ok_or_else(|| {
            Error::Scene(format!("{}: texture index {t} does not exist", label()))
        })?;
        if mesh.uvs.is_some() {
            material.texture_offset = texture_offsets[t];
            material.texture_width = texture.width;
            material.texture_height = texture.height;
            material.samplers |= texture.sampler.bits() << gpu_types::SLOT_BASE;
            features.textures = true;
        } else {
            log::warn!("{} has a texture but no UVs: rendering it white", label());
            material.albedo = [1.0; 3];
        }
    }
    let mut tangents = None;
    if let Material::Pbr(p) = &object.material {
        let slot = |t: Option<usize>, name: &str| -> Result<Option<usize>> {
            match t {
                Some(t) if t >= scene.textures.len() => Err(Error::Scene(format!(
                    "{}: {name} {t} does not exist",
                    label()
                ))),
                Some(_) if mesh.uvs.is_none() => {
                    log::warn!("{} has a {name} but no UVs: ignoring it", label());
                    Ok(None)
                }
                other => Ok(other),
            }
        };
        // (offset, width, height) of a slot, its sampler in `samplers` at `shift`.
        let mut bind = |t: usize, shift: u32, samplers: &mut u32| {
            let texture = &scene.textures[t];
            *samplers |= texture.sampler.bits() << shift;
            features.textures = true;
            (texture_offsets[t], texture.width, texture.height)
        };
        let mut samplers = material.samplers;
        if let Some(t) = slot(p.metallic_roughness_texture, "metallic-roughness texture")? {
            (
                material.mr_texture_offset,
                material.mr_texture_width,
                material.mr_texture_height,
            ) = bind(t, gpu_types::SLOT_METALLIC_ROUGHNESS, &mut samplers);
        }
        if let Some(t) = slot(p.emission_texture, "emission texture")? {
            (
                material.emission_texture_offset,
                material.emission_texture_width,
                material.emission_texture_height,
            ) = bind(t, gpu_types::SLOT_EMISSION, &mut samplers);
        }
        if let Some(t) = slot(p.normal_texture, "normal texture")? {
            match crate::tangents::mikktspace_tangents(mesh) {
                Some(t_corners) => {
                    (
                        material.normal_texture_offset,
                        material.normal_texture_width,
                        material.normal_texture_height,
                    ) = bind(t, gpu_types::SLOT_NORMAL, &mut samplers);
                    tangents = Some(t_corners);
                    features.normal_maps = true;
                }
                None => log::warn!(
                    "{}: no tangents (it needs normals and UVs): ignoring its normal map",
                    label()
                ),
            }
        }
        material.samplers = samplers;
        // Coverage comes from the factor and the base colour texture: without UVs only the factor.
        let cuts = match p.alpha_mode {
            AlphaMode::Opaque => false,
            AlphaMode::Mask => material.texture_offset != NO_TEXTURE || p.alpha < p.alpha_cutoff,
            AlphaMode::Blend => material.texture_offset != NO_TEXTURE || p.alpha < 1.0,
        };
        if cuts {
            material.flags |= match p.alpha_mode {
                AlphaMode::Mask => gpu_types::ALPHA_MASK,
                _ => gpu_types::ALPHA_BLEND,
            };
            features.alpha = true;
        }
    }
    features.metal |= material.kind == material_kind::METAL;
    features.dielectric |= material.kind == material_kind::DIELECTRIC;
    features.pbr |= material.kind == material_kind::PBR;
    Ok((material, tangents))
}

fn triangle_extent(triangles: &[Triangle]) -> f32 {
    let (mut lo, mut hi) = (glam::Vec3::splat(f32::MAX), glam::Vec3::splat(f32::MIN));
    for t in triangles {
        for v in [t.v0, t.v1, t.v2] {
            lo = lo.min(v.into());
            hi = hi.max(v.into());
        }
    }
    if triangles.is_empty() {
        0.0
    } else {
        (hi - lo).max_element()
    }
}

impl GpuScene {
    pub fn build(scene: &Scene) -> Result<Self> {
        Self::build_with(scene, BvhQuality::default())
    }

    pub fn build_with(scene: &Scene, quality: BvhQuality) -> Result<Self> {
        Self::build_with_layout(scene, quality, BvhLayout::default())
    }

    pub fn build_with_layout(
        scene: &Scene,
        quality: BvhQuality,
        layout: BvhLayout,
    ) -> Result<Self> {
        let mut out = GpuScene::default();
        let mut texture_offsets = Vec::with_capacity(scene.textures.len());
        for texture in &scene.textures {
            let expected = texture.width as usize * texture.height as usize * 4;
            if texture.rgba8.len() != expected || expected == 0 {
                return Err(Error::Scene(format!(
                    "texture '{}' has no pixel data",
                    texture.name
                )));
            }
            texture_offsets.push(out.texels.len() as u32);
            out.texels.extend(
                texture
                    .rgba8
                    .chunks_exact(4)
                    .map(|p| u32::from_le_bytes([p[0], p[1], p[2], p[3]])),
            );
        }

        let mut world = Vec::with_capacity(scene.triangle_count());
        let mut tri_data = Vec::with_capacity(scene.triangle_count());
        for (object_index, object) in scene.objects.iter().enumerate() {
            let mesh = &object.mesh;
            let label = || format!("object '{}'", object.name);
            let (material, tangents) =
                object_material(scene, object, &texture_offsets, &mut out.features)?;
            // Vertex colours tint diffuse and PBR materials (the others have no base colour).
            let colored = mesh
                .colors
                .as_ref()
                .is_some_and(|c| c.len() == mesh.positions.len())
                && matches!(
                    object.material,
                    Material::Lambertian { .. } | Material::Pbr(_)
                );
            out.materials.push(material);

            let m = object.transform.matrix();
            let nm = object.transform.normal_matrix();
            if !m.is_finite() || m.determinant() == 0.0 {
                return Err(Error::Scene(format!(
                    "{}: transform is singular or not finite",
                    label()
                )));
            }
            let flip = m.determinant() < 0.0;
            for (i, p) in mesh.positions.iter().enumerate() {
                if !p.is_finite() {
                    return Err(Error::Scene(format!(
                        "{}: vertex {} is not finite ({p})",
                        label(),
                        i + 1
                    )));
                }
            }
            let count = mesh.positions.len();
            for (face, idx) in mesh.indices.iter().enumerate() {
                if let Some(bad) = idx.iter().find(|&&i| i as usize >= count) {
                    return Err(Error::Scene(format!(
                        "{}: triangle {} uses vertex {} of {count}",
                        label(),
                        face + 1,
                        bad + 1
                    )));
                }
                // A mirroring transform reverses winding; swap two corners to keep the front face.
                let idx = if flip { [idx[0], idx[2], idx[1]] } else { *idx };
                let p = idx.map(|i| m.transform_point3(mesh.positions[i as usize]));
                let n = mesh
                    .normals
                    .as_ref()
                    .map(|ns| idx.map(|i| (nm * ns[i as usize]).normalize_or_zero()));
                let uv = mesh.uvs.as_ref().map(|uvs| idx.map(|i| uvs[i as usize]));
                let colors = mesh
                    .colors
                    .as_ref()
                    .filter(|_| colored)
                    .map(|cs| idx.map(|i| gpu_types::pack_color(cs[i as usize].to_array())));
                let corners = if flip { [0, 2, 1] } else { [0, 1, 2] };
                let sign = if flip { -1.0 } else { 1.0 };
                let t = tangents.as_ref().map(|t: &Vec<[f32; 4]>| {
                    corners.map(|c| {
                        let [x, y, z, w] = t[face * 3 + c];
                        let d = m.transform_vector3(Vec3::new(x, y, z)).normalize_or_zero();
                        [d.x, d.y, d.z, w * sign]
                    })
                });
                world.push(p);
                tri_data.push((object_index as u32, n, uv, t, colors));
            }
        }

        out.layout = layout;
        let triangle_order = match layout {
            BvhLayout::Bvh2 => {
                let bvh = build_bvh(&world, quality).map_err(Error::Scene)?;
                (out.bvh_depth, out.bvh_build_time) = (bvh.depth, bvh.build_time);
                out.nodes = bvh.nodes;
                bvh.triangle_order
            }
            BvhLayout::Cwbvh => match build_wide_bvh(&world, quality) {
                Ok(bvh) => {
                    (out.bvh_depth, out.bvh_build_time) = (bvh.depth, bvh.build_time);
                    out.wide_nodes = bvh.nodes;
                    bvh.triangle_order
                }
                Err(why) => {
                    log::warn!("{why}; using the binary BVH instead");
                    out.layout = BvhLayout::Bvh2;
                    let bvh = build_bvh(&world, quality).map_err(Error::Scene)?;
                    (out.bvh_depth, out.bvh_build_time) = (bvh.depth, bvh.build_time);
                    out.nodes = bvh.nodes;
                    bvh.triangle_order
                }
            },
        };
        out.triangles.reserve(world.len());
        out.shading.reserve(world.len());
        for &i in &triangle_order {
            let p = world[i as usize];
            let (material, normals, uvs, t, colors) = &tri_data[i as usize];
            if out.features.normal_maps {
                out.tangents.extend(t.unwrap_or([[0.0; 4]; 3]));
            }
            let normals = normals.filter(|n| n.iter().all(|v| v.length_squared() > 0.0));
            out.triangles.push(Triangle {
                v0: p[0].to_array(),
                material: *material,
                v1: p[1].to_array(),
                has_normals: normals.is_some() as u32 * gpu_types::HAS_NORMALS
                    + colors.is_some() as u32 * gpu_types::HAS_COLORS,
                v2: p[2].to_array(),
                has_uvs: uvs.is_some() as u32,
            });
            let n = normals.unwrap_or([Vec3::ZERO; 3]);
            let uv = uvs.unwrap_or([Vec2::ZERO; 3]);
            let c = colors.unwrap_or([u32::MAX; 3]);
            out.shading.push(Shading {
                c0: c[0],
                c1: c[1],
                c2: c[2],
                n0: n[0].to_array(),
                n1: n[1].to_array(),
                n2: n[2].to_array(),
                uv0: uv[0].to_array(),
                uv1: uv[1].to_array(),
                uv2: uv[2].to_array(),
                ..Default::default()
            });
        }
        // The kernel reads shading attributes only for triangles that have them.
        if out
            .triangles
            .iter()
            .all(|t| t.has_normals == 0 && t.has_uvs == 0)
        {
            out.shading = Vec::new();
        }
        out.extent = triangle_extent(&out.triangles);
        out.light(scene)?;
        out.ggx_energy = crate::math::microfacet::energy_table().to_vec();
        Ok(out)
    }

    /// This scene's geometry (triangles, BVH, shading attributes, tangents) with `scene`'s
    /// materials, emitters, lights and environment: what the interactive viewport does for an
    /// edit that moves nothing, instead of rebuilding the BVH. `scene` must have the same objects
    /// with the same meshes and transforms and the same textures as the scene this one was built
    /// from; `None` when an object gains or loses a normal map (its tangents are built with the
    /// geometry).
    pub fn restyle(&self, scene: &Scene) -> Result<Option<GpuScene>> {
        if scene.objects.len() != self.materials.len() {
            return Ok(None);
        }
        let mut texture_offsets = Vec::with_capacity(scene.textures.len());
        let mut offset = 0u32;
        for texture in &scene.textures {
            texture_offsets.push(offset);
            offset += texture.width * texture.height;
        }
        if offset as usize != self.texels.len() {
            return Ok(None);
        }
        let mut features = SceneFeatures::default();
        let mut materials = Vec::with_capacity(self.materials.len());
        for (object, old) in scene.objects.iter().zip(&self.materials) {
            let (material, tangents) =
                object_material(scene, object, &texture_offsets, &mut features)?;
            let had_normal_map = old.normal_texture_width > 0;
            if tangents.is_some() != had_normal_map {
                return Ok(None);
            }
            materials.push(material);
        }
        let mut out = GpuScene {
            materials,
            features,
            ..self.clone()
        };
        out.light(scene)?;
        Ok(Some(out))
    }

    /// Emitters, delta lights, the environment and the features that follow from them and the
    /// camera, from `scene` and this scene's triangles and materials.
    fn light(&mut self, scene: &Scene) -> Result<()> {
        let out = self;
        out.features.thin_lens = scene.camera.aperture_radius > 0.0;
        (out.emitters, out.emitter_power) =
            crate::emitters::build_emitters(&out.triangles, &out.materials);
        out.features.nee = scene.settings.next_event_estimation && !out.emitters.is_empty();
        for light in &scene.lights {
            light.validate().map_err(Error::Scene)?;
        }
        out.delta_lights = scene
            .lights
            .iter()
            .filter(|l| l.intensity > 0.0 && l.color.iter().any(|c| *c > 0.0))
            .map(|l| l.gpu())
            .collect();
        out.features.delta_lights = !out.delta_lights.is_empty();
        (
            out.env_texels,
            out.env_width,
            out.env_height,
            out.env_rotation,
        ) = (Vec::new(), 0, 0, 0.0);
        out.features.environment = false;
        if let Some(env) = &scene.environment {
            env.validate().map_err(Error::Scene)?;
            if let Some(texels) = crate::environment::build_env_texels(&env.map, env.strength) {
                out.env_texels = texels;
                out.env_width = env.map.width;
                out.env_height = env.map.height;
                out.env_rotation = env.rotation_deg / 360.0;
                out.features.environment = true;
            }
        }
        Ok(())
    }

    /// Checks every index the tracing kernels follow, the invariants the builder promises them
    /// (wgpu's injected bounds checks keep a broken one from reading outside an array, but it
    /// would give a wrong image): BVH children point forwards (so traversal ends, and `bvh_depth`
    /// is found in one pass) and inside the node array, leaves' triangle ranges, triangles'
    /// materials and shading records, textures' texel ranges and the emitter table all lie inside
    /// their arrays. The error names the first bad record.
    pub fn check_kernel_indices(&self) -> std::result::Result<(), String> {
        match self.layout {
            BvhLayout::Bvh2 => self.check_bvh2_indices()?,
            BvhLayout::Cwbvh => self.check_wide_indices()?,
        }
        self.check_record_indices()
    }

    /// The wide BVH's inner children are later nodes, its leaves' triangle ranges lie inside the
    /// triangles, and each slot's byte is one the kernel decodes as intended: a leaf's bits stay below
    /// bit 24, where the kernel keeps inner children.
    fn check_wide_indices(&self) -> std::result::Result<(), String> {
        let (nodes, triangles) = (self.wide_nodes.len(), self.triangles.len());
        if nodes == 0 {
            return Err("the wide BVH has no root node".into());
        }
        for (i, node) in self.wide_nodes.iter().enumerate() {
            let imask = node.exponents_imask >> 24;
            let inner = imask.count_ones();
            if inner > 0
                && !(node.child_base as usize > i
                    && node.child_base as usize + inner as usize <= nodes)
            {
                return Err(format!(
                    "wide BVH node {i}: inner children {}..{} are not later nodes of the {nodes}",
                    node.child_base,
                    u64::from(node.child_base) + u64::from(inner)
                ));
            }
            for slot in 0..8u32 {
                let meta = (node.slots[(slot / 4) as usize] >> (slot % 4 * 8)) & 0xff;
                let is_inner = imask & (1 << slot) != 0;
                let ok = if is_inner {
                    meta == 0b0010_0000 | (24 + slot)
                } else if meta == 0 {
                    true
                } else {
                    let (count, offset) = ((meta >> 5).count_ones(), meta & 31);
                    let end = u64::from(node.primitive_base) + u64::from(offset + count);
                    matches!(meta >> 5, 1 | 3 | 7)
                        && offset + count <= 24
                        && end <= triangles as u64
                };
                if !ok {
                    return Err(format!(
                        "wide BVH node {i}: slot {slot} ({}) has meta {meta:#010b} (primitive base {} of {triangles} triangles)",
                        if is_inner { "inner" } else { "leaf" },
                        node.primitive_base
                    ));
                }
            }
        }
        Ok(())
    }

    fn check_bvh2_indices(&self) -> std::result::Result<(), String> {
        let (nodes, triangles) = (self.nodes.len(), self.triangles.len());
        if nodes == 0 {
            return Err("the BVH has no root node".into());
        }
        for (i, node) in self.nodes.iter().enumerate() {
            // Child 0 with no triangles is no child (traversals skip it).
            for (side, index, count) in [
                ("left", node.left, node.left_count),
                ("right", node.right, node.right_count),
            ] {
                if count > 0 {
                    if u64::from(index) + u64::from(count) > triangles as u64 {
                        return Err(format!(
                            "BVH node {i}: {side} leaf triangles {index}..{} past the {triangles} triangles",
                            u64::from(index) + u64::from(count)
                        ));
                    }
                } else if index != 0 && !(index as usize > i && (index as usize) < nodes) {
                    return Err(format!(
                        "BVH node {i}: {side} child {index} is not a later node of the {nodes}"
                    ));
                }
            }
        }
        Ok(())
    }

    /// Triangles' materials and shading records, textures' texels and the emitter table.
    fn check_record_indices(&self) -> std::result::Result<(), String> {
        let triangles = self.triangles.len();
        let needs_shading = |t: &Triangle| t.has_normals != 0 || t.has_uvs != 0;
        for (i, t) in self.triangles.iter().enumerate() {
            if t.material as usize >= self.materials.len() {
                return Err(format!(
                    "triangle {i}: material {} of {}",
                    t.material,
                    self.materials.len()
                ));
            }
            if needs_shading(t) && i >= self.shading.len() {
                return Err(format!(
                    "triangle {i}: no shading record ({} records)",
                    self.shading.len()
                ));
            }
        }
        for (i, m) in self.materials.iter().enumerate() {
            for (what, offset, w, h) in [
                (
                    "texture",
                    m.texture_offset,
                    m.texture_width,
                    m.texture_height,
                ),
                (
                    "metallic-roughness texture",
                    m.mr_texture_offset,
                    m.mr_texture_width,
                    m.mr_texture_height,
                ),
                (
                    "normal texture",
                    m.normal_texture_offset,
                    m.normal_texture_width,
                    m.normal_texture_height,
                ),
                (
                    "emission texture",
                    m.emission_texture_offset,
                    m.emission_texture_width,
                    m.emission_texture_height,
                ),
            ] {
                if offset == NO_TEXTURE {
                    continue;
                }
                let end = u64::from(offset) + u64::from(w) * u64::from(h);
                if w == 0 || h == 0 || end > self.texels.len() as u64 {
                    return Err(format!(
                        "material {i}: {what} texels {offset}..{end} ({w}x{h}) outside the {} texels",
                        self.texels.len()
                    ));
                }
            }
            if m.normal_texture_offset != NO_TEXTURE && self.tangents.len() != 3 * triangles {
                return Err(format!(
                    "material {i} is normal-mapped but there are {} tangents for {triangles} triangles",
                    self.tangents.len()
                ));
            }
        }
        if self.env_texels.len() != (self.env_width as usize) * (self.env_height as usize) {
            return Err(format!(
                "environment: {} texels for {}x{}",
                self.env_texels.len(),
                self.env_width,
                self.env_height
            ));
        }
        if let Some(i) = self
            .env_texels
            .iter()
            .position(|t| t.alias_index as usize >= self.env_texels.len())
        {
            return Err(format!(
                "environment texel {i}: alias {} of {}",
                self.env_texels[i].alias_index,
                self.env_texels.len()
            ));
        }
        for (i, e) in self.emitters.iter().enumerate() {
            if e.triangle as usize >= triangles || e.alias_index as usize >= self.emitters.len() {
                return Err(format!(
                    "emitter {i}: triangle {} of {triangles}, alias {} of {}",
                    e.triangle,
                    e.alias_index,
                    self.emitters.len()
                ));
            }
        }
        Ok(())
    }

    /// The node array of `layout`, as uploaded.
    pub fn node_bytes(&self) -> &[u8] {
        match self.layout {
            BvhLayout::Bvh2 => bytemuck::cast_slice(&self.nodes),
            BvhLayout::Cwbvh => bytemuck::cast_slice(&self.wide_nodes),
        }
    }

    /// Bytes each buffer needs, by buffer name, for limit checks and reports.
    pub fn buffer_sizes(&self) -> [(&'static str, u64); 8] {
        let bytes = |len: usize, size: usize| (len * size) as u64;
        [
            (
                "triangles",
                bytes(self.triangles.len(), size_of::<Triangle>()),
            ),
            ("shading", bytes(self.shading.len(), size_of::<Shading>())),
            (
                "materials",
                bytes(self.materials.len(), size_of::<gpu_types::Material>()),
            ),
            ("texels", bytes(self.texels.len(), 4)),
            (
                "bvh nodes",
                bytes(self.nodes.len(), size_of::<BvhNode>())
                    + bytes(self.wide_nodes.len(), size_of::<WideBvhNode>()),
            ),
            (
                "emitters",
                bytes(self.emitters.len(), size_of::<gpu_types::Emitter>()),
            ),
            (
                "environment",
                bytes(self.env_texels.len(), size_of::<gpu_types::EnvTexel>()),
            ),
            ("tangents", bytes(self.tangents.len(), 16)),
        ]
    }
}

fn gpu_material(material: &Material) -> gpu_types::Material {
    let base = gpu_types::Material {
        texture_offset: NO_TEXTURE,
        mr_texture_offset: NO_TEXTURE,
        normal_texture_offset: NO_TEXTURE,
        emission_texture_offset: NO_TEXTURE,
        alpha: 1.0,
        ..Default::default()
    };
    match *material {
        Material::Lambertian { albedo, .. } => gpu_types::Material {
            albedo,
            kind: material_kind::LAMBERTIAN,
            ..base
        },
        Material::Metal { albedo, fuzz } => gpu_types::Material {
            albedo,
            kind: material_kind::METAL,
            param: fuzz,
            ..base
        },
        Material::Dielectric { ior, tint } => gpu_types::Material {
            albedo: tint,
            kind: material_kind::DIELECTRIC,
            param: ior,
            ..base
        },
        Material::Emissive { color, intensity } => gpu_types::Material {
            kind: material_kind::EMISSIVE,
            emission: color.map(|c| c * intensity),
            ..base
        },
        Material::Pbr(ref p) => gpu_types::Material {
            normal_scale: p.normal_scale,
            albedo: p.base_color,
            kind: material_kind::PBR,
            emission: p.emission.map(|c| c * p.emission_strength),
            param: p.ior,
            absorption: p.absorption(),
            metallic: p.metallic,
            roughness: p.roughness,
            transmission: p.transmission,
            alpha: p.alpha,
            alpha_cutoff: p.alpha_cutoff,
            flags: if p.thin_walled {
                gpu_types::THIN_WALLED
            } else {
                0
            },
            ..base
        },
    }
}
