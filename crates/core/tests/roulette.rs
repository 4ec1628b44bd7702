#![allow(clippy::unwrap_used)]
//! Russian roulette is unbiased: on the CPU backend, the Cornell box with a smooth glass ball and a
//! rough glass ball (paths that refract in and out, where the roulette undoes 1/η²) renders to the
//! same image as without roulette, over the whole image and over the balls, and so does the same
//! box filled with fog (roulette after a scattering): a paired Z-test on the difference of the two
//! estimates, sample by sample.

use std::sync::Arc;

use rayon::prelude::*;
use rt_core::estimator::radiance;
use rt_core::material::Pbr;
use rt_core::math::sampling::luminance;
use rt_core::scene::{Object, Transform};
use rt_core::{GpuScene, Material, Scene};

const SIZE: u32 = 32;
const SPP: u32 = 1024;

fn glass_cornell() -> Scene {
    let mut scene = rt_io::assets::cornell_box().unwrap();
    // Brighter walls: long paths, where roulette plays (from the fifth vertex), carry more of the
    // image, so a wrong re-weighting shows sooner.
    for object in &mut scene.objects {
        if let Material::Lambertian { albedo, .. } = &mut object.material {
            *albedo = albedo.map(|a| (a * 1.3).min(0.9));
        }
    }
    let ball = Arc::new(rt_core::shapes::uv_sphere(90.0, 24, 48));
    let at = |x: f32, y: f32, z: f32| Transform {
        translation: [x, y, z],
        ..Default::default()
    };
    scene.objects.push(Object {
        shadow_catcher: false,
        animation_node: None,
        name: "smooth glass".into(),
        mesh: ball.clone(),
        material: Material::Dielectric {
            ior: 1.5,
            tint: [1.0; 3],
        },
        transform: at(190.0, 330.0, 250.0),
    });
    scene.objects.push(Object {
        shadow_catcher: false,
        animation_node: None,
        name: "rough glass".into(),
        mesh: ball,
        material: Material::Pbr(Box::new(Pbr {
            transmission: 1.0,
            roughness: 0.3,
            ior: 1.5,
            ..Pbr::default()
        })),
        transform: at(366.0, 330.0, 250.0),
    });
    scene.settings.width = SIZE;
    scene.settings.height = SIZE;
    scene.settings.max_depth = 10;
    scene
}

/// One pixel's paired samples, in luminance.
struct PixelPairs {
    /// The mean of L_roulette − L_none and that mean's variance.
    difference: f64,
    variance: f64,
    /// The mean of L_none (the level the difference is judged against, for the message).
    without: f64,
}

/// Per pixel, L_roulette − L_none over samples paired by their random numbers (the same sample
/// index and seed: both paths agree up to the first roulette, so the difference has little
/// variance and the test is sharp).
fn paired_differences(scene: &Scene) -> Vec<PixelPairs> {
    let frame_with = |roulette: bool| {
        let mut scene = scene.clone();
        scene.settings.russian_roulette = roulette;
        let gpu = GpuScene::build(&scene).unwrap();
        let frame = rt_core::frame::frame_for(&scene, &gpu).unwrap();
        (gpu, frame)
    };
    let (gpu, with) = frame_with(true);
    let (_, without) = frame_with(false);
    (0..SIZE * SIZE)
        .into_par_iter()
        .map(|i| {
            let (x, y) = (i % SIZE, i / SIZE);
            let (mut sum, mut sum_sq, mut level) = (0.0, 0.0, 0.0);
            for s in 0..SPP {
                let plain = f64::from(luminance(radiance(&gpu, &without, x, y, s)));
                let d = f64::from(luminance(radiance(&gpu, &with, x, y, s))) - plain;
                sum += d;
                sum_sq += d * d;
                level += plain;
            }
            let n = f64::from(SPP);
            let mean = sum / n;
            PixelPairs {
                difference: mean,
                variance: (sum_sq / n - mean * mean).max(0.0) / (n - 1.0),
                without: level / n,
            }
        })
        .collect()
}

/// Over `pixels`: the mean luminance without roulette, the mean paired difference and its Z score.
fn z_score(pairs: &[PixelPairs], pixels: &[usize]) -> (f64, f64, f64) {
    let n = pixels.len() as f64;
    let sum = |f: fn(&PixelPairs) -> f64| pixels.iter().map(|&i| f(&pairs[i])).sum::<f64>();
    let mean = sum(|p| p.difference) / n;
    let var = sum(|p| p.variance) / (n * n);
    (sum(|p| p.without) / n, mean, mean / var.sqrt())
}

/// The image and the two balls' pixels keep their means with roulette.
fn assert_roulette_unbiased(scene: &Scene) {
    let differences = paired_differences(scene);
    let all: Vec<usize> = (0..(SIZE * SIZE) as usize).collect();
    // The pixels that see each ball: the camera looks down the box's axis (x = 278), the balls
    // sit 88 mm either side of it, their centres about 0.38 and 0.62 of the way across and 0.42
    // down, 3.8 pixels in radius.
    let block = |x0: u32, x1: u32| -> Vec<usize> {
        (SIZE * 3 / 10..SIZE / 2)
            .flat_map(|y| (x0..x1).map(move |x| (y * SIZE + x) as usize))
            .collect()
    };
    let regions = [
        ("image", all),
        ("one glass ball", block(SIZE * 5 / 16, SIZE * 7 / 16)),
        ("the other glass ball", block(SIZE * 9 / 16, SIZE * 11 / 16)),
    ];
    for (name, pixels) in regions {
        let (level, d, z) = z_score(&differences, &pixels);
        assert!(level > 0.0, "{name}: black");
        // |Z| < 4.5: three checks, a false alarm about once in 10⁵ runs. A roulette whose
        // survivors are re-weighted 5% too little fails it in the clear box (Z ≈ −5.3); in the
        // darker fog, 10% does (Z ≈ −7.4).
        assert!(
            z.abs() < 4.5,
            "{name}: roulette changes the mean luminance {level:.5} by {d:.2e}, Z = {z:.2}"
        );
    }
}

#[test]
fn roulette_leaves_the_image_and_the_glass_balls_unchanged() {
    assert_roulette_unbiased(&glass_cornell());
}

/// In fog a scattering is a vertex where roulette is played too (after the phase sample).
#[test]
fn roulette_in_fog_leaves_the_image_unchanged() {
    let mut scene = glass_cornell();
    // About one mean free path across the box (556 mm).
    scene.fog = rt_core::fog::Fog {
        density: 1.0 / 556.0,
        albedo: [0.9, 0.8, 0.7],
        anisotropy: 0.3,
    };
    assert_roulette_unbiased(&scene);
}
