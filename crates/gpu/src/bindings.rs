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
}

/// One entry of group 0.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Binding {
    pub number: u32,
    /// The WGSL variable.
    pub name: &'static str,
    pub access: Access,
    /// Only the wavefront kernels declare it (their queues); else every tracing kernel does.
    pub wavefront_only: bool,
}

const fn shared(number: u32, name: &'static str, access: Access) -> Binding {
    Binding {
        number,
        name,
        access,
        wavefront_only: false,
    }
}

const fn wavefront(number: u32, name: &'static str) -> Binding {
    Binding {
        number,
        name,
        access: Access::ReadWrite,
        wavefront_only: true,
    }
}

// The scene (shaders/shared/scene_bindings.wgsl).
pub const FRAME: Binding = shared(0, "frame", Access::Uniform);
pub const TRIANGLES: Binding = shared(1, "triangles", Access::Read);
pub const SHADING: Binding = shared(2, "shading", Access::Read);
pub const MATERIALS: Binding = shared(3, "materials", Access::Read);
pub const NODES: Binding = shared(4, "nodes", Access::Read);
pub const TEXELS: Binding = shared(5, "texels", Access::Read);
pub const EMITTERS: Binding = shared(8, "emitters", Access::Read);
pub const DELTA_LIGHTS: Binding = shared(9, "delta_lights", Access::Read);
// The outputs, declared by each kernel's own file.
pub const ACCUM: Binding = shared(6, "accum", Access::ReadWrite);
pub const COUNTERS: Binding = shared(7, "counters", Access::ReadWrite);
pub const AOVS: Binding = shared(10, "aovs", Access::ReadWrite);
// The wavefront's queues (shaders/wavefront.wgsl).
pub const PATHS: Binding = wavefront(12, "paths");
pub const RAY_QUEUES: Binding = wavefront(13, "ray_queues");
pub const SHADOW_RAYS: Binding = wavefront(14, "shadow_rays");
pub const QUEUES: Binding = wavefront(15, "queues");
pub const PATH_AOVS: Binding = wavefront(16, "path_aovs");

/// Every binding of the tracing kernels.
pub const ALL: [Binding; 16] = [
    FRAME,
    TRIANGLES,
    SHADING,
    MATERIALS,
    NODES,
    TEXELS,
    ACCUM,
    COUNTERS,
    EMITTERS,
    DELTA_LIGHTS,
    AOVS,
    PATHS,
    RAY_QUEUES,
    SHADOW_RAYS,
    QUEUES,
    PATH_AOVS,
];

/// The bindings `kernel` declares, in binding order.
pub fn of(kernel: Kernel) -> impl Iterator<Item = Binding> {
    ALL.into_iter()
        .filter(move |b| kernel == Kernel::Wavefront || !b.wavefront_only)
}

/// The bind-group layout of `kernel`'s bindings.
pub(crate) fn layout(ctx: &GpuContext, kernel: Kernel) -> wgpu::BindGroupLayout {
    let entries: Vec<wgpu::BindGroupLayoutEntry> = of(kernel)
        .map(|b| wgpu::BindGroupLayoutEntry {
            binding: b.number,
            visibility: wgpu::ShaderStages::COMPUTE,
            ty: wgpu::BindingType::Buffer {
                ty: match b.access {
                    Access::Uniform => wgpu::BufferBindingType::Uniform,
                    Access::Read => wgpu::BufferBindingType::Storage { read_only: true },
                    Access::ReadWrite => wgpu::BufferBindingType::Storage { read_only: false },
                },
                has_dynamic_offset: false,
                min_binding_size: None,
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

/// A bind group over `layout` (made by `layout` for `kernel`) from (binding, buffer) pairs; pairs
/// the kernel does not declare are left out, so one list serves both kernels.
pub(crate) fn bind_group(
    ctx: &GpuContext,
    kernel: Kernel,
    layout: &wgpu::BindGroupLayout,
    buffers: &[(Binding, &wgpu::Buffer)],
) -> wgpu::BindGroup {
    let entries: Vec<wgpu::BindGroupEntry> = buffers
        .iter()
        .filter(|(b, _)| kernel == Kernel::Wavefront || !b.wavefront_only)
        .map(|(b, buffer)| wgpu::BindGroupEntry {
            binding: b.number,
            resource: buffer.as_entire_binding(),
        })
        .collect();
    ctx.device.create_bind_group(&wgpu::BindGroupDescriptor {
        label: Some(kernel.name()),
        layout,
        entries: &entries,
    })
}
