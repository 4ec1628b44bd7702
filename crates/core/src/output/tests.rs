use super::*;

/// The variance channel holds s²/n of luminance, and readers that want RGB (the `image` crate,
/// `RgbImage::load`) still read the colour.
#[test]
fn exr_renders_carry_a_variance_channel() {
    // Two pixels after 4 samples: luminance mean 0.5 with mean square 0.5 (s² = 1/3 after
    // Bessel), and a constant pixel (variance 0).
    let pixels = [[0.5, 0.5, 0.5, 0.5], [0.2, 0.2, 0.2, 0.04]];
    let bytes = encode_exr_with_variance(2, 1, &pixels, SampleCounts::Uniform(4)).unwrap();
    let dir = std::env::temp_dir().join(format!("rt-exr-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let path = dir.join("v.exr");
    std::fs::write(&path, &bytes).unwrap();
    let rgb = crate::metrics::RgbImage::load(&path).unwrap();
    assert_eq!(rgb.pixels[0], [0.5, 0.5, 0.5]);
    let image = exr::prelude::read_all_flat_layers_from_file(&path).unwrap();
    let channels = &image.layer_data[0].channel_data.list;
    let variance = channels
        .iter()
        .find(|c| c.name.to_string() == "variance.Y")
        .expect("variance channel");
    let values: Vec<f32> = variance.sample_data.values_as_f32().collect();
    assert!(
        (values[0] - (0.25 * 4.0 / 3.0) / 4.0).abs() < 1e-6,
        "{values:?}"
    );
    assert!(values[1].abs() < 1e-6);
    assert!(
        !channels.iter().any(|c| c.name.to_string() == "samples.Y"),
        "no count channel without per-pixel counts"
    );
    std::fs::remove_dir_all(&dir).unwrap();
}

/// With adaptive sampling's per-pixel counts, the variance uses each pixel's own count and a
/// `samples.Y` channel holds the counts exactly.
#[test]
fn exr_renders_carry_per_pixel_sample_counts() {
    let pixels = [[0.5, 0.5, 0.5, 0.5], [0.5, 0.5, 0.5, 0.5]];
    let counts = [4u32, 16_777_217];
    let bytes = encode_exr_with_variance(2, 1, &pixels, SampleCounts::PerPixel(&counts));
    let dir = std::env::temp_dir().join(format!("rt-exr-counts-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let path = dir.join("c.exr");
    std::fs::write(&path, bytes.unwrap()).unwrap();
    let image = exr::prelude::read_all_flat_layers_from_file(&path).unwrap();
    let channels = &image.layer_data[0].channel_data.list;
    let channel = |name: &str| {
        channels
            .iter()
            .find(|c| c.name.to_string() == name)
            .unwrap_or_else(|| panic!("no {name} channel"))
    };
    match &channel("samples.Y").sample_data {
        exr::prelude::FlatSamples::U32(values) => assert_eq!(values, &counts),
        other => panic!("samples.Y is not u32: {other:?}"),
    }
    let variance: Vec<f32> = channel("variance.Y").sample_data.values_as_f32().collect();
    let expected = |n: f64| (0.25 * n / (n - 1.0) / n) as f32;
    assert!((variance[0] - expected(4.0)).abs() < 1e-7, "{variance:?}");
    assert!(
        (variance[1] - expected(16_777_217.0)).abs() < 1e-12,
        "{variance:?}"
    );
    std::fs::remove_dir_all(&dir).unwrap();
}

/// PBR Neutral keeps dark and mid colours (minus its small black offset), keeps hue, rolls
/// highlights off below 1 without clipping, and is monotonic.
#[test]
fn khronos_pbr_neutral_keeps_midtones_and_compresses_highlights() {
    let mid = khronos_pbr_neutral([0.5, 0.3, 0.2]);
    for (a, b) in mid.iter().zip([0.46, 0.26, 0.16]) {
        assert!((a - b).abs() < 1e-6, "{mid:?}");
    }
    let mut last = 0.0;
    for i in 1..200 {
        let v = khronos_pbr_neutral([i as f32 * 0.1; 3])[0];
        assert!(v >= last && v < 1.0, "{} -> {v}", i as f32 * 0.1);
        last = v;
    }
    assert!(last > 0.98, "bright white approaches 1: {last}");
    let bright = View {
        transform: ViewTransform::KhronosPbrNeutral,
        ..View::default()
    }
    .to_srgb8([4.0, 2.0, 1.0]);
    let clamped = View::from(0.0).to_srgb8([4.0, 2.0, 1.0]);
    assert_eq!(clamped, [255, 255, 255]);
    assert!(bright[0] > bright[1] && bright[1] > bright[2], "{bright:?}");
}

#[test]
fn srgb_encoding_endpoints_and_exposure() {
    assert_eq!(tone_map_u8(0.0, 0.0), 0);
    assert_eq!(tone_map_u8(1.0, 0.0), 255);
    assert_eq!(tone_map_u8(5.0, 0.0), 255, "clamped");
    assert_eq!(tone_map_u8(0.5, 1.0), 255, "+1 stop doubles");
    assert_eq!(
        tone_map_u8(0.215_861, 0.0),
        128,
        "sRGB 128 is linear 0.2159"
    );
}

#[test]
fn every_format_round_trips_through_a_file() {
    let dir = std::env::temp_dir().join(format!("rt-output-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let rgb = vec![[0.25f32, 0.5, 1.0]; 6];
    for ext in ["png", "jpg", "ppm", "exr"] {
        let path = dir.join(format!("img.{ext}"));
        save_image(&path, 3, 2, &rgb, 0.0).unwrap();
        let img = image::open(&path).unwrap();
        assert_eq!((img.width(), img.height()), (3, 2), "{ext}");
        if ext == "exr" {
            let px = img.to_rgb32f().get_pixel(1, 1).0;
            assert_eq!(px, [0.25, 0.5, 1.0], "EXR keeps linear floats");
        }
    }
    assert!(save_image(&dir.join("img.bmp"), 3, 2, &rgb, 0.0).is_err());
    std::fs::remove_dir_all(&dir).unwrap();
}
