//! Compute pipelines, specialised per scene feature set with override constants and cached on the
//! context, so a scene that uses no metal or glass runs (and compiles) a kernel without them.

use rt_core::SceneFeatures;
use rt_core::bvh::BvhLayout;

use crate::context::GpuContext;
use crate::error::Result;
use crate::shaders;

/// What a trace pipeline is specialised for.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct PipelineKey {
    pub features: SceneFeatures,
    /// The BVH the kernel traverses (a different module, not a constant: the node types differ).
    pub layout: BvhLayout,
    pub count_rays: bool,
    /// Bits of the firefly clamp (`f32::to_bits`); 0 is off.
    pub clamp_bits: u32,
    /// Work-group width and height.
    pub workgroup: [u32; 2],
    /// Owen-scrambled Sobol points instead of independent random numbers.
    pub sobol: bool,
    /// Accumulate first-hit albedo and normal for the denoiser.
    pub aovs: bool,
    /// Compile without wgpu's injected bounds checks and loop guards: only for scenes whose indices
    /// `GpuScene::check_kernel_indices` has proven in range (`Renderer::new` decides).
    pub trusted: bool,
    /// Traversal reads vertices from the structure-of-arrays copy (a layout experiment).
    pub soa_triangles: bool,
}

impl PipelineKey {
    /// Constants only the megakernel (trace.wgsl) declares.
    pub(crate) const MEGAKERNEL_ONLY: [&'static str; 3] = ["WG_X", "WG_Y", "SOA_TRIANGLES"];

    pub(crate) fn constants(&self) -> [(&'static str, f64); 13] {
        let flag = |b: bool| if b { 1.0 } else { 0.0 };
        [
            ("HAS_TEXTURES", flag(self.features.textures)),
            ("HAS_METAL", flag(self.features.metal)),
            ("HAS_DIELECTRIC", flag(self.features.dielectric)),
            ("HAS_THIN_LENS", flag(self.features.thin_lens)),
            ("COUNT_RAYS", flag(self.count_rays)),
            ("HAS_NEE", flag(self.features.nee)),
            ("HAS_DELTA_LIGHTS", flag(self.features.delta_lights)),
            ("CLAMP_MAX", f64::from(f32::from_bits(self.clamp_bits))),
            ("WG_X", f64::from(self.workgroup[0])),
            ("WG_Y", f64::from(self.workgroup[1])),
            ("SOBOL", flag(self.sobol)),
            ("WRITE_AOVS", flag(self.aovs)),
            ("SOA_TRIANGLES", flag(self.soa_triangles)),
        ]
    }
}

/// The trace pipeline for `key`, built on first use.
pub fn trace_pipeline(ctx: &GpuContext, key: PipelineKey) -> Result<wgpu::ComputePipeline> {
    if let Some(p) = ctx
        .pipelines
        .lock()
        .unwrap_or_else(|e| e.into_inner())
        .get(&key)
    {
        return Ok(p.clone());
    }
    let started = std::time::Instant::now();
    let pipeline = ctx.scoped(|| {
        let descriptor = wgpu::ShaderModuleDescriptor {
            label: Some("trace"),
            source: wgpu::ShaderSource::Wgsl(shaders::trace_module(key.layout).source().into()),
        };
        #[allow(unsafe_code)] // the one unsafe call in rt; see SAFETY below
        let module = if key.trusted {
            // SAFETY: the kernel indexes storage arrays only through the scene's indices, which
            // `GpuScene::check_kernel_indices` checked before this key was made (BVH children point
            // forwards, so traversal ends), the pixel slot through rows the renderer keeps inside
            // the accumulation buffer, the work-group traversal stacks at local index x 64 + depth
            // (under 64 x 64: `Renderer::new` refuses larger work groups, the push is guarded), and
            // vector components under explicit guards; the other loops are bounded by uniforms.
            // `tests/extremes.rs` checks the images match those of the checked kernel.
            unsafe {
                ctx.device.create_shader_module_trusted(
                    descriptor,
                    wgpu::ShaderRuntimeChecks::unchecked(),
                )
            }
        } else {
            ctx.device.create_shader_module(descriptor)
        };
        let constants = key.constants();
        ctx.device
            .create_compute_pipeline(&wgpu::ComputePipelineDescriptor {
                label: Some("trace"),
                layout: None,
                module: &module,
                entry_point: Some("main"),
                compilation_options: wgpu::PipelineCompilationOptions {
                    constants: &constants,
                    ..Default::default()
                },
                cache: None,
            })
    })?;
    log::info!(
        "compiled trace pipeline {key:?} in {:.2?}",
        started.elapsed()
    );
    ctx.pipelines
        .lock()
        .unwrap_or_else(|e| e.into_inner())
        .insert(key, pipeline.clone());
    Ok(pipeline)
}

/// The ray-query pipeline used by tests to check BVH traversal.
pub fn trace_rays_pipeline(ctx: &GpuContext, layout: BvhLayout) -> Result<wgpu::ComputePipeline> {
    ctx.scoped(|| {
        let module = ctx
            .device
            .create_shader_module(wgpu::ShaderModuleDescriptor {
                label: Some("trace_rays"),
                source: wgpu::ShaderSource::Wgsl(
                    shaders::trace_rays_module(layout).source().into(),
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
