//! The irradiance volume on the GPU: its ambient cubes as a 3D texture and its probes' radiance
//! maps as a 2D atlas (layouts in `bounce.rs`), half floats.

use std::sync::Arc;

use wgpu::util::DeviceExt;

use super::bounce;

/// The irradiance volume's texture and the volume it holds (compared by address).
pub(crate) struct ProbeTexture {
    pub volume: Arc<bounce::IrradianceVolume>,
    pub view: wgpu::TextureView,
    /// The probes' radiance maps (`IrradianceVolume::radiance`).
    pub radiance: wgpu::TextureView,
}

pub(crate) fn probe_texture(
    device: &wgpu::Device,
    queue: &wgpu::Queue,
    volume: &Arc<bounce::IrradianceVolume>,
) -> ProbeTexture {
    let [nx, ny, nz] = volume.dims;
    let data: Vec<half::f16> = volume
        .texels
        .iter()
        .flatten()
        .map(|&c| half::f16::from_f32(c.clamp(0.0, 65000.0)))
        .collect();
    let texture = device.create_texture_with_data(
        queue,
        &wgpu::TextureDescriptor {
            label: Some("preview irradiance volume"),
            size: wgpu::Extent3d {
                width: 6 * nx,
                height: ny,
                depth_or_array_layers: nz,
            },
            mip_level_count: 1,
            sample_count: 1,
            dimension: wgpu::TextureDimension::D3,
            format: wgpu::TextureFormat::Rgba16Float,
            usage: wgpu::TextureUsages::TEXTURE_BINDING | wgpu::TextureUsages::COPY_DST,
            view_formats: &[],
        },
        wgpu::util::TextureDataOrder::LayerMajor,
        bytemuck::cast_slice(&data),
    );
    let oct = bounce::OCT;
    let radiance: Vec<half::f16> = volume
        .radiance
        .iter()
        .flatten()
        .map(|&c| half::f16::from_f32(c.clamp(0.0, 65000.0)))
        .collect();
    let radiance = device.create_texture_with_data(
        queue,
        &wgpu::TextureDescriptor {
            label: Some("preview probe radiance"),
            size: wgpu::Extent3d {
                width: oct * oct * nx,
                height: ny,
                depth_or_array_layers: nz,
            },
            mip_level_count: 1,
            sample_count: 1,
            dimension: wgpu::TextureDimension::D3,
            format: wgpu::TextureFormat::Rgba16Float,
            usage: wgpu::TextureUsages::TEXTURE_BINDING | wgpu::TextureUsages::COPY_DST,
            view_formats: &[],
        },
        wgpu::util::TextureDataOrder::LayerMajor,
        bytemuck::cast_slice(&radiance),
    );
    ProbeTexture {
        volume: volume.clone(),
        view: texture.create_view(&Default::default()),
        radiance: radiance.create_view(&Default::default()),
    }
}
