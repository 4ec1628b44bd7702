//! Twin tests of the PBR material's layers: the clear coat, the sheen and the stack they form over
//! the base with `KHR_materials_specular`, and rough glass's energy compensation (`coat.wgsl`,
//! `sheen.wgsl`, `layers.wgsl`, `glass_energy.wgsl` ⇄ their `.rs`).

use super::*;
use rt_core::math::coat::{coat_eval, sample_coat};
use rt_core::math::glass_energy::glass_energy;
use rt_core::math::layers::{
    Layered, Layers, TABLE_COAT, TABLE_GLASS, TABLE_SHEEN, albedo_lookup, albedo_tables,
};
use rt_core::math::sheen::{charlie_d, charlie_lambda, sample_sheen, sheen_alpha, sheen_eval};

/// The coat's and the sheen's functions, their albedo tables and rough glass's, within rounding.
#[test]
fn coat_and_sheen_match_their_twin() {
    let Some(ctx) = gpu() else { return };
    let input = inputs(10, |rng| {
        let mut wo = unit(rng);
        wo.z = wo.z.abs().max(1e-3);
        let wo = wo.normalize();
        let wi = unit(rng);
        bits(&[
            wo.x,
            wo.y,
            wo.z,
            wi.x,
            wi.y,
            wi.z,
            // Roughness from 0.1, as in `microfacet_matches_its_twin`.
            0.1 + 0.9 * rng.next_f32(),
            rng.next_f32(),
            rng.next_f32(),
            // η from 1/2.4 to 2.4, entering and leaving.
            2.4f32.powf(2.0 * rng.next_f32() - 1.0),
        ])
    });
    let kernel = TwinKernel {
        words_in: 10,
        words_out: 15,
        body: "let wo = v3_in(item, 0u); let wi = v3_in(item, 3u); let r = f_in(item, 6u);
    let u1 = f_in(item, 7u); let u2 = f_in(item, 8u);
    let c = coat_eval(wo, wi, alpha_of_roughness(r));
    put(item, 0u, c.x); put(item, 1u, c.y);
    let s = sample_coat(wo, alpha_of_roughness(r), u1, u2);
    put3(item, 2u, select(vec3(0.0), s.xyz, s.w > 0.0));
    let a = sheen_alpha(r);
    put(item, 5u, charlie_d(wi.z, a));
    put(item, 6u, charlie_lambda(abs(wi.z), a));
    put(item, 7u, sheen_eval(wo, wi, a));
    put3(item, 8u, sample_sheen(u1, u2));
    put(item, 11u, albedo_lookup(TABLE_COAT, wo.z, r));
    put(item, 12u, albedo_lookup(TABLE_SHEEN, wo.z, r));
    put(item, 13u, albedo_lookup(TABLE_SHEEN, u1, u2));
    put(item, 14u, glass_energy(wo.z, r, f_in(item, 9u)));",
        sobol: false,
    };
    let gpu_out = kernel.run(ctx, &input);
    let tables = albedo_tables();
    let glass = &tables[TABLE_GLASS * ENERGY_SIDE * ENERGY_SIDE..];
    Comparison {
        name: "coat, sheen and glass energy",
        rel: 2e-4,
        abs: 1e-5,
        exact_words: &[],
    }
    .check(&gpu_out, 15, |item| {
        let f = |k: usize| f32::from_bits(input[item * 10 + k]);
        let wo = Vec3::new(f(0), f(1), f(2));
        let wi = Vec3::new(f(3), f(4), f(5));
        let (r, u1, u2) = (f(6), f(7), f(8));
        let (c, pc) = coat_eval(wo, wi, alpha_of_roughness(r));
        let s = sample_coat(wo, alpha_of_roughness(r), u1, u2).unwrap_or(Vec3::ZERO);
        let a = sheen_alpha(r);
        let sh = sample_sheen(u1, u2);
        bits(&[
            c,
            pc,
            s.x,
            s.y,
            s.z,
            charlie_d(wi.z, a),
            charlie_lambda(wi.z.abs(), a),
            sheen_eval(wo, wi, a),
            sh.x,
            sh.y,
            sh.z,
            albedo_lookup(&tables, TABLE_COAT, wo.z, r),
            albedo_lookup(&tables, TABLE_SHEEN, wo.z, r),
            albedo_lookup(&tables, TABLE_SHEEN, u1, u2),
            glass_energy(glass, wo.z, r, f(9)),
        ])
    });
}

/// The layered BSDF's evaluation and sampling with random coats, sheens and specular settings
/// over random bases, as `pbr_bsdf_matches_its_twin` checks the base alone: a sample whose lobe
/// choice flips on a last-bit difference is counted, not compared.
#[test]
fn layered_bsdf_matches_its_twin() {
    let Some(ctx) = gpu() else { return };
    const WORDS: usize = 35;
    let input = inputs(WORDS, |rng| {
        let mut wo = unit(rng);
        wo.z = wo.z.abs().max(1e-3);
        let wo = wo.normalize();
        let wi = unit(rng);
        let some = |rng: &mut Rng, p: f32| {
            if rng.next_f32() < p {
                rng.next_f32()
            } else {
                0.0
            }
        };
        let metallic = some(rng, 0.5);
        let transmission = some(rng, 0.4);
        let eta = if rng.next_f32() < 0.5 {
            1.5
        } else {
            1.0 / 1.33
        };
        let mut words = vec![wo.x, wo.y, wo.z, wi.x, wi.y, wi.z];
        words.extend([rng.next_f32(), rng.next_f32(), rng.next_f32()]); // base colour
        words.extend([metallic, 0.1 + 0.9 * rng.next_f32(), eta, transmission]);
        words.push(if rng.next_f32() < 0.3 { 1.0 } else { 0.0 }); // thin
        words.extend([rng.next_f32(), rng.next_f32()]); // u_lobe, u1 (u2 reuses word 6)
        words.extend([2.0 * rng.next_f32(), rng.next_f32(), rng.next_f32()]); // specular colour
        words.push(rng.next_f32()); // specular
        words.extend([some(rng, 0.6), 0.1 + 0.9 * rng.next_f32()]); // coat, its roughness
        let sheen = some(rng, 0.6);
        words.extend([sheen, sheen * rng.next_f32(), sheen * rng.next_f32()]);
        words.push(rng.next_f32()); // sheen roughness
        words.push(0.4 + 0.6 * rng.next_f32()); // the glass part's albedo
        // Half the coats in a frame of their own, tilted up to 0.5 rad.
        words.push(if rng.next_f32() < 0.5 {
            0.5 * rng.next_f32()
        } else {
            0.0
        });
        // Diffuse transmission on a third, with its colour.
        words.push(some(rng, 0.3));
        words.extend([rng.next_f32(), rng.next_f32(), rng.next_f32()]);
        // A thin film on half: weight, index, thickness (nm).
        words.extend([some(rng, 0.5), 1.0 + rng.next_f32(), 800.0 * rng.next_f32()]);
        bits(&words)
    });
    let kernel = TwinKernel {
        words_in: WORDS,
        words_out: 14,
        body: "let wo = v3_in(item, 0u); let wi = v3_in(item, 3u); let base = v3_in(item, 6u);
    let r = f_in(item, 10u);
    var b = pbr_bsdf(base, f_in(item, 9u), r, f_in(item, 11u), f_in(item, 12u), wo.z,
                     energy_lookup(wo.z, r));
    b = pbr_with_specular(b, v3_in(item, 16u), f_in(item, 19u), wo.z);
    b.thin = f_in(item, 13u) > 0.5;
    b = pbr_with_glass_energy(b, f_in(item, 26u));
    b = pbr_with_diffuse_transmission(b, f_in(item, 28u), v3_in(item, 29u));
    b = pbr_with_iridescence(b, f_in(item, 32u), f_in(item, 33u), f_in(item, 34u));
    let tilt = f_in(item, 27u);
    let c = cos(tilt);
    let sn = sin(tilt);
    // A rotation about x by `tilt` (columns), the coat's own frame where tilt ≠ 0.
    let m = mat3x3(vec3(1.0, 0.0, 0.0), vec3(0.0, c, sn), vec3(0.0, -sn, c));
    let l = layered_bsdf(b, f_in(item, 20u), f_in(item, 21u), v3_in(item, 22u), f_in(item, 25u), wo,
                         tilt != 0.0, m);
    let e = layered_eval(l, wo, wi);
    put3(item, 0u, e.xyz); put(item, 3u, e.w);
    let s = layered_sample(l, wo, f_in(item, 14u), f_in(item, 15u), f_in(item, 6u));
    put_u(item, 4u, u32(s.valid));
    put3(item, 5u, select(vec3(0.0), s.wi, s.valid));
    put3(item, 8u, select(vec3(0.0), s.weight, s.valid));
    put(item, 11u, select(0.0, s.pdf, s.valid));
    put(item, 12u, l.q_coat); put(item, 13u, l.q_sheen);",
        sobol: false,
    };
    let gpu_out = kernel.run(ctx, &input);
    let tables = albedo_tables();
    // The Rust row, the sample's weight and pdf evaluated at the GPU's direction (see
    // `pbr_bsdf_matches_its_twin`).
    let rust = |item: usize, wi_gpu: Vec3| {
        let f = |k: usize| f32::from_bits(input[item * WORDS + k]);
        let v = |k: usize| Vec3::new(f(k), f(k + 1), f(k + 2));
        let (wo, wi) = (v(0), v(3));
        let r = f(10);
        let energy = energy_lookup(&tables, wo.z, r);
        let base = Pbr::new(v(6), f(9), r, f(11), f(12), wo.z, energy)
            .with_specular(v(16), f(19), wo.z)
            .thin_walled(f(13) > 0.5)
            .with_glass_energy(f(26))
            .with_diffuse_transmission(f(28), v(29))
            .with_iridescence(f(32), f(33), f(34));
        let layers = Layers {
            clearcoat: f(20),
            clearcoat_roughness: f(21),
            sheen_color: v(22),
            sheen_roughness: f(25),
            coat_frame: (f(27) != 0.0).then(|| glam::Mat3::from_rotation_x(f(27))),
        };
        let l = Layered::new(base, &layers, &tables, wo);
        let sample = l.sample(wo, f(14), f(15), f(6));
        let mut out = bsdf_row(|w| l.eval(wo, w), wi, sample.is_some(), wi_gpu);
        out.extend(bits(&[l.q_coat, l.q_sheen]));
        (out, sample.map(|s| s.wi))
    };
    let (gpu_kept, rust_kept) = same_lobe_rows("layered bsdf", &gpu_out, 14, rust);
    // Every layer is exercised: items with a coat, with a sheen, and samples drawn.
    let coated = rust_kept
        .iter()
        .filter(|r| f32::from_bits(r[12]) > 0.0)
        .count();
    let sheened = rust_kept
        .iter()
        .filter(|r| f32::from_bits(r[13]) > 0.0)
        .count();
    let drawn = rust_kept.iter().filter(|r| r[4] == 1).count();
    assert!(
        coated > ITEMS / 3 && sheened > ITEMS / 3 && drawn > ITEMS / 2,
        "{coated} coated, {sheened} with sheen, {drawn} drawn"
    );
    Comparison {
        name: "layered bsdf",
        rel: 2e-3,
        abs: 1e-5,
        exact_words: &[4],
    }
    .check_rows(&gpu_kept, 14, &rust_kept);
}
