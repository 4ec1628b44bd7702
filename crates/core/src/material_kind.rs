//! The one enumeration of material kinds. Everything else that lists kinds is derived from it or
//! checked against it: the GPU tag (`gpu_types::Material::kind`), the WGSL constants `MAT_*`
//! (`tests/shaders.rs`), the pipeline switches that compile a kind's BSDF in or out and the
//! `SceneFeatures` that set them, and the editor's kind list. A new kind is a variant here, its
//! BSDF twins, and its parameter block (`gpu_types`, docs/architecture.md "Adding a material kind").

use crate::material::Material;

/// What model a material's surface follows; the tag the kernels dispatch their BSDF on.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
#[repr(u32)]
pub enum MaterialKind {
    Lambertian = 0,
    Metal = 1,
    Dielectric = 2,
    Emissive = 3,
    /// glTF metallic-roughness (`math::bsdf`).
    Pbr = 4,
}

impl MaterialKind {
    /// Every kind, in tag order.
    pub const ALL: [MaterialKind; 5] = [
        MaterialKind::Lambertian,
        MaterialKind::Metal,
        MaterialKind::Dielectric,
        MaterialKind::Emissive,
        MaterialKind::Pbr,
    ];

    /// The value of `gpu_types::Material::kind`.
    pub const fn tag(self) -> u32 {
        self as u32
    }

    pub fn from_tag(tag: u32) -> Option<MaterialKind> {
        MaterialKind::ALL.get(tag as usize).copied()
    }

    /// The WGSL constant holding `tag` (`crates/core/src/gpu_types.wgsl`).
    pub fn wgsl_constant(self) -> &'static str {
        match self {
            MaterialKind::Lambertian => "MAT_LAMBERTIAN",
            MaterialKind::Metal => "MAT_METAL",
            MaterialKind::Dielectric => "MAT_DIELECTRIC",
            MaterialKind::Emissive => "MAT_EMISSIVE",
            MaterialKind::Pbr => "MAT_PBR",
        }
    }

    /// The boolean pipeline constant that compiles this kind's BSDF into the kernels, for kinds a
    /// scene may lack; `None` for those every kernel has (Lambert is the fallback lobe, emitters
    /// need no BSDF).
    pub fn pipeline_switch(self) -> Option<&'static str> {
        match self {
            MaterialKind::Lambertian | MaterialKind::Emissive => None,
            MaterialKind::Metal => Some("HAS_METAL"),
            MaterialKind::Dielectric => Some("HAS_DIELECTRIC"),
            MaterialKind::Pbr => Some("HAS_PBR"),
        }
    }

    /// What the kind looks like, in a sentence (the editor's tooltip).
    pub fn summary(self) -> &'static str {
        match self {
            MaterialKind::Lambertian => "Lambertian: matte, one colour",
            MaterialKind::Metal => "A mirror, blurred by fuzz",
            MaterialKind::Dielectric => "A smooth dielectric that refracts",
            MaterialKind::Emissive => "A light source (emits from its front faces)",
            MaterialKind::Pbr => {
                "glTF metallic-roughness: metal or dielectric, rough or polished, opaque or clear"
            }
        }
    }

    /// The name a user sees (the editor's kind list).
    pub fn label(self) -> &'static str {
        match self {
            MaterialKind::Lambertian => "Diffuse",
            MaterialKind::Metal => "Metal",
            MaterialKind::Dielectric => "Glass",
            MaterialKind::Emissive => "Emissive",
            MaterialKind::Pbr => "Physically based",
        }
    }
}

impl Material {
    pub fn kind(&self) -> MaterialKind {
        match self {
            Material::Lambertian { .. } => MaterialKind::Lambertian,
            Material::Metal { .. } => MaterialKind::Metal,
            Material::Dielectric { .. } => MaterialKind::Dielectric,
            Material::Emissive { .. } => MaterialKind::Emissive,
            Material::Pbr(_) => MaterialKind::Pbr,
        }
    }
}

/// A set of material kinds (which ones a scene uses).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub struct KindSet(u32);

impl KindSet {
    pub fn all() -> Self {
        KindSet(MaterialKind::ALL.iter().fold(0, |s, k| s | 1 << k.tag()))
    }

    pub fn insert(&mut self, kind: MaterialKind) {
        self.0 |= 1 << kind.tag();
    }

    pub fn contains(self, kind: MaterialKind) -> bool {
        self.0 & (1 << kind.tag()) != 0
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn tags_are_the_kinds_in_order() {
        for (i, kind) in MaterialKind::ALL.iter().enumerate() {
            assert_eq!(kind.tag(), i as u32);
            assert_eq!(MaterialKind::from_tag(i as u32), Some(*kind));
        }
        assert_eq!(MaterialKind::from_tag(MaterialKind::ALL.len() as u32), None);
        let mut set = KindSet::default();
        set.insert(MaterialKind::Metal);
        assert!(set.contains(MaterialKind::Metal) && !set.contains(MaterialKind::Pbr));
        assert!(
            MaterialKind::ALL
                .iter()
                .all(|&k| KindSet::all().contains(k))
        );
    }
}
