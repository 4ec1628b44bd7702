//! The renderer at its limits: cancelling and restarting, 100,000 samples, tiles, kernels and
//! work-group shapes, rebuilt pipelines.

use super::*;
use rt_gpu::Tuning;

/// Stopping after any batch leaves a readable image of the samples so far, and a new render can
/// start at once on the same device.
#[test]
fn a_render_can_be_cancelled_and_restarted() {
    let Some(ctx) = gpu() else { return };
    let mut scene = rt_io::assets::cornell_box().unwrap();
    scene.settings = settings(32, 32, 1000, 8);
    let gpu_scene = GpuScene::build(&scene).unwrap();
    let mut renderer =
        rt_gpu::Renderer::for_scene(ctx, &scene, &gpu_scene, RenderOptions::default()).unwrap();
    renderer.render(1000, |done| done < 3).unwrap();
    let partial = renderer.read_image().unwrap();
    assert!(partial.samples_per_pixel >= 3 && partial.samples_per_pixel < 1000);
    assert!(
        partial
            .pixels
            .iter()
            .all(|p| p.iter().all(|c| c.is_finite()))
            && mean(&partial) > 0.0
    );
    scene.settings.samples_per_pixel = 4;
    let again = render(ctx, &scene);
    assert_eq!(again.samples_per_pixel, 4);
}

/// 100,000 samples per pixel accumulate without drift: the running mean (updated one sample at a
/// time) of a random, unbiased estimate with a known value stays within 4 standard errors of it.
#[test]
fn a_hundred_thousand_samples_accumulate_without_drift() {
    let Some(ctx) = gpu() else { return };
    let spp = 100_000;
    let mut scene = scene(
        vec![object(
            "room",
            cuboid(Vec3::splat(-1.0), Vec3::splat(1.0), true),
            Material::lambertian([0.5; 3]),
        )],
        camera(Vec3::ZERO, -Vec3::Z, 60.0),
        [0.0; 3],
        settings(2, 2, spp, 10),
    );
    scene.settings.russian_roulette = true;
    let mut gpu_scene = GpuScene::build(&scene).unwrap();
    gpu_scene.materials[0].emission = [0.5; 3];
    let image = render_gpu(ctx, &scene, &gpu_scene, RenderOptions::default());
    assert_eq!(image.samples_per_pixel, spp);
    let expected = 1.0 - 0.5f64.powi(10);
    for p in &image.pixels {
        // Grey values: luminance = value, so w holds the mean of squares.
        let (m, m2) = (f64::from(p[0]), f64::from(p[3]));
        let std_error = ((m2 - m * m).max(0.0) / f64::from(spp)).sqrt();
        assert!(std_error > 0.0, "roulette should make the samples random");
        assert!(
            (m - expected).abs() <= 4.0 * std_error,
            "mean {m} vs {expected} (σ {std_error})"
        );
    }
}

/// An image whose accumulation buffer would not fit renders in bands of rows; the stitched image
/// is bit-identical to the untiled one (random numbers are keyed by the pixel's place in the whole
/// image), whatever the tile height, including one row per tile.
#[test]
fn tiled_renders_are_bit_identical_to_untiled_ones() {
    let Some(ctx) = gpu() else { return };
    let mut s = scene(
        lit_room(),
        camera(Vec3::new(0.0, 0.0, 1.9), Vec3::ZERO, 70.0),
        [0.0; 3],
        settings(37, 23, 3, 5),
    );
    s.settings.seed = 7;
    let gpu_scene = GpuScene::build(&s).unwrap();
    // With the denoiser's AOVs, which tiles must stitch too.
    let options = RenderOptions {
        aovs: true,
        ..Default::default()
    };
    let mut renderer = Renderer::for_scene(ctx, &s, &gpu_scene, options).unwrap();
    renderer.render(3, |_| true).unwrap();
    let whole = renderer.read_image().unwrap();
    let whole_aovs = renderer.read_aovs().unwrap().unwrap();
    for rows in [1u32, 5, 22] {
        let rt_gpu::TiledRender { image: tiled, aovs } = rt_gpu::render_tiled(
            ctx,
            (&s, &gpu_scene),
            options,
            3,
            Some(u64::from(rows) * 37 * rt_gpu::pixel_binding_bytes(&options)),
            |_| true,
        )
        .unwrap();
        assert_eq!((tiled.width, tiled.height), (37, 23));
        assert_eq!(tiled.samples_per_pixel, 3);
        assert!(
            tiled.pixels == whole.pixels && tiled.sums == whole.sums,
            "tiles of {rows} rows differ from the untiled image"
        );
        let aovs = aovs.unwrap();
        assert!(
            aovs.albedo == whole_aovs.albedo
                && aovs.normal == whole_aovs.normal
                && aovs.emission == whole_aovs.emission,
            "tiles of {rows} rows: the stitched AOVs differ from the untiled ones"
        );
    }
    // Tiles are sized by the largest per-pixel binding: the guides when the denoiser keeps them.
    assert_eq!(
        rt_gpu::pixel_binding_bytes(&options),
        rt_gpu::renderer::AOV_BYTES_PER_PIXEL
    );
    assert_eq!(rt_gpu::pixel_binding_bytes(&RenderOptions::default()), 16);
    assert_eq!(rt_gpu::tile_rows(16384, 16384, 16, 128 << 20), 512);
    assert_eq!(rt_gpu::tile_rows(2560, 1440, 48, 128 << 20), 1092);
    let whole = |options| rt_gpu::whole_image_binding_bytes(2560, 1440, options);
    assert!(whole(&options) > 128 << 20);
    assert!(whole(&RenderOptions::default()) <= 128 << 20);
}

/// The generic kernel (every feature compiled in) and other work-group shapes compute the same
/// image bit for bit as the specialised 8 x 8 default: specialisation only removes dead code, and
/// each pixel's samples do not depend on how pixels are grouped.
#[test]
fn generic_kernels_and_workgroup_shapes_give_identical_images() {
    let Some(ctx) = gpu() else { return };
    let mut s = rt_io::assets::cornell_box().unwrap();
    s.settings.width = 29;
    s.settings.height = 17;
    s.settings.samples_per_pixel = 3;
    let gpu_scene = GpuScene::build(&s).unwrap();
    // Work-group shapes are the megakernel's; the wavefront kernels are specialised too.
    let mega = RenderOptions {
        kernel: Kernel::Megakernel,
        ..Default::default()
    };
    let experiment = |kernel: Kernel, generic_kernel: bool, workgroup: [u32; 2]| RenderOptions {
        kernel,
        tuning: Tuning {
            generic_kernel,
            workgroup,
            ..Default::default()
        },
        ..Default::default()
    };
    let base = render_gpu(ctx, &s, &gpu_scene, mega);
    for options in [
        experiment(Kernel::Megakernel, true, [8, 8]),
        experiment(Kernel::Megakernel, false, [16, 4]),
        experiment(Kernel::Megakernel, true, [32, 1]),
        experiment(Kernel::Wavefront, true, [8, 8]),
    ] {
        let image = render_gpu(ctx, &s, &gpu_scene, options);
        assert!(image.pixels == base.pixels, "{options:?} changed the image");
    }
}

/// A work group too large for the traversal stacks in work-group memory, or a work-group shape
/// asked of the wavefront kernels (whose shape is fixed), is a clear error, not a validation panic
/// or a silently ignored option.
#[test]
fn an_impossible_work_group_is_a_clear_error() {
    let Some(ctx) = gpu() else { return };
    let s = rt_io::assets::cornell_box().unwrap();
    let gpu_scene = GpuScene::build(&s).unwrap();
    for (kernel, workgroup) in [
        (Kernel::Megakernel, [16, 16]),
        (Kernel::Megakernel, [0, 8]),
        (Kernel::Megakernel, [65, 1]),
        (Kernel::Wavefront, [16, 4]),
    ] {
        let options = RenderOptions {
            kernel,
            tuning: Tuning {
                workgroup,
                ..Default::default()
            },
            ..Default::default()
        };
        let Err(e) = rt_gpu::Renderer::for_scene(ctx, &s, &gpu_scene, options) else {
            panic!("{kernel:?} with work group {workgroup:?} was accepted");
        };
        assert!(
            matches!(e, rt_gpu::GpuError::Options(_)) && e.to_string().contains("work group"),
            "{e}"
        );
    }
}

/// A rebuilt pipeline (`Tuning::pipeline_rebuilds`, against lavapipe's memory growth:
/// `tests/memory.rs`) changes no sample: rebuilding before every batch gives the same bytes as
/// never rebuilding.
#[test]
fn rebuilding_the_pipeline_changes_no_sample() {
    let Some(ctx) = gpu() else { return };
    let mut scene = rt_io::assets::cornell_box().unwrap();
    scene.settings.width = 24;
    scene.settings.height = 24;
    let gpu_scene = GpuScene::build(&scene).unwrap();
    for kernel in [Kernel::Wavefront, Kernel::Megakernel] {
        let render = |lifetime: Duration| {
            let options = RenderOptions {
                max_samples_per_dispatch: Some(1),
                kernel,
                tuning: Tuning {
                    pipeline_rebuilds: rt_gpu::PipelineRebuilds::Every(lifetime),
                    ..Default::default()
                },
                ..Default::default()
            };
            let mut renderer = Renderer::for_scene(ctx, &scene, &gpu_scene, options).unwrap();
            renderer.render(12, |_| true).unwrap();
            (renderer.read_image().unwrap(), renderer.pipeline_rebuilds())
        };
        let (rebuilt, rebuilds) = render(Duration::ZERO);
        let (kept, kept_rebuilds) = render(Duration::from_secs(3600));
        assert!(rebuilds >= 11, "{kernel:?}: {rebuilds} rebuilds");
        assert_eq!(kept_rebuilds, 0);
        assert_eq!(rebuilt.samples_per_pixel, 12);
        assert!(
            rebuilt.pixels == kept.pixels,
            "{kernel:?}: images differ after pipeline rebuilds"
        );
    }
}
