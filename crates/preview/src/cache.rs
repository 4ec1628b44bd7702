//! The preview's GPU copies of the scene's meshes and textures, cached by the `Arc` they come from
//! so that a frame uploads only what is new, with each material's textures bound together, all
//! dropped a while after the scene stops using them.

use std::sync::Arc;

use rt_core::Mesh;
use wgpu::util::DeviceExt;

use super::PreviewRenderer;
use super::frame::{MaterialTextures, PreviewFrame, TextureRef};
use super::types::MeshVertex;

pub(super) struct CachedMesh {
    pub(super) vertices: wgpu::Buffer,
    pub(super) indices: wgpu::Buffer,
    pub(super) index_count: u32,
    /// Keeps the mesh alive so that its address, the cache key, cannot be reused.
    _mesh: Arc<Mesh>,
    last_used: u64,
}

pub(super) struct CachedTexture {
    view: wgpu::TextureView,
    _texels: Arc<[u8]>,
    last_used: u64,
}

/// A material's textures bound together, keyed by their images' cache keys.
pub(super) struct CachedBinding {
    pub(super) bind_group: wgpu::BindGroup,
    last_used: u64,
}

/// The cache key of a texture slot's image: its texels' address, and whether it holds colour
/// (sRGB-encoded) or data (linear); 0 for an empty slot.
fn texture_key(texture: Option<&TextureRef>, srgb: bool) -> usize {
    texture.map_or(0, |t| {
        (Arc::as_ptr(&t.texels) as *const u8 as usize) | usize::from(srgb)
    })
}

/// The bind-group key of a material's slots.
pub(super) fn binding_key(textures: &MaterialTextures) -> [usize; 4] {
    std::array::from_fn(|slot| texture_key(textures.slots[slot].as_ref(), SRGB_SLOTS[slot]))
}

impl PreviewRenderer {
    /// Uploads the meshes and textures of `frame` not cached yet, marks those it uses as used at
    /// `now`, and drops the ones it has not used for a while.
    pub(super) fn update_caches(
        &mut self,
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        frame: &PreviewFrame,
        now: u64,
    ) {
        for mesh in &frame.meshes {
            let key = Arc::as_ptr(mesh) as usize;
            self.meshes
                .entry(key)
                .or_insert_with(|| upload_mesh(device, mesh))
                .last_used = now;
        }
        for material in &frame.textures {
            for (slot, texture) in material.slots.iter().enumerate() {
                let Some(texture) = texture else { continue };
                let srgb = SRGB_SLOTS[slot];
                self.textures
                    .entry(texture_key(Some(texture), srgb))
                    .or_insert_with(|| CachedTexture {
                        view: upload_texture(
                            device,
                            queue,
                            &texture.texels,
                            [texture.width, texture.height],
                            srgb,
                        ),
                        _texels: texture.texels.clone(),
                        last_used: now,
                    })
                    .last_used = now;
            }
            let key = binding_key(material);
            if key == [0; 4] {
                continue;
            }
            if !self.bindings.contains_key(&key) {
                let views: [&wgpu::TextureView; 4] = std::array::from_fn(|slot| {
                    self.textures
                        .get(&key[slot])
                        .map_or(&self.defaults[slot], |t| &t.view)
                });
                let bind_group = self.pipelines.texture_bind_group(device, views);
                self.bindings.insert(
                    key,
                    CachedBinding {
                        bind_group,
                        last_used: now,
                    },
                );
            }
            if let Some(binding) = self.bindings.get_mut(&key) {
                binding.last_used = now;
            }
        }
        // Buffers of meshes and textures no longer in the scene go after a few frames (undo may
        // bring them back at once).
        self.meshes.retain(|_, m| now - m.last_used < 120);
        self.textures.retain(|_, t| now - t.last_used < 120);
        self.bindings.retain(|_, b| now - b.last_used < 120);
    }
}

/// Which slots hold colour (sRGB-encoded, decoded by the sampler): base colour and emission; the
/// metallic-roughness image and the normal map hold data.
pub(super) const SRGB_SLOTS: [bool; 4] = [true, false, false, true];

/// A texture of `texels` (RGBA8, row-major); a malformed or oversized image becomes one white
/// texel rather than an error in the middle of a frame.
pub(super) fn upload_texture(
    device: &wgpu::Device,
    queue: &wgpu::Queue,
    texels: &[u8],
    [width, height]: [u32; 2],
    srgb: bool,
) -> wgpu::TextureView {
    let limit = device.limits().max_texture_dimension_2d;
    let valid = texels.len() == width as usize * height as usize * 4
        && width > 0
        && height > 0
        && width <= limit
        && height <= limit;
    let (texels, width, height) = if valid {
        (texels, width, height)
    } else {
        (&[255u8, 255, 255, 255][..], 1, 1)
    };
    let descriptor = wgpu::TextureDescriptor {
        label: Some("preview material image"),
        size: wgpu::Extent3d {
            width,
            height,
            depth_or_array_layers: 1,
        },
        mip_level_count: 1,
        sample_count: 1,
        dimension: wgpu::TextureDimension::D2,
        format: if srgb {
            wgpu::TextureFormat::Rgba8UnormSrgb
        } else {
            wgpu::TextureFormat::Rgba8Unorm
        },
        usage: wgpu::TextureUsages::TEXTURE_BINDING | wgpu::TextureUsages::COPY_DST,
        view_formats: &[],
    };
    device
        .create_texture_with_data(
            queue,
            &descriptor,
            wgpu::util::TextureDataOrder::LayerMajor,
            texels,
        )
        .create_view(&wgpu::TextureViewDescriptor::default())
}

fn upload_mesh(device: &wgpu::Device, mesh: &Arc<Mesh>) -> CachedMesh {
    let vertices: Vec<MeshVertex> = (0..mesh.positions.len())
        .map(|i| MeshVertex {
            position: mesh.positions[i].to_array(),
            normal: mesh
                .normals
                .as_ref()
                .and_then(|n| n.get(i))
                .map_or([0.0; 3], |n| n.to_array()),
            uv: mesh
                .uvs
                .as_ref()
                .and_then(|t| t.get(i))
                .map_or([0.0; 2], |t| t.to_array()),
            color: mesh
                .colors
                .as_ref()
                .and_then(|c| c.get(i))
                .map_or([1.0; 3], |c| c.to_array()),
        })
        .collect();
    let indices: Vec<u32> = mesh
        .indices
        .iter()
        .filter(|t| t.iter().all(|&i| (i as usize) < vertices.len()))
        .flatten()
        .copied()
        .collect();
    let vertex_bytes: &[u8] = if vertices.is_empty() {
        &[0; std::mem::size_of::<MeshVertex>()]
    } else {
        bytemuck::cast_slice(&vertices)
    };
    let index_bytes: &[u8] = if indices.is_empty() {
        &[0; 12]
    } else {
        bytemuck::cast_slice(&indices)
    };
    CachedMesh {
        vertices: device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
            label: Some("preview vertices"),
            contents: vertex_bytes,
            usage: wgpu::BufferUsages::VERTEX,
        }),
        indices: device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
            label: Some("preview indices"),
            contents: index_bytes,
            usage: wgpu::BufferUsages::INDEX,
        }),
        index_count: indices.len() as u32,
        _mesh: mesh.clone(),
        last_used: 0,
    }
}
