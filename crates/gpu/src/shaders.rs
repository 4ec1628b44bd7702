//! WGSL sources, composed from `shaders/` at compile time. WGSL has no includes, so each entry
//! point is its shared files followed by its own file.

use rt_core::bvh::BvhLayout;

macro_rules! shader_file {
    ($name:literal) => {
        ($name, include_str!(concat!("../../../shaders/", $name)))
    };
}

/// Every WGSL file under `shaders/`, by path relative to that folder.
pub const FILES: &[(&str, &str)] = &[
    shader_file!("shared/types.wgsl"),
    shader_file!("shared/rng.wgsl"),
    shader_file!("shared/sampling.wgsl"),
    shader_file!("shared/microfacet.wgsl"),
    shader_file!("shared/bsdf.wgsl"),
    shader_file!("shared/environment.wgsl"),
    shader_file!("shared/intersect.wgsl"),
    shader_file!("shared/bvh.wgsl"),
    shader_file!("shared/cwbvh.wgsl"),
    shader_file!("shared/ray_query.wgsl"),
    shader_file!("shared/scene_bindings.wgsl"),
    shader_file!("shared/texture.wgsl"),
    shader_file!("shared/path.wgsl"),
    shader_file!("shared/accumulate.wgsl"),
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
                "shared/types.wgsl",
                "shared/rng.wgsl",
                "shared/sampling.wgsl",
                "shared/intersect.wgsl",
                "shared/scene_bindings.wgsl",
                "shared/texture.wgsl",
                "shared/microfacet.wgsl",
                "shared/bsdf.wgsl",
                "shared/environment.wgsl",
                "shared/path.wgsl",
                "shared/accumulate.wgsl",
                $entry,
            ],
        }
    };
}

/// The megakernel over the BVH2.
pub const TRACE: ShaderModule = tracing_module!("trace", "shared/bvh.wgsl", "trace.wgsl");
/// `TRACE` over the compressed wide BVH.
pub const TRACE_WIDE: ShaderModule =
    tracing_module!("trace_wide", "shared/cwbvh.wgsl", "trace.wgsl");
/// `TRACE` over the driver's ray queries (`Trace::Hardware`).
pub const TRACE_HW: ShaderModule =
    tracing_module!("trace_hw", "shared/ray_query.wgsl", "trace.wgsl");
/// The wavefront kernels (the default: `Kernel::Wavefront`), over the BVH2.
pub const WAVEFRONT: ShaderModule =
    tracing_module!("wavefront", "shared/bvh.wgsl", "wavefront.wgsl");
/// `WAVEFRONT` over the compressed wide BVH.
pub const WAVEFRONT_WIDE: ShaderModule =
    tracing_module!("wavefront_wide", "shared/cwbvh.wgsl", "wavefront.wgsl");
/// `WAVEFRONT` over the driver's ray queries (`Trace::Hardware`).
pub const WAVEFRONT_HW: ShaderModule =
    tracing_module!("wavefront_hw", "shared/ray_query.wgsl", "wavefront.wgsl");

pub const TRACE_RAYS: ShaderModule = ShaderModule {
    name: "trace_rays",
    files: &[
        "shared/types.wgsl",
        "shared/intersect.wgsl",
        "shared/bvh.wgsl",
        "trace_rays.wgsl",
    ],
};

pub const TRACE_RAYS_WIDE: ShaderModule = ShaderModule {
    name: "trace_rays_wide",
    files: &[
        "shared/types.wgsl",
        "shared/intersect.wgsl",
        "shared/cwbvh.wgsl",
        "trace_rays.wgsl",
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
        "shared/ray_query.wgsl",
        "shared/types.wgsl",
        "shared/intersect.wgsl",
        "trace_rays.wgsl",
    ],
};

/// The editor's raster preview (used by `rt-app`; validated here with the others).
pub const PREVIEW: ShaderModule = ShaderModule {
    name: "preview",
    files: &["preview.wgsl"],
};

pub const PREVIEW_BLIT: ShaderModule = ShaderModule {
    name: "preview_blit",
    files: &["preview_blit.wgsl"],
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
