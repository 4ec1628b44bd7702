//! Nearest-hit queries through the kernel's BVH traversal, for checking it against the CPU.

use rt_core::GpuScene;
use rt_core::gpu_types::{Hit, Ray};

use crate::buffers::{read_buffer, storage_buffer};
use crate::context::GpuContext;
use crate::error::Result;
use crate::options::Trace;
use crate::pipelines::trace_rays_pipeline;

/// Traces `rays` against `scene` on the GPU and returns one `Hit` per ray: through rt's BVH, or
/// with `Trace::Hardware` the driver's ray queries (`Auto` is rt's BVH here).
pub fn trace_rays(
    ctx: &GpuContext,
    scene: &GpuScene,
    rays: &[Ray],
    trace: Trace,
) -> Result<Vec<Hit>> {
    if rays.is_empty() {
        return Ok(Vec::new());
    }
    let accel = match trace {
        Trace::Hardware => Some(crate::accel::build(ctx, scene)?),
        Trace::Auto | Trace::Bvh => None,
    };
    let pipeline = trace_rays_pipeline(ctx, scene.layout, accel.is_some())?;
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
            ]
            .into_iter()
            // The pipeline's layout is derived from what its shader uses: over ray queries, not
            // the triangles (1) or the BVH nodes (2).
            .filter(|entry| accel.is_none() || !matches!(entry.binding, 1 | 2))
            .chain(accel.as_ref().map(|a| wgpu::BindGroupEntry {
                binding: crate::bindings::SCENE_TLAS.number,
                resource: wgpu::BindingResource::AccelerationStructure(&a.tlas),
            }))
            .collect::<Vec<_>>(),
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
