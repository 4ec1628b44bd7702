// Multiple-scattering compensation of anisotropic conductors: the four-way linear lookup of the
// white anisotropic conductor's albedo E(μ, φ, r, s); mirrors
// crates/core/src/math/anisotropic_energy.rs (the table's layout there). The table lies in
// albedo_tables after rough glass's two.

const ANISO_MU: u32 = 16u;
const ANISO_PHI: u32 = 6u;
const ANISO_ROUGHNESS: u32 = 16u;
const ANISO_STRENGTH: u32 = 8u;

fn aniso_at(base: u32, s: u32, r: u32, p: u32, m: u32) -> f32 {
    return albedo_tables[base + ((s * ANISO_ROUGHNESS + r) * ANISO_PHI + p) * ANISO_MU + m];
}

fn anisotropic_energy(wo: vec3<f32>, roughness: f32, strength: f32) -> f32 {
    let base = TABLE_GLASS * ENERGY_SIDE * ENERGY_SIDE + 2u * GLASS_MU * GLASS_ROUGHNESS * GLASS_IOR;
    let phi = atan2(abs(wo.y), abs(wo.x));
    let gm = glass_grid((wo.z - GLASS_MU_MIN) / (1.0 - GLASS_MU_MIN) * f32(ANISO_MU - 1u), ANISO_MU);
    let gp = glass_grid(phi / (0.5 * PI) * f32(ANISO_PHI - 1u), ANISO_PHI);
    let gr = glass_grid(roughness * f32(ANISO_ROUGHNESS - 1u), ANISO_ROUGHNESS);
    let gs = glass_grid(strength * f32(ANISO_STRENGTH - 1u), ANISO_STRENGTH);
    let m = u32(gm.x);
    let p = u32(gp.x);
    var out = 0.0;
    for (var ds = 0u; ds < 2u; ds++) {
        for (var dr = 0u; dr < 2u; dr++) {
            let s = u32(gs.x) + ds;
            let r = u32(gr.x) + dr;
            let w = select(1.0 - gs.y, gs.y, ds == 1u) * select(1.0 - gr.y, gr.y, dr == 1u);
            let lo = aniso_at(base, s, r, p, m) + (aniso_at(base, s, r, p, m + 1u) - aniso_at(base, s, r, p, m)) * gm.y;
            let hi = aniso_at(base, s, r, p + 1u, m) + (aniso_at(base, s, r, p + 1u, m + 1u) - aniso_at(base, s, r, p + 1u, m)) * gm.y;
            out += w * (lo + (hi - lo) * gp.y);
        }
    }
    return out;
}
