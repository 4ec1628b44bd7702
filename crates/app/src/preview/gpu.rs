//! GPU resources of the preview, kept in `egui_wgpu`'s callback resources so they are created once:
//! pipelines, per-mesh and per-texture buffers (cached by the `Arc` they come from), and an
//! offscreen colour + depth target sized to the viewport.

use std::collections::HashMap;
use std::sync::Arc;

use rt_core::Mesh;
use wgpu::util::DeviceExt;

use super::PreviewFrame;
use super::types::{GridVertex, MeshVertex, PreviewObject, PreviewView};

/// Offscreen format: plain RGBA8 holding sRGB-encoded values (the shader encodes), so that the
/// blit can serve sRGB and non-sRGB egui targets alike.
const COLOR_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Rgba8Unorm;
const DEPTH_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Depth32Float;
/// The viewport's background (sRGB-encoded).
const BACKGROUND: wgpu::Color = wgpu::Color {
    r: 0.11,
    g: 0.115,
    b: 0.13,
    a: 1.0,
};

struct CachedMesh {
    vertices: wgpu::Buffer,
    indices: wgpu::Buffer,
    index_count: u32,
    /// Keeps the mesh alive so that its address, the cache key, cannot be reused.
    _mesh: Arc<Mesh>,
    last_used: u64,
}

struct CachedTexture {
    bind_group: wgpu::BindGroup,
    _texels: Arc<[u8]>,
    last_used: u64,
}

struct Target {
    size: [u32; 2],
    color: wgpu::TextureView,
    depth: wgpu::TextureView,
    blit: wgpu::BindGroup,
}

pub struct PreviewResources {
    mesh_pipeline: wgpu::RenderPipeline,
    grid_pipeline: wgpu::RenderPipeline,
    blit_pipeline: wgpu::RenderPipeline,
    view_layout: wgpu::BindGroupLayout,
    texture_layout: wgpu::BindGroupLayout,
    blit_layout: wgpu::BindGroupLayout,
    sampler: wgpu::Sampler,
    view_buffer: wgpu::Buffer,
    objects_buffer: wgpu::Buffer,
    view_bind_group: wgpu::BindGroup,
    white: wgpu::BindGroup,
    meshes: HashMap<usize, CachedMesh>,
    textures: HashMap<usize, CachedTexture>,
    target: Option<Target>,
    frame: u64,
}

/// Creates the preview's resources on egui's device and stores them for the paint callback.
pub fn install(render_state: &egui_wgpu::RenderState) {
    let resources = PreviewResources::new(
        &render_state.device,
        &render_state.queue,
        render_state.target_format,
    );
    render_state
        .renderer
        .write()
        .callback_resources
        .insert(resources);
}

fn shader(device: &wgpu::Device, label: &str, source: String) -> wgpu::ShaderModule {
    device.create_shader_module(wgpu::ShaderModuleDescriptor {
        label: Some(label),
        source: wgpu::ShaderSource::Wgsl(source.into()),
    })
}

impl PreviewResources {
    pub fn new(
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        target_format: wgpu::TextureFormat,
    ) -> Self {
        let module = shader(device, "preview", rt_gpu::shaders::PREVIEW.source());
        let blit_module = shader(
            device,
            "preview blit",
            rt_gpu::shaders::PREVIEW_BLIT.source(),
        );
        let uniform = |binding, visibility| wgpu::BindGroupLayoutEntry {
            binding,
            visibility,
            ty: wgpu::BindingType::Buffer {
                ty: wgpu::BufferBindingType::Uniform,
                has_dynamic_offset: false,
                min_binding_size: None,
            },
            count: None,
        };
        let storage = |binding, visibility| wgpu::BindGroupLayoutEntry {
            binding,
            visibility,
            ty: wgpu::BindingType::Buffer {
                ty: wgpu::BufferBindingType::Storage { read_only: true },
                has_dynamic_offset: false,
                min_binding_size: None,
            },
            count: None,
        };
        let texture = |binding| wgpu::BindGroupLayoutEntry {
            binding,
            visibility: wgpu::ShaderStages::FRAGMENT,
            ty: wgpu::BindingType::Texture {
                sample_type: wgpu::TextureSampleType::Float { filterable: true },
                view_dimension: wgpu::TextureViewDimension::D2,
                multisampled: false,
            },
            count: None,
        };
        let sampler_entry = |binding| wgpu::BindGroupLayoutEntry {
            binding,
            visibility: wgpu::ShaderStages::FRAGMENT,
            ty: wgpu::BindingType::Sampler(wgpu::SamplerBindingType::Filtering),
            count: None,
        };
        let vf = wgpu::ShaderStages::VERTEX_FRAGMENT;
        let view_layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("preview view"),
            entries: &[uniform(0, vf), storage(1, vf)],
        });
        let texture_layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("preview texture"),
            entries: &[texture(0), sampler_entry(1)],
        });
        let blit_layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("preview blit"),
            entries: &[texture(0), sampler_entry(1)],
        });
        let mesh_layout = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
            label: Some("preview mesh"),
            bind_group_layouts: &[Some(&view_layout), Some(&texture_layout)],
            immediate_size: 0,
        });
        let blit_pipeline_layout = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
            label: Some("preview blit"),
            bind_group_layouts: &[Some(&blit_layout)],
            immediate_size: 0,
        });
        let depth = Some(wgpu::DepthStencilState {
            format: DEPTH_FORMAT,
            depth_write_enabled: Some(true),
            depth_compare: Some(wgpu::CompareFunction::LessEqual),
            stencil: wgpu::StencilState::default(),
            bias: wgpu::DepthBiasState::default(),
        });
        let color_target = [Some(wgpu::ColorTargetState {
            format: COLOR_FORMAT,
            blend: None,
            write_mask: wgpu::ColorWrites::ALL,
        })];
        let mesh_attributes =
            wgpu::vertex_attr_array![0 => Float32x3, 1 => Float32x3, 2 => Float32x2];
        let mesh_pipeline = device.create_render_pipeline(&wgpu::RenderPipelineDescriptor {
            label: Some("preview mesh"),
            layout: Some(&mesh_layout),
            vertex: wgpu::VertexState {
                module: &module,
                entry_point: Some("vs_mesh"),
                compilation_options: Default::default(),
                buffers: &[Some(wgpu::VertexBufferLayout {
                    array_stride: std::mem::size_of::<MeshVertex>() as u64,
                    step_mode: wgpu::VertexStepMode::Vertex,
                    attributes: &mesh_attributes,
                })],
            },
            primitive: wgpu::PrimitiveState::default(),
            depth_stencil: depth.clone(),
            multisample: wgpu::MultisampleState::default(),
            fragment: Some(wgpu::FragmentState {
                module: &module,
                entry_point: Some("fs_mesh"),
                compilation_options: Default::default(),
                targets: &color_target,
            }),
            multiview_mask: None,
            cache: None,
        });
        let grid_attributes = wgpu::vertex_attr_array![0 => Float32x3, 1 => Float32x4];
        let grid_pipeline = device.create_render_pipeline(&wgpu::RenderPipelineDescriptor {
            label: Some("preview grid"),
            layout: Some(&mesh_layout),
            vertex: wgpu::VertexState {
                module: &module,
                entry_point: Some("vs_grid"),
                compilation_options: Default::default(),
                buffers: &[Some(wgpu::VertexBufferLayout {
                    array_stride: std::mem::size_of::<GridVertex>() as u64,
                    step_mode: wgpu::VertexStepMode::Vertex,
                    attributes: &grid_attributes,
                })],
            },
            primitive: wgpu::PrimitiveState {
                topology: wgpu::PrimitiveTopology::LineList,
                ..Default::default()
            },
            depth_stencil: depth,
            multisample: wgpu::MultisampleState::default(),
            fragment: Some(wgpu::FragmentState {
                module: &module,
                entry_point: Some("fs_grid"),
                compilation_options: Default::default(),
                targets: &color_target,
            }),
            multiview_mask: None,
            cache: None,
        });
        let srgb_target = [(
            "TARGET_IS_SRGB",
            if target_format.is_srgb() { 1.0 } else { 0.0 },
        )];
        let blit_pipeline = device.create_render_pipeline(&wgpu::RenderPipelineDescriptor {
            label: Some("preview blit"),
            layout: Some(&blit_pipeline_layout),
            vertex: wgpu::VertexState {
                module: &blit_module,
                entry_point: Some("vs_blit"),
                compilation_options: Default::default(),
                buffers: &[],
            },
            primitive: wgpu::PrimitiveState::default(),
            depth_stencil: None,
            multisample: wgpu::MultisampleState::default(),
            fragment: Some(wgpu::FragmentState {
                module: &blit_module,
                entry_point: Some("fs_blit"),
                compilation_options: wgpu::PipelineCompilationOptions {
                    constants: &srgb_target,
                    ..Default::default()
                },
                targets: &[Some(wgpu::ColorTargetState {
                    format: target_format,
                    blend: None,
                    write_mask: wgpu::ColorWrites::ALL,
                })],
            }),
            multiview_mask: None,
            cache: None,
        });
        let sampler = device.create_sampler(&wgpu::SamplerDescriptor {
            label: Some("preview"),
            address_mode_u: wgpu::AddressMode::Repeat,
            address_mode_v: wgpu::AddressMode::Repeat,
            mag_filter: wgpu::FilterMode::Linear,
            min_filter: wgpu::FilterMode::Linear,
            ..Default::default()
        });
        let view_buffer = device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("preview view"),
            size: std::mem::size_of::<PreviewView>() as u64,
            usage: wgpu::BufferUsages::UNIFORM | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        let objects_buffer = objects_buffer(device, 16);
        let view_bind_group = view_bind_group(device, &view_layout, &view_buffer, &objects_buffer);
        let white = texture_bind_group(
            device,
            queue,
            &texture_layout,
            &sampler,
            &[255, 255, 255, 255],
            1,
            1,
        );
        PreviewResources {
            mesh_pipeline,
            grid_pipeline,
            blit_pipeline,
            view_layout,
            texture_layout,
            blit_layout,
            sampler,
            view_buffer,
            objects_buffer,
            view_bind_group,
            white,
            meshes: HashMap::new(),
            textures: HashMap::new(),
            target: None,
            frame: 0,
        }
    }

    /// Renders `frame` into the offscreen target.
    pub fn render(
        &mut self,
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        encoder: &mut wgpu::CommandEncoder,
        frame: &PreviewFrame,
    ) {
        self.frame += 1;
        let now = self.frame;
        self.ensure_target(device, frame.size_px);
        let object_bytes =
            (frame.objects.len().max(1) * std::mem::size_of::<PreviewObject>()) as u64;
        if object_bytes > self.objects_buffer.size() {
            self.objects_buffer = objects_buffer(device, frame.objects.len().next_power_of_two());
            self.view_bind_group = view_bind_group(
                device,
                &self.view_layout,
                &self.view_buffer,
                &self.objects_buffer,
            );
        }
        queue.write_buffer(&self.view_buffer, 0, bytemuck::bytes_of(&frame.view));
        if !frame.objects.is_empty() {
            queue.write_buffer(
                &self.objects_buffer,
                0,
                bytemuck::cast_slice(&frame.objects),
            );
        }
        for mesh in &frame.meshes {
            let key = Arc::as_ptr(mesh) as usize;
            self.meshes
                .entry(key)
                .or_insert_with(|| upload_mesh(device, mesh))
                .last_used = now;
        }
        for texture in frame.textures.iter().flatten() {
            let key = Arc::as_ptr(&texture.texels) as *const u8 as usize;
            let (layout, sampler) = (&self.texture_layout, &self.sampler);
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

        let grid = (!frame.grid.is_empty()).then(|| {
            device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
                label: Some("preview grid"),
                contents: bytemuck::cast_slice(&frame.grid),
                usage: wgpu::BufferUsages::VERTEX,
            })
        });
        let Some(target) = &self.target else {
            return;
        };
        let mut pass = encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
            label: Some("preview"),
            color_attachments: &[Some(wgpu::RenderPassColorAttachment {
                view: &target.color,
                depth_slice: None,
                resolve_target: None,
                ops: wgpu::Operations {
                    load: wgpu::LoadOp::Clear(BACKGROUND),
                    store: wgpu::StoreOp::Store,
                },
            })],
            depth_stencil_attachment: Some(wgpu::RenderPassDepthStencilAttachment {
                view: &target.depth,
                depth_ops: Some(wgpu::Operations {
                    load: wgpu::LoadOp::Clear(1.0),
                    store: wgpu::StoreOp::Discard,
                }),
                stencil_ops: None,
            }),
            timestamp_writes: None,
            occlusion_query_set: None,
            multiview_mask: None,
        });
        pass.set_pipeline(&self.mesh_pipeline);
        pass.set_bind_group(0, &self.view_bind_group, &[]);
        for (i, mesh) in frame.meshes.iter().enumerate() {
            let Some(cached) = self.meshes.get(&(Arc::as_ptr(mesh) as usize)) else {
                continue;
            };
            if cached.index_count == 0 {
                continue;
            }
            let texture = frame.textures[i]
                .as_ref()
                .and_then(|t| {
                    self.textures
                        .get(&(Arc::as_ptr(&t.texels) as *const u8 as usize))
                })
                .map_or(&self.white, |t| &t.bind_group);
            pass.set_bind_group(1, texture, &[]);
            pass.set_vertex_buffer(0, cached.vertices.slice(..));
            pass.set_index_buffer(cached.indices.slice(..), wgpu::IndexFormat::Uint32);
            let instance = i as u32;
            pass.draw_indexed(0..cached.index_count, 0, instance..instance + 1);
        }
        if let Some(grid) = &grid {
            pass.set_pipeline(&self.grid_pipeline);
            pass.set_bind_group(1, &self.white, &[]);
            pass.set_vertex_buffer(0, grid.slice(..));
            pass.draw(0..frame.grid.len() as u32, 0..1);
        }
    }

    /// Copies the offscreen image into egui's pass (whose viewport egui has set to our rect).
    pub fn paint(&self, pass: &mut wgpu::RenderPass<'static>) {
        if let Some(target) = &self.target {
            pass.set_pipeline(&self.blit_pipeline);
            pass.set_bind_group(0, &target.blit, &[]);
            pass.draw(0..3, 0..1);
        }
    }

    fn ensure_target(&mut self, device: &wgpu::Device, size: [u32; 2]) {
        let limit = device.limits().max_texture_dimension_2d;
        let size = size.map(|s| s.clamp(1, limit));
        if self.target.as_ref().is_some_and(|t| t.size == size) {
            return;
        }
        let texture = |label, format, usage| {
            device
                .create_texture(&wgpu::TextureDescriptor {
                    label: Some(label),
                    size: wgpu::Extent3d {
                        width: size[0],
                        height: size[1],
                        depth_or_array_layers: 1,
                    },
                    mip_level_count: 1,
                    sample_count: 1,
                    dimension: wgpu::TextureDimension::D2,
                    format,
                    usage,
                    view_formats: &[],
                })
                .create_view(&wgpu::TextureViewDescriptor::default())
        };
        let color = texture(
            "preview colour",
            COLOR_FORMAT,
            wgpu::TextureUsages::RENDER_ATTACHMENT | wgpu::TextureUsages::TEXTURE_BINDING,
        );
        let depth = texture(
            "preview depth",
            DEPTH_FORMAT,
            wgpu::TextureUsages::RENDER_ATTACHMENT,
        );
        let blit = device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("preview blit"),
            layout: &self.blit_layout,
            entries: &[
                wgpu::BindGroupEntry {
                    binding: 0,
                    resource: wgpu::BindingResource::TextureView(&color),
                },
                wgpu::BindGroupEntry {
                    binding: 1,
                    resource: wgpu::BindingResource::Sampler(&self.sampler),
                },
            ],
        });
        self.target = Some(Target {
            size,
            color,
            depth,
            blit,
        });
    }
}

fn objects_buffer(device: &wgpu::Device, capacity: usize) -> wgpu::Buffer {
    device.create_buffer(&wgpu::BufferDescriptor {
        label: Some("preview objects"),
        size: (capacity.max(1) * std::mem::size_of::<PreviewObject>()) as u64,
        usage: wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_DST,
        mapped_at_creation: false,
    })
}

fn view_bind_group(
    device: &wgpu::Device,
    layout: &wgpu::BindGroupLayout,
    view: &wgpu::Buffer,
    objects: &wgpu::Buffer,
) -> wgpu::BindGroup {
    device.create_bind_group(&wgpu::BindGroupDescriptor {
        label: Some("preview view"),
        layout,
        entries: &[
            wgpu::BindGroupEntry {
                binding: 0,
                resource: view.as_entire_binding(),
            },
            wgpu::BindGroupEntry {
                binding: 1,
                resource: objects.as_entire_binding(),
            },
        ],
    })
}

fn texture_bind_group(
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

/// The paint callback: one per preview frame.
pub struct PreviewCallback(pub Arc<PreviewFrame>);

impl egui_wgpu::CallbackTrait for PreviewCallback {
    fn prepare(
        &self,
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        _screen: &egui_wgpu::ScreenDescriptor,
        encoder: &mut wgpu::CommandEncoder,
        resources: &mut egui_wgpu::CallbackResources,
    ) -> Vec<wgpu::CommandBuffer> {
        if let Some(preview) = resources.get_mut::<PreviewResources>() {
            preview.render(device, queue, encoder, &self.0);
        }
        Vec::new()
    }

    fn paint(
        &self,
        _info: egui::PaintCallbackInfo,
        pass: &mut wgpu::RenderPass<'static>,
        resources: &egui_wgpu::CallbackResources,
    ) {
        if let Some(preview) = resources.get::<PreviewResources>() {
            preview.paint(pass);
        }
    }
}
