//! Rendering actions of the editor: starting, polling and cancelling render jobs (each shown in a
//! viewer window), and keeping the path-traced viewport in step with the document.

use std::time::Duration;

use super::{RenderView, RtApp};
use crate::render_job::{JobOptions, JobState, RenderJob};

impl RtApp {
    /// Starts a render of the scene with its settings; earlier results stay open.
    pub fn start_render(&mut self) -> Option<u64> {
        if let Err(e) = rt_core::frame::validate(&self.doc.scene) {
            self.show_error(format!("Cannot render: {e}"));
            return None;
        }
        let bidirectional = self.doc.scene.settings.integrator == rt_core::Integrator::Bdpt;
        let mut scene = self.doc.scene.clone();
        if let Some(region) = self.ui.render_region
            && let Err(e) = scene.settings.crop_to_region(region)
        {
            self.show_error(format!("Cannot render the region: {e}"));
            return None;
        }
        let job = RenderJob::start(
            self.device.clone(),
            scene,
            None,
            JobOptions {
                preview_every: Some(Duration::from_millis(500)),
                // Bidirectional path tracing renders on the CPU backend.
                keep_aovs: true,
                on_cpu: bidirectional || self.ui.render_device.on_cpu(false).0,
            },
            self.waker(),
        );
        Some(self.add_render_view(job))
    }

    /// Opens a viewer window on `job`; returns its id.
    pub(super) fn add_render_view(&mut self, job: RenderJob) -> u64 {
        let id = self.next_render_id;
        self.next_render_id += 1;
        self.renders.push(RenderView::new(id, job));
        id
    }

    pub fn cancel_renders(&mut self) {
        for r in &self.renders {
            r.job.cancel();
        }
    }

    pub fn is_rendering(&self) -> bool {
        self.renders.iter().any(|r| r.job.is_running())
    }

    /// Takes in progress from the render threads; called once per frame.
    pub fn poll_jobs(&mut self) {
        for r in &mut self.renders {
            let was_running = r.job.is_running();
            r.job.poll();
            if was_running && !r.job.is_running() {
                match &r.job.state {
                    JobState::Finished | JobState::Cancelled => {
                        self.ui.last_render = Some(r.job.progress.elapsed);
                    }
                    JobState::Failed(message) => {
                        self.ui.error = Some(format!("The render failed:\n{message}"));
                    }
                    JobState::Running => {}
                }
            }
        }
        self.renders.retain(|r| r.open || r.job.is_running());
        if let Some(view) = &mut self.live.view {
            view.tick();
            if let Some(message) = view.error() {
                let message = message.to_string();
                self.live.enabled = false;
                self.live.view = None;
                self.show_error(format!("The path-traced viewport stopped:\n{message}"));
            }
        }
    }

    /// Keeps the path-traced viewport in step with the scene, the viewport's size and whether the
    /// user is dragging (the view then stays at its coarse step); starts and stops its threads.
    pub fn update_live_view(&mut self, size: [u32; 2], interacting: bool) {
        if !self.live.enabled {
            self.live.view = None;
            self.live.key = None;
            self.live.texture = None;
            self.live.texture_key = None;
            return;
        }
        // The view traces where the render windows do (the Render panel's Device): on a machine
        // without a GPU, the CPU backend, which answers at once where lavapipe would first compile
        // its kernels.
        let on_cpu = self.ui.render_device.on_cpu(false).0;
        if self.live.on_cpu != on_cpu {
            self.live.view = None;
            self.live.key = None;
            self.live.on_cpu = on_cpu;
        }
        let waker = self.waker();
        let device = self.device.clone();
        let view = self.live.view.get_or_insert_with(|| {
            let settings = rt_gpu::live::LiveSettings::default();
            if on_cpu {
                rt_gpu::live::LiveView::start_on_cpu(settings, waker)
            } else {
                rt_gpu::live::LiveView::start(
                    move || device.get().map_err(|e| format!("{e:#}")),
                    settings,
                    waker,
                )
            }
        });
        view.show_denoised = self.live.show_denoised;
        let key = (self.doc.revision(), size);
        if self.live.key == Some(key) {
            if interacting != self.live.interacting {
                view.set_interacting(interacting);
                self.live.interacting = interacting;
            }
            return;
        }
        let mut scene = self.doc.scene.clone();
        scene.settings.width = size[0].max(1);
        scene.settings.height = size[1].max(1);
        if rt_core::frame::validate(&scene).is_err() {
            return;
        }
        self.live.key = Some(key);
        self.live.interacting = interacting;
        view.request(rt_gpu::live::LiveRequest {
            scene,
            size,
            interacting,
        });
    }
}
