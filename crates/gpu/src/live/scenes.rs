//! What a change to the scene rebuilds: nothing for the camera (the renderer restarts on a new
//! frame), the materials, emitters, lights and environment for edits that move nothing
//! (`GpuScene::restyle`, no BVH build), the top level over instances when copies of shared meshes
//! move (`GpuScene::with_moved_instances`, no mesh BVH), everything for other geometry.

use std::sync::Arc;

use rt_core::{GpuScene, Scene};

/// What a change rebuilt, coarsest last.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Rebuild {
    /// Camera, size or render settings only: the GPU scene is reused.
    Nothing,
    /// Materials, lights or environment: new GPU arrays for them, the BVH and triangles reused.
    Shading,
    /// Copies of shared meshes moved, turned or scaled: the top level over the instances, the
    /// meshes' BVHs and triangles reused.
    Instances,
    /// Objects, meshes, transforms or textures: a new GPU scene and BVH.
    Geometry,
}

impl Rebuild {
    pub fn name(self) -> &'static str {
        match self {
            Rebuild::Nothing => "nothing",
            Rebuild::Shading => "materials and lights",
            Rebuild::Instances => "instance placements",
            Rebuild::Geometry => "geometry and BVH",
        }
    }
}

/// The last scene the viewport built and its GPU arrays.
#[derive(Default)]
pub struct SceneCache {
    last: Option<(Scene, Arc<GpuScene>)>,
}

impl SceneCache {
    /// `scene`'s GPU arrays, rebuilt as little as the change from the last one allows.
    pub fn get(&mut self, scene: &Scene) -> rt_core::Result<(Arc<GpuScene>, Rebuild)> {
        let (built, rebuild) = match &self.last {
            Some((old, built)) if same_geometry(old, scene) => {
                if same_shading(old, scene) {
                    (built.clone(), Rebuild::Nothing)
                } else {
                    match built.restyle(scene)? {
                        Some(restyled) => (Arc::new(restyled), Rebuild::Shading),
                        None => (Arc::new(GpuScene::build(scene)?), Rebuild::Geometry),
                    }
                }
            }
            Some((old, built)) if same_meshes(old, scene) && same_shading(old, scene) => {
                let moved = |i: usize| old.objects[i].transform != scene.objects[i].transform;
                match built.with_moved_instances(scene, moved)? {
                    Some(placed) => (Arc::new(placed), Rebuild::Instances),
                    None => (Arc::new(GpuScene::build(scene)?), Rebuild::Geometry),
                }
            }
            _ => (Arc::new(GpuScene::build(scene)?), Rebuild::Geometry),
        };
        self.last = Some((scene.clone(), built.clone()));
        Ok((built, rebuild))
    }
}

/// Same objects (meshes compared by identity: edits never change one in place), transforms and
/// textures.
fn same_geometry(a: &Scene, b: &Scene) -> bool {
    same_meshes(a, b)
        && (a.objects.iter())
            .zip(&b.objects)
            .all(|(x, y)| x.transform == y.transform)
}

/// Same objects with the same meshes and textures, wherever they stand.
fn same_meshes(a: &Scene, b: &Scene) -> bool {
    a.objects.len() == b.objects.len()
        && (a.objects.iter())
            .zip(&b.objects)
            .all(|(x, y)| Arc::ptr_eq(&x.mesh, &y.mesh))
        && a.textures.len() == b.textures.len()
        && a.textures.iter().zip(&b.textures).all(|(x, y)| {
            Arc::ptr_eq(&x.rgba8, &y.rgba8) && x.width == y.width && x.height == y.height
        })
}

/// Same materials (shadow catchers included), lights, environment and light sampling (what
/// `GpuScene::restyle` redoes).
fn same_shading(a: &Scene, b: &Scene) -> bool {
    let same_environment = match (&a.environment, &b.environment) {
        (None, None) => true,
        (Some(x), Some(y)) => {
            Arc::ptr_eq(&x.map, &y.map)
                && x.rotation_deg == y.rotation_deg
                && x.strength == y.strength
        }
        _ => false,
    };
    a.objects
        .iter()
        .zip(&b.objects)
        .all(|(x, y)| x.material == y.material && x.shadow_catcher == y.shadow_catcher)
        && a.lights == b.lights
        && same_environment
        && a.settings.next_event_estimation == b.settings.next_event_estimation
}

#[cfg(test)]
mod tests {
    use super::*;
    use rt_core::MaterialKind;

    #[test]
    fn camera_moves_reuse_material_edits_restyle_and_geometry_edits_rebuild() {
        let scene = rt_io::assets::cornell_box().unwrap();
        let mut cache = SceneCache::default();
        let (first, how) = cache.get(&scene).unwrap();
        assert_eq!(how, Rebuild::Geometry);

        let mut moved = scene.clone();
        moved.camera.vfov_deg += 5.0;
        let (same, how) = cache.get(&moved).unwrap();
        assert_eq!(how, Rebuild::Nothing);
        assert!(Arc::ptr_eq(&same, &first));

        let mut recoloured = moved.clone();
        let floor = recoloured
            .objects
            .iter_mut()
            .find(|o| o.name == "floor")
            .unwrap();
        floor.material = rt_core::Material::Metal {
            albedo: [0.9, 0.6, 0.2],
            fuzz: 0.1,
        };
        let (restyled, how) = cache.get(&recoloured).unwrap();
        assert_eq!(how, Rebuild::Shading);
        // The restyled scene is the one a full build gives.
        let full = GpuScene::build(&recoloured).unwrap();
        assert_eq!(restyled.materials, full.materials);
        assert_eq!(restyled.emitters, full.emitters);
        assert_eq!(restyled.triangles, full.triangles);
        assert_eq!(restyled.features, full.features);
        assert!(
            restyled.features.kinds.contains(MaterialKind::Metal)
                && !first.features.kinds.contains(MaterialKind::Metal)
        );

        // A shadow catcher is a material flag on the GPU.
        let mut catching = recoloured.clone();
        catching.objects[0].shadow_catcher = true;
        let (caught, how) = cache.get(&catching).unwrap();
        assert_eq!(how, Rebuild::Shading);
        assert_eq!(
            caught.materials,
            GpuScene::build(&catching).unwrap().materials
        );

        let mut shifted = recoloured.clone();
        shifted.objects[0].transform.translation[0] += 0.1;
        let (_, how) = cache.get(&shifted).unwrap();
        assert_eq!(how, Rebuild::Geometry);
    }

    #[test]
    fn moving_a_copy_of_a_shared_mesh_rebuilds_only_the_top_level() {
        let mut scene = rt_io::assets::cornell_box().unwrap();
        let block = scene
            .objects
            .iter()
            .position(|o| o.name == "tall_block")
            .unwrap();
        let mut copy = scene.objects[block].clone();
        copy.name = "tall_block 2".into();
        copy.transform.translation[2] += 50.0;
        scene.objects.push(copy);
        let mut cache = SceneCache::default();
        let (first, _) = cache.get(&scene).unwrap();
        assert_eq!(first.instances.len(), 2);

        let mut moved = scene.clone();
        let last = moved.objects.len() - 1;
        moved.objects[last].transform.translation[0] -= 40.0;
        moved.objects[last].transform.rotation_deg[1] += 30.0;
        let (placed, how) = cache.get(&moved).unwrap();
        assert_eq!(how, Rebuild::Instances);
        // What a full build of the moved scene holds, but for the order the top level keeps.
        let full = GpuScene::build(&moved).unwrap();
        assert_eq!(placed.triangles, full.triangles);
        assert_eq!(placed.wide_nodes, full.wide_nodes);
        let sorted = |g: &GpuScene| {
            let mut v = g.instances.clone();
            v.sort_by_key(|i| i.material);
            v
        };
        assert_eq!(sorted(&placed), sorted(&full));
        assert_eq!(placed.extent, full.extent);

        // A world-space object moved: a full build.
        let mut floor_moved = moved.clone();
        floor_moved.objects[0].transform.translation[1] -= 1.0;
        let (_, how) = cache.get(&floor_moved).unwrap();
        assert_eq!(how, Rebuild::Geometry);
    }
}
