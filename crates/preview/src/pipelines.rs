//! Creation of the preview's GPU objects that live as long as it does: the shader module, bind
//! group layouts, the pipelines (opaque and blended meshes, background, grid, shadow maps), the
//! samplers, and the bindings of its buffers.

use super::types::{GridVertex, MeshVertex, PreviewObject};
use super::{COLOR_FORMAT, DEPTH_FORMAT};

pub(super) struct Pipelines {
    pub(super) opaque: wgpu::RenderPipeline,
    pub(super) reading: wgpu::RenderPipeline,
    pub(super) blended: wgpu::RenderPipeline,
    pub(super) background: wgpu::RenderPipeline,
    pub(super) grid: wgpu::RenderPipeline,
    pub(super) shadow: wgpu::RenderPipeline,
    pub(super) outline: super::outline::Outline,
    pub(super) view_layout: wgpu::BindGroupLayout,
    pub(super) shadow_layout: wgpu::BindGroupLayout,
    pub(super) texture_layout: wgpu::BindGroupLayout,
    pub(super) sampler: wgpu::Sampler,
    pub(super) shadow_sampler: wgpu::Sampler,
    pub(super) clamped: wgpu::Sampler,
}

fn buffer_entry(
    binding: u32,
    visibility: wgpu::ShaderStages,
    ty: wgpu::BufferBindingType,
) -> wgpu::BindGroupLayoutEntry {
    wgpu::BindGroupLayoutEntry {
        binding,
        visibility,
        ty: wgpu::BindingType::Buffer {
            ty,
            has_dynamic_offset: false,
            min_binding_size: None,
        },
        count: None,
    }
}

fn texture_entry(
    binding: u32,
    sample_type: wgpu::TextureSampleType,
    view_dimension: wgpu::TextureViewDimension,
) -> wgpu::BindGroupLayoutEntry {
    wgpu::BindGroupLayoutEntry {
        binding,
        visibility: wgpu::ShaderStages::FRAGMENT,
        ty: wgpu::BindingType::Texture {
            sample_type,
            view_dimension,
            multisampled: false,
        },
        count: None,
    }
}

fn sampler_entry(binding: u32, ty: wgpu::SamplerBindingType) -> wgpu::BindGroupLayoutEntry {
    wgpu::BindGroupLayoutEntry {
        binding,
        visibility: wgpu::ShaderStages::FRAGMENT,
        ty: wgpu::BindingType::Sampler(ty),
        count: None,
    }
}

/// Premultiplied alpha: what is drawn adds to what lies behind, which keeps 1 − alpha.
const PREMULTIPLIED: wgpu::BlendState = wgpu::BlendState {
    color: wgpu::BlendComponent {
        src_factor: wgpu::BlendFactor::One,
        dst_factor: wgpu::BlendFactor::OneMinusSrcAlpha,
        operation: wgpu::BlendOperation::Add,
    },
    alpha: wgpu::BlendComponent::OVER,
};

/// The mesh vertex layout (position, normal, uv, tangent), for the mesh and shadow pipelines.
const MESH_ATTRIBUTES: [wgpu::VertexAttribute; 4] =
    wgpu::vertex_attr_array![0 => Float32x3, 1 => Float32x3, 2 => Float32x2, 3 => Float32x3];

fn mesh_buffer() -> wgpu::VertexBufferLayout<'static> {
    wgpu::VertexBufferLayout {
        array_stride: std::mem::size_of::<MeshVertex>() as u64,
        step_mode: wgpu::VertexStepMode::Vertex,
        attributes: &MESH_ATTRIBUTES,
    }
}

/// The pipelines that draw into the target.
struct DrawPipelines {
    opaque: wgpu::RenderPipeline,
    reading: wgpu::RenderPipeline,
    blended: wgpu::RenderPipeline,
    background: wgpu::RenderPipeline,
    grid: wgpu::RenderPipeline,
}

impl Pipelines {
    pub(super) fn new(device: &wgpu::Device) -> Self {
        let module = device.create_shader_module(wgpu::ShaderModuleDescriptor {
            label: Some("preview"),
            source: wgpu::ShaderSource::Wgsl(rt_gpu::shaders::PREVIEW.source().into()),
        });
        let [view_layout, shadow_layout, texture_layout] = bind_group_layouts(device);
        let draw = draw_pipelines(device, &module, [&view_layout, &texture_layout]);
        let shadow = shadow_pipeline(device, &module, &shadow_layout);
        let outline = super::outline::Outline::new(
            device,
            &module,
            [&view_layout, &texture_layout],
            mesh_buffer(),
        );
        let [sampler, clamped, shadow_sampler] = samplers(device);
        Pipelines {
            opaque: draw.opaque,
            reading: draw.reading,
            blended: draw.blended,
            background: draw.background,
            grid: draw.grid,
            shadow,
            outline,
            view_layout,
            shadow_layout,
            texture_layout,
            sampler,
            shadow_sampler,
            clamped,
        }
    }

    /// The frame's bindings: the view, objects and shadow views' buffers, the shadow maps, the
    /// environment's sharp and prefiltered images, the BRDF table, the irradiance volume and the
    /// copy of the frame behind solid glass (colour, depth).
    pub(super) fn view_bind_group(
        &self,
        device: &wgpu::Device,
        [view, objects, matrices]: [&wgpu::Buffer; 3],
        shadow_maps: &wgpu::TextureView,
        [sharp, blur, brdf, probes, radiance, behind, behind_depth]: [&wgpu::TextureView; 7],
    ) -> wgpu::BindGroup {
        let texture = |binding, view| wgpu::BindGroupEntry {
            binding,
            resource: wgpu::BindingResource::TextureView(view),
        };
        device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("preview view"),
            layout: &self.view_layout,
            entries: &[
                wgpu::BindGroupEntry {
                    binding: 0,
                    resource: view.as_entire_binding(),
                },
                wgpu::BindGroupEntry {
                    binding: 1,
                    resource: objects.as_entire_binding(),
                },
                wgpu::BindGroupEntry {
                    binding: 2,
                    resource: matrices.as_entire_binding(),
                },
                texture(3, shadow_maps),
                wgpu::BindGroupEntry {
                    binding: 4,
                    resource: wgpu::BindingResource::Sampler(&self.shadow_sampler),
                },
                texture(5, sharp),
                texture(6, blur),
                texture(7, brdf),
                wgpu::BindGroupEntry {
                    binding: 8,
                    resource: wgpu::BindingResource::Sampler(&self.clamped),
                },
                texture(9, probes),
                texture(10, radiance),
                texture(11, behind),
                texture(12, behind_depth),
            ],
        })
    }

    /// A material's images: base colour, metallic-roughness, normal map, emission.
    pub(super) fn texture_bind_group(
        &self,
        device: &wgpu::Device,
        [base, metal_rough, normal, emission]: [&wgpu::TextureView; 4],
    ) -> wgpu::BindGroup {
        let texture = |binding, view| wgpu::BindGroupEntry {
            binding,
            resource: wgpu::BindingResource::TextureView(view),
        };
        device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("preview material images"),
            layout: &self.texture_layout,
            entries: &[
                texture(0, base),
                wgpu::BindGroupEntry {
                    binding: 1,
                    resource: wgpu::BindingResource::Sampler(&self.sampler),
                },
                texture(2, metal_rough),
                texture(3, normal),
                texture(4, emission),
            ],
        })
    }

    pub(super) fn shadow_bind_group(
        &self,
        device: &wgpu::Device,
        objects: &wgpu::Buffer,
        matrices: &wgpu::Buffer,
    ) -> wgpu::BindGroup {
        device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("preview shadow"),
            layout: &self.shadow_layout,
            entries: &[
                wgpu::BindGroupEntry {
                    binding: 1,
                    resource: objects.as_entire_binding(),
                },
                wgpu::BindGroupEntry {
                    binding: 2,
                    resource: matrices.as_entire_binding(),
                },
            ],
        })
    }
}

pub(super) fn objects_buffer(device: &wgpu::Device, capacity: usize) -> wgpu::Buffer {
    device.create_buffer(&wgpu::BufferDescriptor {
        label: Some("preview objects"),
        size: (capacity.max(1) * std::mem::size_of::<PreviewObject>()) as u64,
        usage: wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_DST,
        mapped_at_creation: false,
    })
}

/// The shadow-map layers' views: a uniform array of `MAX_SHADOW_LAYERS` matrices.
pub(super) fn matrices_buffer(device: &wgpu::Device) -> wgpu::Buffer {
    device.create_buffer(&wgpu::BufferDescriptor {
        label: Some("preview shadow views"),
        size: (super::shadows::MAX_SHADOW_LAYERS * 64) as u64,
        usage: wgpu::BufferUsages::UNIFORM | wgpu::BufferUsages::COPY_DST,
        mapped_at_creation: false,
    })
}

/// The view's, the shadow pass's and a material's images' bind group layouts.
fn bind_group_layouts(device: &wgpu::Device) -> [wgpu::BindGroupLayout; 3] {
    let vf = wgpu::ShaderStages::VERTEX_FRAGMENT;
    let storage = wgpu::BufferBindingType::Storage { read_only: true };
    let float = wgpu::TextureSampleType::Float { filterable: true };
    let d2 = wgpu::TextureViewDimension::D2;
    let d2_array = wgpu::TextureViewDimension::D2Array;
    let view_layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
        label: Some("preview view"),
        entries: &[
            buffer_entry(0, vf, wgpu::BufferBindingType::Uniform),
            buffer_entry(1, vf, storage),
            buffer_entry(2, vf, wgpu::BufferBindingType::Uniform),
            texture_entry(3, wgpu::TextureSampleType::Depth, d2_array),
            sampler_entry(4, wgpu::SamplerBindingType::Comparison),
            texture_entry(5, float, d2),
            texture_entry(6, float, d2_array),
            texture_entry(7, float, d2),
            sampler_entry(8, wgpu::SamplerBindingType::Filtering),
            texture_entry(9, float, wgpu::TextureViewDimension::D3),
            texture_entry(10, float, wgpu::TextureViewDimension::D3),
            // The frame behind solid glass (`behind.rs`), read texel by texel.
            texture_entry(11, float, d2),
            texture_entry(12, wgpu::TextureSampleType::Depth, d2),
        ],
    });
    // The shadow pass binds only what its vertex stage reads: the maps it draws into cannot
    // be bound at the same time.
    let vertex = wgpu::ShaderStages::VERTEX;
    let shadow_layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
        label: Some("preview shadow"),
        entries: &[
            buffer_entry(1, vertex, storage),
            buffer_entry(2, vertex, wgpu::BufferBindingType::Uniform),
        ],
    });
    let texture_layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
        label: Some("preview material images"),
        entries: &[
            texture_entry(0, float, d2),
            sampler_entry(1, wgpu::SamplerBindingType::Filtering),
            texture_entry(2, float, d2),
            texture_entry(3, float, d2),
            texture_entry(4, float, d2),
        ],
    });
    [view_layout, shadow_layout, texture_layout]
}

/// The opaque and blended meshes, the background and the grid, over the view's and a material's
/// bindings.
fn draw_pipelines(
    device: &wgpu::Device,
    module: &wgpu::ShaderModule,
    [view_layout, texture_layout]: [&wgpu::BindGroupLayout; 2],
) -> DrawPipelines {
    let mesh_layout = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
        label: Some("preview mesh"),
        bind_group_layouts: &[Some(view_layout), Some(texture_layout)],
        immediate_size: 0,
    });
    let depth = |write: bool| {
        Some(wgpu::DepthStencilState {
            format: DEPTH_FORMAT,
            depth_write_enabled: Some(write),
            depth_compare: Some(wgpu::CompareFunction::LessEqual),
            stencil: wgpu::StencilState::default(),
            bias: wgpu::DepthBiasState::default(),
        })
    };
    let mesh_buffers = [Some(mesh_buffer())];
    let grid_attributes = wgpu::vertex_attr_array![0 => Float32x3, 1 => Float32x4];
    let grid_buffers = [Some(wgpu::VertexBufferLayout {
        array_stride: std::mem::size_of::<GridVertex>() as u64,
        step_mode: wgpu::VertexStepMode::Vertex,
        attributes: &grid_attributes,
    })];
    let pipeline = |label: &str,
                    (vs, fs): (&str, &str),
                    buffers: &[Option<wgpu::VertexBufferLayout>],
                    topology: wgpu::PrimitiveTopology,
                    depth_write: bool,
                    blend: Option<wgpu::BlendState>| {
        device.create_render_pipeline(&wgpu::RenderPipelineDescriptor {
            label: Some(label),
            layout: Some(&mesh_layout),
            vertex: wgpu::VertexState {
                module,
                entry_point: Some(vs),
                compilation_options: Default::default(),
                buffers,
            },
            primitive: wgpu::PrimitiveState {
                topology,
                ..Default::default()
            },
            depth_stencil: depth(depth_write),
            multisample: wgpu::MultisampleState::default(),
            fragment: Some(wgpu::FragmentState {
                module,
                entry_point: Some(fs),
                compilation_options: Default::default(),
                targets: &[Some(wgpu::ColorTargetState {
                    format: COLOR_FORMAT,
                    blend,
                    write_mask: wgpu::ColorWrites::ALL,
                })],
            }),
            multiview_mask: None,
            cache: None,
        })
    };
    let triangles = wgpu::PrimitiveTopology::TriangleList;
    let mesh = ("vs_mesh", "fs_mesh");
    let opaque = pipeline("preview opaque", mesh, &mesh_buffers, triangles, true, None);
    // Solid glass and smooth metals, drawn as opaque over a copy of the frame, which they read.
    let reading = pipeline(
        "preview reading",
        ("vs_mesh", "fs_reading"),
        &mesh_buffers,
        triangles,
        true,
        None,
    );
    // Blended surfaces test depth but leave none: what lies behind them stays drawable.
    let blended = pipeline(
        "preview blended",
        mesh,
        &mesh_buffers,
        triangles,
        false,
        Some(PREMULTIPLIED),
    );
    let background = pipeline(
        "preview background",
        ("vs_background", "fs_background"),
        &[],
        triangles,
        false,
        None,
    );
    // Faded lines would hide each other if they left depth.
    let grid = pipeline(
        "preview grid",
        ("vs_grid", "fs_grid"),
        &grid_buffers,
        wgpu::PrimitiveTopology::LineList,
        false,
        Some(PREMULTIPLIED),
    );
    DrawPipelines {
        opaque,
        reading,
        blended,
        background,
        grid,
    }
}

/// The shadow maps' depth-only pipeline.
fn shadow_pipeline(
    device: &wgpu::Device,
    module: &wgpu::ShaderModule,
    shadow_layout: &wgpu::BindGroupLayout,
) -> wgpu::RenderPipeline {
    let shadow_pipeline_layout = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
        label: Some("preview shadow"),
        bind_group_layouts: &[Some(shadow_layout)],
        immediate_size: 0,
    });
    device.create_render_pipeline(&wgpu::RenderPipelineDescriptor {
        label: Some("preview shadow"),
        layout: Some(&shadow_pipeline_layout),
        vertex: wgpu::VertexState {
            module,
            entry_point: Some("vs_shadow"),
            compilation_options: Default::default(),
            buffers: &[Some(mesh_buffer())],
        },
        primitive: wgpu::PrimitiveState::default(),
        depth_stencil: Some(wgpu::DepthStencilState {
            format: DEPTH_FORMAT,
            depth_write_enabled: Some(true),
            depth_compare: Some(wgpu::CompareFunction::LessEqual),
            stencil: wgpu::StencilState::default(),
            // Slope-scaled: surfaces at a grazing angle to the light do not shadow themselves.
            bias: wgpu::DepthBiasState {
                constant: 2,
                slope_scale: 2.0,
                clamp: 0.0,
            },
        }),
        multisample: wgpu::MultisampleState::default(),
        fragment: None,
        multiview_mask: None,
        cache: None,
    })
}

/// The material images' sampler, the environment's (clamped at the poles) and the shadow maps'
/// comparison sampler.
fn samplers(device: &wgpu::Device) -> [wgpu::Sampler; 3] {
    let linear = |label, (u, v), compare| {
        device.create_sampler(&wgpu::SamplerDescriptor {
            label: Some(label),
            address_mode_u: u,
            address_mode_v: v,
            mag_filter: wgpu::FilterMode::Linear,
            min_filter: wgpu::FilterMode::Linear,
            compare,
            ..Default::default()
        })
    };
    let (repeat, clamp) = (wgpu::AddressMode::Repeat, wgpu::AddressMode::ClampToEdge);
    let sampler = linear("preview", (repeat, repeat), None);
    // The environment wraps around in u and stops at the poles. The BRDF table and the
    // irradiance volume share it: their lookups keep within their texels' centres.
    let clamped = linear("preview environment", (repeat, clamp), None);
    let shadow_sampler = linear(
        "preview shadow",
        (clamp, clamp),
        Some(wgpu::CompareFunction::LessEqual),
    );
    [sampler, clamped, shadow_sampler]
}
