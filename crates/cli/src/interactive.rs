//! `rt-cli bench --interactive`: the path-traced viewport's engine (`rt_gpu::live`, the code the
//! editor runs) driven by a simulated 60 Hz UI, headless. Per scene it measures the time from a
//! camera change to the first new image, the UI frame intervals while the view refines, the
//! samples after 5 s and 30 s, and (with a reference) the relMSE of the denoised and raw view.
//!
//! The simulated UI does on its thread what the editor's does each frame for the view (take in the
//! threads' images, copy the one to show into a texture image) and sleeps to the next 60 Hz
//! deadline; a frame interval above 16.7 ms is time the UI thread did not get the CPU.

use std::path::{Path, PathBuf};
use std::sync::Arc;
use std::time::{Duration, Instant};

use anyhow::{Context, Result};
use rt_core::Scene;
use rt_core::metrics::{RgbImage, compare};
use rt_gpu::live::{LiveRequest, LiveSettings, LiveView};
use rt_gpu::progressive::Progressive;
use rt_gpu::{GpuContext, RenderOptions, Renderer};

const FRAME: Duration = Duration::from_nanos(16_666_667);

/// What `--interactive` takes from `bench`'s arguments.
pub struct InteractiveArgs {
    pub size: [u32; 2],
    pub seconds: f64,
    pub reference_dir: Option<PathBuf>,
    pub reference_spp: u32,
    /// Run the view without its denoiser (to measure what denoising costs).
    pub no_denoise: bool,
    pub kernel: rt_gpu::Kernel,
}

/// A 60 Hz UI loop's record.
#[derive(Default)]
struct Frames {
    intervals: Vec<Duration>,
    work: Vec<Duration>,
    last: Option<Instant>,
}

impl Frames {
    /// One UI frame: tick the view, copy a changed image as a texture upload would, wait for the
    /// next frame.
    fn frame(&mut self, view: &mut LiveView) {
        let started = Instant::now();
        if let Some(last) = self.last {
            self.intervals.push(started - last);
        }
        self.last = Some(started);
        if view.tick()
            && let Some(shown) = view.display()
        {
            // egui's ColorImage::from_rgba_unmultiplied: a pass over the pixels into Color32s.
            let texture: Vec<[u8; 4]> = shown
                .rgba8
                .chunks_exact(4)
                .map(|p| [p[0], p[1], p[2], p[3]])
                .collect();
            std::hint::black_box(texture);
        }
        let work = started.elapsed();
        self.work.push(work);
        if let Some(rest) = FRAME.checked_sub(work) {
            std::thread::sleep(rest);
        }
    }

    fn take(&mut self) -> Frames {
        std::mem::take(self)
    }
}

pub fn percentile(values: &[Duration], p: f64) -> Duration {
    if values.is_empty() {
        return Duration::ZERO;
    }
    let mut sorted = values.to_vec();
    sorted.sort();
    sorted[((sorted.len() - 1) as f64 * p).round() as usize]
}

pub fn ms(d: Duration) -> f64 {
    d.as_secs_f64() * 1e3
}

/// The camera orbited by `degrees` about the vertical through its target.
pub fn orbit(scene: &Scene, degrees: f32) -> Scene {
    let mut scene = scene.clone();
    let to = glam::Vec3::from(scene.camera.to);
    let offset = glam::Vec3::from(scene.camera.from) - to;
    let turned = glam::Quat::from_rotation_y(degrees.to_radians()) * offset;
    scene.camera.from = (to + turned).to_array();
    scene
}

fn request(view: &mut LiveView, scene: &Scene, size: [u32; 2], interacting: bool) {
    let mut scene = scene.clone();
    scene.settings.width = size[0];
    scene.settings.height = size[1];
    view.request(LiveRequest {
        scene,
        size,
        interacting,
    });
}

fn until(
    view: &mut LiveView,
    frames: &mut Frames,
    limit: Duration,
    mut done: impl FnMut(&LiveView) -> bool,
) -> Result<bool> {
    let started = Instant::now();
    while started.elapsed() < limit {
        frames.frame(view);
        if let Some(e) = view.error() {
            anyhow::bail!("the viewport failed: {e}");
        }
        if done(view) {
            return Ok(true);
        }
    }
    Ok(false)
}

/// The scene's reference at the view's size: read from the reference folder, or rendered there
/// first with `reference_spp` samples.
fn reference(
    ctx: Option<&GpuContext>,
    name: &str,
    scene: &Scene,
    args: &InteractiveArgs,
) -> Result<Option<RgbImage>> {
    let Some(dir) = &args.reference_dir else {
        return Ok(None);
    };
    let path = reference_name(dir, name, args.size);
    if !path.exists() {
        if args.reference_spp == 0 {
            eprintln!(
                "{name}: no reference {} (pass --reference-spp N to render one)",
                path.display()
            );
            return Ok(None);
        }
        std::fs::create_dir_all(dir).with_context(|| format!("creating {}", dir.display()))?;
        let mut scene = scene.clone();
        scene.settings.width = args.size[0];
        scene.settings.height = args.size[1];
        eprintln!(
            "{name}: rendering the reference ({} spp) into {}",
            args.reference_spp,
            path.display()
        );
        // A reference takes every sample in every pixel.
        scene.settings.adaptive_threshold = None;
        let gpu_scene = rt_core::GpuScene::build(&scene)?;
        let mut run = match ctx {
            Some(ctx) => Progressive::Gpu(Box::new(Renderer::for_scene(
                ctx,
                &scene,
                &gpu_scene,
                RenderOptions::default(),
            )?)),
            None => Progressive::cpu(&scene, &gpu_scene, 0, false)?,
        };
        run.render(args.reference_spp)?;
        let pixels = run.read_image()?.rgb();
        rt_core::output::save_image(
            &path,
            args.size[0],
            args.size[1],
            &pixels,
            rt_core::output::View::default(),
        )?;
    }
    Ok(Some(RgbImage::load(&path)?))
}

fn rel_mse(pixels: &[[f32; 3]], size: [u32; 2], reference: &RgbImage) -> Option<f64> {
    let image = RgbImage {
        width: size[0],
        height: size[1],
        pixels: pixels.to_vec(),
    };
    compare(&image, reference).ok().map(|e| e.rel_mse)
}

/// Runs the measurement on each scene and prints one block per scene: on `ctx`'s GPU, or on the
/// native CPU backend without one (as the editor's view runs where that is the device).
pub fn run(
    ctx: Option<GpuContext>,
    suite: Vec<(String, Scene)>,
    args: &InteractiveArgs,
) -> Result<()> {
    let ctx = ctx.map(Arc::new);
    let cores = std::thread::available_parallelism().map_or(0, |n| n.get());
    println!(
        "interactive viewport, {}x{}, {}, {cores} cores, denoiser {}",
        args.size[0],
        args.size[1],
        ctx.as_ref()
            .map_or_else(rt_gpu::progressive::cpu_label, |c| format!(
                "adapter {}",
                c.adapter_label()
            )),
        match rt_core::oidn::Oidn::get() {
            Ok(o) => format!("Open Image Denoise ({})", o.path().display()),
            Err(_) => "À-Trous (OIDN not installed)".into(),
        }
    );
    for (name, scene) in suite {
        let reference = reference(ctx.as_deref(), &name, &scene, args)?;
        measure(ctx.as_ref(), &name, &scene, args, reference.as_ref())?;
    }
    Ok(())
}

fn measure(
    ctx: Option<&Arc<GpuContext>>,
    name: &str,
    scene: &Scene,
    args: &InteractiveArgs,
    reference: Option<&RgbImage>,
) -> Result<()> {
    let size = args.size;
    let settings = LiveSettings {
        denoise: !args.no_denoise,
        kernel: args.kernel,
        ..Default::default()
    };
    let mut view = match ctx {
        Some(ctx) => {
            let shared = ctx.clone();
            LiveView::start(move || Ok(shared), settings, || {})
        }
        None => LiveView::start_on_cpu(settings, || {}),
    };
    let mut frames = Frames::default();

    // Opening: builds the GPU scene and compiles the pipelines (lavapipe caches them on disk),
    // the CPU backend showing the first images meanwhile; waits for the GPU's images, so that the
    // drag below measures the device asked for.
    let opening = Instant::now();
    let mut device_images_after = None;
    let mut stood_in = false;
    request(&mut view, scene, size, false);
    until(&mut view, &mut frames, Duration::from_secs(600), |v| {
        stood_in |= v.raw().is_some_and(|f| f.while_compiling);
        if device_images_after.is_none() && v.raw().is_some_and(|f| !f.while_compiling) {
            device_images_after = Some(opening.elapsed());
        }
        device_images_after.is_some() && v.display().is_some_and(|f| f.pixel_size == 1)
    })?;
    let opened = view.first_image_after().unwrap_or_default();
    frames.take();

    // A drag: ten camera steps 100 ms apart, out and back to the start.
    let mut drag = Vec::new();
    let mut angle = 0.0;
    for step in 0..10 {
        angle += if step < 5 { 3.0 } else { -3.0 };
        let last = step == 9;
        request(&mut view, &orbit(scene, angle), size, !last);
        let limit = if last {
            FRAME
        } else {
            Duration::from_millis(100)
        };
        let started = Instant::now();
        while started.elapsed() < limit {
            frames.frame(&mut view);
        }
        if !last {
            drag.push(view.first_image_after());
        }
    }
    let drag_frames = frames.take();

    // Release at the start's camera: refine for `seconds`.
    let released = Instant::now();
    let mut first_after_release = None;
    let mut full_after = None;
    let mut at_5s = None;
    let limit = Duration::from_secs_f64(args.seconds);
    until(&mut view, &mut frames, limit, |v| {
        if first_after_release.is_none() {
            first_after_release = v.first_image_after();
        }
        if full_after.is_none() && v.raw().is_some_and(|f| f.pixel_size == 1) {
            full_after = Some(released.elapsed());
        }
        if at_5s.is_none() && released.elapsed() >= Duration::from_secs(5) {
            at_5s = v.raw().map(|f| f.samples);
        }
        false
    })?;
    let refine = frames.take();
    let raw = view.raw().context("no image after refining")?.clone();
    let denoised = view.denoised().cloned();

    let answered = drag.iter().flatten().copied().collect::<Vec<_>>();
    println!("\n{name} ({} triangles)", scene.triangle_count());
    let mut opening_line = format!("  opening: first image {:.0} ms", ms(opened));
    if stood_in {
        opening_line += &format!(
            " (the CPU backend's, while the GPU's kernel compiled), the GPU's images after {:.0} ms",
            ms(device_images_after.unwrap_or_default())
        );
    }
    println!("{opening_line}");
    println!(
        "  drag, a change each 100 ms: {}/{} changes got an image within 100 ms; change -> first \
         image median {:.0} ms, max {:.0} ms; UI frame median {:.1} ms, p95 {:.1} ms",
        answered.len(),
        drag.len(),
        ms(percentile(&answered, 0.5)),
        ms(percentile(&answered, 1.0)),
        ms(percentile(&drag_frames.intervals, 0.5)),
        ms(percentile(&drag_frames.intervals, 0.95)),
    );
    println!(
        "  release -> first image {:.0} ms, full resolution after {:.2} s",
        ms(first_after_release.unwrap_or_default()),
        full_after.unwrap_or_default().as_secs_f64()
    );
    println!(
        "  refining {:.0} s: UI frame median {:.1} ms, p95 {:.1} ms, max {:.1} ms (UI work p95 \
         {:.2} ms); spp after 5 s {}, after {:.0} s {}",
        args.seconds,
        ms(percentile(&refine.intervals, 0.5)),
        ms(percentile(&refine.intervals, 0.95)),
        ms(percentile(&refine.intervals, 1.0)),
        ms(percentile(&refine.work, 0.95)),
        at_5s.map_or("-".into(), |n| n.to_string()),
        args.seconds,
        raw.samples
    );
    if let Some(reference) = reference {
        let raw_error = rel_mse(&raw.pixels, size, reference);
        let denoised_error = denoised
            .as_ref()
            .filter(|d| d.pixel_size == 1)
            .and_then(|d| rel_mse(&d.pixels, size, reference));
        println!(
            "  relMSE at {:.0} s against the reference: raw {} ({} spp), denoised {} ({}, {} spp)",
            args.seconds,
            raw_error.map_or("-".into(), |e| format!("{e:.4}")),
            raw.samples,
            denoised_error.map_or("-".into(), |e| format!("{e:.4}")),
            denoised
                .as_ref()
                .and_then(|d| d.denoiser)
                .map_or("none", |d| d.name()),
            denoised.as_ref().map_or(0, |d| d.samples),
        );
    }
    if !view.shut_down(Duration::from_secs(30)) {
        eprintln!("{name}: the viewport's threads did not stop within 30 s");
    }
    Ok(())
}

/// `WxH`: the interactive view's size.
pub fn parse_size(s: &str) -> Result<[u32; 2], String> {
    crate::options::parse_pair(s, "1280x720", 16384, "a size")
}

/// `DIR/NAME-WxH.exr`.
fn reference_name(dir: &Path, name: &str, size: [u32; 2]) -> PathBuf {
    dir.join(format!("{name}-{}x{}.exr", size[0], size[1]))
}
