//! Device faults mid-render (a lost device, out of memory, a batch failing part way): a clear
//! error, and no sample lost.

use super::*;

/// A context of its own (for faults that must not disturb the other tests) and a 16 x 16 Cornell
/// box.
fn own_context_and_small_cornell() -> (rt_gpu::GpuContext, rt_core::Scene, GpuScene) {
    let ctx = rt_gpu::GpuContext::new(&rt_gpu::AdapterChoice::Software).unwrap();
    let mut s = rt_io::assets::cornell_box().unwrap();
    s.settings.width = 16;
    s.settings.height = 16;
    let gpu_scene = GpuScene::build(&s).unwrap();
    (ctx, s, gpu_scene)
}

/// A device lost mid-render (simulated with `Device::destroy`) makes the next batch and readback
/// return errors, not panic; the image read back before the loss is intact, so it can be saved.
#[test]
fn a_lost_device_is_an_error_and_earlier_readbacks_stay_usable() {
    if gpu().is_none() {
        return;
    }
    let (ctx, s, gpu_scene) = own_context_and_small_cornell();
    let mut renderer =
        rt_gpu::Renderer::for_scene(&ctx, &s, &gpu_scene, RenderOptions::default()).unwrap();
    renderer.render_batch(2).unwrap();
    let before = renderer.read_image().unwrap();
    assert!(before.channel_means()[0] > 0.0);
    ctx.device.destroy();
    let batch = renderer.render_batch(2);
    let read = renderer.read_image();
    assert!(
        batch.is_err() || read.is_err(),
        "a destroyed device went unnoticed"
    );
    let message = batch.err().or(read.err()).unwrap().to_string();
    assert!(
        message.to_lowercase().contains("lost")
            || message.to_lowercase().contains("destroy")
            || message.to_lowercase().contains("invalid"),
        "{message}"
    );
}

/// Out of memory mid-render (injected: `GpuContext::inject_out_of_memory` fails the next GPU
/// operation as an allocation would) is a clear error, not a panic; nothing rendered before is
/// lost (the accumulation reads back unchanged), and the render can go on once memory allows.
#[test]
fn out_of_memory_mid_render_is_an_error_and_loses_no_samples() {
    if gpu().is_none() {
        return;
    }
    let (ctx, s, gpu_scene) = own_context_and_small_cornell();
    for options in [
        RenderOptions::default(),
        RenderOptions {
            kernel: Kernel::Megakernel,
            ..Default::default()
        },
    ] {
        let mut renderer = rt_gpu::Renderer::for_scene(&ctx, &s, &gpu_scene, options).unwrap();
        renderer.render_batch(2).unwrap();
        let before = renderer.read_image().unwrap();
        assert!(before.channel_means()[0] > 0.0);
        ctx.inject_out_of_memory(1);
        let error = renderer.render_batch(2).unwrap_err();
        assert!(
            matches!(error, rt_gpu::GpuError::OutOfMemory(_))
                && error.to_string().contains("ran out of memory"),
            "{error}"
        );
        let after = renderer.read_image().unwrap();
        assert_eq!(after.samples_per_pixel, before.samples_per_pixel);
        assert!(
            after.pixels == before.pixels,
            "the failed batch changed the image"
        );
        // A batch takes up to 2 samples (how many depends on the measured speed).
        let batch = renderer.render_batch(2).unwrap();
        assert!(batch.samples >= 1);
        assert_eq!(
            renderer.samples_done(),
            before.samples_per_pixel + batch.samples
        );
    }
}

/// A batch that fails part-way (out of memory injected while its bands of rows are being
/// rendered) is finished by the next one: the render then goes on to the same image, bit for bit,
/// as one that never failed; no band gets a sample twice. (A first batch would hide the bug: it
/// starts every pixel's mean afresh.) The failure is injected at many points of the batch, without
/// knowing how many GPU operations a band takes; a failure that left some rows rendered and others
/// not (seen in the image read back after it) must occur among them.
#[test]
fn a_batch_failing_part_way_is_finished_by_the_next() {
    if gpu().is_none() {
        return;
    }
    let (ctx, mut s, _) = own_context_and_small_cornell();
    s.settings.width = 64;
    s.settings.height = 20;
    s.settings.samples_per_pixel = 3;
    let gpu_scene = GpuScene::build(&s).unwrap();
    // With adaptive sampling too: its waves walk the list of pixels still sampling, 64 at a time.
    s.settings.adaptive_min_samples = 2;
    for (kernel, adaptive) in [
        (Kernel::Wavefront, None),
        (Kernel::Megakernel, None),
        (Kernel::Wavefront, Some(0.3)),
    ] {
        s.settings.adaptive_threshold = adaptive;
        // A 1 µs target shrinks batches after the first to one sample in bands of one row.
        let options = RenderOptions {
            kernel,
            target_dispatch: Duration::from_micros(1),
            ..Default::default()
        };
        let clean = render_gpu(&ctx, &s, &gpu_scene, options);
        let mut failed_part_way = false;
        for operations in [2, 3, 5, 8, 13, 21, 34, 55, 89] {
            let mut renderer = rt_gpu::Renderer::for_scene(&ctx, &s, &gpu_scene, options).unwrap();
            renderer.render_batch(1).unwrap();
            let before = renderer.read_image().unwrap();
            ctx.inject_out_of_memory(operations);
            let Err(error) = renderer.render_batch(1) else {
                // The batch ended before the failure: disarm it for the next renderer.
                ctx.inject_out_of_memory(0);
                continue;
            };
            assert!(
                matches!(error, rt_gpu::GpuError::OutOfMemory(_)),
                "{kernel:?}: {error}"
            );
            // A failure in the batch's last operation (reading its counters back) comes after
            // every band has its sample.
            assert!(
                matches!(renderer.samples_done(), 1 | 2),
                "{kernel:?}: {} samples",
                renderer.samples_done()
            );
            let after = renderer.read_image().unwrap();
            let rows_changed = (0..20)
                .filter(|y| {
                    let row = y * 64..(y + 1) * 64;
                    after.pixels[row.clone()] != before.pixels[row]
                })
                .count();
            // With adaptive sampling the image shows whole batches only (its two streams take
            // a batch at a time): the renderer says whether one waits to be finished.
            failed_part_way |= if adaptive.is_some() {
                renderer.batch_unfinished() && rows_changed == 0
            } else {
                rows_changed > 0 && rows_changed < 20
            };
            renderer.render(3, |_| true).unwrap();
            let resumed = renderer.read_image().unwrap();
            assert_eq!(resumed.samples_per_pixel, 3);
            assert!(
                resumed.pixels == clean.pixels && resumed.sample_counts == clean.sample_counts,
                "{kernel:?}, adaptive {adaptive:?}, failing at GPU operation {operations}: the \
                 resumed render differs from one that never failed"
            );
        }
        assert!(
            failed_part_way,
            "{kernel:?}: no injected failure landed part-way through a batch"
        );
    }
}
