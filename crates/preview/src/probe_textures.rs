//! The irradiance volume on the GPU: its ambient cubes and its probes' radiance maps, each a 3D
//! texture of half floats laid out by blocks (layouts in `bounce.rs`).

use std::sync::Arc;

use wgpu::util::DeviceExt;

use super::bounce;

/// The irradiance volume's textures and the volume they hold (compared by address).
pub(crate) struct ProbeTexture {
    pub volume: Arc<bounce::IrradianceVolume>,
    /// The ambient cubes (`IrradianceVolume::texels`).
    pub view: wgpu::TextureView,
    /// The probes' radiance maps (`IrradianceVolume::radiance`).
    pub radiance: wgpu::TextureView,
}

/// `texels` as a 3D texture of `blocks` blocks of the probe grid side by side along x.
fn blocks_texture(
    device: &wgpu::Device,
    queue: &wgpu::Queue,
    label: &str,
    [nx, ny, nz]: [u32; 3],
    blocks: u32,
    texels: &[[f32; 4]],
) -> wgpu::TextureView {
    let data: Vec<half::f16> = texels
        .iter()
        .flatten()
        .map(|&c| half::f16::from_f32(c.clamp(0.0, 65000.0)))
        .collect();
    device
        .create_texture_with_data(
            queue,
            &wgpu::TextureDescriptor {
                label: Some(label),
                size: wgpu::Extent3d {
                    width: blocks * nx,
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
        )
        .create_view(&Default::default())
}

pub(crate) fn probe_texture(
    device: &wgpu::Device,
    queue: &wgpu::Queue,
    volume: &Arc<bounce::IrradianceVolume>,
) -> ProbeTexture {
    let dims = volume.dims;
    ProbeTexture {
        volume: volume.clone(),
        view: blocks_texture(
            device,
            queue,
            "preview irradiance volume",
            dims,
            6,
            &volume.texels,
        ),
        radiance: blocks_texture(
            device,
            queue,
            "preview probe radiance",
            dims,
            bounce::BINS,
            &volume.radiance,
        ),
    }
}
