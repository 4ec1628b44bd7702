//! Compute pipelines, specialised per scene feature set with override constants and cached on the
//! context, so a scene that uses no metal or glass runs (and compiles) a kernel without them.
//! Both kernels (megakernel and wavefront) go through one keyed cache.

use std::sync::Arc;

#[cfg(feature = "testing")]
use rt_core::bvh::BvhLayout;

use crate::bindings;
use crate::context::GpuContext;
use crate::error::Result;
use crate::options::Kernel;
use crate::pipeline_cache::{KernelPipelines, PipelineKey};
use crate::shaders;

/// Entry points of each kernel's module.
const MEGAKERNEL_STAGES: &[&str] = &["main"];
const WAVEFRONT_STAGES: &[&str] = &[
    "generate", "extend", "shade", "connect", "advance", "finish",
];

/// The pipelines of `key`'s kernel, built on first use and cached on the context (one cache for
/// both kernels).
pub(crate) fn kernel_pipelines(ctx: &GpuContext, key: PipelineKey) -> Result<Arc<KernelPipelines>> {
    let key = key.normalised();
    if let Some(p) = ctx
        .pipelines
        .lock()
        .unwrap_or_else(|e| e.into_inner())
        .get(&key)
    {
        return Ok(p.clone());
    }
    let started = std::time::Instant::now();
    let (module_source, stages) = match key.kernel {
        Kernel::Megakernel => (
            shaders::trace_module(key.layout, key.ray_query),
            MEGAKERNEL_STAGES,
        ),
        Kernel::Wavefront => (
            shaders::wavefront_module(key.layout, key.ray_query),
            WAVEFRONT_STAGES,
        ),
    };
    let constants = key.constants();
    let pipelines = ctx.scoped(|| {
        let module = ctx
            .device
            .create_shader_module(wgpu::ShaderModuleDescriptor {
                label: Some(key.kernel.name()),
                source: wgpu::ShaderSource::Wgsl(module_source.source().into()),
            });
        let layout = bindings::layout(ctx, key.kernel, key.ray_query);
        let pipeline_layout = ctx
            .device
            .create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
                label: Some(key.kernel.name()),
                bind_group_layouts: &[Some(&layout)],
                immediate_size: 0,
            });
        let stages = stages
            .iter()
            .map(|&entry| {
                let pipeline =
                    ctx.device
                        .create_compute_pipeline(&wgpu::ComputePipelineDescriptor {
                            label: Some(entry),
                            layout: Some(&pipeline_layout),
                            module: &module,
                            entry_point: Some(entry),
                            compilation_options: wgpu::PipelineCompilationOptions {
                                constants: &constants,
                                // The wavefront's BVH stacks in work-group memory are pushed before
                                // they are read; a 16 KiB clear per work group, three dispatches per
                                // depth, would be waste.
                                zero_initialize_workgroup_memory: key.kernel == Kernel::Megakernel,
                            },
                            cache: None,
                        });
                (entry, pipeline)
            })
            .collect();
        KernelPipelines { layout, stages }
    })?;
    log::info!(
        "compiled {} pipelines {key:?} in {:.2?}",
        key.kernel.name(),
        started.elapsed()
    );
    let pipelines = Arc::new(pipelines);
    ctx.pipelines
        .lock()
        .unwrap_or_else(|e| e.into_inner())
        .insert(key, pipelines.clone());
    Ok(pipelines)
}

/// Drops the context's handle to `pipelines`, so the next `kernel_pipelines` builds them afresh
/// (and the driver can free what it holds for the old ones once the renderer drops them too).
pub(crate) fn forget(ctx: &GpuContext, pipelines: &Arc<KernelPipelines>) {
    ctx.pipelines
        .lock()
        .unwrap_or_else(|e| e.into_inner())
        .retain(|_, p| !Arc::ptr_eq(p, pipelines));
}

/// The nearest-hit pipeline used by tests to check traversal (rt's of `layout`, or the driver's
/// ray queries with `ray_query`).
#[cfg(feature = "testing")]
pub fn trace_rays_pipeline(
    ctx: &GpuContext,
    layout: BvhLayout,
    ray_query: bool,
) -> Result<wgpu::ComputePipeline> {
    ctx.scoped(|| {
        let module = ctx
            .device
            .create_shader_module(wgpu::ShaderModuleDescriptor {
                label: Some("trace_rays"),
                source: wgpu::ShaderSource::Wgsl(
                    shaders::trace_rays_module(layout, ray_query)
                        .source()
                        .into(),
                ),
            });
        ctx.device
            .create_compute_pipeline(&wgpu::ComputePipelineDescriptor {
                label: Some("trace_rays"),
                layout: None,
                module: &module,
                entry_point: Some("main"),
                compilation_options: Default::default(),
                cache: None,
            })
    })
}
