// A hit on a triangle of an instance's mesh turned into the world-space triangle the flattened
// scene would hold (instances.rs beside it; the `Instance` records of gpu_types.wgsl). Needs the
// `instances` binding and HAS_INSTANCES (gpu_scene.wgsl).

fn instance_apply(rows: array<vec4<f32>, 3>, v: vec3<f32>, w: f32) -> vec3<f32> {
    return vec3(dot(rows[0], vec4(v, w)), dot(rows[1], vec4(v, w)), dot(rows[2], vec4(v, w)));
}

// A world-space point in the mesh's space (instances.rs `Instance::point_to_object`).
fn instance_point(inst: Instance, p: vec3<f32>) -> vec3<f32> {
    return instance_apply(inst.to_object, p, 1.0);
}

// A world-space direction in the mesh's space, not renormalised: t measures the same distance.
fn instance_direction(inst: Instance, d: vec3<f32>) -> vec3<f32> {
    return instance_apply(inst.to_object, d, 0.0);
}

// A normal to world space: by the inverse transpose of the linear part, whose rows are
// `to_object`'s columns.
fn instance_normal(inst: Instance, n: vec3<f32>) -> vec3<f32> {
    return inst.to_object[0].xyz * n.x + inst.to_object[1].xyz * n.y + inst.to_object[2].xyz * n.z;
}

// glam's `normalize_or_zero`: by the reciprocal length, zero where that is not finite.
fn normalize_or_zero(v: vec3<f32>) -> vec3<f32> {
    let r = 1.0 / length(v);
    return select(vec3(0.0), v * r, r > 0.0 && r < 3.0e38);
}

// `Instance::place`: corners placed, the material the instance's object's, normals by the inverse
// transpose; with a mirror corners 1 and 2 swap (and the hit's barycentrics, by the caller).
fn place_triangle(inst: Instance, tri: ptr<function, Triangle>, sh: ptr<function, Shading>) {
    (*tri).v0 = instance_apply(inst.to_world, (*tri).v0, 1.0);
    (*tri).v1 = instance_apply(inst.to_world, (*tri).v1, 1.0);
    (*tri).v2 = instance_apply(inst.to_world, (*tri).v2, 1.0);
    (*tri).material = inst.material;
    if (((*tri).has_normals & HAS_NORMALS) != 0u) {
        (*sh).n0 = normalize_or_zero(instance_normal(inst, (*sh).n0));
        (*sh).n1 = normalize_or_zero(instance_normal(inst, (*sh).n1));
        (*sh).n2 = normalize_or_zero(instance_normal(inst, (*sh).n2));
    }
    if (inst.mirrored != 0u) {
        let v1 = (*tri).v1;
        (*tri).v1 = (*tri).v2;
        (*tri).v2 = v1;
        let n1 = (*sh).n1;
        (*sh).n1 = (*sh).n2;
        (*sh).n2 = n1;
        let c1 = (*sh).c1;
        (*sh).c1 = (*sh).c2;
        (*sh).c2 = c1;
        let uv1 = (*sh).uv1;
        (*sh).uv1 = (*sh).uv2;
        (*sh).uv2 = uv1;
    }
}

// `Instance::place_tangents`: corner tangents by the transform, handedness flipped and corners
// 1 and 2 swapped with a mirror.
fn place_tangents(inst: Instance, t: array<vec4<f32>, 3>) -> array<vec4<f32>, 3> {
    let sign = select(1.0, -1.0, inst.mirrored != 0u);
    var out: array<vec4<f32>, 3>;
    for (var k = 0u; k < 3u; k++) {
        out[k] = vec4(normalize_or_zero(instance_apply(inst.to_world, t[k].xyz, 0.0)), t[k].w * sign);
    }
    if (inst.mirrored != 0u) {
        let t1 = out[1];
        out[1] = out[2];
        out[2] = t1;
    }
    return out;
}

// The three corner tangents of the triangle `hit` found, in world space (instances.rs
// `hit_triangle`'s `tangents`).
fn hit_tangents(hit: Hit) -> array<vec4<f32>, 3> {
    let i = 3u * hit.triangle;
    let t = array(tangents[i], tangents[i + 1u], tangents[i + 2u]);
    if (HAS_INSTANCES && hit.instance != NO_INSTANCE) {
        return place_tangents(instances[hit.instance], t);
    }
    return t;
}
