// BVH2 traversal: the nearest hit, or with `any_hit` the first found (shadow rays). Needs storage
// bindings `nodes: array<BvhNode>` and `intersect_triangle_at(ray, index, t_max)` (gpu_scene.wgsl).
// Mirrors crates/core/src/estimator/bvh.rs: each node holds both children's boxes; leaves are tested at once and
// inner children visited near first.

alias BvhNodeRecord = BvhNode;

const BVH_STACK_SIZE: u32 = 64u; // core::bvh::MAX_BVH_DEPTH
// Each invocation's traversal stack, in work-group memory: 64 invocations at most
// (rt_gpu::MAX_WORKGROUP_INVOCATIONS) x 64 entries = 16 KiB, the default limit. On lavapipe this was
// 1.3-1.5x faster on the Cornell box scenes than a private array (docs/performance.md), which it
// keeps in scratch memory. The entry point sets `stack_base` from its local invocation index.
var<workgroup> bvh_stacks: array<u32, 4096>;
var<private> stack_base: u32;

// The nearest hit (or with `any_hit` the first) in the BVH whose root is node `root`: the
// world-space triangles' (0) or an instanced mesh's (instance_bvh.wgsl).
fn intersect_mesh(root: u32, origin: vec3<f32>, direction: vec3<f32>, t_max: f32, any_hit: bool) -> Hit {
    let ray = prepare_ray(origin, direction);
    var hit = Hit(t_max, MISS, 0.0, 0.0, NO_INSTANCE);
    var sp = 0u;
    var index = root;
    loop {
        let node = nodes[index];
        let tl = intersect_box(ray, node.left_min, node.left_max, hit.t);
        let tr = intersect_box(ray, node.right_min, node.right_max, hit.t);
        // Both leaves' triangles in one loop: first the left range, then the right.
        let nl = select(0u, node.left_count, tl >= 0.0);
        let nr = select(0u, node.right_count, tr >= 0.0);
        for (var k = 0u; k < nl + nr; k++) {
            let i = select(node.right + (k - nl), node.left + k, k < nl);
            let h = intersect_triangle_at(ray, i, hit.t);
            if (h.x > 0.0) {
                hit = Hit(h.x, i, h.y, h.z, NO_INSTANCE);
                if (any_hit) {
                    return hit;
                }
            }
        }
        // Child 0 with no triangles is no child (the root is nobody's child): an empty scene's root
        // has two, whose inverted boxes the slab test cannot tell from a hit.
        let visit_l = tl >= 0.0 && node.left_count == 0u && node.left != 0u && tl < hit.t;
        let visit_r = tr >= 0.0 && node.right_count == 0u && node.right != 0u && tr < hit.t;
        if (visit_l && visit_r) {
            if (sp < BVH_STACK_SIZE) {
                bvh_stacks[stack_base + sp] = select(node.left, node.right, tl <= tr);
                sp++;
            }
            index = select(node.right, node.left, tl <= tr);
        } else if (visit_l) {
            index = node.left;
        } else if (visit_r) {
            index = node.right;
        } else if (sp == 0u) {
            break;
        } else {
            sp--;
            index = bvh_stacks[stack_base + sp];
        }
    }
    return hit;
}
