// Ray-triangle, ray-box and the self-intersection offset; mirrors crates/core/src/math/intersect.rs.

// A ray prepared for the watertight test of Woop, Benthin and Wald (JCGT 2013).
struct PreparedRay {
    origin: vec3<f32>,
    inv_direction: vec3<f32>,
    k: vec3<u32>,
    shear: vec3<f32>,
}

fn prepare_ray(origin: vec3<f32>, direction: vec3<f32>) -> PreparedRay {
    let a = abs(direction);
    var kz = 2u;
    if (a.x > a.y) {
        if (a.x > a.z) { kz = 0u; }
    } else if (a.y > a.z) {
        kz = 1u;
    }
    var kx = (kz + 1u) % 3u;
    var ky = (kx + 1u) % 3u;
    if (direction[kz] < 0.0) {
        let tmp = kx;
        kx = ky;
        ky = tmp;
    }
    let dz = direction[kz];
    // A zero component would give 0 * inf = NaN in the slab test for a ray lying in a box's face
    // plane (min/max of NaN is undefined in WGSL): a tiny positive component instead.
    let safe = select(direction, vec3(1e-30), direction == vec3(0.0));
    return PreparedRay(origin, 1.0 / safe, vec3(kx, ky, kz),
        vec3(direction[kx] / dz, direction[ky] / dz, 1.0 / dz));
}

// Returns (t, b1, b2) with t < 0 for a miss; hits only strictly inside (0, t_max).
fn intersect_triangle(ray: PreparedRay, v0: vec3<f32>, v1: vec3<f32>, v2: vec3<f32>, t_max: f32) -> vec3<f32> {
    let a = v0 - ray.origin;
    let b = v1 - ray.origin;
    let c = v2 - ray.origin;
    let s = ray.shear;
    let kx = ray.k.x;
    let ky = ray.k.y;
    let kz = ray.k.z;
    let ax = a[kx] - s.x * a[kz];
    let ay = a[ky] - s.y * a[kz];
    let bx = b[kx] - s.x * b[kz];
    let by = b[ky] - s.y * b[kz];
    let cx = c[kx] - s.x * c[kz];
    let cy = c[ky] - s.y * c[kz];
    let u = cx * by - cy * bx;
    let v = ax * cy - ay * cx;
    let w = bx * ay - by * ax;
    let miss = vec3(-1.0, 0.0, 0.0);
    if ((u < 0.0 || v < 0.0 || w < 0.0) && (u > 0.0 || v > 0.0 || w > 0.0)) {
        return miss;
    }
    let det = u + v + w;
    if (det == 0.0) {
        return miss;
    }
    let t_scaled = u * (s.z * a[kz]) + v * (s.z * b[kz]) + w * (s.z * c[kz]);
    let t = t_scaled / det;
    if (!(t > 0.0 && t < t_max)) {
        return miss;
    }
    return vec3(t, v / det, w / det);
}

// Entry distance of the slab test, or -1 for a miss; far side widened by 1 + 2*gamma_3 (pbrt).
fn intersect_box(ray: PreparedRay, lo: vec3<f32>, hi: vec3<f32>, t_max: f32) -> f32 {
    let t0 = (lo - ray.origin) * ray.inv_direction;
    let t1 = (hi - ray.origin) * ray.inv_direction;
    let tn = min(t0, t1);
    let tf = max(t0, t1);
    let near = max(max(max(tn.x, tn.y), tn.z), 0.0);
    let far = min(min(tf.x, tf.y), tf.z) * 1.0000004;
    return select(-1.0, near, near <= far && near < t_max);
}

// Offsets a surface point along n by ULPs of its own magnitude (Waechter and Binder, Ray Tracing Gems
// ch. 6); near the origin, where ULPs vanish, by a fixed distance relative to `scale` (the scene's
// extent, at most 1), so a scene a thousandth of a unit wide is not offset by a visible amount.
fn offset_ray_origin(p: vec3<f32>, n: vec3<f32>, scale: f32) -> vec3<f32> {
    let of_i = vec3<i32>(256.0 * n);
    let p_i = bitcast<vec3<f32>>(bitcast<vec3<i32>>(p) + select(of_i, -of_i, p < vec3(0.0)));
    return select(p_i, p + (scale / 65536.0) * n, abs(p) < vec3(scale / 32.0));
}
