//! rt's GPU layer: adapter and device, pipelines specialised per scene, and the progressive
//! path-tracing renderer. Everything it uploads is built by `rt-core`.
//!
//! - `options`: what a caller may ask (`RenderOptions`, `Kernel`, `Tuning`).
//! - `bindings`: the tracing kernels' bind group, declared once.
//! - `pipelines`: both kernels' pipelines, specialised per feature set, in one cache (the key,
//!   the compiled stages and the cache the context holds are in `pipeline_cache`, below both).
//! - `renderer`: progressive batches of short dispatches; `sizing` chooses their size. What a
//!   renderer is made of: the scene's buffers (`buffers`), the output buffers and what is read
//!   back from them (`outputs`), what traces the paths (`engine`: the megakernel or the wavefront
//!   kernels, and the key that specialises them) and when its pipeline is rebuilt
//!   (`pipeline_lifetime`).
//! - `wavefront`: the wavefront kernels' queues and waves.
//! - `accel`: the driver's acceleration structure, for tracing with ray queries.
//! - `adaptive`: adaptive sampling's stop marks and the pixels still sampling.
//! - `tiling`: images larger than one buffer, in bands of rows.
//! - `image`: what is read back, and the one denoise helper.
//! - `faults`: the faults the test suites inject (only with the `testing` feature).

mod accel;
mod adaptive;
pub mod bindings;
pub mod both_devices;
mod buffers;
pub mod context;
mod engine;
pub mod error;
pub mod faults;
pub mod image;
pub mod live;
pub mod options;
mod outputs;
mod pipeline_cache;
mod pipeline_lifetime;
pub mod pipelines;
pub mod progressive;
pub mod render_loop;
pub mod renderer;
pub mod shaders;
pub mod sizing;
pub mod tiling;
#[cfg(feature = "testing")]
pub mod trace_rays;
pub mod wavefront;

pub use buffers::read_buffer;
pub use context::{AdapterChoice, DeviceOptions, GpuContext, hardware_gpu};
pub use error::{GpuError, Result};
pub use image::{Aovs, Image};
pub use options::{
    Adaptive, Kernel, MAX_WORKGROUP_INVOCATIONS, PipelineRebuilds, RenderOptions, Trace, Tuning,
};
pub use renderer::{BatchStats, Renderer};
pub use tiling::{
    TiledRender, pixel_binding_bytes, render_tiled, tile_rows, whole_image_binding_bytes,
};
