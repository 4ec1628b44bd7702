//! `rt --interactive-bench REPORT [FILE]`: the real editor window (under Xvfb on a headless
//! machine) measured while its path-traced viewport answers an orbit: the time from each camera
//! change to the first new image on screen, the UI frame intervals while dragging and while the
//! view refines, and the samples after 5 s and 30 s. Writes a text report and quits. A benchmark,
//! not a test: the numbers go to docs/performance.md with the machine and adapter.

use std::fmt::Write as _;
use std::path::PathBuf;
use std::time::{Duration, Instant};

use crate::app::RtApp;
use crate::smoke::Outcome;

const REFINE: Duration = Duration::from_secs(30);
/// The first part of the refinement redraws continuously (a user moving the mouse); after it the
/// editor draws only when the view has a new image (a user watching).
const ACTIVE: Duration = Duration::from_secs(10);
const DRAG_CHANGES: u32 = 20;
/// Frames between drag steps (a fast mouse moves every frame; this leaves each step time to show).
const FRAMES_PER_CHANGE: u32 = 6;
/// Frames of the editor alone (the path-traced view off) first: the baseline frame time.
const IDLE_FRAMES: u32 = 60;

enum Stage {
    Warmup(u32),
    Idle(u32),
    Opening(Instant),
    Drag { changes: u32, frames: u32 },
    Refine(Instant),
    Done,
}

#[derive(Default)]
struct Record {
    idle_frames: Vec<Duration>,
    /// The longest refining frame and how long after the release it began.
    slowest: (Duration, Duration),
    opening: Duration,
    drag_frames: Vec<Duration>,
    refine_frames: Vec<Duration>,
    latencies: Vec<Duration>,
    release_latency: Option<Duration>,
    full_resolution_after: Option<Duration>,
    spp_5s: Option<u32>,
    spp_end: u32,
    /// Frames the editor drew while left to refine on its own.
    watching_frames: u32,
    viewport: [u32; 2],
}

pub struct InteractiveBench {
    pub app: RtApp,
    report: PathBuf,
    stage: Stage,
    outcome: Outcome,
    last_frame: Option<Instant>,
    /// The change waiting for its first image: (generation, the start of the frame that sent it to
    /// the view, as a mouse event's frame would).
    pending: Option<(u64, Option<Instant>)>,
    record: Record,
    started: Instant,
}

impl InteractiveBench {
    pub fn new(app: RtApp, report: PathBuf, outcome: Outcome) -> Self {
        InteractiveBench {
            app,
            report,
            stage: Stage::Warmup(0),
            outcome,
            last_frame: None,
            pending: None,
            record: Record::default(),
            started: Instant::now(),
        }
    }

    fn finish(&mut self, ctx: &egui::Context, result: Result<(), String>) {
        match &result {
            Ok(()) => eprintln!(
                "rt: interactive benchmark written to {}",
                self.report.display()
            ),
            Err(e) => eprintln!("rt: interactive benchmark failed: {e}"),
        }
        if let Ok(mut slot) = self.outcome.lock() {
            *slot = Some(result);
        }
        self.stage = Stage::Done;
        ctx.send_viewport_cmd(egui::ViewportCommand::Close);
    }

    fn change_camera(&mut self, degrees: f32, dragging: bool) {
        let mut camera = self.app.doc.scene.camera.clone();
        let pivot = glam::Vec3::from(camera.to);
        // The viewport's own orbit, as a mouse drag of this many pixels would turn it.
        crate::navigation::orbit(&mut camera, pivot, glam::Vec2::new(degrees * 2.0, 0.0));
        self.app
            .doc
            .edit("orbit", "camera", |s| s.camera = camera.clone());
        self.app.ui.scripted_drag = dragging;
    }

    /// Notes when the pending change's first image is on screen (this frame draws it).
    fn watch(&mut self) -> Option<Duration> {
        let view = self.app.live.view.as_ref()?;
        let (generation, at) = self.pending?;
        let at = at?;
        if view.generation() != generation {
            // The viewport has not taken the change in yet (it does when it draws).
            return None;
        }
        view.display()?;
        self.pending = None;
        Some(at.elapsed())
    }

    fn step(&mut self, ctx: &egui::Context, interval: Option<Duration>) -> Result<(), String> {
        let shown = self.watch();
        match self.stage {
            Stage::Warmup(n) if n < 5 => self.stage = Stage::Warmup(n + 1),
            Stage::Warmup(_) => self.stage = Stage::Idle(0),
            Stage::Idle(n) if n < IDLE_FRAMES => {
                self.record.idle_frames.extend(interval);
                self.stage = Stage::Idle(n + 1);
            }
            Stage::Idle(_) => {
                self.app.live.enabled = true;
                self.stage = Stage::Opening(Instant::now());
            }
            Stage::Opening(at) => {
                let full = self
                    .app
                    .live
                    .view
                    .as_ref()
                    .and_then(|v| v.raw())
                    .is_some_and(|f| f.pixel_size == 1);
                if full {
                    self.record.opening = at.elapsed();
                    self.stage = Stage::Drag {
                        changes: 0,
                        frames: 0,
                    };
                }
            }
            Stage::Drag { changes, frames } => {
                self.record.drag_frames.extend(interval);
                if let Some(latency) = shown {
                    self.record.latencies.push(latency);
                }
                if frames % FRAMES_PER_CHANGE == 0 {
                    let back = changes >= DRAG_CHANGES / 2;
                    // The last step lets go of the mouse, and the view refines from there.
                    let last = changes + 1 == DRAG_CHANGES;
                    self.pending = None;
                    self.change_camera(if back { -1.5 } else { 1.5 }, !last);
                    self.arm();
                    self.stage = if last {
                        Stage::Refine(Instant::now())
                    } else {
                        Stage::Drag {
                            changes: changes + 1,
                            frames: frames + 1,
                        }
                    };
                } else {
                    self.stage = Stage::Drag {
                        changes,
                        frames: frames + 1,
                    };
                }
            }
            Stage::Refine(released) => {
                if released.elapsed() >= ACTIVE {
                    self.record.watching_frames += 1;
                }
                if released.elapsed() < ACTIVE {
                    self.record.refine_frames.extend(interval);
                    if let Some(i) = interval
                        && i > self.record.slowest.0
                    {
                        self.record.slowest = (i, released.elapsed());
                    }
                }
                if let Some(latency) = shown {
                    self.record.release_latency.get_or_insert(latency);
                }
                let raw = self.app.live.view.as_ref().and_then(|v| v.raw());
                if self.record.full_resolution_after.is_none()
                    && raw.is_some_and(|f| f.pixel_size == 1)
                {
                    self.record.full_resolution_after = Some(released.elapsed());
                }
                if self.record.spp_5s.is_none() && released.elapsed() >= Duration::from_secs(5) {
                    self.record.spp_5s = raw.map(|f| f.samples);
                }
                if released.elapsed() >= REFINE {
                    self.record.spp_end = raw.map_or(0, |f| f.samples);
                    self.write()?;
                    self.finish(ctx, Ok(()));
                }
            }
            Stage::Done => {}
        }
        Ok(())
    }

    /// The change just made waits for its first image; the viewport takes it in this frame.
    fn arm(&mut self) {
        let next = self.app.live.view.as_ref().map_or(0, |v| v.generation()) + 1;
        self.pending = Some((next, None));
    }

    fn write(&self) -> Result<(), String> {
        let r = &self.record;
        let ms = |d: Duration| d.as_secs_f64() * 1e3;
        let pct = |v: &[Duration], p: f64| {
            let mut s = v.to_vec();
            s.sort();
            s.get(((s.len().max(1) - 1) as f64 * p).round() as usize)
                .copied()
                .map_or(0.0, ms)
        };
        let mut out = String::new();
        let _ = writeln!(
            out,
            "rt editor, interactive benchmark: adapter {}; {} cores; path-traced viewport {}x{} \
             points; scene {}",
            self.app.adapter_label(),
            std::thread::available_parallelism().map_or(0, |n| n.get()),
            r.viewport[0],
            r.viewport[1],
            self.app.doc.title()
        );
        let _ = writeln!(
            out,
            "editor alone (raster preview, redrawing continuously): UI frame median {:.1} ms, p95 \
             {:.1} ms",
            pct(&r.idle_frames, 0.5),
            pct(&r.idle_frames, 0.95)
        );
        let _ = writeln!(out, "opening to full resolution: {:.0} ms", ms(r.opening));
        let _ = writeln!(
            out,
            "drag ({} changes, one each {FRAMES_PER_CHANGE} frames): change -> first image on \
             screen median {:.0} ms, p95 {:.0} ms, max {:.0} ms ({} answered within \
             {FRAMES_PER_CHANGE} frames); UI frame median {:.1} ms, p95 {:.1} ms",
            DRAG_CHANGES - 1,
            pct(&r.latencies, 0.5),
            pct(&r.latencies, 0.95),
            pct(&r.latencies, 1.0),
            r.latencies.len(),
            pct(&r.drag_frames, 0.5),
            pct(&r.drag_frames, 0.95),
        );
        let _ = writeln!(
            out,
            "release -> first image {:.0} ms; full resolution after {:.2} s",
            r.release_latency.map_or(0.0, ms),
            r.full_resolution_after.map_or(0.0, |d| d.as_secs_f64())
        );
        let _ = writeln!(
            out,
            "refining: first {} s redrawing continuously, UI frame median {:.1} ms, p95 {:.1} ms, \
             max {:.1} ms (at {:.1} s), then redrawing on new images ({} frames in {} s); spp \
             after 5 s {}, after {} s {}",
            ACTIVE.as_secs(),
            pct(&r.refine_frames, 0.5),
            pct(&r.refine_frames, 0.95),
            ms(r.slowest.0),
            r.slowest.1.as_secs_f64(),
            r.watching_frames,
            (REFINE - ACTIVE).as_secs(),
            r.spp_5s.unwrap_or(0),
            REFINE.as_secs(),
            r.spp_end
        );
        print!("{out}");
        rt_core::output::write_atomically(&self.report, out.as_bytes()).map_err(|e| e.to_string())
    }
}

impl eframe::App for InteractiveBench {
    fn ui(&mut self, ui: &mut egui::Ui, _frame: &mut eframe::Frame) {
        let now = Instant::now();
        let interval = self.last_frame.map(|last| now - last);
        self.last_frame = Some(now);
        if let Some((_, at @ None)) = &mut self.pending {
            *at = Some(now);
        }
        self.app.draw(ui);
        let ctx = ui.ctx().clone();
        if matches!(self.stage, Stage::Done) {
            return;
        }
        if let Some(key) = self.app.live.key {
            self.record.viewport = key.1;
        }
        if let Some(error) = self.app.ui.error.clone() {
            self.finish(&ctx, Err(error));
            return;
        }
        if self.started.elapsed() > Duration::from_secs(600) {
            self.finish(&ctx, Err("not done after 10 minutes".into()));
            return;
        }
        if let Err(e) = self.step(&ctx, interval) {
            self.finish(&ctx, Err(e));
            return;
        }
        // Continuous redraws, as while the user drags or moves the mouse, except once the view is
        // left to refine on its own.
        match self.stage {
            Stage::Refine(released) if released.elapsed() >= ACTIVE => {
                ctx.request_repaint_after(Duration::from_millis(250));
            }
            _ => ctx.request_repaint(),
        }
    }
}
