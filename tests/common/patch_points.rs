//! Hard queries for patch sets (issue 23): points a small distance from every patch edge
//! (seams and boundary curves), corner and collapsed pole, along the surface normal and straight
//! below boundary curves. Shared by `tests/patches/patches_seams.rs` and `examples/patch_seams.rs`.
#![allow(dead_code)]

use gwn::patch::PatchSet;
use gwn::patch::boundary::{EdgeLink, edge_indices, link_edges};

/// One query with what it is near.
#[derive(Clone, Copy, Debug)]
pub struct Query {
    /// "seam", "boundary", "below-boundary", "corner" or "pole".
    pub kind: &'static str,
    /// Distance from the feature, as a fraction of the set's bounding-box diagonal (0 for a
    /// query on it).
    pub offset: f64,
    pub q: [f64; 3],
}

/// The bounding-box diagonal of the control points.
pub fn diagonal(set: &PatchSet) -> f64 {
    let (lo, hi) = set.bounding_box();
    (0..3).map(|a| (hi[a] - lo[a]).powi(2)).sum::<f64>().sqrt()
}

/// The unit normal `∂S/∂t × ∂S/∂s` at `(s, t)`, taken a little inside the patch where a
/// collapsed side makes it vanish.
pub fn normal(set: &PatchSet, p: usize, s: f64, t: f64) -> [f64; 3] {
    let patch = &set.patches()[p];
    for inset in [0.0, 1e-4, 1e-2] {
        let (s, t) = (s.clamp(inset, 1.0 - inset), t.clamp(inset, 1.0 - inset));
        let (_, ds, dt) = patch.eval_with_partials(s, t);
        let n = [
            dt[1] * ds[2] - dt[2] * ds[1],
            dt[2] * ds[0] - dt[0] * ds[2],
            dt[0] * ds[1] - dt[1] * ds[0],
        ];
        let len = (n[0] * n[0] + n[1] * n[1] + n[2] * n[2]).sqrt();
        if len > 1e-12 {
            return n.map(|c| c / len);
        }
    }
    [0.0, 0.0, 1.0]
}

/// Queries at `offset × diagonal` from the midpoint of every non-degenerate patch edge along
/// the patch's normal (both signs if `both_sides`; shared edges once, from the lower patch),
/// from every patch corner likewise, and straight below (−z) the midpoints of boundary edges.
pub fn near_feature_queries(set: &PatchSet, offsets: &[f64], both_sides: bool) -> Vec<Query> {
    let links = link_edges(set);
    let diag = diagonal(set);
    let signs: &[f64] = if both_sides { &[1.0, -1.0] } else { &[1.0] };
    let mut out = Vec::new();
    for (p, patch) in set.patches().iter().enumerate() {
        for e in 0..4 {
            let kind = match links[p][e] {
                EdgeLink::Degenerate => continue,
                EdgeLink::Shared { patch: o, .. } if o < p => continue,
                EdgeLink::Shared { .. } => "seam",
                EdgeLink::Boundary => "boundary",
            };
            let (s, t) = [(0.0, 0.5), (0.5, 1.0), (1.0, 0.5), (0.5, 0.0)][e];
            let x = patch.eval(s, t);
            let n = normal(set, p, s, t);
            for &off in offsets {
                for &sign in signs {
                    let d = sign * off * diag;
                    out.push(Query {
                        kind,
                        offset: off,
                        q: [0, 1, 2].map(|a| x[a] + d * n[a]),
                    });
                }
                if kind == "boundary" {
                    out.push(Query {
                        kind: "below-boundary",
                        offset: off,
                        q: [x[0], x[1], x[2] - off * diag],
                    });
                }
            }
        }
        for (s, t) in [(0.0, 0.0), (0.0, 1.0), (1.0, 0.0), (1.0, 1.0)] {
            let x = patch.eval(s, t);
            let n = normal(set, p, s, t);
            for &off in offsets {
                for &sign in signs {
                    let d = sign * off * diag;
                    out.push(Query {
                        kind: "corner",
                        offset: off,
                        q: [0, 1, 2].map(|a| x[a] + d * n[a]),
                    });
                }
            }
        }
    }
    out
}

/// The points of collapsed patch sides (the teapot's knob, lid and bottom poles), exactly,
/// each once.
pub fn poles(set: &PatchSet) -> Vec<Query> {
    let links = link_edges(set);
    let mut out: Vec<Query> = Vec::new();
    for (p, patch) in set.patches().iter().enumerate() {
        for (e, link) in links[p].iter().enumerate() {
            if *link != EdgeLink::Degenerate {
                continue;
            }
            let (m, n) = patch.degree();
            let q = patch.points()[edge_indices(m, n, e)[0]];
            if !out.iter().any(|o| o.q == q) {
                out.push(Query {
                    kind: "pole",
                    offset: 0.0,
                    q,
                });
            }
        }
    }
    out
}
