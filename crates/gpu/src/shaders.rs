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

/// Every WGSL file of the kernels and the preview, by path from the workspace root. The
/// estimator's files live beside their Rust twins in `rt-core` (same folder, same stem), which
/// exports each as `WGSL`; `shaders/` keeps the entry points and what has no CPU twin (the
/// driver's ray queries, the raster preview). `tests/shaders.rs` checks this list against the
/// files on disk.
pub const FILES: &[(&str, &str)] = &[
    ("crates/core/src/gpu_types.wgsl", rt_core::gpu_types::WGSL),
    ("crates/core/src/math/rng.wgsl", rt_core::math::rng::WGSL),
    (
        "crates/core/src/math/sampling.wgsl",
        rt_core::math::sampling::WGSL,
    ),
    (
        "crates/core/src/math/microfacet.wgsl",
        rt_core::math::microfacet::WGSL,
    ),
    ("crates/core/src/math/bsdf.wgsl", rt_core::math::bsdf::WGSL),
    ("crates/core/src/math/coat.wgsl", rt_core::math::coat::WGSL),
    (
        "crates/core/src/math/iridescence.wgsl",
        rt_core::math::iridescence::WGSL,
    ),
    (
        "crates/core/src/math/dispersion.wgsl",
        rt_core::math::dispersion::WGSL,
    ),
    (
        "crates/core/src/math/glass_energy.wgsl",
        rt_core::math::glass_energy::WGSL,
    ),
    (
        "crates/core/src/math/anisotropic_energy.wgsl",
        rt_core::math::anisotropic_energy::WGSL,
    ),
    (
        "crates/core/src/math/sheen.wgsl",
        rt_core::math::sheen::WGSL,
    ),
    (
        "crates/core/src/math/layers.wgsl",
        rt_core::math::layers::WGSL,
    ),
    (
        "crates/core/src/math/medium.wgsl",
        rt_core::math::medium::WGSL,
    ),
    (
        "crates/core/src/environment.wgsl",
        rt_core::environment::WGSL,
    ),
    (
        "crates/core/src/math/intersect.wgsl",
        rt_core::math::intersect::WGSL,
    ),
    (
        "crates/core/src/estimator/bvh.wgsl",
        rt_core::estimator::bvh::WGSL,
    ),
    (
        "crates/core/src/estimator/cwbvh.wgsl",
        rt_core::estimator::cwbvh::WGSL,
    ),
    shader_file!("ray_query.wgsl"),
    ("crates/core/src/gpu_scene.wgsl", rt_core::gpu_scene::WGSL),
    (
        "crates/core/src/estimator/texture.wgsl",
        rt_core::estimator::texture::WGSL,
    ),
    (
        "crates/core/src/estimator/surface.wgsl",
        rt_core::estimator::surface::WGSL,
    ),
    (
        "crates/core/src/estimator/light_tree.wgsl",
        rt_core::estimator::light_tree::WGSL,
    ),
    (
        "crates/core/src/estimator/light.wgsl",
        rt_core::estimator::light::WGSL,
    ),
    (
        "crates/core/src/estimator/path.wgsl",
        rt_core::estimator::path::WGSL,
    ),
    (
        "crates/core/src/accumulation.wgsl",
        rt_core::accumulation::WGSL,
    ),
    shader_file!("trace.wgsl"),
    shader_file!("wavefront.wgsl"),
    shader_file!("trace_rays.wgsl"),
    shader_file!("preview.wgsl"),
    shader_file!("preview_blit.wgsl"),
];

/// An entry-point module: its name and the files it is made of, in order.
pub struct ShaderModule {
    pub name: &'static str,
    pub files: &'static [&'static str],
}

/// A tracing module: its nearest-hit traversal (first: the ray-query file's `enable` must precede
/// every declaration; WGSL's module-scope order does not matter otherwise), the shared estimator,
/// and its entry file.
macro_rules! tracing_module {
    ($name:literal, $traversal:literal, $entry:literal) => {
        ShaderModule {
            name: $name,
            files: &[
                $traversal,
                "crates/core/src/gpu_types.wgsl",
                "crates/core/src/math/rng.wgsl",
                "crates/core/src/math/sampling.wgsl",
                "crates/core/src/math/intersect.wgsl",
                "crates/core/src/gpu_scene.wgsl",
                "crates/core/src/estimator/texture.wgsl",
                "crates/core/src/math/microfacet.wgsl",
                "crates/core/src/math/bsdf.wgsl",
                "crates/core/src/math/coat.wgsl",
                "crates/core/src/math/iridescence.wgsl",
                "crates/core/src/math/dispersion.wgsl",
                "crates/core/src/math/glass_energy.wgsl",
                "crates/core/src/math/anisotropic_energy.wgsl",
                "crates/core/src/math/sheen.wgsl",
                "crates/core/src/math/layers.wgsl",
                "crates/core/src/math/medium.wgsl",
                "crates/core/src/environment.wgsl",
                "crates/core/src/estimator/surface.wgsl",
                "crates/core/src/estimator/light_tree.wgsl",
                "crates/core/src/estimator/light.wgsl",
                "crates/core/src/estimator/path.wgsl",
                "crates/core/src/accumulation.wgsl",
                $entry,
            ],
        }
    };
}

/// The megakernel over the BVH2.
pub const TRACE: ShaderModule = tracing_module!(
    "trace",
    "crates/core/src/estimator/bvh.wgsl",
    "shaders/trace.wgsl"
);
/// `TRACE` over the compressed wide BVH.
pub const TRACE_WIDE: ShaderModule = tracing_module!(
    "trace_wide",
    "crates/core/src/estimator/cwbvh.wgsl",
    "shaders/trace.wgsl"
);
/// `TRACE` over the driver's ray queries (`Trace::Hardware`).
pub const TRACE_HW: ShaderModule =
    tracing_module!("trace_hw", "shaders/ray_query.wgsl", "shaders/trace.wgsl");
/// The wavefront kernels (the default: `Kernel::Wavefront`), over the BVH2.
pub const WAVEFRONT: ShaderModule = tracing_module!(
    "wavefront",
    "crates/core/src/estimator/bvh.wgsl",
    "shaders/wavefront.wgsl"
);
/// `WAVEFRONT` over the compressed wide BVH.
pub const WAVEFRONT_WIDE: ShaderModule = tracing_module!(
    "wavefront_wide",
    "crates/core/src/estimator/cwbvh.wgsl",
    "shaders/wavefront.wgsl"
);
/// `WAVEFRONT` over the driver's ray queries (`Trace::Hardware`).
pub const WAVEFRONT_HW: ShaderModule = tracing_module!(
    "wavefront_hw",
    "shaders/ray_query.wgsl",
    "shaders/wavefront.wgsl"
);

pub const TRACE_RAYS: ShaderModule = ShaderModule {
    name: "trace_rays",
    files: &[
        "crates/core/src/gpu_types.wgsl",
        "crates/core/src/math/intersect.wgsl",
        "crates/core/src/estimator/bvh.wgsl",
        "shaders/trace_rays.wgsl",
    ],
};

pub const TRACE_RAYS_WIDE: ShaderModule = ShaderModule {
    name: "trace_rays_wide",
    files: &[
        "crates/core/src/gpu_types.wgsl",
        "crates/core/src/math/intersect.wgsl",
        "crates/core/src/estimator/cwbvh.wgsl",
        "shaders/trace_rays.wgsl",
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
    files: &[
        "shaders/ray_query.wgsl",
        "crates/core/src/gpu_types.wgsl",
        "crates/core/src/math/intersect.wgsl",
        "shaders/trace_rays.wgsl",
    ],
};

/// The raster preview (`crate::preview`: the editor's first view and `rt-cli preview`).
pub const PREVIEW: ShaderModule = ShaderModule {
    name: "preview",
    files: &["shaders/preview.wgsl"],
};

pub const PREVIEW_BLIT: ShaderModule = ShaderModule {
    name: "preview_blit",
    files: &["shaders/preview_blit.wgsl"],
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

impl ShaderModule {
    /// The composed source.
    pub fn source(&self) -> String {
        self.files
            .iter()
            .map(|f| {
                FILES
                    .iter()
                    .find(|(name, _)| name == f)
                    .map_or("", |(_, src)| *src)
            })
            .collect::<Vec<_>>()
            .join("\n")
    }
}
