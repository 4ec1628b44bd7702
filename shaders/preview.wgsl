// The editor's raster preview: each object shaded by its material's colour or texture under the
// ambient light, the scene's point, spot and sun lights and the emissive objects (approximated as
// point lights at their centres), lights
// drawn glowing, the selection highlighted, fog as a haze, and a ground grid. An approximation for placing things,
// not an estimate of the rendered image: the path tracer is the truth.

const MAX_PREVIEW_LIGHTS: u32 = 8u;
// How an object is shaded (PreviewObject.flags.w; crates/app/src/preview/types.rs `look`).
const LOOK_DIFFUSE: u32 = 0u;
const LOOK_METAL: u32 = 1u;
const LOOK_GLASS: u32 = 2u;
const LOOK_EMITTER: u32 = 3u;

struct PreviewLight {
    // xyz: position; w unused.
    position: vec4<f32>,
    // rgb: radiant intensity (W/sr-like, in scene units) over pi; a: a spot's cos(inner angle).
    intensity: vec4<f32>,
    // xyz: a spot's axis; w: cos(outer angle), or -2 (types.rs NO_CONE) for the other lights.
    direction: vec4<f32>,
}

struct PreviewView {
    view_proj: mat4x4<f32>,
    // xyz: camera position; w: exposure (scale applied before tone mapping).
    eye: vec4<f32>,
    // rgb: ambient radiance; a: the fog's density (0: none).
    ambient: vec4<f32>,
    light_count: u32,
    // The radiance thick fog glows with (types.rs `PreviewView::fog_r`).
    fog_r: f32,
    fog_g: f32,
    fog_b: f32,
    lights: array<PreviewLight, 8>,
}

struct PreviewObject {
    model: mat4x4<f32>,
    // Columns 0..2: the inverse transpose of the model's linear part.
    normal_matrix: mat4x4<f32>,
    // rgb: reflectance (albedo, metal colour, glass tint); a: an alpha mask's threshold on the
    // image's alpha (cutoff / alpha factor; 0 cuts nothing).
    color: vec4<f32>,
    // rgb: emitted radiance; black for non-emitters.
    emission: vec4<f32>,
    // x: selected, y: textured, z: has vertex normals, w: 0 diffuse, 1 metal, 2 glass, 3 emitter.
    flags: vec4<u32>,
}

@group(0) @binding(0) var<uniform> view: PreviewView;
@group(0) @binding(1) var<storage, read> objects: array<PreviewObject>;
@group(1) @binding(0) var albedo_texture: texture_2d<f32>;
@group(1) @binding(1) var albedo_sampler: sampler;

struct MeshVertex {
    @location(0) position: vec3<f32>,
    @location(1) normal: vec3<f32>,
    @location(2) uv: vec2<f32>,
}

struct MeshVarying {
    @builtin(position) clip: vec4<f32>,
    @location(0) world: vec3<f32>,
    @location(1) normal: vec3<f32>,
    @location(2) uv: vec2<f32>,
    @location(3) @interpolate(flat) object: u32,
}

@vertex
fn vs_mesh(v: MeshVertex, @builtin(instance_index) object: u32) -> MeshVarying {
    let o = objects[object];
    let world = (o.model * vec4<f32>(v.position, 1.0)).xyz;
    var out: MeshVarying;
    out.clip = view.view_proj * vec4<f32>(world, 1.0);
    out.world = world;
    out.normal = mat3x3<f32>(o.normal_matrix[0].xyz, o.normal_matrix[1].xyz, o.normal_matrix[2].xyz) * v.normal;
    out.uv = v.uv;
    out.object = object;
    return out;
}

fn srgb_encode(c: vec3<f32>) -> vec3<f32> {
    let lo = c * 12.92;
    let hi = 1.055 * pow(max(c, vec3<f32>(0.0)), vec3<f32>(1.0 / 2.4)) - 0.055;
    return select(hi, lo, c <= vec3<f32>(0.0031308));
}

// Reinhard on each channel, then sRGB: the offscreen target is plain RGBA8 (see the blit).
fn display(radiance: vec3<f32>) -> vec4<f32> {
    let x = radiance * view.eye.w;
    return vec4<f32>(srgb_encode(x / (vec3<f32>(1.0) + x)), 1.0);
}

@fragment
fn fs_mesh(in: MeshVarying) -> @location(0) vec4<f32> {
    // Derivatives and texture sampling need uniform control flow: take them first.
    let face = cross(dpdx(in.world), dpdy(in.world));
    let sampled = textureSample(albedo_texture, albedo_sampler, in.uv);
    let texel = sampled.rgb;
    let o = objects[in.object];
    if sampled.a < o.color.a {
        discard;
    }
    let to_eye = normalize(view.eye.xyz - in.world);
    var n = normalize(face);
    if o.flags.z != 0u && dot(in.normal, in.normal) > 0.0 {
        n = normalize(in.normal);
    }
    // Two-sided: shade the side that faces the camera.
    if dot(n, to_eye) < 0.0 {
        n = -n;
    }
    var albedo = o.color.rgb;
    // A texture replaces the albedo, as in the renderer.
    if o.flags.y != 0u {
        albedo = texel;
    }
    var radiance: vec3<f32>;
    if o.flags.w == LOOK_EMITTER {
        // Lights glow in their colour at a fixed display brightness, whatever their power.
        let e = o.emission.rgb / max(max(o.emission.r, max(o.emission.g, o.emission.b)), 1e-6);
        radiance = (vec3<f32>(0.5) + 3.5 * e) / max(view.eye.w, 1e-6);
    } else {
        var irradiance = view.ambient.rgb;
        var highlight = vec3<f32>(0.0);
        // emission.w: a PBR material's roughness (its Blinn-Phong equivalent exponent 2/alpha^2 - 2
        // sizes the highlight), or < 0 for the other materials (exponent 64).
        let r = o.emission.w;
        let shininess = select(64.0, clamp(2.0 / max(r * r * r * r, 1e-4) - 2.0, 2.0, 2048.0), r >= 0.0);
        for (var i = 0u; i < min(view.light_count, MAX_PREVIEW_LIGHTS); i++) {
            let light = view.lights[i];
            let d = light.position.xyz - in.world;
            let d2 = max(dot(d, d), 1e-12);
            let l = d * inverseSqrt(d2);
            var intensity = light.intensity.rgb;
            if light.direction.w > -1.5 {
                // A spot: the renderer's smoothstep falloff between its cones.
                let c = dot(-l, light.direction.xyz);
                let t = clamp((c - light.direction.w) / max(light.intensity.a - light.direction.w, 1e-6), 0.0, 1.0);
                intensity *= t * t * (3.0 - 2.0 * t);
            }
            irradiance += intensity * max(dot(n, l), 0.0) / d2;
            let h = normalize(l + to_eye);
            highlight += intensity / d2 * pow(max(dot(n, h), 0.0), shininess) * (shininess + 2.0) / 66.0;
        }
        // A weak headlight keeps unlit sides readable.
        let fill = 0.08 / max(view.eye.w, 1e-6) * max(dot(n, to_eye), 0.0);
        radiance = albedo * (irradiance + vec3<f32>(fill));
        if o.flags.w == LOOK_METAL {
            radiance = radiance * 0.6 + albedo * highlight;
        } else if o.flags.w == LOOK_DIFFUSE && r >= 0.0 {
            // A PBR dielectric: its specular layer reflects about 4% of the light, untinted.
            radiance += 0.04 * highlight;
        } else if o.flags.w == LOOK_GLASS {
            let fresnel = pow(1.0 - max(dot(n, to_eye), 0.0), 5.0);
            radiance = radiance * 0.35 + highlight + vec3<f32>(fresnel) / max(view.eye.w, 1e-6);
        }
        // A PBR material's emission (colour x strength), the radiance the render gives it.
        radiance += o.emission.rgb;
    }
    // Fog between the eye and the surface: what lies behind it dims by exp(-density d) and the fog
    // glows in its place (a uniform single-scattering approximation of the render's).
    let density = view.ambient.a;
    if density > 0.0 {
        let t = exp(-density * length(view.eye.xyz - in.world));
        radiance = radiance * t + vec3<f32>(view.fog_r, view.fog_g, view.fog_b) * (1.0 - t);
    }
    var color = display(radiance);
    if o.flags.x != 0u {
        let rim = pow(1.0 - max(dot(n, to_eye), 0.0), 2.0);
        color = vec4<f32>(mix(color.rgb, vec3<f32>(1.0, 0.55, 0.1), 0.25 + 0.6 * rim), 1.0);
    }
    return color;
}

struct GridVertex {
    @location(0) position: vec3<f32>,
    @location(1) color: vec4<f32>,
}

struct GridVarying {
    @builtin(position) clip: vec4<f32>,
    @location(0) color: vec4<f32>,
}

@vertex
fn vs_grid(v: GridVertex) -> GridVarying {
    var out: GridVarying;
    out.clip = view.view_proj * vec4<f32>(v.position, 1.0);
    out.color = v.color;
    return out;
}

@fragment
fn fs_grid(in: GridVarying) -> @location(0) vec4<f32> {
    return in.color;
}
