enable wgpu_ray_query;

// Traversal by the driver's ray queries (Vulkan VK_KHR_ray_query, DX12 DXR 1.1, Metal; lavapipe
// >= 24.1 in software) over bottom-level structures in the order of `triangles` (rt_gpu::accel):
// the world-space triangles' (custom data 0: a hit's primitive index is rt's triangle index) and
// each shared mesh's under an instance per copy (custom data k + 1 for rt's instance k: its
// primitives count from the mesh's `first_triangle`; the hit carries the instance, which
// `hit_triangle` places in the world as after rt's own traversal). Stands in
// for bvh.wgsl or cwbvh.wgsl (the same `intersect_scene`); the `nodes` binding stays
// declared (gpu_scene.wgsl) but is not read, and there is no traversal stack.
// This file is first in its modules: WGSL wants the `enable` before any declaration.

alias BvhNodeRecord = BvhNode;

const BVH_STACK_SIZE: u32 = 64u;
// Set by the entry points for the software traversals' stacks; unused here.
var<private> stack_base: u32;

@group(0) @binding(17) var scene_tlas: acceleration_structure;

// rt's triangle index and instance of a driver's hit (see the head of this file).
fn query_hit(custom_data: u32, primitive: u32) -> vec2<u32> {
    if (custom_data == 0u) {
        return vec2<u32>(primitive, NO_INSTANCE);
    }
    let k = custom_data - 1u;
    return vec2<u32>(instance_first_triangle(k) + primitive, k);
}

fn intersect_scene(origin: vec3<f32>, direction: vec3<f32>, t_max: f32, any_hit: bool) -> Hit {
    // With alpha the geometry is built non-opaque (rt_gpu::accel), so the driver hands each hit
    // over as a candidate that `stops_ray` confirms or lets pass.
    var flags = select(RAY_FLAG_FORCE_OPAQUE, RAY_FLAG_NONE, HAS_ALPHA);
    if (any_hit) {
        flags |= RAY_FLAG_TERMINATE_ON_FIRST_HIT;
    }
    var query: ray_query;
    // t_min 0: the estimator offsets ray origins off the surface (intersect.wgsl), as the
    // software traversals need; the BVH code accepts any t > 0 likewise.
    rayQueryInitialize(&query, scene_tlas, RayDesc(flags, 0xffu, 0.0, t_max, origin, direction));
    if (HAS_ALPHA) {
        let ray = prepare_ray(origin, direction);
        while (rayQueryProceed(&query)) {
            let c = rayQueryGetCandidateIntersection(&query);
            // Only world-space triangles have holes: instanced meshes are opaque.
            let i = query_hit(c.instance_custom_data, c.primitive_index).x;
            if (c.kind == RAY_QUERY_INTERSECTION_TRIANGLE && stops_ray_at(ray, i, c.barycentrics.x, c.barycentrics.y)) {
                rayQueryConfirmIntersection(&query);
            }
        }
    } else {
        rayQueryProceed(&query);
    }
    let found = rayQueryGetCommittedIntersection(&query);
    if (found.kind == RAY_QUERY_INTERSECTION_NONE) {
        return Hit(t_max, MISS, 0.0, 0.0, NO_INSTANCE);
    }
    let at = query_hit(found.instance_custom_data, found.primitive_index);
    return Hit(found.t, at.x, found.barycentrics.x, found.barycentrics.y, at.y);
}
