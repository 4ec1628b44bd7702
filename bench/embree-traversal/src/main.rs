//! Embree 3 (Debian's libembree 3.13, loaded at run time) against rt's CPU traversal on the same
//! rays of one scene, one thread each, alternated: camera rays, diffuse bounce rays from their
//! hits (incoherent), and shadow rays from those points toward a point above the scene. Prints
//! rays per second and how often the two disagree on the nearest triangle or on occlusion.
//!
//! Why: issue 42 asks whether Embree measures better than rt's vectorised traversal by enough to
//! pay for a system library (and for images that would no longer equal the GPU kernels' bit for
//! bit: Embree's triangle test is not rt's watertight one).

use std::ffi::{CString, c_char, c_void};
use std::path::Path;
use std::time::Instant;

use glam::Vec3;
use libloading::Library;
use rt_core::gpu_scene::GpuScene;

type Handle = *mut c_void;

#[repr(C, align(16))]
#[derive(Clone, Copy)]
struct RtcRay {
    org: [f32; 3],
    tnear: f32,
    dir: [f32; 3],
    time: f32,
    tfar: f32,
    mask: u32,
    id: u32,
    flags: u32,
}

#[repr(C, align(16))]
#[derive(Clone, Copy)]
struct RtcHit {
    ng: [f32; 3],
    u: f32,
    v: f32,
    prim_id: u32,
    geom_id: u32,
    inst_id: [u32; 1],
}

#[repr(C)]
#[derive(Clone, Copy)]
struct RtcRayHit {
    ray: RtcRay,
    hit: RtcHit,
}

/// `RTCIntersectContext` as Debian's build lays it out (one instance level, no minimum width).
#[repr(C)]
struct RtcContext {
    flags: u32,
    filter: *const c_void,
    inst_id: [u32; 1],
}

const INVALID_ID: u32 = u32::MAX;

impl RtcContext {
    /// `rtcInitIntersectContext` (a header-only inline function), for incoherent rays.
    fn new() -> Self {
        RtcContext {
            flags: 0,
            filter: std::ptr::null(),
            inst_id: [INVALID_ID],
        }
    }
}

struct Embree {
    _library: Library,
    scene: Handle,
    intersect1: unsafe extern "C" fn(Handle, *mut RtcContext, *mut RtcRayHit),
    occluded1: unsafe extern "C" fn(Handle, *mut RtcContext, *mut RtcRay),
    build_seconds: f64,
}

impl Embree {
    /// Embree's scene over the triangles in rt's storage order (so primID = rt's index).
    #[allow(unsafe_code)]
    fn build(triangles: &[[Vec3; 3]], quality: u32) -> Result<Self, String> {
        // SAFETY: the symbols are Embree 3's C API with the signatures of its headers; every
        // handle passed back is one it returned; the buffers it allocates are written within the
        // sizes asked for.
        unsafe {
            let library = Library::new("libembree3.so.3")
                .map_err(|e| format!("libembree3.so.3: {e} (apt-get install libembree3-3)"))?;
            macro_rules! function {
                ($name:literal, $ty:ty) => {
                    *library
                        .get::<$ty>($name)
                        .map_err(|e| format!("{}: {e}", String::from_utf8_lossy($name)))?
                };
            }
            let new_device = function!(
                b"rtcNewDevice",
                unsafe extern "C" fn(*const c_char) -> Handle
            );
            let new_scene = function!(b"rtcNewScene", unsafe extern "C" fn(Handle) -> Handle);
            let set_quality = function!(
                b"rtcSetSceneBuildQuality",
                unsafe extern "C" fn(Handle, u32)
            );
            let new_geometry = function!(
                b"rtcNewGeometry",
                unsafe extern "C" fn(Handle, u32) -> Handle
            );
            let new_buffer = function!(
                b"rtcSetNewGeometryBuffer",
                unsafe extern "C" fn(Handle, u32, u32, u32, usize, usize) -> *mut c_void
            );
            let commit_geometry = function!(b"rtcCommitGeometry", unsafe extern "C" fn(Handle));
            let attach = function!(
                b"rtcAttachGeometry",
                unsafe extern "C" fn(Handle, Handle) -> u32
            );
            let release_geometry = function!(b"rtcReleaseGeometry", unsafe extern "C" fn(Handle));
            let commit_scene = function!(b"rtcCommitScene", unsafe extern "C" fn(Handle));
            let intersect1 = function!(
                b"rtcIntersect1",
                unsafe extern "C" fn(Handle, *mut RtcContext, *mut RtcRayHit)
            );
            let occluded1 = function!(
                b"rtcOccluded1",
                unsafe extern "C" fn(Handle, *mut RtcContext, *mut RtcRay)
            );

            let config = CString::new("").expect("no NUL");
            let device = new_device(config.as_ptr());
            if device.is_null() {
                return Err("rtcNewDevice failed".into());
            }
            let start = Instant::now();
            let scene = new_scene(device);
            set_quality(scene, quality);
            let geometry = new_geometry(device, 0); // RTC_GEOMETRY_TYPE_TRIANGLE
            let n = triangles.len();
            // RTC_BUFFER_TYPE_VERTEX, RTC_FORMAT_FLOAT3 (one spare float: Embree reads 16 bytes).
            let vertices = new_buffer(geometry, 1, 0, 0x9003, 12, 3 * n + 1) as *mut [f32; 3];
            let indices = new_buffer(geometry, 0, 0, 0x5003, 12, n) as *mut [u32; 3];
            for (i, t) in triangles.iter().enumerate() {
                for (c, v) in t.iter().enumerate() {
                    vertices.add(3 * i + c).write(v.to_array());
                }
                let first = 3 * i as u32;
                indices.add(i).write([first, first + 1, first + 2]);
            }
            commit_geometry(geometry);
            attach(scene, geometry);
            release_geometry(geometry);
            commit_scene(scene);
            Ok(Embree {
                _library: library,
                scene,
                intersect1,
                occluded1,
                build_seconds: start.elapsed().as_secs_f64(),
            })
        }
    }

    /// The nearest hit's triangle and distance.
    #[allow(unsafe_code)]
    fn nearest(&self, origin: Vec3, direction: Vec3) -> Option<(u32, f32)> {
        let mut ray = RtcRayHit {
            ray: ray(origin, direction, f32::INFINITY),
            hit: RtcHit {
                ng: [0.0; 3],
                u: 0.0,
                v: 0.0,
                prim_id: INVALID_ID,
                geom_id: INVALID_ID,
                inst_id: [INVALID_ID],
            },
        };
        let mut context = RtcContext::new();
        // SAFETY: a committed scene, a context and a ray laid out as Embree's headers say.
        unsafe { (self.intersect1)(self.scene, &mut context, &mut ray) };
        (ray.hit.geom_id != INVALID_ID).then_some((ray.hit.prim_id, ray.ray.tfar))
    }

    #[allow(unsafe_code)]
    fn occluded(&self, origin: Vec3, direction: Vec3, distance: f32) -> bool {
        let mut ray = ray(origin, direction, distance);
        let mut context = RtcContext::new();
        // SAFETY: as `nearest`.
        unsafe { (self.occluded1)(self.scene, &mut context, &mut ray) };
        ray.tfar < 0.0
    }
}

fn ray(origin: Vec3, direction: Vec3, tfar: f32) -> RtcRay {
    RtcRay {
        org: origin.to_array(),
        tnear: 0.0,
        dir: direction.to_array(),
        time: 0.0,
        tfar,
        mask: u32::MAX,
        id: 0,
        flags: 0,
    }
}

/// A linear congruential generator: the same rays on every run.
struct Random(u64);

impl Random {
    fn unit(&mut self) -> f32 {
        self.0 = self
            .0
            .wrapping_mul(6_364_136_223_846_793_005)
            .wrapping_add(1_442_695_040_888_963_407);
        (self.0 >> 40) as f32 / 16_777_216.0
    }
}

/// Rays as (origin, direction, distance for shadow rays).
type Rays = Vec<(Vec3, Vec3, f32)>;

/// Camera rays through random points of the image, bounce rays (cosine about the geometric
/// normal) from the camera rays' hits, and shadow rays from those hits toward a point above the
/// scene.
fn rays(scene: &rt_core::scene::Scene, gpu: &GpuScene, count: usize) -> (Rays, Rays, Rays) {
    let camera = &scene.camera;
    let from = Vec3::from(camera.from);
    let w = (Vec3::from(camera.to) - from).normalize();
    let u = w.cross(Vec3::from(camera.up)).normalize();
    let v = u.cross(w);
    let tan = (camera.vfov_deg.to_radians() * 0.5).tan();
    let (lo, hi) = scene.bounds().unwrap_or_default();
    let light = Vec3::new(
        (lo.x + hi.x) * 0.5,
        hi.y - 0.05 * (hi.y - lo.y),
        (lo.z + hi.z) * 0.5,
    );
    let offset = 1e-4 * (hi - lo).length();
    let mut random = Random(7);
    let (mut primary, mut bounce, mut shadow) = (Vec::new(), Vec::new(), Vec::new());
    while primary.len() < count {
        let (x, y) = (random.unit() * 2.0 - 1.0, random.unit() * 2.0 - 1.0);
        let d = (w + u * (x * tan) + v * (y * tan)).normalize();
        primary.push((from, d, f32::INFINITY));
        let hit = rt_core::estimator::trace(gpu, from, d, f32::INFINITY);
        if !hit.t.is_finite() || hit.instance != rt_core::gpu_types::NO_INSTANCE {
            continue;
        }
        let t = &gpu.triangles[hit.triangle as usize];
        let (v0, v1, v2) = (Vec3::from(t.v0), Vec3::from(t.v1), Vec3::from(t.v2));
        let mut n = (v1 - v0).cross(v2 - v0).normalize();
        if n.dot(d) > 0.0 {
            n = -n;
        }
        let p = from + d * hit.t + n * offset;
        let (a, b) = (random.unit(), random.unit() * std::f32::consts::TAU);
        let t1 = n.any_orthonormal_vector();
        let t2 = n.cross(t1);
        let dir = (t1 * (a.sqrt() * b.cos()) + t2 * (a.sqrt() * b.sin()) + n * (1.0 - a).sqrt())
            .normalize();
        bounce.push((p, dir, f32::INFINITY));
        let to = light - p;
        shadow.push((p, to.normalize(), to.length()));
    }
    (primary, bounce, shadow)
}

fn main() -> Result<(), String> {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let source = args.first().map_or("cornell", String::as_str);
    let mut scene = if source == "cornell" {
        rt_io::assets::cornell_box().map_err(|e| e.to_string())?
    } else {
        rt_io::load(Path::new(source), &rt_io::LoadOptions::default()).map_err(|e| e.to_string())?
    };
    if let Some(i) = args.iter().position(|a| a == "--camera") {
        let path = args.get(i + 1).ok_or("--camera needs a file")?;
        let camera =
            rt_io::camera_json::CameraFile::load(Path::new(path)).map_err(|e| e.to_string())?;
        camera.apply(&mut scene);
    }
    let start = Instant::now();
    let gpu = GpuScene::build(&scene).map_err(|e| e.to_string())?;
    let rt_build = start.elapsed().as_secs_f64();
    let triangles: Vec<[Vec3; 3]> = gpu
        .triangles
        .iter()
        .map(|t| [t.v0.into(), t.v1.into(), t.v2.into()])
        .collect();
    // RTC_BUILD_QUALITY_LOW, _MEDIUM (binned SAH) or _HIGH (with spatial splits, the default).
    let quality = match args
        .iter()
        .position(|a| a == "--quality")
        .map(|i| args.get(i + 1))
    {
        None => 2,
        Some(Some(q)) if q == "high" => 2,
        Some(Some(q)) if q == "medium" => 1,
        Some(Some(q)) if q == "low" => 0,
        Some(q) => return Err(format!("--quality {q:?}: low, medium or high")),
    };
    let embree = Embree::build(&triangles, quality)?;
    println!(
        "{source}: {} triangles; scene build (rt, all of it) {rt_build:.3} s, Embree (quality {quality}) {:.3} s",
        triangles.len(),
        embree.build_seconds
    );
    let (primary, bounce, shadow) = rays(&scene, &gpu, 400_000);

    let mut disagree = [0usize; 3];
    for (set, rays) in [&primary, &bounce].into_iter().enumerate() {
        for &(o, d, _) in rays {
            let ours = rt_core::estimator::trace(&gpu, o, d, f32::INFINITY);
            let ours = ours.t.is_finite().then_some(ours.triangle);
            if ours != embree.nearest(o, d).map(|h| h.0) {
                disagree[set] += 1;
            }
        }
    }
    for &(o, d, l) in &shadow {
        if rt_core::estimator::occluded(&gpu, o, d, l) != embree.occluded(o, d, l) {
            disagree[2] += 1;
        }
    }

    let timed = |f: &dyn Fn() -> usize, n: usize| {
        let start = Instant::now();
        std::hint::black_box(f());
        n as f64 / start.elapsed().as_secs_f64() / 1e6
    };
    let names = ["camera rays", "bounce rays", "shadow rays"];
    for (set, rays) in [&primary, &bounce, &shadow].into_iter().enumerate() {
        let ours = || {
            rays.iter()
                .map(|&(o, d, l)| match set {
                    2 => usize::from(rt_core::estimator::occluded(&gpu, o, d, l)),
                    _ => rt_core::estimator::trace(&gpu, o, d, f32::INFINITY).triangle as usize,
                })
                .fold(0, usize::wrapping_add)
        };
        let theirs = || {
            rays.iter()
                .map(|&(o, d, l)| match set {
                    2 => usize::from(embree.occluded(o, d, l)),
                    _ => embree.nearest(o, d).map_or(0, |h| h.0 as usize),
                })
                .fold(0, usize::wrapping_add)
        };
        let (mut rt, mut em) = (Vec::new(), Vec::new());
        for _ in 0..3 {
            rt.push(timed(&ours, rays.len()));
            em.push(timed(&theirs, rays.len()));
        }
        let best = |v: &[f64]| v.iter().copied().fold(0.0, f64::max);
        println!(
            "{:12} {:>8} rays: rt {:6.2} M/s, Embree {:6.2} M/s (Embree/rt {:.2}); disagree on {} ({:.4}%)",
            names[set],
            rays.len(),
            best(&rt),
            best(&em),
            best(&em) / best(&rt),
            disagree[set],
            100.0 * disagree[set] as f64 / rays.len() as f64
        );
    }
    Ok(())
}
