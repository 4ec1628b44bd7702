//! Per-function twin tests, as vello tests its CPU shaders: each WGSL function of the estimator's
//! math runs on the GPU (lavapipe in CI) through a small test entry point, over the same random
//! inputs as its Rust twin beside it in `rt-core`, and the outputs are compared: integer functions
//! (random numbers, hashes, fixed-point sums, ray offsets) bit for bit, floating-point ones within
//! a few float roundings (the drivers' `sqrt`, `pow`, `acos`, `sin` … may differ from Rust's libm
//! in the last bits). The harness binds the frame, an environment map and texture images, so the
//! environment's functions and texture lookups are compared too; the image-level lockstep and
//! Z-tests (`tests/reference.rs`) and the traversal against brute force cover the functions that
//! read the rest of the scene (traversal, emitters and lights, the path vertex).

mod common;

use bytemuck::Zeroable;
use common::gpu;
use glam::Vec3;
use rt_core::accumulation;
use rt_core::environment::{self as env, EnvironmentMap, build_env_texels};
use rt_core::gpu_types::{EnvTexel, Frame};
use rt_core::math::bsdf::Pbr;
use rt_core::math::intersect::{PreparedRay, intersect_box, intersect_triangle, offset_ray_origin};
use rt_core::math::microfacet::*;
use rt_core::math::rng::{Rng, SamplerKind, nested_uniform_scramble, pcg_hash, sobol_dim1};
use rt_core::math::sampling::*;
use rt_gpu::GpuContext;
use wgpu::util::DeviceExt;

/// Items per test: enough inputs to reach the branches, small enough for lavapipe.
const ITEMS: usize = 4096;

/// The scene bindings a test's functions read: the frame (uniform), the environment's texels and
/// the texture images' texels.
struct TwinScene {
    frame: Frame,
    environment: Vec<EnvTexel>,
    texels: Vec<u32>,
}

impl Default for TwinScene {
    fn default() -> Self {
        TwinScene {
            frame: Frame::zeroed(),
            environment: vec![EnvTexel::zeroed()],
            texels: vec![0],
        }
    }
}

/// A test entry point over the estimator's files: `body` reads item `item`'s inputs with
/// `f_in`/`v3_in`/`u_in` and writes its outputs with `put`/`put3`/`put_u`.
struct TwinKernel {
    words_in: usize,
    words_out: usize,
    body: &'static str,
    sobol: bool,
}

impl TwinKernel {
    fn source(&self) -> String {
        // The megakernel's whole module (its entry point declares bindings the estimator's files
        // use), so a function is tested exactly as the kernels compile it.
        let estimator: String = rt_gpu::shaders::TRACE_WIDE
            .files
            .iter()
            .map(|f| {
                rt_gpu::shaders::FILES
                    .iter()
                    .find(|(name, _)| name == f)
                    .map(|(_, src)| *src)
                    .unwrap_or_else(|| panic!("{f} is not in FILES"))
            })
            .collect::<Vec<_>>()
            .join("\n");
        format!(
            "{estimator}
@group(1) @binding(0) var<storage, read> twin_in: array<u32>;
@group(1) @binding(1) var<storage, read_write> twin_out: array<u32>;
fn u_in(item: u32, k: u32) -> u32 {{ return twin_in[item * {wi}u + k]; }}
fn f_in(item: u32, k: u32) -> f32 {{ return bitcast<f32>(u_in(item, k)); }}
fn v3_in(item: u32, k: u32) -> vec3<f32> {{
    return vec3(f_in(item, k), f_in(item, k + 1u), f_in(item, k + 2u));
}}
fn put_u(item: u32, k: u32, v: u32) {{ twin_out[item * {wo}u + k] = v; }}
fn put(item: u32, k: u32, v: f32) {{ put_u(item, k, bitcast<u32>(v)); }}
fn put3(item: u32, k: u32, v: vec3<f32>) {{ put(item, k, v.x); put(item, k + 1u, v.y); put(item, k + 2u, v.z); }}
@compute @workgroup_size(64)
fn twin_main(@builtin(global_invocation_id) gid: vec3<u32>) {{
    let item = gid.x;
    if (item >= {items}u) {{ return; }}
    {body}
}}
",
            wi = self.words_in,
            wo = self.words_out,
            items = ITEMS,
            body = self.body,
        )
    }

    /// Runs the kernel over `inputs` (`words_in` words an item) and returns `words_out` words an
    /// item.
    fn run(&self, ctx: &GpuContext, inputs: &[u32]) -> Vec<u32> {
        self.run_in(ctx, &TwinScene::default(), inputs)
    }

    /// `run` with the frame and environment of `scene` bound.
    fn run_in(&self, ctx: &GpuContext, scene: &TwinScene, inputs: &[u32]) -> Vec<u32> {
        assert_eq!(inputs.len(), ITEMS * self.words_in);
        ctx.scoped(|| self.dispatch(ctx, scene, inputs))
            .unwrap_or_else(|e| panic!("the twin test kernel failed: {e}"))
    }

    fn dispatch(&self, ctx: &GpuContext, scene: &TwinScene, inputs: &[u32]) -> Vec<u32> {
        let device = &ctx.device;
        let module = device.create_shader_module(wgpu::ShaderModuleDescriptor {
            label: Some("twin test"),
            source: wgpu::ShaderSource::Wgsl(self.source().into()),
        });
        let storage = |binding, read_only| wgpu::BindGroupLayoutEntry {
            binding,
            visibility: wgpu::ShaderStages::COMPUTE,
            ty: wgpu::BindingType::Buffer {
                ty: wgpu::BufferBindingType::Storage { read_only },
                has_dynamic_offset: false,
                min_binding_size: None,
            },
            count: None,
        };
        // The scene bindings the functions under test read (group 0): the frame, the environment
        // and the GGX albedo table.
        let uniform = wgpu::BindGroupLayoutEntry {
            binding: 0,
            visibility: wgpu::ShaderStages::COMPUTE,
            ty: wgpu::BindingType::Buffer {
                ty: wgpu::BufferBindingType::Uniform,
                has_dynamic_offset: false,
                min_binding_size: None,
            },
            count: None,
        };
        let scene_layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: None,
            entries: &[
                uniform,
                storage(5, true),
                storage(20, true),
                storage(21, true),
            ],
        });
        let twin_layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: None,
            entries: &[storage(0, true), storage(1, false)],
        });
        let layout = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
            label: None,
            bind_group_layouts: &[Some(&scene_layout), Some(&twin_layout)],
            immediate_size: 0,
        });
        let constants = [("SOBOL", f64::from(u8::from(self.sobol)))];
        let pipeline = device.create_compute_pipeline(&wgpu::ComputePipelineDescriptor {
            label: Some("twin test"),
            layout: Some(&layout),
            module: &module,
            entry_point: Some("twin_main"),
            compilation_options: wgpu::PipelineCompilationOptions {
                constants: &constants,
                ..Default::default()
            },
            cache: None,
        });
        let buffer = |contents: &[u8], usage| {
            device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
                label: None,
                contents,
                usage,
            })
        };
        let energy = buffer(
            bytemuck::cast_slice(energy_table()),
            wgpu::BufferUsages::STORAGE,
        );
        let input = buffer(bytemuck::cast_slice(inputs), wgpu::BufferUsages::STORAGE);
        let frame = buffer(
            bytemuck::bytes_of(&scene.frame),
            wgpu::BufferUsages::UNIFORM,
        );
        let environment = buffer(
            bytemuck::cast_slice(&scene.environment),
            wgpu::BufferUsages::STORAGE,
        );
        let texels = buffer(
            bytemuck::cast_slice(&scene.texels),
            wgpu::BufferUsages::STORAGE,
        );
        let out_bytes = (ITEMS * self.words_out * 4) as u64;
        let output = device.create_buffer(&wgpu::BufferDescriptor {
            label: None,
            size: out_bytes,
            usage: wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_SRC,
            mapped_at_creation: false,
        });
        let readback = device.create_buffer(&wgpu::BufferDescriptor {
            label: None,
            size: out_bytes,
            usage: wgpu::BufferUsages::MAP_READ | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        let bind = |layout, entries: &[(u32, &wgpu::Buffer)]| {
            let entries: Vec<wgpu::BindGroupEntry> = entries
                .iter()
                .map(|(binding, buffer)| wgpu::BindGroupEntry {
                    binding: *binding,
                    resource: buffer.as_entire_binding(),
                })
                .collect();
            device.create_bind_group(&wgpu::BindGroupDescriptor {
                label: None,
                layout,
                entries: &entries,
            })
        };
        let scene_group = bind(
            &scene_layout,
            &[(0, &frame), (5, &texels), (20, &environment), (21, &energy)],
        );
        let twin_group = bind(&twin_layout, &[(0, &input), (1, &output)]);
        let mut encoder = device.create_command_encoder(&Default::default());
        {
            let mut pass = encoder.begin_compute_pass(&Default::default());
            pass.set_pipeline(&pipeline);
            pass.set_bind_group(0, &scene_group, &[]);
            pass.set_bind_group(1, &twin_group, &[]);
            pass.dispatch_workgroups(ITEMS.div_ceil(64) as u32, 1, 1);
        }
        encoder.copy_buffer_to_buffer(&output, 0, &readback, 0, out_bytes);
        ctx.queue.submit([encoder.finish()]);
        readback
            .slice(..)
            .map_async(wgpu::MapMode::Read, |r| r.expect("map"));
        device
            .poll(wgpu::PollType::wait_indefinitely())
            .expect("poll");
        let view = readback.slice(..).get_mapped_range().expect("mapped");
        bytemuck::cast_slice(&view).to_vec()
    }
}

/// Random inputs: `ITEMS` items of `words` each, built by `item` from a PCG stream.
fn inputs(words: usize, mut item: impl FnMut(&mut Rng) -> Vec<u32>) -> Vec<u32> {
    let mut out = Vec::with_capacity(ITEMS * words);
    for i in 0..ITEMS {
        let mut rng = Rng::new(i as u32, 0, 0x7417);
        let v = item(&mut rng);
        assert_eq!(v.len(), words);
        out.extend(v);
    }
    out
}

/// A unit direction, uniform on the sphere.
fn unit(rng: &mut Rng) -> Vec3 {
    let z = 1.0 - 2.0 * rng.next_f32();
    let phi = std::f32::consts::TAU * rng.next_f32();
    let r = (1.0 - z * z).max(0.0).sqrt();
    Vec3::new(r * phi.cos(), r * phi.sin(), z)
}

fn bits(v: &[f32]) -> Vec<u32> {
    v.iter().map(|x| x.to_bits()).collect()
}

/// Compares item by item, word by word: `expected` is the Rust twin's output for an item. Float
/// words agree within `rel` of their size or within `abs` (near zero); NaN only with NaN.
struct Comparison {
    name: &'static str,
    rel: f32,
    abs: f32,
    /// Outputs that are integers (compared exactly), by word index within an item.
    exact_words: &'static [usize],
}

impl Comparison {
    /// `gpu` holds `words` words per item; `expected(item)` is the Rust twin's output for it.
    fn check(&self, gpu: &[u32], words: usize, expected: impl FnMut(usize) -> Vec<u32>) {
        let rows: Vec<Vec<u32>> = (0..gpu.len() / words).map(expected).collect();
        self.check_rows(gpu, words, &rows);
    }

    fn check_rows(&self, gpu: &[u32], words: usize, rows: &[Vec<u32>]) {
        assert_eq!(gpu.len(), rows.len() * words, "{}: item count", self.name);
        let mut worst = 0.0f32;
        for (item, rust) in rows.iter().enumerate() {
            assert_eq!(rust.len(), words, "{}: Rust twin's output size", self.name);
            for (k, &r) in rust.iter().enumerate() {
                let g = gpu[item * words + k];
                if self.exact_words.contains(&k) {
                    assert_eq!(g, r, "{}: item {item}, word {k}", self.name);
                    continue;
                }
                let (g, r) = (f32::from_bits(g), f32::from_bits(r));
                if g.is_nan() || r.is_nan() {
                    assert!(
                        g.is_nan() && r.is_nan(),
                        "{}: item {item}, word {k}: GPU {g}, Rust {r}",
                        self.name
                    );
                    continue;
                }
                let err = (g - r).abs() / g.abs().max(r.abs()).max(self.abs / self.rel.max(1e-12));
                assert!(
                    err <= self.rel || g == r,
                    "{}: item {item}, word {k}: GPU {g}, Rust {r} (relative {err:e} > {:e})",
                    self.name,
                    self.rel
                );
                worst = worst.max(err);
            }
        }
        eprintln!("{}: worst relative difference {worst:e}", self.name);
    }
}

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
    let input = inputs(10, |rng| {
        let mut wo = unit(rng);
        wo.z = wo.z.abs().max(1e-3);
        let wo = wo.normalize();
        let mut wi = unit(rng);
        wi.z = wi.z.abs();
        let roughness = rng.next_f32();
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
        ])
    });
    let kernel = TwinKernel {
        words_in: 10,
        words_out: 12,
        body: "let wo = v3_in(item, 0u); let wi = v3_in(item, 3u); let r = f_in(item, 6u);
    let u1 = f_in(item, 7u); let u2 = f_in(item, 8u);
    let a = alpha_of_roughness(r);
    let m = sample_vndf(wo, a, u1, u2);
    put(item, 0u, a);
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
    .check(&gpu_out, 12, |item| {
        let f = |k: usize| f32::from_bits(input[item * 10 + k]);
        let wo = Vec3::new(f(0), f(1), f(2));
        let wi = Vec3::new(f(3), f(4), f(5));
        let (r, u1, u2) = (f(6), f(7), f(8));
        let a = alpha_of_roughness(r);
        let m = sample_vndf(wo, a, u1, u2);
        bits(&[
            a,
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
    let input = inputs(16, |rng| {
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
        ])
    });
    let kernel = TwinKernel {
        words_in: 16,
        words_out: 16,
        body: "let wo = v3_in(item, 0u); let wi = v3_in(item, 3u); let base = v3_in(item, 6u);
    let r = f_in(item, 10u);
    var b = pbr_bsdf(base, f_in(item, 9u), r, f_in(item, 11u), f_in(item, 12u), wo.z,
                     energy_lookup(wo.z, r));
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
        let f = |k: usize| f32::from_bits(input[item * 16 + k]);
        let wo = Vec3::new(f(0), f(1), f(2));
        let wi = Vec3::new(f(3), f(4), f(5));
        let base = Vec3::new(f(6), f(7), f(8));
        let r = f(10);
        let energy = energy_lookup(table, wo.z, r);
        let b = Pbr::new(base, f(9), r, f(11), f(12), wo.z, energy).thin_walled(f(13) > 0.5);
        let (e, pdf) = b.eval(wo, wi);
        let sample = b.sample(wo, f(14), f(15), f(6));
        let (f_s, pdf_s) = b.eval(wo, wi_gpu);
        let (wi_s, w, p) = match sample {
            Some(_) => (wi_gpu, f_s / pdf_s, pdf_s),
            None => (Vec3::ZERO, Vec3::ZERO, 0.0),
        };
        let mut out = bits(&[e.x, e.y, e.z, pdf]);
        out.push(u32::from(sample.is_some()));
        out.extend(bits(&[
            wi_s.x,
            wi_s.y,
            wi_s.z,
            w.x,
            w.y,
            w.z,
            p,
            b.q_reflect,
        ]));
        out.extend(bits(&[b.ms.x, b.ms.y, b.ms.z]));
        (out, sample.map(|s| s.wi))
    };
    // Items whose sampled direction took another branch on the two sides are set aside.
    let mut other_branch = 0;
    let (mut gpu_kept, mut rust_kept) = (Vec::new(), Vec::new());
    for item in 0..ITEMS {
        let g = &gpu_out[item * 16..(item + 1) * 16];
        let wi_gpu = Vec3::new(
            f32::from_bits(g[5]),
            f32::from_bits(g[6]),
            f32::from_bits(g[7]),
        );
        let (r, wi_rust) = rust(item, wi_gpu);
        let same = match wi_rust {
            Some(wi) => g[4] == 1 && wi.abs_diff_eq(wi_gpu, 1e-3),
            None => g[4] == 0,
        };
        if !same {
            other_branch += 1;
            continue;
        }
        gpu_kept.extend_from_slice(g);
        rust_kept.push(r);
    }
    eprintln!("pbr bsdf: {other_branch} of {ITEMS} samples took another lobe");
    assert!(
        other_branch * 500 <= ITEMS,
        "{other_branch} of {ITEMS} samples took another lobe on the GPU"
    );
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
/// coin (`texture.wgsl` ⇄ `texture.rs`) and the power heuristic (`path.wgsl` ⇄ `path.rs`).
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
        out.push(rt_core::reference::wrap_index(
            w(4) as i32,
            w(5) as i32,
            w(6),
        ));
        out.push(rt_core::reference::power_heuristic(f(2), f(3)).to_bits());
        let dir = Vec3::new(1.0, f(8), f(9));
        let ray = PreparedRay::new(Vec3::new(a, b, 1.0), dir);
        out.push(rt_core::reference::alpha_coin(&ray, w(7)).to_bits());
        out.extend([fa[0], fa[2], fa[3]]);
        out
    });
}

/// The environment map's mapping both ways, its lookup (radiance and pdf) and its importance
/// sampling (`environment.wgsl` ⇄ `environment.rs`), over a random 16 × 8 map, turned. A lookup
/// whose direction lies on a texel boundary may read the neighbour when `atan2` or `acos` differ in
/// their last bit: such items (a few in a thousand at most) are counted, not compared.
#[test]
fn environment_functions_match_their_twin() {
    let Some(ctx) = gpu() else { return };
    let (w, h) = (16u32, 8u32);
    let mut rng = Rng::new(0, 0, 0xe17);
    let radiance = (0..w * h)
        .map(|_| {
            let s = 10f32.powf(3.0 * rng.next_f32() - 1.0);
            [rng.next_f32() * s, rng.next_f32() * s, rng.next_f32() * s]
        })
        .collect();
    let map = EnvironmentMap::from_texels(w, h, radiance).0;
    let texels = build_env_texels(&map, 1.0).unwrap();
    let rotation = 0.3125;
    let mut frame = Frame::zeroed();
    frame.env_width = w;
    frame.env_height = h;
    frame.env_rotation = rotation;
    let scene = TwinScene {
        frame,
        environment: texels.clone(),
        ..Default::default()
    };
    let input = inputs(9, |rng| {
        let d = unit(rng);
        let u: Vec<f32> = (0..6).map(|_| rng.next_f32()).collect();
        let mut words = bits(&[d.x, d.y, d.z]);
        words.extend(bits(&u));
        words
    });
    let kernel = TwinKernel {
        words_in: 9,
        words_out: 16,
        body: "let d = v3_in(item, 0u);
    let uv = env_uv(d);
    put(item, 0u, uv.x); put(item, 1u, uv.y);
    put3(item, 2u, env_direction(f_in(item, 3u), f_in(item, 4u)));
    let l = env_lookup(d);
    put3(item, 5u, l.xyz); put(item, 8u, l.w);
    let s = sample_env(f_in(item, 5u), f_in(item, 6u), f_in(item, 7u), f_in(item, 8u));
    put3(item, 9u, s.direction); put3(item, 12u, s.radiance); put(item, 15u, s.pdf);",
        sobol: false,
    };
    let gpu_out = kernel.run_in(ctx, &scene, &input);
    let mut on_a_boundary = 0;
    let (mut gpu_kept, mut rust_kept) = (Vec::new(), Vec::new());
    for item in 0..ITEMS {
        let f = |k: usize| f32::from_bits(input[item * 9 + k]);
        let g = &gpu_out[item * 16..(item + 1) * 16];
        let d = Vec3::new(f(0), f(1), f(2));
        let (u, v) = env::env_uv(d, rotation);
        let (gu, gv) = (f32::from_bits(g[0]), f32::from_bits(g[1]));
        if env::env_texel_index(u, v, w, h) != env::env_texel_index(gu, gv, w, h) {
            on_a_boundary += 1;
            continue;
        }
        let dir = env::env_direction(f(3), f(4), rotation);
        let (le, pdf) = env::env_lookup(&texels, w, h, rotation, d);
        let (sd, sl, spdf) = env::sample_env(&texels, w, h, rotation, [f(5), f(6), f(7), f(8)]);
        gpu_kept.extend_from_slice(g);
        rust_kept.push(bits(&[
            u, v, dir.x, dir.y, dir.z, le.x, le.y, le.z, pdf, sd.x, sd.y, sd.z, sl.x, sl.y, sl.z,
            spdf,
        ]));
    }
    eprintln!("environment: {on_a_boundary} of {ITEMS} directions on a texel boundary");
    assert!(
        on_a_boundary * 200 <= ITEMS,
        "{on_a_boundary} directions read another texel"
    );
    // Vulkan lets `acos` and `atan2` err by far more than an ulp (lavapipe's acos: ~5e-5 at
    // v ≈ 0.4), hence a looser bound than the other twins'.
    Comparison {
        name: "environment",
        rel: 5e-4,
        abs: 1e-4,
        exact_words: &[],
    }
    .check_rows(&gpu_kept, 16, &rust_kept);
}

/// Texture lookups (`sample_slot` in `texture.wgsl` ⇄ `Slot::sample` in `texture.rs`): bilinear and
/// nearest, sRGB-decoded or linear, every wrap mode on each axis, over two random images of odd
/// sizes, at coordinates well outside [0, 1].
#[test]
fn texture_lookups_match_their_twin() {
    let Some(ctx) = gpu() else { return };
    let mut rng = Rng::new(0, 0, 0x7e8);
    let images = [(0u32, 7u32, 5u32), (35, 4, 9)];
    let texels: Vec<u32> = (0..35 + 36)
        .map(|_| (rng.next_f32() * 4_294_967_296.0) as u32)
        .collect();
    let scene = TwinScene {
        texels: texels.clone(),
        ..Default::default()
    };
    let input = inputs(6, |rng| {
        let (offset, w, h) = images[usize::from(rng.next_f32() < 0.5)];
        // Wrap s and t (0 repeat, 1 clamp, 2 mirror) and the nearest filter, as `TextureSampler::bits`.
        let wrap = |rng: &mut Rng| ((rng.next_f32() * 3.0) as u32).min(2);
        let nearest = if rng.next_f32() < 0.3 { 16 } else { 0 };
        let sampler = wrap(rng) | (wrap(rng) << 2) | nearest;
        let uv = [6.0 * rng.next_f32() - 3.0, 6.0 * rng.next_f32() - 3.0];
        let srgb = u32::from(rng.next_f32() < 0.5);
        let mut words = vec![offset | (w << 8) | (h << 16), sampler, srgb];
        words.extend(bits(&uv));
        words.push(0);
        words
    });
    let kernel = TwinKernel {
        words_in: 6,
        words_out: 4,
        body: "let slot = u_in(item, 0u);
    let t = sample_slot(slot & 0xffu, (slot >> 8u) & 0xffu, slot >> 16u, u_in(item, 1u),
                        vec2(f_in(item, 3u), f_in(item, 4u)), u_in(item, 2u) == 1u);
    put3(item, 0u, t.xyz); put(item, 3u, t.w);",
        sobol: false,
    };
    let gpu_out = kernel.run_in(ctx, &scene, &input);
    let gpu_scene = rt_core::GpuScene {
        texels,
        ..Default::default()
    };
    Comparison {
        name: "texture lookups",
        rel: 1e-5,
        abs: 1e-6,
        exact_words: &[],
    }
    .check(&gpu_out, 4, |item| {
        let w = |k: usize| input[item * 6 + k];
        let slot = rt_core::reference::Slot {
            offset: w(0) & 0xff,
            width: (w(0) >> 8) & 0xff,
            height: w(0) >> 16,
            bits: w(1),
        };
        let uv = glam::Vec2::new(f32::from_bits(w(3)), f32::from_bits(w(4)));
        let t = slot.sample(&gpu_scene, uv, w(2) == 1);
        bits(&[t.x, t.y, t.z, t.w])
    });
}

/// Where each kind of delta light lies from a point and the irradiance it gives there
/// (`delta_light_incidence` in `path.wgsl` ⇄ `path.rs`): point, spot (smoothstep falloff), glTF
/// spot (quadratic falloff) and sun, from points inside and outside the cones.
#[test]
fn delta_light_incidence_matches_its_twin() {
    use rt_core::gpu_types::{DeltaLight, light_kind};
    let Some(ctx) = gpu() else { return };
    let kinds = [
        light_kind::POINT,
        light_kind::SPOT,
        light_kind::SPOT_GLTF,
        light_kind::DIRECTIONAL,
    ];
    let light_of = |w: &[u32]| {
        let f = |k: usize| f32::from_bits(w[k]);
        DeltaLight {
            position: [f(0), f(1), f(2)],
            kind: w[3],
            direction: [f(4), f(5), f(6)],
            cos_inner: f(7),
            power: [f(8), f(9), f(10)],
            cos_outer: f(11),
        }
    };
    let input = inputs(15, |rng| {
        let position = (Vec3::new(rng.next_f32(), rng.next_f32(), rng.next_f32()) - 0.5) * 8.0;
        let direction = unit(rng);
        let kind = kinds[((rng.next_f32() * 4.0) as usize).min(3)];
        let outer = 0.3 + 0.6 * rng.next_f32();
        let inner = outer + (1.0 - outer) * rng.next_f32();
        let power = [
            rng.next_f32() * 100.0,
            rng.next_f32() * 10.0,
            rng.next_f32(),
        ];
        let origin = (Vec3::new(rng.next_f32(), rng.next_f32(), rng.next_f32()) - 0.5) * 8.0;
        let mut words = bits(&position.to_array());
        words.push(kind);
        words.extend(bits(&direction.to_array()));
        words.push(inner.to_bits());
        words.extend(bits(&power));
        words.push(outer.to_bits());
        words.extend(bits(&origin.to_array()));
        words
    });
    let kernel = TwinKernel {
        words_in: 15,
        words_out: 7,
        body: "let light = DeltaLight(v3_in(item, 0u), u_in(item, 3u), v3_in(item, 4u), f_in(item, 7u),
                           v3_in(item, 8u), f_in(item, 11u));
    let incidence = delta_light_incidence(light, v3_in(item, 12u));
    put3(item, 0u, incidence.dir); put(item, 3u, incidence.distance);
    put3(item, 4u, incidence.irradiance);",
        sobol: false,
    };
    let gpu_out = kernel.run(ctx, &input);
    // The spots' falloff is steep at their cone's edge: bound it by a few roundings of the cosine.
    Comparison {
        name: "delta light incidence",
        rel: 1e-4,
        abs: 1e-6,
        exact_words: &[],
    }
    .check(&gpu_out, 7, |item| {
        let w = &input[item * 15..(item + 1) * 15];
        let light = light_of(w);
        let origin = Vec3::new(
            f32::from_bits(w[12]),
            f32::from_bits(w[13]),
            f32::from_bits(w[14]),
        );
        let (dir, distance, e) = rt_core::reference::path::delta_light_incidence(&light, origin);
        bits(&[dir.x, dir.y, dir.z, distance, e.x, e.y, e.z])
    });
}
