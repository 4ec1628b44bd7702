//! Named materials for people who do not know albedos and indices of refraction by heart.

use rt_core::Material;
use rt_core::material::Pbr;

fn pbr(p: Pbr) -> Material {
    Material::Pbr(Box::new(p))
}

pub struct Preset {
    pub name: &'static str,
    pub tip: &'static str,
    pub material: fn() -> Material,
}

/// Metal colours are the linear sRGB normal-incidence reflectances of the pure metals (as in
/// common PBR tables); indices of refraction are the usual textbook values at ~590 nm.
pub const PRESETS: &[Preset] = &[
    Preset {
        name: "Copper",
        tip: "Metal, reflectance (0.955, 0.638, 0.538), slightly rough",
        material: || Material::Metal {
            albedo: [0.955, 0.638, 0.538],
            fuzz: 0.05,
        },
    },
    Preset {
        name: "Gold",
        tip: "Metal, reflectance (1.0, 0.766, 0.336)",
        material: || Material::Metal {
            albedo: [1.0, 0.766, 0.336],
            fuzz: 0.02,
        },
    },
    Preset {
        name: "Silver",
        tip: "Metal, reflectance (0.972, 0.960, 0.915), polished",
        material: || Material::Metal {
            albedo: [0.972, 0.960, 0.915],
            fuzz: 0.0,
        },
    },
    Preset {
        name: "Chrome",
        tip: "Metal, reflectance (0.55, 0.556, 0.554), mirror polished",
        material: || Material::Metal {
            albedo: [0.55, 0.556, 0.554],
            fuzz: 0.0,
        },
    },
    Preset {
        name: "Aluminium",
        tip: "Metal, reflectance (0.913, 0.922, 0.924), brushed",
        material: || Material::Metal {
            albedo: [0.913, 0.922, 0.924],
            fuzz: 0.15,
        },
    },
    Preset {
        name: "Water",
        tip: "Dielectric, IOR 1.333",
        material: || Material::Dielectric {
            ior: 1.333,
            tint: [1.0; 3],
        },
    },
    Preset {
        name: "Crown glass",
        tip: "Dielectric, IOR 1.517 (common window and lens glass)",
        material: || Material::Dielectric {
            ior: 1.517,
            tint: [1.0; 3],
        },
    },
    Preset {
        name: "Diamond",
        tip: "Dielectric, IOR 2.417",
        material: || Material::Dielectric {
            ior: 2.417,
            tint: [1.0; 3],
        },
    },
    Preset {
        name: "Rough gold",
        tip: "Physically based metal, base (1.0, 0.766, 0.336), roughness 0.4",
        material: || {
            pbr(Pbr {
                base_color: [1.0, 0.766, 0.336],
                metallic: 1.0,
                roughness: 0.4,
                ..Default::default()
            })
        },
    },
    Preset {
        name: "Brushed aluminium",
        tip: "Physically based metal, base (0.913, 0.922, 0.924), roughness 0.3 (isotropic)",
        material: || {
            pbr(Pbr {
                base_color: [0.913, 0.922, 0.924],
                metallic: 1.0,
                roughness: 0.3,
                ..Default::default()
            })
        },
    },
    Preset {
        name: "Frosted glass",
        tip: "Physically based rough glass, IOR 1.5, roughness 0.3",
        material: || {
            pbr(Pbr {
                base_color: [1.0; 3],
                roughness: 0.3,
                transmission: 1.0,
                ..Default::default()
            })
        },
    },
    Preset {
        name: "Plastic",
        tip: "Physically based dielectric, white, IOR 1.5, roughness 0.2",
        material: || {
            pbr(Pbr {
                base_color: [0.8; 3],
                roughness: 0.2,
                ..Default::default()
            })
        },
    },
    Preset {
        name: "Car paint",
        tip: "Physically based red paint, roughness 0.4, under a clear coat (roughness 0.03)",
        material: || {
            pbr(Pbr {
                base_color: [0.5, 0.02, 0.02],
                roughness: 0.4,
                clearcoat: 1.0,
                clearcoat_roughness: 0.03,
                ..Default::default()
            })
        },
    },
    Preset {
        name: "Velvet",
        tip: "Physically based deep red cloth with a pink sheen (sheen roughness 0.5)",
        material: || {
            pbr(Pbr {
                base_color: [0.3, 0.02, 0.06],
                roughness: 1.0,
                sheen_color: [1.0, 0.55, 0.65],
                sheen_roughness: 0.5,
                ..Default::default()
            })
        },
    },
    Preset {
        name: "Rubber",
        tip: "Physically based dielectric, near black, IOR 1.52, roughness 0.8",
        material: || {
            pbr(Pbr {
                base_color: [0.02; 3],
                roughness: 0.8,
                ior: 1.52,
                ..Default::default()
            })
        },
    },
];

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_preset_is_a_valid_material() {
        for preset in PRESETS {
            (preset.material)()
                .validate(preset.name)
                .expect("preset in range");
        }
    }
}
