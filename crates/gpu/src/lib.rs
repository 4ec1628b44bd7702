//! rt's GPU layer: adapter and device, pipelines specialised per scene, and the progressive
//! path-tracing renderer. Everything it uploads is built by `rt-core`.

mod buffers;
pub mod context;
pub mod error;
pub mod pipelines;
pub mod renderer;
pub mod shaders;
pub mod trace_rays;
pub mod wavefront;

pub use context::{AdapterChoice, GpuContext};
pub use error::{GpuError, Result};
pub use renderer::{Aovs, BatchStats, Image, MAX_WORKGROUP_INVOCATIONS, RenderOptions, Renderer};
