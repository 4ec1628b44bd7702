//! Twin tests of the estimator's math: random numbers, sampling, microfacets, the PBR BSDF,
//! intersection, the exact sums.

use super::*;

/// PCG hash, Sobol's second dimension, the nested uniform scramble, and whole sample streams of
/// both samplers: bit for bit.
#[test]
fn random_numbers_match_their_twin_bit_for_bit() {
    let Some(ctx) = gpu() else { return };
    let input = inputs(3, |rng| {
        (0..3)
            .map(|_| (rng.next_f32() * 16_777_216.0) as u32 ^ (rng.next_f32().to_bits() << 7))
            .collect()
    });
    const STREAM: usize = 12;
    for (sobol, kind) in [
        (false, SamplerKind::Independent),
        (true, SamplerKind::Sobol),
    ] {
        let kernel = TwinKernel {
            words_in: 3,
            words_out: 3 + STREAM,
            body: "let a = u_in(item, 0u); let b = u_in(item, 1u); let c = u_in(item, 2u);
    put_u(item, 0u, pcg_hash(a));
    put_u(item, 1u, sobol_dim1(b));
    put_u(item, 2u, nested_uniform_scramble(a, c));
    var s = rng_init(a, b % 4096u, c);
    for (var k = 0u; k < 12u; k++) { put(item, 3u + k, rng_next(&s)); }",
            sobol,
        };
        let gpu_out = kernel.run(ctx, &input);
        let all: Vec<usize> = (0..3 + STREAM).collect();
        let exact: &'static [usize] = Box::leak(all.into_boxed_slice());
        Comparison {
            name: if sobol { "rng (Sobol)" } else { "rng (PCG)" },
            rel: 0.0,
            abs: 0.0,
            exact_words: exact,
        }
        .check(&gpu_out, 3 + STREAM, |item| {
            let [a, b, c] = [0, 1, 2].map(|k| input[item * 3 + k]);
            let mut out = vec![pcg_hash(a), sobol_dim1(b), nested_uniform_scramble(a, c)];
            let mut rng = Rng::with_sampler(a, b % 4096, c, kind);
            out.extend((0..STREAM).map(|_| rng.next_f32().to_bits()));
            out
        });
    }
}

/// Directions, Fresnel, refraction, colour, and the fuzzy metal's and smooth dielectric's samples
/// (`sampling.wgsl` ⇄ `sampling.rs`).
#[test]
fn sampling_functions_match_their_twin() {
    let Some(ctx) = gpu() else { return };
    let input = inputs(9, |rng| {
        let n = unit(rng);
        let d = unit(rng);
        let cos = 2.0 * rng.next_f32() - 1.0;
        let eta = 0.5 + 2.0 * rng.next_f32();
        let c = 1.2 * rng.next_f32();
        bits(&[n.x, n.y, n.z, d.x, d.y, d.z, cos, eta, c])
    });
    let kernel = TwinKernel {
        words_in: 9,
        words_out: 31,
        body: "let n = v3_in(item, 0u); let d = v3_in(item, 3u);
    let cos_in = f_in(item, 6u); let eta = f_in(item, 7u); let c = f_in(item, 8u);
    let basis = onb(n);
    put3(item, 0u, basis.t); put3(item, 3u, basis.b);
    var s = rng_init(item, 0u, 9u);
    put3(item, 6u, sample_cosine_hemisphere(n, &s));
    let disk = sample_disk(&s);
    put(item, 9u, disk.x); put(item, 10u, disk.y);
    put3(item, 11u, sample_unit_ball(&s));
    put3(item, 14u, sample_triangle(f_in(item, 6u) * 0.5 + 0.5, c / 1.2));
    put(item, 17u, fresnel_dielectric(cos_in, eta));
    let nd = select(n, -n, dot(d, n) > 0.0);
    put3(item, 18u, refract_dir(d, nd, eta));
    put(item, 21u, srgb_to_linear(vec3(c)).x);
    put(item, 22u, luminance(n));
    put(item, 23u, reflect_dir(d, n).x);
    var t = rng_init(item, 1u, 9u);
    put3(item, 24u, sample_metal(d, nd, c / 1.2, &t));
    let glass = sample_dielectric(d, nd, eta, &t);
    put3(item, 27u, glass.direction);
    put(item, 30u, select(0.0, 1.0, glass.refracted));",
        sobol: false,
    };
    let gpu_out = kernel.run(ctx, &input);
    Comparison {
        name: "sampling",
        rel: 2e-5,
        abs: 1e-6,
        exact_words: &[],
    }
    .check(&gpu_out, 31, |item| {
        let f = |k: usize| f32::from_bits(input[item * 9 + k]);
        let n = Vec3::new(f(0), f(1), f(2));
        let d = Vec3::new(f(3), f(4), f(5));
        let (cos, eta, c) = (f(6), f(7), f(8));
        let (t, b) = onb(n);
        let mut rng = Rng::new(item as u32, 0, 9);
        let h = sample_cosine_hemisphere(n, &mut rng);
        let (dx, dy) = sample_disk(&mut rng);
        let ball = sample_unit_ball(&mut rng);
        let tri = sample_triangle(cos * 0.5 + 0.5, c / 1.2);
        let nd = if d.dot(n) > 0.0 { -n } else { n };
        let r = refract(d, nd, eta);
        let mut out = vec![t.x, t.y, t.z, b.x, b.y, b.z, h.x, h.y, h.z, dx, dy];
        out.extend([ball.x, ball.y, ball.z, tri[0], tri[1], tri[2]]);
        out.extend([fresnel_dielectric(cos, eta), r.x, r.y, r.z]);
        out.extend([srgb_to_linear(c), luminance(n), reflect(d, n).x]);
        let mut rng = Rng::new(item as u32, 1, 9);
        let metal = sample_metal(d, nd, c / 1.2, &mut rng);
        let (glass, refracted) = sample_dielectric(d, nd, eta, &mut rng);
        out.extend([metal.x, metal.y, metal.z, glass.x, glass.y, glass.z]);
        out.push(if refracted { 1.0 } else { 0.0 });
        bits(&out)
    });
}

/// GGX: D, Λ, G1, G2, the visible-normal sample and its pdf, Schlick's Fresnel and the albedo
/// table's lookup (`microfacet.wgsl` ⇄ `microfacet.rs`).
#[test]
fn microfacet_functions_match_their_twin() {
    let Some(ctx) = gpu() else { return };
    let input = inputs(11, |rng| {
        let mut wo = unit(rng);
        wo.z = wo.z.abs().max(1e-3);
        let wo = wo.normalize();
        let mut wi = unit(rng);
        wi.z = wi.z.abs();
        let roughness = rng.next_f32();
        // Half the items anisotropic.
        let strength = if rng.next_f32() < 0.5 {
            0.0
        } else {
            rng.next_f32()
        };
        bits(&[
            wo.x,
            wo.y,
            wo.z,
            wi.x,
            wi.y,
            wi.z,
            roughness,
            rng.next_f32(),
            rng.next_f32(),
            rng.next_f32(),
            strength,
        ])
    });
    let kernel = TwinKernel {
        words_in: 11,
        words_out: 14,
        body: "let wo = v3_in(item, 0u); let wi = v3_in(item, 3u); let r = f_in(item, 6u);
    let u1 = f_in(item, 7u); let u2 = f_in(item, 8u);
    let a = anisotropic_alpha(r, f_in(item, 10u));
    let m = sample_vndf(wo, a, u1, u2);
    put(item, 0u, a.x);
    put(item, 12u, a.y);
    put(item, 13u, equivalent_roughness(a));
    put(item, 1u, ggx_d(normalize(wo + wi), a));
    put(item, 2u, ggx_lambda(wi, a));
    put(item, 3u, ggx_g1(wo, a));
    put(item, 4u, ggx_g2(wo, wi, a));
    put3(item, 5u, m);
    put(item, 8u, vndf_pdf(wo, normalize(wo + wi), a));
    put(item, 9u, fresnel_schlick(vec3(f_in(item, 9u)), wo.z).x);
    put(item, 10u, energy_lookup(wo.z, r));
    put(item, 11u, energy_lookup(u2, u1));",
        sobol: false,
    };
    let gpu_out = kernel.run(ctx, &input);
    let table = energy_table();
    Comparison {
        name: "microfacet",
        rel: 1e-4,
        abs: 1e-5,
        exact_words: &[],
    }
    .check(&gpu_out, 14, |item| {
        let f = |k: usize| f32::from_bits(input[item * 11 + k]);
        let wo = Vec3::new(f(0), f(1), f(2));
        let wi = Vec3::new(f(3), f(4), f(5));
        let (r, u1, u2) = (f(6), f(7), f(8));
        let a = anisotropic_alpha(r, f(10));
        let m = sample_vndf(wo, a, u1, u2);
        bits(&[
            a.x,
            ggx_d((wo + wi).normalize(), a),
            ggx_lambda(wi, a),
            ggx_g1(wo, a),
            ggx_g2(wo, wi, a),
            m.x,
            m.y,
            m.z,
            // At a given normal: at a sampled one, the pdf of a narrow lobe would magnify the
            // sample's last-bit differences.
            vndf_pdf(wo, (wo + wi).normalize(), a),
            fresnel_schlick(Vec3::splat(f(9)), wo.z).x,
            energy_lookup(table, wo.z, r),
            energy_lookup(table, u2, u1),
            a.y,
            equivalent_roughness(a),
        ])
    });
}

/// The PBR BSDF's evaluation (f·cos and pdf) and sampling, for metals, dielectrics, glass and
/// thin-walled sheets (`bsdf.wgsl` ⇄ `bsdf.rs`). A sample near a lobe's threshold may pick the
/// other lobe when a Fresnel term differs in its last bit: at most a few in a thousand may
/// disagree on which direction was drawn, and those are counted, not compared.
#[test]
fn pbr_bsdf_matches_its_twin() {
    let Some(ctx) = gpu() else { return };
    let input = inputs(17, |rng| {
        let mut wo = unit(rng);
        wo.z = wo.z.abs().max(1e-3);
        let wo = wo.normalize();
        let wi = unit(rng);
        let pick = |rng: &mut Rng, p: f32| {
            if rng.next_f32() < p {
                1.0
            } else {
                rng.next_f32()
            }
        };
        let metallic = pick(rng, 0.3);
        let transmission = pick(rng, 0.4);
        let thin = if rng.next_f32() < 0.3 { 1.0 } else { 0.0 };
        let eta = if rng.next_f32() < 0.5 {
            1.5
        } else {
            1.0 / 1.33
        };
        bits(&[
            wo.x,
            wo.y,
            wo.z,
            wi.x,
            wi.y,
            wi.z,
            rng.next_f32(),
            rng.next_f32(),
            rng.next_f32(),
            metallic,
            // Roughness from 0.1 (α = 0.01): below, GGX's D near its peak computes sin²θ as
            // 1 − cos²θ, which loses most of its bits (in both twins alike), so a twin comparison
            // there measures rounding, not the formula.
            0.1 + 0.9 * rng.next_f32(),
            eta,
            transmission,
            thin,
            rng.next_f32(),
            rng.next_f32(),
            // A third of the items anisotropic.
            if rng.next_f32() < 0.67 {
                0.0
            } else {
                rng.next_f32()
            },
        ])
    });
    let kernel = TwinKernel {
        words_in: 17,
        words_out: 16,
        body: "let wo = v3_in(item, 0u); let wi = v3_in(item, 3u); let base = v3_in(item, 6u);
    let r = f_in(item, 10u);
    var b = pbr_bsdf(base, f_in(item, 9u), r, f_in(item, 11u), f_in(item, 12u), wo.z,
                     energy_lookup(wo.z, r));
    b = pbr_anisotropic(b, anisotropic_alpha(r, f_in(item, 16u)));
    b.thin = f_in(item, 13u) > 0.5;
    let e = pbr_eval(b, wo, wi);
    put3(item, 0u, e.xyz); put(item, 3u, e.w);
    let s = pbr_sample(b, wo, f_in(item, 14u), f_in(item, 15u), f_in(item, 6u));
    put_u(item, 4u, u32(s.valid));
    put3(item, 5u, select(vec3(0.0), s.wi, s.valid));
    put3(item, 8u, select(vec3(0.0), s.weight, s.valid));
    put(item, 11u, select(0.0, s.pdf, s.valid));
    put(item, 12u, b.q_reflect); put3(item, 13u, b.ms);",
        sobol: false,
    };
    let gpu_out = kernel.run(ctx, &input);
    let table = energy_table();
    // The Rust twin's row for an item; the sample's weight and pdf are evaluated at the GPU's
    // direction `wi_gpu` (checked against the Rust sample's own direction first): a narrow lobe's
    // pdf would otherwise magnify the direction's last-bit differences into per cents.
    let rust = |item: usize, wi_gpu: Vec3| {
        let f = |k: usize| f32::from_bits(input[item * 17 + k]);
        let wo = Vec3::new(f(0), f(1), f(2));
        let wi = Vec3::new(f(3), f(4), f(5));
        let base = Vec3::new(f(6), f(7), f(8));
        let r = f(10);
        let energy = energy_lookup(table, wo.z, r);
        let b = Pbr::new(base, f(9), r, f(11), f(12), wo.z, energy)
            .anisotropic(anisotropic_alpha(r, f(16)))
            .thin_walled(f(13) > 0.5);
        let sample = b.sample(wo, f(14), f(15), f(6));
        let mut out = bsdf_row(|w| b.eval(wo, w), wi, sample.is_some(), wi_gpu);
        out.extend(bits(&[b.q_reflect]));
        out.extend(bits(&[b.ms.x, b.ms.y, b.ms.z]));
        (out, sample.map(|s| s.wi))
    };
    let (gpu_kept, rust_kept) = same_lobe_rows("pbr bsdf", &gpu_out, 16, rust);
    // Every kind of outcome is exercised: samples drawn and refused, transmission and reflection.
    let drawn = rust_kept.iter().filter(|r| r[4] == 1).count();
    let below = rust_kept
        .iter()
        .filter(|r| r[4] == 1 && f32::from_bits(r[7]) < 0.0)
        .count();
    assert!(
        drawn > ITEMS / 2 && below > ITEMS / 50,
        "{drawn} drawn, {below} transmitted"
    );
    Comparison {
        name: "pbr bsdf",
        rel: 2e-3,
        abs: 1e-5,
        exact_words: &[4],
    }
    .check_rows(&gpu_kept, 16, &rust_kept);
}

/// The watertight triangle test, the slab test and the self-intersection offset
/// (`intersect.wgsl` ⇄ `intersect.rs`): hit or miss and the offset bit for bit, distances and
/// barycentrics within rounding.
#[test]
fn intersection_functions_match_their_twin() {
    let Some(ctx) = gpu() else { return };
    let input = inputs(19, |rng| {
        let mut p =
            |s: f32| Vec3::new(rng.next_f32(), rng.next_f32(), rng.next_f32()) * s - s / 2.0;
        let o = p(4.0);
        let [v0, v1, v2] = [p(2.0), p(2.0), p(2.0)];
        let target = (v0 + v1 + v2) / 3.0 + p(1.0);
        let d = (target - o).normalize();
        let far = p(1e4);
        let scale = 10f32.powf(-3.0 + 4.0 * rng.next_f32());
        // Far from the origin on every axis, so the offset takes its integer (ULP) path.
        let far = far + Vec3::select(far.cmplt(Vec3::ZERO), Vec3::splat(-20.0), Vec3::splat(20.0));
        let mut v = [o, d, v0, v1, v2, far];
        v.iter_mut().for_each(|x| {
            if x.x.abs() < 1e-3 {
                x.x = 0.0;
            }
        });
        let mut words: Vec<u32> = v.iter().flat_map(|x| bits(&x.to_array())).collect();
        words.push(scale.to_bits());
        words
    });
    let kernel = TwinKernel {
        words_in: 19,
        words_out: 11,
        body: "let ray = prepare_ray(v3_in(item, 0u), v3_in(item, 3u));
    let hit = intersect_triangle(ray, v3_in(item, 6u), v3_in(item, 9u), v3_in(item, 12u), 1e30);
    put_u(item, 0u, u32(hit.x >= 0.0));
    put3(item, 1u, select(vec3(0.0), hit, hit.x >= 0.0));
    let lo = min(v3_in(item, 6u), v3_in(item, 9u));
    let hi = max(v3_in(item, 6u), v3_in(item, 9u));
    put(item, 4u, intersect_box(ray, lo, hi, 1e30));
    let n = v3_in(item, 3u);
    let p = v3_in(item, 15u);
    put3(item, 5u, offset_ray_origin(p, n, f_in(item, 18u)));
    put3(item, 8u, offset_ray_origin(v3_in(item, 6u) * 1e-3, n, f_in(item, 18u)));",
        sobol: false,
    };
    let gpu_out = kernel.run(ctx, &input);
    Comparison {
        name: "intersect",
        rel: 1e-5,
        abs: 1e-6,
        exact_words: &[0, 5, 6, 7, 8, 9, 10],
    }
    .check(&gpu_out, 11, |item| {
        let f = |k: usize| f32::from_bits(input[item * 19 + k]);
        let v = |k: usize| Vec3::new(f(k), f(k + 1), f(k + 2));
        let ray = PreparedRay::new(v(0), v(3));
        let hit = intersect_triangle(&ray, v(6), v(9), v(12), 1e30);
        let (t, b1, b2) = hit.unwrap_or((0.0, 0.0, 0.0));
        let bx = intersect_box(&ray, v(6).min(v(9)), v(6).max(v(9)), 1e30).unwrap_or(-1.0);
        let o1 = offset_ray_origin(v(15), v(3), f(18));
        let o2 = offset_ray_origin(v(6) * 1e-3, v(3), f(18));
        let mut out = vec![u32::from(hit.is_some())];
        out.extend(bits(&[t, b1, b2, bx, o1.x, o1.y, o1.z, o2.x, o2.y, o2.z]));
        out
    });
}

/// The exact sums: a sample's fixed-point value, addition, negation and what is kept
/// (`accumulation.wgsl` ⇄ `accumulation.rs`), bit for bit; the texture wrap modes and the alpha
/// coin (`texture.wgsl` ⇄ `texture.rs`) and the power heuristic (`light.wgsl` ⇄ `light.rs`).
#[test]
fn fixed_point_sums_wrap_modes_and_heuristic_match_their_twin() {
    let Some(ctx) = gpu() else { return };
    let input = inputs(10, |rng| {
        let e = |rng: &mut Rng| 2f32.powf(-30.0 + 80.0 * rng.next_f32());
        let sign = |rng: &mut Rng| if rng.next_f32() < 0.2 { -1.0 } else { 1.0 };
        let a = sign(rng) * e(rng);
        let b = e(rng);
        let i = (rng.next_f32() * 200.0) as i32 - 100;
        let n = 1 + (rng.next_f32() * 17.0) as i32;
        let mode = (rng.next_f32() * 3.0) as u32;
        // Powers of two: their reciprocals (the coin hashes 1/direction) are exact on any GPU.
        let pow2 = |rng: &mut Rng| 2f32.powi((rng.next_f32() * 20.0) as i32 - 10);
        let mut words = bits(&[a, b, rng.next_f32(), rng.next_f32() * 4.0]);
        words.extend([i as u32, n as u32, mode, (rng.next_f32() * 1e6) as u32]);
        words.extend(bits(&[pow2(rng), -pow2(rng)]));
        words
    });
    let kernel = TwinKernel {
        words_in: 10,
        words_out: 15,
        body: "let a = f_in(item, 0u); let b = f_in(item, 1u);
    let fa = to_fixed(a); let fb = to_fixed(b);
    let s = fixed_add(fa, fb);
    let ng = fixed_negate(fa);
    put_u(item, 0u, s.x); put_u(item, 1u, s.y); put_u(item, 2u, s.z); put_u(item, 3u, s.w);
    put_u(item, 4u, ng.x); put_u(item, 5u, ng.y); put_u(item, 6u, ng.z); put_u(item, 7u, ng.w);
    put_u(item, 8u, u32(sample_is_kept(vec3(a, b, 1.0))));
    put_u(item, 9u, wrap_index(i32(u_in(item, 4u)), i32(u_in(item, 5u)), u_in(item, 6u)));
    put(item, 10u, power_heuristic(f_in(item, 2u), f_in(item, 3u)));
    let ray = prepare_ray(vec3(a, b, 1.0), vec3(1.0, f_in(item, 8u), f_in(item, 9u)));
    put(item, 11u, alpha_coin(ray, u_in(item, 7u)));
    put_u(item, 12u, fa.x); put_u(item, 13u, fa.z); put_u(item, 14u, fa.w);",
        sobol: false,
    };
    let gpu_out = kernel.run(ctx, &input);
    Comparison {
        name: "fixed point, wrap, heuristic",
        rel: 2e-6,
        abs: 1e-7,
        exact_words: &[0, 1, 2, 3, 4, 5, 6, 7, 8, 9, 11, 12, 13, 14],
    }
    .check(&gpu_out, 15, |item| {
        let w = |k: usize| input[item * 10 + k];
        let f = |k: usize| f32::from_bits(w(k));
        let (a, b) = (f(0), f(1));
        let (fa, fb) = (accumulation::to_fixed(a), accumulation::to_fixed(b));
        let mut out: Vec<u32> = accumulation::add(fa, fb).to_vec();
        out.extend(accumulation::negate(fa));
        let mut sums = accumulation::PixelSums::default();
        out.push(u32::from(accumulation::add_sample(&mut sums, [a, b, 1.0])));
        out.push(rt_core::estimator::wrap_index(
            w(4) as i32,
            w(5) as i32,
            w(6),
        ));
        out.push(rt_core::estimator::power_heuristic(f(2), f(3)).to_bits());
        let dir = Vec3::new(1.0, f(8), f(9));
        let ray = PreparedRay::new(Vec3::new(a, b, 1.0), dir);
        out.push(rt_core::estimator::alpha_coin(&ray, w(7)).to_bits());
        out.extend([fa[0], fa[2], fa[3]]);
        out
    });
}

/// Participating media: the Henyey–Greenstein phase function and its sample, transmittance, and
/// free flight through a chromatic medium (`medium.wgsl` ⇄ `medium.rs`), with the segment short
/// enough to pass at times and as long as a ray that left the scene.
#[test]
fn medium_functions_match_their_twin() {
    use rt_core::gpu_types::Medium;
    use rt_core::math::medium::*;
    let Some(ctx) = gpu() else { return };
    let input = inputs(12, |rng| {
        let d = unit(rng);
        let g = 1.9 * rng.next_f32() - 0.95;
        let cos = 2.0 * rng.next_f32() - 1.0;
        let sigma_t = Vec3::new(rng.next_f32(), rng.next_f32(), rng.next_f32()) * 3.0;
        let albedo = Vec3::new(rng.next_f32(), rng.next_f32(), rng.next_f32());
        // A quarter absorb only; a quarter of the segments leave the scene.
        let sigma_s = if rng.next_f32() < 0.25 {
            Vec3::ZERO
        } else {
            sigma_t * albedo
        };
        let t_max = if rng.next_f32() < 0.25 {
            FAR
        } else {
            2.0 * rng.next_f32()
        };
        let mut v = vec![d.x, d.y, d.z, g, cos, t_max];
        v.extend(sigma_t.to_array());
        v.extend(sigma_s.to_array());
        bits(&v)
    });
    let kernel = TwinKernel {
        words_in: 12,
        words_out: 13,
        body: "let d = v3_in(item, 0u); let g = f_in(item, 3u); let cos_in = f_in(item, 4u);
    let t_max = f_in(item, 5u);
    let m = Medium(v3_in(item, 6u), g, v3_in(item, 9u), 0.0);
    put(item, 0u, hg_phase(cos_in, g));
    var s = rng_init(item, 0u, 9u);
    let u1 = rng_next(&s); let u2 = rng_next(&s);
    put3(item, 1u, sample_hg(d, g, u1, u2));
    put3(item, 4u, transmittance(m.sigma_t, t_max));
    let f = free_flight(m, t_max, &s);
    put3(item, 7u, f.weight); put(item, 10u, f.t); put_u(item, 11u, u32(f.scattered));
    put_u(item, 12u, u32(is_vacuum(m)));",
        sobol: false,
    };
    let gpu_out = kernel.run(ctx, &input);
    Comparison {
        name: "medium",
        rel: 5e-5,
        abs: 1e-6,
        exact_words: &[11, 12],
    }
    .check(&gpu_out, 13, |item| {
        let f = |k: usize| f32::from_bits(input[item * 12 + k]);
        let v = |k: usize| Vec3::new(f(k), f(k + 1), f(k + 2));
        let (d, g, cos, t_max) = (v(0), f(3), f(4), f(5));
        let m = Medium {
            sigma_t: v(6).into(),
            anisotropy: g,
            sigma_s: v(9).into(),
            _pad: 0.0,
        };
        let mut rng = Rng::new(item as u32, 0, 9);
        let (u1, u2) = (rng.next_f32(), rng.next_f32());
        let s = sample_hg(d, g, u1, u2);
        let tr = transmittance(Vec3::from(m.sigma_t), t_max);
        let fl = free_flight(&m, t_max, &mut rng);
        let mut out = bits(&[hg_phase(cos, g), s.x, s.y, s.z, tr.x, tr.y, tr.z]);
        out.extend(bits(&[fl.weight.x, fl.weight.y, fl.weight.z, fl.t]));
        out.push(u32::from(fl.scattered));
        out.push(u32::from(is_vacuum(&m)));
        out
    });
}
