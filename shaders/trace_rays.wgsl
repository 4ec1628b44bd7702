// Test kernel: the nearest hit of each ray through the same BVH traversal as trace.wgsl.
// Composed with gpu_types.wgsl, intersect.wgsl and bvh.wgsl (crates/core/src, beside their twins).

@group(0) @binding(0) var<storage, read> rays_in: array<Ray>;
@group(0) @binding(1) var<storage, read> triangles: array<Triangle>;
@group(0) @binding(2) var<storage, read> nodes: array<BvhNodeRecord>;
@group(0) @binding(3) var<storage, read_write> hits: array<Hit>;

// The traversals' test kernel meets opaque triangles only (ray_query.wgsl asks).
const HAS_ALPHA: bool = false;

fn stops_ray_at(ray: PreparedRay, i: u32, b1: f32, b2: f32) -> bool {
    return true;
}

// Nor any instance (its scenes are world-space triangles): ray_query.wgsl's custom data is 0.
fn instance_first_triangle(k: u32) -> u32 {
    return 0u;
}

fn intersect_triangle_at(ray: PreparedRay, i: u32, t_max: f32) -> vec3<f32> {
    let tri = triangles[i];
    return intersect_triangle(ray, tri.v0, tri.v1, tri.v2, t_max);
}

@compute @workgroup_size(64, 1, 1)
fn main(@builtin(global_invocation_id) gid: vec3<u32>, @builtin(local_invocation_index) lid: u32) {
    stack_base = lid * BVH_STACK_SIZE;
    let i = gid.x;
    if (i >= arrayLength(&rays_in)) {
        return;
    }
    let ray = rays_in[i];
    hits[i] = intersect_scene(ray.origin, ray.direction, ray.t_max, false);
}
