// Multiple-scattering compensation of rough glass: the trilinear lookup of its directional albedo
// E(μ, roughness, η); mirrors crates/core/src/math/glass_energy.rs (the table's layout there). The
// tables lie in albedo_tables from unit TABLE_GLASS on.

const GLASS_MU: u32 = 32u;
const GLASS_ROUGHNESS: u32 = 32u;
const GLASS_IOR: u32 = 16u;
const GLASS_MU_MIN: f32 = 0.015625;

fn glass_grid(v: f32, size: u32) -> vec2<f32> {
    let c = clamp(v, 0.0, f32(size - 1u));
    let lo = min(floor(c), f32(size - 2u));
    return vec2(lo, c - lo);
}

fn glass_at(base: u32, k: u32, i: u32, j: u32) -> f32 {
    return albedo_tables[base + (k * GLASS_ROUGHNESS + i) * GLASS_MU + j];
}

fn glass_energy(mu: f32, roughness: f32, eta: f32) -> f32 {
    let table_size = GLASS_MU * GLASS_ROUGHNESS * GLASS_IOR;
    let base = TABLE_GLASS * ENERGY_SIDE * ENERGY_SIDE + select(table_size, 0u, eta >= 1.0);
    let n = select(1.0 / eta, eta, eta >= 1.0);
    let z = 2.0 * (n - 1.0) / (n + 1.0);
    let gj = glass_grid((mu - GLASS_MU_MIN) / (1.0 - GLASS_MU_MIN) * f32(GLASS_MU - 1u), GLASS_MU);
    let gi = glass_grid(roughness * f32(GLASS_ROUGHNESS - 1u), GLASS_ROUGHNESS);
    let gk = glass_grid(z * f32(GLASS_IOR - 1u), GLASS_IOR);
    let j = u32(gj.x);
    let i = u32(gi.x);
    var planes: array<f32, 2>;
    for (var d = 0u; d < 2u; d++) {
        let k = u32(gk.x) + d;
        let lo = glass_at(base, k, i, j) + (glass_at(base, k, i, j + 1u) - glass_at(base, k, i, j)) * gj.y;
        let hi = glass_at(base, k, i + 1u, j) + (glass_at(base, k, i + 1u, j + 1u) - glass_at(base, k, i + 1u, j)) * gj.y;
        planes[d] = lo + (hi - lo) * gi.y;
    }
    return planes[0] + (planes[1] - planes[0]) * gk.y;
}
