//! The viewport's render thread and denoise thread.

use std::sync::atomic::{AtomicU64, Ordering};
use std::sync::mpsc::{Receiver, RecvTimeoutError, Sender, TryRecvError};
use std::sync::{Arc, Condvar, Mutex};
use std::thread::JoinHandle;
use std::time::{Duration, Instant};

use rt_core::{GpuScene, Scene};

use super::backend::LiveRenderer;
use super::ladder::Ladder;
use super::scenes::{Rebuild, SceneCache};
use super::slicing::{SliceClock, dispatch_target};
use super::{Event, LiveFrame, LiveRequest, LiveSettings, Message, Shared};
use crate::{Aovs, GpuContext, Image, RenderOptions};

/// A denoise to run: the newest image of a step and its guides.
struct DenoiseJob {
    generation: u64,
    pixel_size: u32,
    image: Image,
    aovs: Aovs,
    elapsed: Duration,
    rebuild: Rebuild,
    while_compiling: bool,
}

/// How often an idle view looks whether the GPU's kernel it waits for has compiled.
const COMPILE_POLL: Duration = Duration::from_millis(50);

/// The one-slot queue between the render and the denoise thread: a newer job replaces one not yet
/// started, so the denoiser never falls behind.
#[derive(Default)]
struct DenoiseSlot {
    job: Mutex<(Option<DenoiseJob>, bool)>,
    ready: Condvar,
    /// How long the last denoise took, in microseconds (paces the next).
    last_micros: AtomicU64,
}

impl DenoiseSlot {
    fn put(&self, job: DenoiseJob) {
        if let Ok(mut slot) = self.job.lock() {
            slot.0 = Some(job);
        }
        self.ready.notify_one();
    }

    fn close(&self) {
        if let Ok(mut slot) = self.job.lock() {
            slot.1 = true;
        }
        self.ready.notify_one();
    }

    /// The next job, or `None` once closed.
    fn take(&self) -> Option<DenoiseJob> {
        let mut slot = self.job.lock().ok()?;
        loop {
            if slot.1 {
                return None;
            }
            if let Some(job) = slot.0.take() {
                return Some(job);
            }
            slot = self.ready.wait(slot).ok()?;
        }
    }

    fn last(&self) -> Duration {
        Duration::from_micros(self.last_micros.load(Ordering::Relaxed))
    }
}

/// `open` gives the GPU the view renders on, or `None` for the native CPU backend.
pub(super) fn spawn(
    open: impl FnOnce() -> Result<Option<Arc<GpuContext>>, String> + Send + 'static,
    settings: LiveSettings,
    inbox: Receiver<Message>,
    outbox: Sender<Event>,
    shared: Arc<Shared>,
    wake: Arc<dyn Fn() + Send + Sync>,
) -> std::io::Result<Vec<JoinHandle<()>>> {
    let slot = Arc::new(DenoiseSlot::default());
    let denoiser = {
        let (slot, shared, outbox, wake) =
            (slot.clone(), shared.clone(), outbox.clone(), wake.clone());
        let settings = settings.clone();
        std::thread::Builder::new()
            .name("rt-live-denoise".into())
            .spawn(move || denoise_loop(&settings, &slot, &shared, &outbox, &*wake))?
    };
    let render = std::thread::Builder::new()
        .name("rt-live-render".into())
        .spawn(move || {
            let result = open().and_then(|ctx| {
                let mut thread = RenderThread {
                    ctx: ctx.as_deref(),
                    gpu: ctx.clone(),
                    compiling: None,
                    settings,
                    shared: &shared,
                    outbox: &outbox,
                    slot: &slot,
                    wake: &*wake,
                    scenes: SceneCache::default(),
                };
                thread.run(&inbox)
            });
            if let Err(message) = result {
                let _ = outbox.send(Event::Failed(message));
            }
            slot.close();
            wake();
        })?;
    Ok(vec![render, denoiser])
}

fn denoise_loop(
    settings: &LiveSettings,
    slot: &DenoiseSlot,
    shared: &Shared,
    outbox: &Sender<Event>,
    wake: &dyn Fn(),
) {
    let threads = settings.denoise_threads.unwrap_or_else(|| {
        let cores = std::thread::available_parallelism().map_or(2, |n| n.get() as u32);
        (cores / 2).max(1)
    });
    while let Some(job) = slot.take() {
        if !shared.current(job.generation) {
            continue;
        }
        let started = Instant::now();
        let generation = job.generation;
        let result =
            job.image
                .denoised_limited(&job.aovs, settings.denoiser, Some(threads), &|| {
                    shared.current(generation)
                });
        slot.last_micros
            .store(started.elapsed().as_micros() as u64, Ordering::Relaxed);
        match result {
            Ok(denoised) => {
                log::debug!(
                    "live: denoised {}x{} in {:.1?}",
                    job.image.width,
                    job.image.height,
                    started.elapsed()
                );
                let mut frame = LiveFrame::new(
                    job.generation,
                    job.pixel_size,
                    (job.image.width, job.image.height),
                    denoised.pixels,
                    job.image.samples_per_pixel,
                    job.elapsed,
                    job.rebuild,
                );
                frame.noise = noise_of(&job.image);
                frame.denoiser = Some(denoised.denoiser);
                frame.fallback = denoised.fallback;
                frame.while_compiling = job.while_compiling;
                if outbox.send(Event::Denoised(frame)).is_err() {
                    return;
                }
            }
            Err(e) if e == rt_core::oidn::CANCELLED => {
                log::debug!(
                    "live: a stale denoise stopped after {:.1?}",
                    started.elapsed()
                );
            }
            // The raw image stays on screen.
            Err(e) => log::warn!("the viewport's denoiser failed: {e}"),
        }
        shared.wake(wake);
    }
}

/// One change being rendered.
struct Job {
    generation: u64,
    scene: Scene,
    size: [u32; 2],
    gpu_scene: Arc<GpuScene>,
    rebuild: Rebuild,
    ladder: Ladder,
    started: Instant,
    /// When this step's image was last sent, and its samples then.
    last_shown: Option<(Instant, u32)>,
    /// When this step was last queued for the denoiser, and its samples then.
    last_denoise: Option<(Instant, u32)>,
    done: bool,
    /// Where the time went (for the debug log): path tracing, waiting for UI frames, reading back.
    spent: [Duration; 3],
    /// What the last image cost to read back and send.
    show_cost: Duration,
    /// No slice has run yet.
    fresh: bool,
    /// Images of this step are not shown below this many samples: the GPU took the step over
    /// from the CPU backend, which had shown that many.
    hold_below: u32,
}

struct RenderThread<'a> {
    /// The GPU; `None`: the CPU backend renders.
    ctx: Option<&'a GpuContext>,
    /// The same, for the thread that compiles its kernels.
    gpu: Option<Arc<GpuContext>>,
    /// A GPU kernel being compiled (`Renderer`s wait for none: the CPU backend stands in).
    compiling: Option<JoinHandle<Result<(), String>>>,
    settings: super::LiveSettings,
    shared: &'a Shared,
    outbox: &'a Sender<Event>,
    slot: &'a DenoiseSlot,
    wake: &'a dyn Fn(),
    scenes: SceneCache,
}

impl<'a> RenderThread<'a> {
    fn run(&mut self, inbox: &Receiver<Message>) -> Result<(), String> {
        let mut job: Option<Job> = None;
        let mut renderer: Option<(LiveRenderer<'a>, Arc<GpuScene>)> = None;
        let mut interacting = false;
        loop {
            // The newest request wins; block while there is nothing to render.
            let mut newest = None;
            let idle = job.as_ref().is_none_or(|j| j.done);
            let mut first = if idle {
                match self.next_message(inbox) {
                    Ok(m) => m,
                    Err(()) => return Ok(()),
                }
            } else {
                None
            };
            loop {
                let message = match first.take() {
                    Some(m) => m,
                    None => match inbox.try_recv() {
                        Ok(m) => m,
                        Err(TryRecvError::Empty) => break,
                        Err(TryRecvError::Disconnected) => return Ok(()),
                    },
                };
                match message {
                    Message::Request(request, generation) => {
                        interacting = request.interacting;
                        newest = Some((request, generation));
                    }
                    Message::Interacting(now) => {
                        interacting = now;
                        // Letting go of the mouse lets a held ladder go on.
                        if let Some(j) = job.as_mut() {
                            j.done = false;
                        }
                    }
                }
            }
            if self.shared.stop.load(Ordering::Relaxed) {
                return Ok(());
            }
            if let Some((request, generation)) = newest {
                if !self.shared.current(generation) {
                    continue;
                }
                job = Some(self.start(*request, generation)?);
                if let Some(j) = job.as_mut() {
                    self.prepare(j, &mut renderer)?;
                }
            }
            let Some(j) = job.as_mut() else { continue };
            if self.compiled()?
                && let Some((r, _)) = renderer.as_ref()
                && r.on_cpu()
            {
                let (_, full, options) = self.step(j)?;
                if self.kernel_ready(&full, &j.gpu_scene, options)? {
                    // The GPU takes the step over, shown once it has the samples the CPU had.
                    j.hold_below = r.samples_done();
                    j.done = false;
                    self.prepare(j, &mut renderer)?;
                } else {
                    // That compile was another scene's: this one's starts now.
                    self.compile(&full, &j.gpu_scene, options)?;
                }
            }
            if j.done || !self.shared.current(j.generation) {
                continue;
            }
            let Some((r, _)) = renderer.as_mut() else {
                continue;
            };
            // A new change's first slice does not wait: the UI has just drawn, and waits for it.
            if !j.fresh {
                let waited = Instant::now();
                self.shared.wait_for_ui(self.settings.frame_wait);
                j.spent[1] += waited.elapsed();
            }
            if !self.shared.current(j.generation) {
                continue;
            }
            if self.slice(j, r, interacting)? {
                j.hold_below = 0;
                self.prepare(j, &mut renderer)?;
            }
            j.fresh = false;
        }
    }

    /// A job for `request`, its GPU scene rebuilt as little as the change allows.
    fn start(&mut self, request: LiveRequest, generation: u64) -> Result<Job, String> {
        let started = Instant::now();
        let mut scene = request.scene;
        // Restarts keep the renderer, which adaptive sampling's per-pixel state would not allow.
        scene.settings.adaptive_threshold = None;
        let (gpu_scene, rebuild) = self.scenes.get(&scene).map_err(|e| e.to_string())?;
        Ok(Job {
            generation,
            scene,
            size: [request.size[0].max(1), request.size[1].max(1)],
            gpu_scene,
            rebuild,
            ladder: Ladder::new(
                &self.settings.pixel_sizes,
                request.size,
                self.settings.first_step_pixels,
            ),
            started,
            last_shown: None,
            last_denoise: None,
            done: false,
            spent: [Duration::ZERO; 3],
            show_cost: Duration::ZERO,
            fresh: true,
            hold_below: 0,
        })
    }

    /// The job's current ladder step: its frame, the scene at the whole view's size (what a
    /// renderer is built for) and the renderer's options.
    fn step(&self, job: &Job) -> Result<(rt_core::gpu_types::Frame, Scene, RenderOptions), String> {
        let [w, h] = job.ladder.resolution(job.size);
        let mut step_scene = job.scene.clone();
        step_scene.settings.width = w;
        step_scene.settings.height = h;
        let frame =
            rt_core::frame::frame_for(&step_scene, &job.gpu_scene).map_err(|e| e.to_string())?;
        // A new renderer holds the whole view's pixels, so every later step restarts it.
        let mut full = step_scene;
        full.settings.width = job.size[0];
        full.settings.height = job.size[1];
        let options = RenderOptions {
            kernel: self.settings.kernel,
            aovs: true,
            target_dispatch: dispatch_target(self.settings.budget),
            ..Default::default()
        };
        Ok((frame, full, options))
    }

    /// Whether the GPU's kernel for a step (`step`'s scene and options) is compiled (false on
    /// the CPU backend).
    fn kernel_ready(
        &self,
        full: &Scene,
        gpu_scene: &GpuScene,
        options: RenderOptions,
    ) -> Result<bool, String> {
        let Some(ctx) = self.ctx else {
            return Ok(false);
        };
        crate::engine::kernel_compiled(ctx, full, gpu_scene, options).map_err(|e| e.to_string())
    }

    /// Points the renderer at the job's current ladder step: a restart on a new frame where the
    /// pipeline and buffers allow, else a new renderer. A GPU renderer whose kernel is not yet
    /// compiled is not waited for: its kernel compiles on another thread while the CPU backend
    /// renders (the same samples), and the GPU takes over once it is ready.
    fn prepare(
        &mut self,
        job: &mut Job,
        renderer: &mut Option<(LiveRenderer<'a>, Arc<GpuScene>)>,
    ) -> Result<(), String> {
        let (frame, full, options) = self.step(job)?;
        job.last_shown = None;
        let gpu_ready = self.kernel_ready(&full, &job.gpu_scene, options)?;
        if let Some((r, built)) = renderer.as_mut()
            && Arc::ptr_eq(built, &job.gpu_scene)
            && !(r.on_cpu() && gpu_ready)
            && r.restart(&job.gpu_scene, frame)
        {
            return Ok(());
        }
        *renderer = None;
        let ctx = if gpu_ready {
            self.ctx
        } else {
            self.compile(&full, &job.gpu_scene, options)?;
            None
        };
        let r = LiveRenderer::new(ctx, &full, &job.gpu_scene, frame, options)?;
        *renderer = Some((r, job.gpu_scene.clone()));
        Ok(())
    }

    /// Starts compiling the GPU's kernel for `full` on its own thread, unless one is compiling
    /// (its end brings the next `prepare`, which starts this one if still needed) or the view
    /// renders on the CPU backend.
    fn compile(
        &mut self,
        full: &Scene,
        gpu_scene: &Arc<GpuScene>,
        options: RenderOptions,
    ) -> Result<(), String> {
        let Some(ctx) = self.gpu.clone() else {
            return Ok(());
        };
        if self.compiling.is_some() {
            return Ok(());
        }
        let (full, gpu_scene) = (full.clone(), gpu_scene.clone());
        let compile = move || {
            crate::engine::compile_kernel(&ctx, &full, &gpu_scene, options)
                .map_err(|e| e.to_string())
        };
        let thread = std::thread::Builder::new()
            .name("rt-live-compile".into())
            .spawn(compile)
            .map_err(|e| format!("could not start the kernel's compile thread: {e}"))?;
        self.compiling = Some(thread);
        Ok(())
    }

    /// Whether a kernel compile has just ended; its error fails the view, as a renderer's would.
    fn compiled(&mut self) -> Result<bool, String> {
        if !self.compiling.as_ref().is_some_and(|t| t.is_finished()) {
            return Ok(false);
        }
        match self.compiling.take().map(JoinHandle::join) {
            Some(Ok(result)) => result.map(|()| true),
            Some(Err(_)) => Err("the GPU kernel's compile thread panicked".into()),
            None => Ok(false),
        }
    }

    /// The next message while there is nothing to render: waits for one, but while a kernel
    /// compiles only briefly (the view then moves to the GPU). `Err` once the UI has gone.
    fn next_message(&self, inbox: &Receiver<Message>) -> Result<Option<Message>, ()> {
        if self.compiling.is_none() {
            return inbox.recv().map(Some).map_err(|_| ());
        }
        match inbox.recv_timeout(COMPILE_POLL) {
            Ok(m) => Ok(Some(m)),
            Err(RecvTimeoutError::Timeout) => Ok(None),
            Err(RecvTimeoutError::Disconnected) => Err(()),
        }
    }

    /// One UI frame's work; returns true when the ladder moved to a finer step.
    fn slice(
        &self,
        job: &mut Job,
        renderer: &mut LiveRenderer<'a>,
        interacting: bool,
    ) -> Result<bool, String> {
        // The first slice after a change may run three budgets: the user is waiting for exactly
        // that image (the coarsest step's sample), not for the UI's next frame.
        let budget = if job.fresh {
            self.settings.budget * 3
        } else {
            self.settings.budget
        };
        let mut clock = SliceClock::new(budget);
        let generation = job.generation;
        let shared = self.shared;
        loop {
            let left =
                self.settings.max_samples - renderer.samples_done().min(self.settings.max_samples);
            // A step shows as soon as it has one sample: its first batch takes just that.
            let max = if renderer.samples_done() == 0 {
                left.min(1)
            } else {
                left
            };
            if max == 0 {
                job.done = true;
                return Ok(false);
            }
            let traced = Instant::now();
            let stats = renderer.render_slice(max, |last| clock.another(last), &|| {
                !shared.current(generation)
            })?;
            job.spent[0] += traced.elapsed();
            if !stats.complete || !shared.current(generation) {
                return Ok(false);
            }
            let samples = renderer.samples_done();
            if job.ladder.is_final() && samples.is_power_of_two() {
                log::debug!(
                    "live: {samples} spp after {:.2?}: tracing {:.2?}, waiting for the UI {:.2?}, \
                     reading back {:.2?}",
                    job.started.elapsed(),
                    job.spent[0],
                    job.spent[1],
                    job.spent[2]
                );
            }
            let step_first = job.last_shown.is_none_or(|(_, n)| n == 0);
            // Reading back costs 64 bytes a pixel: at most a fifth of the time goes to it.
            let every = self.settings.show_every.max(job.show_cost * 4);
            let due = job.last_shown.is_none_or(|(at, _)| at.elapsed() >= every);
            if (step_first || due) && samples >= job.hold_below {
                let shown = Instant::now();
                self.show(job, renderer, step_first, interacting)?;
                job.show_cost = shown.elapsed();
                job.spent[2] += job.show_cost;
            }
            if job.ladder.advance(samples, interacting) {
                log::debug!(
                    "live: step 1/{} after {:.2?}: tracing {:.2?}, waiting for the UI {:.2?}, \
                     reading back {:.2?}",
                    job.ladder.pixel_size(),
                    job.started.elapsed(),
                    job.spent[0],
                    job.spent[1],
                    job.spent[2]
                );
                return Ok(true);
            }
            if interacting && !job.ladder.is_final() {
                // Held at the coarsest step while the user drags: one sample is enough to follow
                // the mouse; wait for the next change or the end of the drag.
                job.done = true;
                return Ok(false);
            }
            if !clock.another(stats.last_dispatch) {
                return Ok(false);
            }
        }
    }

    /// Sends the step's image (and queues it for the denoiser when due).
    fn show(
        &self,
        job: &mut Job,
        renderer: &LiveRenderer<'a>,
        step_first: bool,
        interacting: bool,
    ) -> Result<(), String> {
        let read_started = Instant::now();
        let image = renderer.read_image()?;
        log::debug!(
            "live: {}x{} at {} spp read back in {:.1?}",
            image.width,
            image.height,
            image.samples_per_pixel,
            read_started.elapsed()
        );
        let elapsed = job.started.elapsed();
        let mut frame = LiveFrame::new(
            job.generation,
            job.ladder.pixel_size(),
            (image.width, image.height),
            image.rgb(),
            image.samples_per_pixel,
            elapsed,
            job.rebuild,
        );
        frame.noise = noise_of(&image);
        let while_compiling = renderer.on_cpu() && self.ctx.is_some();
        frame.while_compiling = while_compiling;
        job.last_shown = Some((Instant::now(), image.samples_per_pixel));
        let _ = self.outbox.send(Event::Raw(frame));
        self.shared.wake(self.wake);
        let pace = self.settings.denoise_every.max(self.slot.last() * 2);
        let samples = image.samples_per_pixel;
        let denoise_due = step_first
            || job.last_denoise.is_none_or(|(at, n)| {
                at.elapsed() >= pace && u64::from(samples) * 2 >= u64::from(n) * 3
            });
        // While the user drags, only the coarse step is denoised (cheap): a finer one would hold
        // a core the next change needs.
        let denoise_due = denoise_due && !(interacting && job.ladder.pixel_size() == 1);
        if self.settings.denoise
            && denoise_due
            && let Some(aovs) = renderer.read_aovs()?
        {
            self.slot.put(DenoiseJob {
                generation: job.generation,
                pixel_size: job.ladder.pixel_size(),
                image,
                aovs,
                elapsed,
                rebuild: job.rebuild,
                while_compiling,
            });
            job.last_denoise = Some((Instant::now(), samples));
        }
        Ok(())
    }
}

fn noise_of(image: &Image) -> Option<f64> {
    let noise = image.estimated_noise();
    noise.is_finite().then_some(noise)
}
