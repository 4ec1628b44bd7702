//! What `rt-cli render` prints when a render is done (on stderr, one `name:   value` line each).

use std::time::Duration;

use rt_core::{GpuScene, Scene};
use rt_gpu::{GpuContext, Renderer};

/// How a progressive render ended.
pub struct Finish {
    pub render_time: Duration,
    /// The rule that stopped it ("samples per pixel", "noise target", ...).
    pub stopped_by: &'static str,
}

/// The summary of a progressive render (not tiled): the adapter and scene, the image, adaptive
/// sampling and the shard where they apply, time, noise and speed; more with `verbose`.
pub fn print_render_summary(
    ctx: &GpuContext,
    renderer: &Renderer,
    (scene, gpu_scene): (&Scene, &GpuScene),
    image: &rt_gpu::Image,
    range: Option<[u32; 2]>,
    finish: &Finish,
    verbose: bool,
) {
    print_scene_summary(ctx, renderer.kernel(), renderer.trace(), gpu_scene);
    print_image_summary((scene, gpu_scene), image, range, finish);
    if renderer.dropped_samples() > 0 {
        eprintln!(
            "dropped:        {} NaN/Inf samples (counted as black)",
            renderer.dropped_samples()
        );
    }
    if verbose {
        eprintln!("longest dispatch: {:.2?}", renderer.longest_dispatch());
        let m = image.channel_means();
        eprintln!("channel means:  {:.6} {:.6} {:.6}", m[0], m[1], m[2]);
    }
}

/// The adapter, kernel, tracing, triangles and BVH build, as both render paths print them.
pub fn print_scene_summary(
    ctx: &GpuContext,
    kernel: rt_gpu::Kernel,
    trace: rt_gpu::Trace,
    gpu_scene: &GpuScene,
) {
    eprintln!("adapter:        {}", ctx.adapter_label());
    eprintln!(
        "kernel:         {}, tracing {}",
        kernel.name(),
        trace_name(trace)
    );
    eprintln!("triangles:      {}", triangles_line(gpu_scene));
    eprintln!(
        "BVH build:      {:.2?} (depth {})",
        gpu_scene.bvh_build_time, gpu_scene.bvh_depth
    );
}

fn trace_name(trace: rt_gpu::Trace) -> &'static str {
    match trace {
        rt_gpu::Trace::Hardware => "with ray queries",
        rt_gpu::Trace::Bvh | rt_gpu::Trace::Auto => "rt's BVH",
    }
}

/// "max depth D, next-event estimation on|off|on (light tree), S sampler".
pub fn estimator_summary(settings: &rt_core::RenderSettings, gpu_scene: &GpuScene) -> String {
    format!(
        "max depth {}, next-event estimation {}, {} sampler",
        settings.max_depth,
        match (gpu_scene.features.nee, gpu_scene.light_tree.is_empty()) {
            (false, _) => "off",
            (true, true) => "on",
            (true, false) => "on (light tree)",
        },
        match settings.sampler {
            rt_core::math::rng::SamplerKind::Sobol => "Sobol",
            rt_core::math::rng::SamplerKind::Independent => "independent",
        }
    )
}

/// The lines of a render's summary that do not depend on the backend: the image, adaptive
/// sampling and the shard where they apply, time, noise and speed.
pub fn print_image_summary(
    (scene, gpu_scene): (&Scene, &GpuScene),
    image: &rt_gpu::Image,
    range: Option<[u32; 2]>,
    finish: &Finish,
) {
    let noise = image.estimated_noise();
    let render_time = finish.render_time;
    let secs = render_time.as_secs_f64().max(1e-9);
    let pixels = u64::from(scene.settings.width) * u64::from(scene.settings.height);
    let paths = pixels as f64 * image.mean_samples();
    eprintln!(
        "image:          {}x{}, {} spp, {}",
        image.width,
        image.height,
        image.samples_per_pixel,
        estimator_summary(&scene.settings, gpu_scene)
    );
    if let (Some(threshold), Some(counts)) =
        (scene.settings.adaptive_threshold, &image.sample_counts)
    {
        let stopped = counts
            .iter()
            .filter(|&&c| c < image.samples_per_pixel)
            .count();
        eprintln!(
            "adaptive:       threshold {threshold}, mean {:.1} spp, {:.1}% of pixels stopped before the last batch",
            image.mean_samples(),
            100.0 * stopped as f64 / counts.len().max(1) as f64
        );
    }
    if let Some([a, b]) = range {
        eprintln!(
            "shard:          samples {a}..{b} of {}, saved as a part for `rt-cli merge`",
            scene.settings.samples_per_pixel
        );
    }
    eprintln!(
        "render time:    {render_time:.2?} (stopped by {})",
        finish.stopped_by
    );
    eprintln!("noise:          {noise:.5} (estimated sqrt(relMSE) against the converged image)");
    eprintln!(
        "samples/s:      {:.1} spp/s",
        f64::from(image.samples_per_pixel) / secs
    );
    eprintln!("paths/s:        {:.3} M", paths / secs / 1e6);
}

/// The triangles a scene stores, and how many of its objects are copies placed as instances.
pub fn triangles_line(gpu_scene: &rt_core::GpuScene) -> String {
    match gpu_scene.instances.len() {
        0 => gpu_scene.triangles.len().to_string(),
        n => format!(
            "{} stored ({n} objects are instances of shared meshes, each stored once)",
            gpu_scene.triangles.len()
        ),
    }
}
