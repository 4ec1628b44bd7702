//! A progressive render on either backend, behind the few calls a command that drives one batch
//! by batch needs (`converge`, `render --device cpu`): the GPU's `Renderer`, or the native CPU
//! backend's accumulation (`rt_core::cpu_render`).

use std::sync::atomic::AtomicBool;

use anyhow::Result;
use rt_core::cpu_render::CpuAccumulation;
use rt_core::gpu_types::Frame;
use rt_core::{GpuScene, Scene};
use rt_gpu::Renderer;

pub enum Progressive<'a> {
    Gpu(Box<Renderer<'a>>),
    Cpu(Box<CpuRun<'a>>),
}

/// The CPU backend's state: the scene, its frame, and the samples so far.
pub struct CpuRun<'a> {
    scene: &'a GpuScene,
    frame: Frame,
    accumulation: CpuAccumulation,
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
        let frame = rt_core::frame::frame_for(scene, gpu_scene)?;
        let adaptive = rt_core::adaptive::Adaptive::of_settings(&scene.settings);
        Ok(Progressive::Cpu(Box::new(CpuRun {
            scene: gpu_scene,
            accumulation: CpuAccumulation::new(&frame, first_sample, adaptive, guides),
            frame,
        })))
    }

    /// Samples taken of every pixel still sampling.
    pub fn samples_done(&self) -> u32 {
        match self {
            Progressive::Gpu(r) => r.samples_done(),
            Progressive::Cpu(c) => c.accumulation.samples,
        }
    }

    pub fn active_pixels(&self) -> usize {
        match self {
            Progressive::Gpu(r) => r.active_pixels(),
            Progressive::Cpu(c) => c.accumulation.active_pixels(),
        }
    }

    /// Up to `samples` more samples of every pixel still sampling.
    pub fn render_batch(&mut self, samples: u32) -> Result<()> {
        match self {
            Progressive::Gpu(r) => {
                r.render_batch(samples)?;
            }
            Progressive::Cpu(c) => {
                let never = AtomicBool::new(false);
                c.accumulation.add_batch(c.scene, &c.frame, samples, &never);
            }
        }
        Ok(())
    }

    pub fn read_image(&self) -> Result<rt_gpu::Image> {
        Ok(match self {
            Progressive::Gpu(r) => r.read_image()?,
            Progressive::Cpu(c) => image_of(&c.accumulation),
        })
    }

    /// The denoiser's guides, when kept.
    pub fn read_aovs(&self) -> Result<Option<rt_gpu::Aovs>> {
        Ok(match self {
            Progressive::Gpu(r) => r.read_aovs()?,
            Progressive::Cpu(c) => c.accumulation.guides().map(|g| rt_gpu::Aovs {
                albedo: g.albedo.clone(),
                normal: g.normal.clone(),
                emission: g.emission.clone(),
            }),
        })
    }
}

/// The CPU accumulation as the image the rest of rt-cli saves and measures.
pub fn image_of(accumulation: &CpuAccumulation) -> rt_gpu::Image {
    rt_gpu::Image {
        width: accumulation.width,
        height: accumulation.height,
        samples_per_pixel: accumulation.samples,
        sample_counts: accumulation.adaptive().then(|| accumulation.counts()),
        pixels: accumulation.pixels(),
        sums: accumulation.sums.clone(),
    }
}
