//! Degenerate and invalid geometry, a camera inside an object, extreme fields of view, image
//! sizes and depths, scene scale, and rays grazing edges and vertices.

use super::*;
use rt_core::Mesh;

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
        colors: None,
        indices: vec![[0, 1, 2], [0, 0, 0], [0, 1, 4], [0, 1, 4], [3, 5, 4]],
    };
    objects.push(object("degenerate", mesh, Material::lambertian([0.5; 3])));
    // Degenerate emitters too: they get no share of next-event estimation.
    let needle = Mesh {
        positions: vec![Vec3::ZERO, Vec3::Y, Vec3::Y * 2.0],
        normals: None,
        uvs: None,
        colors: None,
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
        colors: None,
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
        colors: None,
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
    std::sync::Arc::make_mut(&mut scene.objects[0].mesh).positions[1] = Vec3::X;
    std::sync::Arc::make_mut(&mut scene.objects[0].mesh).indices[0] = [0, 1, 7];
    let message = GpuScene::build(&scene).unwrap_err().to_string();
    assert!(
        message.contains("'broken'") && message.contains("vertex 8"),
        "{message}"
    );
    std::sync::Arc::make_mut(&mut scene.objects[0].mesh).indices[0] = [0, 1, 2];
    scene.objects[0].transform.scale = [0.0, 1.0, 1.0];
    assert!(
        GpuScene::build(&scene)
            .unwrap_err()
            .to_string()
            .contains("singular")
    );
}

/// The Cornell box scaled by 1e-4 … 1e6, and moved 1e5 away from the origin, renders the same image
/// (camera scaled and moved with it): no self-intersection acne, no leaks through closed corners.
/// Compared by the image means of independent renders, within 5 standard errors of the difference.
#[test]
fn scene_scale_and_offset_do_not_change_the_image() {
    let Some(ctx) = gpu() else { return };
    let base = rt_io::assets::cornell_box().unwrap();
    let render_at = |scale: f32, offset: Vec3| {
        let mut scene = base.clone();
        for o in &mut scene.objects {
            o.transform.scale = [scale; 3];
            o.transform.translation = offset.to_array();
        }
        let moved = |p: [f32; 3]| (Vec3::from(p) * scale + offset).to_array();
        scene.camera.from = moved(scene.camera.from);
        scene.camera.to = moved(scene.camera.to);
        scene.settings = settings(48, 48, 32, 8);
        mean_and_error(ctx, &scene, 4)
    };
    let (reference, ref_err) = render_at(1.0, Vec3::ZERO);
    for (scale, offset) in [
        (1e-8f32, Vec3::ZERO),
        (1e-6, Vec3::ZERO),
        (1e-4, Vec3::ZERO),
        (1e4, Vec3::ZERO),
        (1e6, Vec3::ZERO),
        (1.0, Vec3::splat(1e5)),
    ] {
        let (m, err) = render_at(scale, offset);
        let sigma = (ref_err * ref_err + err * err).sqrt();
        assert!(
            (m - reference).abs() <= 5.0 * sigma + 1e-4 * reference,
            "scale {scale}, offset {offset}: mean {m} vs {reference} at scale 1 (σ {sigma})"
        );
    }
}

/// An n×n grid of quads over [-1, 1]² in the plane y = 0, facing +y: many shared edges and
/// vertices shared by up to six triangles.
fn grid(n: u32) -> Mesh {
    let mut positions = Vec::new();
    for j in 0..=n {
        for i in 0..=n {
            positions.push(Vec3::new(
                -1.0 + 2.0 * i as f32 / n as f32,
                0.0,
                -1.0 + 2.0 * j as f32 / n as f32,
            ));
        }
    }
    let mut indices = Vec::new();
    let at = |i: u32, j: u32| j * (n + 1) + i;
    for j in 0..n {
        for i in 0..n {
            // Alternate the diagonal so that some vertices join six triangles.
            if (i + j) % 2 == 0 {
                indices.push([at(i, j), at(i, j + 1), at(i + 1, j + 1)]);
                indices.push([at(i, j), at(i + 1, j + 1), at(i + 1, j)]);
            } else {
                indices.push([at(i, j), at(i, j + 1), at(i + 1, j)]);
                indices.push([at(i + 1, j), at(i, j + 1), at(i + 1, j + 1)]);
            }
        }
    }
    Mesh {
        positions,
        normals: None,
        uvs: None,
        colors: None,
        indices,
    }
}

/// Grazing rays (0.01° to 0.09° to the plane), rays exactly along the axes (zero direction
/// components), and rays aimed exactly at shared vertices and edges all hit the grid, at the right
/// distance, on the GPU and in the CPU reference alike: no cracks, no misses from infinities in the
/// slab test.
#[test]
fn grazing_axis_aligned_and_vertex_rays_hit_where_they_should() {
    let Some(ctx) = gpu() else { return };
    let n = 8;
    let s = scene(
        vec![object("grid", grid(n), Material::lambertian([0.5; 3]))],
        camera(Vec3::new(0.0, 3.0, 3.0), Vec3::ZERO, 40.0),
        [0.0; 3],
        settings(4, 4, 1, 1),
    );
    let gpu_scene = GpuScene::build(&s).unwrap();
    let ray = |origin: Vec3, direction: Vec3| rt_core::gpu_types::Ray {
        origin: origin.to_array(),
        t_max: f32::MAX,
        direction: direction.normalize().to_array(),
        _pad: 0.0,
    };
    // (ray, expected distance)
    let mut cases = Vec::new();
    for degrees in [0.01f32, 0.03, 0.05, 0.09] {
        let angle = degrees.to_radians();
        for z in [-0.9f32, -0.3, 0.0, 0.55] {
            // Starts 1.5 before the hit at x = 0.1 (and at z = 0: along a row of shared edges).
            let distance = 1.5f32;
            let origin = Vec3::new(0.1 - distance * angle.cos(), distance * angle.sin(), z);
            cases.push((
                ray(origin, Vec3::new(angle.cos(), -angle.sin(), 0.0)),
                distance,
            ));
        }
    }
    // Interior vertices and edges only: a ray through the mesh's outer boundary may rightly go
    // either way.
    for j in 1..n {
        for i in 1..n {
            let x = -1.0 + 2.0 * i as f32 / n as f32;
            let z = -1.0 + 2.0 * j as f32 / n as f32;
            // Exactly down the y axis onto every vertex, and onto the middle of an edge.
            cases.push((ray(Vec3::new(x, 1.0, z), Vec3::NEG_Y), 1.0));
            cases.push((ray(Vec3::new(x + 1.0 / n as f32, 2.0, z), Vec3::NEG_Y), 2.0));
            // Obliquely at the vertex from above.
            let from = Vec3::new(x + 0.3, 0.7, z - 0.2);
            let target = Vec3::new(x, 0.0, z);
            cases.push((ray(from, target - from), (target - from).length()));
        }
    }
    let rays: Vec<_> = cases.iter().map(|(r, _)| *r).collect();
    let hits = rt_gpu::trace_rays::trace_rays(ctx, &gpu_scene, &rays, rt_gpu::Trace::Bvh).unwrap();
    for ((r, expected), gpu_hit) in cases.iter().zip(&hits) {
        let cpu =
            rt_core::estimator::trace(&gpu_scene, r.origin.into(), r.direction.into(), r.t_max);
        for (what, hit) in [("GPU", gpu_hit), ("CPU", &cpu)] {
            assert_ne!(hit.triangle, u32::MAX, "{what} missed: {r:?}");
            assert!(
                (hit.t - expected).abs() <= 1e-4 * expected,
                "{what} hit at {} instead of {expected}: {r:?}",
                hit.t
            );
        }
    }
    assert!(cases.len() > 150);
}
