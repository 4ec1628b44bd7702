// BVH2 traversal: the nearest hit, or with `any_hit` the first found (shadow rays). Needs storage bindings `nodes: array<BvhNode>` and
// `triangles: array<Triangle>` from the entry-point file. Mirrors reference::trace.

const BVH_STACK_SIZE: u32 = 64u; // core::bvh::MAX_BVH_DEPTH

fn intersect_scene(origin: vec3<f32>, direction: vec3<f32>, t_max: f32, any_hit: bool) -> Hit {
    let ray = prepare_ray(origin, direction);
    var hit = Hit(t_max, MISS, 0.0, 0.0);
    let root = nodes[0];
    if (intersect_box(ray, root.min, root.max, hit.t) < 0.0) {
        return hit;
    }
    var stack: array<u32, BVH_STACK_SIZE>;
    var sp = 0u;
    var index = 0u;
    loop {
        let node = nodes[index];
        if (node.count > 0u) {
            for (var i = node.first; i < node.first + node.count; i++) {
                let tri = triangles[i];
                let h = intersect_triangle(ray, tri.v0, tri.v1, tri.v2, hit.t);
                if (h.x > 0.0) {
                    hit = Hit(h.x, i, h.y, h.z);
                    if (any_hit) {
                        return hit;
                    }
                }
            }
        } else {
            let l = node.first;
            let r = l + 1u;
            let nl = nodes[l];
            let nr = nodes[r];
            let tl = intersect_box(ray, nl.min, nl.max, hit.t);
            let tr = intersect_box(ray, nr.min, nr.max, hit.t);
            if (tl >= 0.0 && tr >= 0.0) {
                if (sp < BVH_STACK_SIZE) {
                    stack[sp] = select(l, r, tl <= tr);
                    sp++;
                }
                index = select(r, l, tl <= tr);
                continue;
            }
            if (tl >= 0.0) {
                index = l;
                continue;
            }
            if (tr >= 0.0) {
                index = r;
                continue;
            }
        }
        if (sp == 0u) {
            break;
        }
        sp--;
        index = stack[sp];
    }
    return hit;
}
