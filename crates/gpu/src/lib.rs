//! rt's GPU layer: adapter and device, pipelines specialised per scene, and the progressive
//! path-tracing renderer. Everything it uploads is built by `rt-core`.
//!
//! - `options`: what a caller may ask (`RenderOptions`, `Kernel`, `Experiments`).
//! - `bindings`: the tracing kernels' bind group, declared once.
//! - `pipelines`: both kernels' pipelines, specialised per feature set, in one cache.
//! - `renderer`: progressive batches of short dispatches; `sizing` chooses their size.
//! - `wavefront`: the wavefront kernels' queues and waves.
//! - `accel`: the driver's acceleration structure, for tracing with ray queries.
//! - `adaptive`: adaptive sampling's stop marks and the pixels still sampling.
//! - `tiling`: images larger than one buffer, in bands of rows.
//! - `image`: what is read back, and the one denoise helper.

mod accel;
mod adaptive;
pub mod bindings;
mod buffers;
pub mod context;
pub mod error;
pub mod image;
pub mod live;
pub mod options;
pub mod pipelines;
pub mod renderer;
pub mod shaders;
pub mod sizing;
pub mod tiling;
pub mod trace_rays;
pub mod wavefront;

pub use context::{AdapterChoice, GpuContext};
pub use error::{GpuError, Result};
pub use image::{Aovs, Image};
pub use options::{Adaptive, Experiments, Kernel, MAX_WORKGROUP_INVOCATIONS, RenderOptions, Trace};
pub use renderer::{BatchStats, Renderer};
pub use tiling::{TiledRender, render_tiled, tile_rows};
