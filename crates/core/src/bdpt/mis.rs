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
    // Light that only a camera subpath finds (the environment) has no other strategy.
    if s == 0 && matches!(camera[t - 1].point, Point::Escaped { .. }) {
        return 1.0;
    }
    // The connection's ends and their neighbours, as the connection changes them.
    let mut qs = (s > 0).then(|| match sampled {
        Some(v) if s == 1 => *v,
        _ => light[s - 1],
    });
    let mut pt = match sampled {
        Some(v) if t == 1 => *v,
        _ => camera[t - 1],
    };
    let qs_minus = (s > 1).then(|| light[s - 2]);
    let pt_minus = (t > 1).then(|| camera[t - 2]);
    pt.delta = false;
    if let Some(q) = qs.as_mut() {
        q.delta = false;
    }
    pt.pdf_rev = match &qs {
        Some(q) => q.pdf(scene, frame, choice, qs_minus.as_ref(), &pt),
        None => pt.pdf_light_origin(scene, frame, choice),
    };
    let pt_minus_rev = pt_minus.as_ref().map(|m| match &qs {
        Some(q) => pt.pdf(scene, frame, choice, Some(q), m),
        None => pt.pdf_light(scene, choice, m),
    });
    if let Some(q) = qs.as_mut() {
        q.pdf_rev = pt.pdf(scene, frame, choice, pt_minus.as_ref(), q);
    }
    let qs_minus_rev = qs_minus.as_ref().and_then(|m| {
        qs.as_ref()
            .map(|q| q.pdf(scene, frame, choice, Some(&pt), m))
    });

    let camera_vertex = |i: usize| -> (f32, f32, bool) {
        if i == t - 1 {
            (pt.pdf_rev, pt.pdf_fwd, pt.delta)
        } else if t >= 2 && i == t - 2 {
            let v = &camera[i];
            (pt_minus_rev.unwrap_or(v.pdf_rev), v.pdf_fwd, v.delta)
        } else {
            let v = &camera[i];
            (v.pdf_rev, v.pdf_fwd, v.delta)
        }
    };
    let light_vertex = |i: usize| -> (f32, f32, bool, bool) {
        let v = if i == s - 1 {
            qs.expect("s > 0")
        } else {
            light[i]
        };
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
