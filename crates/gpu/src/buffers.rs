//! Storage buffers for a `GpuScene`, checked against the adapter's limits, and readback.

use rt_core::GpuScene;
use wgpu::util::DeviceExt;

use crate::bindings::{self, Binding};
use crate::context::GpuContext;
use crate::error::{GpuError, Result};

/// Uploads `scene`'s thirteen storage buffers (in this order), each with the binding the tracing
/// kernels read it at. Textures beyond what one buffer may hold are box-filtered down
/// (`GpuScene::with_textures_within`), with a warning saying what and why, rather than failing.
pub fn scene_buffers(ctx: &GpuContext, scene: &GpuScene) -> Result<[(Binding, wgpu::Buffer); 13]> {
    let limits = ctx.device.limits();
    let budget = limits
        .max_storage_buffer_binding_size
        .min(limits.max_buffer_size);
    let fitted = scene.with_textures_within(budget).map(|(fitted, fit)| {
        log::warn!("{fit}");
        fitted
    });
    let scene = fitted.as_ref().unwrap_or(scene);
    Ok([
        (
            bindings::TRIANGLES,
            upload(ctx, "triangles", &scene.triangles)?,
        ),
        (bindings::SHADING, upload(ctx, "shading", &scene.shading)?),
        (
            bindings::MATERIALS,
            upload(ctx, "materials", &scene.materials)?,
        ),
        (
            bindings::NODES,
            upload(ctx, "bvh nodes", scene.node_bytes())?,
        ),
        (bindings::TEXELS, upload(ctx, "texels", &scene.texels)?),
        (
            bindings::EMITTERS,
            upload(ctx, "emitters", &scene.emitters)?,
        ),
        (
            bindings::LIGHT_TREE,
            upload(ctx, "light tree", &scene.light_tree)?,
        ),
        (
            bindings::DELTA_LIGHTS,
            upload(ctx, "delta lights", &scene.delta_lights)?,
        ),
        (
            bindings::ENVIRONMENT,
            upload(ctx, "environment", &scene.env_texels)?,
        ),
        (
            bindings::ALBEDO_TABLES,
            upload(ctx, "albedo tables", &scene.albedo_tables)?,
        ),
        (
            bindings::TANGENTS,
            upload(ctx, "tangents", &scene.tangents)?,
        ),
        (
            bindings::INSTANCES,
            upload(ctx, "instances", &scene.instances)?,
        ),
        (
            bindings::INSTANCE_NODES,
            upload(ctx, "instance nodes", &scene.instance_nodes)?,
        ),
    ])
}

/// One of the scene's buffers: read-only storage.
fn upload<T: bytemuck::Pod>(
    ctx: &GpuContext,
    name: &'static str,
    data: &[T],
) -> Result<wgpu::Buffer> {
    storage_buffer(ctx, name, data, wgpu::BufferUsages::empty())
}

/// Creates a storage buffer from `data`, padded to at least 16 bytes (wgpu rejects empty bindings).
pub fn storage_buffer<T: bytemuck::Pod>(
    ctx: &GpuContext,
    name: &'static str,
    data: &[T],
    extra: wgpu::BufferUsages,
) -> Result<wgpu::Buffer> {
    let mut bytes = bytemuck::cast_slice::<T, u8>(data).to_vec();
    let element = size_of::<T>().max(16);
    if bytes.len() < element {
        bytes.resize(element, 0);
    }
    ctx.check_buffer(name, bytes.len() as u64)?;
    ctx.scoped(|| {
        ctx.device
            .create_buffer_init(&wgpu::util::BufferInitDescriptor {
                label: Some(name),
                contents: &bytes,
                usage: wgpu::BufferUsages::STORAGE | extra,
            })
    })
}

/// An uninitialised storage buffer the kernels write and the CPU reads back or clears (the
/// accumulation, AOVs, counters and the wavefront's queues). Call inside `GpuContext::scoped`.
pub fn output_buffer(ctx: &GpuContext, label: &str, size: u64) -> wgpu::Buffer {
    ctx.device.create_buffer(&wgpu::BufferDescriptor {
        label: Some(label),
        size,
        usage: wgpu::BufferUsages::STORAGE
            | wgpu::BufferUsages::COPY_SRC
            | wgpu::BufferUsages::COPY_DST,
        mapped_at_creation: false,
    })
}

/// Copies `size` bytes of `buffer` back to the CPU and waits for them.
pub fn read_buffer(ctx: &GpuContext, buffer: &wgpu::Buffer, size: u64) -> Result<Vec<u8>> {
    ctx.alive()?;
    let (tx, rx) = std::sync::mpsc::channel();
    let staging = ctx.scoped(|| {
        let staging = ctx.device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("readback"),
            size,
            usage: wgpu::BufferUsages::MAP_READ | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        let mut encoder = ctx.device.create_command_encoder(&Default::default());
        encoder.copy_buffer_to_buffer(buffer, 0, &staging, 0, size);
        ctx.queue.submit([encoder.finish()]);
        staging.map_async(wgpu::MapMode::Read, .., move |r| {
            let _ = tx.send(r);
        });
        staging
    })?;
    ctx.device
        .poll(wgpu::PollType::wait_indefinitely())
        .map_err(|e| GpuError::Wgpu(e.to_string()))?;
    rx.recv()
        .map_err(|e| GpuError::Wgpu(e.to_string()))?
        .map_err(|e| GpuError::Wgpu(format!("reading back results: {e}")))?;
    let data = staging
        .get_mapped_range(..)
        .map_err(|e| GpuError::Wgpu(e.to_string()))?
        .to_vec();
    staging.unmap();
    Ok(data)
}
