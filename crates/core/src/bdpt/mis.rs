//! The MIS weight of strategy (s, t) by the power heuristic over every strategy that could have
//! made the same path (Veach §10.2; pbrt-v4's `MISWeight`): with p_i the density with which
//! strategy i (i light vertices) makes the path,
//!   w_{s,t} = p_s² / Σ_i p_i² = 1 / (1 + Σ_{i≠s} (p_i / p_s)²),
//! each ratio p_i / p_s a product of per-vertex ratios p_rev / p_fwd walked outward from the
//! connection, so no vertex's densities are stored twice. Strategies that would have to connect at
//! a delta vertex (a mirror, smooth glass, a point or sun light) make no path and are skipped; a
//! density of zero is taken as 1 in a ratio (a delta at both of its ends cancels).

use super::subpath::Walks;
use super::vertex::{Point, Vertex};

fn remap(pdf: f32) -> f32 {
    if pdf != 0.0 { pdf } else { 1.0 }
}

/// The weight of the path that strategy (s, t) made of `light[..s]` and `camera[..t]`, with
/// `sampled` standing for the vertex that s = 1 or t = 1 sampled anew.
pub fn weight(
    walks: &Walks,
    light: &[Vertex],
    camera: &[Vertex],
    sampled: Option<&Vertex>,
    s: usize,
    t: usize,
) -> f32 {
    if s + t == 2 {
        return 1.0;
    }
    let (scene, frame, choice) = (walks.scene, walks.frame, walks.choice);
    // Light that only a camera subpath finds has no other strategy: an environment no light
    // subpath starts from (the uniform ambient light, or a map without light above its mean).
    if s == 0
        && matches!(camera[t - 1].point, Point::Environment { .. })
        && choice.environment <= 0.0
    {
        return 1.0;
    }
    // The connection's ends and their neighbours, read in place (a vertex is a few hundred
    // bytes); what the connection changes about them (the ends' reverse densities, their neighbours'
    // and the ends no longer delta) is kept beside them.
    let qs = (s > 0).then(|| match sampled {
        Some(v) if s == 1 => v,
        _ => &light[s - 1],
    });
    let pt = match sampled {
        Some(v) if t == 1 => v,
        _ => &camera[t - 1],
    };
    let qs_minus = (s > 1).then(|| &light[s - 2]);
    let pt_minus = (t > 1).then(|| &camera[t - 2]);
    let pt_rev = match qs {
        Some(q) => q.pdf(scene, frame, choice, qs_minus, pt),
        None => pt.pdf_light_origin(scene, frame, choice),
    };
    let pt_minus_rev = pt_minus.map(|m| match qs {
        Some(q) => pt.pdf(scene, frame, choice, Some(q), m),
        None => pt.pdf_light(scene, choice, m),
    });
    let qs_rev = qs.map(|q| pt.pdf(scene, frame, choice, pt_minus, q));
    let qs_minus_rev = qs_minus.and_then(|m| qs.map(|q| q.pdf(scene, frame, choice, Some(pt), m)));

    let camera_vertex = |i: usize| -> (f32, f32, bool) {
        if i == t - 1 {
            (pt_rev, pt.pdf_fwd, false)
        } else if t >= 2 && i == t - 2 {
            let v = &camera[i];
            (pt_minus_rev.unwrap_or(v.pdf_rev), v.pdf_fwd, v.delta)
        } else {
            let v = &camera[i];
            (v.pdf_rev, v.pdf_fwd, v.delta)
        }
    };
    let light_vertex = |i: usize| -> (f32, f32, bool, bool) {
        if i == s - 1 {
            let q = qs.expect("s > 0");
            let rev = qs_rev.expect("s > 0");
            return (rev, q.pdf_fwd, false, q.is_delta_light());
        }
        let v = &light[i];
        let rev = if s >= 2 && i == s - 2 {
            qs_minus_rev.unwrap_or(v.pdf_rev)
        } else {
            v.pdf_rev
        };
        (rev, v.pdf_fwd, v.delta, v.is_delta_light())
    };

    let mut sum = 0.0f32;
    let mut ratio = 1.0f32;
    for i in (1..t).rev() {
        let (rev, fwd, delta) = camera_vertex(i);
        ratio *= remap(rev) / remap(fwd);
        if !delta && !camera_vertex(i - 1).2 {
            sum += ratio * ratio;
        }
    }
    ratio = 1.0;
    for i in (0..s).rev() {
        let (rev, fwd, delta, _) = light_vertex(i);
        ratio *= remap(rev) / remap(fwd);
        let before_is_delta = if i > 0 {
            light_vertex(i - 1).2
        } else {
            light_vertex(0).3
        };
        if !delta && !before_is_delta {
            sum += ratio * ratio;
        }
    }
    1.0 / (1.0 + sum)
}
