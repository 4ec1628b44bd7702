//! The flags `render`, `converge` and `bench` share, as clap structs flattened into each, and the
//! one place they become `RenderSettings` and `RenderOptions`.

use clap::Args;
use rt_core::RenderSettings;
use rt_core::bvh::{BvhLayout, BvhQuality};
use rt_core::math::rng::SamplerKind;
use rt_gpu::{AdapterChoice, DeviceOptions, GpuContext, Kernel, RenderOptions, Trace};

/// Image size and estimator (render, converge).
#[derive(Args, Debug, Clone, Default)]
pub struct EstimatorArgs {
    #[arg(long)]
    pub width: Option<u32>,
    #[arg(long)]
    pub height: Option<u32>,
    /// Ray segments per path (1: emitters only, 2: direct light, ...).
    #[arg(long)]
    pub max_depth: Option<u32>,
    /// Turn off next-event estimation (sample only the BSDF; noisier, for comparisons).
    #[arg(long)]
    pub no_nee: bool,
    /// Diagnostic: take area lights from next-event estimation alone, without MIS (unbiased but
    /// noisier; for comparing estimators).
    #[arg(long, conflicts_with = "no_nee")]
    pub nee_only: bool,
    /// Turn off Russian roulette (every path runs to max depth unless it is absorbed or escapes).
    #[arg(long)]
    pub no_roulette: bool,
    /// Firefly clamp: scale each contribution of bounced light down so no channel exceeds X
    /// (directly seen emitters stay exact). Biased (removes energy); off by default.
    #[arg(long, value_name = "X")]
    pub clamp: Option<f32>,
    /// Random numbers: sobol (Owen-scrambled Sobol points, the default: less noise for the same
    /// samples) or independent (PCG streams).
    #[arg(long, value_enum)]
    pub sampler: Option<SamplerArg>,
    /// Adaptive sampling: after 64 samples (--adaptive-min-samples) a pixel stops once its
    /// estimated noise (the square root of its relMSE term, as --noise-target measures the image)
    /// and its neighbours' is at most X, judged on each of two halves of its samples for the other
    /// half (so it stays unbiased).
    #[arg(long, value_name = "X")]
    pub adaptive: Option<f32>,
    /// The samples every pixel takes before adaptive sampling may stop it (Cycles' Min Samples;
    /// default 64, at least 2).
    #[arg(long, value_name = "N")]
    pub adaptive_min_samples: Option<u32>,
    /// How next-event estimation picks a light: tree (an emitter, point or spot light by its
    /// importance at the shading point, through the light tree: for scenes with many lights), power
    /// (an emitter in proportion to its power, every point and spot light summed), or auto (the
    /// default: the tree from 16 lights on).
    #[arg(long, value_enum)]
    pub light_sampler: Option<LightSamplerArg>,
    /// How light is gathered: path (path tracing, the default) or bdpt (bidirectional path
    /// tracing: paths from the lights as well, for caustics such as light focused through glass;
    /// the CPU backend only, so `--device auto` renders it there).
    #[arg(long, value_enum)]
    pub integrator: Option<IntegratorArg>,
}

/// `--integrator` values.
#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
pub enum IntegratorArg {
    Path,
    Bdpt,
}

impl From<IntegratorArg> for rt_core::Integrator {
    fn from(i: IntegratorArg) -> Self {
        match i {
            IntegratorArg::Path => Self::Path,
            IntegratorArg::Bdpt => Self::Bdpt,
        }
    }
}

impl EstimatorArgs {
    /// Applies the flags over the scene's own settings (a flag left out keeps the scene's value).
    pub fn apply(&self, settings: &mut RenderSettings) {
        settings.width = self.width.unwrap_or(settings.width);
        settings.height = self.height.unwrap_or(settings.height);
        settings.max_depth = self.max_depth.unwrap_or(settings.max_depth);
        settings.next_event_estimation = !self.no_nee;
        settings.nee_only = self.nee_only;
        settings.russian_roulette = !self.no_roulette;
        settings.clamp = self.clamp.or(settings.clamp);
        if let Some(sampler) = self.sampler {
            settings.sampler = sampler.into();
        }
        settings.adaptive_threshold = self.adaptive.or(settings.adaptive_threshold);
        settings.adaptive_min_samples = self
            .adaptive_min_samples
            .unwrap_or(settings.adaptive_min_samples);
        if let Some(sampler) = self.light_sampler {
            settings.light_sampler = sampler.into();
        }
        if let Some(integrator) = self.integrator {
            settings.integrator = integrator.into();
        }
    }
}

/// `--light-sampler` values.
#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
pub enum LightSamplerArg {
    Auto,
    Power,
    Tree,
}

impl From<LightSamplerArg> for rt_core::LightSampler {
    fn from(s: LightSamplerArg) -> Self {
        match s {
            LightSamplerArg::Auto => Self::Auto,
            LightSamplerArg::Power => Self::Power,
            LightSamplerArg::Tree => Self::Tree,
        }
    }
}

/// Which adapter and kernel render (render, converge, bench).
#[derive(Args, Debug, Clone, Default)]
pub struct EngineArgs {
    /// What traces the paths: wavefront (the default) or megakernel; the same image either way
    /// (docs/performance.md compares them).
    #[arg(long, value_enum)]
    pub kernel: Option<KernelArg>,
    /// What finds the nearest hits: hw (the driver's ray queries: ray-tracing hardware where the
    /// GPU has it), bvh (rt's own traversal) or auto (hw on GPUs that offer ray queries, else bvh).
    #[arg(long, value_enum, default_value = "auto")]
    pub trace: TraceArg,
    /// GPU adapter: auto, lavapipe (a software GPU on the CPU, also `cpu`; not --device cpu, rt's
    /// native CPU backend), or part of an adapter's name.
    #[arg(long, default_value = "auto")]
    pub adapter: AdapterChoice,
    /// What renders: auto (the default: a hardware GPU if there is one, else cpu), gpu (a GPU
    /// through wgpu; lavapipe where there is none), cpu (rt's native CPU backend, the
    /// estimator's Rust twin on every core: the same samples, so the same image and mergeable
    /// parts) or all (`render` only: the GPU and the CPU backend on one frame, each taking ranges
    /// of its samples as fast as it renders them).
    #[arg(long, value_enum, default_value = "auto")]
    pub device: DeviceArg,
}

/// `--device` values (`rt_gpu::progressive::Device`).
#[derive(clap::ValueEnum, Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum DeviceArg {
    #[default]
    Auto,
    Gpu,
    Cpu,
    All,
}

impl EngineArgs {
    /// Whether the CPU backend renders, and why (the summary's `device:` line). `--adapter`,
    /// `--kernel` and `--trace hw` choose how a GPU renders: with `--device cpu` they are an
    /// error, and they make `auto` a GPU.
    pub fn on_cpu(&self) -> anyhow::Result<(bool, String)> {
        let gpu_flags: Vec<&str> = [
            (self.kernel.is_some(), "--kernel"),
            (self.adapter != AdapterChoice::Auto, "--adapter"),
            // Ray queries are a GPU's (`--trace bvh` is what the CPU backend does anyway).
            (self.trace == TraceArg::Hw, "--trace hw"),
        ]
        .into_iter()
        .filter_map(|(given, flag)| given.then_some(flag))
        .collect();
        if self.device == DeviceArg::Cpu && !gpu_flags.is_empty() {
            let one = gpu_flags.len() == 1;
            anyhow::bail!(
                "{} choose{} how a GPU renders, and --device cpu renders without one: drop {}, or \
                 render with --device gpu",
                gpu_flags.join(" and "),
                if one { "s" } else { "" },
                if one { "it" } else { "them" },
            );
        }
        let device = match self.device {
            DeviceArg::Auto => rt_gpu::progressive::Device::Auto,
            DeviceArg::Gpu => rt_gpu::progressive::Device::Gpu,
            DeviceArg::Cpu => rt_gpu::progressive::Device::Cpu,
            DeviceArg::All => anyhow::bail!(
                "--device all is for `render` (one frame on both devices); choose auto, gpu or \
                 cpu here"
            ),
        };
        Ok(device.on_cpu(!gpu_flags.is_empty()))
    }

    /// `on_cpu` for a render with `settings`: bidirectional path tracing renders on the CPU
    /// backend only, so `auto` puts it there and `gpu` or `all` is an error.
    pub fn on_cpu_for(&self, settings: &RenderSettings) -> anyhow::Result<(bool, String)> {
        if settings.integrator != rt_core::Integrator::Bdpt {
            return self.on_cpu();
        }
        match self.device {
            DeviceArg::Cpu => self.on_cpu(),
            DeviceArg::Auto => {
                let on_cpu = EngineArgs {
                    device: DeviceArg::Cpu,
                    ..self.clone()
                };
                on_cpu.on_cpu()?;
                Ok((
                    true,
                    "auto: --integrator bdpt renders on the CPU backend".into(),
                ))
            }
            DeviceArg::Gpu | DeviceArg::All => anyhow::bail!(
                "bidirectional path tracing (--integrator bdpt) renders on the CPU backend only, \
                 not with --device {}: render with --device cpu, or with --integrator path",
                if self.device == DeviceArg::All {
                    "all"
                } else {
                    "gpu"
                }
            ),
        }
    }

    pub fn kernel(&self) -> Kernel {
        self.kernel.map(Into::into).unwrap_or_default()
    }

    /// The options a user's render runs with: `render` (whole or tiled) and `converge` use these
    /// as they are; `bench` adds its measurement switches on top.
    pub fn render_options(&self, denoise: bool) -> RenderOptions {
        RenderOptions {
            kernel: self.kernel(),
            trace: self.trace.into(),
            aovs: denoise,
            // Bounds lavapipe's memory growth over long megakernel renders (docs/performance.md).
            tuning: rt_gpu::Tuning {
                pipeline_rebuilds: rt_gpu::PipelineRebuilds::OnGrowingCpuDrivers {
                    lifetime: pipeline_lifetime_from_env(),
                },
                ..Default::default()
            },
            ..Default::default()
        }
    }
}

/// `RT_PIPELINE_LIFETIME_S` (seconds, finite and not negative): the exact pipeline lifetime of
/// the CPU memory workaround (`PipelineRebuilds::OnGrowingCpuDrivers`). The binary reads the
/// environment; the library takes the value.
fn pipeline_lifetime_from_env() -> Option<std::time::Duration> {
    std::env::var("RT_PIPELINE_LIFETIME_S")
        .ok()
        .and_then(|v| v.trim().parse::<f64>().ok())
        .filter(|s| s.is_finite() && *s >= 0.0)
        .map(std::time::Duration::from_secs_f64)
}

/// Opens `adapter`'s device as the environment asks: `RT_NO_RAY_QUERY` (set, and not `0`) leaves
/// ray queries off, should a driver misbehave with them (every subcommand opens it here).
pub fn open_device(adapter: &AdapterChoice) -> rt_gpu::Result<GpuContext> {
    let no_ray_query = std::env::var_os("RT_NO_RAY_QUERY");
    let options = DeviceOptions::from_no_ray_query_var(no_ray_query.as_deref());
    GpuContext::with_options(adapter, options)
}

/// The BVH (converge, bench).
#[derive(Args, Debug, Clone)]
pub struct BvhArgs {
    /// BVH build preset: faster builds make slower traversal (`fast`, the default, traverses as
    /// fast as `medium` on the bench scenes and builds 10-15% sooner).
    #[arg(long, value_enum, default_value = "fast")]
    pub bvh_quality: Quality,
    /// BVH layout the kernel traverses.
    #[arg(long, value_enum, default_value = "cwbvh")]
    pub bvh: Layout,
}

/// `--sampler` values.
#[derive(Clone, Copy, Debug, clap::ValueEnum)]
pub enum SamplerArg {
    Independent,
    Sobol,
}

impl From<SamplerArg> for SamplerKind {
    fn from(s: SamplerArg) -> Self {
        match s {
            SamplerArg::Independent => Self::Independent,
            SamplerArg::Sobol => Self::Sobol,
        }
    }
}

/// `--kernel` values.
#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
pub enum KernelArg {
    /// A kernel per path stage over queues of paths (the default).
    Wavefront,
    /// One kernel runs whole paths.
    Megakernel,
}

impl From<KernelArg> for Kernel {
    fn from(k: KernelArg) -> Self {
        match k {
            KernelArg::Wavefront => Kernel::Wavefront,
            KernelArg::Megakernel => Kernel::Megakernel,
        }
    }
}

/// `--trace` values.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, clap::ValueEnum)]
pub enum TraceArg {
    #[default]
    Auto,
    Bvh,
    Hw,
}

impl From<TraceArg> for Trace {
    fn from(t: TraceArg) -> Self {
        match t {
            TraceArg::Auto => Trace::Auto,
            TraceArg::Bvh => Trace::Bvh,
            TraceArg::Hw => Trace::Hardware,
        }
    }
}

/// `--bvh-quality` values.
#[derive(Clone, Copy, Debug, clap::ValueEnum)]
pub enum Quality {
    Fastest,
    Fast,
    Medium,
    Slow,
}

impl From<Quality> for BvhQuality {
    fn from(q: Quality) -> Self {
        match q {
            Quality::Fastest => BvhQuality::Fastest,
            Quality::Fast => BvhQuality::Fast,
            Quality::Medium => BvhQuality::Medium,
            Quality::Slow => BvhQuality::Slow,
        }
    }
}

/// `--bvh` values.
#[derive(Clone, Copy, Debug, clap::ValueEnum)]
pub enum Layout {
    /// Binary BVH, uncompressed boxes.
    Bvh2,
    /// Compressed wide BVH8 (the default).
    Cwbvh,
}

impl From<Layout> for BvhLayout {
    fn from(l: Layout) -> Self {
        match l {
            Layout::Bvh2 => BvhLayout::Bvh2,
            Layout::Cwbvh => BvhLayout::Cwbvh,
        }
    }
}

#[cfg(test)]
mod tests {
    use clap::Parser;

    use super::*;

    #[derive(Parser)]
    struct Flags {
        #[command(flatten)]
        estimator: EstimatorArgs,
        #[command(flatten)]
        engine: EngineArgs,
    }

    fn parse(args: &[&str]) -> Flags {
        match Flags::try_parse_from(std::iter::once("rt-cli").chain(args.iter().copied())) {
            Ok(flags) => flags,
            Err(e) => panic!("{args:?}: {e}"),
        }
    }

    #[test]
    fn every_estimator_flag_reaches_the_settings() {
        let flags = parse(&[
            "--width",
            "7",
            "--height",
            "5",
            "--max-depth",
            "3",
            "--nee-only",
            "--no-roulette",
            "--clamp",
            "2.5",
            "--sampler",
            "independent",
            "--adaptive",
            "0.05",
        ]);
        let mut settings = RenderSettings::default();
        flags.estimator.apply(&mut settings);
        assert_eq!(settings.adaptive_threshold, Some(0.05));
        assert_eq!(
            (settings.width, settings.height, settings.max_depth),
            (7, 5, 3)
        );
        assert!(settings.nee_only && settings.next_event_estimation);
        assert!(!settings.russian_roulette);
        assert_eq!(settings.clamp, Some(2.5));
        assert_eq!(settings.sampler, SamplerKind::Independent);
        let mut settings = RenderSettings::default();
        parse(&["--no-nee"]).estimator.apply(&mut settings);
        assert!(!settings.next_event_estimation);
    }

    #[test]
    fn flags_left_out_keep_the_scene_settings() {
        let scene = RenderSettings {
            width: 33,
            max_depth: 11,
            clamp: Some(4.0),
            sampler: SamplerKind::Independent,
            adaptive_threshold: Some(0.1),
            ..RenderSettings::default()
        };
        let mut settings = scene.clone();
        parse(&[]).estimator.apply(&mut settings);
        assert_eq!(settings, scene);
    }

    #[test]
    fn the_engine_flags_reach_the_options() {
        let options = parse(&["--kernel", "megakernel"])
            .engine
            .render_options(true);
        assert_eq!(options.kernel, Kernel::Megakernel);
        assert!(
            options.aovs
                && matches!(
                    options.tuning.pipeline_rebuilds,
                    rt_gpu::PipelineRebuilds::OnGrowingCpuDrivers { .. }
                )
        );
        let options = parse(&[]).engine.render_options(false);
        assert_eq!(options.kernel, Kernel::Wavefront);
        assert_eq!(options.trace, Trace::Auto);
        assert!(!options.aovs);
    }
}

/// `--denoise[=auto|oidn|atrous]`: which denoiser (`rt_core::denoiser`). `auto` (a bare
/// `--denoise`) runs Open Image Denoise when it loads and rt's À-Trous filter otherwise, saying
/// why; `oidn` fails when OIDN is missing instead.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, clap::ValueEnum)]
pub enum DenoiseArg {
    #[default]
    Auto,
    Oidn,
    Atrous,
}

impl DenoiseArg {
    pub fn name(self) -> &'static str {
        match self {
            DenoiseArg::Auto => "auto",
            DenoiseArg::Oidn => "oidn",
            DenoiseArg::Atrous => "atrous",
        }
    }

    pub fn choice(self) -> rt_core::denoiser::DenoiserChoice {
        use rt_core::denoiser::DenoiserChoice;
        match self {
            DenoiseArg::Auto => DenoiserChoice::Auto,
            DenoiseArg::Oidn => DenoiserChoice::Oidn,
            DenoiseArg::Atrous => DenoiserChoice::Atrous,
        }
    }
}

/// `WxH` with each side in `1..=max`, e.g. `example`; errors name `what` a side is.
pub fn parse_pair(s: &str, example: &str, max: u32, what: &str) -> Result<[u32; 2], String> {
    let (a, b) = s
        .split_once('x')
        .ok_or_else(|| format!("expected WxH like {example}, got '{s}'"))?;
    let parse = |v: &str| match v.trim().parse::<u32>() {
        Ok(n) if (1..=max).contains(&n) => Ok(n),
        _ => Err(format!("'{v}' is not {what} in 1..={max}")),
    };
    Ok([parse(a)?, parse(b)?])
}
