// The wavefront variant of trace.wgsl (the default; docs/performance.md): the same estimator
// (path.wgsl), but each stage of a path is its own kernel over a queue of paths, so every
// invocation of a dispatch runs the same code:
//   generate: one path per (pixel, sample) of the wave, its camera ray queued (with adaptive
//     sampling a wave's pixels are a run of the list of those still sampling: `wave_slot`);
//   then up to max_depth times (the host stops once the queue is empty):
//     extend:  the nearest hit of each queued ray;
//     shade:   each queued path's vertex (shade_vertex): light seen there added, a shadow ray queued
//              for next-event estimation, the path re-queued if it goes on;
//     connect: each shadow ray traced, its contribution added to its path if unoccluded;
//     advance: (one invocation) the next queue becomes current;
//   finish: each pixel's samples added to its exact sums (accumulation.wgsl), as the megakernel
//           does, so the two give the same image.
// Composed with the estimator's files in crates/core/src (see crates/gpu/src/shaders.rs).

// [0]: rays traced; [1]: samples dropped as NaN/Inf.
@group(0) @binding(7) var<storage, read_write> counters: array<atomic<u32>, 2>;
// With WRITE_AOVS, per pixel of the tile: running means of the first hit's albedo, normal and the
// light seen directly (as in trace.wgsl); and per path of the wave, its sample's three values.
@group(0) @binding(10) var<storage, read_write> aovs: array<vec4<f32>>;
@group(0) @binding(16) var<storage, read_write> path_aovs: array<vec4<f32>>;

struct WavePath {
    path: PathState,
    rng: Sampler,
    hit: Hit,
}

// Queue lengths and the indirect dispatch size over the current queue. Rust mirror:
// rt_gpu::wavefront::WaveQueues (its layout is checked against this one).
struct WaveQueues {
    // Work groups (x, y, z) for extend, shade and connect: ceil(rays / 64), 1, 1.
    groups_x: u32,
    groups_y: u32,
    groups_z: u32,
    // Paths in the current queue, in the next, and shadow rays of this depth.
    rays: atomic<u32>,
    next_rays: atomic<u32>,
    shadows: atomic<u32>,
    // Which half of `ray_queues` is current (0 or 1).
    parity: u32,
    _pad: u32,
}

// Path i of the wave is sample i / band_pixels of the wave's pixel i % band_pixels (`wave_slot`).
@group(0) @binding(12) var<storage, read_write> paths: array<WavePath>;
// Two queues of path indices, `arrayLength / 2` each: the current one and the next.
@group(0) @binding(13) var<storage, read_write> ray_queues: array<u32>;
@group(0) @binding(14) var<storage, read_write> shadow_rays: array<ShadowRay>;
@group(0) @binding(15) var<storage, read_write> queues: WaveQueues;
// Adaptive sampling: the tile slots of the pixels still sampling, ascending (rebuilt by the
// renderer whenever pixels stop); a placeholder otherwise.
@group(0) @binding(19) var<storage, read> active_slots: array<u32>;

const WAVE_GROUP: u32 = 64u;

fn band_pixels() -> u32 {
    if (ADAPTIVE) {
        return frame.active_count;
    }
    return (frame.row_end - frame.row_begin) * frame.width;
}

// The accumulation slot (pixel of the tile) of the wave's pixel `k`: the band's k-th pixel, or with
// adaptive sampling the k-th of its list of pixels still sampling.
fn wave_slot(k: u32) -> u32 {
    if (ADAPTIVE) {
        return active_slots[frame.active_begin + k];
    }
    return (frame.row_begin - frame.tile_row_begin) * frame.width + k;
}

fn current_queue() -> u32 {
    return queues.parity * (arrayLength(&ray_queues) / 2u);
}

@compute @workgroup_size(WAVE_GROUP, 1, 1)
fn generate(@builtin(global_invocation_id) gid: vec3<u32>) {
    let i = gid.x;
    let band = band_pixels();
    if (i >= band * frame.samples_this_dispatch) {
        return;
    }
    let slot = wave_slot(i % band);
    let x = slot % frame.width;
    let y = frame.tile_row_begin + slot / frame.width;
    var rng = rng_init(film_pixel(x, y), frame.sample_offset + frame.sample_base + i / band, frame.seed);
    let path = start_path(x, y, &rng);
    paths[i] = WavePath(path, rng, Hit(0.0, MISS, 0.0, 0.0, NO_INSTANCE));
    ray_queues[i] = i;
    if (WRITE_AOVS) {
        // Stay zero if the path never reaches a vertex (max depth 0).
        for (var k = 0u; k < AOV_VECS; k++) {
            path_aovs[AOV_VECS * i + k] = vec4(0.0);
        }
    }
}

@compute @workgroup_size(WAVE_GROUP, 1, 1)
fn extend(@builtin(global_invocation_id) gid: vec3<u32>, @builtin(local_invocation_index) lid: u32) {
    stack_base = lid * BVH_STACK_SIZE;
    if (gid.x >= atomicLoad(&queues.rays)) {
        return;
    }
    let p = ray_queues[current_queue() + gid.x];
    paths[p].hit = intersect_scene(paths[p].path.origin, paths[p].path.direction, 3.0e38, false);
}

@compute @workgroup_size(WAVE_GROUP, 1, 1)
fn shade(@builtin(global_invocation_id) gid: vec3<u32>, @builtin(local_invocation_index) lid: u32) {
    stack_base = lid * BVH_STACK_SIZE;
    if (gid.x >= atomicLoad(&queues.rays)) {
        return;
    }
    let p = ray_queues[current_queue() + gid.x];
    var path = paths[p].path;
    var rng = paths[p].rng;
    var shadow: ShadowRay;
    var rays = 0u;
    let first = path.depth == 0u;
    reset_aov_sample();
    let goes_on = shade_vertex(&path, paths[p].hit, &rng, &shadow, true, &rays);
    if (WRITE_AOVS && first) {
        let values = aov_sample_values();
        let a = AOV_VECS * p;
        path_aovs[a] = values.albedo;
        path_aovs[a + 1u] = values.normal;
        path_aovs[a + 2u] = values.emission;
        path_aovs[a + 3u] = values.caught;
    }
    paths[p].path = path;
    paths[p].rng = rng;
    if (shadow.distance > 0.0) {
        shadow.path = p;
        shadow_rays[atomicAdd(&queues.shadows, 1u)] = shadow;
    }
    if (goes_on) {
        let next = (1u - queues.parity) * (arrayLength(&ray_queues) / 2u);
        ray_queues[next + atomicAdd(&queues.next_rays, 1u)] = p;
    }
    // Delta-light rays, traced in shade_vertex (extend and connect rays are counted by advance).
    if (COUNT_RAYS && rays > 0u) {
        atomicAdd(&counters[0], rays);
    }
}

@compute @workgroup_size(WAVE_GROUP, 1, 1)
fn connect(@builtin(global_invocation_id) gid: vec3<u32>, @builtin(local_invocation_index) lid: u32) {
    stack_base = lid * BVH_STACK_SIZE;
    if (gid.x >= atomicLoad(&queues.shadows)) {
        return;
    }
    let shadow = shadow_rays[gid.x];
    if (intersect_scene(shadow.origin, shadow.direction, shadow.distance, true).triangle == MISS) {
        // One shadow ray per path and depth: no other invocation touches this path.
        paths[shadow.path].path.radiance += shadow.contribution;
    }
}

@compute @workgroup_size(1, 1, 1)
fn advance() {
    let next = atomicLoad(&queues.next_rays);
    if (COUNT_RAYS) {
        atomicAdd(&counters[0], atomicLoad(&queues.rays) + atomicLoad(&queues.shadows));
    }
    atomicStore(&queues.rays, next);
    atomicStore(&queues.next_rays, 0u);
    atomicStore(&queues.shadows, 0u);
    queues.parity = 1u - queues.parity;
    queues.groups_x = (next + WAVE_GROUP - 1u) / WAVE_GROUP;
}

@compute @workgroup_size(WAVE_GROUP, 1, 1)
fn finish(@builtin(global_invocation_id) gid: vec3<u32>) {
    let band = band_pixels();
    if (gid.x >= band) {
        return;
    }
    let slot = wave_slot(gid.x);
    var sums = load_pixel_sums(slot);
    var aov_means: AovMeans;
    if (WRITE_AOVS) {
        aov_means = load_aov_means(slot);
    }
    var dropped = 0u;
    for (var s = 0u; s < frame.samples_this_dispatch; s++) {
        let i = s * band + gid.x;
        let l = paths[i].path.radiance;
        if (sample_is_kept(l)) {
            add_sample(&sums, l);
        } else {
            dropped += 1u;
        }
        let n = f32(frame.sample_base + s + 1u);
        if (WRITE_AOVS) {
            let a = AOV_VECS * i;
            let values = AovMeans(path_aovs[a], path_aovs[a + 1u], path_aovs[a + 2u], path_aovs[a + 3u]);
            add_aov_sample(&aov_means, values, n);
        }
    }
    store_pixel_sums(slot, sums);
    if (WRITE_AOVS) {
        store_aov_means(slot, aov_means);
    }
    if (dropped > 0u) {
        atomicAdd(&counters[1], dropped);
    }
}
