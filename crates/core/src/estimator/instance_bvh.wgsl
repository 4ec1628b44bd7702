// The scene's nearest hit with instances (instance_bvh.rs beside it): the world-space triangles'
// BVH (node 0), then the top-level BVH2 over the instances' world boxes (`instance_nodes`), each
// instance entered by carrying the ray into its mesh's space (instances.wgsl) and tracing its
// mesh's BVH (`intersect_mesh` of bvh.wgsl or cwbvh.wgsl).

const INSTANCE_STACK_SIZE: u32 = 64u; // core::bvh::MAX_BVH_DEPTH

fn intersect_scene(origin: vec3<f32>, direction: vec3<f32>, t_max: f32, any_hit: bool) -> Hit {
    let hit = intersect_mesh(0u, origin, direction, t_max, any_hit);
    if (!HAS_INSTANCES || (any_hit && hit.triangle != MISS)) {
        return hit;
    }
    return trace_instances(origin, direction, hit, any_hit);
}

// `hit` narrowed by the instances the ray meets before `hit.t` (with `any_hit`, the first found).
// The top level keeps its own stack: a mesh's traversal below it uses the work-group one.
fn trace_instances(origin: vec3<f32>, direction: vec3<f32>, first: Hit, any_hit: bool) -> Hit {
    let ray = prepare_ray(origin, direction);
    var hit = first;
    var stack: array<u32, INSTANCE_STACK_SIZE>;
    var sp = 0u;
    var index = 0u;
    loop {
        let node = instance_nodes[index];
        let tl = intersect_box(ray, node.left_min, node.left_max, hit.t);
        let tr = intersect_box(ray, node.right_min, node.right_max, hit.t);
        let nl = select(0u, node.left_count, tl >= 0.0);
        let nr = select(0u, node.right_count, tr >= 0.0);
        for (var k = 0u; k < nl + nr; k++) {
            let i = select(node.right + (k - nl), node.left + k, k < nl);
            let inst = instances[i];
            let o = instance_point(inst, origin);
            let d = instance_direction(inst, direction);
            let found = intersect_mesh(inst.root, o, d, hit.t, any_hit);
            if (found.triangle != MISS) {
                hit = Hit(found.t, found.triangle, found.b1, found.b2, i);
                if (any_hit) {
                    return hit;
                }
            }
        }
        let visit_l = tl >= 0.0 && node.left_count == 0u && node.left != 0u && tl < hit.t;
        let visit_r = tr >= 0.0 && node.right_count == 0u && node.right != 0u && tr < hit.t;
        if (visit_l && visit_r) {
            if (sp < INSTANCE_STACK_SIZE) {
                stack[sp] = select(node.left, node.right, tl <= tr);
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
            index = stack[sp];
        }
    }
    return hit;
}
