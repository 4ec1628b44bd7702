//! The driver's acceleration structures over a scene, for tracing with ray queries
//! (`Trace::Hardware`): a bottom-level structure of the world-space triangles and one of each
//! shared mesh's (in its own space), each in the order of `GpuScene::triangles` from its first
//! triangle, so that a hit's primitive index counted from there is rt's triangle index; under a
//! top level of the world's structure (identity transform, custom data 0) and one instance per
//! rt instance k (its transform, custom data k + 1), as `ray_query.wgsl` reads them back.

use std::ops::Range;

use rt_core::GpuScene;
use wgpu::util::DeviceExt;

use crate::context::GpuContext;
use crate::error::{GpuError, Result};

/// The structures, kept alive as long as a bind group refers to them.
pub(crate) struct SceneAccel {
    pub tlas: wgpu::Tlas,
    _blases: Vec<wgpu::Blas>,
    _vertices: Vec<wgpu::Buffer>,
}

const IDENTITY: [f32; 12] = [1.0, 0.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 0.0, 1.0, 0.0];

/// Instances the top level's 24-bit custom data can number (after the world's 0).
const MAX_INSTANCES: usize = (1 << 24) - 2;

/// The triangles of each bottom-level structure: the world-space ones (those before the first
/// shared mesh's; empty when every object is an instance) and each shared mesh's, keyed by its
/// first triangle (meshes are stored one after another).
fn mesh_ranges(scene: &GpuScene) -> (Range<u32>, Vec<Range<u32>>) {
    let end = scene.triangles.len() as u32;
    let mut firsts: Vec<u32> = scene.instances.iter().map(|i| i.first_triangle).collect();
    firsts.sort_unstable();
    firsts.dedup();
    let world = 0..firsts.first().copied().unwrap_or(end);
    let meshes = (firsts.iter().enumerate())
        .map(|(k, &first)| first..firsts.get(k + 1).copied().unwrap_or(end))
        .collect();
    (world, meshes)
}

/// Builds (and submits the build of) the acceleration structures of `scene`.
pub(crate) fn build(ctx: &GpuContext, scene: &GpuScene) -> Result<SceneAccel> {
    if !ctx.has_ray_queries() {
        return Err(GpuError::Options(format!(
            "{} has no ray queries: trace with rt's BVH (--trace bvh) instead",
            ctx.adapter_label()
        )));
    }
    if scene.triangles.is_empty() {
        return Err(GpuError::Options(
            "an empty scene has nothing to build ray queries over: trace with rt's BVH".into(),
        ));
    }
    if scene.instances.len() > MAX_INSTANCES {
        return Err(GpuError::Options(format!(
            "{} instances are more than ray queries number ({MAX_INSTANCES}): trace with rt's \
             BVH (--trace bvh)",
            scene.instances.len()
        )));
    }
    ctx.check_buffer(
        "triangle vertices for ray queries",
        scene.triangles.len() as u64 * 36,
    )?;
    let (world, meshes) = mesh_ranges(scene);
    ctx.scoped(|| {
        // Surfaces with holes need their hits handed to the shader as candidates; they are never
        // instanced (`rt_core::instances`), so shared meshes are opaque.
        let world_flags = if scene.features.alpha {
            wgpu::AccelerationStructureGeometryFlags::empty()
        } else {
            wgpu::AccelerationStructureGeometryFlags::OPAQUE
        };
        let ranges: Vec<(Range<u32>, wgpu::AccelerationStructureGeometryFlags)> =
            std::iter::once((world.clone(), world_flags))
                .chain(
                    (meshes.iter().cloned())
                        .map(|m| (m, wgpu::AccelerationStructureGeometryFlags::OPAQUE)),
                )
                .filter(|(range, _)| !range.is_empty())
                .collect();
        let mut vertex_buffers = Vec::with_capacity(ranges.len());
        let mut sizes = Vec::with_capacity(ranges.len());
        let mut blases = Vec::with_capacity(ranges.len());
        for (range, flags) in &ranges {
            let vertices: Vec<[f32; 3]> = scene.triangles[range.start as usize..range.end as usize]
                .iter()
                .flat_map(|t| [t.v0, t.v1, t.v2])
                .collect();
            vertex_buffers.push(
                ctx.device
                    .create_buffer_init(&wgpu::util::BufferInitDescriptor {
                        label: Some("triangle vertices for ray queries"),
                        contents: bytemuck::cast_slice(&vertices),
                        usage: wgpu::BufferUsages::BLAS_INPUT,
                    }),
            );
            let size = wgpu::BlasTriangleGeometrySizeDescriptor {
                vertex_format: wgpu::VertexFormat::Float32x3,
                vertex_count: 3 * (range.end - range.start),
                index_format: None,
                index_count: None,
                flags: *flags,
            };
            blases.push(ctx.device.create_blas(
                &wgpu::CreateBlasDescriptor {
                    label: Some("scene triangles"),
                    flags: wgpu::AccelerationStructureFlags::PREFER_FAST_TRACE,
                    update_mode: wgpu::AccelerationStructureUpdateMode::Build,
                },
                wgpu::BlasGeometrySizeDescriptors::Triangles {
                    descriptors: vec![size.clone()],
                },
            ));
            sizes.push(size);
        }
        let blas_of = |first: u32| {
            let k = ranges
                .iter()
                .position(|(r, _)| r.start == first && r != &world);
            k.map(|k| &blases[k])
        };
        let mut tlas = ctx.device.create_tlas(&wgpu::CreateTlasDescriptor {
            label: Some("scene"),
            max_instances: 1 + scene.instances.len() as u32,
            flags: wgpu::AccelerationStructureFlags::PREFER_FAST_TRACE,
            update_mode: wgpu::AccelerationStructureUpdateMode::Build,
        });
        if !world.is_empty() {
            tlas[0] = Some(wgpu::TlasInstance::new(&blases[0], IDENTITY, 0, 0xff));
        }
        for (k, instance) in scene.instances.iter().enumerate() {
            let Some(blas) = blas_of(instance.first_triangle) else {
                continue; // a mesh without triangles: nothing to meet
            };
            let transform: [f32; 12] = bytemuck::cast(instance.to_world);
            tlas[k + 1] = Some(wgpu::TlasInstance::new(blas, transform, k as u32 + 1, 0xff));
        }
        let entries: Vec<wgpu::BlasBuildEntry> = (blases.iter().zip(&sizes).zip(&vertex_buffers))
            .map(|((blas, size), vertex_buffer)| wgpu::BlasBuildEntry {
                blas,
                geometry: wgpu::BlasGeometries::TriangleGeometries(vec![
                    wgpu::BlasTriangleGeometry {
                        size,
                        vertex_buffer,
                        first_vertex: 0,
                        vertex_stride: 12,
                        index_buffer: None,
                        first_index: None,
                        transform_buffer: None,
                        transform_buffer_offset: None,
                    },
                ]),
            })
            .collect();
        let mut encoder = ctx.device.create_command_encoder(&Default::default());
        encoder.build_acceleration_structures(entries.iter(), [&tlas]);
        ctx.queue.submit([encoder.finish()]);
        drop(entries);
        SceneAccel {
            tlas,
            _blases: blases,
            _vertices: vertex_buffers,
        }
    })
}
