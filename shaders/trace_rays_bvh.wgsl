// The traversal test kernel's `intersect_scene` over rt's BVH (trace_rays.wgsl; ray_query.wgsl has
// its own): its scenes are flat, so the world-space triangles' BVH is all there is.
fn intersect_scene(origin: vec3<f32>, direction: vec3<f32>, t_max: f32, any_hit: bool) -> Hit {
    return intersect_mesh(0u, origin, direction, t_max, any_hit);
}
