//! The raster preview, shared by the editor's first view and `rt-cli preview`: what to draw
//! ([`PreviewFrame`], built from the scene by [`build_frame`]) and the renderer that draws it
//! ([`PreviewRenderer`]) into an offscreen target of linear radiance, which the caller shows
//! through the render's view transform (the editor's blit, or `rt_core::output` for a file).
//!
//! Per frame: the shadow maps when an object or light moved (`shadows.rs`), the prefiltered
//! environment when it changed (`environment.rs`), the irradiance volume when the geometry,
//! materials or lights changed (`bounce.rs`), then the opaque objects, the environment behind
//! them and the ground grid; solid glass and smooth metals over a copy of those (`behind.rs`);
//! the blended objects (thin transmitting sheets, alpha) over them all. The shading is `shaders/preview*.wgsl`'s.

mod behind;
pub mod bounce;
mod cache;
pub mod environment;
mod frame;
mod outline;
pub use outline::image_layout;
mod pipelines;
mod probe_textures;
mod probes;
pub mod shadows;
pub mod sun;
mod surfaces;
pub mod types;
mod volume_cache;

use std::collections::HashMap;
use std::sync::Arc;

use wgpu::util::DeviceExt;

use behind::Layer;
use cache::{CachedBinding, CachedMesh, CachedTexture};
pub use frame::{
    MaterialTextures, PreviewEnvironment, PreviewFrame, TextureRef, build_frame,
    build_interactive_frame, grid_lines, grid_step, view_projection,
};
use pipelines::Pipelines;
use probe_textures::{ProbeTexture, probe_texture};
use rt_gpu::GpuContext;
use rt_gpu::{GpuError, Result};

/// The target's format: linear radiance, blendable and filterable everywhere.
pub const COLOR_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Rgba16Float;
const DEPTH_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Depth32Float;

struct Target {
    size: [u32; 2],
    color_texture: wgpu::Texture,
    color: wgpu::TextureView,
    depth_texture: wgpu::Texture,
    depth: wgpu::TextureView,
    /// The frame as drawn before solid glass and smooth metals, which they read (`behind.rs`).
    behind: behind::Behind,
    /// The selection's mask (`outline.rs`).
    mask: outline::Mask,
}

/// The shadow maps: one depth layer per view of `ShadowPlan`, and the key they were drawn for.
struct ShadowMaps {
    layers: u32,
    array: wgpu::TextureView,
    layer_views: Vec<wgpu::TextureView>,
    key: Option<u64>,
}

struct EnvironmentTextures {
    key: u64,
    sharp: wgpu::TextureView,
    blur: wgpu::TextureView,
}

/// A 2D image of `size` for the offscreen target (colour, depth, the selection's mask).
fn target_texture(
    device: &wgpu::Device,
    label: &str,
    size: [u32; 2],
    format: wgpu::TextureFormat,
    usage: wgpu::TextureUsages,
) -> wgpu::Texture {
    device.create_texture(&wgpu::TextureDescriptor {
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
}

/// The preview's GPU resources, created once per device: pipelines, the view and objects buffers,
/// cached copies of meshes and textures (by the `Arc` they come from), shadow maps, the prefiltered
/// environment and the offscreen target, sized to the last frame.
pub struct PreviewRenderer {
    pipelines: Pipelines,
    view_buffer: wgpu::Buffer,
    objects_buffer: wgpu::Buffer,
    objects_capacity: usize,
    matrices_buffer: wgpu::Buffer,
    shadow_bind_group: wgpu::BindGroup,
    view_bind_group: Option<wgpu::BindGroup>,
    /// Each texture slot's neutral image (white, or a flat normal), and a binding of all four.
    defaults: [wgpu::TextureView; 4],
    white: wgpu::BindGroup,
    brdf: wgpu::TextureView,
    meshes: HashMap<usize, CachedMesh>,
    textures: HashMap<usize, CachedTexture>,
    bindings: HashMap<[usize; 4], CachedBinding>,
    shadow_maps: ShadowMaps,
    environment: Option<EnvironmentTextures>,
    probes: Option<ProbeTexture>,
    target: Option<Target>,
    frame: u64,
}

fn texture_2d(
    device: &wgpu::Device,
    queue: &wgpu::Queue,
    label: &str,
    [width, height, layers]: [u32; 3],
    texels: &[[f32; 3]],
) -> wgpu::TextureView {
    let data: Vec<half::f16> = texels
        .iter()
        .flat_map(|t| [t[0], t[1], t[2], 1.0])
        .map(|c| half::f16::from_f32(c.min(65000.0)))
        .collect();
    let texture = device.create_texture_with_data(
        queue,
        &wgpu::TextureDescriptor {
            label: Some(label),
            size: wgpu::Extent3d {
                width,
                height,
                depth_or_array_layers: layers,
            },
            mip_level_count: 1,
            sample_count: 1,
            dimension: wgpu::TextureDimension::D2,
            format: wgpu::TextureFormat::Rgba16Float,
            usage: wgpu::TextureUsages::TEXTURE_BINDING | wgpu::TextureUsages::COPY_DST,
            view_formats: &[],
        },
        wgpu::util::TextureDataOrder::LayerMajor,
        bytemuck::cast_slice(&data),
    );
    texture.create_view(&wgpu::TextureViewDescriptor {
        dimension: Some(if layers > 1 {
            wgpu::TextureViewDimension::D2Array
        } else {
            wgpu::TextureViewDimension::D2
        }),
        ..Default::default()
    })
}

fn shadow_maps(device: &wgpu::Device, layers: u32) -> ShadowMaps {
    let layers = layers.max(1);
    let texture = device.create_texture(&wgpu::TextureDescriptor {
        label: Some("preview shadow maps"),
        size: wgpu::Extent3d {
            width: shadows::SHADOW_SIZE,
            height: shadows::SHADOW_SIZE,
            depth_or_array_layers: layers,
        },
        mip_level_count: 1,
        sample_count: 1,
        dimension: wgpu::TextureDimension::D2,
        format: DEPTH_FORMAT,
        usage: wgpu::TextureUsages::RENDER_ATTACHMENT | wgpu::TextureUsages::TEXTURE_BINDING,
        view_formats: &[],
    });
    let array = texture.create_view(&wgpu::TextureViewDescriptor {
        dimension: Some(wgpu::TextureViewDimension::D2Array),
        ..Default::default()
    });
    let layer_views = (0..layers)
        .map(|layer| {
            texture.create_view(&wgpu::TextureViewDescriptor {
                dimension: Some(wgpu::TextureViewDimension::D2),
                base_array_layer: layer,
                array_layer_count: Some(1),
                ..Default::default()
            })
        })
        .collect();
    ShadowMaps {
        layers,
        array,
        layer_views,
        key: None,
    }
}

impl PreviewRenderer {
    pub fn new(device: &wgpu::Device, queue: &wgpu::Queue) -> Self {
        let pipelines = Pipelines::new(device);
        let view_buffer = device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("preview view"),
            size: std::mem::size_of::<types::PreviewView>() as u64,
            usage: wgpu::BufferUsages::UNIFORM | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        let objects_capacity = 16;
        let objects_buffer = pipelines::objects_buffer(device, objects_capacity);
        let matrices_buffer = pipelines::matrices_buffer(device);
        let shadow_bind_group =
            pipelines.shadow_bind_group(device, &objects_buffer, &matrices_buffer);
        let defaults: [wgpu::TextureView; 4] = std::array::from_fn(|slot| {
            let texel = if slot == 2 {
                [128, 128, 255, 255]
            } else {
                [255; 4]
            };
            cache::upload_texture(device, queue, &texel, [1, 1], cache::SRGB_SLOTS[slot])
        });
        let white = pipelines.texture_bind_group(device, std::array::from_fn(|s| &defaults[s]));
        let side = environment::BRDF_TABLE_SIDE as u32;
        let brdf_texels: Vec<[f32; 3]> = environment::brdf_table()
            .iter()
            .zip(rt_core::math::sheen::sheen_table())
            .map(|(&[a, b], &sheen)| [a, b, sheen])
            .collect();
        let brdf = texture_2d(device, queue, "preview brdf", [side, side, 1], &brdf_texels);
        PreviewRenderer {
            pipelines,
            view_buffer,
            objects_buffer,
            objects_capacity,
            matrices_buffer,
            shadow_bind_group,
            view_bind_group: None,
            defaults,
            white,
            brdf,
            meshes: HashMap::new(),
            textures: HashMap::new(),
            bindings: HashMap::new(),
            shadow_maps: shadow_maps(device, 1),
            environment: None,
            probes: None,
            target: None,
            frame: 0,
        }
    }

    /// The last frame's image (linear radiance in `COLOR_FORMAT`).
    pub fn target_view(&self) -> Option<&wgpu::TextureView> {
        self.target.as_ref().map(|t| &t.color)
    }

    /// Records the drawing of `frame` into the offscreen target.
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
        self.upload(device, queue, frame);
        self.update_caches(device, queue, frame, now);
        self.draw_shadows(encoder, frame);
        let (Some(target), Some(view_bind_group)) = (&self.target, &self.view_bind_group) else {
            return;
        };
        let grid = (!frame.grid.is_empty()).then(|| {
            device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
                label: Some("preview grid"),
                contents: bytemuck::cast_slice(&frame.grid),
                usage: wgpu::BufferUsages::VERTEX,
            })
        });
        let reading = (0..frame.meshes.len()).any(|i| behind::layer(frame, i) == Layer::Reading);
        let mut pass = main_pass(encoder, target, true);
        pass.set_bind_group(0, view_bind_group, &[]);
        pass.set_pipeline(&self.pipelines.opaque);
        self.draw_meshes(&mut pass, frame, Layer::Opaque);
        pass.set_pipeline(&self.pipelines.background);
        pass.draw(0..3, 0..1);
        if let Some(grid) = &grid {
            pass.set_pipeline(&self.pipelines.grid);
            pass.set_bind_group(1, &self.white, &[]);
            pass.set_vertex_buffer(0, grid.slice(..));
            pass.draw(0..frame.grid.len() as u32, 0..1);
        }
        if reading {
            // Glass and mirrors read what was drawn before them: the pass ends for the copy.
            drop(pass);
            let (color, depth) = (&target.color_texture, &target.depth_texture);
            target.behind.copy_from(encoder, color, depth);
            pass = main_pass(encoder, target, false);
            pass.set_bind_group(0, view_bind_group, &[]);
            pass.set_pipeline(&self.pipelines.reading);
            self.draw_meshes(&mut pass, frame, Layer::Reading);
        }
        pass.set_pipeline(&self.pipelines.blended);
        self.draw_meshes(&mut pass, frame, Layer::Blended);
        drop(pass);
        if frame.objects.iter().any(|o| o.flags[0] != 0) {
            let views = [&target.color, &target.depth];
            self.pipelines
                .outline
                .draw(encoder, &target.mask, views, |pass| {
                    pass.set_bind_group(0, view_bind_group, &[]);
                    pass.set_bind_group(1, &self.white, &[]);
                    self.draw_selected(pass, frame);
                });
        }
    }

    /// Draws the selected objects' meshes (the pipeline and bindings set by the caller).
    fn draw_selected(&self, pass: &mut wgpu::RenderPass<'_>, frame: &PreviewFrame) {
        for (i, mesh) in frame.meshes.iter().enumerate() {
            if frame.objects.get(i).is_none_or(|o| o.flags[0] == 0) {
                continue;
            }
            let Some(cached) = self.meshes.get(&(Arc::as_ptr(mesh) as usize)) else {
                continue;
            };
            pass.set_vertex_buffer(0, cached.vertices.slice(..));
            pass.set_index_buffer(cached.indices.slice(..), wgpu::IndexFormat::Uint32);
            let instance = i as u32;
            pass.draw_indexed(0..cached.index_count, 0, instance..instance + 1);
        }
    }

    /// Draws `frame` and waits until the GPU has finished it (what a frame costs, for benchmarks).
    pub fn draw_and_wait(&mut self, ctx: &GpuContext, frame: &PreviewFrame) -> Result<()> {
        ctx.scoped(|| {
            let mut encoder = ctx.device.create_command_encoder(&Default::default());
            self.render(&ctx.device, &ctx.queue, &mut encoder, frame);
            ctx.queue.submit([encoder.finish()]);
        })?;
        ctx.device
            .poll(wgpu::PollType::wait_indefinitely())
            .map_err(|e| GpuError::Wgpu(e.to_string()))?;
        Ok(())
    }

    fn draw_meshes(&self, pass: &mut wgpu::RenderPass<'_>, frame: &PreviewFrame, layer: Layer) {
        for (i, mesh) in frame.meshes.iter().enumerate() {
            if behind::layer(frame, i) != layer {
                continue;
            }
            let Some(cached) = self.meshes.get(&(Arc::as_ptr(mesh) as usize)) else {
                continue;
            };
            if cached.index_count == 0 {
                continue;
            }
            let texture = frame
                .textures
                .get(i)
                .and_then(|t| self.bindings.get(&cache::binding_key(t)))
                .map_or(&self.white, |b| &b.bind_group);
            pass.set_bind_group(1, texture, &[]);
            pass.set_vertex_buffer(0, cached.vertices.slice(..));
            pass.set_index_buffer(cached.indices.slice(..), wgpu::IndexFormat::Uint32);
            let instance = i as u32;
            pass.draw_indexed(0..cached.index_count, 0, instance..instance + 1);
        }
    }

    /// Draws the shadow maps again when what they show changed.
    fn draw_shadows(&mut self, encoder: &mut wgpu::CommandEncoder, frame: &PreviewFrame) {
        let plan = &frame.shadows;
        if plan.matrices.is_empty() || self.shadow_maps.key == Some(plan.key) {
            return;
        }
        self.shadow_maps.key = Some(plan.key);
        let capacity = self.objects_capacity as u32;
        for (layer, view) in self
            .shadow_maps
            .layer_views
            .iter()
            .enumerate()
            .take(plan.matrices.len())
        {
            let mut pass = encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
                label: Some("preview shadow map"),
                color_attachments: &[],
                depth_stencil_attachment: Some(wgpu::RenderPassDepthStencilAttachment {
                    view,
                    depth_ops: Some(wgpu::Operations {
                        load: wgpu::LoadOp::Clear(1.0),
                        store: wgpu::StoreOp::Store,
                    }),
                    stencil_ops: None,
                }),
                timestamp_writes: None,
                occlusion_query_set: None,
                multiview_mask: None,
            });
            pass.set_pipeline(&self.pipelines.shadow);
            pass.set_bind_group(0, &self.shadow_bind_group, &[]);
            for (i, mesh) in frame.meshes.iter().enumerate() {
                if plan.skip[layer] == i as u32 + 1 {
                    continue;
                }
                let Some(cached) = self.meshes.get(&(Arc::as_ptr(mesh) as usize)) else {
                    continue;
                };
                if cached.index_count == 0 {
                    continue;
                }
                pass.set_vertex_buffer(0, cached.vertices.slice(..));
                pass.set_index_buffer(cached.indices.slice(..), wgpu::IndexFormat::Uint32);
                let instance = layer as u32 * capacity + i as u32;
                pass.draw_indexed(0..cached.index_count, 0, instance..instance + 1);
            }
        }
    }

    /// Writes the frame's uniforms and objects, growing buffers and rebuilding the bindings (shadow
    /// maps, environment) that changed.
    fn upload(&mut self, device: &wgpu::Device, queue: &wgpu::Queue, frame: &PreviewFrame) {
        let mut rebind = self.view_bind_group.is_none();
        if frame.objects.len() > self.objects_capacity {
            self.objects_capacity = frame.objects.len().next_power_of_two();
            self.objects_buffer = pipelines::objects_buffer(device, self.objects_capacity);
            self.shadow_maps.key = None;
            rebind = true;
        }
        let layers = frame.shadows.matrices.len() as u32;
        if layers > self.shadow_maps.layers {
            self.shadow_maps = shadow_maps(device, layers);
            rebind = true;
        }
        if self
            .environment
            .as_ref()
            .is_none_or(|e| e.key != frame.environment.key)
        {
            let prefiltered = environment::prefilter(&frame.environment);
            let sharp = &prefiltered.sharp;
            let first = &prefiltered.blur[0];
            let blur: Vec<[f32; 3]> = prefiltered
                .blur
                .iter()
                .flat_map(|l| l.texels.iter().copied())
                .collect();
            let layers = prefiltered.blur.len() as u32;
            self.environment = Some(EnvironmentTextures {
                key: frame.environment.key,
                sharp: texture_2d(
                    device,
                    queue,
                    "preview environment",
                    [sharp.width, sharp.height, 1],
                    &sharp.texels,
                ),
                blur: texture_2d(
                    device,
                    queue,
                    "preview environment prefiltered",
                    [first.width, first.height, layers],
                    &blur,
                ),
            });
            rebind = true;
        }
        if self
            .probes
            .as_ref()
            .is_none_or(|p| !Arc::ptr_eq(&p.volume, &frame.volume))
        {
            self.probes = Some(probe_texture(device, queue, &frame.volume));
            rebind = true;
        }
        if rebind {
            self.shadow_bind_group = self.pipelines.shadow_bind_group(
                device,
                &self.objects_buffer,
                &self.matrices_buffer,
            );
            if let (Some(env), Some(probes), Some(target)) =
                (&self.environment, &self.probes, &self.target)
            {
                self.view_bind_group = Some(self.pipelines.view_bind_group(
                    device,
                    [
                        &self.view_buffer,
                        &self.objects_buffer,
                        &self.matrices_buffer,
                    ],
                    &self.shadow_maps.array,
                    [
                        &env.sharp,
                        &env.blur,
                        &self.brdf,
                        &probes.view,
                        &probes.radiance,
                        &target.behind.color,
                        &target.behind.depth,
                    ],
                ));
            }
        }
        queue.write_buffer(&self.view_buffer, 0, bytemuck::bytes_of(&frame.view));
        if !frame.objects.is_empty() {
            queue.write_buffer(
                &self.objects_buffer,
                0,
                bytemuck::cast_slice(&frame.objects),
            );
        }
        if !frame.shadows.matrices.is_empty() {
            queue.write_buffer(
                &self.matrices_buffer,
                0,
                bytemuck::cast_slice(&frame.shadows.matrices),
            );
        }
    }

    fn ensure_target(&mut self, device: &wgpu::Device, size: [u32; 2]) {
        let limit = device.limits().max_texture_dimension_2d;
        let size = size.map(|s| s.clamp(1, limit));
        if self.target.as_ref().is_some_and(|t| t.size == size) {
            return;
        }
        let texture = |label, format, usage| target_texture(device, label, size, format, usage);
        let color_texture = texture(
            "preview colour",
            COLOR_FORMAT,
            wgpu::TextureUsages::RENDER_ATTACHMENT
                | wgpu::TextureUsages::TEXTURE_BINDING
                | wgpu::TextureUsages::COPY_SRC,
        );
        let depth_texture = texture(
            "preview depth",
            DEPTH_FORMAT,
            wgpu::TextureUsages::RENDER_ATTACHMENT | wgpu::TextureUsages::COPY_SRC,
        );
        self.target = Some(Target {
            size,
            color: color_texture.create_view(&Default::default()),
            color_texture,
            depth: depth_texture.create_view(&Default::default()),
            depth_texture,
            behind: behind::Behind::new(device, size),
            mask: self.pipelines.outline.mask(device, size),
        });
        // The view's bindings hold the copy behind glass: bound anew with the new target.
        self.view_bind_group = None;
    }
}

/// The pass that draws into the target's colour and depth: cleared first, or continuing them.
fn main_pass<'e>(
    encoder: &'e mut wgpu::CommandEncoder,
    target: &Target,
    clear: bool,
) -> wgpu::RenderPass<'e> {
    let (color_load, depth_load) = if clear {
        (
            wgpu::LoadOp::Clear(wgpu::Color::BLACK),
            wgpu::LoadOp::Clear(1.0),
        )
    } else {
        (wgpu::LoadOp::Load, wgpu::LoadOp::Load)
    };
    encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
        label: Some("preview"),
        color_attachments: &[Some(wgpu::RenderPassColorAttachment {
            view: &target.color,
            depth_slice: None,
            resolve_target: None,
            ops: wgpu::Operations {
                load: color_load,
                store: wgpu::StoreOp::Store,
            },
        })],
        depth_stencil_attachment: Some(wgpu::RenderPassDepthStencilAttachment {
            view: &target.depth,
            depth_ops: Some(wgpu::Operations {
                load: depth_load,
                // Kept for the glass pass and the selection's mask.
                store: wgpu::StoreOp::Store,
            }),
            stencil_ops: None,
        }),
        timestamp_writes: None,
        occlusion_query_set: None,
        multiview_mask: None,
    })
}

/// Renders `frame` headless and reads it back: linear RGB radiance, row-major from the top row.
pub fn render_image(ctx: &GpuContext, frame: &PreviewFrame) -> Result<Vec<[f32; 3]>> {
    let mut renderer = ctx.scoped(|| PreviewRenderer::new(&ctx.device, &ctx.queue))?;
    let [width, height] = frame.size_px.map(|s| s.max(1));
    let row_bytes = (width * 8).next_multiple_of(wgpu::COPY_BYTES_PER_ROW_ALIGNMENT);
    let size = u64::from(row_bytes) * u64::from(height);
    let readback = ctx.scoped(|| {
        let mut encoder = ctx.device.create_command_encoder(&Default::default());
        renderer.render(&ctx.device, &ctx.queue, &mut encoder, frame);
        let buffer = ctx.device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("preview image"),
            size,
            usage: wgpu::BufferUsages::COPY_DST | wgpu::BufferUsages::COPY_SRC,
            mapped_at_creation: false,
        });
        if let Some(target) = &renderer.target {
            encoder.copy_texture_to_buffer(
                target.color_texture.as_image_copy(),
                wgpu::TexelCopyBufferInfo {
                    buffer: &buffer,
                    layout: wgpu::TexelCopyBufferLayout {
                        offset: 0,
                        bytes_per_row: Some(row_bytes),
                        rows_per_image: Some(height),
                    },
                },
                wgpu::Extent3d {
                    width,
                    height,
                    depth_or_array_layers: 1,
                },
            );
        }
        ctx.queue.submit([encoder.finish()]);
        buffer
    })?;
    let bytes = rt_gpu::read_buffer(ctx, &readback, size)?;
    if renderer.target.is_none() {
        return Err(GpuError::Wgpu("the preview has no target".into()));
    }
    let mut pixels = Vec::with_capacity((width * height) as usize);
    for row in bytes.chunks_exact(row_bytes as usize) {
        let texels: &[half::f16] = bytemuck::cast_slice(&row[..(width * 8) as usize]);
        pixels.extend(
            texels
                .chunks_exact(4)
                .map(|t| [t[0].to_f32(), t[1].to_f32(), t[2].to_f32()]),
        );
    }
    Ok(pixels)
}
