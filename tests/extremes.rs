//! Degenerate geometry and extreme settings render without NaN/Inf (checked by `render_gpu`) and
//! with the expected result, or fail with a clear error (part of issue 5's suite).

mod common;

use common::*;
use glam::Vec3;
use rt_core::shapes::{cuboid, quad};
use rt_core::{GpuScene, Material, Mesh};
use rt_gpu::RenderOptions;

fn lit_room() -> Vec<rt_core::Object> {
    vec![
        object(
            "room",
            cuboid(Vec3::splat(-2.0), Vec3::splat(2.0), true),
            Material::lambertian([0.6; 3]),
        ),
        object(
            "light",
            quad(Vec3::new(0.0, 1.99, 0.0), -Vec3::Y, 1.0),
            Material::Emissive {
                color: [8.0; 3],
                intensity: 1.0,
            },
        ),
    ]
}

fn mean(image: &rt_gpu::Image) -> f64 {
    image.channel_means().iter().sum::<f64>() / 3.0
}

#[test]
fn zero_area_and_duplicated_triangles_are_harmless() {
    let Some(ctx) = gpu() else { return };
    let mut objects = lit_room();
    // A needle, a point-triangle, a duplicated face and a duplicated vertex.
    let mesh = Mesh {
        positions: vec![
            Vec3::ZERO,
            Vec3::X,
            Vec3::X * 2.0,
            Vec3::ZERO,
            Vec3::new(0.0, 0.5, 0.0),
            Vec3::X,
        ],
        normals: None,
        uvs: None,
        indices: vec![[0, 1, 2], [0, 0, 0], [0, 1, 4], [0, 1, 4], [3, 5, 4]],
    };
    objects.push(object("degenerate", mesh, Material::lambertian([0.5; 3])));
    // Degenerate emitters too: they get no share of next-event estimation.
    let needle = Mesh {
        positions: vec![Vec3::ZERO, Vec3::Y, Vec3::Y * 2.0],
        normals: None,
        uvs: None,
        indices: vec![[0, 1, 2]],
    };
    objects.push(object(
        "needle light",
        needle,
        Material::Emissive {
            color: [1.0; 3],
            intensity: 1.0,
        },
    ));
    let scene = scene(
        objects,
        camera(Vec3::new(0.0, 0.0, 1.8), Vec3::ZERO, 70.0),
        [0.0; 3],
        settings(16, 16, 16, 6),
    );
    let gpu_scene = GpuScene::build(&scene).unwrap();
    assert_eq!(
        gpu_scene.emitters.len(),
        2,
        "only the light's two triangles have area"
    );
    let image = render_gpu(ctx, &scene, &gpu_scene, RenderOptions::default());
    assert!(mean(&image) > 0.05, "the room should be lit");
}

#[test]
fn one_triangle_and_camera_inside_an_object() {
    let Some(ctx) = gpu() else { return };
    let one = Mesh {
        positions: vec![
            Vec3::new(-1.0, -1.0, -1.0),
            Vec3::new(1.0, -1.0, -1.0),
            Vec3::new(0.0, 1.0, -1.0),
        ],
        normals: None,
        uvs: None,
        indices: vec![[0, 1, 2]],
    };
    let scene1 = scene(
        vec![object(
            "tri",
            one,
            Material::Emissive {
                color: [1.0; 3],
                intensity: 1.0,
            },
        )],
        camera(Vec3::ZERO, -Vec3::Z, 30.0),
        [0.0; 3],
        settings(9, 9, 4, 2),
    );
    let image = render(ctx, &scene1);
    assert_eq!(
        image.pixels[4 * 9 + 4][0],
        1.0,
        "the centre pixel sees the emitting triangle"
    );
    // Inside a closed box lit from inside: every pixel sees the inside walls.
    let scene2 = scene(
        lit_room(),
        camera(Vec3::new(0.3, -0.5, 0.2), Vec3::new(1.0, 0.0, -1.0), 60.0),
        [5.0; 3],
        settings(8, 8, 8, 4),
    );
    let image = render(ctx, &scene2);
    assert!(
        image.pixels.iter().all(|p| p[0] > 0.0),
        "a closed room lets no ambient light in but is lit"
    );
}

#[test]
fn extreme_fields_of_view_and_image_sizes() {
    let Some(ctx) = gpu() else { return };
    for (vfov, width, height) in [
        (0.1f32, 4, 4),
        (179.0, 16, 8),
        (40.0, 1, 1),
        (40.0, 1, 37),
        (60.0, 53, 1),
    ] {
        let scene = scene(
            lit_room(),
            camera(Vec3::new(0.0, 0.0, 1.5), Vec3::ZERO, vfov),
            [0.0; 3],
            settings(width, height, 2, 5),
        );
        let image = render(ctx, &scene);
        assert_eq!(image.pixels.len(), (width * height) as usize);
        assert!(
            mean(&image) > 0.0,
            "vfov {vfov} {width}x{height}: black image"
        );
    }
}

#[test]
fn max_depth_zero_is_black_and_one_shows_emitters_only() {
    let Some(ctx) = gpu() else { return };
    let objects = lit_room();
    let look_up = camera(Vec3::ZERO, Vec3::new(0.0, 1.0, 0.001), 20.0);
    let image = render(
        ctx,
        &scene(
            objects.clone(),
            look_up.clone(),
            [1.0; 3],
            settings(4, 4, 2, 0),
        ),
    );
    assert!(
        image.pixels.iter().all(|p| p[..3] == [0.0; 3]),
        "max depth 0 traces nothing"
    );
    let image = render(
        ctx,
        &scene(objects, look_up, [1.0; 3], settings(4, 4, 2, 1)),
    );
    assert!(
        image.pixels.iter().all(|p| p[..3] == [8.0; 3]),
        "max depth 1 sees only the light: {:?}",
        image.pixels[0]
    );
}

#[test]
fn invalid_geometry_is_rejected_naming_object_and_vertex() {
    let mut scene = scene(
        Vec::new(),
        camera(Vec3::Z, Vec3::ZERO, 40.0),
        [0.0; 3],
        settings(4, 4, 1, 1),
    );
    let mesh = Mesh {
        positions: vec![Vec3::ZERO, Vec3::new(f32::NAN, 0.0, 0.0), Vec3::Y],
        normals: None,
        uvs: None,
        indices: vec![[0, 1, 2]],
    };
    scene
        .objects
        .push(object("broken", mesh, Material::lambertian([0.5; 3])));
    let message = GpuScene::build(&scene).unwrap_err().to_string();
    assert!(
        message.contains("'broken'") && message.contains("vertex 2"),
        "{message}"
    );
    scene.objects[0].mesh.positions[1] = Vec3::X;
    scene.objects[0].mesh.indices[0] = [0, 1, 7];
    let message = GpuScene::build(&scene).unwrap_err().to_string();
    assert!(
        message.contains("'broken'") && message.contains("vertex 8"),
        "{message}"
    );
    scene.objects[0].mesh.indices[0] = [0, 1, 2];
    scene.objects[0].transform.scale = [0.0, 1.0, 1.0];
    assert!(
        GpuScene::build(&scene)
            .unwrap_err()
            .to_string()
            .contains("singular")
    );
}
