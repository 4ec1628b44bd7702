//! A progressive render on either backend, driven batch by batch by rt's one loop
//! (`crate::render_loop::render_to`: `rt-cli render`, `converge`, `bench`, `interactive`'s
//! references, the editor's render windows): the GPU's `Renderer`, or the native CPU backend's
//! accumulation (`rt_core::cpu_render`), whose batches are sized to take about `BATCH_DURATION`
//! each so that progress, previews and cancelling stay responsive.

use std::sync::atomic::AtomicBool;
use std::time::Instant;

use rt_core::cpu_render::{BATCH_DURATION, CpuAccumulation};
use rt_core::gpu_types::Frame;
use rt_core::{GpuScene, Scene};

use crate::both_devices::BothDevices;
use crate::error::Result;
use crate::image::{Aovs, Image};
use crate::render_loop::{AfterBatch, Batches, Ended, render_to};
use crate::renderer::Renderer;

/// Which backend renders: what `rt-cli --device` and the editor's Device choose.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Device {
    /// A hardware GPU when wgpu finds one, else the CPU backend (software adapters such as
    /// lavapipe are slower than it, so they do not count): the default.
    #[default]
    Auto,
    /// The GPU through wgpu (lavapipe on a machine without one).
    Gpu,
    /// rt's native CPU backend.
    Cpu,
}

impl Device {
    /// Whether the CPU backend renders, and why (for a summary line). `gpu_flags`: the caller
    /// was asked for a particular adapter, kernel or ray queries, which makes `Auto` a GPU.
    pub fn on_cpu(self, gpu_flags: bool) -> (bool, String) {
        match self {
            Device::Auto if gpu_flags => (
                false,
                "auto: --adapter, --kernel or --trace hw asks for a GPU".into(),
            ),
            Device::Auto => match hardware_gpu_cached() {
                Some(name) => (false, format!("auto: hardware GPU {name}")),
                None => (
                    true,
                    "auto: no hardware GPU (software adapters such as lavapipe do not count)"
                        .into(),
                ),
            },
            Device::Gpu => (false, "--device gpu".into()),
            Device::Cpu => (true, "--device cpu".into()),
        }
    }
}

/// `crate::hardware_gpu`, asked once per process (it enumerates the adapters).
fn hardware_gpu_cached() -> Option<&'static str> {
    static FOUND: std::sync::OnceLock<Option<String>> = std::sync::OnceLock::new();
    FOUND.get_or_init(crate::hardware_gpu).as_deref()
}

pub enum Progressive<'a> {
    Gpu(Box<Renderer<'a>>),
    Cpu(Box<CpuRun<'a>>),
    /// `--device all`: both on one frame.
    Both(Box<BothDevices<'a>>),
}

/// The CPU backend's state: the scene, its frame, the samples so far, and the next batch's size.
pub struct CpuRun<'a> {
    scene: &'a GpuScene,
    frame: Frame,
    accumulation: CpuAccumulation,
    batch: u32,
}

impl<'a> Progressive<'a> {
    /// The CPU backend on `scene` from sample `first_sample`, keeping the denoiser's guides when
    /// `guides` asks; adaptive sampling as the scene's settings say.
    pub fn cpu(
        scene: &Scene,
        gpu_scene: &'a GpuScene,
        first_sample: u32,
        guides: bool,
    ) -> Result<Self> {
        let frame = rt_core::frame::frame_for(scene, gpu_scene)
            .map_err(|e| crate::GpuError::Options(e.to_string()))?;
        let adaptive = rt_core::adaptive::Adaptive::of_settings(&scene.settings);
        let accumulation = CpuAccumulation::new(&frame, first_sample, adaptive, guides)
            .with_integrator(scene.settings.integrator, gpu_scene, &frame)
            .map_err(crate::GpuError::Options)?;
        Ok(Progressive::Cpu(Box::new(CpuRun {
            scene: gpu_scene,
            accumulation,
            frame,
            batch: 1,
        })))
    }

    /// The render taken to `spp` samples per pixel (`render_loop::render_to`), with nothing to
    /// cancel or watch it.
    pub fn render(&mut self, spp: u32) -> Result<Ended> {
        let never = AtomicBool::new(false);
        render_to(
            self,
            spp,
            &never,
            |done| spp - done,
            |_| Ok(AfterBatch::Continue),
        )
    }

    /// Rays traced so far (on the GPU only with `Tuning::count_rays`).
    pub fn rays_traced(&self) -> u64 {
        match self {
            Progressive::Gpu(r) => r.rays_traced(),
            Progressive::Cpu(c) => c.accumulation.rays,
            Progressive::Both(b) => b.rays_traced(),
        }
    }

    /// Samples taken of every pixel still sampling.
    pub fn samples_done(&self) -> u32 {
        match self {
            Progressive::Gpu(r) => r.samples_done(),
            Progressive::Cpu(c) => c.accumulation.samples,
            Progressive::Both(b) => b.samples_done(),
        }
    }

    pub fn active_pixels(&self) -> usize {
        match self {
            Progressive::Gpu(r) => r.active_pixels(),
            Progressive::Cpu(c) => c.accumulation.active_pixels(),
            Progressive::Both(b) => b.gpu().active_pixels(),
        }
    }

    /// The image's estimated noise (`Image::estimated_noise`); on the CPU without copying its
    /// sums.
    pub fn estimated_noise(&self) -> Result<f64> {
        Ok(match self {
            Progressive::Gpu(r) => r.read_image()?.estimated_noise(),
            Progressive::Both(b) => b.read_image()?.estimated_noise(),
            Progressive::Cpu(c) => {
                let counts = c.accumulation.counts();
                rt_core::metrics::estimated_rel_mse(
                    &c.accumulation.pixels(),
                    rt_core::output::SampleCounts::PerPixel(&counts),
                )
                .sqrt()
            }
        })
    }

    pub fn read_image(&self) -> Result<Image> {
        Ok(match self {
            Progressive::Gpu(r) => r.read_image()?,
            Progressive::Cpu(c) => image_of(&c.accumulation),
            Progressive::Both(b) => b.read_image()?,
        })
    }

    /// The denoiser's guides, when kept.
    pub fn read_aovs(&self) -> Result<Option<Aovs>> {
        Ok(match self {
            Progressive::Gpu(r) => r.read_aovs()?,
            Progressive::Cpu(c) => Aovs::of_cpu(&c.accumulation),
            Progressive::Both(b) => b.read_aovs()?,
        })
    }
}

impl Batches for Progressive<'_> {
    fn samples_done(&self) -> u32 {
        Progressive::samples_done(self)
    }

    fn active_pixels(&self) -> usize {
        Progressive::active_pixels(self)
    }

    /// Up to `samples` more samples of every pixel still sampling (on the CPU, as many as fit in
    /// about `BATCH_DURATION`; a batch that `cancel` stops adds nothing).
    fn take_batch(&mut self, samples: u32, cancel: &AtomicBool) -> Result<()> {
        match self {
            Progressive::Gpu(r) => {
                r.render_batch(samples)?;
            }
            Progressive::Cpu(c) => {
                let count = samples.min(c.batch).max(1);
                let started = Instant::now();
                if c.accumulation.add_batch(c.scene, &c.frame, count, cancel)
                    && started.elapsed() < BATCH_DURATION / 2
                {
                    c.batch = c.batch.saturating_mul(2);
                }
            }
            Progressive::Both(b) => b.render_batch(samples, cancel)?,
        }
        Ok(())
    }
}

/// The CPU backend, as a status line names it.
pub fn cpu_label() -> String {
    format!(
        "CPU (native backend, {} threads)",
        rt_core::cpu_render::threads()
    )
}

/// The CPU accumulation as the image the rest of rt saves and measures.
pub(crate) fn image_of(accumulation: &CpuAccumulation) -> Image {
    let (sums, counts) = accumulation.image_sums();
    crate::outputs::mean_image(
        accumulation.width,
        accumulation.height,
        accumulation.samples,
        sums,
        accumulation.adaptive().then_some(counts),
    )
}
