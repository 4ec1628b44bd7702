//! The selection outline, as Blender and most editors draw it: the selected object's visible
//! pixels are drawn into a mask (its mesh again, depth-tested against the frame's depth, which
//! the mesh vertex shader reproduces exactly: its position is `@invariant`), then every pixel
//! within two pixels of the mask but outside it turns orange. The object's own shading is left as
//! it is, so the material being edited stays visible.

use super::{COLOR_FORMAT, DEPTH_FORMAT};

/// The mask's format: one channel, 1 on the selection.
const MASK_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::R8Unorm;

pub(super) struct Outline {
    mask_pipeline: wgpu::RenderPipeline,
    outline_pipeline: wgpu::RenderPipeline,
    layout: wgpu::BindGroupLayout,
    sampler: wgpu::Sampler,
}

/// A target's mask and the outline pass's binding of it.
pub(super) struct Mask {
    view: wgpu::TextureView,
    bind_group: wgpu::BindGroup,
}

/// The binding of one filterable 2D image and its sampler that `preview_blit.wgsl`'s entry points
/// read (the editor's blit of the preview's image and the outline's mask).
pub fn image_layout(device: &wgpu::Device, label: &str) -> wgpu::BindGroupLayout {
    device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
        label: Some(label),
        entries: &[
            wgpu::BindGroupLayoutEntry {
                binding: 0,
                visibility: wgpu::ShaderStages::FRAGMENT,
                ty: wgpu::BindingType::Texture {
                    sample_type: wgpu::TextureSampleType::Float { filterable: true },
                    view_dimension: wgpu::TextureViewDimension::D2,
                    multisampled: false,
                },
                count: None,
            },
            wgpu::BindGroupLayoutEntry {
                binding: 1,
                visibility: wgpu::ShaderStages::FRAGMENT,
                ty: wgpu::BindingType::Sampler(wgpu::SamplerBindingType::Filtering),
                count: None,
            },
        ],
    })
}

impl Outline {
    pub(super) fn new(
        device: &wgpu::Device,
        preview: &wgpu::ShaderModule,
        [view_layout, texture_layout]: [&wgpu::BindGroupLayout; 2],
        mesh_buffer: wgpu::VertexBufferLayout<'_>,
    ) -> Self {
        let mesh_layout = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
            label: Some("preview selection mask"),
            bind_group_layouts: &[Some(view_layout), Some(texture_layout)],
            immediate_size: 0,
        });
        let mask_pipeline = device.create_render_pipeline(&wgpu::RenderPipelineDescriptor {
            label: Some("preview selection mask"),
            layout: Some(&mesh_layout),
            vertex: wgpu::VertexState {
                module: preview,
                entry_point: Some("vs_mesh"),
                compilation_options: Default::default(),
                buffers: &[Some(mesh_buffer)],
            },
            primitive: wgpu::PrimitiveState::default(),
            // The frame's depth, kept: only the selection's visible pixels pass.
            depth_stencil: Some(wgpu::DepthStencilState {
                format: DEPTH_FORMAT,
                depth_write_enabled: Some(false),
                depth_compare: Some(wgpu::CompareFunction::LessEqual),
                stencil: wgpu::StencilState::default(),
                bias: wgpu::DepthBiasState::default(),
            }),
            multisample: wgpu::MultisampleState::default(),
            fragment: Some(wgpu::FragmentState {
                module: preview,
                entry_point: Some("fs_mask"),
                compilation_options: Default::default(),
                targets: &[Some(MASK_FORMAT.into())],
            }),
            multiview_mask: None,
            cache: None,
        });
        let blit = device.create_shader_module(wgpu::ShaderModuleDescriptor {
            label: Some("preview outline"),
            source: wgpu::ShaderSource::Wgsl(rt_gpu::shaders::PREVIEW_BLIT.source().into()),
        });
        let layout = image_layout(device, "preview outline");
        let outline_layout = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
            label: Some("preview outline"),
            bind_group_layouts: &[Some(&layout)],
            immediate_size: 0,
        });
        let outline_pipeline = device.create_render_pipeline(&wgpu::RenderPipelineDescriptor {
            label: Some("preview outline"),
            layout: Some(&outline_layout),
            vertex: wgpu::VertexState {
                module: &blit,
                entry_point: Some("vs_blit"),
                compilation_options: Default::default(),
                buffers: &[],
            },
            primitive: wgpu::PrimitiveState::default(),
            depth_stencil: None,
            multisample: wgpu::MultisampleState::default(),
            fragment: Some(wgpu::FragmentState {
                module: &blit,
                entry_point: Some("fs_outline"),
                compilation_options: Default::default(),
                targets: &[Some(wgpu::ColorTargetState {
                    format: COLOR_FORMAT,
                    blend: Some(wgpu::BlendState::ALPHA_BLENDING),
                    write_mask: wgpu::ColorWrites::ALL,
                })],
            }),
            multiview_mask: None,
            cache: None,
        });
        let sampler = device.create_sampler(&wgpu::SamplerDescriptor {
            label: Some("preview outline"),
            ..Default::default()
        });
        Outline {
            mask_pipeline,
            outline_pipeline,
            layout,
            sampler,
        }
    }

    /// A mask for a target of `size`.
    pub(super) fn mask(&self, device: &wgpu::Device, size: [u32; 2]) -> Mask {
        let usage = wgpu::TextureUsages::RENDER_ATTACHMENT | wgpu::TextureUsages::TEXTURE_BINDING;
        let view =
            super::target_texture(device, "preview selection mask", size, MASK_FORMAT, usage)
                .create_view(&Default::default());
        let bind_group = device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("preview outline"),
            layout: &self.layout,
            entries: &[
                wgpu::BindGroupEntry {
                    binding: 0,
                    resource: wgpu::BindingResource::TextureView(&view),
                },
                wgpu::BindGroupEntry {
                    binding: 1,
                    resource: wgpu::BindingResource::Sampler(&self.sampler),
                },
            ],
        });
        Mask { view, bind_group }
    }

    /// Draws the selection's mask (`draw_selected` draws its meshes with the mask pipeline set),
    /// then its outline over `color`.
    pub(super) fn draw(
        &self,
        encoder: &mut wgpu::CommandEncoder,
        mask: &Mask,
        [color, depth]: [&wgpu::TextureView; 2],
        draw_selected: impl FnOnce(&mut wgpu::RenderPass<'_>),
    ) {
        {
            let mut pass = encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
                label: Some("preview selection mask"),
                color_attachments: &[Some(wgpu::RenderPassColorAttachment {
                    view: &mask.view,
                    depth_slice: None,
                    resolve_target: None,
                    ops: wgpu::Operations {
                        load: wgpu::LoadOp::Clear(wgpu::Color::TRANSPARENT),
                        store: wgpu::StoreOp::Store,
                    },
                })],
                depth_stencil_attachment: Some(wgpu::RenderPassDepthStencilAttachment {
                    view: depth,
                    depth_ops: Some(wgpu::Operations {
                        load: wgpu::LoadOp::Load,
                        store: wgpu::StoreOp::Discard,
                    }),
                    stencil_ops: None,
                }),
                timestamp_writes: None,
                occlusion_query_set: None,
                multiview_mask: None,
            });
            pass.set_pipeline(&self.mask_pipeline);
            draw_selected(&mut pass);
        }
        let mut pass = encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
            label: Some("preview outline"),
            color_attachments: &[Some(wgpu::RenderPassColorAttachment {
                view: color,
                depth_slice: None,
                resolve_target: None,
                ops: wgpu::Operations {
                    load: wgpu::LoadOp::Load,
                    store: wgpu::StoreOp::Store,
                },
            })],
            depth_stencil_attachment: None,
            timestamp_writes: None,
            occlusion_query_set: None,
            multiview_mask: None,
        });
        pass.set_pipeline(&self.outline_pipeline);
        pass.set_bind_group(0, &mask.bind_group, &[]);
        pass.draw(0..3, 0..1);
    }
}
