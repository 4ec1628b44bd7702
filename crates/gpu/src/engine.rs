//! What traces a renderer's paths: the megakernel (trace.wgsl, one invocation per pixel runs whole
//! paths) or the wavefront kernels (`wavefront`, a kernel per path stage), and the `PipelineKey`
//! that specialises either for a scene, a frame and the render options.

use std::sync::Arc;
use std::time::{Duration, Instant};

use rt_core::gpu_types::Frame;
use rt_core::{GpuScene, Scene, SceneFeatures};

use crate::accel::SceneAccel;
use crate::bindings::{self, Binding};
use crate::context::GpuContext;
use crate::error::{GpuError, Result};
use crate::options::{Kernel, RenderOptions, Trace};
use crate::pipeline_cache::{KernelPipelines, PipelineKey};
use crate::pipelines::{forget, kernel_pipelines};
use crate::wavefront::{MAX_WAVE_PATHS, Wavefront};

/// What traces the paths.
pub(crate) enum Engine {
    /// trace.wgsl: one invocation per pixel runs whole paths.
    Megakernel {
        pipelines: Arc<KernelPipelines>,
        bind_group: wgpu::BindGroup,
    },
    /// wavefront.wgsl: a kernel per path stage.
    Wavefront(Wavefront),
}

impl Engine {
    /// The megakernel over `bound`, from `pipelines` (built before the scene's buffers were
    /// uploaded, so a kernel that fails to build is reported first).
    pub fn megakernel(
        ctx: &GpuContext,
        pipelines: Arc<KernelPipelines>,
        bound: &[(Binding, wgpu::Buffer)],
        tlas: Option<&wgpu::Tlas>,
    ) -> Result<Self> {
        Ok(Engine::Megakernel {
            bind_group: ctx.scoped(|| megakernel_bind_group(ctx, &pipelines, bound, tlas))?,
            pipelines,
        })
    }

    /// The most paths one wave holds; `None` for the megakernel.
    pub fn wave_capacity(&self) -> Option<u32> {
        match self {
            Engine::Wavefront(wave) => Some(wave.capacity),
            Engine::Megakernel { .. } => None,
        }
    }

    /// Replaces the pipelines with freshly built ones (dropping these and the context's handles
    /// to the old ones, so the driver can free what it holds for them) over the same buffers.
    pub fn rebuild(
        &mut self,
        ctx: &GpuContext,
        key: PipelineKey,
        bound: &[(Binding, wgpu::Buffer)],
        tlas: Option<&wgpu::Tlas>,
    ) -> Result<()> {
        if let Engine::Wavefront(wave) = self {
            return wave.rebuild(ctx, key, bound, tlas);
        }
        if let Engine::Megakernel { pipelines, .. } = self {
            forget(ctx, pipelines);
        }
        let pipelines = kernel_pipelines(ctx, key)?;
        let bind_group = ctx.scoped(|| megakernel_bind_group(ctx, &pipelines, bound, tlas))?;
        *self = Engine::Megakernel {
            pipelines,
            bind_group,
        };
        Ok(())
    }

    /// Runs one dispatch (megakernel: `rows` rows of `frame.width` pixels, in work groups of
    /// `workgroup`) or wave (wavefront) of `frame`, written into `frame_buffer` first; returns its
    /// longest submission's time and, for a wave, the path depths it ran.
    pub fn run(
        &self,
        ctx: &GpuContext,
        frame_buffer: &wgpu::Buffer,
        frame: &Frame,
        rows: u32,
        workgroup: [u32; 2],
    ) -> Result<(Duration, u32)> {
        let (pipeline, bind_group) = match self {
            Engine::Megakernel {
                pipelines,
                bind_group,
            } => (pipelines.stage("main"), bind_group),
            // A wave is a submission per path depth; the longest one's time bounds each dispatch's.
            Engine::Wavefront(wave) => {
                let run = wave.run(ctx, frame_buffer, frame)?;
                return Ok((run.longest, run.depths));
            }
        };
        let started = Instant::now();
        ctx.scoped(|| {
            ctx.queue
                .write_buffer(frame_buffer, 0, bytemuck::bytes_of(frame));
            let mut encoder = ctx.device.create_command_encoder(&Default::default());
            {
                let mut pass = encoder.begin_compute_pass(&Default::default());
                pass.set_pipeline(pipeline);
                pass.set_bind_group(0, bind_group, &[]);
                let [wx, wy] = workgroup;
                pass.dispatch_workgroups(frame.width.div_ceil(wx), rows.div_ceil(wy), 1);
            }
            ctx.queue.submit([encoder.finish()]);
        })?;
        ctx.device
            .poll(wgpu::PollType::wait_indefinitely())
            .map_err(|e| GpuError::Wgpu(e.to_string()))?;
        Ok((started.elapsed(), 0))
    }
}

/// What the kernels are specialised for: the scene's features as `frame` and `options` use them,
/// its BVH layout, and the options compiled in.
pub(crate) fn pipeline_key(
    scene: &GpuScene,
    frame: &Frame,
    options: &RenderOptions,
    ray_query: bool,
    adaptive: bool,
) -> PipelineKey {
    PipelineKey {
        kernel: options.kernel,
        features: specialised_features(scene, frame, options),
        layout: scene.layout,
        ray_query,
        count_rays: options.tuning.count_rays,
        workgroup: options.tuning.workgroup,
        sobol: frame.sampler == 1,
        aovs: options.aovs,
        adaptive,
    }
}

/// The branches the kernels compile in: the scene's features, the lens and light sampling as
/// `frame` asks, or every branch with `Tuning::generic_kernel`.
fn specialised_features(scene: &GpuScene, frame: &Frame, options: &RenderOptions) -> SceneFeatures {
    let mut features = scene.features;
    features.thin_lens = frame.lens_radius > 0.0;
    // The tree may hold point and spot lights alone: next-event estimation then has no emitter
    // triangles and still samples.
    features.light_tree = frame.light_sampler == 1 && !scene.light_tree.is_empty();
    features.nee = frame.emitter_count > 0 || features.light_tree;
    features.media |= !rt_core::math::medium::is_vacuum(&frame.fog);
    if options.tuning.generic_kernel {
        // Every branch compiled in; each still checks its data at run time. (NEE stays as the
        // scene needs: the emitter table must not be empty.)
        features.textures = true;
        features.kinds = rt_core::material_kind::KindSet::all();
        features.thin_lens = true;
        features.delta_lights = true;
        features.environment = true;
        features.normal_maps = true;
        features.alpha = true;
        features.media = true;
    }
    features
}

/// The megakernel's pipelines for `key`, or `None` for the wavefront kernels (which build their
/// own in `Wavefront::new`).
pub(crate) fn megakernel_pipelines(
    ctx: &GpuContext,
    key: PipelineKey,
) -> Result<Option<Arc<KernelPipelines>>> {
    match key.kernel {
        Kernel::Megakernel => Ok(Some(kernel_pipelines(ctx, key)?)),
        Kernel::Wavefront => Ok(None),
    }
}

/// The kernel `Renderer::for_scene(ctx, scene, gpu_scene, options)` runs.
fn key_for_scene(
    ctx: &GpuContext,
    scene: &Scene,
    gpu_scene: &GpuScene,
    options: RenderOptions,
) -> Result<PipelineKey> {
    let frame = rt_core::frame::frame_for(scene, gpu_scene)?;
    let ray_query = ctx.resolve_trace(options.trace, gpu_scene) == Trace::Hardware;
    let adaptive = scene.settings.adaptive_threshold.is_some();
    Ok(pipeline_key(
        gpu_scene, &frame, &options, ray_query, adaptive,
    ))
}

/// Whether the kernel `Renderer::for_scene` would run with these arguments is compiled on `ctx`
/// already. Compiling one can take seconds (tens of seconds for a rich scene on a cold driver
/// cache): the viewport renders on the CPU backend until it is (`compile_kernel`).
pub(crate) fn kernel_compiled(
    ctx: &GpuContext,
    scene: &Scene,
    gpu_scene: &GpuScene,
    options: RenderOptions,
) -> Result<bool> {
    let key = key_for_scene(ctx, scene, gpu_scene, options)?.normalised();
    Ok(ctx
        .pipelines
        .lock()
        .unwrap_or_else(|e| e.into_inner())
        .contains_key(&key))
}

/// Compiles that kernel into `ctx`'s cache (on any thread), so that the renderer then built finds
/// it.
pub(crate) fn compile_kernel(
    ctx: &GpuContext,
    scene: &Scene,
    gpu_scene: &GpuScene,
    options: RenderOptions,
) -> Result<()> {
    kernel_pipelines(ctx, key_for_scene(ctx, scene, gpu_scene, options)?).map(|_| ())
}

/// A wave's capacity: room for the whole tile (`pixels`) at the most samples a wave may take
/// (`loop_cap`), within `MAX_WAVE_PATHS` (but always a row of `width` pixels).
pub(crate) fn wave_capacity(pixels: u64, loop_cap: u32, width: u32) -> u32 {
    pixels
        .saturating_mul(u64::from(loop_cap))
        .min(u64::from(MAX_WAVE_PATHS))
        .max(u64::from(width)) as u32
}

/// The megakernel's bind group over `bound`.
fn megakernel_bind_group(
    ctx: &GpuContext,
    pipelines: &KernelPipelines,
    bound: &[(Binding, wgpu::Buffer)],
    tlas: Option<&wgpu::Tlas>,
) -> wgpu::BindGroup {
    let buffers: Vec<(Binding, &wgpu::Buffer)> = bound.iter().map(|(b, buf)| (*b, buf)).collect();
    bindings::bind_group(ctx, Kernel::Megakernel, &pipelines.layout, &buffers, tlas)
}

/// The acceleration structure's top level, when tracing with ray queries.
pub(crate) fn tlas(accel: &Option<SceneAccel>) -> Option<&wgpu::Tlas> {
    accel.as_ref().map(|a| &a.tlas)
}

#[cfg(test)]
mod tests {
    use super::*;
    use rt_core::{Light, LightKind, LightSampler, Material, Object, Scene};

    /// A floor under `lights` point lights and, with `lamp`, an emissive quad.
    fn scene(lights: usize, lamp: bool, sampler: LightSampler) -> Scene {
        let quad = |y: f32, material| Object {
            shadow_catcher: false,
            animation_node: None,
            name: "quad".into(),
            mesh: rt_core::shapes::quad(glam::Vec3::new(0.0, y, 0.0), glam::Vec3::Y, 4.0).into(),
            material,
            transform: Default::default(),
        };
        let mut scene = Scene::default();
        scene
            .objects
            .push(quad(0.0, Material::lambertian([0.5; 3])));
        if lamp {
            scene.objects.push(quad(
                1.0,
                Material::Emissive {
                    color: [1.0; 3],
                    intensity: 1.0,
                },
            ));
        }
        for i in 0..lights {
            let mut light = Light::new(LightKind::Point, &format!("point {i}"));
            light.position = [i as f32 * 0.1, 2.0, 0.0];
            scene.lights.push(light);
        }
        scene.settings.light_sampler = sampler;
        scene
    }

    fn features(scene: &Scene) -> SceneFeatures {
        let gpu = GpuScene::build(scene).unwrap();
        let frame = rt_core::frame::frame_for(scene, &gpu).unwrap();
        specialised_features(&gpu, &frame, &RenderOptions::default())
    }

    /// The kernels compile the tree in whenever the frame samples through it, emitter triangles
    /// or not (with point lights alone they once summed them instead), and not otherwise.
    #[test]
    fn the_tree_is_compiled_in_with_or_without_emitter_triangles() {
        let alone = features(&scene(20, false, LightSampler::Auto));
        assert!(alone.nee && alone.light_tree, "{alone:?}");
        let both = features(&scene(20, true, LightSampler::Tree));
        assert!(both.nee && both.light_tree, "{both:?}");
        let power = features(&scene(20, true, LightSampler::Power));
        assert!(power.nee && !power.light_tree, "{power:?}");
        let few = features(&scene(2, false, LightSampler::Auto));
        assert!(!few.nee && !few.light_tree, "{few:?}");
    }
}
