//! WGSL sources, composed at compile time from `shaders/` and the estimator's files beside their
//! Rust twins in `rt-core`. WGSL has no includes, so each entry
//! point is its shared files followed by its own file.

use rt_core::bvh::BvhLayout;

macro_rules! shader_file {
    ($name:literal) => {
        (
            concat!("shaders/", $name),
            include_str!(concat!("../../../shaders/", $name)),
        )
    };
}

/// One WGSL file: its path from the workspace root and its text.
pub type WgslFile = (&'static str, &'static str);

pub const GPU_TYPES: WgslFile = ("crates/core/src/gpu_types.wgsl", rt_core::gpu_types::WGSL);
pub const RNG: WgslFile = ("crates/core/src/math/rng.wgsl", rt_core::math::rng::WGSL);
pub const SAMPLING: WgslFile = (
    "crates/core/src/math/sampling.wgsl",
    rt_core::math::sampling::WGSL,
);
pub const MICROFACET: WgslFile = (
    "crates/core/src/math/microfacet.wgsl",
    rt_core::math::microfacet::WGSL,
);
pub const BSDF: WgslFile = ("crates/core/src/math/bsdf.wgsl", rt_core::math::bsdf::WGSL);
pub const COAT: WgslFile = ("crates/core/src/math/coat.wgsl", rt_core::math::coat::WGSL);
pub const IRIDESCENCE: WgslFile = (
    "crates/core/src/math/iridescence.wgsl",
    rt_core::math::iridescence::WGSL,
);
pub const DISPERSION: WgslFile = (
    "crates/core/src/math/dispersion.wgsl",
    rt_core::math::dispersion::WGSL,
);
pub const GLASS_ENERGY: WgslFile = (
    "crates/core/src/math/glass_energy.wgsl",
    rt_core::math::glass_energy::WGSL,
);
pub const ANISOTROPIC_ENERGY: WgslFile = (
    "crates/core/src/math/anisotropic_energy.wgsl",
    rt_core::math::anisotropic_energy::WGSL,
);
pub const SHEEN: WgslFile = (
    "crates/core/src/math/sheen.wgsl",
    rt_core::math::sheen::WGSL,
);
pub const LAYERS: WgslFile = (
    "crates/core/src/math/layers.wgsl",
    rt_core::math::layers::WGSL,
);
pub const MEDIUM: WgslFile = (
    "crates/core/src/math/medium.wgsl",
    rt_core::math::medium::WGSL,
);
pub const ENVIRONMENT: WgslFile = (
    "crates/core/src/environment.wgsl",
    rt_core::environment::WGSL,
);
pub const INTERSECT: WgslFile = (
    "crates/core/src/math/intersect.wgsl",
    rt_core::math::intersect::WGSL,
);
pub const BVH: WgslFile = (
    "crates/core/src/estimator/bvh.wgsl",
    rt_core::estimator::bvh::WGSL,
);
pub const CWBVH: WgslFile = (
    "crates/core/src/estimator/cwbvh.wgsl",
    rt_core::estimator::cwbvh::WGSL,
);
pub const INSTANCE_BVH: WgslFile = (
    "crates/core/src/estimator/instance_bvh.wgsl",
    rt_core::estimator::instance_bvh::WGSL,
);
pub const INSTANCES: WgslFile = (
    "crates/core/src/estimator/instances.wgsl",
    rt_core::estimator::instances::WGSL,
);
pub const SHADER_RAY_QUERY: WgslFile = shader_file!("ray_query.wgsl");
pub const GPU_SCENE: WgslFile = ("crates/core/src/gpu_scene.wgsl", rt_core::gpu_scene::WGSL);
pub const TEXTURE: WgslFile = (
    "crates/core/src/estimator/texture.wgsl",
    rt_core::estimator::texture::WGSL,
);
pub const SURFACE: WgslFile = (
    "crates/core/src/estimator/surface.wgsl",
    rt_core::estimator::surface::WGSL,
);
pub const LIGHT_TREE: WgslFile = (
    "crates/core/src/estimator/light_tree.wgsl",
    rt_core::estimator::light_tree::WGSL,
);
pub const LIGHT: WgslFile = (
    "crates/core/src/estimator/light.wgsl",
    rt_core::estimator::light::WGSL,
);
pub const SHADOW_CATCHER: WgslFile = (
    "crates/core/src/estimator/shadow_catcher.wgsl",
    rt_core::estimator::shadow_catcher::WGSL,
);
pub const MEDIA: WgslFile = (
    "crates/core/src/estimator/media.wgsl",
    rt_core::estimator::media::WGSL,
);
pub const SHADING: WgslFile = (
    "crates/core/src/estimator/shading.wgsl",
    rt_core::estimator::shading::WGSL,
);
pub const CAMERA: WgslFile = (
    "crates/core/src/estimator/camera.wgsl",
    rt_core::estimator::camera::WGSL,
);
pub const PATH: WgslFile = (
    "crates/core/src/estimator/path.wgsl",
    rt_core::estimator::path::WGSL,
);
pub const ACCUMULATION: WgslFile = (
    "crates/core/src/accumulation.wgsl",
    rt_core::accumulation::WGSL,
);
pub const SHADER_TRACE: WgslFile = shader_file!("trace.wgsl");
pub const SHADER_WAVEFRONT: WgslFile = shader_file!("wavefront.wgsl");
pub const SHADER_TRACE_RAYS: WgslFile = shader_file!("trace_rays.wgsl");
pub const SHADER_TRACE_RAYS_BVH: WgslFile = shader_file!("trace_rays_bvh.wgsl");
pub const SHADER_PREVIEW: WgslFile = shader_file!("preview.wgsl");
pub const SHADER_PREVIEW_SHADING: WgslFile = shader_file!("preview_shading.wgsl");
pub const SHADER_PREVIEW_GLASS: WgslFile = shader_file!("preview_glass.wgsl");
pub const SHADER_PREVIEW_BLIT: WgslFile = shader_file!("preview_blit.wgsl");

/// An entry-point module: its name and the files it is made of, in order.
pub struct ShaderModule {
    pub name: &'static str,
    pub files: &'static [WgslFile],
}

/// A tracing module: its nearest-hit traversal (first: the ray-query file's `enable` must precede
/// every declaration; WGSL's module-scope order does not matter otherwise), the shared estimator,
/// and its entry file.
macro_rules! tracing_module {
    ($name:literal, [$($traversal:expr),*], $entry:expr) => {
        ShaderModule {
            name: $name,
            files: &[
                $($traversal,)*
                GPU_TYPES,
                RNG,
                SAMPLING,
                INTERSECT,
                GPU_SCENE,
                INSTANCES,
                TEXTURE,
                MICROFACET,
                BSDF,
                COAT,
                IRIDESCENCE,
                DISPERSION,
                GLASS_ENERGY,
                ANISOTROPIC_ENERGY,
                SHEEN,
                LAYERS,
                MEDIUM,
                ENVIRONMENT,
                SURFACE,
                LIGHT_TREE,
                LIGHT,
                SHADOW_CATCHER,
                MEDIA,
                SHADING,
                CAMERA,
                PATH,
                ACCUMULATION,
                $entry,
            ],
        }
    };
}

/// The megakernel over the BVH2.
pub const TRACE: ShaderModule = tracing_module!("trace", [BVH, INSTANCE_BVH], SHADER_TRACE);
/// `TRACE` over the compressed wide BVH.
pub const TRACE_WIDE: ShaderModule =
    tracing_module!("trace_wide", [CWBVH, INSTANCE_BVH], SHADER_TRACE);
/// `TRACE` over the driver's ray queries (`Trace::Hardware`).
pub const TRACE_HW: ShaderModule = tracing_module!("trace_hw", [SHADER_RAY_QUERY], SHADER_TRACE);
/// The wavefront kernels (the default: `Kernel::Wavefront`), over the BVH2.
pub const WAVEFRONT: ShaderModule =
    tracing_module!("wavefront", [BVH, INSTANCE_BVH], SHADER_WAVEFRONT);
/// `WAVEFRONT` over the compressed wide BVH.
pub const WAVEFRONT_WIDE: ShaderModule =
    tracing_module!("wavefront_wide", [CWBVH, INSTANCE_BVH], SHADER_WAVEFRONT);
/// `WAVEFRONT` over the driver's ray queries (`Trace::Hardware`).
pub const WAVEFRONT_HW: ShaderModule =
    tracing_module!("wavefront_hw", [SHADER_RAY_QUERY], SHADER_WAVEFRONT);

pub const TRACE_RAYS: ShaderModule = ShaderModule {
    name: "trace_rays",
    files: &[
        GPU_TYPES,
        INTERSECT,
        BVH,
        SHADER_TRACE_RAYS_BVH,
        SHADER_TRACE_RAYS,
    ],
};

pub const TRACE_RAYS_WIDE: ShaderModule = ShaderModule {
    name: "trace_rays_wide",
    files: &[
        GPU_TYPES,
        INTERSECT,
        CWBVH,
        SHADER_TRACE_RAYS_BVH,
        SHADER_TRACE_RAYS,
    ],
};

/// The megakernel for a BVH layout, or over ray queries (`hardware`).
pub fn trace_module(layout: BvhLayout, hardware: bool) -> &'static ShaderModule {
    match (hardware, layout) {
        (true, _) => &TRACE_HW,
        (false, BvhLayout::Bvh2) => &TRACE,
        (false, BvhLayout::Cwbvh) => &TRACE_WIDE,
    }
}

/// The wavefront kernels for a BVH layout, or over ray queries (`hardware`).
pub fn wavefront_module(layout: BvhLayout, hardware: bool) -> &'static ShaderModule {
    match (hardware, layout) {
        (true, _) => &WAVEFRONT_HW,
        (false, BvhLayout::Bvh2) => &WAVEFRONT,
        (false, BvhLayout::Cwbvh) => &WAVEFRONT_WIDE,
    }
}

/// The nearest-hit test kernel for a BVH layout, or over ray queries (`hardware`).
pub fn trace_rays_module(layout: BvhLayout, hardware: bool) -> &'static ShaderModule {
    match (hardware, layout) {
        (true, _) => &TRACE_RAYS_HW,
        (false, BvhLayout::Bvh2) => &TRACE_RAYS,
        (false, BvhLayout::Cwbvh) => &TRACE_RAYS_WIDE,
    }
}

/// `TRACE_RAYS` over the driver's ray queries.
pub const TRACE_RAYS_HW: ShaderModule = ShaderModule {
    name: "trace_rays_hw",
    files: &[SHADER_RAY_QUERY, GPU_TYPES, INTERSECT, SHADER_TRACE_RAYS],
};

/// The raster preview (`crate::preview`: the editor's first view and `rt-cli preview`).
pub const PREVIEW: ShaderModule = ShaderModule {
    name: "preview",
    files: &[SHADER_PREVIEW, SHADER_PREVIEW_SHADING, SHADER_PREVIEW_GLASS],
};

pub const PREVIEW_BLIT: ShaderModule = ShaderModule {
    name: "preview_blit",
    files: &[SHADER_PREVIEW_BLIT],
};

pub const MODULES: &[ShaderModule] = &[
    TRACE,
    TRACE_WIDE,
    TRACE_HW,
    WAVEFRONT,
    WAVEFRONT_WIDE,
    WAVEFRONT_HW,
    TRACE_RAYS,
    TRACE_RAYS_WIDE,
    TRACE_RAYS_HW,
    PREVIEW,
    PREVIEW_BLIT,
];

/// Every WGSL file of the kernels and the preview, once each: those the modules are made of
/// (`tests/shaders.rs` checks them against the files on disk). The estimator's files live beside
/// their Rust twins in `rt-core` (same folder, same stem), which exports each as `WGSL`;
/// `shaders/` keeps the entry points and what has no CPU twin (the driver's ray queries, the
/// raster preview).
pub fn files() -> Vec<WgslFile> {
    let mut files: Vec<WgslFile> = Vec::new();
    for file in MODULES.iter().flat_map(|m| m.files) {
        if !files.iter().any(|(name, _)| *name == file.0) {
            files.push(*file);
        }
    }
    files
}

impl ShaderModule {
    /// The composed source.
    pub fn source(&self) -> String {
        self.files
            .iter()
            .map(|(_, text)| *text)
            .collect::<Vec<_>>()
            .join("\n")
    }
}
