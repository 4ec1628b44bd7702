//! The raster preview in the editor: `rt_preview`'s renderer kept in `egui_wgpu`'s callback
//! resources, drawing each frame offscreen (linear radiance), then a blit that shows it in egui's
//! pass through the path-traced view's display (the standard view at exposure 0, sRGB), so that
//! both views show the same radiance the same way.

use std::sync::Arc;

use rt_preview::PreviewRenderer;
pub use rt_preview::{PreviewFrame, build_interactive_frame, grid_step};

pub struct PreviewResources {
    renderer: PreviewRenderer,
    blit_pipeline: wgpu::RenderPipeline,
    blit_layout: wgpu::BindGroupLayout,
    sampler: wgpu::Sampler,
    /// The blit's binding of the renderer's target, rebuilt when the target is.
    blit: Option<(wgpu::TextureView, wgpu::BindGroup)>,
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
    fn new(device: &wgpu::Device, queue: &wgpu::Queue, target_format: wgpu::TextureFormat) -> Self {
        let module = device.create_shader_module(wgpu::ShaderModuleDescriptor {
            label: Some("preview blit"),
            source: wgpu::ShaderSource::Wgsl(rt_gpu::shaders::PREVIEW_BLIT.source().into()),
        });
        let blit_layout = rt_preview::image_layout(device, "preview blit");
        let layout = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
            label: Some("preview blit"),
            bind_group_layouts: &[Some(&blit_layout)],
            immediate_size: 0,
        });
        let srgb_target = [(
            "TARGET_IS_SRGB",
            if target_format.is_srgb() { 1.0 } else { 0.0 },
        )];
        let blit_pipeline = device.create_render_pipeline(&wgpu::RenderPipelineDescriptor {
            label: Some("preview blit"),
            layout: Some(&layout),
            vertex: wgpu::VertexState {
                module: &module,
                entry_point: Some("vs_blit"),
                compilation_options: Default::default(),
                buffers: &[],
            },
            primitive: wgpu::PrimitiveState::default(),
            depth_stencil: None,
            multisample: wgpu::MultisampleState::default(),
            fragment: Some(wgpu::FragmentState {
                module: &module,
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
            label: Some("preview blit"),
            mag_filter: wgpu::FilterMode::Linear,
            min_filter: wgpu::FilterMode::Linear,
            ..Default::default()
        });
        PreviewResources {
            renderer: PreviewRenderer::new(device, queue),
            blit_pipeline,
            blit_layout,
            sampler,
            blit: None,
        }
    }

    fn render(
        &mut self,
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        encoder: &mut wgpu::CommandEncoder,
        frame: &PreviewFrame,
    ) {
        self.renderer.render(device, queue, encoder, frame);
        let Some(target) = self.renderer.target_view() else {
            return;
        };
        if self.blit.as_ref().is_none_or(|(view, _)| view != target) {
            let bind_group = device.create_bind_group(&wgpu::BindGroupDescriptor {
                label: Some("preview blit"),
                layout: &self.blit_layout,
                entries: &[
                    wgpu::BindGroupEntry {
                        binding: 0,
                        resource: wgpu::BindingResource::TextureView(target),
                    },
                    wgpu::BindGroupEntry {
                        binding: 1,
                        resource: wgpu::BindingResource::Sampler(&self.sampler),
                    },
                ],
            });
            self.blit = Some((target.clone(), bind_group));
        }
    }

    /// Copies the offscreen image into egui's pass (whose viewport egui has set to our rect).
    fn paint(&self, pass: &mut wgpu::RenderPass<'static>) {
        if let Some((_, bind_group)) = &self.blit {
            pass.set_pipeline(&self.blit_pipeline);
            pass.set_bind_group(0, bind_group, &[]);
            pass.draw(0..3, 0..1);
        }
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
