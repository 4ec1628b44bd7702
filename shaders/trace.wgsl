// The path-tracing megakernel: one invocation per pixel, `frame.samples_this_dispatch` whole paths
// each (path.wgsl's vertices in a loop), added to the pixel's exact sums (accumulation.wgsl) so any number
// of dispatches can be stopped after any one. Composed with the estimator's files in
// crates/core/src (gpu_types, rng, sampling, intersect, bvh or cwbvh, gpu_scene, path, …: see
// crates/gpu/src/shaders.rs).

// [0]: rays traced; [1]: samples dropped as NaN/Inf.
@group(0) @binding(7) var<storage, read_write> counters: array<atomic<u32>, 2>;
// Per pixel of the tile: [3i] running mean of the first hit's albedo, [3i + 1] of its normal,
// [3i + 2] of the light seen directly (emitters and sky at the first segment, which need no
// denoising).
@group(0) @binding(10) var<storage, read_write> aovs: array<vec4<f32>>;

fn path_radiance(x: u32, y: u32, rng: ptr<function, Sampler>, rays: ptr<function, u32>) -> vec3<f32> {
    var path = start_path(x, y, rng);
    var shadow: ShadowRay;
    while (path.depth < frame.max_depth) {
        let hit = intersect_scene(path.origin, path.direction, 3.0e38, false);
        *rays += 1u;
        if (!shade_vertex(&path, hit, rng, &shadow, false, rays)) {
            break;
        }
    }
    return path.radiance;
}

// Work-group shape (measured in docs/performance-log.md; 8 x 8 unless a benchmark asks otherwise).
override WG_X: u32 = 8u;
override WG_Y: u32 = 8u;

@compute @workgroup_size(WG_X, WG_Y, 1)
fn main(@builtin(global_invocation_id) gid: vec3<u32>, @builtin(local_invocation_index) lid: u32) {
    stack_base = lid * BVH_STACK_SIZE;
    let x = gid.x;
    let y = gid.y + frame.row_begin;
    if (x >= frame.width || y >= frame.row_end) {
        return;
    }
    // The pixel's number seeds its random numbers (the same whether or not the image is tiled); the
    // accumulation buffer holds only this tile's rows.
    let pixel = film_pixel(x, y);
    let slot = (y - frame.tile_row_begin) * frame.width + x;
    if (pixel_stopped(slot)) {
        return;
    }
    var sums = load_pixel_sums(slot);
    var aov_means: AovMeans;
    if (WRITE_AOVS) {
        aov_means = load_aov_means(slot);
    }
    var rays = 0u;
    var dropped = 0u;
    for (var s = 0u; s < frame.samples_this_dispatch; s++) {
        let sample_index = frame.sample_offset + frame.sample_base + s;
        var rng = rng_init(pixel, sample_index, frame.seed);
        reset_aov_sample();
        var l = path_radiance(x, y, &rng, &rays);
        if (sample_is_kept(l)) {
            add_sample(&sums, l);
        } else {
            dropped += 1u;
        }
        if (WRITE_AOVS) {
            let values = aov_sample_values();
            add_aov_sample(&aov_means, values, f32(frame.sample_base + s + 1u));
        }
    }
    store_pixel_sums(slot, sums);
    if (WRITE_AOVS) {
        store_aov_means(slot, aov_means);
    }
    if (COUNT_RAYS) {
        atomicAdd(&counters[0], rays);
    }
    if (dropped > 0u) {
        atomicAdd(&counters[1], dropped);
    }
}
