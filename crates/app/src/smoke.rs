//! `rt --smoke-test DIR`: drives the real window through a short session (render a few samples,
//! save the image and a project, reload it, take a screenshot) and quits, for CI under Xvfb.

use std::path::PathBuf;
use std::sync::{Arc, Mutex};
use std::time::{Duration, Instant};

use crate::app::RtApp;
use crate::render_job::JobState;

const TIME_LIMIT: Duration = Duration::from_secs(300);

enum Stage {
    Warmup(u32),
    Rendering(u64),
    Screenshot,
    Done,
}

/// The outcome, read by `main` after the window closes.
pub type Outcome = Arc<Mutex<Option<Result<(), String>>>>;

pub struct SmokeTest {
    pub app: RtApp,
    out: PathBuf,
    stage: Stage,
    start: Instant,
    outcome: Outcome,
    screenshot: Arc<Mutex<Option<Arc<egui::ColorImage>>>>,
}

impl SmokeTest {
    pub fn new(app: RtApp, out: PathBuf, outcome: Outcome) -> Self {
        SmokeTest {
            app,
            out,
            stage: Stage::Warmup(0),
            start: Instant::now(),
            outcome,
            screenshot: Arc::default(),
        }
    }

    fn finish(&mut self, ctx: &egui::Context, result: Result<(), String>) {
        if let Err(e) = &result {
            eprintln!("rt smoke test failed: {e}");
        } else {
            eprintln!("rt smoke test passed; files in {}", self.out.display());
        }
        if let Ok(mut slot) = self.outcome.lock() {
            *slot = Some(result);
        }
        self.stage = Stage::Done;
        ctx.send_viewport_cmd(egui::ViewportCommand::Close);
    }

    fn step(&mut self, ctx: &egui::Context) -> Result<(), String> {
        match self.stage {
            Stage::Warmup(frames) if frames < 5 => self.stage = Stage::Warmup(frames + 1),
            Stage::Warmup(_) => {
                self.app.doc.edit("smoke settings", "smoke", |s| {
                    s.settings.width = 96;
                    s.settings.height = 96;
                    s.settings.samples_per_pixel = 8;
                });
                let id = self
                    .app
                    .start_render()
                    .ok_or_else(|| format!("the render did not start: {:?}", self.app.ui.error))?;
                self.stage = Stage::Rendering(id);
            }
            Stage::Rendering(id) => {
                let Some(view) = self.app.renders.iter().find(|r| r.id == id) else {
                    return Err("the render window disappeared".into());
                };
                match &view.job.state {
                    JobState::Running => {}
                    JobState::Finished => {
                        let image = self.out.join("render.png");
                        crate::ui::renders_save(view, &image).map_err(|e| e.to_string())?;
                        let project = self.out.join("smoke.rtproj");
                        if !self.app.save_project_to(&project) {
                            return Err(format!("saving the project: {:?}", self.app.ui.error));
                        }
                        let saved = self.app.doc.scene.clone();
                        if !self.app.open_path(&project) || self.app.doc.scene != saved {
                            return Err("the reloaded project differs from the saved one".into());
                        }
                        let slot = self.screenshot.clone();
                        let repaint = ctx.clone();
                        ctx.send_viewport_cmd(egui::ViewportCommand::Screenshot(
                            egui::ScreenshotCallback::new(move |image| {
                                if let Ok(mut s) = slot.lock() {
                                    *s = Some(image);
                                }
                                repaint.request_repaint();
                            }),
                        ));
                        self.stage = Stage::Screenshot;
                    }
                    other => return Err(format!("the render ended as {other:?}")),
                }
            }
            Stage::Screenshot => {
                let shot = self.screenshot.lock().ok().and_then(|mut s| s.take());
                if let Some(shot) = shot {
                    let [w, h] = shot.size;
                    let bytes: Vec<u8> = shot.pixels.iter().flat_map(|c| c.to_array()).collect();
                    let path = self.out.join("window.png");
                    image::save_buffer(&path, &bytes, w as u32, h as u32, image::ColorType::Rgba8)
                        .map_err(|e| format!("{}: {e}", path.display()))?;
                    self.finish(ctx, Ok(()));
                }
            }
            Stage::Done => {}
        }
        Ok(())
    }
}

impl eframe::App for SmokeTest {
    fn ui(&mut self, ui: &mut egui::Ui, _frame: &mut eframe::Frame) {
        self.app.draw(ui);
        let ctx = ui.ctx().clone();
        if matches!(self.stage, Stage::Done) {
            return;
        }
        if let Some(error) = self.app.ui.error.clone() {
            self.finish(&ctx, Err(error));
            return;
        }
        if self.start.elapsed() > TIME_LIMIT {
            self.finish(&ctx, Err(format!("not done after {TIME_LIMIT:?}")));
            return;
        }
        if let Err(e) = self.step(&ctx) {
            self.finish(&ctx, Err(e));
            return;
        }
        ctx.request_repaint_after(Duration::from_millis(20));
    }
}
