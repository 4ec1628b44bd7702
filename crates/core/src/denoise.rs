//! A portable denoiser: the edge-avoiding À-Trous wavelet filter (Dammertz, Sewtz, Hanika and
//! Lensch, "Edge-Avoiding À-Trous Wavelet Transform for fast Global Illumination Filtering", HPG
//! 2010), guided by the first-hit albedo and normal the kernel writes beside the image, with the
//! colour weight scaled by each pixel's estimated standard deviation (as in SVGF, Schied et al. 2017).
//!
//! The filter works on the reflected light divided by its albedo (the lighting), so texture and
//! colour edges that the albedo carries are not blurred, and multiplies the albedo back; light seen
//! directly (emitters, sky) is left out of the filter and added back as it is. Five passes with holes
//! of 1, 2, 4, 8 and 16 pixels spread a 5 × 5 B3-spline kernel over 129 × 129 pixels. Each tap
//! q of pixel p is weighted by
//!   h(q) · exp(−|n_p − n_q|² / σ_n²) · exp(−|a_p − a_q|² / σ_a²) · exp(−|l_p − l_q| / (σ_l s_p + ε)),
//! with n the normal, a the albedo, l the luminance of the lighting and s_p its standard deviation.
//!
//! Denoising is biased (it trades noise for blur); rt never replaces the raw render with it.

/// Per-pixel inputs, row-major, all the same length (`width × height`).
pub struct DenoiseInput<'a> {
    pub width: u32,
    pub height: u32,
    /// Mean radiance.
    pub color: &'a [[f32; 3]],
    /// The part of `color` seen directly (emitters, sky): kept as it is, not filtered.
    pub emission: &'a [[f32; 3]],
    /// Mean first-hit albedo (zero where a ray escaped).
    pub albedo: &'a [[f32; 3]],
    /// Mean first-hit shading normal (zero where a ray escaped).
    pub normal: &'a [[f32; 3]],
    /// Variance of each pixel's luminance estimate (s²/n), or zeros when unknown.
    pub variance: &'a [f32],
}

/// Filter strengths.
#[derive(Clone, Copy, Debug)]
pub struct DenoiseParams {
    pub sigma_normal: f32,
    pub sigma_albedo: f32,
    /// How many standard deviations of luminance difference still count as the same surface.
    pub sigma_luminance: f32,
    pub passes: u32,
}

impl Default for DenoiseParams {
    fn default() -> Self {
        DenoiseParams {
            sigma_normal: 0.3,
            sigma_albedo: 0.1,
            sigma_luminance: 8.0,
            passes: 5,
        }
    }
}

fn luminance(c: [f32; 3]) -> f32 {
    crate::math::sampling::luminance(glam::Vec3::from(c))
}

fn dist2(a: [f32; 3], b: [f32; 3]) -> f32 {
    (0..3).map(|i| (a[i] - b[i]).powi(2)).sum()
}

/// The denoised image, or an error naming the mismatched input.
pub fn denoise(input: &DenoiseInput, params: &DenoiseParams) -> Result<Vec<[f32; 3]>, String> {
    let (w, h) = (input.width as usize, input.height as usize);
    let n = w * h;
    for (name, len) in [
        ("color", input.color.len()),
        ("emission", input.emission.len()),
        ("albedo", input.albedo.len()),
        ("normal", input.normal.len()),
        ("variance", input.variance.len()),
    ] {
        if len != n {
            return Err(format!(
                "denoise: {name} has {len} pixels, expected {w}x{h}"
            ));
        }
    }
    // Demodulate: filter the lighting, not the albedo.
    const MIN_ALBEDO: f32 = 1e-3;
    let demodulate = |c: [f32; 3], a: [f32; 3]| {
        let mut out = [0.0; 3];
        for i in 0..3 {
            out[i] = if a[i] > MIN_ALBEDO { c[i] / a[i] } else { c[i] };
        }
        out
    };
    let reflected = |i: usize| {
        let (c, e) = (input.color[i], input.emission[i]);
        [c[0] - e[0], c[1] - e[1], c[2] - e[2]]
    };
    let mut light: Vec<[f32; 3]> = (0..n)
        .map(|i| demodulate(reflected(i), input.albedo[i]))
        .collect();
    // The standard deviation of the demodulated luminance, from that of the colour.
    let raw_variance: Vec<f32> = (0..n)
        .map(|i| {
            let a = luminance(input.albedo[i]);
            let v = input.variance[i].max(0.0);
            if a > MIN_ALBEDO { v / (a * a) } else { v }
        })
        .collect();
    // A few samples give a poor variance per pixel: average it over 3 × 3 neighbours (SVGF's
    // spatial estimate), then carry it through the passes as the filter shrinks it.
    let mut variance: Vec<f32> = (0..n)
        .map(|p| {
            let (x, y) = ((p % w) as isize, (p / w) as isize);
            let mut sum = 0.0;
            let mut count = 0.0;
            for dy in -1..=1 {
                for dx in -1..=1 {
                    let (qx, qy) = (x + dx, y + dy);
                    if qx >= 0 && qy >= 0 && (qx as usize) < w && (qy as usize) < h {
                        sum += raw_variance[qy as usize * w + qx as usize];
                        count += 1.0;
                    }
                }
            }
            sum / count
        })
        .collect();
    const KERNEL: [f32; 5] = [1.0 / 16.0, 1.0 / 4.0, 3.0 / 8.0, 1.0 / 4.0, 1.0 / 16.0];
    let inv_n = 1.0 / (params.sigma_normal * params.sigma_normal).max(1e-12);
    let inv_a = 1.0 / (params.sigma_albedo * params.sigma_albedo).max(1e-12);
    for pass in 0..params.passes {
        let step = 1isize << pass;
        let mut next = vec![[0.0f32; 3]; n];
        let mut next_variance = vec![0.0f32; n];
        for y in 0..h {
            for x in 0..w {
                let p = y * w + x;
                let (lp, np, ap) = (light[p], input.normal[p], input.albedo[p]);
                let lum_p = luminance(lp);
                let scale = params.sigma_luminance * variance[p].sqrt() + 1e-4;
                let mut sum = [0.0f32; 3];
                let mut weight_sum = 0.0f32;
                let mut variance_sum = 0.0f32;
                for (j, ky) in KERNEL.iter().enumerate() {
                    let qy = y as isize + (j as isize - 2) * step;
                    if qy < 0 || qy >= h as isize {
                        continue;
                    }
                    for (i, kx) in KERNEL.iter().enumerate() {
                        let qx = x as isize + (i as isize - 2) * step;
                        if qx < 0 || qx >= w as isize {
                            continue;
                        }
                        let q = qy as usize * w + qx as usize;
                        let lq = light[q];
                        let weight = kx
                            * ky
                            * (-dist2(np, input.normal[q]) * inv_n).exp()
                            * (-dist2(ap, input.albedo[q]) * inv_a).exp()
                            * (-(lum_p - luminance(lq)).abs() / scale).exp();
                        if !(weight.is_finite() && lq.iter().all(|v| v.is_finite())) {
                            continue;
                        }
                        for c in 0..3 {
                            sum[c] += weight * lq[c];
                        }
                        weight_sum += weight;
                        variance_sum += weight * weight * variance[q];
                    }
                }
                if weight_sum > 0.0 {
                    next[p] = sum.map(|s| s / weight_sum);
                    next_variance[p] = variance_sum / (weight_sum * weight_sum);
                } else {
                    next[p] = lp;
                    next_variance[p] = variance[p];
                }
            }
        }
        light = next;
        variance = next_variance;
    }
    Ok((0..n)
        .map(|i| {
            let (l, a, e) = (light[i], input.albedo[i], input.emission[i]);
            let mut out = [0.0; 3];
            for c in 0..3 {
                out[c] = e[c] + if a[c] > MIN_ALBEDO { l[c] * a[c] } else { l[c] };
            }
            out
        })
        .collect())
}

#[cfg(test)]
mod tests {
    use super::*;

    fn run(color: &[[f32; 3]], albedo: &[[f32; 3]], normal: &[[f32; 3]], w: u32) -> Vec<[f32; 3]> {
        let n = color.len();
        let variance = vec![0.01; n];
        let emission = vec![[0.0; 3]; n];
        denoise(
            &DenoiseInput {
                width: w,
                height: (n as u32) / w,
                color,
                emission: &emission,
                albedo,
                normal,
                variance: &variance,
            },
            &DenoiseParams::default(),
        )
        .expect("sizes match")
    }

    #[test]
    fn a_constant_image_is_unchanged() {
        let n = 32 * 16;
        let out = run(
            &vec![[0.3, 0.5, 0.7]; n],
            &vec![[0.5; 3]; n],
            &vec![[0.0, 1.0, 0.0]; n],
            32,
        );
        for p in out {
            for (c, e) in p.iter().zip([0.3, 0.5, 0.7]) {
                assert!((c - e).abs() < 1e-5, "{p:?}");
            }
        }
    }

    /// Noise on a flat surface is smoothed; an edge between two surfaces (different normals and
    /// albedos) does not bleed.
    #[test]
    fn noise_is_smoothed_and_edges_are_kept() {
        let (w, h) = (64usize, 32usize);
        let mut state = 1u32;
        let mut noise = || {
            state = crate::math::rng::pcg_hash(state);
            (state >> 8) as f32 / 16_777_216.0 - 0.5
        };
        let mut color = Vec::new();
        let mut albedo = Vec::new();
        let mut normal = Vec::new();
        for _y in 0..h {
            for x in 0..w {
                let left = x < w / 2;
                let a = if left { [0.8; 3] } else { [0.2; 3] };
                let lighting = 1.0 + 0.3 * noise();
                color.push(a.map(|v| v * lighting));
                albedo.push(a);
                normal.push(if left {
                    [0.0, 1.0, 0.0]
                } else {
                    [1.0, 0.0, 0.0]
                });
            }
        }
        let out = run(&color, &albedo, &normal, w as u32);
        let spread = |img: &[[f32; 3]], x0: usize, x1: usize| {
            let vals: Vec<f32> = (0..h)
                .flat_map(|y| (x0..x1).map(move |x| y * w + x))
                .map(|p| img[p][0])
                .collect();
            let m = vals.iter().sum::<f32>() / vals.len() as f32;
            let v = vals.iter().map(|v| (v - m).powi(2)).sum::<f32>() / vals.len() as f32;
            (m, v.sqrt())
        };
        let (m_in, s_in) = spread(&color, 0, w / 2);
        let (m_out, s_out) = spread(&out, 0, w / 2);
        assert!(s_out < s_in / 4.0, "noise {s_in} -> {s_out}");
        assert!((m_out - m_in).abs() < 0.02, "mean kept: {m_in} -> {m_out}");
        // Right next to the edge the dark side stays dark.
        for y in 0..h {
            let p = y * w + w / 2;
            assert!(
                out[p][0] < 0.3,
                "the bright side bled into pixel {p}: {:?}",
                out[p]
            );
        }
    }

    #[test]
    fn mismatched_inputs_are_an_error() {
        let c = vec![[0.0; 3]; 4];
        let err = denoise(
            &DenoiseInput {
                width: 2,
                height: 2,
                color: &c,
                emission: &c,
                albedo: &c[..3],
                normal: &c,
                variance: &[0.0; 4],
            },
            &DenoiseParams::default(),
        );
        assert!(err.unwrap_err().contains("albedo"));
    }
}
