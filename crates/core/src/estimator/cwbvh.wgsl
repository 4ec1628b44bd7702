// Compressed wide BVH8 traversal (Ylitie, Karras and Laine, HPG 2017): the nearest hit, or with
// `any_hit` the first found (shadow rays). Needs storage bindings `nodes: array<BvhNodeRecord>` and
// `intersect_triangle_at(ray, index, t_max)` (gpu_scene.wgsl). Mirrors core::estimator::cwbvh, whose
// module doc explains the hit masks and groups.

alias BvhNodeRecord = WideBvhNode;

const BVH_STACK_SIZE: u32 = 32u; // core::bvh::MAX_WIDE_BVH_DEPTH
// Each invocation's stack of groups (child base, ranks | inner-slot mask), in work-group memory as in
// bvh.wgsl: 64 invocations at most x 32 entries x 8 bytes = 16 KiB. The entry point sets
// `stack_base` from its local invocation index.
var<workgroup> bvh_stacks: array<vec2<u32>, 2048>;
var<private> stack_base: u32;

const INNER_BITS: u32 = 0xff000000u;

// The hit bits of four children whose bytes are packed in these words (see wide_bvh::child_hits).
fn wide_child_hits4(slots: u32, lo_x: u32, hi_x: u32, lo_y: u32, hi_y: u32, lo_z: u32, hi_z: u32,
                    scaled_inv: vec3<f32>, shifted_origin: vec3<f32>, neg: vec3<bool>,
                    oct_inv4: u32, t_max: f32) -> u32 {
    let lx = vec4<f32>(unpack4xU8(lo_x));
    let hx = vec4<f32>(unpack4xU8(hi_x));
    let ly = vec4<f32>(unpack4xU8(lo_y));
    let hy = vec4<f32>(unpack4xU8(hi_y));
    let lz = vec4<f32>(unpack4xU8(lo_z));
    let hz = vec4<f32>(unpack4xU8(hi_z));
    let near_x = select(lx, hx, neg.x) * scaled_inv.x + shifted_origin.x;
    let far_x = select(hx, lx, neg.x) * scaled_inv.x + shifted_origin.x;
    let near_y = select(ly, hy, neg.y) * scaled_inv.y + shifted_origin.y;
    let far_y = select(hy, ly, neg.y) * scaled_inv.y + shifted_origin.y;
    let near_z = select(lz, hz, neg.z) * scaled_inv.z + shifted_origin.z;
    let far_z = select(hz, lz, neg.z) * scaled_inv.z + shifted_origin.z;
    let near = max(max(near_x, near_y), max(near_z, vec4(0.0)));
    let far = min(min(far_x, far_y), far_z) * 1.0000004;
    let entered = (near <= far) & (near < vec4(t_max));
    let inner = (slots & (slots << 1u)) & 0x10101010u;
    let shift = (slots ^ (oct_inv4 & ((inner >> 4u) * 0xffu))) & 0x1f1f1f1fu;
    let bits = (slots >> 5u) & 0x07070707u;
    let h = select(vec4(0u), unpack4xU8(bits) << unpack4xU8(shift), entered);
    return h.x | h.y | h.z | h.w;
}

fn wide_child_hits(node: WideBvhNode, ray: PreparedRay, oct_inv4: u32, neg: vec3<bool>, t_max: f32) -> u32 {
    let e = node.exponents_imask;
    let cell = bitcast<vec3<f32>>(vec3((e & 0xffu) << 23u, ((e >> 8u) & 0xffu) << 23u,
                                       ((e >> 16u) & 0xffu) << 23u));
    let scaled_inv = cell * ray.inv_direction;
    let shifted_origin = (node.origin - ray.origin) * ray.inv_direction;
    return wide_child_hits4(node.slots.x, node.lo_x.x, node.hi_x.x, node.lo_y.x, node.hi_y.x,
                            node.lo_z.x, node.hi_z.x, scaled_inv, shifted_origin, neg, oct_inv4, t_max)
        | wide_child_hits4(node.slots.y, node.lo_x.y, node.hi_x.y, node.lo_y.y, node.hi_y.y,
                           node.lo_z.y, node.hi_z.y, scaled_inv, shifted_origin, neg, oct_inv4, t_max);
}

// The nearest hit (or with `any_hit` the first) in the wide BVH whose root is node `root`: the
// world-space triangles' (0) or an instanced mesh's (instance_bvh.wgsl).
fn intersect_mesh(root: u32, origin: vec3<f32>, direction: vec3<f32>, t_max: f32, any_hit: bool) -> Hit {
    let ray = prepare_ray(origin, direction);
    var hit = Hit(t_max, MISS, 0.0, 0.0, NO_INSTANCE);
    let oct_inv = select(0u, 4u, direction.x >= 0.0) | select(0u, 2u, direction.y >= 0.0)
        | select(0u, 1u, direction.z >= 0.0);
    let oct_inv4 = oct_inv * 0x01010101u;
    let neg = direction < vec3(0.0);
    var sp = 0u;
    // The root is the one inner child (rank 7, no inner slots before it) of a virtual node whose
    // children begin at `root`.
    var group = vec2(root, 0x80000000u);
    var tris = vec2(0u, 0u);
    loop {
        loop {
            if (tris.y == 0u) {
                break;
            }
            let bit = firstTrailingBit(tris.y);
            tris.y &= ~(1u << bit);
            let i = tris.x + bit;
            let h = intersect_triangle_at(ray, i, hit.t);
            if (h.x > 0.0) {
                hit = Hit(h.x, i, h.y, h.z, NO_INSTANCE);
                if (any_hit) {
                    return hit;
                }
            }
        }
        if ((group.y & INNER_BITS) == 0u) {
            if (sp == 0u) {
                break;
            }
            sp--;
            group = bvh_stacks[stack_base + sp];
        }
        let rank_bit = firstLeadingBit(group.y);
        group.y &= ~(1u << rank_bit);
        let slot = (rank_bit - 24u) ^ oct_inv;
        let child = group.x + countOneBits(group.y & 0xffu & ((1u << slot) - 1u));
        if ((group.y & INNER_BITS) != 0u && sp < BVH_STACK_SIZE) {
            bvh_stacks[stack_base + sp] = group;
            sp++;
        }
        let node = nodes[child];
        let hits = wide_child_hits(node, ray, oct_inv4, neg, hit.t);
        group = vec2(node.child_base, (hits & INNER_BITS) | (node.exponents_imask >> 24u));
        tris = vec2(node.primitive_base, hits & ~INNER_BITS);
    }
    return hit;
}
