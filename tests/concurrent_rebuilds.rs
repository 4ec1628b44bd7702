//! Renderers on three threads sharing one device, each rebuilding its pipelines before every batch
//! (`PipelineRebuilds::Every` of zero, the lavapipe memory workaround at its most frequent),
//! finish and change no sample: each thread's image equals a render of the same seed without
//! rebuilds. (A CI run once stalled inside lavapipe with every renderer rebuilding; this test would
//! then hang, and the harness's time limit fail it.)

mod common;

use common::{gpu, render_gpu};
use rt_core::GpuScene;
use rt_gpu::{Kernel, RenderOptions, Renderer, Tuning};
use std::time::Duration;

#[test]
fn concurrent_pipeline_rebuilds_finish_and_change_no_sample() {
    let Some(ctx) = gpu() else { return };
    for kernel in [Kernel::Wavefront, Kernel::Megakernel] {
        std::thread::scope(|scope| {
            for seed in 0..3 {
                scope.spawn(move || {
                    let mut s = rt_io::assets::cornell_box().unwrap();
                    s.settings.width = 32;
                    s.settings.height = 32;
                    s.settings.seed = seed;
                    let gpu_scene = GpuScene::build(&s).unwrap();
                    let options = RenderOptions {
                        kernel,
                        max_samples_per_dispatch: Some(1),
                        ..Default::default()
                    };
                    let rebuilding = RenderOptions {
                        tuning: Tuning {
                            pipeline_rebuilds: rt_gpu::PipelineRebuilds::Every(Duration::ZERO),
                            ..Default::default()
                        },
                        ..options
                    };
                    let mut renderer =
                        Renderer::for_scene(ctx, &s, &gpu_scene, rebuilding).unwrap();
                    renderer.render(20, |_| true).unwrap();
                    assert!(
                        renderer.pipeline_rebuilds() >= 19,
                        "{kernel:?} seed {seed}: {} rebuilds",
                        renderer.pipeline_rebuilds()
                    );
                    let rebuilt = renderer.read_image().unwrap();
                    s.settings.samples_per_pixel = 20;
                    let kept = render_gpu(ctx, &s, &gpu_scene, options);
                    assert!(
                        rebuilt.pixels == kept.pixels,
                        "{kernel:?} seed {seed}: concurrent rebuilds changed the image"
                    );
                });
            }
        });
    }
}
