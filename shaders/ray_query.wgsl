enable wgpu_ray_query;

// Traversal by the driver's ray queries (Vulkan VK_KHR_ray_query, DX12 DXR 1.1, Metal; lavapipe
// >= 24.1 in software) over one bottom-level structure of every scene triangle, in the order of
// `triangles`, so a hit's primitive index is the triangle index the estimator expects. Stands in
// for bvh.wgsl or cwbvh.wgsl (the same `intersect_scene`); the `nodes` binding stays
// declared (gpu_scene.wgsl) but is not read, and there is no traversal stack.
// This file is first in its modules: WGSL wants the `enable` before any declaration.

alias BvhNodeRecord = BvhNode;

const BVH_STACK_SIZE: u32 = 64u;
// Set by the entry points for the software traversals' stacks; unused here.
var<private> stack_base: u32;

@group(0) @binding(17) var scene_tlas: acceleration_structure;

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
            let i = c.primitive_index;
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
    return Hit(
        found.t, found.primitive_index, found.barycentrics.x, found.barycentrics.y, NO_INSTANCE
    );
}
