//! The wavefront kernels (`Kernel::Wavefront`, the default) run the megakernel's estimator
//! stage by stage: the same random numbers in the same order, so the same image and ray count.

mod common;

use common::{
    camera, gpu, object, scene, settings, textured_scene_with_normals_metal_glass_and_lens,
};
use glam::Vec3;
use rt_core::bvh::{BvhLayout, BvhQuality};
use rt_core::math::rng::SamplerKind;
use rt_core::shapes::{cuboid, quad};
use rt_core::{GpuScene, Material, Scene};
use rt_gpu::{Aovs, Image, Kernel, RenderOptions, Renderer};

/// Renders in batches of at most 2 samples (so waves start mid-image and mid-sample); returns the
/// image, its AOVs and the rays traced.
fn render(
    ctx: &rt_gpu::GpuContext,
    scene: &Scene,
    gpu_scene: &GpuScene,
    kernel: Kernel,
) -> (Image, Aovs, u64) {
    let options = RenderOptions {
        kernel,
        aovs: true,
        tuning: rt_gpu::Tuning {
            count_rays: true,
            ..Default::default()
        },
        max_samples_per_dispatch: Some(2),
        ..Default::default()
    };
    let mut renderer = Renderer::for_scene(ctx, scene, gpu_scene, options).expect("renderer");
    renderer
        .render(scene.settings.samples_per_pixel, |_| true)
        .expect("render");
    assert_eq!(renderer.dropped_samples(), 0, "NaN/Inf samples");
    (
        renderer.read_image().expect("read back"),
        renderer.read_aovs().expect("read back").expect("AOVs"),
        renderer.rays_traced(),
    )
}

fn cornell_with_metal_and_glass() -> Scene {
    let mut s = rt_io::assets::cornell_box().unwrap();
    s.objects[0].material = Material::Metal {
        albedo: [0.9; 3],
        fuzz: 0.3,
    };
    s.objects[1].material = Material::Dielectric {
        ior: 1.5,
        tint: [1.0; 3],
    };
    s
}

fn scenes() -> Vec<(&'static str, Scene)> {
    // The other scenes use the default Sobol sampler.
    let mut independent = rt_io::assets::cornell_box().unwrap();
    independent.settings.sampler = SamplerKind::Independent;
    independent.settings.max_depth = 12;
    let mut empty = rt_io::assets::cornell_box().unwrap();
    empty.objects.clear();
    empty.ambient = [0.5; 3];
    vec![
        (
            "Cornell box with metal and glass",
            cornell_with_metal_and_glass(),
        ),
        (
            "textures, normals, metal, glass, lens",
            textured_scene_with_normals_metal_glass_and_lens(),
        ),
        ("Cornell box, independent sampler, depth 12", independent),
        ("empty scene", empty),
    ]
}

/// The first value of `a` that differs from `b`'s by more than `relative` of the larger (0: any
/// difference), as a message.
fn first_difference(a: &[[f32; 3]], b: &[[f32; 3]], relative: f32) -> Option<String> {
    if a.len() != b.len() {
        return Some(format!("{} values against {}", a.len(), b.len()));
    }
    a.iter()
        .zip(b)
        .enumerate()
        .flat_map(|(i, (x, y))| (0..3).map(move |c| (i, c, x[c], y[c])))
        .find(|(_, _, x, y)| {
            let d = (x - y).abs();
            x != y && (d.is_nan() || d > relative * x.abs().max(y.abs()))
        })
        .map(|(i, c, x, y)| format!("value {i} channel {c}: wavefront {x} vs megakernel {y}"))
}

/// Bit for bit on CPU adapters: every stage does the megakernel's float operations in its order
/// (the next-event contribution is added by connect before the path's next vertex, as the
/// megakernel adds it). A GPU driver may fuse the megakernel's multiply-add where the wavefront
/// stores the product first, so there they agree to rounding (1e-5), every path the same.
#[test]
fn the_wavefront_kernels_give_the_megakernels_image() {
    let Some(ctx) = gpu() else { return };
    let relative = if ctx.info.device_type == wgpu::DeviceType::Cpu {
        0.0
    } else {
        1e-5
    };
    for (name, mut s) in scenes() {
        s.settings.width = 23;
        s.settings.height = 13;
        s.settings.samples_per_pixel = 5;
        for layout in [BvhLayout::Cwbvh, BvhLayout::Bvh2] {
            let gpu_scene = GpuScene::build_with_layout(&s, BvhQuality::Medium, layout).unwrap();
            let (mega, mega_aovs, mega_rays) = render(ctx, &s, &gpu_scene, Kernel::Megakernel);
            let (wave, wave_aovs, wave_rays) = render(ctx, &s, &gpu_scene, Kernel::Wavefront);
            assert_eq!(wave.samples_per_pixel, 5, "{name}, {layout:?}");
            assert!(
                wave.channel_means().iter().any(|m| *m > 0.0),
                "{name}, {layout:?}: black image"
            );
            if let Some(d) = first_difference(&wave.rgb(), &mega.rgb(), relative) {
                panic!("{name}, {layout:?}: image: {d}");
            }
            assert_eq!(wave_rays, mega_rays, "{name}, {layout:?}: rays traced");
            for (aov, w, m) in [
                ("albedo", &wave_aovs.albedo, &mega_aovs.albedo),
                ("normal", &wave_aovs.normal, &mega_aovs.normal),
                ("emission", &wave_aovs.emission, &mega_aovs.emission),
            ] {
                if let Some(d) = first_difference(w, m, relative) {
                    panic!("{name}, {layout:?}: {aov}: {d}");
                }
            }
            assert!(
                name == "empty scene" || wave_aovs.albedo.iter().flatten().any(|a| *a > 0.0),
                "{name}, {layout:?}: no albedo recorded"
            );
        }
    }
}

/// With point lights the light sums are added in another order (delta lights before the
/// next-event estimate), so the images agree to rounding, not bit for bit.
#[test]
fn the_wavefront_kernels_agree_with_delta_lights() {
    let Some(ctx) = gpu() else { return };
    let mut s = cornell_with_metal_and_glass();
    let mut bulb = rt_core::Light::new(rt_core::LightKind::Point, "bulb");
    bulb.position = [150.0, 400.0, 250.0];
    bulb.intensity = 40_000.0;
    s.lights.push(bulb);
    s.settings.width = 23;
    s.settings.height = 13;
    s.settings.samples_per_pixel = 3;
    let gpu_scene = GpuScene::build(&s).unwrap();
    let (mega, _, mega_rays) = render(ctx, &s, &gpu_scene, Kernel::Megakernel);
    let (wave, _, wave_rays) = render(ctx, &s, &gpu_scene, Kernel::Wavefront);
    if let Some(d) = first_difference(&wave.rgb(), &mega.rgb(), 1e-5) {
        panic!("{d}");
    }
    assert_eq!(wave_rays, mega_rays, "rays traced");
}

/// A wave stops at its first empty queue. Under an open sky every path leaves after its bounce off
/// a floor, so a max depth of 64 runs two depths a wave (the hit and the bounce that escapes);
/// inside a closed room without roulette every path lives to the max depth, so all 64 run.
#[test]
fn a_wave_stops_once_every_path_has_ended() {
    let Some(ctx) = gpu() else { return };
    let depths_per_wave = |objects, roulette: bool| {
        let mut s = scene(
            objects,
            camera(Vec3::new(0.0, 3.0, 0.1), Vec3::ZERO, 60.0),
            [0.5; 3],
            settings(16, 16, 4, 64),
        );
        s.settings.russian_roulette = roulette;
        let gpu_scene = GpuScene::build(&s).unwrap();
        let mut renderer =
            Renderer::for_scene(ctx, &s, &gpu_scene, RenderOptions::default()).unwrap();
        assert_eq!(renderer.kernel(), Kernel::Wavefront);
        let stats = renderer.render_batch(4).unwrap();
        assert!(stats.dispatches > 0);
        f64::from(stats.wave_depths) / f64::from(stats.dispatches)
    };
    let floor = vec![object(
        "floor",
        quad(Vec3::ZERO, Vec3::Y, 100.0),
        Material::lambertian([0.5; 3]),
    )];
    let open = depths_per_wave(floor, true);
    assert_eq!(open, 2.0, "depths a wave ran under an open sky");
    let room = vec![object(
        "room",
        cuboid(Vec3::splat(-5.0), Vec3::splat(5.0), true),
        Material::lambertian([0.5; 3]),
    )];
    let closed = depths_per_wave(room, false);
    assert_eq!(closed, 64.0, "depths a wave ran in a closed room");
}
