//! A hit turned into the world-space triangle that the flattened scene would have held
//! (`hit_triangle`), which is what shading reads: a triangle of an instance's mesh
//! (`crate::instances`) placed by the instance's transform. The twin of `instances.wgsl` beside
//! it; the rays' way through the instances is `instance_bvh.rs`.

/// The WGSL twin of this module, `instances.wgsl` beside it (composed into the kernels by
/// `rt_gpu::shaders`).
pub const WGSL: &str = include_str!("instances.wgsl");

use crate::gpu_scene::GpuScene;
use crate::gpu_types::{Hit, NO_INSTANCE, Shading, Triangle};
pub use crate::instances::PlacedTriangle;

/// The triangle a hit found, as shading reads it: its corners, material and flags, its shading
/// attributes (`shading`, zero where the scene has none) and its three corner tangents (zero
/// without). References into the scene's arrays for a world-space triangle (a copy cost the CPU
/// backend 5%; its attributes are gathered from their vertex records only when read), into a
/// `PlacedTriangle` for a triangle in an instance.
#[derive(Clone, Copy, Debug)]
pub struct HitTriangle<'a> {
    pub tri: &'a Triangle,
    pub tangents: &'a [[f32; 4]; 3],
    attributes: Attributes<'a>,
}

/// Where a hit triangle's shading attributes come from.
#[derive(Clone, Copy, Debug)]
enum Attributes<'a> {
    Stored(&'a GpuScene, u32),
    Placed(&'a Shading),
}

impl HitTriangle<'_> {
    /// The triangle's normals, colours and texture coordinates by corner (zero where its flags
    /// say it has none).
    #[inline]
    pub fn shading(&self) -> Shading {
        match self.attributes {
            Attributes::Stored(_, _) if self.tri.has_normals == 0 && self.tri.has_uvs == 0 => {
                Shading::default()
            }
            Attributes::Stored(scene, i) => scene.stored_shading(i),
            Attributes::Placed(shading) => *shading,
        }
    }
}

const NO_TANGENTS: [[f32; 4]; 3] = [[0.0; 4]; 3];

/// The world-space triangle `hit` found. A triangle in an instance is placed by the instance's
/// transform (its material the instance's object's) into `placed`; where that mirrors, corners
/// 1 and 2 swap to keep its front, and `hit`'s barycentrics with them.
#[inline(always)]
pub fn hit_triangle<'a>(
    scene: &'a GpuScene,
    hit: &mut Hit,
    placed: &'a mut Option<PlacedTriangle>,
) -> HitTriangle<'a> {
    let i = hit.triangle as usize;
    let tangents = scene.tangents.get(3 * i..3 * i + 3);
    let stored = HitTriangle {
        tri: &scene.triangles[i],
        tangents: tangents
            .and_then(|t| t.try_into().ok())
            .unwrap_or(&NO_TANGENTS),
        attributes: Attributes::Stored(scene, hit.triangle),
    };
    if hit.instance == NO_INSTANCE {
        return stored;
    }
    let p = placed.insert(place_in_world(scene, hit, stored));
    HitTriangle {
        tri: &p.tri,
        tangents: &p.tangents,
        attributes: Attributes::Placed(&p.shading),
    }
}

/// `hit_triangle`'s triangle in an instance, placed (out of line: the world-space path stays
/// short).
#[inline(never)]
fn place_in_world(scene: &GpuScene, hit: &mut Hit, stored: HitTriangle) -> PlacedTriangle {
    let instance = &scene.instances[hit.instance as usize];
    let mut placed = PlacedTriangle {
        tri: *stored.tri,
        shading: stored.shading(),
        tangents: *stored.tangents,
    };
    instance.place(&mut placed);
    if instance.mirrored != 0 {
        std::mem::swap(&mut hit.b1, &mut hit.b2);
    }
    placed
}
