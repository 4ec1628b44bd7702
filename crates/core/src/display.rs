//! Display colour beyond a clamp: the AgX view transform (Blender's default since 4.0) and a white
//! balance by colour temperature (Blender's, since 4.3). Both act on linear Rec.709/sRGB radiance before the sRGB
//! encoding of 8-bit outputs (`output::View`); EXR stays linear.

/// AgX (Troy Sobotka's view transform; Blender 4's default): linear sRGB to Rec.2020, Blender's
/// inset matrix, a log2 encoding over [−12.47, +4.03] stops, Benjamin Wrensch's published
/// polynomial fit of the base contrast curve (MIT, 2024), the outset matrix, the curve's 2.4
/// display exponent undone and back to linear sRGB (three.js and Filament run the same chain with
/// a 2.2 exponent; 2.4, Blender's AgX Base encoding, lands closer to Blender). Returns linear
/// display values in [0, 1]: highlights roll off and desaturate towards white as film does, where
/// Standard clips a bright red to red. Against Blender 5.2.3's AgX (8-bit-scale display values):
/// greys from 0.01 to 64 within 0.025, mid grey 0.471 against 0.461; dark saturated colours
/// differ more (a dim red's blue 0.21 against 0.11: Blender keeps them purer).
pub fn agx(rgb: [f32; 3]) -> [f32; 3] {
    const MIN_EV: f32 = -12.473_93;
    const MAX_EV: f32 = 4.026_069;
    // Row-major M · rgb.
    const SRGB_TO_REC2020: [[f32; 3]; 3] = [
        [0.6274, 0.3293, 0.0433],
        [0.0691, 0.9195, 0.0113],
        [0.0164, 0.0880, 0.8956],
    ];
    const REC2020_TO_SRGB: [[f32; 3]; 3] = [
        [1.6605, -0.5876, -0.0728],
        [-0.1246, 1.1329, -0.0083],
        [-0.0182, -0.1006, 1.1187],
    ];
    const INSET: [[f32; 3]; 3] = [
        [0.856_627_15, 0.095_121_24, 0.048_251_606],
        [0.137_318_97, 0.761_242, 0.101_439_04],
        [0.111_898_21, 0.076_799_42, 0.811_302_4],
    ];
    const OUTSET: [[f32; 3]; 3] = [
        [1.127_100_6, -0.110_606_64, -0.016_493_939],
        [-0.141_329_76, 1.157_823_7, -0.016_493_939],
        [-0.141_329_76, -0.110_606_64, 1.251_936_4],
    ];
    let encoded = mul(INSET, mul(SRGB_TO_REC2020, rgb)).map(|v| {
        let ev = v.max(1e-10).log2().clamp(MIN_EV, MAX_EV);
        contrast((ev - MIN_EV) / (MAX_EV - MIN_EV))
    });
    let display = mul(OUTSET, encoded).map(|v| v.max(0.0).powf(2.4));
    mul(REC2020_TO_SRGB, display).map(|v| v.clamp(0.0, 1.0))
}

/// AgX's base contrast curve on log-encoded x ∈ [0, 1] (the fit's polynomial).
fn contrast(x: f32) -> f32 {
    let x2 = x * x;
    let x4 = x2 * x2;
    15.5 * x4 * x2 - 40.14 * x4 * x + 31.96 * x4 - 6.868 * x2 * x + 0.4298 * x2 + 0.1191 * x
        - 0.00232
}

fn mul(m: [[f32; 3]; 3], v: [f32; 3]) -> [f32; 3] {
    m.map(|row| row[0] * v[0] + row[1] * v[1] + row[2] * v[2])
}

/// Blender's default white balance: 6500 K with a tint of 10, which is about D65, the display's
/// white (so it changes colours by under 0.3%).
pub const NEUTRAL_KELVIN: f32 = 6500.0;

/// The tint Blender's white balance defaults to (a shift off the Planckian locus, in units of
/// 1/3000 in CIE 1960 uv, towards green): rt keeps it, so `--white-balance K` matches Blender's
/// "White Balance" at temperature K.
const TINT: f64 = 10.0;

/// The linear-sRGB matrix that makes light of a black body at `kelvin` (tint 10, as Blender's
/// default) display white: a Bradford chromatic adaptation from that white point to D65, as
/// Blender 4.3+ does. Measured against Blender 5.2.3 on mid grey: 3200 K gives ×(0.370, 1.097,
/// 3.049) where Blender gives ×(0.368, 1.099, 3.042); 10000 K ×(1.185, 0.984, 0.704) against
/// ×(1.186, 0.985, 0.704). `None` outside the locus fit's range, 1667–25000 K.
pub fn white_balance_matrix(kelvin: f32) -> Option<[[f32; 3]; 3]> {
    const BRADFORD: [[f64; 3]; 3] = [
        [0.8951, 0.2664, -0.1614],
        [-0.7502, 1.7135, 0.0367],
        [0.0389, -0.0685, 1.0296],
    ];
    const XYZ_TO_RGB: [[f64; 3]; 3] = [
        [3.2406, -1.5372, -0.4986],
        [-0.9689, 1.8758, 0.0415],
        [0.0557, -0.2040, 1.0570],
    ];
    let source = white_point_xyz(f64::from(kelvin))?;
    let rgb_to_xyz = invert(XYZ_TO_RGB);
    let d65 = mul64(rgb_to_xyz, [1.0; 3]);
    let (lms_src, lms_dst) = (mul64(BRADFORD, source), mul64(BRADFORD, d65));
    let gain = [0, 1, 2].map(|i| lms_dst[i] / lms_src[i]);
    let diag = [
        [gain[0], 0.0, 0.0],
        [0.0, gain[1], 0.0],
        [0.0, 0.0, gain[2]],
    ];
    let adapt = matmul(invert(BRADFORD), matmul(diag, BRADFORD));
    let m = matmul(XYZ_TO_RGB, matmul(adapt, rgb_to_xyz));
    m.iter()
        .flatten()
        .all(|v| v.is_finite())
        .then(|| m.map(|row| row.map(|v| v as f32)))
}

/// XYZ (Y = 1) of the white point at `kelvin` with Blender's default tint: Kim et al.'s (2002)
/// cubic fit of the Planckian locus in CIE xy, moved off the locus along its normal in CIE 1960 uv.
fn white_point_xyz(kelvin: f64) -> Option<[f64; 3]> {
    if !(1667.0..=25000.0).contains(&kelvin) {
        return None;
    }
    let on_locus = planck_uv(kelvin);
    let tangent = sub(planck_uv(kelvin * 1.001), planck_uv(kelvin / 1.001));
    let length = tangent[0].hypot(tangent[1]);
    let mut normal = [-tangent[1] / length, tangent[0] / length];
    if normal[1] < 0.0 {
        normal = [-normal[0], -normal[1]];
    }
    let (u, v) = (
        on_locus[0] + normal[0] * TINT / 3000.0,
        on_locus[1] + normal[1] * TINT / 3000.0,
    );
    let d = 2.0 * u - 8.0 * v + 4.0;
    let (x, y) = (3.0 * u / d, 2.0 * v / d);
    Some([x / y, 1.0, (1.0 - x - y) / y])
}

/// The Planckian locus at `t` kelvin in CIE 1960 uv (Kim et al.'s fit in xy, 1667–25000 K).
fn planck_uv(t: f64) -> [f64; 2] {
    let (t1, t2, t3) = (1e3 / t, 1e6 / (t * t), 1e9 / (t * t * t));
    let x = if t <= 4000.0 {
        -0.266_123_9 * t3 - 0.234_358_9 * t2 + 0.877_695_6 * t1 + 0.179_910
    } else {
        -3.025_846_9 * t3 + 2.107_037_9 * t2 + 0.222_634_7 * t1 + 0.240_390
    };
    let y = if t <= 2222.0 {
        -1.106_381_4 * x.powi(3) - 1.348_110_20 * x * x + 2.185_558_32 * x - 0.202_196_83
    } else if t <= 4000.0 {
        -0.954_947_6 * x.powi(3) - 1.374_185_93 * x * x + 2.091_370_15 * x - 0.167_488_67
    } else {
        3.081_758_0 * x.powi(3) - 5.873_386_70 * x * x + 3.751_129_97 * x - 0.370_014_83
    };
    let d = -2.0 * x + 12.0 * y + 3.0;
    [4.0 * x / d, 6.0 * y / d]
}

fn sub(a: [f64; 2], b: [f64; 2]) -> [f64; 2] {
    [a[0] - b[0], a[1] - b[1]]
}

fn mul64(m: [[f64; 3]; 3], v: [f64; 3]) -> [f64; 3] {
    m.map(|row| row[0] * v[0] + row[1] * v[1] + row[2] * v[2])
}

fn matmul(a: [[f64; 3]; 3], b: [[f64; 3]; 3]) -> [[f64; 3]; 3] {
    a.map(|row| [0, 1, 2].map(|j| row[0] * b[0][j] + row[1] * b[1][j] + row[2] * b[2][j]))
}

fn invert(m: [[f64; 3]; 3]) -> [[f64; 3]; 3] {
    glam::DMat3::from_cols_array_2d(&m)
        .transpose()
        .inverse()
        .transpose()
        .to_cols_array_2d()
}

#[cfg(test)]
mod tests {
    use super::*;

    /// AgX keeps greys grey, is monotonic, maps black near 0 and very bright light near (never
    /// past) 1; a bright saturated red goes towards white (its green and blue rise) where the
    /// clamp keeps it pure red; greys land within 0.03 (display scale) of Blender 5.2.3's AgX
    /// (values read from Blender's own transform applied to these linear greys).
    #[test]
    fn agx_keeps_greys_rolls_highlights_off_and_follows_blenders_greys() {
        let mut last = -1.0;
        for i in 0..400 {
            let v = 1e-4 * 1.05f32.powi(i);
            let out = agx([v; 3]);
            assert!(
                (out[0] - out[1]).abs() < 2e-3 && (out[1] - out[2]).abs() < 2e-3,
                "{v}: {out:?}"
            );
            assert!(out[1] >= last - 1e-6, "monotonic at {v}: {out:?}");
            last = out[1];
        }
        assert!(agx([0.0; 3])[0] < 1e-3);
        assert!(agx([1e4; 3])[0] > 0.95 && agx([1e4; 3])[0] <= 1.0);
        let dim = agx([0.5, 0.0, 0.0]);
        let bright = agx([64.0, 0.0, 0.0]);
        assert!(dim[1] / dim[0] < 0.2, "{dim:?}");
        assert!(
            bright[1] / bright[0] > 0.5,
            "bright red desaturates: {bright:?}"
        );
        let blender = [
            (0.01, 0.0725),
            (0.05, 0.2272),
            (0.18, 0.4613),
            (0.5, 0.6652),
            (1.0, 0.771),
            (2.0, 0.8518),
            (4.0, 0.9137),
            (16.0, 0.9986),
            (64.0, 1.0),
        ];
        for (linear, shown) in blender {
            let ours = crate::output::linear_to_srgb(agx([linear; 3])[1]);
            assert!(
                (ours - shown).abs() <= 0.03,
                "{linear}: rt shows {ours}, Blender {shown}"
            );
        }
    }

    /// Against Blender 5.2.3's "White Balance" (default tint 10) on mid grey: 6500 K changes
    /// nothing visible, 3200 K makes tungsten light white and so cools the image, 10000 K warms
    /// it; out of range is refused.
    #[test]
    fn white_balance_matches_blenders_on_grey() {
        let grey = |k: f32| {
            let m = white_balance_matrix(k).unwrap();
            m.map(|row| row.iter().sum::<f32>())
        };
        let close = |a: [f32; 3], b: [f32; 3], tol: f32| {
            assert!(
                (0..3).all(|i| (a[i] - b[i]).abs() <= tol * b[i]),
                "{a:?} vs Blender's {b:?}"
            )
        };
        close(grey(6500.0), [1.0007, 0.9997, 1.0016], 0.003);
        close(grey(3200.0), [0.3676, 1.0987, 3.0415], 0.01);
        close(grey(10000.0), [1.1855, 0.9845, 0.704], 0.01);
        assert!(white_balance_matrix(1000.0).is_none());
        assert!(white_balance_matrix(f32::NAN).is_none());
    }
}
