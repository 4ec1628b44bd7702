//! Nearest-hit queries through the kernel's BVH traversal, for checking it against the CPU.

use rt_core::GpuScene;
use rt_core::gpu_types::{Hit, Ray};

use crate::buffers::{read_buffer, storage_buffer};
use crate::context::GpuContext;
use crate::error::Result;
use crate::pipelines::trace_rays_pipeline;

/// Traces `rays` against `scene` on the GPU and returns one `Hit` per ray.
pub fn trace_rays(ctx: &GpuContext, scene: &GpuScene, rays: &[Ray]) -> Result<Vec<Hit>> {
    if rays.is_empty() {
        return Ok(Vec::new());
    }
    let pipeline = trace_rays_pipeline(ctx, scene.layout)?;
    let rays_buffer = storage_buffer(ctx, "rays", rays, wgpu::BufferUsages::empty())?;
    let triangles = storage_buffer(
        ctx,
        "triangles",
        &scene.triangles,
        wgpu::BufferUsages::empty(),
    )?;
    let nodes = storage_buffer(
        ctx,
        "bvh nodes",
        scene.node_bytes(),
        wgpu::BufferUsages::empty(),
    )?;
    let hits = storage_buffer(
        ctx,
        "hits",
        &vec![Hit::default(); rays.len()],
        wgpu::BufferUsages::COPY_SRC,
    )?;
    ctx.scoped(|| {
        let bind_group = ctx.device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("trace_rays"),
            layout: &pipeline.get_bind_group_layout(0),
            entries: &[
                wgpu::BindGroupEntry {
                    binding: 0,
                    resource: rays_buffer.as_entire_binding(),
                },
                wgpu::BindGroupEntry {
                    binding: 1,
                    resource: triangles.as_entire_binding(),
                },
                wgpu::BindGroupEntry {
                    binding: 2,
                    resource: nodes.as_entire_binding(),
                },
                wgpu::BindGroupEntry {
                    binding: 3,
                    resource: hits.as_entire_binding(),
                },
            ],
        });
        let mut encoder = ctx.device.create_command_encoder(&Default::default());
        {
            let mut pass = encoder.begin_compute_pass(&Default::default());
            pass.set_pipeline(&pipeline);
            pass.set_bind_group(0, &bind_group, &[]);
            pass.dispatch_workgroups((rays.len() as u32).div_ceil(64), 1, 1);
        }
        ctx.queue.submit([encoder.finish()]);
    })?;
    let bytes = read_buffer(ctx, &hits, (rays.len() * size_of::<Hit>()) as u64)?;
    Ok(bytemuck::pod_collect_to_vec(&bytes))
}
