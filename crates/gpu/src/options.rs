//! What one run chooses of a render: the kernel, dispatch sizing and AOVs (the contract; what the
//! scene asks for, adaptive sampling included, is in its settings and so in the `Frame` or, for
//! adaptive sampling, read from them by `Renderer::for_scene` and `render_tiled`), and `Tuning`:
//! how the kernels run (measurements, tests and driver workarounds), never what they compute.

use std::time::Duration;

use crate::error::{GpuError, Result};

/// The most invocations a work group of the megakernel may have: each holds a 64-entry BVH
/// traversal stack in work-group memory (`crates/core/src/estimator/bvh.wgsl`), 16 KiB in all.
pub const MAX_WORKGROUP_INVOCATIONS: u32 = 64;

/// The megakernel's work group unless an experiment asks for another (measured in
/// docs/performance-log.md, "Work-group shape").
pub const DEFAULT_WORKGROUP: [u32; 2] = [8, 8];

/// The least pipeline lifetime of `PipelineRebuilds::OnGrowingCpuDrivers` without one given (the
/// compile-time amortisation usually decides: see docs/performance.md).
pub const CPU_PIPELINE_LIFETIME: Duration = Duration::from_secs(5);

/// Between rebuilds the kernel runs at least this many times as long as the last (re)build's first
/// batch took, which holds the JIT compile: rebuilds cost under 1/this of the render time.
pub const REBUILD_AMORTISATION: u32 = 10;

/// What traces the paths. Both run the one estimator of `crates/core/src/estimator/path.wgsl` and give the
/// same samples (bit for bit on lavapipe without delta lights; `tests/wavefront.rs`).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub enum Kernel {
    /// `shaders/wavefront.wgsl`: a kernel per path stage over queues of paths (the default:
    /// 1.35-1.9x the megakernel on lavapipe, docs/performance.md).
    #[default]
    Wavefront,
    /// `shaders/trace.wgsl`: one invocation runs whole paths.
    Megakernel,
}

impl Kernel {
    pub fn name(self) -> &'static str {
        match self {
            Kernel::Wavefront => "wavefront",
            Kernel::Megakernel => "megakernel",
        }
    }
}

/// What finds the rays' nearest hits.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub enum Trace {
    /// `Hardware` on GPUs that offer ray queries, `Bvh` elsewhere: on lavapipe, whose ray queries
    /// are software too, rt's own traversal measured faster (docs/performance.md).
    #[default]
    Auto,
    /// rt's traversal of the obvhs BVH (`crates/core/src/estimator/cwbvh.wgsl` or `bvh.wgsl`).
    Bvh,
    /// The driver's ray queries over an acceleration structure it builds
    /// (`shaders/ray_query.wgsl`): ray-tracing hardware where the GPU has it. An error
    /// where the adapter has no ray queries.
    Hardware,
}

impl Trace {
    pub fn name(self) -> &'static str {
        match self {
            Trace::Auto => "auto",
            Trace::Bvh => "bvh",
            Trace::Hardware => "hw",
        }
    }
}

/// How to render. `Default` is what `rt` and `rt-cli` use, apart from the switches they set.
#[derive(Clone, Copy, Debug)]
pub struct RenderOptions {
    pub kernel: Kernel,
    pub trace: Trace,
    /// Each dispatch (of the wavefront kernels: each submission of a wave) should take about this,
    /// well under the ~100 ms at which operating systems start to suspect a hung GPU.
    pub target_dispatch: Duration,
    /// Upper bound on samples per pixel in one dispatch; `None` derives it from the loop budget.
    pub max_samples_per_dispatch: Option<u32>,
    /// Also accumulate each pixel's first-hit albedo and normal and the light seen directly (for
    /// the denoiser; read them with `Renderer::read_aovs`).
    pub aovs: bool,
    /// The index of the render's first sample: a shard of a larger render (`rt-cli render
    /// --shard`) takes samples `first_sample..first_sample + spp` of the whole image's, with the
    /// same random numbers a one-machine render gives them.
    pub first_sample: u32,
    /// How the kernels run, never what they compute: measurements and driver workarounds.
    pub tuning: Tuning,
}

impl Default for RenderOptions {
    fn default() -> Self {
        RenderOptions {
            kernel: Kernel::default(),
            trace: Trace::default(),
            target_dispatch: Duration::from_millis(40),
            max_samples_per_dispatch: None,
            aovs: false,
            first_sample: 0,
            tuning: Tuning::default(),
        }
    }
}

pub use rt_core::adaptive::Adaptive;

/// How the kernels run, never what they compute (tests/extremes/ checks the images are
/// identical): switches for measurements (`rt-cli bench`) and tests, and the CPU-driver memory
/// workaround the binaries turn on. No user setting lives here; `Default` is the library's
/// behaviour.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Tuning {
    /// Count rays in the kernel (benchmarks); compiled out otherwise.
    pub count_rays: bool,
    /// When the tracing pipeline is rebuilt (never, by default).
    pub pipeline_rebuilds: PipelineRebuilds,
    /// Compile every optional feature in, as if the scene used them all (benchmarks compare this
    /// generic kernel with the specialised one).
    pub generic_kernel: bool,
    /// The megakernel's work-group width and height, at most `MAX_WORKGROUP_INVOCATIONS`
    /// invocations (the BVH traversal stacks live in work-group memory). The wavefront kernels
    /// always run 64 x 1.
    pub workgroup: [u32; 2],
}

impl Default for Tuning {
    fn default() -> Self {
        Tuning {
            count_rays: false,
            pipeline_rebuilds: PipelineRebuilds::Never,
            generic_kernel: false,
            workgroup: DEFAULT_WORKGROUP,
        }
    }
}

/// When a renderer rebuilds its tracing pipeline (`Tuning::pipeline_rebuilds`). A rebuild changes
/// no sample. Some CPU drivers hold host memory for every path a compiled megakernel traces until
/// its pipeline is destroyed (Mesa 22.3's lavapipe; the wavefront kernels do not grow:
/// tests/memory.rs), and a fresh build lets them free it.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum PipelineRebuilds {
    /// Never: the default, for renderers that share a device with others (the tests: a CI run
    /// of the suite with rebuilds on stalled inside lavapipe).
    #[default]
    Never,
    /// Where the driver grows: a CPU adapter other than Mesa 25 or newer (which stays flat,
    /// docs/performance-log.md), with the megakernel. After `lifetime` of kernel time exactly, or
    /// by default after `CPU_PIPELINE_LIFETIME` or `REBUILD_AMORTISATION` times the last build's
    /// first batch (its JIT compile), whichever is longer. `rt-cli render` and `converge` ask for
    /// it (`lifetime` from `RT_PIPELINE_LIFETIME_S`: rt-gpu reads no environment).
    OnGrowingCpuDrivers { lifetime: Option<Duration> },
    /// After exactly this much kernel time (not counting the first batch after a build),
    /// whatever the adapter and kernel.
    Every(Duration),
}

impl RenderOptions {
    /// An error for a combination that cannot be honoured (rather than silently ignoring a part).
    pub fn validate(&self) -> Result<()> {
        let [wx, wy] = self.tuning.workgroup;
        if wx == 0
            || wy == 0
            || wx
                .checked_mul(wy)
                .is_none_or(|n| n > MAX_WORKGROUP_INVOCATIONS)
        {
            return Err(GpuError::Options(format!(
                "work group {wx}x{wy}: it must have 1 to {MAX_WORKGROUP_INVOCATIONS} invocations \
                 (their BVH traversal stacks share the work group's 16 KiB of memory)"
            )));
        }
        if self.kernel == Kernel::Wavefront && self.tuning.workgroup != DEFAULT_WORKGROUP {
            return Err(GpuError::Options(format!(
                "work group {wx}x{wy}: work-group shapes are the megakernel's (the wavefront \
                 kernels run 64x1); choose the megakernel"
            )));
        }
        Ok(())
    }
}
