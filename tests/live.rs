//! The interactive viewport's engine (`rt_gpu::live`) on a real device: the resolution ladder, exact
//! restarts, cancelling on a change, rebuilds per kind of change, the denoised view, and shutdown.

mod common;

use std::sync::Arc;
use std::time::{Duration, Instant};

use rt_gpu::live::{LiveFrame, LiveRequest, LiveSettings, LiveView, Rebuild};
use rt_gpu::{GpuContext, RenderOptions, Renderer};

fn start(settings: LiveSettings) -> Option<LiveView> {
    let ctx = Arc::new(GpuContext::for_tests()?);
    Some(LiveView::start(move || Ok(ctx), settings, || {}))
}

fn cornell(width: u32, height: u32) -> rt_core::Scene {
    let mut scene = rt_io::assets::cornell_box().unwrap();
    scene.settings.width = width;
    scene.settings.height = height;
    scene
}

fn request(view: &mut LiveView, scene: &rt_core::Scene) {
    view.request(LiveRequest {
        scene: scene.clone(),
        size: [scene.settings.width, scene.settings.height],
        interacting: false,
    });
}

/// Ticks like a 60 Hz UI until `done`, recording every raw image shown; panics after a minute.
fn tick_until(
    view: &mut LiveView,
    what: &str,
    mut done: impl FnMut(&LiveView) -> bool,
) -> Vec<(u32, u32)> {
    let started = Instant::now();
    let mut shown = Vec::new();
    loop {
        if view.tick()
            && let Some(raw) = view.raw()
            && shown.last() != Some(&(raw.pixel_size, raw.samples))
        {
            assert_eq!(
                raw.generation,
                view.generation(),
                "only the newest change shows"
            );
            shown.push((raw.pixel_size, raw.samples));
        }
        assert!(view.error().is_none(), "{:?}", view.error());
        if done(view) {
            return shown;
        }
        assert!(
            started.elapsed() < Duration::from_secs(120),
            "timed out waiting for {what}; shown so far: {shown:?}"
        );
        std::thread::sleep(Duration::from_millis(16));
    }
}

/// Small views for speed, with the whole ladder from 8 (the default would start them finer).
fn small_view_settings() -> LiveSettings {
    LiveSettings {
        pixel_sizes: vec![8, 4, 2, 1],
        first_step_pixels: 0,
        ..Default::default()
    }
}

fn raw_settings() -> LiveSettings {
    LiveSettings {
        denoise: false,
        ..small_view_settings()
    }
}

/// The first image after a change is the coarsest step, each step follows once it has a sample, and
/// full resolution comes without input; the restarted renderer's full-resolution samples are
/// exactly a fresh render's (same pixels, bit for bit).
#[test]
fn a_change_starts_coarse_refines_by_itself_and_restarts_exactly() {
    let Some(mut view) = start(raw_settings()) else {
        return;
    };
    let scene = cornell(96, 64);
    request(&mut view, &scene);
    // The GPU's own images: the CPU backend shows the first ones while its kernel compiles.
    let shown = tick_until(&mut view, "full resolution with 3 GPU samples", |v| {
        v.raw()
            .is_some_and(|r| r.pixel_size == 1 && r.samples >= 3 && !r.while_compiling)
    });
    assert_eq!(
        shown[0].0, 8,
        "the first image is the coarsest step: {shown:?}"
    );
    assert!(
        shown.windows(2).all(|w| w[1].0 <= w[0].0),
        "steps only get finer: {shown:?}"
    );
    for size in [8, 4, 2] {
        assert!(
            shown.iter().any(|s| s.0 == size),
            "step {size} was shown: {shown:?}"
        );
    }
    let raw = view.raw().unwrap().clone();
    assert_eq!((raw.width, raw.height), (96, 64));
    assert_eq!(raw.rebuild, Rebuild::Geometry);

    // A fresh renderer with the same samples gives the same image.
    let ctx = common::gpu().unwrap();
    let gpu_scene = rt_core::GpuScene::build(&scene).unwrap();
    let options = RenderOptions {
        aovs: true,
        ..Default::default()
    };
    let mut fresh = Renderer::for_scene(ctx, &scene, &gpu_scene, options).unwrap();
    fresh.render(raw.samples, |_| true).unwrap();
    let reference = fresh.read_image().unwrap();
    assert_eq!(reference.samples_per_pixel, raw.samples);
    assert!(
        reference.rgb() == raw.pixels,
        "the restarted renderer's image differs from a fresh render's"
    );
    assert!(view.shut_down(Duration::from_secs(30)), "the threads end");
}

/// A view on a GPU whose kernel is not yet compiled shows the CPU backend's images at once (the
/// CPU backend's exact samples) while the kernel compiles on another thread; the GPU then takes
/// over without showing fewer samples than the CPU had; a later change finds the kernel compiled
/// and starts on the GPU.
#[test]
fn the_cpu_backend_stands_in_while_the_gpu_kernel_compiles() {
    // A new context: no kernel compiled on it yet.
    let Some(mut view) = start(raw_settings()) else {
        return;
    };
    let scene = cornell(48, 32);
    request(&mut view, &scene);
    tick_until(&mut view, "the first image", |v| v.raw().is_some());
    let first = view.raw().unwrap().clone();
    assert!(
        first.while_compiling,
        "the first image waited for the kernel"
    );
    let mut full_resolution = Vec::new();
    let mut stand_in = None;
    tick_until(&mut view, "the GPU's full-resolution image", |v| {
        if let Some(r) = v.raw().filter(|r| r.pixel_size == 1) {
            full_resolution.push((r.samples, r.while_compiling));
            if r.while_compiling && stand_in.is_none() {
                stand_in = Some(r.clone());
            }
        }
        v.raw()
            .is_some_and(|r| r.pixel_size == 1 && !r.while_compiling)
    });
    assert!(
        full_resolution.windows(2).all(|w| w[1].0 >= w[0].0),
        "the GPU took over without showing fewer samples: {full_resolution:?}"
    );
    // The stand-in's image is the CPU backend's, exactly (when the compile outlasted the coarse
    // steps, as it does on lavapipe).
    if let Some(r) = stand_in {
        let gpu_scene = rt_core::GpuScene::build(&scene).unwrap();
        let frame = rt_core::frame::frame_for(&scene, &gpu_scene).unwrap();
        let mut cpu = rt_core::cpu_render::CpuAccumulation::new(&frame, 0, None, false);
        let go = std::sync::atomic::AtomicBool::new(false);
        assert!(cpu.add_batch(&gpu_scene, &frame, r.samples, &go));
        let expected: Vec<[f32; 3]> = cpu.pixels().iter().map(|p| [p[0], p[1], p[2]]).collect();
        assert!(
            expected == r.pixels,
            "the stand-in's image at {} spp",
            r.samples
        );
    }

    let mut moved = scene.clone();
    moved.camera.vfov_deg += 5.0;
    request(&mut view, &moved);
    let generation = view.generation();
    tick_until(&mut view, "an image of the change", |v| {
        v.raw().is_some_and(|r| r.generation == generation)
    });
    assert!(
        !view.raw().unwrap().while_compiling,
        "the compiled kernel serves the next change"
    );
    assert!(view.shut_down(Duration::from_secs(30)));
}

/// A camera move reuses the GPU scene, a material edit restyles it (no BVH build), a transform
/// rebuilds it; each restarts at the coarsest step.
#[test]
fn each_kind_of_change_rebuilds_only_what_it_must() {
    let Some(mut view) = start(raw_settings()) else {
        return;
    };
    let mut scene = cornell(64, 64);
    let first_of = |view: &mut LiveView, scene: &rt_core::Scene| -> LiveFrame {
        request(view, scene);
        tick_until(view, "the first image", |v| v.raw().is_some());
        view.raw().unwrap().clone()
    };
    assert_eq!(first_of(&mut view, &scene).rebuild, Rebuild::Geometry);
    scene.camera.vfov_deg = 30.0;
    let moved = first_of(&mut view, &scene);
    assert_eq!((moved.rebuild, moved.pixel_size), (Rebuild::Nothing, 8));
    scene.objects[0].material = rt_core::Material::Metal {
        albedo: [0.9, 0.9, 0.9],
        fuzz: 0.2,
    };
    assert_eq!(first_of(&mut view, &scene).rebuild, Rebuild::Shading);
    scene.objects[0].transform.scale = [0.9; 3];
    assert_eq!(first_of(&mut view, &scene).rebuild, Rebuild::Geometry);
}

/// A change while a slice runs stops the old work: nothing of the old change is shown after it,
/// and the new change's first image is the new scene's.
#[test]
fn a_change_during_a_slice_cancels_it_and_shows_nothing_stale() {
    let Some(mut view) = start(raw_settings()) else {
        return;
    };
    let mut scene = cornell(256, 256);
    request(&mut view, &scene);
    tick_until(&mut view, "full resolution", |v| {
        v.raw().is_some_and(|r| r.pixel_size == 1)
    });
    let before = view.generation();
    // Move the camera repeatedly, a frame apart, as a drag does.
    for step in 0..5 {
        scene.camera.from[0] += 0.05 * step as f32;
        request(&mut view, &scene);
        view.tick();
        assert!(
            view.raw().is_none_or(|r| r.generation == view.generation()),
            "an image of an earlier change was shown"
        );
        std::thread::sleep(Duration::from_millis(16));
    }
    assert_eq!(view.generation(), before + 5);
    assert!(
        view.previous().is_some(),
        "the old image stays up, marked as previous"
    );
    tick_until(&mut view, "the newest change's first image", |v| {
        v.raw().is_some()
    });
    let first = view.raw().unwrap();
    assert_eq!(first.generation, view.generation());
    assert_eq!(first.pixel_size, 8);
    assert!(view.previous().is_none());
}

/// The denoised view arrives for the newest change and names its denoiser: OIDN where it loads.
#[test]
fn the_denoised_view_arrives_and_names_its_denoiser() {
    let Some(mut view) = start(small_view_settings()) else {
        return;
    };
    let scene = cornell(64, 48);
    request(&mut view, &scene);
    tick_until(&mut view, "a denoised full-resolution image", |v| {
        v.denoised().is_some_and(|d| d.pixel_size == 1)
    });
    let denoised = view.denoised().unwrap();
    let expected = match rt_core::oidn::Oidn::get() {
        Ok(_) => rt_core::denoiser::Denoiser::Oidn,
        Err(_) => rt_core::denoiser::Denoiser::Atrous,
    };
    assert_eq!(denoised.denoiser, Some(expected));
    assert_eq!(
        view.display().map(|d| d.denoiser),
        Some(Some(expected)),
        "the view shows the denoised image by default"
    );
    view.show_denoised = false;
    assert_eq!(
        view.display().map(|d| d.denoiser),
        Some(None),
        "raw one click away"
    );
    assert!(view.shut_down(Duration::from_secs(30)));
}

/// The view on the native CPU backend (a machine without a GPU): no adapter needed; it starts
/// coarse, refines to full resolution, denoises, and its full-resolution samples are exactly the
/// CPU backend's for the same frame (the same sums: a restart per step loses nothing); a change
/// restarts it.
#[test]
fn the_cpu_view_refines_denoises_and_equals_the_cpu_backend() {
    let mut view = LiveView::start_on_cpu(small_view_settings(), || {});
    let scene = cornell(48, 32);
    request(&mut view, &scene);
    let shown = tick_until(&mut view, "full resolution with 2 samples, denoised", |v| {
        v.raw().is_some_and(|r| r.pixel_size == 1 && r.samples >= 2)
            && v.denoised().is_some_and(|d| d.pixel_size == 1)
    });
    // A small view's coarse steps take well under a UI frame here: the ticks see some of them.
    assert!(
        shown.windows(2).all(|w| w[1].0 <= w[0].0),
        "steps only get finer: {shown:?}"
    );
    let raw = view.raw().unwrap().clone();
    assert_eq!((raw.width, raw.height), (48, 32));

    let gpu_scene = rt_core::GpuScene::build(&scene).unwrap();
    let frame = rt_core::frame::frame_for(&scene, &gpu_scene).unwrap();
    let mut cpu = rt_core::cpu_render::CpuAccumulation::new(&frame, 0, None, false);
    let go = std::sync::atomic::AtomicBool::new(false);
    assert!(cpu.add_batch(&gpu_scene, &frame, raw.samples, &go));
    let expected = cpu.pixels();
    assert!(expected.iter().any(|p| p[0] > 0.0), "all black");
    for (i, (v, e)) in raw.pixels.iter().zip(&expected).enumerate() {
        assert_eq!(v, &[e[0], e[1], e[2]], "pixel {i} at {} spp", raw.samples);
    }

    let mut moved = scene.clone();
    moved.camera.vfov_deg += 5.0;
    request(&mut view, &moved);
    let generation = view.generation();
    tick_until(&mut view, "an image of the change", |v| {
        v.raw().is_some_and(|r| r.generation == generation)
    });
    assert!(view.shut_down(Duration::from_secs(30)));
}
