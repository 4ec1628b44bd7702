//! Renders on a background thread with progress, previews and cancel, so the UI never waits on
//! the GPU. Final renders and the path-traced viewport both run as jobs.

use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::mpsc::{Receiver, Sender, TryRecvError, channel};
use std::sync::{Arc, Mutex};
use std::thread::JoinHandle;
use std::time::{Duration, Instant};

use rt_core::{GpuScene, Scene};
use rt_gpu::context::{AdapterChoice, DeviceOptions, GpuContext};
use rt_gpu::progressive::Progressive;
use rt_gpu::render_loop::{AfterBatch, Ended, render_to};
use rt_gpu::{Image, RenderOptions, Renderer};

/// The render device, opened on first use and shared by every job (opening one takes a while, and
/// pipelines are cached on it).
#[derive(Clone, Default)]
pub struct RenderDevice {
    inner: Arc<Mutex<Option<Arc<GpuContext>>>>,
    choice: AdapterChoice,
    options: DeviceOptions,
}

impl RenderDevice {
    pub fn new(choice: AdapterChoice, options: DeviceOptions) -> Self {
        RenderDevice {
            inner: Arc::default(),
            choice,
            options,
        }
    }

    pub fn get(&self) -> anyhow::Result<Arc<GpuContext>> {
        let mut slot = self
            .inner
            .lock()
            .map_err(|_| anyhow::anyhow!("the render device lock was poisoned"))?;
        if let Some(ctx) = slot.as_ref() {
            return Ok(ctx.clone());
        }
        let ctx = Arc::new(GpuContext::with_options(&self.choice, self.options)?);
        *slot = Some(ctx.clone());
        Ok(ctx)
    }

    /// The adapter's name once a job has opened it.
    pub fn adapter_label(&self) -> Option<String> {
        let slot = self.inner.lock().ok()?;
        slot.as_ref().map(|c| c.adapter_label())
    }
}

/// What a job reports, in order: progress and previews while it runs, then exactly one of
/// `Finished` or `Failed`.
pub enum JobEvent {
    /// The scene's GPU arrays, for a later job on the same geometry to reuse.
    SceneBuilt(Arc<GpuScene>),
    Progress(Progress),
    Preview(Image),
    Finished {
        image: Image,
        /// Albedo, normal and directly seen light, for the denoiser (when asked for).
        aovs: Option<rt_gpu::Aovs>,
        cancelled: bool,
    },
    Failed(String),
}

#[derive(Clone, Copy, Debug, Default)]
pub struct Progress {
    pub samples_done: u32,
    pub samples_total: u32,
    pub elapsed: Duration,
    /// Estimated relative RMS error of the image so far (from the per-pixel variance).
    pub noise: Option<f64>,
}

impl Progress {
    pub fn fraction(&self) -> f32 {
        if self.samples_total == 0 {
            0.0
        } else {
            self.samples_done as f32 / self.samples_total as f32
        }
    }

    /// Time left at the rate so far.
    pub fn eta(&self) -> Option<Duration> {
        (self.samples_done > 0).then(|| {
            let left = f64::from(self.samples_total - self.samples_done.min(self.samples_total));
            self.elapsed.mul_f64(left / f64::from(self.samples_done))
        })
    }
}

#[derive(Clone, Debug, PartialEq, Eq)]
pub enum JobState {
    Running,
    Finished,
    Cancelled,
    Failed(String),
}

/// How a job reports and what it keeps.
#[derive(Clone, Copy, Debug, Default)]
pub struct JobOptions {
    /// How often to send the image so far (`None`: only progress).
    pub preview_every: Option<Duration>,
    /// Keep albedo, normals and direct light for the denoiser.
    pub keep_aovs: bool,
    /// Render with the native CPU backend rather than the GPU.
    pub on_cpu: bool,
}

/// Which backend renders the editor's render windows (the Render panel's "Device").
pub use rt_gpu::progressive::Device as DeviceChoice;

/// The Render panel's name for `choice`.
pub fn device_label(choice: DeviceChoice) -> &'static str {
    match choice {
        DeviceChoice::Auto => "Auto",
        DeviceChoice::Gpu => "GPU",
        DeviceChoice::Cpu => "CPU",
    }
}

/// A render in progress or done.
pub struct RenderJob {
    pub scene: Scene,
    pub state: JobState,
    pub progress: Progress,
    /// The latest image (a preview while running, the result when finished).
    pub image: Option<Image>,
    /// Bumped whenever `image` changes, so views know to re-upload it.
    pub image_revision: u64,
    pub adapter: Option<String>,
    /// The scene's GPU arrays once built (or as given).
    pub gpu_scene: Option<Arc<GpuScene>>,
    /// The denoiser's guides, once finished (if the job kept them).
    pub aovs: Option<rt_gpu::Aovs>,
    cancel: Arc<AtomicBool>,
    events: Receiver<JobEvent>,
    thread: Option<JoinHandle<()>>,
}

impl RenderJob {
    /// Starts rendering `scene` with its settings. `wake` is called after each event (to repaint
    /// the UI).
    /// `gpu_scene`, when given, must have been built from the same objects and settings.
    pub fn start(
        device: RenderDevice,
        scene: Scene,
        gpu_scene: Option<Arc<GpuScene>>,
        options: JobOptions,
        wake: impl Fn() + Send + 'static,
    ) -> Self {
        let cancel = Arc::new(AtomicBool::new(false));
        let (tx, rx) = channel();
        let thread = {
            let cancel = cancel.clone();
            let scene = scene.clone();
            let gpu_scene = gpu_scene.clone();
            std::thread::Builder::new()
                .name("rt-render".into())
                .spawn(move || {
                    let failed = tx.clone();
                    if let Err(e) = run(&device, &scene, gpu_scene, options, &cancel, &tx, &wake) {
                        let _ = failed.send(JobEvent::Failed(format!("{e:#}")));
                    }
                    wake();
                })
        };
        let (state, thread) = match thread {
            Ok(t) => (JobState::Running, Some(t)),
            Err(e) => (
                JobState::Failed(format!("could not start a thread: {e}")),
                None,
            ),
        };
        RenderJob {
            progress: Progress {
                samples_total: scene.settings.samples_per_pixel,
                ..Progress::default()
            },
            scene,
            state,
            image: None,
            image_revision: 0,
            adapter: None,
            gpu_scene,
            aovs: None,
            cancel,
            events: rx,
            thread,
        }
    }

    /// A finished job holding an image rendered elsewhere (a merged EXR opened in the viewer).
    pub fn finished(image: Image, aovs: Option<rt_gpu::Aovs>, adapter: Option<String>) -> Self {
        let (_, events) = channel();
        let mut scene = Scene::default();
        scene.settings.width = image.width;
        scene.settings.height = image.height;
        scene.settings.samples_per_pixel = image.samples_per_pixel;
        RenderJob {
            progress: Progress {
                samples_done: image.samples_per_pixel,
                samples_total: image.samples_per_pixel,
                elapsed: Duration::ZERO,
                noise: Some(image.estimated_noise()),
            },
            scene,
            state: JobState::Finished,
            image: Some(image),
            image_revision: 1,
            adapter,
            gpu_scene: None,
            aovs,
            cancel: Arc::new(AtomicBool::new(false)),
            events,
            thread: None,
        }
    }

    pub fn is_running(&self) -> bool {
        self.state == JobState::Running
    }

    /// Asks the job to stop after its current dispatch; it then finishes with what it has.
    pub fn cancel(&self) {
        self.cancel.store(true, Ordering::Relaxed);
    }

    /// Takes in what the job reported since the last call. Returns true if anything changed.
    pub fn poll(&mut self) -> bool {
        let mut changed = false;
        loop {
            match self.events.try_recv() {
                Ok(event) => {
                    changed = true;
                    match event {
                        JobEvent::SceneBuilt(built) => self.gpu_scene = Some(built),
                        JobEvent::Progress(p) => self.progress = p,
                        JobEvent::Preview(image) => self.set_image(image),
                        JobEvent::Finished {
                            image,
                            aovs,
                            cancelled,
                        } => {
                            self.aovs = aovs;
                            self.progress.samples_done = image.samples_per_pixel;
                            self.set_image(image);
                            self.state = if cancelled {
                                JobState::Cancelled
                            } else {
                                JobState::Finished
                            };
                        }
                        JobEvent::Failed(message) => self.state = JobState::Failed(message),
                    }
                }
                Err(TryRecvError::Empty) => break,
                Err(TryRecvError::Disconnected) => {
                    if self.state == JobState::Running {
                        self.state = JobState::Failed("the render thread stopped".into());
                        changed = true;
                    }
                    break;
                }
            }
        }
        if !self.is_running()
            && let Some(t) = self.thread.take()
        {
            let _ = t.join();
        }
        changed
    }

    /// Waits (blocking) until the job is done; for tests and the command line.
    pub fn wait(&mut self, timeout: Duration) -> bool {
        let start = Instant::now();
        while self.is_running() && start.elapsed() < timeout {
            self.poll();
            std::thread::sleep(Duration::from_millis(10));
        }
        !self.is_running()
    }

    fn set_image(&mut self, image: Image) {
        self.image = Some(image);
        self.image_revision += 1;
    }
}

impl Drop for RenderJob {
    fn drop(&mut self) {
        self.cancel();
    }
}

fn run(
    device: &RenderDevice,
    scene: &Scene,
    gpu_scene: Option<Arc<GpuScene>>,
    job: JobOptions,
    cancel: &AtomicBool,
    tx: &Sender<JobEvent>,
    wake: &dyn Fn(),
) -> anyhow::Result<()> {
    let start = Instant::now();
    let ctx = if job.on_cpu {
        None
    } else {
        Some(device.get()?)
    };
    let gpu_scene = match gpu_scene {
        Some(built) => built,
        None => {
            let built = Arc::new(GpuScene::build(scene)?);
            let _ = tx.send(JobEvent::SceneBuilt(built.clone()));
            built
        }
    };
    let mut renderer = match &ctx {
        Some(ctx) => {
            let options = RenderOptions {
                aovs: job.keep_aovs,
                ..Default::default()
            };
            Progressive::Gpu(Box::new(Renderer::for_scene(
                ctx, scene, &gpu_scene, options,
            )?))
        }
        None => Progressive::cpu(scene, &gpu_scene, 0, job.keep_aovs)?,
    };
    let total = scene.settings.samples_per_pixel;
    let mut last_preview = Instant::now();
    let mut noise = None;
    // Adaptive sampling may stop every pixel before `total`.
    let unfinished = |r: &Progressive| r.samples_done() < total && r.active_pixels() > 0;
    // The only stop: nobody left to send the image to (the window was closed).
    const CLOSED: AfterBatch = AfterBatch::Stop("the render window was closed");
    let after_batch = |renderer: &Progressive| {
        let due = job
            .preview_every
            .is_some_and(|every| last_preview.elapsed() >= every);
        if due && unfinished(renderer) {
            let image = renderer.read_image()?;
            noise = noise_of(&image);
            if tx.send(JobEvent::Preview(image)).is_err() {
                return Ok(CLOSED);
            }
            last_preview = Instant::now();
        }
        let progress = Progress {
            samples_done: renderer.samples_done(),
            samples_total: total,
            elapsed: start.elapsed(),
            noise,
        };
        if tx.send(JobEvent::Progress(progress)).is_err() {
            return Ok(CLOSED);
        }
        wake();
        Ok(AfterBatch::Continue)
    };
    let ended = render_to(
        &mut renderer,
        total,
        cancel,
        |done| total - done,
        after_batch,
    )?;
    if let Ended::Stopped(_) = ended {
        return Ok(());
    }
    let image = renderer.read_image()?;
    let progress = Progress {
        samples_done: image.samples_per_pixel,
        samples_total: total,
        elapsed: start.elapsed(),
        noise: noise_of(&image),
    };
    let _ = tx.send(JobEvent::Progress(progress));
    let cancelled = unfinished(&renderer);
    let aovs = renderer.read_aovs()?;
    let _ = tx.send(JobEvent::Finished {
        image,
        aovs,
        cancelled,
    });
    Ok(())
}

fn noise_of(image: &Image) -> Option<f64> {
    let noise = image.estimated_noise();
    noise.is_finite().then_some(noise)
}
