// Solid glass in the raster preview (`refracted`, called by preview_shading.wgsl's `shade`): what
// lies beyond it, bent through it as through a ball, from the frame drawn before it (screen-space
// refraction, crates/preview/src/behind.rs), the emitters, the probes and the environment; and
// the sun's glint reflected once inside it. Smooth metals read the same frame along their mirror
// direction (`behind_along`).

// What solid glass of index `ior` shows at p: the view ray refracted in, through the object as
// through a sphere of its bounding radius (`volume.a`; a chord of 2 r cos θt, attenuated by
// exp(−σ chord), σ = `volume.rgb`), and out, bent as much again (rotating i by twice the angle
// from i to the refracted t: d = 2 (i·t) t − i). What the exit looks at along d is read from the
// frame drawn before the glass (`behind_along`, in its pass), else from an emitter there, else as
// reflections read: from the probes one cell beyond the exit along d, and the environment beyond
// them. (Blending what lies behind, unbent, as thin sheets do, showed a glass ball under a sky
// 76% too dark: the render sees the sky turned through it.)
fn refracted(v: vec3<f32>, n: vec3<f32>, ior: f32, p: vec3<f32>, volume: vec4<f32>, roughness: f32) -> vec3<f32> {
    // A render whose paths end at their second surface (max_depth ≤ 2) shows nothing through it.
    if view.max_depth <= 2u {
        return vec3<f32>(0.0);
    }
    let i = -v;
    let t = refract(i, n, 1.0 / ior);
    var d = i;
    var chord = 2.0 * volume.a;
    if dot(t, t) > 0.0 {
        d = normalize(2.0 * dot(i, t) * t - i);
        chord *= max(-dot(t, n), 0.0);
    }
    let exit = p + t * chord;
    let dims = vec3<f32>(textureDimensions(probes)) / vec3<f32>(6.0, 1.0, 1.0);
    let cell = (view.probe_hi.xyz - view.probe_lo.xyz) / dims;
    let ahead = probe_radiance_along(exit + d * min(cell.x, min(cell.y, cell.z)), d);
    let sky = sky_along(d, roughness);
    // What lies beyond: as drawn, where the frame shows it (the glass pass); else an emitter the
    // view meets (the probes see it only blurred over a bin); else the probes and the environment.
    // Sharp through smooth glass, the probes' blur through rough.
    let lamp = emitter_along(exit, d);
    var beyond = vec4<f32>(lamp.radiance, lamp.seen);
    if reads_behind {
        // A lit surface seen through it takes a path of four segments (below max_depth 4 it
        // only hides what lies beyond).
        let drawn = behind_along(exit, d);
        let lit = select(vec3<f32>(0.0), drawn.rgb, view.max_depth >= 4u);
        beyond = select(beyond, vec4<f32>(lit, 1.0), drawn.a > 0.0);
    }
    var shown = mix(reflected(sky, ahead), beyond.rgb, beyond.a * sharp_share(roughness));
    // And the light reflected once inside before it leaves (the glint of the sun a glass ball
    // shows low in it): through a sphere every inner segment meets the surface at θt, so it
    // leaves turned by a further π − 2θt, weighted by the reflectance inside, F (1 − F) after the
    // caller's entry.
    let inward = -n - dot(-n, i) * i;
    if dot(t, t) > 0.0 && dot(inward, inward) > 1e-8 {
        let theta_i = acos(clamp(dot(v, n), -1.0, 1.0));
        let theta_t = acos(clamp(-dot(t, n), -1.0, 1.0));
        let turn = 2.0 * (theta_i - theta_t) + PI - 2.0 * theta_t;
        let once = cos(turn) * i + sin(turn) * normalize(inward);
        let f0 = (ior - 1.0) * (ior - 1.0) / ((ior + 1.0) * (ior + 1.0));
        let f = fresnel_schlick(vec3<f32>(f0), 1.0, dot(v, n)).x;
        shown += f * (1.0 - f) * sky_along(once, roughness);
    }
    return shown * exp(-volume.rgb * chord);
}

// The environment along `d` (blurred by `roughness`) with its sun, taken out of the map as a
// light, where d meets its disc (solid angle Ω in `position.w`: radiance E/Ω).
fn sky_along(d: vec3<f32>, roughness: f32) -> vec3<f32> {
    var sky = environment(d, roughness);
    for (var k = 0u; k < min(view.light_count, MAX_PREVIEW_LIGHTS); k++) {
        let light = view.lights[k];
        let omega = light.position.w;
        if light.shadow.x == LIGHT_DIRECTIONAL && omega > 0.0
            && dot(d, -light.direction.xyz) >= 1.0 - omega / (2.0 * PI) {
            sky += light.color.rgb / omega;
        }
    }
    return sky;
}

// How much of what lies beyond glass, or before a metal, is seen sharply (`behind_along`,
// `emitter_along`) rather than as the probes and the prefiltered environment blur it: all of it
// through a smooth surface, none from roughness SHARP_ROUGHNESS (crates/preview/src/behind.rs).
const SHARP_ROUGHNESS: f32 = 0.5;
fn sharp_share(roughness: f32) -> f32 {
    return 1.0 - smoothstep(0.0, SHARP_ROUGHNESS, roughness);
}

// The steps of `behind_along`'s march at most, and the pixels one step covers at least.
const BEHIND_STEPS: f32 = 16.0;
const BEHIND_STEP_PIXELS: f32 = 16.0;
// The halvings of the step that crossed a surface: to a pixel or two.
const BEHIND_HALVINGS: u32 = 4u;
// How far behind a drawn surface, as a share of the scene's extent, a marched ray still meets it.
const BEHIND_THICKNESS: f32 = 0.05;

// The ray from `origin` along `d` marched across the frame drawn before the glass (`behind_color`,
// `behind_depth`; screen-space refraction): rgb, the radiance drawn where the ray first passes
// behind a surface, with a = 1; a = 0 where it leaves the screen or the scene's bounds first, or
// meets only the background (the caller keeps the probes and the environment there).
// The segment up to the scene's extent is clipped to the view in clip space (where it is a line),
// then walked in even steps across the screen: the point at screen fraction f lies at clip-space
// fraction f w0 / ((1 − f) w1 + f w0) of it (w: its ends' clip w). The ray passes behind a surface
// between two steps where the depth drawn at the second lies between the ray's depths at the two;
// a few halvings of that step then find the pixel.
fn behind_along(origin: vec3<f32>, d: vec3<f32>) -> vec4<f32> {
    let reach = length(view.probe_hi.xyz - view.probe_lo.xyz);
    let a = view.view_proj * vec4<f32>(origin, 1.0);
    let b = view.view_proj * vec4<f32>(origin + d * reach, 1.0);
    // The view's planes as clip-space distances (inside ≥ 0): left, right, bottom, top; near.
    let pa = vec4<f32>(a.w + a.x, a.w - a.x, a.w + a.y, a.w - a.y);
    let pb = vec4<f32>(b.w + b.x, b.w - b.x, b.w + b.y, b.w - b.y);
    if any((pa < vec4<f32>(0.0)) & (pb < vec4<f32>(0.0))) || (a.z < 0.0 && b.z < 0.0) {
        return vec4<f32>(0.0);
    }
    // Where the segment crosses each plane (a fraction of it), entering or leaving.
    let cross4 = pa / (pa - pb);
    let cross_z = a.z / (a.z - b.z);
    let entering = select(vec4<f32>(0.0), cross4, pa < vec4<f32>(0.0));
    let leaving = select(vec4<f32>(1.0), cross4, pa >= vec4<f32>(0.0) & pb < vec4<f32>(0.0));
    var span = vec2<f32>(
        max(max(max(entering.x, entering.y), max(entering.z, entering.w)), select(0.0, cross_z, a.z < 0.0)),
        min(min(min(leaving.x, leaving.y), min(leaving.z, leaving.w)), select(1.0, cross_z, a.z >= 0.0 && b.z < 0.0)),
    );
    if span.x >= span.y {
        return vec4<f32>(0.0);
    }
    let c0 = mix(a, b, span.x);
    let c1 = mix(a, b, span.y);
    let size = vec2<f32>(textureDimensions(behind_depth));
    let to_pixels = vec2<f32>(0.5, -0.5) * size;
    let length_px = length((c1.xy / c1.w - c0.xy / c0.w) * to_pixels);
    let steps = clamp(ceil(length_px / BEHIND_STEP_PIXELS), 1.0, BEHIND_STEPS);
    var before = 0.0;
    var before_depth = c0.z / c0.w;
    for (var k = 1.0; k <= steps; k += 1.0) {
        let f = k / steps;
        let c = along_segment(c0, c1, f);
        let depth = c.z / c.w;
        let drawn = textureLoad(behind_depth, pixel_of(c, size), 0);
        // Behind a surface that the ray reached in this step; or one it is just behind (by less
        // than BEHIND_THICKNESS of the scene's extent), reached where the frame showed a
        // surface farther off: the glass or mirror itself is not in the frame, which shows what
        // it hides there, and the ray may meet, say, the floor beneath it there. Farther behind a
        // surface, it passed behind something thin in front and goes on.
        if drawn < 1.0 && depth >= drawn && before_depth > drawn {
            let ray_point = view.inverse_view_proj * c;
            let surface = view.inverse_view_proj * vec4<f32>(c.xy / c.w, drawn, 1.0);
            let gap = distance(ray_point.xyz / ray_point.w, surface.xyz / surface.w);
            if gap < BEHIND_THICKNESS * reach {
                return vec4<f32>(textureLoad(behind_color, pixel_of(c, size), 0).rgb, 1.0);
            }
        }
        if drawn < 1.0 && depth >= drawn && before_depth <= drawn {
            // The step that crossed, halved down to the pixel.
            var lo = before;
            var hi = f;
            for (var h = 0u; h < BEHIND_HALVINGS; h++) {
                let mid = 0.5 * (lo + hi);
                let m = along_segment(c0, c1, mid);
                let under = textureLoad(behind_depth, pixel_of(m, size), 0);
                if under < 1.0 && m.z / m.w >= under {
                    hi = mid;
                } else {
                    lo = mid;
                }
            }
            let pixel = pixel_of(along_segment(c0, c1, hi), size);
            return vec4<f32>(textureLoad(behind_color, pixel, 0).rgb, 1.0);
        }
        before = f;
        before_depth = depth;
    }
    return vec4<f32>(0.0);
}

// The clip-space point at screen fraction f of the segment c0 → c1.
fn along_segment(c0: vec4<f32>, c1: vec4<f32>, f: f32) -> vec4<f32> {
    return mix(c0, c1, f * c0.w / ((1.0 - f) * c1.w + f * c0.w));
}

// The pixel a clip-space point falls in.
fn pixel_of(c: vec4<f32>, size: vec2<f32>) -> vec2<i32> {
    let uv = vec2<f32>(0.5 + 0.5 * c.x / c.w, 0.5 - 0.5 * c.y / c.w);
    return vec2<i32>(clamp(uv * size, vec2<f32>(0.0), size - 1.0));
}
