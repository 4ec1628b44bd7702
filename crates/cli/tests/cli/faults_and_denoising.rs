//! Device faults mid-render save what was read back; denoising and its fallbacks.

use super::*;

/// Runs a long render with the fault injected by `fault_env` after two batches; rt-cli must exit 2
/// with an error containing `says` and save the samples it had read back before to `file`.
fn fault_mid_render_saves_the_samples_read_back_before(fault_env: &str, says: &str, file: &str) {
    if !has_gpu() {
        return;
    }
    let dir = temp_dir(fault_env);
    let out = dir.join(file);
    let output = std::process::Command::new(env!("CARGO_BIN_EXE_rt-cli"))
        .args([
            "render", "--device", "gpu", "--width", "24", "--height", "24", "--spp", "100000", "-o",
        ])
        .arg(&out)
        .env(fault_env, "2")
        .output()
        .unwrap();
    let stderr = String::from_utf8_lossy(&output.stderr);
    assert_eq!(output.status.code(), Some(2), "{stderr}");
    assert!(
        stderr.contains(says) && stderr.contains("were saved to"),
        "{stderr}"
    );
    assert!(!stderr.contains("panicked"), "{stderr}");
    let (w, h) = image::image_dimensions(&out).unwrap();
    assert_eq!((w, h), (24, 24));
    std::fs::remove_dir_all(&dir).unwrap();
}

/// When the GPU is lost mid-render (injected: the device is destroyed after two batches), rt-cli
/// exits with an error that says so and saves the samples it had read back before.
#[test]
fn a_device_lost_mid_render_saves_the_samples_read_back_before() {
    fault_mid_render_saves_the_samples_read_back_before(
        "RT_FAULT_LOSE_DEVICE_AFTER_BATCHES",
        "device was lost",
        "partial.exr",
    );
}

/// Out of memory mid-render (injected: the GPU operation after two batches fails as an allocation
/// would): rt-cli says so, exits 2 and saves the samples it had read back before.
#[test]
fn out_of_memory_mid_render_saves_the_samples_read_back_before() {
    fault_mid_render_saves_the_samples_read_back_before(
        "RT_FAULT_OUT_OF_MEMORY_AFTER_BATCHES",
        "ran out of memory",
        "partial.png",
    );
}

/// `--denoise` writes a denoised copy beside the raw output, which stays as rendered.
#[test]
fn denoise_writes_a_second_image_and_keeps_the_raw_one() {
    if !has_gpu() {
        return;
    }
    let dir = temp_dir("denoise");
    let out = dir.join("img.exr");
    let (code, stderr) = render_cornell(32, 32, 4, &out, &["--denoise"]);
    assert_eq!(code, 0, "{stderr}");
    let raw = image::open(&out).unwrap().to_rgb32f();
    let denoised = image::open(dir.join("img.denoised.exr"))
        .unwrap()
        .to_rgb32f();
    assert_eq!(raw.dimensions(), denoised.dimensions());
    // Smoother: the denoised image varies less from pixel to pixel.
    let roughness = |img: &image::Rgb32FImage| {
        img.pixels()
            .zip(img.pixels().skip(1))
            .map(|(a, b)| f64::from((a.0[1] - b.0[1]).abs().min(1.0)))
            .sum::<f64>()
    };
    assert!(
        roughness(&denoised) < roughness(&raw) * 0.8,
        "{} vs {}",
        roughness(&denoised),
        roughness(&raw)
    );
    std::fs::remove_dir_all(&dir).unwrap();
}

/// `--denoise` says which denoiser ran. With a corrupt OIDN library (`RT_OIDN_LIBRARY`), a bare
/// `--denoise` falls back to À-Trous, naming the file and why, and still writes the image;
/// `--denoise=oidn` fails with that message and writes no denoised image.
#[test]
fn a_corrupt_oidn_library_falls_back_or_fails_as_asked() {
    if !has_gpu() {
        return;
    }
    let dir = temp_dir("oidn-corrupt");
    let library = dir.join("libOpenImageDenoise.so.1");
    std::fs::write(&library, b"not a shared library").unwrap();
    let library = library.to_str().unwrap();
    let out = dir.join("img.png");
    let env = [("RT_OIDN_LIBRARY", library)];
    let (code, stderr) = render_cornell_with_env(16, 16, 2, &out, &["--denoise"], &env);
    assert_eq!(code, 0, "{stderr}");
    assert!(
        stderr.contains("À-Trous, since") && stderr.contains(library),
        "{stderr}"
    );
    assert!(dir.join("img.denoised.png").exists());
    std::fs::remove_file(dir.join("img.denoised.png")).unwrap();
    let (code, stderr) = render_cornell_with_env(16, 16, 2, &out, &["--denoise=oidn"], &env);
    assert_ne!(code, 0);
    assert!(stderr.contains(library), "{stderr}");
    assert!(!dir.join("img.denoised.png").exists());
    let (code, stderr) = render_cornell(16, 16, 2, &out, &["--denoise=atrous"]);
    assert_eq!(code, 0, "{stderr}");
    assert!(stderr.contains("(À-Trous,"), "{stderr}");
    std::fs::remove_dir_all(&dir).unwrap();
}

/// `--denoise` at 2560x1440: the accumulation (16 bytes a pixel) fits one binding on lavapipe but
/// the denoiser's guides and first hits (64 bytes a pixel, 236 MB) do not, so the render must be tiled by the
/// guides' size (it once failed with "the albedo, normal, emission buffer needs 176947200 bytes").
/// The tiled render is the untiled one (rendered without the guides) bit for bit, and its denoised
/// copy covers the whole frame.
#[test]
fn denoising_works_where_the_guides_exceed_one_binding() {
    if !has_gpu() {
        return;
    }
    let dir = temp_dir("denoise-big");
    let (denoised_out, plain_out) = (dir.join("denoised.png"), dir.join("plain.png"));
    let flags = ["--max-depth", "2", "--denoise=atrous"];
    let (code, stderr) = render_cornell(2560, 1440, 1, &denoised_out, &flags);
    assert_eq!(code, 0, "{stderr}");
    let (code, plain_log) = render_cornell(2560, 1440, 1, &plain_out, &flags[..2]);
    assert_eq!(code, 0, "{plain_log}");
    assert!(
        std::fs::read(&denoised_out).unwrap() == std::fs::read(&plain_out).unwrap(),
        "the render kept for denoising differs from the plain one:\n{stderr}\n{plain_log}"
    );
    let denoised = image::open(dir.join("denoised.denoised.png")).unwrap();
    assert_eq!((denoised.width(), denoised.height()), (2560, 1440));
    // The lit box fills the frame's middle: every band of rows there has lit pixels.
    let rgb = denoised.to_rgb8();
    for band in 1..7 {
        let lit = (band * 180..(band + 1) * 180)
            .flat_map(|y| (0..2560).map(move |x| (x, y)))
            .filter(|&(x, y)| rgb.get_pixel(x, y).0.iter().any(|&c| c > 16))
            .count();
        assert!(
            lit > 180 * 256,
            "rows of band {band}: {lit} lit pixels\n{stderr}"
        );
    }
    std::fs::remove_dir_all(&dir).unwrap();
}
