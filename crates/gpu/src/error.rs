//! Errors of the GPU layer.

#[derive(Debug, thiserror::Error)]
pub enum GpuError {
    /// No adapter matched (or none exists at all).
    #[error("no GPU adapter found{0}")]
    NoAdapter(String),
    /// The device could not be created.
    #[error("could not open the GPU device: {0}")]
    Device(String),
    /// A buffer the scene needs exceeds one of the adapter's limits.
    #[error(
        "the {buffer} buffer needs {size} bytes but this adapter allows at most {limit} bytes ({what})"
    )]
    TooLarge {
        buffer: &'static str,
        size: u64,
        limit: u64,
        what: &'static str,
    },
    /// The render options contradict each other or the adapter.
    #[error("invalid render options: {0}")]
    Options(String),
    /// wgpu reported a validation error.
    #[error("GPU error: {0}")]
    Wgpu(String),
    /// Creating a resource (buffer, texture) failed for lack of GPU memory. The device stays
    /// usable: what was rendered before can still be read back. (wgpu 30 marks the device lost when
    /// memory runs out in a submission or a pipeline: that arrives as `DeviceLost`.)
    #[error(
        "the GPU ran out of memory ({0}); a smaller image, fewer triangles or textures, or another \
         adapter may fit"
    )]
    OutOfMemory(String),
    /// The device was lost (driver reset, GPU removed, watchdog, or destroyed); nothing more can
    /// be rendered or read back on it.
    #[error("the GPU device was lost ({0})")]
    DeviceLost(String),
    /// The scene or its settings are invalid.
    #[error(transparent)]
    Scene(#[from] rt_core::Error),
}

pub type Result<T, E = GpuError> = std::result::Result<T, E>;
