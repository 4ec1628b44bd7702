// The scene's bindings, shared by the megakernel (trace.wgsl) and the wavefront kernels
// (wavefront.wgsl); each entry file adds its own outputs at the other binding numbers.

@group(0) @binding(0) var<uniform> frame: Frame;
@group(0) @binding(1) var<storage, read> triangles: array<Triangle>;
// Normals, colours and texture coordinates by corner (corner_records.rs): three words per
// triangle saying where its corners' vertex records begin, then the records (normal xyz, colour,
// uv); a placeholder when no triangle has any.
@group(0) @binding(2) var<storage, read> shading: array<u32>;
@group(0) @binding(3) var<storage, read> materials: array<Material>;
@group(0) @binding(4) var<storage, read> nodes: array<BvhNodeRecord>;
@group(0) @binding(5) var<storage, read> texels: array<u32>;
@group(0) @binding(8) var<storage, read> emitters: array<Emitter>;
@group(0) @binding(9) var<storage, read> delta_lights: array<DeltaLight>;
// The light tree over the emitters (light_tree.rs; a placeholder unless frame.light_sampler == 1).
@group(0) @binding(26) var<storage, read> light_tree: array<LightNode>;
// The environment map's texels (one placeholder without one: frame.env_width == 0).
@group(0) @binding(20) var<storage, read> environment: array<EnvTexel>;
// The white GGX conductor's albedo E(mu, roughness), ENERGY_SIDE x ENERGY_SIDE.
@group(0) @binding(21) var<storage, read> albedo_tables: array<f32>;
// Normal maps: per triangle three corner tangents (xyz, w the bitangent's sign); a placeholder
// without normal maps.
@group(0) @binding(22) var<storage, read> tangents: array<vec4<f32>>;

// Triangle i's shading attributes, gathered from its corners' vertex records; read only where its
// flags say it has some (gpu_scene.rs `stored_shading`).
fn stored_shading(i: u32) -> Shading {
    let a = shading[3u * i];
    let b = shading[3u * i + 1u];
    let c = shading[3u * i + 2u];
    return Shading(
        corner_normal(a), shading[a + 3u],
        corner_normal(b), shading[b + 3u],
        corner_normal(c), shading[c + 3u],
        corner_uv(a), corner_uv(b), corner_uv(c), vec2(0.0)
    );
}

fn corner_normal(o: u32) -> vec3<f32> {
    return bitcast<vec3<f32>>(vec3(shading[o], shading[o + 1u], shading[o + 2u]));
}

fn corner_uv(o: u32) -> vec2<f32> {
    return bitcast<vec2<f32>>(vec2(shading[o + 4u], shading[o + 5u]));
}

// The texture coordinates at the barycentrics (b1, b2) of triangle i (gpu_scene.rs `stored_uv`):
// the corners' UV words only, as the alpha test calls it during traversal.
fn stored_uv(i: u32, b1: f32, b2: f32) -> vec2<f32> {
    let uv0 = corner_uv(shading[3u * i]);
    let uv1 = corner_uv(shading[3u * i + 1u]);
    let uv2 = corner_uv(shading[3u * i + 2u]);
    return uv0 * (1.0 - b1 - b2) + uv1 * b1 + uv2 * b2;
}

// Shared meshes (instances.rs): the placed copies and the top-level BVH2 over their world boxes
// (placeholders, never read, without instances).
override HAS_INSTANCES: bool = false;
@group(0) @binding(27) var<storage, read> instances: array<Instance>;

// The first triangle of instance k's mesh, where the driver's ray queries count its primitives
// from (ray_query.wgsl; the Rust side reads `Instance::first_triangle` directly).
fn instance_first_triangle(k: u32) -> u32 {
    return instances[k].first_triangle;
}
@group(0) @binding(28) var<storage, read> instance_nodes: array<BvhNode>;

// Adaptive sampling: per pixel of the tile, 0 while it takes samples, else the sample count it
// stopped at (the renderer sets it between batches from each pixel's noise estimate). Without
// ADAPTIVE the buffer is a placeholder that is never read.
override ADAPTIVE: bool = false;
@group(0) @binding(18) var<storage, read> pixel_done: array<u32>;

fn pixel_stopped(slot: u32) -> bool {
    return ADAPTIVE && pixel_done[slot] != 0u;
}

// Alpha-masked or blended surfaces: each hit reads its coverage (texture.wgsl `stops_ray`).
override HAS_ALPHA: bool = true;

// The triangle test BVH traversal (bvh.wgsl, cwbvh.wgsl) calls on leaf triangles:
// (t, b1, b2), t < 0 for a miss or a hole.
fn intersect_triangle_at(ray: PreparedRay, i: u32, t_max: f32) -> vec3<f32> {
    let tri = triangles[i];
    let h = intersect_triangle(ray, tri.v0, tri.v1, tri.v2, t_max);
    if (HAS_ALPHA && h.x > 0.0 && !stops_ray(ray, tri, i, h.y, h.z)) {
        return vec3(-1.0, 0.0, 0.0);
    }
    return h;
}
