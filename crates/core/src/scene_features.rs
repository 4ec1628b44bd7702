//! `SceneFeatures`: which optional kernel features a scene needs, found while packing it
//! (`GpuScene::build`); the pipeline compiles the others out.

/// Which optional kernel features a scene needs; the pipeline compiles the others out.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub struct SceneFeatures {
    pub textures: bool,
    pub metal: bool,
    pub dielectric: bool,
    pub thin_lens: bool,
    /// Next-event estimation (the scene has emitters and the settings ask for it).
    pub nee: bool,
    /// Point, spot or directional lights (always sampled directly).
    pub delta_lights: bool,
    /// The PBR material.
    pub pbr: bool,
    /// PBR normal maps (the kernel reads `GpuScene::tangents`).
    pub normal_maps: bool,
    /// An environment map (sampled directly, and by MIS with the BSDF).
    pub environment: bool,
    /// Alpha-masked or blended surfaces (the traversal reads their coverage at each hit).
    pub alpha: bool,
}
