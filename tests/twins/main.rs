//! Per-function twin tests, as vello tests its CPU shaders: each WGSL function of the estimator
//! runs on the GPU (lavapipe in CI) through a small test entry point, over the same random inputs
//! as its Rust twin beside it in `rt-core`, and the outputs are compared: integer functions
//! (random numbers, hashes, fixed-point sums, ray offsets) bit for bit, floating-point ones within
//! a few float roundings (the drivers' `sqrt`, `pow`, `acos`, `sin` … may differ from Rust's libm
//! in the last bits). The harness binds the frame and a whole `GpuScene` as the kernels do, so
//! the functions that read the scene (traversal, light sampling, environment, textures) are
//! compared too: `math.rs` holds the math, `layers.rs` the coat, sheen and layer stack, `scene.rs` the environment, textures, delta lights and
//! the surface dispatch, `lights.rs` light sampling, direct light, the delta lights' sum, the escaped sky, camera rays and
//! traversal. The image-level
//! lockstep and Z-tests (`tests/reference/`) compare whole paths.

#[path = "../common/mod.rs"]
mod common;
mod layers;
mod lights;
mod math;
mod scene;

use bytemuck::Zeroable;
use common::gpu;
use glam::Vec3;
use rt_core::accumulation;
use rt_core::environment::{self as env, EnvironmentMap, build_env_texels};
use rt_core::gpu_types::Frame;
use rt_core::math::bsdf::Pbr;
use rt_core::math::intersect::{PreparedRay, intersect_box, intersect_triangle, offset_ray_origin};
use rt_core::math::microfacet::*;
use rt_core::math::rng::{Rng, SamplerKind, nested_uniform_scramble, pcg_hash, sobol_dim1};
use rt_core::math::sampling::*;
use rt_gpu::GpuContext;
use wgpu::util::DeviceExt;

/// Items per test: enough inputs to reach the branches, small enough for lavapipe.
pub(crate) const ITEMS: usize = 4096;

/// The scene a test's functions read: the frame (uniform) and a `GpuScene`'s buffers, bound as
/// the kernels bind them (empty ones as zeroed placeholders). The scene's BVH layout picks the
/// traversal compiled in (`TRACE_WIDE` or `TRACE`).
pub(crate) struct TwinScene {
    frame: Frame,
    scene: rt_core::GpuScene,
}

impl Default for TwinScene {
    fn default() -> Self {
        TwinScene {
            frame: Frame::zeroed(),
            scene: rt_core::GpuScene {
                albedo_tables: rt_core::math::layers::albedo_tables(),
                ..Default::default()
            },
        }
    }
}

/// A test entry point over the estimator's files: `body` reads item `item`'s inputs with
/// `f_in`/`v3_in`/`u_in` and writes its outputs with `put`/`put3`/`put_u`.
pub(crate) struct TwinKernel {
    words_in: usize,
    words_out: usize,
    body: &'static str,
    sobol: bool,
}

impl TwinKernel {
    fn source(&self, layout: rt_core::bvh::BvhLayout) -> String {
        // The megakernel's whole module (its entry point declares bindings the estimator's files
        // use), so a function is tested exactly as the kernels compile it.
        let module = match layout {
            rt_core::bvh::BvhLayout::Cwbvh => &rt_gpu::shaders::TRACE_WIDE,
            rt_core::bvh::BvhLayout::Bvh2 => &rt_gpu::shaders::TRACE,
        };
        let estimator: String = module
            .files
            .iter()
            .map(|(_, src)| *src)
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
fn twin_main(@builtin(global_invocation_id) gid: vec3<u32>, @builtin(local_invocation_index) lid: u32) {{
    // The traversal's stack in work-group memory, as the megakernel's entry point sets it.
    stack_base = lid * BVH_STACK_SIZE;
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
    pub(crate) fn run(&self, ctx: &GpuContext, inputs: &[u32]) -> Vec<u32> {
        self.run_in(ctx, &TwinScene::default(), inputs)
    }

    /// `run` with the frame and environment of `scene` bound.
    pub(crate) fn run_in(&self, ctx: &GpuContext, scene: &TwinScene, inputs: &[u32]) -> Vec<u32> {
        assert_eq!(inputs.len(), ITEMS * self.words_in);
        ctx.scoped(|| self.dispatch(ctx, scene, inputs))
            .unwrap_or_else(|e| panic!("the twin test kernel failed: {e}"))
    }

    fn dispatch(&self, ctx: &GpuContext, scene: &TwinScene, inputs: &[u32]) -> Vec<u32> {
        let device = &ctx.device;
        let module = device.create_shader_module(wgpu::ShaderModuleDescriptor {
            label: Some("twin test"),
            source: wgpu::ShaderSource::Wgsl(self.source(scene.scene.layout).into()),
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
        // The scene bindings the functions under test may read (group 0), as `gpu_scene.wgsl`
        // numbers them.
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
                storage(1, true),
                storage(2, true),
                storage(3, true),
                storage(4, true),
                storage(5, true),
                storage(8, true),
                storage(9, true),
                storage(20, true),
                storage(21, true),
                storage(22, true),
                storage(26, true),
                storage(27, true),
                storage(28, true),
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
        let constants = [
            ("SOBOL", f64::from(u8::from(self.sobol))),
            (
                "HAS_INSTANCES",
                f64::from(u8::from(scene.scene.features.instances)),
            ),
        ];
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
        // An empty array is bound as zeros (a binding holds at least one record).
        let storage_buffer = |bytes: &[u8]| {
            let mut contents = bytes.to_vec();
            contents.resize(contents.len().max(256), 0);
            buffer(&contents, wgpu::BufferUsages::STORAGE)
        };
        let g = &scene.scene;
        let input = buffer(bytemuck::cast_slice(inputs), wgpu::BufferUsages::STORAGE);
        let frame = buffer(
            bytemuck::bytes_of(&scene.frame),
            wgpu::BufferUsages::UNIFORM,
        );
        let scene_buffers = [
            (1, storage_buffer(bytemuck::cast_slice(&g.triangles))),
            (2, storage_buffer(bytemuck::cast_slice(&g.shading))),
            (3, storage_buffer(bytemuck::cast_slice(&g.materials))),
            (4, storage_buffer(g.node_bytes())),
            (5, storage_buffer(bytemuck::cast_slice(&g.texels))),
            (8, storage_buffer(bytemuck::cast_slice(&g.emitters))),
            (9, storage_buffer(bytemuck::cast_slice(&g.delta_lights))),
            (20, storage_buffer(bytemuck::cast_slice(&g.env_texels))),
            (21, storage_buffer(bytemuck::cast_slice(&g.albedo_tables))),
            (22, storage_buffer(bytemuck::cast_slice(&g.tangents))),
            (26, storage_buffer(bytemuck::cast_slice(&g.light_tree))),
            (27, storage_buffer(bytemuck::cast_slice(&g.instances))),
            (28, storage_buffer(bytemuck::cast_slice(&g.instance_nodes))),
        ];
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
        let mut scene_entries = vec![(0, &frame)];
        scene_entries.extend(scene_buffers.iter().map(|(binding, b)| (*binding, b)));
        let scene_group = bind(&scene_layout, &scene_entries);
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
pub(crate) fn inputs(words: usize, mut item: impl FnMut(&mut Rng) -> Vec<u32>) -> Vec<u32> {
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
pub(crate) fn unit(rng: &mut Rng) -> Vec3 {
    let z = 1.0 - 2.0 * rng.next_f32();
    let phi = std::f32::consts::TAU * rng.next_f32();
    let r = (1.0 - z * z).max(0.0).sqrt();
    Vec3::new(r * phi.cos(), r * phi.sin(), z)
}

pub(crate) fn bits(v: &[f32]) -> Vec<u32> {
    v.iter().map(|x| x.to_bits()).collect()
}

/// Compares item by item, word by word: `expected` is the Rust twin's output for an item. Float
/// words agree within `rel` of their size or within `abs` (near zero); NaN only with NaN.
pub(crate) struct Comparison {
    name: &'static str,
    rel: f32,
    abs: f32,
    /// Outputs that are integers (compared exactly), by word index within an item.
    exact_words: &'static [usize],
}

impl Comparison {
    /// `gpu` holds `words` words per item; `expected(item)` is the Rust twin's output for it.
    pub(crate) fn check(&self, gpu: &[u32], words: usize, expected: impl FnMut(usize) -> Vec<u32>) {
        let rows: Vec<Vec<u32>> = (0..gpu.len() / words).map(expected).collect();
        self.check_rows(gpu, words, &rows);
    }

    pub(crate) fn check_rows(&self, gpu: &[u32], words: usize, rows: &[Vec<u32>]) {
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

/// The rows of a BSDF twin test to compare, whose GPU output holds per item a sample's validity at
/// word 4 and its direction at words 5–7: `rust(item, wi_gpu)` gives the Rust twin's row (its
/// sample evaluated at the GPU's direction, so a narrow lobe's pdf does not magnify the
/// direction's last-bit differences) and the Rust sample's own direction. An item whose sample
/// took another lobe on the two sides (a threshold met within a last-bit difference of a Fresnel
/// term) is set aside and counted: at most one in 500 may.
pub(crate) fn same_lobe_rows(
    name: &str,
    gpu_out: &[u32],
    words: usize,
    rust: impl Fn(usize, Vec3) -> (Vec<u32>, Option<Vec3>),
) -> (Vec<u32>, Vec<Vec<u32>>) {
    let mut other_branch = 0;
    let (mut gpu_kept, mut rust_kept) = (Vec::new(), Vec::new());
    for item in 0..ITEMS {
        let g = &gpu_out[item * words..(item + 1) * words];
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
    eprintln!("{name}: {other_branch} of {ITEMS} samples took another lobe");
    assert!(
        other_branch * 500 <= ITEMS,
        "{name}: {other_branch} of {ITEMS} samples took another lobe on the GPU"
    );
    (gpu_kept, rust_kept)
}

/// The head of a BSDF twin test's Rust row (words 0–11): f·cos and pdf towards `wi`, whether the
/// sample drew a direction, and if so the GPU's direction with the weight and pdf there (see
/// `same_lobe_rows`).
pub(crate) fn bsdf_row(
    eval: impl Fn(Vec3) -> (Vec3, f32),
    wi: Vec3,
    drawn: bool,
    wi_gpu: Vec3,
) -> Vec<u32> {
    let (e, pdf) = eval(wi);
    let (f_s, pdf_s) = eval(wi_gpu);
    let (wi_s, w, p) = if drawn {
        (wi_gpu, f_s / pdf_s, pdf_s)
    } else {
        (Vec3::ZERO, Vec3::ZERO, 0.0)
    };
    let mut out = bits(&[e.x, e.y, e.z, pdf]);
    out.push(u32::from(drawn));
    out.extend(bits(&[wi_s.x, wi_s.y, wi_s.z, w.x, w.y, w.z, p]));
    out
}
