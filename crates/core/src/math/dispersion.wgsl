// Dispersion (KHR_materials_dispersion): the index of refraction by wavelength and the path's
// hero channel; mirrors crates/core/src/math/dispersion.rs (equations there).

const CHANNEL_WAVELENGTHS: vec3<f32> = vec3(612.0, 549.0, 465.0);

fn ior_at(ior: f32, dispersion: f32, lambda: f32) -> f32 {
    if (dispersion <= 0.0) {
        return ior;
    }
    let abbe = 20.0 / dispersion;
    return max(ior + (ior - 1.0) * (523655.0 / (lambda * lambda) - 1.5168) / abbe, 1.0);
}

// The index for a path's hero channel (1, 2, 3: red, green, blue; 0: none chosen).
fn channel_ior(ior: f32, dispersion: f32, channel: u32) -> f32 {
    if (channel == 0u) {
        return ior;
    }
    return ior_at(ior, dispersion, CHANNEL_WAVELENGTHS[min(channel - 1u, 2u)]);
}

// The hero channel (1, 2, 3) a uniform number picks.
fn pick_channel(u: f32) -> u32 {
    return min(u32(u * 3.0), 2u) + 1u;
}

// The throughput's mask for a hero channel: that channel alone, weighted by 3.
fn channel_mask(channel: u32) -> vec3<f32> {
    var mask = vec3(0.0);
    mask[channel - 1u] = 3.0;
    return mask;
}
