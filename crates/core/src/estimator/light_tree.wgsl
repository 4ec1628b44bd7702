// Sampling the light tree; mirrors crates/core/src/estimator/light_tree.rs (which gives the
// importance's equation and why each bound is conservative); crates/core/src/light_tree.rs builds it.

const LIGHT_TREE_DEPTH: u32 = 41u; // light_tree.rs MAX_DEPTH
const DELTA_LEAF: u32 = 0x80000000u; // light_tree.rs DELTA_LEAF: a leaf's point or spot light
const NO_NORMAL: u32 = 0x80008000u; // light_tree.rs NO_NORMAL: a vertex lit from both sides
const ONE_MINUS_EPSILON: f32 = 0.99999994;

fn cos_sub_clamped(sin_a: vec4<f32>, cos_a: vec4<f32>, sin_b: vec4<f32>, cos_b: vec4<f32>) -> vec4<f32> {
    return select(cos_a * cos_b + sin_a * sin_b, vec4(1.0), cos_a > cos_b);
}

fn sin_sub_clamped(sin_a: vec4<f32>, cos_a: vec4<f32>, sin_b: vec4<f32>, cos_b: vec4<f32>) -> vec4<f32> {
    return select(sin_a * cos_b - cos_a * sin_b, vec4(0.0), cos_a > cos_b);
}

fn sine4(c: vec4<f32>) -> vec4<f32> {
    return sqrt(max(vec4(1.0) - c * c, vec4(0.0)));
}

// The importance of each of the node's four slots at x with normal n (light_tree.rs
// `slot_importances`; 0 for an empty slot).
fn slot_importances(node: LightNode, x: vec3<f32>, n: vec3<f32>) -> vec4<f32> {
    let tx = vec4(x.x) - node.centre_x;
    let ty = vec4(x.y) - node.centre_y;
    let tz = vec4(x.z) - node.centre_z;
    let d2 = tx * tx + ty * ty + tz * tz;
    let r2 = node.radius * node.radius;
    let inside = node.power / max(r2, vec4(1.17549435e-38));
    let inv_d = vec4(1.0) / sqrt(d2);
    let wx = tx * inv_d;
    let wy = ty * inv_d;
    let wz = tz * inv_d;
    let sin_b = min(node.radius * inv_d, vec4(1.0));
    let cos_b = sine4(sin_b);
    let cos_i = -(wx * n.x + wy * n.y + wz * n.z);
    let cos_pi = select(cos_sub_clamped(sine4(cos_i), cos_i, sin_b, cos_b), vec4(1.0), all(n == vec3(0.0)));
    let cos_w = wx * node.axis_x + wy * node.axis_y + wz * node.axis_z;
    let sin_w = sine4(cos_w);
    let cos_x = cos_sub_clamped(sin_w, cos_w, node.sin_theta_o, node.cos_theta_o);
    let sin_x = sin_sub_clamped(sin_w, cos_w, node.sin_theta_o, node.cos_theta_o);
    let cos_p = cos_sub_clamped(sin_x, cos_x, sin_b, cos_b);
    let lit = (cos_p > node.cos_theta_e) & (cos_pi > vec4(0.0));
    let outside = select(vec4(0.0), node.power * cos_p * cos_pi / d2, lit);
    let value = select(outside, inside, d2 <= r2);
    return select(vec4(0.0), value, node.power > vec4(0.0));
}

// Positive and finite (light_tree.rs `usable`).
fn usable(x: f32) -> bool {
    return x > 0.0 && x <= 3.40282347e38;
}

// The sum of the four importances in a fixed order (light_tree.rs `total`).
fn importance_total(i: vec4<f32>) -> f32 {
    return (i.x + i.y) + (i.z + i.w);
}

// A light (an emitter triangle, or DELTA_LEAF | a delta light's index) and its pmf for the uniform
// number u (light_tree.rs `sample_tree`); pmf 0: none.
struct TreeSample {
    light: u32,
    pmf: f32,
}

fn sample_tree(x: vec3<f32>, n: vec3<f32>, u_in: f32) -> TreeSample {
    var u = u_in;
    var index = 0u;
    var pmf = 1.0;
    for (var depth = 0u; depth < LIGHT_TREE_DEPTH; depth++) {
        let node = light_tree[index];
        let importance = slot_importances(node, x, n);
        let sum = importance_total(importance);
        if (!usable(sum)) {
            return TreeSample(0u, 0.0);
        }
        // The slot whose share holds u (pick_slot): the last with importance if rounding passes all.
        let goal = u * sum;
        var below = 0.0;
        var slot = 4u;
        var last = 0u;
        for (var k = 0u; k < 4u; k++) {
            let i = importance[k];
            if (i > 0.0) {
                if (slot == 4u && goal < below + i) {
                    slot = k;
                } else if (slot == 4u) {
                    below += i;
                    last = k;
                }
            }
        }
        if (slot == 4u) {
            slot = last;
            below -= importance[last];
        }
        u = clamp((goal - below) / importance[slot], 0.0, ONE_MINUS_EPSILON);
        pmf *= importance[slot] / sum;
        if ((node.leaves & (1u << slot)) != 0u) {
            return TreeSample(node.child[slot], select(0.0, pmf, usable(pmf)));
        }
        index = node.child[slot];
    }
    return TreeSample(0u, 0.0);
}

// The pmf with which sample_tree at (x, n) picks the emitter in slot `code` = 4 x node + slot
// (light_tree.rs `tree_pmf`).
fn tree_pmf(code_in: u32, x: vec3<f32>, n: vec3<f32>) -> f32 {
    var pmf = 1.0;
    var code = code_in;
    for (var depth = 0u; depth < LIGHT_TREE_DEPTH; depth++) {
        let node = light_tree[code / 4u];
        let importance = slot_importances(node, x, n);
        let sum = importance_total(importance);
        if (!usable(sum)) {
            return 0.0;
        }
        pmf *= importance[code % 4u] / sum;
        if (code / 4u == 0u) {
            return pmf;
        }
        code = node.parent;
    }
    return 0.0;
}

// Where emitter triangle `triangle` sits in the light tree, 4 x node + slot (a binary search of the
// emitters, in triangle order).
fn leaf_of(triangle: u32) -> u32 {
    var lo = 0u;
    var hi = frame.emitter_count;
    while (hi - lo > 1u) {
        let mid = (lo + hi) / 2u;
        if (emitters[mid].triangle <= triangle) {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    return emitters[lo].leaf;
}

// The normal the tree weighs lights with, packed for the path to carry (light_tree.rs
// `pack_normal`; the snorm steps written out rather than pack2x16snorm, whose rounding drivers
// choose, so that both twins pack alike).
fn snorm16(e: f32) -> u32 {
    return u32(i32(floor(0.5 + 32767.0 * clamp(e, -1.0, 1.0)))) & 0xffffu;
}

fn unsnorm16(bits: u32) -> f32 {
    return max(f32(bitcast<i32>(bits << 16u) >> 16u) / 32767.0, -1.0);
}

// NO_NORMAL where point and spot lights reach the surface from its other side (light_tree.rs
// `tree_normal_at`).
fn tree_normal_at(ng: vec3<f32>, lit_through: bool) -> u32 {
    if (lit_through) {
        return NO_NORMAL;
    }
    return pack_normal(ng);
}

fn pack_normal(n: vec3<f32>) -> u32 {
    var e = n.xy / (abs(n.x) + abs(n.y) + abs(n.z));
    if (n.z < 0.0) {
        e = (1.0 - abs(e.yx)) * select(vec2(-1.0), vec2(1.0), e >= vec2(0.0));
    }
    return snorm16(e.x) | (snorm16(e.y) << 16u);
}

fn unpack_normal(packed: u32) -> vec3<f32> {
    if (packed == NO_NORMAL) {
        return vec3(0.0);
    }
    let e = vec2(unsnorm16(packed & 0xffffu), unsnorm16(packed >> 16u));
    let z = 1.0 - abs(e.x) - abs(e.y);
    var xy = e;
    if (z < 0.0) {
        xy = (1.0 - abs(e.yx)) * select(vec2(-1.0), vec2(1.0), e >= vec2(0.0));
    }
    return normalize(vec3(xy, z));
}
