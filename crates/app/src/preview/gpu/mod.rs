//! GPU resources of the preview, kept in `egui_wgpu`'s callback resources so they are created once:
//! pipelines, per-mesh and per-texture buffers (cached by the `Arc` they come from), and an
//! offscreen colour + depth target sized to the viewport. Here: the resources and the per-frame
//! upload and drawing; `pipelines.rs` creates them, `cache.rs` keeps the mesh and texture copies.

mod cache;
mod pipelines;

use std::collections::HashMap;
use std::sync::Arc;

use wgpu::util::DeviceExt;

use super::PreviewFrame;
use super::types::PreviewObject;
use cache::{CachedMesh, CachedTexture};
use pipelines::{objects_buffer, view_bind_group};

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

impl PreviewResources {
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
        self.update_caches(device, queue, frame, now);

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
