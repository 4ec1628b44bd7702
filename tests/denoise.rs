//! The kernel's albedo/normal outputs and the À-Trous denoiser on a real render.

mod common;

use common::*;
use rt_core::GpuScene;
use rt_core::denoise::{DenoiseInput, DenoiseParams, denoise};
use rt_core::metrics::{RgbImage, compare};
use rt_gpu::{RenderOptions, Renderer};

fn render_with_aovs(
    ctx: &rt_gpu::GpuContext,
    scene: &rt_core::Scene,
) -> (rt_gpu::Image, rt_gpu::Aovs) {
    let gpu_scene = GpuScene::build(scene).unwrap();
    let options = RenderOptions {
        aovs: true,
        ..Default::default()
    };
    let mut renderer = Renderer::for_scene(ctx, scene, &gpu_scene, options).unwrap();
    renderer
        .render(scene.settings.samples_per_pixel, |_| true)
        .unwrap();
    let aovs = renderer.read_aovs().unwrap().expect("requested");
    (renderer.read_image().unwrap(), aovs)
}

/// The first-hit albedo is the material's (the floor's, at the bottom of the Cornell box), the
/// normal is unit length and faces the camera; then, at 4 spp, the denoised image is much closer to
/// a 1024-spp reference than the raw one (measured: 3.3× lower relMSE; required: 2.5×), and keeps
/// its mean within 2.5% (measured: −1.3%: the edge-stopping weights suppress rare bright samples).
#[test]
fn albedo_and_normal_outputs_guide_a_denoiser_that_cuts_the_error() {
    let Some(ctx) = gpu() else { return };
    let mut scene = rt_io::assets::cornell_box().unwrap();
    scene.settings.width = 48;
    scene.settings.height = 48;
    scene.settings.samples_per_pixel = 4;
    let (image, aovs) = render_with_aovs(ctx, &scene);
    let (albedo, normal, emission) = (&aovs.albedo, &aovs.normal, &aovs.emission);
    let floor = scene
        .objects
        .iter()
        .find(|o| o.name == "floor")
        .map(|o| match o.material {
            rt_core::Material::Lambertian { albedo, .. } => albedo,
            _ => panic!("the floor is diffuse"),
        })
        .unwrap();
    let p = 46 * 48 + 24; // bottom centre
    for c in 0..3 {
        assert!(
            (albedo[p][c] - floor[c]).abs() < 1e-4,
            "{:?} vs {floor:?}",
            albedo[p]
        );
    }
    assert!(normal[p][1] > 0.99, "the floor faces up: {:?}", normal[p]);
    for n in normal {
        let len = (n[0] * n[0] + n[1] * n[1] + n[2] * n[2]).sqrt();
        assert!(
            len <= 1.0 + 1e-4,
            "a mean of unit normals is at most unit length"
        );
    }

    let variance = rt_core::output::pixel_variance(&image.pixels, image.counts());
    let color = image.rgb();
    let denoised = denoise(
        &DenoiseInput {
            width: 48,
            height: 48,
            color: &color,
            emission,
            albedo,
            normal,
            variance: &variance,
        },
        &DenoiseParams::default(),
    )
    .unwrap();
    scene.settings.samples_per_pixel = 1024;
    scene.settings.seed = 77;
    let reference = render(ctx, &scene);
    let as_image = |pixels: Vec<[f32; 3]>| RgbImage {
        width: 48,
        height: 48,
        pixels,
    };
    let reference = as_image(reference.rgb());
    let raw = compare(&as_image(color.clone()), &reference).unwrap();
    let filtered = compare(&as_image(denoised), &reference).unwrap();
    assert!(
        filtered.rel_mse < raw.rel_mse / 2.5,
        "denoised relMSE {:.3e} vs raw {:.3e}",
        filtered.rel_mse,
        raw.rel_mse
    );
    for c in 0..3 {
        assert!(
            (filtered.mean_ratio[c] - 1.0).abs() < 0.025,
            "the denoiser moved the mean: {:?}",
            filtered.mean_ratio
        );
    }
}

/// At 16 spp on the Cornell box, both denoisers cut the relMSE against a 1024-spp reference, and
/// Open Image Denoise more than À-Trous (OIDN is required under CI, where scripts/test installs it;
/// elsewhere without it only À-Trous is checked, and the test says so). Measured on lavapipe at
/// 64²: raw 1.48e-2, À-Trous 6.9e-3 (required: under raw/1.6), OIDN 2.5e-3 (required: under
/// À-Trous).
#[test]
fn oidn_and_atrous_both_cut_the_error_at_16_spp_and_oidn_more() {
    use rt_core::denoiser::{Denoiser, DenoiserChoice};
    let Some(ctx) = gpu() else { return };
    let mut scene = rt_io::assets::cornell_box().unwrap();
    scene.settings.width = 64;
    scene.settings.height = 64;
    scene.settings.samples_per_pixel = 16;
    let (image, aovs) = render_with_aovs(ctx, &scene);
    scene.settings.samples_per_pixel = 1024;
    scene.settings.seed = 77;
    let reference = render(ctx, &scene);
    let as_image = |pixels: Vec<[f32; 3]>| RgbImage {
        width: 64,
        height: 64,
        pixels,
    };
    let reference = as_image(reference.rgb());
    let raw = compare(&as_image(image.rgb()), &reference).unwrap().rel_mse;
    let atrous = image.denoised(&aovs, DenoiserChoice::Atrous).unwrap();
    assert_eq!(atrous.denoiser, Denoiser::Atrous);
    let atrous = compare(&as_image(atrous.pixels), &reference)
        .unwrap()
        .rel_mse;
    eprintln!("16 spp relMSE: raw {raw:.3e}, À-Trous {atrous:.3e}");
    assert!(atrous < raw / 1.6, "À-Trous {atrous:.3e} vs raw {raw:.3e}");
    let oidn = match image.denoised(&aovs, DenoiserChoice::Oidn) {
        Ok(denoised) => denoised,
        Err(e) if std::env::var_os("CI").is_some() => {
            panic!("CI is set but Open Image Denoise did not run: {e}")
        }
        Err(e) => {
            eprintln!("SKIPPED the OIDN half: {e}");
            return;
        }
    };
    assert_eq!(oidn.denoiser, Denoiser::Oidn);
    let oidn = compare(&as_image(oidn.pixels), &reference).unwrap().rel_mse;
    eprintln!("16 spp relMSE: OIDN {oidn:.3e}");
    assert!(oidn < atrous, "OIDN {oidn:.3e} vs À-Trous {atrous:.3e}");
}
