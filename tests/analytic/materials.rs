//! PBR furnaces, normal maps, texture wrap modes and filters, alpha masks and blending.

use super::*;

/// Renders a white PBR sphere under a uniform white environment (importance-sampled, with MIS)
/// and returns, per pixel, (mean, standard error) of the red channel.
fn pbr_furnace(ctx: &rt_gpu::GpuContext, p: rt_core::material::Pbr, spp: u32) -> Vec<(f64, f64)> {
    let mut sphere = uv_sphere(1.0, 24, 48);
    sphere.normals = None;
    let mut scene = scene(
        vec![object("sphere", sphere, pbr(p))],
        camera(Vec3::new(0.0, 0.0, 4.0), Vec3::ZERO, 24.0),
        [0.0; 3],
        settings(16, 16, spp, 64),
    );
    scene.environment = Some(rt_core::Environment::new(
        "white",
        rt_core::EnvironmentMap::uniform([1.0; 3]),
    ));
    let image = render(ctx, &scene);
    image
        .pixels
        .iter()
        .map(|px| {
            let mean = f64::from(px[0]);
            // The fourth channel is the running mean of squared luminance (= red², all white).
            let var =
                (f64::from(px[3]) - mean * mean).max(0.0) * f64::from(spp) / f64::from(spp - 1);
            (mean, (var / f64::from(spp)).sqrt())
        })
        .collect()
}

/// White furnace on the GPU: a white rough metal sphere keeps ≥ 0.9 of the light at roughness
/// {0, 0.1, 0.5, 1} and never more than 1; a white glass sphere (with its internal bounces) keeps
/// ≥ 0.98 at every roughness (rough glass's multiple-scattering compensation) and never more than
/// 1 beyond its table's 0.6% interpolation error. Per pixel within z·σ (Šidák over all pixels and
/// cases).
#[test]
fn pbr_spheres_under_a_white_environment_conserve_energy() {
    use rt_core::material::Pbr;
    let Some(ctx) = gpu() else { return };
    let spp = 256;
    let z = z_threshold(1.0 - (1.0 - 1e-3f64).powf(1.0 / (256.0 * 8.0)));
    for roughness in [0.0, 0.1, 0.5, 1.0] {
        let metal = Pbr {
            base_color: [1.0; 3],
            metallic: 1.0,
            roughness,
            ..Default::default()
        };
        let glass = Pbr {
            base_color: [1.0; 3],
            roughness,
            transmission: 1.0,
            ..Default::default()
        };
        for (what, p, floor) in [("metal", metal, 0.9), ("glass", glass, 0.98)] {
            let ceiling = if what == "glass" { 1.006 } else { 1.001 };
            let pixels = pbr_furnace(ctx, p, spp);
            // The whole image too, where the standard error is small enough to see 2%.
            let n = pixels.len() as f64;
            let mean = pixels.iter().map(|p| p.0).sum::<f64>() / n;
            let se = pixels.iter().map(|p| p.1 * p.1).sum::<f64>().sqrt() / n;
            eprintln!("{what}, roughness {roughness}: the image keeps {mean:.4} ± {se:.4}");
            assert!(
                mean <= ceiling + z * se && mean >= floor - z * se,
                "{what}, roughness {roughness}: the image keeps {mean:.4} ± {se:.4}"
            );
            for (i, (mean, se)) in pixels.into_iter().enumerate() {
                assert!(
                    mean <= ceiling + z * se && mean >= floor - z * se - 1e-3,
                    "{what}, roughness {roughness}: pixel {i} is {mean:.4} ± {se:.4} \
                     (should lie in [{floor}, 1])"
                );
            }
        }
    }
}

/// A normal map tilts the shading normal exactly as its texels say, about MikkTSpace's tangent:
/// a plane whose u runs along +x, mapped to the normal n = (sin θ, 0, cos θ) in tangent space (one
/// 8-bit texel), under a sun tilted φ towards +x, has radiance ρ/π · E · (n·l) with n·l computed
/// from the decoded texel — cos(θ − φ) up to 8-bit rounding. A PBR dielectric of IOR 1 has no
/// specular layer (F = 0), so it is exactly Lambertian. Without the map, cos φ.
#[test]
fn a_normal_map_tilts_the_lambert_cosine_exactly() {
    use rt_core::material::Pbr;
    let Some(ctx) = gpu() else { return };
    let (theta, phi) = (20f32.to_radians(), 35f32.to_radians());
    let byte = |v: f32| ((v * 0.5 + 0.5) * 255.0).round() as u8;
    let texel = [byte(theta.sin()), 128, byte(theta.cos()), 255];
    let mut plane = quad(Vec3::ZERO, Vec3::Y, 100.0);
    plane.normals = Some(vec![Vec3::Y; 4]);
    plane.uvs = Some(
        plane
            .positions
            .iter()
            .map(|p| glam::Vec2::new(p.x / 100.0 + 0.5, -p.z / 100.0 + 0.5))
            .collect(),
    );
    let material = |normal_texture| {
        pbr(Pbr {
            base_color: [0.5; 3],
            ior: 1.0,
            roughness: 1.0,
            normal_texture,
            ..Default::default()
        })
    };
    let mut sun = rt_core::Light::new(rt_core::LightKind::Directional, "sun");
    sun.direction = [-phi.sin(), -phi.cos(), 0.0];
    sun.intensity = 2.0;
    let mut s = scene(
        vec![object("plane", plane, material(Some(0)))],
        camera(Vec3::new(0.0, 5.0, 0.001), Vec3::ZERO, 20.0),
        [0.0; 3],
        settings(8, 8, 2, 2),
    );
    s.textures.push(rt_core::Texture {
        sampler: Default::default(),
        name: "tilt".into(),
        width: 1,
        height: 1,
        rgba8: texel.to_vec().into(),
    });
    s.lights.push(sun);
    let m = Vec3::new(texel[0] as f32, texel[1] as f32, texel[2] as f32) / 255.0 * 2.0 - Vec3::ONE;
    // Tangent +x, bitangent −z (where v grows), normal +y.
    let n = Vec3::new(m.x, m.z, -m.y).normalize();
    let l = Vec3::new(phi.sin(), phi.cos(), 0.0);
    let expected = 0.5 / std::f32::consts::PI * 2.0 * n.dot(l);
    assert!((n.dot(l) - (theta - phi).cos()).abs() < 0.01);
    assert_all_pixels(&render(ctx, &s), [expected; 3], 1e-5, "normal-mapped plane");
    s.objects[0].material = material(None);
    let flat = 0.5 / std::f32::consts::PI * 2.0 * phi.cos();
    assert_all_pixels(&render(ctx, &s), [flat; 3], 1e-5, "the same plane unmapped");
}

/// A square facing the camera at the origin from z = −1, a bit wider than a 60° view, with `u`
/// running 0..`u_max` from left to right and v = ½.
fn view_filling_square(z: f32, u_max: f32) -> rt_core::Mesh {
    let h = (30f32).to_radians().tan() * -z * 1.0001;
    let positions = [(-h, -h), (h, -h), (h, h), (-h, h)]
        .map(|(x, y)| Vec3::new(x, y, z))
        .to_vec();
    rt_core::Mesh {
        positions,
        normals: None,
        uvs: Some(
            [0.0, u_max, u_max, 0.0]
                .map(|u| glam::Vec2::new(u, 0.5))
                .to_vec(),
        ),
        colors: None,
        indices: vec![[0, 1, 2], [0, 2, 3]],
    }
}

/// Mean of `channel` over image columns `cols` (all rows).
fn column_mean(image: &rt_gpu::Image, cols: std::ops::Range<usize>, channel: usize) -> Vec<f32> {
    let w = image.width as usize;
    cols.map(|x| {
        let col: Vec<f32> = image
            .pixels
            .iter()
            .skip(x)
            .step_by(w)
            .map(|p| p[channel])
            .collect();
        col.iter().sum::<f32>() / col.len() as f32
    })
    .collect()
}

/// A 2×1 emission image (white | black) read with the nearest filter across u ∈ [0, 2], seen head
/// on: repeat tiles it (white, black, white, black by quarters), mirrored repeat mirrors the second
/// copy (white, black, black, white), clamp extends the edge (white, black, black, black). Exact.
#[test]
fn wrap_modes_and_the_nearest_filter_tile_an_emission_image_exactly() {
    use rt_core::material::Pbr;
    use rt_core::{Filter, TextureSampler, Wrap};
    let Some(ctx) = gpu() else { return };
    let mut s = scene(
        vec![object(
            "panel",
            view_filling_square(-1.0, 2.0),
            pbr(Pbr {
                base_color: [0.0; 3],
                emission: [1.0, 2.0, 3.0],
                emission_texture: Some(0),
                ..Default::default()
            }),
        )],
        camera(Vec3::ZERO, Vec3::new(0.0, 0.0, -1.0), 60.0),
        [0.0; 3],
        settings(16, 16, 4, 1),
    );
    for (wrap, quarters) in [
        (Wrap::Repeat, [1.0, 0.0, 1.0, 0.0]),
        (Wrap::MirroredRepeat, [1.0, 0.0, 0.0, 1.0]),
        (Wrap::ClampToEdge, [1.0, 0.0, 0.0, 0.0]),
    ] {
        s.textures = vec![rt_core::Texture {
            name: "white | black".into(),
            width: 2,
            height: 1,
            rgba8: vec![255, 255, 255, 255, 0, 0, 0, 255].into(),
            sampler: TextureSampler {
                wrap_s: wrap,
                wrap_t: wrap,
                filter: Filter::Nearest,
            },
        }];
        let image = render(ctx, &s);
        for (q, expected) in quarters.iter().enumerate() {
            // The two middle columns of each quarter (the edges fall between pixels).
            let cols = q * 4 + 1..q * 4 + 3;
            for (ch, scale) in [1.0f32, 2.0, 3.0].iter().enumerate() {
                for m in column_mean(&image, cols.clone(), ch) {
                    assert!(
                        (m - expected * scale).abs() < 1e-5,
                        "{wrap:?}: quarter {q} channel {ch} is {m}, expected {}",
                        expected * scale
                    );
                }
            }
        }
    }
}

/// A black square in front of a lens-filling emitter of radiance 2. Masked by an image whose
/// alpha is 0 on the left half and 1 on the right, the left half shows the emitter exactly and the
/// right half is black. Blended at α = ¼, each pixel shows (1 − ¼)·2 = 1.5 on average: the image
/// mean is tested against its standard error from the pixels' spread.
#[test]
fn an_alpha_mask_cuts_exact_holes_and_blending_lets_one_minus_alpha_through() {
    use rt_core::material::{AlphaMode, Pbr};
    use rt_core::{Filter, TextureSampler, Wrap};
    let Some(ctx) = gpu() else { return };
    let screen = |alpha_mode, alpha, texture| {
        pbr(Pbr {
            base_color: [0.0; 3],
            texture,
            alpha_mode,
            alpha,
            ..Default::default()
        })
    };
    let mut s = scene(
        vec![
            object(
                "emitter",
                quad(Vec3::new(0.0, 0.0, -2.0), Vec3::Z, 100.0),
                Material::Emissive {
                    color: [1.0; 3],
                    intensity: 2.0,
                },
            ),
            object(
                "screen",
                view_filling_square(-1.0, 1.0),
                screen(AlphaMode::Mask, 1.0, Some(0)),
            ),
        ],
        camera(Vec3::ZERO, Vec3::new(0.0, 0.0, -1.0), 60.0),
        [0.0; 3],
        settings(16, 16, 4, 2),
    );
    s.textures.push(rt_core::Texture {
        name: "hole | solid".into(),
        width: 2,
        height: 1,
        rgba8: vec![255, 255, 255, 0, 255, 255, 255, 255].into(),
        sampler: TextureSampler {
            wrap_s: Wrap::ClampToEdge,
            wrap_t: Wrap::ClampToEdge,
            filter: Filter::Nearest,
        },
    });
    let image = render(ctx, &s);
    for (x, m) in column_mean(&image, 0..16, 0).iter().enumerate() {
        let expected = if x < 8 { 2.0 } else { 0.0 };
        if x != 7 && x != 8 {
            assert!(
                (m - expected).abs() < 1e-5,
                "mask: column {x} is {m}, expected {expected}"
            );
        }
    }
    // Opaque mode ignores the same image's alpha.
    s.objects[1].material = screen(AlphaMode::Opaque, 1.0, Some(0));
    assert_all_pixels(&render(ctx, &s), [0.0; 3], 1e-6, "opaque screen");

    s.objects[1].material = screen(AlphaMode::Blend, 0.25, None);
    s.settings.samples_per_pixel = 64;
    s.settings.width = 32;
    s.settings.height = 32;
    // Through rt's BVH, and through the driver's ray queries where the adapter has them.
    let mut traces = vec![rt_gpu::Trace::Bvh];
    if ctx.has_ray_queries() {
        traces.push(rt_gpu::Trace::Hardware);
    }
    let gpu_scene = GpuScene::build(&s).unwrap();
    for trace in traces {
        let options = RenderOptions {
            trace,
            ..Default::default()
        };
        let image = render_gpu(ctx, &s, &gpu_scene, options);
        let (mean, error) = pixel_mean_and_error(&image);
        // Each sample is 0 or 2: a pixel of 64 has σ = 2·√(¼·¾/64) ≈ 0.108, the image mean
        // ≈ 0.0034.
        assert!(
            error > 0.001 && error < 0.01,
            "{trace:?}: standard error {error}"
        );
        assert!(
            (mean - 1.5).abs() < 4.0 * error,
            "{trace:?}: blend at alpha 0.25: mean {mean} ± {error}, expected 1.5"
        );
    }
}

/// A glass wedge of index 1.5 in front of a bright half-plane: the camera sees the half-plane's
/// edge displaced by refraction. Tracing the centre row's camera rays through the wedge by Snell's
/// law (in 2D, independently of rt) predicts the column of the edge for each channel's index; with
/// `KHR_materials_dispersion` (20 / V_d = 2: n = 1.494 at 612 nm, 1.545 at 465 nm) the red and
/// blue edges part by several pixels, each where Snell's law puts it (within 0.6 pixels, measured
/// from the channel's step integrated over the columns around the edge, which averages the hero
/// channel's noise), and without dispersion all channels share one edge.
#[test]
fn a_prism_splits_white_light() {
    use rt_core::math::dispersion::{CHANNEL_WAVELENGTHS, ior_at};
    let Some(ctx) = gpu() else { return };
    let (width, height, vfov) = (128u32, 16u32, 2.0f32);
    // The wedge: cross-section (−3, −2.5), (3, −2.5), (3, −4.5) in (x, z), extruded along y.
    let section = [
        glam::Vec2::new(-3.0, -2.5),
        glam::Vec2::new(3.0, -2.5),
        glam::Vec2::new(3.0, -4.5),
    ];
    let emitter_z = -10.0;
    // Where a centre-row camera ray through the image's horizontal coordinate `s` (pixel i spans
    // [i, i + 1]) lands on the emitter's plane (x), for index n: Snell at the front face
    // (z = −2.5) and at the slanted back face.
    let refract2 = |d: glam::Vec2, n: glam::Vec2, eta: f32| {
        let c = -d.dot(n);
        let k = 1.0 - eta * eta * (1.0 - c * c);
        (eta * d + (eta * c - k.sqrt()) * n).normalize()
    };
    let landing = |s: f32, ior: f32| {
        let tan_half = (vfov.to_radians() * 0.5).tan() * width as f32 / height as f32;
        let sx = (2.0 * s / width as f32 - 1.0) * tan_half;
        let d = glam::Vec2::new(sx, -1.0).normalize();
        let p = d * (-2.5 / d.y);
        let d = refract2(d, glam::Vec2::Y, 1.0 / ior);
        let (a, b) = (section[0], section[2]);
        let edge = b - a;
        let outward = glam::Vec2::new(edge.y, -edge.x).normalize();
        let outward = if outward.dot(section[1] - a) > 0.0 {
            -outward
        } else {
            outward
        };
        let t = (a - p).dot(outward) / d.dot(outward);
        let q = p + d * t;
        let d = refract2(d, -outward, ior);
        (q + d * ((emitter_z - q.y) / d.y)).x
    };
    // The half-plane's edge lies where the central column's ray lands at index 1.5.
    let edge_x = landing(width as f32 * 0.5, 1.5);
    // The coordinate whose ray lands on the edge (bisection: the landing point grows with s).
    let predicted_column = |ior: f32| {
        let (mut lo, mut hi) = (0.0f32, width as f32);
        for _ in 0..40 {
            let mid = 0.5 * (lo + hi);
            if landing(mid, ior) < edge_x {
                lo = mid;
            } else {
                hi = mid;
            }
        }
        lo
    };
    let mut wedge = rt_core::Mesh {
        positions: Vec::new(),
        normals: None,
        uvs: None,
        colors: None,
        indices: Vec::new(),
    };
    for y in [-3.0, 3.0] {
        for p in section {
            wedge.positions.push(Vec3::new(p.x, y, p.y));
        }
    }
    let centre = Vec3::new(1.0, 0.0, -3.1667);
    for [a, b, c] in [
        [0u32, 1, 2],
        [3, 4, 5],
        [0, 1, 4],
        [0, 4, 3],
        [1, 2, 5],
        [1, 5, 4],
        [2, 0, 3],
        [2, 3, 5],
    ] {
        let p = |k: u32| wedge.positions[k as usize];
        let n = (p(b) - p(a)).cross(p(c) - p(a));
        let outwards = n.dot((p(a) + p(b) + p(c)) / 3.0 - centre) > 0.0;
        wedge
            .indices
            .push(if outwards { [a, b, c] } else { [a, c, b] });
    }
    let half_plane = quad(Vec3::new(edge_x - 25.0, 0.0, emitter_z), Vec3::Z, 50.0);
    for dispersion in [0.0f32, 2.0] {
        let scene = scene(
            vec![
                object(
                    "wedge",
                    wedge.clone(),
                    pbr(rt_core::material::Pbr {
                        base_color: [1.0; 3],
                        roughness: 0.0,
                        transmission: 1.0,
                        ior: 1.5,
                        dispersion,
                        ..Default::default()
                    }),
                ),
                object(
                    "half-plane",
                    half_plane.clone(),
                    Material::Emissive {
                        color: [1.0; 3],
                        intensity: 1.0,
                    },
                ),
            ],
            camera(Vec3::ZERO, Vec3::new(0.0, 0.0, -1.0), vfov),
            [0.0; 3],
            settings(width, height, 256, 8),
        );
        let image = render(ctx, &scene);
        // The edge's coordinate per channel: from column `start`, well left of every edge, to
        // `end`, well right of them (and left of the faint image the wedge's side face reflects
        // into the last columns), the step integrated over the centre rows, each divided by its
        // plateau just left of `start` (near the edge: the wedge's transmittance drifts slowly
        // across the image).
        let rows = [height / 2 - 2, height / 2 - 1, height / 2, height / 2 + 1];
        let (start, end) = (40usize, 96usize);
        let measured = |c: usize| {
            let mut total = 0.0;
            for &y in &rows {
                let row = &image.pixels[(y * width) as usize..((y + 1) * width) as usize];
                let plateau = row[start - 12..start].iter().map(|p| p[c]).sum::<f32>() / 12.0;
                total += row[start..end].iter().map(|p| p[c] / plateau).sum::<f32>();
            }
            start as f32 + total / rows.len() as f32
        };
        let (red, blue) = (measured(0), measured(2));
        let n = |k: usize| ior_at(1.5, dispersion, CHANNEL_WAVELENGTHS[k]);
        let (want_red, want_blue) = (predicted_column(n(0)), predicted_column(n(2)));
        eprintln!(
            "dispersion {dispersion}: red edge at {red:.2} (Snell {want_red:.2}), blue at \
             {blue:.2} (Snell {want_blue:.2})"
        );
        assert!(
            (red - want_red).abs() <= 0.6 && (blue - want_blue).abs() <= 0.6,
            "dispersion {dispersion}: edges at {red:.2} / {blue:.2}, Snell says {want_red:.2} / \
             {want_blue:.2}"
        );
        if dispersion > 0.0 {
            assert!(
                (red - blue).abs() >= 3.0,
                "the prism parts red and blue by {:.2} columns",
                red - blue
            );
        } else {
            assert!(
                (red - blue).abs() <= 0.5,
                "no dispersion: {red:.2} vs {blue:.2}"
            );
        }
    }
}

/// `KHR_materials_diffuse_transmission` against its formula: a thin sheet without a specular layer
/// (specular 0, so Fresnel is 0) is mix(diffuse_brdf(base), diffuse_btdf(dtColor), dt). Under a
/// sun of irradiance E at 60°, seen from the lit side it has radiance (1 − dt)·base/π · E cos60°,
/// from the far side dt·dtColor/π · E cos60°: exactly (a delta light, one sample per pixel).
#[test]
fn a_diffuse_transmitting_sheet_follows_the_gltf_formula() {
    let Some(ctx) = gpu() else { return };
    let angle = 60f32.to_radians();
    let mut sun = rt_core::Light::new(rt_core::LightKind::Directional, "sun");
    sun.direction = [angle.sin(), -angle.cos(), 0.0];
    sun.intensity = 3.0;
    let (dt, base, color) = (0.6, [0.2, 0.4, 0.8], [1.0, 0.5, 0.25]);
    let sheet = pbr(rt_core::material::Pbr {
        base_color: base,
        roughness: 1.0,
        specular: 0.0,
        diffuse_transmission: dt,
        diffuse_transmission_color: color,
        thin_walled: true,
        ..Default::default()
    });
    let e = 3.0 * angle.cos() / std::f32::consts::PI;
    for (from, expected) in [
        (Vec3::new(0.0, 5.0, 0.001), base.map(|b| (1.0 - dt) * b * e)),
        (Vec3::new(0.0, -5.0, 0.001), color.map(|c| dt * c * e)),
    ] {
        let mut s = scene(
            vec![object(
                "sheet",
                quad(Vec3::ZERO, Vec3::Y, 100.0),
                sheet.clone(),
            )],
            camera(from, Vec3::ZERO, 30.0),
            [0.0; 3],
            settings(8, 8, 4, 2),
        );
        s.lights.push(sun.clone());
        let what = if from.y > 0.0 { "lit side" } else { "far side" };
        assert_all_pixels(&render(ctx, &s), expected, 1e-4, what);
    }
}
