//! What memory operations cost per invocation on the adapter (run on lavapipe to see why its
//! traversal is load-bound; docs/performance-log.md, "What lavapipe's kernels spend their time on"):
//!
//!     cargo run --release -p rt-gpu --example lavapipe_costs
//!
//! Each kernel runs 1,000 dependent steps per invocation over 64 Ki invocations; the time per step
//! minus the no-load kernel's is the cost of one 16-byte load (or one queue push) per invocation.
//! Not a test: timings are machine-specific.

use std::time::Instant;

use rt_gpu::{AdapterChoice, GpuContext};
use wgpu::util::DeviceExt;

const LOADS: &str = r#"
@group(0) @binding(0) var<storage, read> data: array<vec4<u32>>;
@group(0) @binding(1) var<uniform> small: array<vec4<u32>, 256>;
@group(0) @binding(2) var texels: texture_2d<u32>;
@group(0) @binding(3) var<storage, read_write> out: array<u32>;
override MODE: u32 = 0u;
@compute @workgroup_size(64)
fn main(@builtin(global_invocation_id) gid: vec3<u32>) {
    var state = gid.x * 2654435761u;
    var acc = vec4(0u);
    for (var k = 0u; k < 1000u; k++) {
        state = state * 1664525u + 1013904223u;
        let j = (state >> 8u) & 255u;
        var v = vec4(state, state * 3u, state ^ 7u, state + 1u);
        switch MODE {
            case 1u: { v = data[j]; }
            case 2u: { v = data[k & 255u]; }
            case 3u: { v = textureLoad(texels, vec2(j, 0u), 0); }
            case 4u: { v = small[j]; }
            default: {}
        }
        acc ^= v;
        state ^= v.x & 1u;
    }
    out[gid.x] = acc.x ^ acc.y ^ acc.z ^ acc.w;
}
"#;

const PUSHES: &str = r#"
@group(0) @binding(0) var<storage, read_write> length: atomic<u32>;
@group(0) @binding(1) var<storage, read_write> queue: array<u32>;
override MODE: u32 = 0u;
var<workgroup> group_length: atomic<u32>;
var<workgroup> group_base: u32;
@compute @workgroup_size(64)
fn main(@builtin(global_invocation_id) gid: vec3<u32>, @builtin(local_invocation_index) lid: u32) {
    let keep = ((gid.x * 2654435761u) >> 31u) == 0u;
    if (MODE == 0u) {
        if (keep) { queue[gid.x] = gid.x; }
    } else if (MODE == 1u) {
        if (keep) { queue[atomicAdd(&length, 1u)] = gid.x; }
    } else {
        var slot = 0u;
        if (keep) { slot = atomicAdd(&group_length, 1u); }
        workgroupBarrier();
        if (lid == 0u) { group_base = atomicAdd(&length, atomicLoad(&group_length)); }
        workgroupBarrier();
        if (keep) { queue[group_base + slot] = gid.x; }
    }
}
"#;

const INVOCATIONS: u32 = 1 << 16;

fn pipeline(ctx: &GpuContext, source: &str, mode: u32) -> wgpu::ComputePipeline {
    let module = ctx
        .device
        .create_shader_module(wgpu::ShaderModuleDescriptor {
            label: None,
            source: wgpu::ShaderSource::Wgsl(source.into()),
        });
    ctx.device
        .create_compute_pipeline(&wgpu::ComputePipelineDescriptor {
            label: None,
            layout: None,
            module: &module,
            entry_point: Some("main"),
            compilation_options: wgpu::PipelineCompilationOptions {
                constants: &[("MODE", f64::from(mode))],
                ..Default::default()
            },
            cache: None,
        })
}

/// The best of five runs of `groups` work groups, in seconds.
fn time(
    ctx: &GpuContext,
    pipeline: &wgpu::ComputePipeline,
    bind: &wgpu::BindGroup,
    groups: u32,
    clear: Option<&wgpu::Buffer>,
) -> f64 {
    (0..5)
        .map(|_| {
            let mut encoder = ctx.device.create_command_encoder(&Default::default());
            if let Some(buffer) = clear {
                encoder.clear_buffer(buffer, 0, None);
            }
            {
                let mut pass = encoder.begin_compute_pass(&Default::default());
                pass.set_pipeline(pipeline);
                pass.set_bind_group(0, bind, &[]);
                pass.dispatch_workgroups(groups, 1, 1);
            }
            let started = Instant::now();
            ctx.queue.submit([encoder.finish()]);
            ctx.device
                .poll(wgpu::PollType::wait_indefinitely())
                .expect("device lost");
            started.elapsed().as_secs_f64()
        })
        .fold(f64::INFINITY, f64::min)
}

/// A bind group of `pipeline`'s group 0 with `resources` at bindings 0, 1, 2, …
fn bind_group<'a>(
    ctx: &GpuContext,
    pipeline: &wgpu::ComputePipeline,
    resources: impl IntoIterator<Item = wgpu::BindingResource<'a>>,
) -> wgpu::BindGroup {
    let entries: Vec<wgpu::BindGroupEntry> = resources
        .into_iter()
        .zip(0..)
        .map(|(resource, binding)| wgpu::BindGroupEntry { binding, resource })
        .collect();
    ctx.device.create_bind_group(&wgpu::BindGroupDescriptor {
        label: None,
        layout: &pipeline.get_bind_group_layout(0),
        entries: &entries,
    })
}

fn buffer(ctx: &GpuContext, contents: &[u8], usage: wgpu::BufferUsages) -> wgpu::Buffer {
    ctx.device
        .create_buffer_init(&wgpu::util::BufferInitDescriptor {
            label: None,
            contents,
            usage,
        })
}

fn main() -> Result<(), rt_gpu::GpuError> {
    let ctx = GpuContext::new(&AdapterChoice::Software)?;
    println!("adapter: {}", ctx.adapter_label());
    let words: Vec<u32> = (0..1024u32)
        .map(|i| i.wrapping_mul(2_654_435_761))
        .collect();
    let data = buffer(
        &ctx,
        bytemuck::cast_slice(&words),
        wgpu::BufferUsages::STORAGE,
    );
    let small = buffer(
        &ctx,
        bytemuck::cast_slice(&words),
        wgpu::BufferUsages::UNIFORM,
    );
    let texture = ctx.device.create_texture_with_data(
        &ctx.queue,
        &wgpu::TextureDescriptor {
            label: None,
            size: wgpu::Extent3d {
                width: 256,
                height: 1,
                depth_or_array_layers: 1,
            },
            mip_level_count: 1,
            sample_count: 1,
            dimension: wgpu::TextureDimension::D2,
            format: wgpu::TextureFormat::Rgba32Uint,
            usage: wgpu::TextureUsages::TEXTURE_BINDING,
            view_formats: &[],
        },
        wgpu::util::TextureDataOrder::LayerMajor,
        bytemuck::cast_slice(&words),
    );
    let view = texture.create_view(&Default::default());
    let out = buffer(
        &ctx,
        &vec![0u8; INVOCATIONS as usize * 4],
        wgpu::BufferUsages::STORAGE,
    );
    let steps = f64::from(INVOCATIONS) * 1000.0;
    let mut baseline = 0.0;
    for (mode, name) in [
        (0, "no load (baseline)"),
        (1, "storage buffer, divergent index"),
        (2, "storage buffer, uniform index"),
        (3, "texture (rgba32uint) textureLoad"),
        (4, "uniform buffer, divergent index"),
    ] {
        let pipeline = pipeline(&ctx, LOADS, mode);
        let bind = bind_group(
            &ctx,
            &pipeline,
            [
                data.as_entire_binding(),
                small.as_entire_binding(),
                wgpu::BindingResource::TextureView(&view),
                out.as_entire_binding(),
            ],
        );
        let ns = time(&ctx, &pipeline, &bind, INVOCATIONS / 64, None) * 1e9 / steps;
        if mode == 0 {
            baseline = ns;
            println!("{name:36} {ns:6.2} ns per step");
        } else {
            println!("{name:36} {:6.2} ns per 16-byte load", ns - baseline);
        }
    }
    let pushes = INVOCATIONS * 32;
    let length = buffer(
        &ctx,
        &[0; 4],
        wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_DST,
    );
    let queue = buffer(
        &ctx,
        &vec![0u8; pushes as usize * 4],
        wgpu::BufferUsages::STORAGE,
    );
    let mut baseline = 0.0;
    for (mode, name) in [
        (0, "store, no queue (baseline)"),
        (1, "push: one global atomicAdd each"),
        (2, "push: one per work group (barriers)"),
    ] {
        let pipeline = pipeline(&ctx, PUSHES, mode);
        let bind = bind_group(
            &ctx,
            &pipeline,
            [length.as_entire_binding(), queue.as_entire_binding()],
        );
        // Half the invocations push.
        let ns =
            time(&ctx, &pipeline, &bind, pushes / 64, Some(&length)) * 1e9 / f64::from(pushes / 2);
        if mode == 0 {
            baseline = ns;
            println!("{name:36} {ns:6.2} ns per pushing invocation");
        } else {
            println!("{name:36} {:6.2} ns more per push", ns - baseline);
        }
    }
    Ok(())
}
