//! Compute pipelines, specialised per scene feature set with override constants and cached on the
//! context, so a scene that uses no metal or glass runs (and compiles) a kernel without them.
//! Both kernels (megakernel and wavefront) go through one keyed cache.

use std::sync::Arc;

use rt_core::SceneFeatures;
use rt_core::bvh::BvhLayout;

use crate::bindings;
use crate::context::GpuContext;
use crate::error::Result;
use crate::options::Kernel;
use crate::shaders;
use crate::wavefront::WAVE_GROUP;

/// What a tracing kernel is specialised for.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct PipelineKey {
    pub kernel: Kernel,
    pub features: SceneFeatures,
    /// The BVH the kernel traverses (a different module, not a constant: the node types differ).
    pub layout: BvhLayout,
    /// Trace with the driver's ray queries instead of traversing `layout` (`Trace::Hardware`).
    pub ray_query: bool,
    pub count_rays: bool,
    /// Bits of the firefly clamp (`f32::to_bits`); 0 is off.
    pub clamp_bits: u32,
    /// The megakernel's work-group width and height (the wavefront kernels' is fixed).
    pub workgroup: [u32; 2],
    /// Owen-scrambled Sobol points instead of independent random numbers.
    pub sobol: bool,
    /// Accumulate first-hit albedo and normal for the denoiser.
    pub aovs: bool,
    /// Skip pixels that adaptive sampling has stopped.
    pub adaptive: bool,
}

impl PipelineKey {
    /// The key as the cache sees it: fields the kernel ignores are normalised, so they cannot make
    /// two entries of one pipeline.
    fn normalised(self) -> Self {
        let key = PipelineKey {
            // Ray queries need no BVH layout of rt's.
            layout: if self.ray_query {
                BvhLayout::Cwbvh
            } else {
                self.layout
            },
            ..self
        };
        match key.kernel {
            Kernel::Megakernel => key,
            Kernel::Wavefront => PipelineKey {
                workgroup: [WAVE_GROUP, 1],
                ..key
            },
        }
    }

    /// The override constants `kernel`'s WGSL declares, with this key's values.
    pub(crate) fn constants(&self) -> Vec<(&'static str, f64)> {
        let flag = |b: bool| if b { 1.0 } else { 0.0 };
        let mut constants = vec![
            ("HAS_TEXTURES", flag(self.features.textures)),
            ("HAS_METAL", flag(self.features.metal)),
            ("HAS_DIELECTRIC", flag(self.features.dielectric)),
            ("HAS_THIN_LENS", flag(self.features.thin_lens)),
            ("COUNT_RAYS", flag(self.count_rays)),
            ("HAS_NEE", flag(self.features.nee)),
            ("HAS_DELTA_LIGHTS", flag(self.features.delta_lights)),
            ("HAS_PBR", flag(self.features.pbr)),
            ("HAS_ENVIRONMENT", flag(self.features.environment)),
            ("HAS_NORMAL_MAPS", flag(self.features.normal_maps)),
            ("HAS_ALPHA", flag(self.features.alpha)),
            ("CLAMP_MAX", f64::from(f32::from_bits(self.clamp_bits))),
            ("SOBOL", flag(self.sobol)),
            ("WRITE_AOVS", flag(self.aovs)),
            ("ADAPTIVE", flag(self.adaptive)),
        ];
        if self.kernel == Kernel::Megakernel {
            constants.push(("WG_X", f64::from(self.workgroup[0])));
            constants.push(("WG_Y", f64::from(self.workgroup[1])));
        }
        constants
    }
}

/// Entry points of each kernel's module.
const MEGAKERNEL_STAGES: &[&str] = &["main"];
const WAVEFRONT_STAGES: &[&str] = &[
    "generate", "extend", "shade", "connect", "advance", "finish",
];

/// The compiled stages of one kernel for one key, over one bind-group layout (`bindings`).
pub(crate) struct KernelPipelines {
    pub layout: wgpu::BindGroupLayout,
    stages: Vec<(&'static str, wgpu::ComputePipeline)>,
}

impl KernelPipelines {
    /// The stage with entry point `entry` (one of the kernel's, fixed in this file).
    pub fn stage(&self, entry: &str) -> &wgpu::ComputePipeline {
        match self.stages.iter().find(|(name, _)| *name == entry) {
            Some((_, pipeline)) => pipeline,
            None => unreachable!("no stage {entry} in {:?}", self.stage_names()),
        }
    }

    fn stage_names(&self) -> Vec<&'static str> {
        self.stages.iter().map(|(name, _)| *name).collect()
    }
}

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
