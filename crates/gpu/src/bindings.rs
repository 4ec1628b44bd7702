//! The tracing kernels' bind group, declared once. Layouts and bind groups are built from this
//! table, and `tests/shaders.rs` checks it against the bindings naga finds in each kernel's WGSL
//! (number, name, address space and access), as the struct layouts are checked.

use crate::context::GpuContext;
use crate::options::Kernel;

/// How a kernel may use a binding.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Access {
    Uniform,
    Read,
    ReadWrite,
    /// A top-level acceleration structure for ray queries.
    AccelerationStructure,
}

/// Which tracing kernels declare a binding.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum DeclaredBy {
    /// Every one.
    All,
    /// The wavefront kernels (their queues).
    Wavefront,
    /// The kernels over ray queries (`Trace::Hardware`: the acceleration structure).
    RayQuery,
}

/// One entry of group 0.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Binding {
    pub number: u32,
    /// The WGSL variable.
    pub name: &'static str,
    pub access: Access,
    pub declared_by: DeclaredBy,
}

impl Binding {
    /// Whether `kernel` (over ray queries when `ray_query`) declares this binding.
    pub fn in_kernel(&self, kernel: Kernel, ray_query: bool) -> bool {
        match self.declared_by {
            DeclaredBy::All => true,
            DeclaredBy::Wavefront => kernel == Kernel::Wavefront,
            DeclaredBy::RayQuery => ray_query,
        }
    }
}

const fn shared(number: u32, name: &'static str, access: Access) -> Binding {
    Binding {
        number,
        name,
        access,
        declared_by: DeclaredBy::All,
    }
}

const fn wavefront(number: u32, name: &'static str) -> Binding {
    Binding {
        number,
        name,
        access: Access::ReadWrite,
        declared_by: DeclaredBy::Wavefront,
    }
}

// The scene (crates/core/src/gpu_scene.wgsl).
pub const FRAME: Binding = shared(0, "frame", Access::Uniform);
pub const TRIANGLES: Binding = shared(1, "triangles", Access::Read);
pub const SHADING: Binding = shared(2, "shading", Access::Read);
pub const MATERIALS: Binding = shared(3, "materials", Access::Read);
pub const NODES: Binding = shared(4, "nodes", Access::Read);
pub const TEXELS: Binding = shared(5, "texels", Access::Read);
pub const EMITTERS: Binding = shared(8, "emitters", Access::Read);
pub const DELTA_LIGHTS: Binding = shared(9, "delta_lights", Access::Read);
pub const LIGHT_TREE: Binding = shared(26, "light_tree", Access::Read);
pub const ENVIRONMENT: Binding = shared(20, "environment", Access::Read);
pub const ALBEDO_TABLES: Binding = shared(21, "albedo_tables", Access::Read);
pub const TANGENTS: Binding = shared(22, "tangents", Access::Read);
/// Shared meshes' placed copies and the top level over them (placeholders without).
pub const INSTANCES: Binding = shared(27, "instances", Access::Read);
pub const INSTANCE_NODES: Binding = shared(28, "instance_nodes", Access::Read);
/// Adaptive sampling's per-pixel stop marks (written by the CPU between batches).
pub const PIXEL_DONE: Binding = shared(18, "pixel_done", Access::Read);
// The outputs, declared by each kernel's own file.
/// The exact sums, a channel per buffer (`crates/core/src/accumulation.wgsl`).
pub const ACCUM: [Binding; 4] = [
    shared(6, "accum_red", Access::ReadWrite),
    shared(23, "accum_green", Access::ReadWrite),
    shared(24, "accum_blue", Access::ReadWrite),
    shared(25, "accum_squared", Access::ReadWrite),
];
pub const COUNTERS: Binding = shared(7, "counters", Access::ReadWrite);
pub const AOVS: Binding = shared(10, "aovs", Access::ReadWrite);
// The wavefront's queues (shaders/wavefront.wgsl).
pub const PATHS: Binding = wavefront(12, "paths");
pub const RAY_QUEUES: Binding = wavefront(13, "ray_queues");
pub const SHADOW_RAYS: Binding = wavefront(14, "shadow_rays");
pub const QUEUES: Binding = wavefront(15, "queues");
pub const PATH_AOVS: Binding = wavefront(16, "path_aovs");
// The scene's acceleration structure (shaders/ray_query.wgsl).
pub const SCENE_TLAS: Binding = Binding {
    number: 17,
    name: "scene_tlas",
    access: Access::AccelerationStructure,
    declared_by: DeclaredBy::RayQuery,
};

/// Adaptive sampling: the pixels still sampling, which the wavefront's waves walk.
pub const ACTIVE_SLOTS: Binding = Binding {
    number: 19,
    name: "active_slots",
    access: Access::Read,
    declared_by: DeclaredBy::Wavefront,
};

/// Every binding of the tracing kernels.
pub const ALL: [Binding; 28] = [
    FRAME,
    TRIANGLES,
    SHADING,
    MATERIALS,
    NODES,
    TEXELS,
    ACCUM[0],
    COUNTERS,
    EMITTERS,
    DELTA_LIGHTS,
    AOVS,
    PATHS,
    RAY_QUEUES,
    SHADOW_RAYS,
    QUEUES,
    PATH_AOVS,
    SCENE_TLAS,
    PIXEL_DONE,
    ACTIVE_SLOTS,
    ENVIRONMENT,
    ALBEDO_TABLES,
    TANGENTS,
    ACCUM[1],
    ACCUM[2],
    ACCUM[3],
    LIGHT_TREE,
    INSTANCES,
    INSTANCE_NODES,
];

/// The bindings `kernel` (over ray queries when `ray_query`) declares, in binding order.
pub fn of(kernel: Kernel, ray_query: bool) -> impl Iterator<Item = Binding> {
    ALL.into_iter()
        .filter(move |b| b.in_kernel(kernel, ray_query))
}

/// The bind-group layout of `kernel`'s bindings.
pub(crate) fn layout(ctx: &GpuContext, kernel: Kernel, ray_query: bool) -> wgpu::BindGroupLayout {
    let buffer = |ty| wgpu::BindingType::Buffer {
        ty,
        has_dynamic_offset: false,
        min_binding_size: None,
    };
    let entries: Vec<wgpu::BindGroupLayoutEntry> = of(kernel, ray_query)
        .map(|b| wgpu::BindGroupLayoutEntry {
            binding: b.number,
            visibility: wgpu::ShaderStages::COMPUTE,
            ty: match b.access {
                Access::Uniform => buffer(wgpu::BufferBindingType::Uniform),
                Access::Read => buffer(wgpu::BufferBindingType::Storage { read_only: true }),
                Access::ReadWrite => buffer(wgpu::BufferBindingType::Storage { read_only: false }),
                Access::AccelerationStructure => wgpu::BindingType::AccelerationStructure {
                    vertex_return: false,
                },
            },
            count: None,
        })
        .collect();
    ctx.device
        .create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some(kernel.name()),
            entries: &entries,
        })
}

/// A bind group over `layout` (made by `layout` for `kernel`) from (binding, buffer) pairs and the
/// acceleration structure when the kernel traces with ray queries (`tlas`); pairs the kernel does
/// not declare are left out, so one list serves both kernels.
pub(crate) fn bind_group(
    ctx: &GpuContext,
    kernel: Kernel,
    layout: &wgpu::BindGroupLayout,
    buffers: &[(Binding, &wgpu::Buffer)],
    tlas: Option<&wgpu::Tlas>,
) -> wgpu::BindGroup {
    let entries: Vec<wgpu::BindGroupEntry> = buffers
        .iter()
        .filter(|(b, _)| b.in_kernel(kernel, tlas.is_some()))
        .map(|(b, buffer)| wgpu::BindGroupEntry {
            binding: b.number,
            resource: buffer.as_entire_binding(),
        })
        .chain(tlas.map(|tlas| wgpu::BindGroupEntry {
            binding: SCENE_TLAS.number,
            resource: wgpu::BindingResource::AccelerationStructure(tlas),
        }))
        .collect();
    ctx.device.create_bind_group(&wgpu::BindGroupDescriptor {
        label: Some(kernel.name()),
        layout,
        entries: &entries,
    })
}
