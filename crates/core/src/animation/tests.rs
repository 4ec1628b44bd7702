use std::f32::consts::FRAC_PI_2;
use std::sync::Arc;

use super::*;
use crate::camera::Camera;
use crate::light::{Light, LightKind};
use crate::material::Material;
use crate::posing::{placed, posed_at};
use crate::scene::Object;
use crate::scene::{Mesh, Scene, Transform};

fn close(a: [f32; 3], b: [f32; 3]) -> bool {
    a.iter().zip(b).all(|(x, y)| (x - y).abs() < 1e-5)
}

fn node(parent: Option<u32>, translation: [f32; 3]) -> Node {
    Node {
        parent,
        translation,
        rotation: [0.0, 0.0, 0.0, 1.0],
        scale: [1.0; 3],
    }
}

fn channel(node: u32, property: Property, times: &[f32], values: &[[f32; 4]]) -> Channel {
    Channel {
        node,
        property,
        interpolation: Interpolation::Linear,
        times: times.to_vec(),
        values: values.to_vec(),
    }
}

fn object(node: Option<u32>, transform: Transform) -> Object {
    Object {
        name: "thing".into(),
        mesh: Arc::new(Mesh {
            positions: vec![Vec3::ZERO, Vec3::X, Vec3::Y],
            indices: vec![[0, 1, 2]],
            ..Mesh::default()
        }),
        material: Material::lambertian([0.5; 3]),
        transform,
        shadow_catcher: false,
        animation_node: node,
    }
}

/// A parent turning a quarter turn about +y in one second, a child one unit along its x.
fn turning_arm() -> Animation {
    let quarter = Quat::from_rotation_y(FRAC_PI_2).to_array();
    Animation {
        nodes: vec![node(None, [0.0; 3]), node(Some(0), [1.0, 0.0, 0.0])],
        channels: vec![channel(
            0,
            Property::Rotation,
            &[0.0, 1.0],
            &[[0.0, 0.0, 0.0, 1.0], quarter],
        )],
    }
}

/// What a child node carries turns with its parent: an object, a point light and the camera
/// stand where the parent's turn puts them, a spot light's direction turns too, and something
/// carried by no node stays.
#[test]
fn children_move_with_their_animated_parents() {
    let at_child = Transform {
        translation: [1.0, 0.0, 0.0],
        ..Transform::default()
    };
    let mut light = Light::new(LightKind::Spot, "lamp");
    light.position = [1.0, 0.0, 0.0];
    light.direction = [1.0, 0.0, 0.0];
    light.animation_node = Some(1);
    let scene = Scene {
        objects: vec![object(Some(1), at_child.clone()), object(None, at_child)],
        lights: vec![light],
        camera: Camera {
            from: [1.0, 0.0, 0.0],
            to: [1.0, 0.0, -1.0],
            animation_node: Some(1),
            ..Camera::default()
        },
        animation: Some(Arc::new(turning_arm())),
        ..Scene::default()
    };
    let posed = posed_at(&scene, 1.0);
    assert!(posed.animation.is_none(), "a posed scene moves no further");
    let moved = &posed.objects[0].transform;
    assert!(close(moved.translation, [0.0, 0.0, -1.0]), "{moved:?}");
    assert!(close(moved.rotation_deg, [0.0, 90.0, 0.0]), "{moved:?}");
    assert_eq!(posed.objects[1].transform, scene.objects[1].transform);
    assert!(close(posed.lights[0].position, [0.0, 0.0, -1.0]));
    assert!(close(posed.lights[0].direction, [0.0, 0.0, -1.0]));
    assert!(close(posed.camera.from, [0.0, 0.0, -1.0]));
    assert!(close(posed.camera.to, [-1.0, 0.0, -1.0]));
    // Halfway, the arm stands at 45° (rotations interpolate along the sphere).
    let half = posed_at(&scene, 0.5).objects[0].transform.translation;
    let r = std::f32::consts::FRAC_1_SQRT_2;
    assert!(close(half, [r, 0.0, -r]), "{half:?}");
    // Before the first key and at rest the scene stands as it was saved.
    assert_eq!(posed_at(&scene, -3.0).objects, scene.objects);
}

/// An object the user moved after loading keeps that move: the animation moves it from where it
/// stands by what its node did since rest.
#[test]
fn a_moved_object_keeps_its_move() {
    let animation = Animation {
        nodes: vec![node(None, [0.0; 3])],
        channels: vec![channel(
            0,
            Property::Translation,
            &[0.0, 2.0],
            &[[0.0; 4], [4.0, 0.0, 0.0, 0.0]],
        )],
    };
    let moved_by_user = Transform {
        translation: [0.0, 3.0, 0.0],
        scale: [2.0; 3],
        ..Transform::default()
    };
    let scene = Scene {
        objects: vec![object(Some(0), moved_by_user)],
        animation: Some(Arc::new(animation)),
        ..Scene::default()
    };
    let t = posed_at(&scene, 1.0).objects[0].transform.clone();
    assert!(close(t.translation, [2.0, 3.0, 0.0]), "{t:?}");
    assert!(close(t.scale, [2.0; 3]));
}

/// A node scaled to nothing at rest (objects that grow in) cannot be undone: what it carries is
/// placed in the node's own space, as the glTF loader places a mesh, a lamp or a camera.
#[test]
fn a_node_at_zero_scale_at_rest_places_what_it_carries_in_its_space() {
    let mut grow = node(None, [0.0, 1.0, 0.0]);
    grow.scale = [0.0; 3];
    let animation = Animation {
        nodes: vec![grow],
        channels: vec![channel(
            0,
            Property::Scale,
            &[0.0, 1.0],
            &[[0.0; 4], [3.0, 3.0, 3.0, 0.0]],
        )],
    };
    let zero = Transform {
        translation: [0.0, 1.0, 0.0],
        scale: [0.0; 3],
        ..Transform::default()
    };
    let mut light = Light::new(LightKind::Spot, "lamp");
    light.animation_node = Some(0);
    let scene = Scene {
        objects: vec![object(Some(0), zero)],
        lights: vec![light],
        animation: Some(Arc::new(animation)),
        ..Scene::default()
    };
    let posed = posed_at(&scene, 1.0);
    let t = &posed.objects[0].transform;
    assert!(
        close(t.translation, [0.0, 1.0, 0.0]) && close(t.scale, [3.0; 3]),
        "{t:?}"
    );
    assert!(close(posed.lights[0].position, [0.0, 1.0, 0.0]));
    assert!(close(posed.lights[0].direction, [0.0, 0.0, -1.0]));
}

/// A sheared world matrix (a non-uniform scale above a turned node) cannot be held by a
/// transform: the posed mesh is baked in world space, each vertex where the matrix puts it.
#[test]
fn a_sheared_pose_bakes_the_mesh() {
    let mut parent = node(None, [0.0; 3]);
    parent.scale = [1.0, 3.0, 1.0];
    let mut child = node(Some(0), [0.0; 3]);
    child.rotation = Quat::from_rotation_z(0.5).to_array();
    let animation = Animation {
        nodes: vec![parent, child],
        channels: vec![channel(
            1,
            Property::Translation,
            &[0.0, 1.0],
            &[[0.0; 4], [0.0, 0.0, 2.0, 0.0]],
        )],
    };
    let rest = animation.world_matrices(None)[1];
    let (mesh, transform) = placed(object(None, Transform::default()).mesh, rest);
    let scene = Scene {
        objects: vec![Object {
            mesh,
            transform,
            ..object(Some(1), Transform::default())
        }],
        animation: Some(Arc::new(animation.clone())),
        ..Scene::default()
    };
    let posed = posed_at(&scene, 1.0);
    let now = animation.world_matrices(Some(1.0))[1];
    let o = &posed.objects[0];
    for (p, q) in o.mesh.positions.iter().zip([Vec3::ZERO, Vec3::X, Vec3::Y]) {
        let placed = o.transform.matrix().transform_point3(*p);
        assert!(
            (placed - now.transform_point3(q)).length() < 1e-5,
            "{placed} {q}"
        );
    }
}

#[test]
fn keys_interpolate_and_hold_at_the_ends() {
    let values = [[0.0; 4], [4.0, 2.0, 0.0, 0.0]];
    let at = |interpolation, values: &[[f32; 4]], t| {
        let c = Channel {
            interpolation,
            ..channel(0, Property::Translation, &[1.0, 3.0], values)
        };
        sample(&c, t).unwrap()
    };
    assert_eq!(
        at(Interpolation::Linear, &values, 2.0),
        Vec4::new(2.0, 1.0, 0.0, 0.0)
    );
    assert_eq!(at(Interpolation::Linear, &values, 0.0), Vec4::ZERO);
    assert_eq!(
        at(Interpolation::Linear, &values, 9.0),
        Vec4::from(values[1])
    );
    assert_eq!(at(Interpolation::Step, &values, 2.9), Vec4::ZERO);
    // A cubic spline with zero tangents eases: halfway is halfway, a quarter is 5/32.
    let cubic = [[0.0; 4], values[0], [0.0; 4], [0.0; 4], values[1], [0.0; 4]];
    assert!((at(Interpolation::CubicSpline, &cubic, 2.0).x - 2.0).abs() < 1e-6);
    assert!((at(Interpolation::CubicSpline, &cubic, 1.5).x - 4.0 * 5.0 / 32.0).abs() < 1e-6);
    let short = channel(0, Property::Translation, &[1.0, 3.0], &values[..1]);
    assert!(sample(&short, 2.0).is_none());
}

#[test]
fn validation_names_what_cannot_play() {
    assert_eq!(turning_arm().validate(), Ok(()));
    let mut circle = turning_arm();
    circle.nodes[0].parent = Some(1);
    assert!(circle.validate().unwrap_err().contains("circle"));
    let mut orphan = turning_arm();
    orphan.nodes[1].parent = Some(7);
    assert!(orphan.validate().unwrap_err().contains("ancestor 7"));
    let mut keys = turning_arm();
    keys.channels[0].values.pop();
    assert!(keys.validate().unwrap_err().contains("do not match"));
    let mut order = turning_arm();
    order.channels[0].times = vec![1.0, 0.0];
    assert!(order.validate().unwrap_err().contains("increasing"));
    let mut target = turning_arm();
    target.channels[0].node = 9;
    assert!(target.validate().unwrap_err().contains("no such node"));
    // Unvalidated circles still end (posing never hangs on a hostile file).
    assert_eq!(circle.world_matrices(Some(0.5)).len(), 2);
}

/// A matrix that scales an axis (or all) to nothing still gives finite numbers (a project holds
/// only those), the remaining axes turned as the matrix turns them.
#[test]
fn singular_matrices_give_finite_transforms() {
    let turn = Quat::from_rotation_y(0.7) * Quat::from_rotation_x(0.3);
    for scale in [
        Vec3::ZERO,
        Vec3::new(2.0, 0.0, 1.0),
        Vec3::new(0.0, 0.0, 3.0),
    ] {
        let m = Mat4::from_scale_rotation_translation(scale, turn, Vec3::new(1.0, 2.0, 3.0));
        let t = crate::posing::transform_of(m);
        let numbers = t.translation.iter().chain(&t.rotation_deg).chain(&t.scale);
        assert!(numbers.into_iter().all(|v| v.is_finite()), "{scale}: {t:?}");
        assert!(close(t.scale, scale.to_array()), "{scale}: {t:?}");
        assert!(close(t.translation, [1.0, 2.0, 3.0]));
        // The axes that remain point where the matrix's do: the same matrix back.
        if scale != Vec3::ZERO {
            let back = t.matrix();
            assert!(back.abs_diff_eq(m, 1e-5), "{back} vs {m}");
        }
    }
}
