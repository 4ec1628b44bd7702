//! The driver's acceleration structure over a scene, for tracing with ray queries
//! (`Trace::Hardware`): one bottom-level structure of every triangle, in the order of
//! `GpuScene::triangles` (so a hit's primitive index is rt's triangle index), under a top level of
//! one instance with the identity transform (the scene's triangles are already in world space).

use rt_core::GpuScene;
use wgpu::util::DeviceExt;

use crate::context::GpuContext;
use crate::error::{GpuError, Result};

/// The structures, kept alive as long as a bind group refers to them.
pub(crate) struct SceneAccel {
    pub tlas: wgpu::Tlas,
    _blas: wgpu::Blas,
    _vertices: wgpu::Buffer,
}

const IDENTITY: [f32; 12] = [1.0, 0.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 0.0, 1.0, 0.0];

/// Builds (and submits the build of) the acceleration structure of `scene`'s triangles.
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
    if !scene.instances.is_empty() {
        return Err(GpuError::Options(
            "ray queries do not yet trace instances (shared meshes): trace with rt's BVH \
             (--trace bvh)"
                .into(),
        ));
    }
    let vertices: Vec<[f32; 3]> = scene
        .triangles
        .iter()
        .flat_map(|t| [t.v0, t.v1, t.v2])
        .collect();
    let vertex_count = u32::try_from(vertices.len()).map_err(|_| {
        GpuError::Options(format!(
            "{} triangles are more than one acceleration structure holds",
            scene.triangles.len()
        ))
    })?;
    ctx.check_buffer(
        "triangle vertices for ray queries",
        (vertices.len() * 12) as u64,
    )?;
    ctx.scoped(|| {
        let vertex_buffer = ctx
            .device
            .create_buffer_init(&wgpu::util::BufferInitDescriptor {
                label: Some("triangle vertices for ray queries"),
                contents: bytemuck::cast_slice(&vertices),
                usage: wgpu::BufferUsages::BLAS_INPUT,
            });
        let size = wgpu::BlasTriangleGeometrySizeDescriptor {
            vertex_format: wgpu::VertexFormat::Float32x3,
            vertex_count,
            index_format: None,
            index_count: None,
            // Surfaces with holes need their hits handed to the shader as candidates.
            flags: if scene.features.alpha {
                wgpu::AccelerationStructureGeometryFlags::empty()
            } else {
                wgpu::AccelerationStructureGeometryFlags::OPAQUE
            },
        };
        let blas = ctx.device.create_blas(
            &wgpu::CreateBlasDescriptor {
                label: Some("scene triangles"),
                flags: wgpu::AccelerationStructureFlags::PREFER_FAST_TRACE,
                update_mode: wgpu::AccelerationStructureUpdateMode::Build,
            },
            wgpu::BlasGeometrySizeDescriptors::Triangles {
                descriptors: vec![size.clone()],
            },
        );
        let mut tlas = ctx.device.create_tlas(&wgpu::CreateTlasDescriptor {
            label: Some("scene"),
            max_instances: 1,
            flags: wgpu::AccelerationStructureFlags::PREFER_FAST_TRACE,
            update_mode: wgpu::AccelerationStructureUpdateMode::Build,
        });
        tlas[0] = Some(wgpu::TlasInstance::new(&blas, IDENTITY, 0, 0xff));
        let mut encoder = ctx.device.create_command_encoder(&Default::default());
        encoder.build_acceleration_structures(
            [&wgpu::BlasBuildEntry {
                blas: &blas,
                geometry: wgpu::BlasGeometries::TriangleGeometries(vec![
                    wgpu::BlasTriangleGeometry {
                        size: &size,
                        vertex_buffer: &vertex_buffer,
                        first_vertex: 0,
                        vertex_stride: 12,
                        index_buffer: None,
                        first_index: None,
                        transform_buffer: None,
                        transform_buffer_offset: None,
                    },
                ]),
            }],
            [&tlas],
        );
        ctx.queue.submit([encoder.finish()]);
        SceneAccel {
            tlas,
            _blas: blas,
            _vertices: vertex_buffer,
        }
    })
}
