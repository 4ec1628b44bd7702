//! The shading set-up at a surface hit, on the CPU: `shade_vertex` (whose WGSL twin does the
//! same inline) and the bidirectional walks (`bdpt::point`), which keep it to rebuild the BSDF
//! for light arriving from another side, read the same values from here.

use glam::{Vec2, Vec3};

use super::{PathState, pbr_inputs_at};
use crate::estimator::instances::HitTriangle;
use crate::estimator::shading::vertex_color;
use crate::estimator::surface::PbrInputs;
use crate::estimator::texture::base_color_texture;
use crate::gpu_scene::GpuScene;
use crate::gpu_types::{HAS_COLORS, HAS_NORMALS, Hit, SLOT_BASE};
use crate::material_kind::MaterialKind;

/// What shading reads at a surface hit (`shade_vertex`'s set-up, kept with the BSDF by the
/// bidirectional walks too): the point, the geometric and shading normals on the side the path
/// arrived from, the colour (base colour texture times vertex colour) and a PBR material's inputs
/// (which may bend the shading normal, and draw a dispersive channel from `path`).
pub struct Shading {
    pub p: Vec3,
    pub ng: Vec3,
    pub ns: Vec3,
    pub color: Vec3,
    pub inputs: PbrInputs,
}

/// `Shading` at `hit` on `surface_triangle`, whose winding normal (not normalised) is `ng_raw`,
/// reached on its `front` side or not.
pub fn shading_at(
    scene: &GpuScene,
    surface_triangle: &HitTriangle<'_>,
    hit: Hit,
    ng_raw: Vec3,
    front: bool,
    path: &mut PathState,
) -> Shading {
    let tri = surface_triangle.tri;
    let material = &scene.materials[tri.material as usize];
    let shading = surface_triangle.shading();
    let (v0, v1, v2) = (Vec3::from(tri.v0), Vec3::from(tri.v1), Vec3::from(tri.v2));
    let b0 = 1.0 - hit.b1 - hit.b2;
    let p = v0 * b0 + v1 * hit.b1 + v2 * hit.b2;
    let ng = if front {
        ng_raw.normalize()
    } else {
        -ng_raw.normalize()
    };
    let mut ns = ng;
    let mut n_interpolated = ng;
    if tri.has_normals & HAS_NORMALS != 0 {
        let n = Vec3::from(shading.n0) * b0
            + Vec3::from(shading.n1) * hit.b1
            + Vec3::from(shading.n2) * hit.b2;
        n_interpolated = n.normalize();
        ns = if n_interpolated.dot(ng) < 0.0 {
            -n_interpolated
        } else {
            n_interpolated
        };
    }
    let uv = (tri.has_uvs != 0).then(|| {
        Vec2::from(shading.uv0) * b0
            + Vec2::from(shading.uv1) * hit.b1
            + Vec2::from(shading.uv2) * hit.b2
    });
    let color = match uv {
        Some(uv) if !material.texture(SLOT_BASE).is_empty() => {
            base_color_texture(scene, material, uv)
        }
        _ => Vec3::from(material.color),
    };
    let color = if tri.has_normals & HAS_COLORS != 0 {
        color * vertex_color(&shading, [b0, hit.b1, hit.b2])
    } else {
        color
    };
    let mut inputs = PbrInputs::default();
    if material.kind == MaterialKind::Pbr.tag() {
        inputs = pbr_inputs_at(
            scene,
            material,
            surface_triangle,
            hit,
            uv,
            n_interpolated,
            ng,
            &mut ns,
            path,
        );
    }
    Shading {
        p,
        ng,
        ns,
        color,
        inputs,
    }
}
