//! Determinism across seeds, and the loop-budget sentinel (the largest dispatch against single
//! samples).

use super::*;

#[test]
fn same_seed_gives_identical_bytes_and_other_seeds_differ() {
    let Some(ctx) = gpu() else { return };
    let mut scene = cornell_with_metal_and_glass(32);
    scene.settings.samples_per_pixel = 8;
    let gpu_scene = GpuScene::build(&scene).unwrap();
    let bytes = |scene: &Scene, options: RenderOptions| {
        let image = render_gpu(ctx, scene, &gpu_scene, options);
        bytemuck::cast_slice::<[f32; 4], u8>(&image.pixels).to_vec()
    };
    let a = bytes(&scene, RenderOptions::default());
    // A different split into dispatches must not change a bit either.
    let b = bytes(
        &scene,
        RenderOptions {
            max_samples_per_dispatch: Some(3),
            target_dispatch: std::time::Duration::from_secs(10),
            ..Default::default()
        },
    );
    assert!(a == b, "same seed, different batching: images differ");
    scene.settings.seed = 2;
    let c = bytes(&scene, RenderOptions::default());
    assert!(a != c, "different seeds gave the same image");
}

/// Lavapipe silently cuts loops short after 65,535 iterations per invocation. The image does not
/// depend on how samples are batched, so the largest batch the renderer allows must give exactly the
/// image of one sample per dispatch; a truncated traversal or path loop would change it.
#[test]
fn largest_dispatch_gives_the_same_image_as_single_samples() {
    let Some(ctx) = gpu() else { return };
    let path =
        std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("assets/bunny/bunny-lowres-npm.obj");
    let mut scene = rt_io::obj::load_obj(&path, 0).unwrap();
    let mut room = rt_core::shapes::cuboid(Vec3::splat(-5.0), Vec3::splat(5.0), true);
    room.positions
        .iter_mut()
        .for_each(|p| *p += Vec3::new(0.0, 2.0, 0.0));
    scene
        .objects
        .push(object("room", room, Material::lambertian([0.8; 3])));
    scene.objects.push(object(
        "light",
        quad(Vec3::new(0.0, 6.9, 0.0), -Vec3::Y, 2.0),
        Material::Emissive {
            color: [10.0; 3],
            intensity: 1.0,
        },
    ));
    scene.camera = camera(Vec3::new(0.0, 1.0, 4.0), Vec3::new(0.0, 1.0, 0.0), 40.0);
    scene.settings = settings(16, 16, 64, 8);
    let gpu_scene = GpuScene::build(&scene).unwrap();
    // The megakernel runs whole paths per invocation, so it is the one at risk (a wavefront
    // invocation traces one ray).
    let slow = RenderOptions {
        target_dispatch: std::time::Duration::from_secs(60),
        kernel: rt_gpu::Kernel::Megakernel,
        ..Default::default()
    };
    let one = render_gpu(
        ctx,
        &scene,
        &gpu_scene,
        RenderOptions {
            max_samples_per_dispatch: Some(1),
            ..slow
        },
    );
    // With a generous time target the renderer grows dispatches to its loop-budget cap.
    let mut renderer = rt_gpu::Renderer::for_scene(ctx, &scene, &gpu_scene, slow).unwrap();
    let mut largest = 0;
    while renderer.samples_done() < 64 {
        largest = largest.max(
            renderer
                .render_batch(64 - renderer.samples_done())
                .unwrap()
                .samples,
        );
    }
    assert!(
        largest > 1,
        "the renderer never batched samples, so this test checks nothing"
    );
    let batched = renderer.read_image().unwrap();
    assert!(
        one.pixels == batched.pixels,
        "batched samples ({largest} per dispatch) changed the image: loop truncation?"
    );
}
