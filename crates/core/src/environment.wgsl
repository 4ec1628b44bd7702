// The environment map; mirrors crates/core/src/environment.rs (mapping and pdf there).

fn env_uv(d: vec3<f32>) -> vec2<f32> {
    let u = atan2(d.x, -d.z) * (0.5 / PI) - frame.env_rotation;
    let v = acos(clamp(d.y, -1.0, 1.0)) * (1.0 / PI);
    return vec2(u - floor(u), v);
}

fn env_direction(u: f32, v: f32) -> vec3<f32> {
    let phi = TAU * (u + frame.env_rotation);
    let theta = PI * v;
    let s = sin(theta);
    return vec3(s * sin(phi), cos(theta), -s * cos(phi));
}

fn env_texel_index(uv: vec2<f32>) -> u32 {
    let x = min(u32(uv.x * f32(frame.env_width)), frame.env_width - 1u);
    let y = min(u32(uv.y * f32(frame.env_height)), frame.env_height - 1u);
    return y * frame.env_width + x;
}

// Radiance from direction d (xyz) and the density of sample_env there (w).
fn env_lookup(d: vec3<f32>) -> vec4<f32> {
    let t = environment[env_texel_index(env_uv(d))];
    let sin_theta = sqrt(max(1.0 - d.y * d.y, 0.0));
    return vec4(t.radiance, select(0.0, t.pdf / sin_theta, sin_theta > 0.0));
}

struct EnvSample {
    direction: vec3<f32>,
    pdf: f32,
    radiance: vec3<f32>,
}

fn sample_env(u0: f32, u1: f32, u2: f32, u3: f32) -> EnvSample {
    let n = frame.env_width * frame.env_height;
    let slot = min(u32(u0 * f32(n)), n - 1u);
    let i = select(environment[slot].alias_index, slot, u1 < environment[slot].threshold);
    let t = environment[i];
    let x = i % frame.env_width;
    let y = i / frame.env_width;
    let tu = (f32(x) + u2) / f32(frame.env_width);
    let tv = (f32(y) + u3) / f32(frame.env_height);
    let sin_theta = sin(PI * tv);
    return EnvSample(env_direction(tu, tv), select(0.0, t.pdf / sin_theta, sin_theta > 0.0), t.radiance);
}
