//! The interactive path-traced viewport's engine, shared by the editor and `rt-cli bench
//! --interactive`: a render thread that answers each change at a coarse pixel size and refines
//! (`ladder`), runs a bounded slice of work per UI frame (`slicing`), keeps the scene's GPU arrays
//! and its renderer across camera and material changes (`scenes`), and a denoise thread that
//! re-denoises the newest image at a bounded rate.
//!
//! The UI side (`LiveView`) is polled once per UI frame (`tick`): it takes what the threads sent,
//! drops anything from before the last change, and lets the render thread start its next slice.

mod backend;
pub mod ladder;
mod scenes;
pub mod slicing;
mod worker;

use std::sync::atomic::{AtomicBool, AtomicU64, Ordering};
use std::sync::mpsc::{Receiver, Sender, TryRecvError, channel};
use std::sync::{Arc, Condvar, Mutex};
use std::thread::JoinHandle;
use std::time::{Duration, Instant};

use rt_core::Scene;
use rt_core::denoiser::{Denoiser, DenoiserChoice};

use crate::{GpuContext, Kernel};

pub use scenes::Rebuild;

/// How the viewport renders.
#[derive(Clone, Debug)]
pub struct LiveSettings {
    /// Each UI frame's slice of path tracing (`slicing`).
    pub budget: Duration,
    /// The resolution ladder's pixel sizes (`ladder`).
    pub pixel_sizes: Vec<u32>,
    /// The ladder starts at its finest step whose next one has more pixels than this.
    pub first_step_pixels: u32,
    /// Denoise the view (the UI may still show the raw image).
    pub denoise: bool,
    pub denoiser: DenoiserChoice,
    /// Re-denoise a step at most this often, once its samples have grown by half since the last
    /// denoise, and never more than a third of the time (each denoise waits at least twice as
    /// long as the last one took).
    pub denoise_every: Duration,
    /// Threads the denoiser may use (`None`: half the cores, leaving the rest to the UI and the
    /// renderer).
    pub denoise_threads: Option<u32>,
    /// At full resolution, send the raw image at most this often (reading it back costs 64 bytes
    /// a pixel).
    pub show_every: Duration,
    /// The view stops refining here.
    pub max_samples: u32,
    /// What traces the paths (the megakernel by default, see `Default`).
    pub kernel: Kernel,
    /// How long the render thread waits for a UI frame between slices before going on anyway
    /// (a window that is not repainting, or no UI at all).
    pub frame_wait: Duration,
}

impl Default for LiveSettings {
    fn default() -> Self {
        LiveSettings {
            budget: slicing::DEFAULT_BUDGET,
            pixel_sizes: ladder::DEFAULT_PIXEL_SIZES.to_vec(),
            first_step_pixels: ladder::FIRST_STEP_PIXELS,
            denoise: true,
            denoiser: DenoiserChoice::Auto,
            denoise_every: Duration::from_millis(1000),
            denoise_threads: None,
            show_every: Duration::from_millis(250),
            max_samples: 1 << 16,
            // The megakernel: the wavefront kernels' per-depth round trips dominate the small,
            // 12 ms dispatches the slices need (measured on lavapipe: 160x90 at 1 spp took ~0.5 s
            // on the wavefront kernels and ~50 ms on the megakernel; docs/performance.md).
            kernel: Kernel::Megakernel,
            frame_wait: Duration::from_millis(60),
        }
    }
}

/// One image of the view: raw or denoised, at one step of the ladder.
#[derive(Clone, Debug)]
pub struct LiveFrame {
    /// The change it answers (`LiveView::generation`).
    pub generation: u64,
    /// Screen pixels per rendered pixel.
    pub pixel_size: u32,
    pub width: u32,
    pub height: u32,
    /// Linear radiance, row-major.
    pub pixels: Vec<[f32; 3]>,
    /// The viewport's display: sRGB, the standard view at exposure 0, RGBA.
    pub rgba8: Vec<u8>,
    pub samples: u32,
    /// From the change to this image's samples.
    pub elapsed: Duration,
    /// Estimated relative RMS error of the raw image (from the per-pixel variance).
    pub noise: Option<f64>,
    /// Which denoiser made it (`None`: the raw image).
    pub denoiser: Option<Denoiser>,
    /// Why OIDN did not run, when it fell back to À-Trous.
    pub fallback: Option<String>,
    /// What the change rebuilt.
    pub rebuild: Rebuild,
    /// Made by the CPU backend standing in while the GPU's kernel for the scene compiles.
    pub while_compiling: bool,
}

impl LiveFrame {
    fn new(
        generation: u64,
        pixel_size: u32,
        (width, height): (u32, u32),
        pixels: Vec<[f32; 3]>,
        samples: u32,
        elapsed: Duration,
        rebuild: Rebuild,
    ) -> Self {
        let rgba8 = rt_core::output::View::default().to_rgba8(&pixels);
        LiveFrame {
            generation,
            pixel_size,
            width,
            height,
            pixels,
            rgba8,
            samples,
            elapsed,
            noise: None,
            denoiser: None,
            fallback: None,
            rebuild,
            while_compiling: false,
        }
    }
}

/// A change for the view: the scene as it now is, the view's size, and whether the user is still
/// dragging.
pub struct LiveRequest {
    pub scene: Scene,
    pub size: [u32; 2],
    pub interacting: bool,
}

enum Message {
    Request(Box<LiveRequest>, u64),
    Interacting(bool),
}

enum Event {
    Raw(LiveFrame),
    Denoised(LiveFrame),
    Failed(String),
}

/// What the threads and the UI share.
struct Shared {
    /// The newest change; work for an older one stops at its next dispatch.
    generation: AtomicU64,
    stop: AtomicBool,
    /// The threads asked the UI for a frame it has not drawn yet.
    repaint_pending: AtomicBool,
    /// UI frames so far, and when the last two began.
    ui_frames: Mutex<(u64, [Option<Instant>; 2])>,
    ui_frame: Condvar,
}

impl Shared {
    fn current(&self, generation: u64) -> bool {
        self.generation.load(Ordering::Acquire) == generation && !self.stop.load(Ordering::Relaxed)
    }

    /// Asks the UI for a frame (to show a new image).
    fn wake(&self, wake: &dyn Fn()) {
        self.repaint_pending.store(true, Ordering::Release);
        wake();
    }

    /// Waits (up to `timeout`) for the UI's next frame when it is drawing (it asked for frames
    /// lately, or the threads asked it for one), so that render slices and UI frames take turns
    /// on the CPU where the GPU is the CPU: one slice per UI frame. A UI with nothing to draw is
    /// not waited for.
    fn wait_for_ui(&self, timeout: Duration) {
        let Ok(frames) = self.ui_frames.lock() else {
            return;
        };
        let (seen, [before, last]) = *frames;
        // Drawing continuously: its last two frames came close together, and lately.
        let continuous = match (before, last) {
            (Some(a), Some(b)) => b - a < timeout && b.elapsed() < timeout,
            _ => false,
        };
        let drawing = self.repaint_pending.load(Ordering::Acquire) || continuous;
        if !drawing {
            return;
        }
        let (_frames, waited) = self
            .ui_frame
            .wait_timeout_while(frames, timeout, |f| {
                f.0 == seen && !self.stop.load(Ordering::Relaxed)
            })
            .unwrap_or_else(|e| e.into_inner());
        if waited.timed_out() {
            // The UI did not draw the frame asked for in time (hidden, or idle): stop waiting for
            // it, so a UI that is not drawing never slows the view.
            self.repaint_pending.store(false, Ordering::Release);
        }
    }
}

/// The UI's handle on the viewport's threads. Dropping it stops them after their current dispatch
/// (the renderer and its buffers go with the render thread).
pub struct LiveView {
    messages: Sender<Message>,
    events: Receiver<Event>,
    shared: Arc<Shared>,
    threads: Vec<JoinHandle<()>>,
    generation: u64,
    changed_at: Instant,
    raw: Option<LiveFrame>,
    denoised: Option<LiveFrame>,
    /// The last image shown before the newest change, until that change has one.
    previous: Option<LiveFrame>,
    /// When the newest change's first image arrived.
    first_image_after: Option<Duration>,
    error: Option<String>,
    /// Show the denoised image when there is one.
    pub show_denoised: bool,
}

impl LiveView {
    /// Starts the threads; `open` gives the render device (called on the render thread: opening one
    /// takes a while), `wake` asks the UI for a frame (called after each slice and image).
    pub fn start(
        open: impl FnOnce() -> Result<Arc<GpuContext>, String> + Send + 'static,
        settings: LiveSettings,
        wake: impl Fn() + Send + Sync + 'static,
    ) -> LiveView {
        Self::start_on(move || open().map(Some), settings, wake)
    }

    /// `start` on the native CPU backend (`rt_core::cpu_render`): the view a machine without a
    /// GPU gets, the same samples as the GPU's for the same frame.
    pub fn start_on_cpu(
        settings: LiveSettings,
        wake: impl Fn() + Send + Sync + 'static,
    ) -> LiveView {
        Self::start_on(|| Ok(None), settings, wake)
    }

    /// `open` gives the GPU, or `None` for the CPU backend.
    fn start_on(
        open: impl FnOnce() -> Result<Option<Arc<GpuContext>>, String> + Send + 'static,
        settings: LiveSettings,
        wake: impl Fn() + Send + Sync + 'static,
    ) -> LiveView {
        let shared = Arc::new(Shared {
            generation: AtomicU64::new(0),
            stop: AtomicBool::new(false),
            repaint_pending: AtomicBool::new(false),
            ui_frames: Mutex::new((0, [None; 2])),
            ui_frame: Condvar::new(),
        });
        let (messages, inbox) = channel();
        let (outbox, events) = channel();
        let wake: Arc<dyn Fn() + Send + Sync> = Arc::new(wake);
        let show_denoised = settings.denoise;
        let threads = worker::spawn(open, settings, inbox, outbox, shared.clone(), wake);
        let (threads, error) = match threads {
            Ok(t) => (t, None),
            Err(e) => (
                Vec::new(),
                Some(format!("could not start the viewport's threads: {e}")),
            ),
        };
        LiveView {
            messages,
            events,
            shared,
            threads,
            generation: 0,
            changed_at: Instant::now(),
            raw: None,
            denoised: None,
            previous: None,
            first_image_after: None,
            error,
            show_denoised,
        }
    }

    /// Restarts the view on a change; what the threads still send for earlier ones is dropped.
    pub fn request(&mut self, request: LiveRequest) {
        if let Some(shown) = self.display().cloned() {
            self.previous = Some(shown);
        }
        self.generation += 1;
        self.shared
            .generation
            .store(self.generation, Ordering::Release);
        self.raw = None;
        self.denoised = None;
        self.first_image_after = None;
        self.changed_at = Instant::now();
        if self
            .messages
            .send(Message::Request(Box::new(request), self.generation))
            .is_err()
            && self.error.is_none()
        {
            self.error = Some("the viewport's render thread stopped".into());
        }
    }

    /// The user started or stopped dragging (without changing anything else).
    pub fn set_interacting(&mut self, interacting: bool) {
        let _ = self.messages.send(Message::Interacting(interacting));
    }

    /// Once per UI frame: takes in what the threads sent and lets the next slice start. Returns
    /// whether the image to show changed.
    pub fn tick(&mut self) -> bool {
        let changed = self.take_events();
        // Only then may the next slice start: an image it sends at once (a small view on the CPU
        // backend takes a millisecond) waits for the next frame instead of replacing, unseen, the
        // one just sent.
        if let Ok(mut frames) = self.shared.ui_frames.lock() {
            *frames = (frames.0 + 1, [frames.1[1], Some(Instant::now())]);
            self.shared.repaint_pending.store(false, Ordering::Release);
        }
        self.shared.ui_frame.notify_all();
        changed
    }

    /// Takes in what the threads sent; whether the image to show changed.
    fn take_events(&mut self) -> bool {
        let mut changed = false;
        loop {
            match self.events.try_recv() {
                Ok(Event::Raw(frame)) if frame.generation == self.generation => {
                    self.first_image_after
                        .get_or_insert(self.changed_at.elapsed());
                    self.previous = None;
                    self.raw = Some(frame);
                    changed = true;
                }
                Ok(Event::Denoised(frame)) if frame.generation == self.generation => {
                    self.denoised = Some(frame);
                    changed = true;
                }
                Ok(Event::Failed(message)) => {
                    self.error = Some(message);
                    changed = true;
                }
                // From before the newest change: never shown.
                Ok(_) => {}
                Err(TryRecvError::Empty) => break,
                Err(TryRecvError::Disconnected) => {
                    if self.error.is_none() {
                        self.error = Some("the viewport's render thread stopped".into());
                        changed = true;
                    }
                    break;
                }
            }
        }
        changed
    }

    /// The image to show for the newest change: the denoised one when asked for and there is one
    /// (it may be a step coarser than the raw image while the finer one is denoised), else the raw
    /// one; `None` until the change has its first image.
    pub fn display(&self) -> Option<&LiveFrame> {
        match (&self.denoised, &self.raw) {
            (Some(d), _) if self.show_denoised => Some(d),
            (_, raw) => raw.as_ref(),
        }
    }

    /// The image shown before the newest change, to keep on screen (marked as updating) until
    /// `display` has one.
    pub fn previous(&self) -> Option<&LiveFrame> {
        self.previous.as_ref()
    }

    pub fn raw(&self) -> Option<&LiveFrame> {
        self.raw.as_ref()
    }

    pub fn denoised(&self) -> Option<&LiveFrame> {
        self.denoised.as_ref()
    }

    /// The newest change's number (frames carry it).
    pub fn generation(&self) -> u64 {
        self.generation
    }

    /// Time from the newest change to its first image, once it has one.
    pub fn first_image_after(&self) -> Option<Duration> {
        self.first_image_after
    }

    pub fn error(&self) -> Option<&str> {
        self.error.as_deref()
    }

    /// Stops the threads and waits for them (up to `timeout`); true if they all ended.
    pub fn shut_down(mut self, timeout: Duration) -> bool {
        self.signal_stop();
        let started = Instant::now();
        while started.elapsed() < timeout && self.threads.iter().any(|t| !t.is_finished()) {
            std::thread::sleep(Duration::from_millis(5));
        }
        let all = self.threads.iter().all(|t| t.is_finished());
        for t in std::mem::take(&mut self.threads) {
            if t.is_finished() {
                let _ = t.join();
            }
        }
        all
    }

    fn signal_stop(&self) {
        self.shared.stop.store(true, Ordering::Relaxed);
        self.shared.generation.fetch_add(1, Ordering::AcqRel);
        self.shared.ui_frame.notify_all();
    }
}

impl Drop for LiveView {
    fn drop(&mut self) {
        // The threads end after their current dispatch; the UI does not wait for them.
        self.signal_stop();
    }
}
