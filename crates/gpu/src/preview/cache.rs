//! The preview's GPU copies of the scene's meshes and textures, cached by the `Arc` they come from
//! so that a frame uploads only what is new, and dropped a while after the scene stops using them.

use std::sync::Arc;

use rt_core::Mesh;
use wgpu::util::DeviceExt;

use super::PreviewRenderer;
use super::frame::PreviewFrame;
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
    pub(super) bind_group: wgpu::BindGroup,
    _texels: Arc<[u8]>,
    last_used: u64,
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
        for texture in frame.textures.iter().flatten() {
            let key = Arc::as_ptr(&texture.texels) as *const u8 as usize;
            let (layout, sampler) = (&self.pipelines.texture_layout, &self.pipelines.sampler);
            self.textures
                .entry(key)
                .or_insert_with(|| CachedTexture {
                    bind_group: texture_bind_group(
                        device,
                        queue,
                        layout,
                        sampler,
                        &texture.texels,
                        texture.width,
                        texture.height,
                    ),
                    _texels: texture.texels.clone(),
                    last_used: now,
                })
                .last_used = now;
        }
        // Buffers of meshes and textures no longer in the scene go after a few frames (undo may
        // bring them back at once).
        self.meshes.retain(|_, m| now - m.last_used < 120);
        self.textures.retain(|_, t| now - t.last_used < 120);
    }
}

pub(super) fn texture_bind_group(
    device: &wgpu::Device,
    queue: &wgpu::Queue,
    layout: &wgpu::BindGroupLayout,
    sampler: &wgpu::Sampler,
    texels: &[u8],
    width: u32,
    height: u32,
) -> wgpu::BindGroup {
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
        label: Some("preview albedo"),
        size: wgpu::Extent3d {
            width,
            height,
            depth_or_array_layers: 1,
        },
        mip_level_count: 1,
        sample_count: 1,
        dimension: wgpu::TextureDimension::D2,
        format: wgpu::TextureFormat::Rgba8UnormSrgb,
        usage: wgpu::TextureUsages::TEXTURE_BINDING | wgpu::TextureUsages::COPY_DST,
        view_formats: &[],
    };
    let texture = device.create_texture_with_data(
        queue,
        &descriptor,
        wgpu::util::TextureDataOrder::LayerMajor,
        texels,
    );
    let view = texture.create_view(&wgpu::TextureViewDescriptor::default());
    device.create_bind_group(&wgpu::BindGroupDescriptor {
        label: Some("preview albedo"),
        layout,
        entries: &[
            wgpu::BindGroupEntry {
                binding: 0,
                resource: wgpu::BindingResource::TextureView(&view),
            },
            wgpu::BindGroupEntry {
                binding: 1,
                resource: wgpu::BindingResource::Sampler(sampler),
            },
        ],
    })
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
        &[0; 32]
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
