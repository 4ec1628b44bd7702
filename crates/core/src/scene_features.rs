//! `SceneFeatures`: which optional kernel features a scene needs, found while packing it
//! (`GpuScene::build`); the pipeline compiles the others out.

use crate::material_kind::KindSet;

/// Which optional kernel features a scene needs; the pipeline compiles the others out.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub struct SceneFeatures {
    /// The material kinds present (each optional kind's BSDF is compiled in only when present:
    /// `MaterialKind::pipeline_switch`).
    pub kinds: KindSet,
    pub textures: bool,
    pub thin_lens: bool,
    /// Next-event estimation samples lights (the settings ask for it, and the scene has emitters
    /// or a light tree).
    pub nee: bool,
    /// Next-event estimation picks emitters, point and spot lights through the light tree
    /// (`GpuScene::light_tree`).
    pub light_tree: bool,
    /// Point, spot or directional lights (summed at each vertex, or sampled through the tree).
    pub delta_lights: bool,
    /// PBR normal maps or anisotropy: tangents (the kernel reads `GpuScene::tangents`).
    pub normal_maps: bool,
    /// An environment map (sampled directly, and by MIS with the BSDF).
    pub environment: bool,
    /// Alpha-masked or blended surfaces (the traversal reads their coverage at each hit).
    pub alpha: bool,
    /// Participating media: a material's interior (or, set from the frame, the scene's fog).
    pub media: bool,
    /// Shared meshes placed as instances (`crate::instances`): rays also walk their top level.
    pub instances: bool,
}
