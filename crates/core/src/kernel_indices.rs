//! `GpuScene::check_kernel_indices`: the index invariants the tracing kernels rely on, checked
//! against a built scene (BVH children and leaves, instances, materials, shading records, texels,
//! emitters).

use crate::bvh::BvhLayout;
use crate::gpu_scene::GpuScene;
use crate::gpu_types::{
    NO_TEXTURE, SLOT_BASE, SLOT_EMISSION, SLOT_METALLIC_ROUGHNESS, SLOT_NORMAL, TextureSlot,
    Triangle,
};

impl GpuScene {
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
        self.check_instance_indices()?;
        self.check_record_indices()
    }

    /// Instances' mesh roots and materials, and the top level's children and leaf ranges.
    fn check_instance_indices(&self) -> std::result::Result<(), String> {
        let nodes = self.nodes.len().max(self.wide_nodes.len());
        for (i, instance) in self.instances.iter().enumerate() {
            if instance.root as usize >= nodes || instance.material as usize >= self.materials.len()
            {
                return Err(format!(
                    "instance {i}: root node {} of {nodes}, material {} of {}",
                    instance.root,
                    instance.material,
                    self.materials.len()
                ));
            }
        }
        if self.instances.is_empty() {
            return Ok(());
        }
        let (top, count) = (self.instance_nodes.len(), self.instances.len() as u64);
        for (i, node) in self.instance_nodes.iter().enumerate() {
            for (index, leaf) in [(node.left, node.left_count), (node.right, node.right_count)] {
                let bad = match leaf {
                    0 => index != 0 && !(index as usize > i && (index as usize) < top),
                    _ => u64::from(index) + u64::from(leaf) > count,
                };
                if bad {
                    return Err(format!(
                        "instance BVH node {i}: child {index} ({leaf} instances) outside the \
                         {top} nodes or {count} instances"
                    ));
                }
            }
        }
        Ok(())
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

    /// Triangle `i`'s corner words and the vertex records they point at (`crate::corner_records`).
    fn check_corner_records(&self, i: usize) -> std::result::Result<(), String> {
        let words = self.shading.len();
        let Some(corners) = self.shading.get(3 * i..3 * i + 3) else {
            return Err(format!(
                "triangle {i}: no shading record ({words} shading words)"
            ));
        };
        let records = 3 * self.triangles.len();
        for &o in corners {
            let end = o as usize + crate::gpu_types::CORNER_WORDS;
            if (o as usize) < records || end > words {
                return Err(format!(
                    "triangle {i}: vertex record at word {o}, outside the records ({records}..{words})"
                ));
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
            if needs_shading(t) {
                self.check_corner_records(i)?;
            }
        }
        for (i, m) in self.materials.iter().enumerate() {
            for slot in 0..crate::gpu_types::SLOTS as u32 {
                let what = match slot {
                    SLOT_BASE => "texture".to_string(),
                    SLOT_METALLIC_ROUGHNESS => "metallic-roughness texture".to_string(),
                    SLOT_NORMAL => "normal texture".to_string(),
                    SLOT_EMISSION => "emission texture".to_string(),
                    _ => format!("texture slot {slot}"),
                };
                let TextureSlot {
                    offset,
                    width: w,
                    height: h,
                } = m.texture(slot);
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
            if m.flags & crate::gpu_types::TANGENTS != 0 && self.tangents.len() != 3 * triangles {
                return Err(format!(
                    "material {i} has tangents but there are {} tangents for {triangles} triangles",
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
}
