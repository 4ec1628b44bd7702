mod common;
use common::gpu;
use rt_core::GpuScene;
use rt_gpu::{RenderOptions, Renderer};
use std::time::{Duration, Instant};

#[test]
fn concurrent_rebuilds() {
    let Some(ctx) = gpu() else { return };
    for wavefront in [true, false] {
        let started = Instant::now();
        std::thread::scope(|scope| {
            for t in 0..3 {
                scope.spawn(move || {
                    let mut s = rt_core::assets::cornell_box().unwrap();
                    s.settings.width = 32;
                    s.settings.height = 32;
                    s.settings.seed = t;
                    let gpu_scene = GpuScene::build(&s).unwrap();
                    let options = RenderOptions {
                        pipeline_lifetime: Some(Duration::ZERO),
                        max_samples_per_dispatch: Some(1),
                        wavefront,
                        ..Default::default()
                    };
                    let mut r = Renderer::for_scene(ctx, &s, &gpu_scene, options).unwrap();
                    r.render(20, |_| true).unwrap();
                    eprintln!(
                        "wavefront {wavefront} thread {t}: {} rebuilds at {:.1?}",
                        r.pipeline_rebuilds(),
                        started.elapsed()
                    );
                });
            }
        });
        eprintln!("wavefront {wavefront}: {:.1?}", started.elapsed());
    }
}
