//! Render passes (AOVs) written beside the beauty in one multilayer EXR, as Blender names its
//! layers: `depth.Z` (distance along the camera ray; 1e10 where nothing was met, as Blender),
//! `normal.X/Y/Z` and `albedo.R/G/B` (the denoiser's guides: the same data, computed once),
//! `position.X/Y/Z` (the point at the pixel's mean depth along its centre ray), `object.ID` and
//! `material.ID` (the first sample's first hit, counted from 1, 0 for nothing; never averaged),
//! and Cryptomatte's `CryptoObject00`–`02` (`crate::cryptomatte`: the scene traced again from the
//! camera, so not in a render part).

use crate::first_hits::FirstHits;
use crate::gpu_types::Frame;
use crate::output::{ExrAttribute, ExrChannel};
use crate::scene::Scene;

/// Where a camera ray met nothing, Blender's depth.
pub const NO_DEPTH: f32 = 1e10;

/// A pass `--aov` names.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Pass {
    Depth,
    Normal,
    Albedo,
    Position,
    Object,
    Material,
    Cryptomatte,
}

impl Pass {
    pub const ALL: [Pass; 7] = [
        Pass::Depth,
        Pass::Normal,
        Pass::Albedo,
        Pass::Position,
        Pass::Object,
        Pass::Material,
        Pass::Cryptomatte,
    ];

    pub fn name(self) -> &'static str {
        match self {
            Pass::Depth => "depth",
            Pass::Normal => "normal",
            Pass::Albedo => "albedo",
            Pass::Position => "position",
            Pass::Object => "object",
            Pass::Material => "material",
            Pass::Cryptomatte => "cryptomatte",
        }
    }
}

/// Parses a comma-separated list of pass names.
pub fn parse_passes(s: &str) -> Result<Vec<Pass>, String> {
    let mut passes = Vec::new();
    for name in s.split(',').map(str::trim).filter(|n| !n.is_empty()) {
        let pass = Pass::ALL
            .into_iter()
            .find(|p| p.name().eq_ignore_ascii_case(name))
            .ok_or_else(|| {
                format!(
                    "unknown pass '{name}': expected depth, normal, albedo, position, object, \
                     material or cryptomatte"
                )
            })?;
        if !passes.contains(&pass) {
            passes.push(pass);
        }
    }
    if passes.is_empty() {
        return Err("--aov needs at least one pass".into());
    }
    Ok(passes)
}

/// What the passes are made of: the guides and first hits of a render, each pixel's position
/// (`positions`) and each object's material id (`material_ids`); a render part keeps these, so a
/// merge writes the passes without the scene.
pub struct PassInputs<'a> {
    pub albedo: &'a [[f32; 3]],
    pub normal: &'a [[f32; 3]],
    pub hits: &'a FirstHits,
    pub position: &'a [[f32; 3]],
    pub material_ids: &'a [u32],
}

/// Each pixel's point at its mean depth along its centre ray through `frame` (the origin where
/// it met nothing). Linear in the depth, so the positions of parts merge as means weighted by
/// their samples' coverage.
pub fn positions(frame: &Frame, hits: &FirstHits) -> Vec<[f32; 3]> {
    let width = frame.width.max(1);
    (0..hits.coverage.len())
        .map(|i| {
            if hits.coverage[i] <= 0.0 {
                return [0.0; 3];
            }
            let (x, y) = (i as u32 % width, i as u32 / width);
            let (origin, direction) = crate::estimator::pixel_centre_ray(frame, x, y);
            (origin + direction * hits.depth(i)).to_array()
        })
        .collect()
}

/// The EXR channels (full names, one value per pixel) of `passes`, all but Cryptomatte's (which
/// traces the scene: [`cryptomatte_layers`]).
pub fn pass_channels(passes: &[Pass], inputs: &PassInputs) -> Vec<(String, Vec<f32>)> {
    let hits = inputs.hits;
    let n = hits.coverage.len();
    let depth: Vec<f32> = (0..n)
        .map(|i| {
            if hits.coverage[i] > 0.0 {
                hits.depth(i)
            } else {
                NO_DEPTH
            }
        })
        .collect();
    let vector = |layer: &str, names: [&str; 3], values: &dyn Fn(usize) -> [f32; 3]| {
        (0..3)
            .map(|c| {
                let name = format!("{layer}.{}", names[c]);
                (name, (0..n).map(|i| values(i)[c]).collect())
            })
            .collect::<Vec<_>>()
    };
    let mut out = Vec::new();
    for pass in passes {
        match pass {
            Pass::Depth => out.push(("depth.Z".to_string(), depth.clone())),
            Pass::Normal => out.extend(vector("normal", ["X", "Y", "Z"], &|i| inputs.normal[i])),
            Pass::Albedo => out.extend(vector("albedo", ["R", "G", "B"], &|i| inputs.albedo[i])),
            Pass::Position => out.extend(vector("position", ["X", "Y", "Z"], &|i| {
                inputs.position.get(i).copied().unwrap_or_default()
            })),
            Pass::Object => out.push((
                "object.ID".to_string(),
                hits.object.iter().map(|&o| o as f32).collect(),
            )),
            Pass::Material => {
                let ids = inputs.material_ids;
                let id = |o: u32| {
                    if o == 0 {
                        0.0
                    } else {
                        ids.get(o as usize - 1).copied().unwrap_or(0) as f32
                    }
                };
                out.push((
                    "material.ID".to_string(),
                    hits.object.iter().map(|&o| id(o)).collect(),
                ));
            }
            Pass::Cryptomatte => {}
        }
    }
    out
}

/// Cryptomatte's channels and header metadata when `passes` asks for them (none otherwise): the
/// render's first camera rays of each pixel traced again through `gpu_scene` (`samples` of them
/// at most `cryptomatte::MAX_SAMPLES`).
pub fn cryptomatte_layers(
    passes: &[Pass],
    scene: &Scene,
    gpu_scene: &crate::GpuScene,
    samples: u32,
) -> crate::Result<(Vec<ExrChannel>, Vec<ExrAttribute>)> {
    if !passes.contains(&Pass::Cryptomatte) {
        return Ok((Vec::new(), Vec::new()));
    }
    let frame = crate::frame::frame_for(scene, gpu_scene)?;
    let coverage = crate::cryptomatte::coverage(gpu_scene, &frame, samples);
    Ok(crate::cryptomatte::layers(scene, &coverage))
}

/// Each object's material id, counted from 1: objects with equal materials (a glTF's objects
/// sharing one, say) share an id, numbered in order of first use.
pub fn material_ids(scene: &Scene) -> Vec<u32> {
    let mut seen: Vec<&crate::Material> = Vec::new();
    scene
        .objects
        .iter()
        .map(|o| match seen.iter().position(|m| **m == o.material) {
            Some(k) => k as u32 + 1,
            None => {
                seen.push(&o.material);
                seen.len() as u32
            }
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Normal and albedo are the guides themselves; depth and position come from the first hits
    /// (the background: Blender's 1e10 and the origin); ids are the first sample's, materials
    /// numbered by first use with equal materials sharing one.
    #[test]
    fn passes_come_from_the_guides_and_first_hits() {
        let mut scene = crate::Scene::default();
        let mesh = std::sync::Arc::new(crate::shapes::quad(glam::Vec3::ZERO, glam::Vec3::Z, 1.0));
        for (name, material) in [
            (
                "a",
                crate::Material::Lambertian {
                    albedo: [0.5; 3],
                    texture: None,
                },
            ),
            (
                "b",
                crate::Material::Emissive {
                    color: [1.0; 3],
                    intensity: 1.0,
                },
            ),
            (
                "c",
                crate::Material::Lambertian {
                    albedo: [0.5; 3],
                    texture: None,
                },
            ),
        ] {
            scene.objects.push(crate::scene::Object {
                shadow_catcher: false,
                animation_node: None,
                name: name.into(),
                mesh: mesh.clone(),
                material,
                transform: Default::default(),
            });
        }
        scene.settings.width = 2;
        scene.settings.height = 1;
        let g = crate::GpuScene::build(&scene).unwrap();
        let frame = crate::frame::frame_for(&scene, &g).unwrap();
        let hits = FirstHits {
            coverage: vec![1.0, 0.0],
            depth_weighted: vec![2.5, 0.0],
            object: vec![3, 0],
            caught: vec![[0.0; 3]; 2],
        };
        let (albedo, normal) = (
            [[0.1, 0.2, 0.3], [0.4, 0.5, 0.6]],
            [[0.0, 0.0, 1.0], [1.0, 0.0, 0.0]],
        );
        let (position, ids) = (positions(&frame, &hits), material_ids(&scene));
        let inputs = PassInputs {
            albedo: &albedo,
            normal: &normal,
            hits: &hits,
            position: &position,
            material_ids: &ids,
        };
        let channels = pass_channels(&Pass::ALL, &inputs);
        let get = |name: &str| channels.iter().find(|(n, _)| n == name).unwrap().1.clone();
        assert_eq!(get("normal.Z"), [1.0, 0.0]);
        assert_eq!(get("albedo.G"), [0.2, 0.5]);
        assert_eq!(get("depth.Z"), [2.5, NO_DEPTH]);
        assert_eq!(get("object.ID"), [3.0, 0.0]);
        assert_eq!(material_ids(&scene), [1, 2, 1]);
        assert_eq!(
            get("material.ID"),
            [1.0, 0.0],
            "object c shares a's material"
        );
        let (o, d) = crate::estimator::pixel_centre_ray(&frame, 0, 0);
        let p = o + d * 2.5;
        assert_eq!(
            [
                get("position.X")[0],
                get("position.Y")[0],
                get("position.Z")[0]
            ],
            p.to_array()
        );
        assert_eq!(get("position.X")[1], 0.0);
    }

    #[test]
    fn pass_lists_parse() {
        assert_eq!(
            parse_passes("depth, normal,depth").unwrap(),
            [Pass::Depth, Pass::Normal]
        );
        assert!(
            parse_passes("depth,velocity")
                .unwrap_err()
                .contains("velocity")
        );
        assert!(parse_passes("").is_err());
    }
}
