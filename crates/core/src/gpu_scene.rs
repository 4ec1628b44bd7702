//! Flattens a `Scene` into the arrays the kernel reads: world-space triangles in BVH order, their
//! shading attributes, one material per object, texels and BVH nodes.
//!
//! Material packing is in `gpu_material`, the feature flags in `scene_features` and the kernels'
//! index checks (`GpuScene::check_kernel_indices`) in `kernel_indices`.

/// The WGSL twin of this module, `gpu_scene.wgsl` beside it (composed into the kernels by
/// `rt_gpu::shaders`).
pub const WGSL: &str = include_str!("gpu_scene.wgsl");

use std::time::Duration;

use glam::{Vec2, Vec3};

use crate::bvh::{BvhLayout, BvhQuality, TriangleBox, build_bvh_over, build_wide_bvh_over};
use crate::corner_records::CornerRecords;
use crate::error::{Error, Result};
use crate::gpu_material::object_material;
use crate::gpu_types::{self, BvhNode, CORNER_WORDS, Shading, Triangle, WideBvhNode};
use crate::object_frames::ObjectFrame;
use crate::scene::Scene;
pub use crate::scene_features::SceneFeatures;

/// Everything the GPU needs for a scene, as plain arrays.
#[derive(Clone, Debug, Default)]
pub struct GpuScene {
    pub triangles: Vec<Triangle>,
    /// Normals, colours and texture coordinates by corner (`crate::corner_records`: three words
    /// per triangle saying where its corners' vertex records are, then the records); empty when
    /// no triangle has any.
    pub shading: Vec<u32>,
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
    /// The light tree over `emitters` (`crate::light_tree`), built where the settings' light
    /// sampler takes it (`LightSampler::uses_tree`); empty otherwise.
    pub light_tree: Vec<gpu_types::LightNode>,
    /// Point, spot and directional lights.
    pub delta_lights: Vec<gpu_types::DeltaLight>,
    /// The environment map's texels and sampling records (empty without one).
    pub env_texels: Vec<gpu_types::EnvTexel>,
    pub env_width: u32,
    pub env_height: u32,
    /// Turns about +y.
    pub env_rotation: f32,
    /// The directional-albedo tables its materials read (`math::layers::albedo_tables_for`).
    pub albedo_tables: Vec<f32>,
    /// Per triangle (BVH order) three corner tangents (xyz, w the bitangent's sign), MikkTSpace,
    /// in world space; empty unless some normal-mapped object needs them.
    pub tangents: Vec<[f32; 4]>,
    pub features: SceneFeatures,
    /// Copies of shared meshes placed in the world (`crate::instances`; none in a flattened
    /// build): their meshes' triangles, in their own space, follow the world-space ones, each
    /// under its own BVH.
    pub instances: Vec<crate::instances::Instance>,
    /// The top-level BVH2 over `instances`' world boxes (leaves index `instances`).
    pub instance_nodes: Vec<BvhNode>,
    /// Each instance's mesh's box in the mesh's space (what a moved instance's world box follows).
    pub instance_mesh_boxes: Vec<(Vec3, Vec3)>,
    /// The box of the triangles stored in world space (inverted without any).
    pub world_box: (Vec3, Vec3),
    /// The largest side of the scene's bounding box (0 without triangles).
    pub extent: f32,
    pub bvh_depth: usize,
    pub bvh_build_time: Duration,
}

impl GpuScene {
    pub fn build(scene: &Scene) -> Result<Self> {
        Self::build_with(scene, BvhQuality::default())
    }

    pub fn build_with(scene: &Scene, quality: BvhQuality) -> Result<Self> {
        Self::build_with_layout(scene, quality, BvhLayout::default())
    }

    /// The scene with each mesh that objects share stored once, under its own BVH, and those
    /// objects as instances of it (`crate::instances`): memory that grows with the unique
    /// triangles, not with the copies.
    pub fn build_with_layout(
        scene: &Scene,
        quality: BvhQuality,
        layout: BvhLayout,
    ) -> Result<Self> {
        Self::build_geometry(scene, quality, layout, true)
    }

    /// The scene flattened: every object's triangles in world space, copies of shared meshes
    /// included (one acceleration structure over all of them, as the driver's ray queries take).
    pub fn build_flattened(scene: &Scene, quality: BvhQuality, layout: BvhLayout) -> Result<Self> {
        Self::build_geometry(scene, quality, layout, false)
    }

    fn build_geometry(
        scene: &Scene,
        quality: BvhQuality,
        layout: BvhLayout,
        share_meshes: bool,
    ) -> Result<Self> {
        if let Some(shown) = crate::posing::with_vanished_hidden(scene) {
            return Self::build_geometry(&shown, quality, layout, share_meshes);
        }
        let mut out = GpuScene::default();
        let texture_offsets = out.pack_texels(scene)?;
        let mut tangents = Vec::with_capacity(scene.objects.len());
        for object in &scene.objects {
            let (material, object_tangents) =
                object_material(scene, object, &texture_offsets, &mut out.features)?;
            out.materials.push(material);
            tangents.push(object_tangents);
        }
        let groups = match share_meshes {
            true => crate::instances::shared_meshes(scene, &out.materials),
            false => Vec::new(),
        };
        let mut instanced = vec![false; scene.objects.len()];
        for &i in groups.iter().flatten() {
            instanced[i] = true;
        }
        let unique: u64 = (scene.objects.iter().zip(&instanced))
            .filter(|(_, shared)| !**shared)
            .map(|(o, _)| o.mesh.indices.len() as u64)
            .chain(
                groups
                    .iter()
                    .map(|g| scene.objects[g[0]].mesh.indices.len() as u64),
            )
            .sum();
        let texels: u64 = scene
            .textures
            .iter()
            .map(|t| u64::from(t.width) * u64::from(t.height))
            .sum();
        crate::memory_budget::check_fits(
            unique,
            crate::memory_budget::build_bytes(unique, texels).saturating_add(
                (groups.iter().map(|g| g.len() as u64).sum::<u64>())
                    .saturating_mul(crate::memory_budget::BUILD_BYTES_PER_INSTANCE),
            ),
            crate::memory_budget::available_bytes(),
        )?;
        // The objects drawn in world space first, under the BVH at node 0.
        let mut frames = Vec::new();
        for (index, object) in scene.objects.iter().enumerate() {
            if !instanced[index] {
                let frame = ObjectFrame::new(object, index as u32, tangents[index].take())?;
                frames.push(frame);
            }
        }
        let mut records = CornerRecords::new(unique as usize);
        let Some((_, world_box)) = out.add_mesh_bvh(&frames, quality, layout, &mut records)? else {
            // A coordinate too large for the wide BVH's grid: all of it binary.
            return Self::build_geometry(scene, quality, BvhLayout::Bvh2, share_meshes);
        };
        drop(frames);
        out.world_box = world_box;
        // Each shared mesh once, in its own space, then its objects as instances.
        for group in &groups {
            let representative = crate::instances::in_mesh_space(&scene.objects[group[0]]);
            let frame =
                ObjectFrame::new(&representative, group[0] as u32, tangents[group[0]].take())?;
            let first_triangle = out.triangles.len() as u32;
            let Some((root, mesh_box)) =
                out.add_mesh_bvh(&[frame], quality, layout, &mut records)?
            else {
                return Self::build_geometry(scene, quality, BvhLayout::Bvh2, share_meshes);
            };
            for &i in group {
                let object = &scene.objects[i];
                ObjectFrame::check_transform(object)?;
                out.instances.push(crate::instances::Instance::new(
                    object,
                    i as u32,
                    (root, first_triangle),
                ));
                out.instance_mesh_boxes.push(mesh_box);
            }
        }
        out.place_instances(quality)?;
        out.light(scene)?;
        out.albedo_tables = crate::math::layers::albedo_tables_for(&out.materials);
        Ok(out)
    }

    /// Every texture's texels, one after another; returns where each begins.
    fn pack_texels(&mut self, scene: &Scene) -> Result<Vec<u32>> {
        let mut texture_offsets = Vec::with_capacity(scene.textures.len());
        for texture in &scene.textures {
            let expected = texture.width as usize * texture.height as usize * 4;
            if texture.rgba8.len() != expected || expected == 0 {
                return Err(Error::Scene(format!(
                    "texture '{}' has no pixel data",
                    texture.name
                )));
            }
            texture_offsets.push(self.texels.len() as u32);
            self.texels.extend(
                texture
                    .rgba8
                    .chunks_exact(4)
                    .map(|p| u32::from_le_bytes([p[0], p[1], p[2], p[3]])),
            );
        }

        Ok(texture_offsets)
    }

    /// Appends the triangles of `frames` (in BVH order, with their attributes) and a BVH over
    /// them in `layout`, its node indices following the nodes already there; returns its root and
    /// the triangles' box. The first call sets the scene's layout; `None` where the wide BVH's grid
    /// cannot hold the coordinates (the caller builds all binary instead).
    fn add_mesh_bvh(
        &mut self,
        frames: &[ObjectFrame],
        quality: BvhQuality,
        layout: BvhLayout,
        records: &mut CornerRecords,
    ) -> Result<Option<(u32, (Vec3, Vec3))>> {
        // Each triangle's box (all the builder reads) and its (frame, face); the
        // corners and attributes are read from the meshes again when written in BVH order.
        let count: usize = frames.iter().map(ObjectFrame::faces).sum();
        let mut boxes = Vec::with_capacity(count);
        let mut faces: Vec<(u32, u32)> = Vec::with_capacity(count);
        let mut bounds = (Vec3::splat(f32::INFINITY), Vec3::splat(f32::NEG_INFINITY));
        for (f, frame) in frames.iter().enumerate() {
            for face in 0..frame.faces() {
                let [v0, v1, v2] = frame.world(face);
                bounds = (
                    bounds.0.min(v0.min(v1).min(v2)),
                    bounds.1.max(v0.max(v1).max(v2)),
                );
                boxes.push(TriangleBox::of([v0, v1, v2]));
                faces.push((f as u32, face as u32));
            }
        }
        self.layout = layout;
        let node_base = self.nodes.len().max(self.wide_nodes.len()) as u32;
        let triangle_base = self.triangles.len() as u32;
        let (order, depth, time) = match layout {
            BvhLayout::Bvh2 => {
                let bvh = build_bvh_over(&boxes, quality).map_err(Error::Scene)?;
                let rebased = bvh
                    .nodes
                    .iter()
                    .map(|n| rebase(n, node_base, triangle_base));
                self.nodes.extend(rebased);
                (bvh.triangle_order, bvh.depth, bvh.build_time)
            }
            BvhLayout::Cwbvh => match build_wide_bvh_over(&boxes, quality) {
                Ok(bvh) => {
                    self.wide_nodes
                        .extend(bvh.nodes.iter().map(|n| WideBvhNode {
                            child_base: n.child_base + node_base,
                            primitive_base: n.primitive_base + triangle_base,
                            ..*n
                        }));
                    (bvh.triangle_order, bvh.depth, bvh.build_time)
                }
                Err(why) => {
                    log::warn!("{why}; using the binary BVH instead");
                    return Ok(None);
                }
            },
        };
        self.bvh_depth = self.bvh_depth.max(depth);
        self.bvh_build_time += time;
        drop(boxes);
        self.push_in_order(&faces, frames, &order, records)?;
        Ok(Some((node_base, bounds)))
    }

    /// The top-level BVH2 over the instances' world boxes, with the instances (and their meshes'
    /// boxes) in its leaf order, and the scene's extent.
    pub(crate) fn place_instances(&mut self, quality: BvhQuality) -> Result<()> {
        let mut bounds = self.world_box;
        let world: Vec<(Vec3, Vec3)> = (self.instances.iter().zip(&self.instance_mesh_boxes))
            .map(|(instance, &(lo, hi))| instance.world_box(lo, hi))
            .collect();
        for &(lo, hi) in &world {
            bounds = (bounds.0.min(lo), bounds.1.max(hi));
        }
        self.extent = if bounds.0.x <= bounds.1.x {
            (bounds.1 - bounds.0).max_element()
        } else {
            0.0
        };
        self.features.instances = !self.instances.is_empty();
        if self.instances.is_empty() {
            self.instance_nodes = Vec::new();
            return Ok(());
        }
        let diagonals: Vec<_> = world
            .iter()
            .map(|&(lo, hi)| TriangleBox::span(lo, hi))
            .collect();
        let bvh = build_bvh_over(&diagonals, quality).map_err(Error::Scene)?;
        self.instance_nodes = bvh.nodes;
        let order = &bvh.triangle_order;
        self.instances = order.iter().map(|&i| self.instances[i as usize]).collect();
        self.instance_mesh_boxes = (order.iter())
            .map(|&i| self.instance_mesh_boxes[i as usize])
            .collect();
        Ok(())
    }

    /// The triangles and their shading attributes (and tangents, with normal maps) in BVH order.
    fn push_in_order(
        &mut self,
        faces: &[(u32, u32)],
        frames: &[ObjectFrame],
        order: &[u32],
        records: &mut CornerRecords,
    ) -> Result<()> {
        self.triangles.reserve(faces.len());
        records.begin(frames.len());
        for &i in order {
            let (f, face) = faces[i as usize];
            let frame = &frames[f as usize];
            let mut p = frame.world(face as usize);
            let mut corners = frame.corners(face as usize);
            let (material, normals, mut t) = frame.data(face as usize);
            let (uvs, colors) = (frame.has_uvs(), frame.has_colors());
            let normals = normals.filter(|n| n.iter().all(|v| v.length_squared() > 0.0));
            // A triangle's front is where its vertex normals point, whatever its winding (as
            // pbrt-v4 orients the geometric normal to the shading normal; Mitsuba's dielectric
            // reads the shading frame): a ball whose faces wind inward but whose normals point
            // out is solid glass seen from outside, not from inside. Swapping corners 1 and 2
            // (with their vertex records) turns the winding over once here, for every estimator,
            // emitter table and light tree alike.
            if let Some(n) = normals
                && (p[1] - p[0]).cross(p[2] - p[0]).dot(n[0] + n[1] + n[2]) < 0.0
            {
                p.swap(1, 2);
                corners.swap(1, 2);
                t = t.map(|t| [t[0], t[2], t[1]]);
            }
            if self.features.normal_maps {
                self.tangents.extend(t.unwrap_or([[0.0; 4]; 3]));
            }
            // Vertex records only once a triangle has attributes: until then the list stays
            // empty, as the build leaves it where none has any.
            if normals.is_some() || uvs || colors {
                let triangle = self.triangles.len();
                records.push(&mut self.shading, triangle, (f as usize, frame), corners)?;
            }
            self.triangles.push(Triangle {
                v0: p[0].to_array(),
                material,
                v1: p[1].to_array(),
                has_normals: normals.is_some() as u32 * gpu_types::HAS_NORMALS
                    + colors as u32 * gpu_types::HAS_COLORS,
                v2: p[2].to_array(),
                has_uvs: uvs as u32,
            });
        }
        Ok(())
    }

    /// Triangle `i`'s shading attributes, gathered from its corners' vertex records
    /// (`crate::corner_records`); zero where it has none. `stored_shading` in `gpu_scene.wgsl`.
    #[inline]
    pub fn stored_shading(&self, i: u32) -> Shading {
        let words = &self.shading;
        let Some(&[a, b, c]) = words.get(3 * i as usize..3 * i as usize + 3) else {
            return Shading::default();
        };
        let record = |o: u32| match words.get(o as usize..o as usize + CORNER_WORDS) {
            Some(&[x, y, z, color, u, v]) => (
                [x, y, z].map(f32::from_bits),
                color,
                [u, v].map(f32::from_bits),
            ),
            _ => ([0.0; 3], 0, [0.0; 2]),
        };
        let (n0, c0, uv0) = record(a);
        let (n1, c1, uv1) = record(b);
        let (n2, c2, uv2) = record(c);
        Shading {
            n0,
            c0,
            n1,
            c1,
            n2,
            c2,
            uv0,
            uv1,
            uv2,
            _pad3: [0.0; 2],
        }
    }

    /// The texture coordinates at the barycentrics (b1, b2) of triangle `i` (zero without), from
    /// the corners' UV words only, as the alpha test calls it during traversal. `stored_uv` in
    /// `gpu_scene.wgsl`.
    pub fn stored_uv(&self, i: u32, b1: f32, b2: f32) -> Vec2 {
        let words = &self.shading;
        let uv = |k: usize| {
            let o = words
                .get(3 * i as usize + k)
                .map_or(usize::MAX, |&o| o as usize);
            match words.get(o.saturating_add(4)..o.saturating_add(6)) {
                Some(&[u, v]) => Vec2::new(f32::from_bits(u), f32::from_bits(v)),
                _ => Vec2::ZERO,
            }
        };
        uv(0) * (1.0 - b1 - b2) + uv(1) * b1 + uv(2) * b2
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
            let had_tangents = old.flags & crate::gpu_types::TANGENTS != 0;
            if tangents.is_some() != had_tangents {
                return Ok(None);
            }
            materials.push(material);
        }
        // Which objects are instances follows their materials (emitters and alpha-tested ones
        // stay in world space): a change to that is a new build.
        if crate::instances::shared_meshes(scene, &materials) != self.instance_groups() {
            return Ok(None);
        }
        let mut out = GpuScene {
            albedo_tables: crate::math::layers::albedo_tables_for(&materials),
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
        // Panorama and fisheye cameras have no lens (`estimator::camera_ray`).
        out.features.thin_lens = scene.camera.aperture_radius > 0.0
            && matches!(
                scene.camera.projection,
                crate::camera::Projection::Perspective | crate::camera::Projection::Orthographic
            );
        (out.emitters, out.emitter_power) =
            crate::emitters::build_emitters(&out.triangles, &out.materials);
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
        // The tree holds the emitters and the point and spot lights.
        let nee = scene.settings.next_event_estimation;
        let tree_lights = out.emitters.len()
            + (out.delta_lights.iter())
                .filter(|l| crate::light_tree::in_tree(l))
                .count();
        out.light_tree =
            if nee && tree_lights > 0 && scene.settings.light_sampler.uses_tree(tree_lights) {
                crate::light_tree::build_light_tree(
                    &mut out.emitters,
                    &out.triangles,
                    &out.materials,
                    &out.delta_lights,
                )
            } else {
                Vec::new()
            };
        out.features.light_tree = !out.light_tree.is_empty();
        out.features.nee = nee && (!out.emitters.is_empty() || out.features.light_tree);
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

    /// The node array of `layout`, as uploaded.
    pub fn node_bytes(&self) -> &[u8] {
        match self.layout {
            BvhLayout::Bvh2 => bytemuck::cast_slice(&self.nodes),
            BvhLayout::Cwbvh => bytemuck::cast_slice(&self.wide_nodes),
        }
    }

    /// Bytes each buffer needs, by buffer name, for limit checks and reports.
    pub fn buffer_sizes(&self) -> [(&'static str, u64); 11] {
        let bytes = |len: usize, size: usize| (len * size) as u64;
        [
            (
                "triangles",
                bytes(self.triangles.len(), size_of::<Triangle>()),
            ),
            ("shading", bytes(self.shading.len(), size_of::<u32>())),
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
                "light tree",
                bytes(self.light_tree.len(), size_of::<gpu_types::LightNode>()),
            ),
            (
                "environment",
                bytes(self.env_texels.len(), size_of::<gpu_types::EnvTexel>()),
            ),
            ("tangents", bytes(self.tangents.len(), 16)),
            (
                "instances",
                bytes(
                    self.instances.len(),
                    size_of::<crate::instances::Instance>(),
                ),
            ),
            (
                "instance nodes",
                bytes(self.instance_nodes.len(), size_of::<BvhNode>()),
            ),
        ]
    }
}

/// A BVH2 node of a mesh whose nodes begin at `node_base` and triangles at `triangle_base`, in the
/// scene's arrays: inner children and leaves moved along (child 0, no child, stays 0).
fn rebase(node: &BvhNode, node_base: u32, triangle_base: u32) -> BvhNode {
    let child = |index: u32, count: u32| match (count, index) {
        (0, 0) => 0,
        (0, _) => index + node_base,
        _ => index + triangle_base,
    };
    BvhNode {
        left: child(node.left, node.left_count),
        right: child(node.right, node.right_count),
        ..*node
    }
}

impl GpuScene {
    /// The objects that are instances, grouped by the mesh they share, as
    /// `instances::shared_meshes` lists them.
    pub fn instance_groups(&self) -> Vec<Vec<usize>> {
        let mut by_root: std::collections::HashMap<u32, Vec<usize>> =
            std::collections::HashMap::new();
        for instance in &self.instances {
            (by_root.entry(instance.root).or_default()).push(instance.material as usize);
        }
        let mut groups: Vec<Vec<usize>> = by_root.into_values().collect();
        for group in &mut groups {
            group.sort_unstable();
        }
        groups.sort_by_key(|g| g[0]);
        groups
    }

    /// This scene with `scene`'s transforms for its instances: only the top level over them is
    /// built again, no mesh's BVH (what the live viewport does when a copy of a shared mesh
    /// moves, turns or scales). `moved(i)` tells whether object `i`'s transform changed; `None`
    /// where one that moved is stored in world space (that needs a full build).
    pub fn with_moved_instances(
        &self,
        scene: &Scene,
        moved: impl Fn(usize) -> bool,
    ) -> crate::Result<Option<crate::GpuScene>> {
        // One flag per object: a crowd moved at once stays linear in its size.
        let mut is_instance = vec![false; self.materials.len()];
        for k in &self.instances {
            is_instance[k.material as usize] = true;
        }
        if scene.objects.len() != self.materials.len()
            || (0..scene.objects.len()).any(|i| moved(i) && !is_instance[i])
        {
            return Ok(None);
        }
        let mut out = self.clone();
        for instance in &mut out.instances {
            let object = &scene.objects[instance.material as usize];
            crate::object_frames::ObjectFrame::check_transform(object)?;
            let mesh = (instance.root, instance.first_triangle);
            *instance = crate::instances::Instance::new(object, instance.material, mesh);
        }
        out.place_instances(crate::bvh::BvhQuality::default())?;
        Ok(Some(out))
    }
}
