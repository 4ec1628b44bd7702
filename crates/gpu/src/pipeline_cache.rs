//! What a tracing kernel is specialised for (`PipelineKey`), its compiled stages
//! (`KernelPipelines`), and the per-device cache of one by the other that `GpuContext` holds and
//! `pipelines` fills. These types sit below both, so the context need not import the module that
//! builds pipelines on it.

use std::collections::HashMap;
use std::sync::{Arc, Mutex};

use rt_core::SceneFeatures;
use rt_core::bvh::BvhLayout;

use crate::options::Kernel;

/// The pipelines built on one device so far (`GpuContext::pipelines`), for every renderer on it.
pub(crate) type PipelineCache = Mutex<HashMap<PipelineKey, Arc<KernelPipelines>>>;

/// What a tracing kernel is specialised for.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct PipelineKey {
    pub kernel: Kernel,
    pub features: SceneFeatures,
    /// The BVH the kernel traverses (a different module, not a constant: the node types differ).
    pub layout: BvhLayout,
    /// Trace with the driver's ray queries instead of traversing `layout` (`Trace::Hardware`).
    pub ray_query: bool,
    pub count_rays: bool,
    /// The megakernel's work-group width and height (the wavefront kernels' is fixed: 0 x 0 in a
    /// normalised key).
    pub workgroup: [u32; 2],
    /// Owen-scrambled Sobol points instead of independent random numbers.
    pub sobol: bool,
    /// Accumulate first-hit albedo and normal for the denoiser.
    pub aovs: bool,
    /// Skip pixels that adaptive sampling has stopped.
    pub adaptive: bool,
}

impl PipelineKey {
    /// The key as the cache sees it: fields the kernel ignores are normalised, so they cannot make
    /// two entries of one pipeline.
    pub(crate) fn normalised(self) -> Self {
        let key = PipelineKey {
            // Ray queries need no BVH layout of rt's.
            layout: if self.ray_query {
                BvhLayout::Cwbvh
            } else {
                self.layout
            },
            ..self
        };
        match key.kernel {
            Kernel::Megakernel => key,
            // The wavefront kernels' work group is fixed in their WGSL (`wavefront::WAVE_GROUP`).
            Kernel::Wavefront => PipelineKey {
                workgroup: [0, 0],
                ..key
            },
        }
    }

    /// The override constants `kernel`'s WGSL declares, with this key's values.
    pub(crate) fn constants(&self) -> Vec<(&'static str, f64)> {
        let flag = |b: bool| if b { 1.0 } else { 0.0 };
        let mut constants = vec![
            ("HAS_TEXTURES", flag(self.features.textures)),
            ("HAS_THIN_LENS", flag(self.features.thin_lens)),
            ("COUNT_RAYS", flag(self.count_rays)),
            ("HAS_NEE", flag(self.features.nee)),
            ("HAS_LIGHT_TREE", flag(self.features.light_tree)),
            ("HAS_DELTA_LIGHTS", flag(self.features.delta_lights)),
            ("HAS_ENVIRONMENT", flag(self.features.environment)),
            ("HAS_NORMAL_MAPS", flag(self.features.normal_maps)),
            ("HAS_ALPHA", flag(self.features.alpha)),
            ("HAS_MEDIA", flag(self.features.media)),
            ("HAS_INSTANCES", flag(self.features.instances)),
            ("SOBOL", flag(self.sobol)),
            ("WRITE_AOVS", flag(self.aovs)),
            ("ADAPTIVE", flag(self.adaptive)),
        ];
        for kind in rt_core::MaterialKind::ALL {
            if let Some(switch) = kind.pipeline_switch() {
                constants.push((switch, flag(self.features.kinds.contains(kind))));
            }
        }
        if self.kernel == Kernel::Megakernel {
            constants.push(("WG_X", f64::from(self.workgroup[0])));
            constants.push(("WG_Y", f64::from(self.workgroup[1])));
        }
        constants
    }
}

/// The compiled stages of one kernel for one key, over one bind-group layout (`bindings`).
pub(crate) struct KernelPipelines {
    pub layout: wgpu::BindGroupLayout,
    /// Each entry point's pipeline (`pipelines` builds them; `stage` finds one).
    pub stages: Vec<(&'static str, wgpu::ComputePipeline)>,
}

impl KernelPipelines {
    /// The stage with entry point `entry` (one of the kernel's, fixed in `pipelines.rs`).
    pub fn stage(&self, entry: &str) -> &wgpu::ComputePipeline {
        match self.stages.iter().find(|(name, _)| *name == entry) {
            Some((_, pipeline)) => pipeline,
            None => unreachable!("no stage {entry} in {:?}", self.stage_names()),
        }
    }

    fn stage_names(&self) -> Vec<&'static str> {
        self.stages.iter().map(|(name, _)| *name).collect()
    }
}
