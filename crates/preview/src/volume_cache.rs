//! The irradiance volume of the frame's scene, kept while the scene, its lights and its sky stay
//! as they were (`irradiance_volume`), built at once or on a thread (`probes::compute`).

use std::hash::{Hash, Hasher};
use std::sync::{Arc, Mutex};

use glam::Vec3;
use rt_core::Scene;

use super::bounce::{IrradianceVolume, Sky, diffuse_albedo, uniform_bounce};
use super::probes::compute;
use super::types::PreviewLight;

/// Scenes up to this many triangles have their volume built at once even in the editor (a few
/// milliseconds); larger ones on a thread while the last volume stands in.
pub const SYNC_TRIANGLES: usize = 20_000;

/// The last volume built, and the one being built on a thread (for its key).
struct Cache {
    key: u64,
    volume: Arc<IrradianceVolume>,
    building: Option<(u64, std::thread::JoinHandle<IrradianceVolume>)>,
}

fn key_of(scene: &Scene, lights: &[PreviewLight], sky: &Sky) -> u64 {
    let mut hasher = std::collections::hash_map::DefaultHasher::new();
    super::surfaces::hash_placements(scene, &mut hasher);
    for object in &scene.objects {
        diffuse_albedo(&object.material, &[])
            .to_array()
            .map(f32::to_bits)
            .hash(&mut hasher);
    }
    bytemuck::cast_slice::<PreviewLight, u32>(lights).hash(&mut hasher);
    sky.mean.to_array().map(f32::to_bits).hash(&mut hasher);
    sky.map
        .as_ref()
        .map(|m| Arc::as_ptr(m) as usize)
        .hash(&mut hasher);
    sky.turns.to_bits().hash(&mut hasher);
    scene.settings.max_depth.hash(&mut hasher);
    hasher.finish()
}

/// The volume of the frame's scene, rebuilt when its geometry, materials, lights or sky changed
/// and kept otherwise (one scene at a time: the editor's). With `wait`, or for a scene of at most
/// `SYNC_TRIANGLES` triangles, it is built before this returns; otherwise on a thread, and until it
/// is ready the last volume (or radiosity's uniform term) stands in and the second value is true:
/// the caller draws again soon.
pub fn irradiance_volume(
    scene: &Scene,
    lights: &[PreviewLight],
    bounds: Option<(Vec3, Vec3)>,
    sky: &Sky,
    wait: bool,
) -> (Arc<IrradianceVolume>, bool) {
    static CACHE: Mutex<Option<Cache>> = Mutex::new(None);
    let Some(bounds) = bounds else {
        return (Arc::new(IrradianceVolume::uniform(Vec3::ZERO)), false);
    };
    let key = key_of(scene, lights, sky);
    let mut guard = CACHE.lock().unwrap_or_else(|e| e.into_inner());
    // A finished build becomes the current volume.
    if let Some(cache) = guard.as_mut()
        && cache
            .building
            .as_ref()
            .is_some_and(|(_, job)| job.is_finished())
        && let Some((built, job)) = cache.building.take()
        && let Ok(volume) = job.join()
    {
        cache.key = built;
        cache.volume = Arc::new(volume);
    }
    if let Some(cache) = guard.as_ref()
        && cache.key == key
    {
        return (cache.volume.clone(), false);
    }
    if wait || scene.triangle_count() <= SYNC_TRIANGLES {
        let volume = Arc::new(compute(scene, lights, bounds, sky));
        let building = guard.take().and_then(|c| c.building);
        *guard = Some(Cache {
            key,
            volume: volume.clone(),
            building,
        });
        return (volume, false);
    }
    let cache = guard.get_or_insert_with(|| Cache {
        key: 0,
        volume: Arc::new(IrradianceVolume::uniform(uniform_bounce(
            scene, lights, bounds,
        ))),
        building: None,
    });
    if cache.building.is_none() {
        let (scene, lights, sky) = (scene.clone(), lights.to_vec(), sky.clone());
        cache.building = Some((
            key,
            std::thread::spawn(move || compute(&scene, &lights, bounds, &sky)),
        ));
    }
    (cache.volume.clone(), true)
}
