//! rt's core: the scene model, the estimator (the GPU data layout, BVH construction, the math and
//! the path tracer's Rust twin beside each WGSL file, the native CPU backend) and film and outputs
//! (exact sums, render parts, denoising, image files). Nothing here depends on wgpu, and nothing
//! here reads scene files: that is rt-io, above it.

pub mod accumulation;
pub mod adaptive;
pub mod animation;
pub mod bdpt;
pub mod bvh;
pub mod camera;
mod corner_records;
pub mod cpu_render;
pub mod cryptomatte;
pub mod denoise;
pub mod denoiser;
pub mod display;
pub mod emitters;
pub mod environment;
pub mod error;
pub mod estimator;
pub mod first_hits;
pub mod fog;
pub mod frame;
mod gpu_material;
pub mod gpu_scene;
pub mod gpu_types;
pub mod instances;
mod kernel_indices;
pub mod light;
pub mod light_kind;
pub mod light_tree;
pub mod material;
pub mod material_kind;
pub mod math;
pub mod memory_budget;
pub mod metrics;
mod object_frames;
pub mod oidn;
pub mod output;
pub mod part;
pub mod passes;
pub mod posing;
pub mod scene;
pub mod scene_features;
pub mod shapes;
pub mod sky;
pub mod smooth_normals;
pub mod tangents;
pub mod texture_budget;

pub use camera::Camera;
pub use environment::{Environment, EnvironmentMap};
pub use error::{Error, Result};
pub use gpu_scene::{GpuScene, SceneFeatures};
pub use light::Light;
pub use light_kind::{LightKind, LightTag};
pub use material::Material;
pub use material_kind::MaterialKind;
pub use scene::{
    Filter, Integrator, LightSampler, Mesh, Object, RenderSettings, Scene, Texture, TextureSampler,
    Transform, Wrap,
};
