//! The winding number of a patch set (paper Section 4.4, Alg. 2, Eq. 15), with the ray's
//! crossing count folded into the boundary integral so that no integer is ever rounded.
//!
//! For the ray `+z` from `q` (in the frame of [`RayAxis`]), every patch is classified by exact
//! tests on its control net (relative to `q`; the curve lies in the net's convex hull because
//! the weights are positive):
//! - [`Form::Up`] if the net lies above `q` (all `z > 0`) or is separated from the ray `−z` by a
//!   plane with an angular margin: its solid angle is `∮ α↑` over its boundary;
//! - [`Form::Down`] if below (all `z < 0`) or separated from `+z` with a margin: `∮ α↓`;
//! - *mixed* otherwise: it is halved in `s` and `t` until every piece is classified.
//!
//! Summing `∮ α` over all pieces gives `4π w` exactly (each `∮` is Stokes on a piece whose image
//! on the sphere avoids the potential's singular pole). Edges shared by two pieces with the same
//! form cancel and are skipped (the paper's "surface boundary" optimisation); an edge shared by an
//! `Up` and a `Down` piece contributes `±2∫dφ`, a closed form ([`azimuth_change`]) certified by
//! exact sign tests. What remains are integrals of smooth integrands over the surface boundary
//! and over the edges next to mixed patches, done by adaptive Gauss–Kronrod. Paper Eq. 15's
//! crossing count `χ(x0)` is carried by the `α↑ − α↓ = 2dφ` difference on the `Up` pieces; it is
//! never formed as an integer, so it cannot disagree with the integral. See `docs/patches.md` for
//! the argument and the error model.

use std::f64::consts::PI;

use rayon::prelude::*;

use super::boundary::{EdgeLink, edge_counts, edge_indices, link_edges};
use super::curve::{
    Form, Homogeneous, azimuth_change, eval_with_derivative, integrand, split_half,
};
use super::model::PatchSet;
use super::quadrature::{Integral, integrate};
use crate::kernel::compensated::NeumaierSum;
use crate::kernel::frame::RayAxis;
use crate::kernel::spherical::triangle_solid_angle;

/// Separation margin `μ`: a plane certifies a net only if every control point makes an angle of
/// at least `asin μ` with it. Keeps the potentials' integrands smooth (bounded by a constant over
/// `μ²` relative to the distance), so the quadrature converges quickly.
const MARGIN: f64 = 0.25;
/// Relative slack on the `z > 0` / `z < 0` tests, far above the rounding of a rational net's
/// Euclidean points (`H / w`), so the tests speak about the true convex hull.
const Z_SLACK: f64 = 1e-12;
/// Subdivision depth of a mixed patch (each level halves both parameters). A piece still mixed
/// at this depth is `2^-48` of its patch: the query lies on the surface to `f64` resolution.
const MAX_DEPTH: u32 = 48;

/// Options of the patch evaluator.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Options {
    /// Ray direction (default `+z`); every choice gives the same `w` off the surface.
    pub ray: RayAxis,
    /// Target absolute error of `w` (default `1e-10`). Each boundary integral is run to a tenth
    /// of it (in units of `w`); [`Evaluation::error_estimate`] reports what was reached.
    pub tolerance: f64,
}

impl Default for Options {
    fn default() -> Self {
        Options {
            ray: RayAxis::PosZ,
            tolerance: 1e-10,
        }
    }
}

/// One evaluation with its diagnostics.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Evaluation {
    /// The winding number.
    pub value: f64,
    /// Sum of the Gauss–Kronrod error estimates of the boundary integrals, in units of `w`.
    pub error_estimate: f64,
    /// Boundary integrals computed.
    pub integrals: usize,
    /// Integrand evaluations.
    pub evaluations: usize,
    /// Patches that had to be subdivided.
    pub mixed_patches: usize,
    /// Pieces still unclassified at the depth limit (query on the surface to `f64`
    /// resolution); their solid angle is the principal value of their corner quad.
    pub uncertified_pieces: usize,
}

/// The winding-number evaluator of a patch set.
#[derive(Clone, Debug)]
pub struct PatchWindingNumber {
    set: PatchSet,
    links: Vec<[EdgeLink; 4]>,
    edges: Vec<[Vec<usize>; 4]>,
    /// World bounding box of each patch's control points.
    boxes: Vec<([f64; 3], [f64; 3])>,
    options: Options,
}

/// A control net in the ray frame relative to the query, homogeneous, row-major.
#[derive(Clone, Debug)]
struct Net {
    m: usize,
    n: usize,
    h: Vec<Homogeneous>,
}

impl PatchWindingNumber {
    /// An evaluator with the default options.
    pub fn new(set: &PatchSet) -> Self {
        Self::with_options(set, Options::default())
    }

    /// An evaluator with the given options. A non-positive or non-finite tolerance is replaced
    /// by the default.
    pub fn with_options(set: &PatchSet, mut options: Options) -> Self {
        if !(options.tolerance.is_finite() && options.tolerance > 0.0) {
            options.tolerance = Options::default().tolerance;
        }
        let links = link_edges(set);
        let edges = set
            .patches()
            .iter()
            .map(|p| {
                let (m, n) = p.degree();
                std::array::from_fn(|e| edge_indices(m, n, e))
            })
            .collect();
        let boxes = set
            .patches()
            .iter()
            .map(|p| {
                let mut lo = [f64::INFINITY; 3];
                let mut hi = [f64::NEG_INFINITY; 3];
                for x in p.points() {
                    for a in 0..3 {
                        lo[a] = lo[a].min(x[a]);
                        hi[a] = hi[a].max(x[a]);
                    }
                }
                (lo, hi)
            })
            .collect();
        PatchWindingNumber {
            set: set.clone(),
            links,
            edges,
            boxes,
            options,
        }
    }

    /// The options in use.
    pub fn options(&self) -> Options {
        self.options
    }

    /// The patch set.
    pub fn patch_set(&self) -> &PatchSet {
        &self.set
    }

    /// `(boundary edges, shared edge pairs, degenerate edges)` of the patch set.
    pub fn edge_counts(&self) -> (usize, usize, usize) {
        edge_counts(&self.links)
    }

    /// The winding number at `q` (NaN for a non-finite query).
    pub fn eval(&self, q: [f64; 3]) -> f64 {
        self.evaluate(q).value
    }

    /// Winding numbers at many points, in parallel.
    pub fn eval_batch(&self, points: &[[f64; 3]]) -> Vec<f64> {
        points.par_iter().map(|&q| self.eval(q)).collect()
    }

    /// The winding number at `q` with its error estimate and work counters.
    pub fn evaluate(&self, q: [f64; 3]) -> Evaluation {
        if q.iter().any(|c| !c.is_finite()) {
            return Evaluation {
                value: f64::NAN,
                ..Evaluation::default()
            };
        }
        let mut acc = Accumulator {
            sum: NeumaierSum::new(),
            tol: self.options.tolerance * 4.0 * PI * 0.1,
            out: Evaluation::default(),
        };
        let ray = self.options.ray;
        let frame_point = |p: usize, k: usize| -> [f64; 3] {
            let pt = self.set.patches()[p].points()[k];
            ray.to_frame([pt[0] - q[0], pt[1] - q[1], pt[2] - q[2]])
        };
        let forms: Vec<Option<Form>> = (0..self.set.patches().len())
            .map(|p| {
                let z = self.frame_z_range(p, q);
                classify_points(
                    (0..self.set.patches()[p].points().len()).map(|k| frame_point(p, k)),
                    Some(z),
                )
            })
            .collect();
        let mut buf = [[0.0f64; 4]; super::model::MAX_DEGREE + 1];
        let fill = |p: usize, e: usize, buf: &mut [Homogeneous]| -> usize {
            let idx = &self.edges[p][e];
            let weights = self.set.patches()[p].weights();
            for (slot, &k) in buf.iter_mut().zip(idx) {
                let d = frame_point(p, k);
                let w = weights[k];
                *slot = [w * d[0], w * d[1], w * d[2], w];
            }
            idx.len()
        };
        let mut edge_ctrl = |p: usize, e: usize| -> Vec<Homogeneous> {
            let len = fill(p, e, &mut buf);
            buf[..len].to_vec()
        };
        for (p, form) in forms.iter().enumerate() {
            let Some(form) = *form else { continue };
            for e in 0..4 {
                match self.links[p][e] {
                    EdgeLink::Degenerate => {}
                    EdgeLink::Boundary => acc.integrate(&edge_ctrl(p, e), form),
                    EdgeLink::Shared { patch: o, .. } => match forms[o] {
                        None => acc.integrate(&edge_ctrl(p, e), form),
                        Some(g) if g == form => {}
                        Some(_) if p < o => acc.interface(&edge_ctrl(p, e), form, None),
                        Some(_) => {}
                    },
                }
            }
        }
        let mut leaf_edges = Vec::new();
        for (p, patch) in self.set.patches().iter().enumerate() {
            if forms[p].is_none() {
                acc.out.mixed_patches += 1;
                let (m, n) = patch.degree();
                let h = (0..patch.points().len())
                    .map(|k| {
                        let d = frame_point(p, k);
                        let w = patch.weights()[k];
                        [w * d[0], w * d[1], w * d[2], w]
                    })
                    .collect();
                self.subdivide(Net { m, n, h }, &mut leaf_edges, &mut acc);
            }
        }
        acc.leaf_edges(leaf_edges);
        let mut out = acc.out;
        out.value = acc.sum.value() / (4.0 * PI);
        out.error_estimate /= 4.0 * PI;
        out
    }

    /// `(min, max, scale)` of the frame `z` of patch `p`'s control points relative to `q`, from
    /// its world box: `fl(x − q)` is monotone in `x`, so these are the extremes of the per-point
    /// values, exactly. `scale` bounds every frame coordinate's magnitude.
    fn frame_z_range(&self, p: usize, q: [f64; 3]) -> (f64, f64, f64) {
        let (lo, hi) = self.boxes[p];
        let [_, _, (axis, negated)] = self.options.ray.map();
        let (a, b) = (lo[axis] - q[axis], hi[axis] - q[axis]);
        let mut scale = 0.0f64;
        for k in 0..3 {
            scale = scale.max((lo[k] - q[k]).abs()).max((hi[k] - q[k]).abs());
        }
        if negated {
            (-b, -a, scale)
        } else {
            (a, b, scale)
        }
    }

    /// Halves a mixed net until its pieces are classified; records their edges.
    fn subdivide(&self, net: Net, leaf_edges: &mut Vec<LeafEdge>, acc: &mut Accumulator) {
        let mut stack = vec![(net, 0u32)];
        while let Some((net, depth)) = stack.pop() {
            if let Some(form) = classify(&net) {
                for e in 0..4 {
                    let ctrl: Vec<Homogeneous> = edge_indices(net.m, net.n, e)
                        .into_iter()
                        .map(|k| net.h[k])
                        .collect();
                    if ctrl.iter().all(|c| *c == ctrl[0]) {
                        continue;
                    }
                    leaf_edges.push(LeafEdge::new(ctrl, form));
                }
                continue;
            }
            if depth >= MAX_DEPTH {
                acc.out.uncertified_pieces += 1;
                acc.sum.add(corner_quad_solid_angle(&net));
                continue;
            }
            for half in split_net(net) {
                stack.push((half, depth + 1));
            }
        }
    }
}

/// The sum under construction.
struct Accumulator {
    sum: NeumaierSum,
    tol: f64,
    out: Evaluation,
}

impl Accumulator {
    fn integrate(&mut self, ctrl: &[Homogeneous], form: Form) {
        let r: Integral = integrate(
            |t| {
                let (n, dn) = eval_with_derivative(ctrl, t);
                integrand(form, n, dn)
            },
            0.0,
            1.0,
            self.tol,
        );
        self.sum.add(r.value);
        self.out.error_estimate += r.error;
        self.out.integrals += 1;
        self.out.evaluations += r.evaluations;
    }

    /// The edge `ctrl` (oriented as in the loop of a piece with form `form`) is shared with a
    /// piece of the other form: `∫(α_form − α_other) = ±2∫dφ`. If `other_ctrl` is given (the
    /// neighbour's copy), an uncertifiable azimuth falls back to integrating both sides.
    fn interface(&mut self, ctrl: &[Homogeneous], form: Form, other_ctrl: Option<&[Homogeneous]>) {
        let sign = match form {
            Form::Up => 2.0,
            Form::Down => -2.0,
        };
        match azimuth_change(ctrl) {
            Some(a) => self.sum.add(sign * a),
            None => {
                // Unreachable when the classification holds (the edge then avoids the ray's
                // line); kept so that a violated assumption costs time, not correctness.
                let other = match form {
                    Form::Up => Form::Down,
                    Form::Down => Form::Up,
                };
                self.integrate(ctrl, form);
                let reversed: Vec<Homogeneous> = match other_ctrl {
                    Some(c) => c.to_vec(),
                    None => ctrl.iter().rev().copied().collect(),
                };
                self.integrate(&reversed, other);
            }
        }
    }

    /// Cancels leaf edges against each other and integrates the rest.
    fn leaf_edges(&mut self, mut edges: Vec<LeafEdge>) {
        edges.sort_by(|a, b| a.key.cmp(&b.key).then(a.form.cmp(&b.form)));
        let mut start = 0;
        while start < edges.len() {
            let mut end = start + 1;
            while end < edges.len() && edges[end].key == edges[start].key {
                end += 1;
            }
            let group = &edges[start..end];
            // Pair opposite traversals: same form first (they cancel), then mixed forms.
            let mut used = vec![false; group.len()];
            for same_form in [true, false] {
                for i in 0..group.len() {
                    if used[i] {
                        continue;
                    }
                    let partner = (0..group.len()).find(|&j| {
                        !used[j]
                            && j != i
                            && group[j].forward != group[i].forward
                            && (group[j].form == group[i].form) == same_form
                    });
                    if let Some(j) = partner {
                        used[i] = true;
                        used[j] = true;
                        if !same_form {
                            self.interface(&group[i].ctrl, group[i].form, Some(&group[j].ctrl));
                        }
                    }
                }
            }
            for (i, e) in group.iter().enumerate() {
                if !used[i] {
                    self.integrate(&e.ctrl, e.form);
                }
            }
            start = end;
        }
    }
}

/// An edge of a classified piece of a mixed patch.
struct LeafEdge {
    /// Bits of the control points in canonical direction.
    key: Vec<u64>,
    /// Whether `ctrl` runs in the key's direction.
    forward: bool,
    form: Form,
    ctrl: Vec<Homogeneous>,
}

impl LeafEdge {
    fn new(ctrl: Vec<Homogeneous>, form: Form) -> LeafEdge {
        let bits = |it: &mut dyn Iterator<Item = &Homogeneous>| -> Vec<u64> {
            it.flat_map(|h| h.map(|c| (c + 0.0).to_bits())).collect()
        };
        let fwd = bits(&mut ctrl.iter());
        let rev = bits(&mut ctrl.iter().rev());
        let (key, forward) = if fwd <= rev {
            (fwd, true)
        } else {
            (rev, false)
        };
        LeafEdge {
            key,
            forward,
            form,
            ctrl,
        }
    }
}

/// The eight axis and diagonal directions of the `xy` plane.
const DIRECTIONS: [[f64; 2]; 8] = [
    [1.0, 0.0],
    [1.0, 1.0],
    [0.0, 1.0],
    [-1.0, 1.0],
    [-1.0, 0.0],
    [-1.0, -1.0],
    [0.0, -1.0],
    [1.0, -1.0],
];

/// The form a leaf net can use, or `None` if it must be subdivided.
fn classify(net: &Net) -> Option<Form> {
    classify_points(
        net.h.iter().map(|h| {
            if h[3] == 1.0 {
                [h[0], h[1], h[2]]
            } else {
                [h[0] / h[3], h[1] / h[3], h[2] / h[3]]
            }
        }),
        None,
    )
}

/// The form a piece with (Euclidean, frame, query-relative) control points `pts` can use, or
/// `None` if it must be subdivided. `z` is `(min z, max z, coordinate scale)` when known.
///
/// First the exact height tests; then separating planes through the query with margin `μ`,
/// tried in the direction of the control points' mean: the flat plane whose normal is the
/// direction `h` (of [`DIRECTIONS`]) closest to the mean's azimuth, its two neighbours, and the
/// best one tilted towards `−z` (certifies [`Form::Down`]) and `+z` ([`Form::Up`]).
fn classify_points(
    pts: impl Iterator<Item = [f64; 3]> + Clone,
    z: Option<(f64, f64, f64)>,
) -> Option<Form> {
    let (z0, z1, scale) = z.unwrap_or_else(|| {
        let mut r = (f64::INFINITY, f64::NEG_INFINITY, 0.0f64);
        for p in pts.clone() {
            r.0 = r.0.min(p[2]);
            r.1 = r.1.max(p[2]);
            r.2 = r.2.max(p[0].abs()).max(p[1].abs()).max(p[2].abs());
        }
        r
    });
    let slack = Z_SLACK * scale;
    if z0 > slack {
        return Some(Form::Up);
    }
    if z1 < -slack {
        return Some(Form::Down);
    }
    let (mut mx, mut my) = (0.0, 0.0);
    for p in pts.clone() {
        let r = (p[0] * p[0] + p[1] * p[1] + p[2] * p[2]).sqrt();
        if r > 0.0 {
            mx += p[0] / r;
            my += p[1] / r;
        }
    }
    let best = (0..8)
        .max_by(|&a, &b| {
            let score = |i: usize| {
                let h = DIRECTIONS[i];
                (h[0] * mx + h[1] * my) / (h[0].abs() + h[1].abs()).sqrt()
            };
            score(a).total_cmp(&score(b))
        })
        .unwrap_or(0);
    let m2 = MARGIN * MARGIN;
    let separates = |n: [f64; 3]| {
        let nn = n[0] * n[0] + n[1] * n[1] + n[2] * n[2];
        pts.clone().all(|p| {
            let d = n[0] * p[0] + n[1] * p[1] + n[2] * p[2];
            d > 0.0 && d * d >= m2 * nn * (p[0] * p[0] + p[1] * p[1] + p[2] * p[2])
        })
    };
    for i in [best, (best + 1) % 8, (best + 7) % 8] {
        let h = DIRECTIONS[i];
        if separates([h[0], h[1], 0.0]) {
            return Some(Form::Down);
        }
    }
    let h = DIRECTIONS[best];
    if separates([h[0], h[1], -1.0]) {
        return Some(Form::Down);
    }
    if separates([h[0], h[1], 1.0]) {
        return Some(Form::Up);
    }
    None
}

/// The four quarters of a net (halved in `s` and in `t`; a direction of degree 0 is not split).
fn split_net(net: Net) -> Vec<Net> {
    let halves_s = if net.m > 0 {
        let (a, b) = split_rows(&net);
        vec![a, b]
    } else {
        vec![net]
    };
    let mut out = Vec::with_capacity(4);
    for h in halves_s {
        if h.n > 0 {
            let t = transpose(&h);
            let (a, b) = split_rows(&t);
            out.push(transpose(&a));
            out.push(transpose(&b));
        } else {
            out.push(h);
        }
    }
    out
}

/// Halves a net in `s` (along its columns).
fn split_rows(net: &Net) -> (Net, Net) {
    let (m, n) = (net.m, net.n);
    let mut a = vec![[0.0; 4]; net.h.len()];
    let mut b = vec![[0.0; 4]; net.h.len()];
    for j in 0..=n {
        let col: Vec<Homogeneous> = (0..=m).map(|i| net.h[i * (n + 1) + j]).collect();
        let (l, r) = split_half(&col);
        for i in 0..=m {
            a[i * (n + 1) + j] = l[i];
            b[i * (n + 1) + j] = r[i];
        }
    }
    (Net { m, n, h: a }, Net { m, n, h: b })
}

fn transpose(net: &Net) -> Net {
    let (m, n) = (net.m, net.n);
    let mut h = vec![[0.0; 4]; net.h.len()];
    for i in 0..=m {
        for j in 0..=n {
            h[j * (m + 1) + i] = net.h[i * (n + 1) + j];
        }
    }
    Net { m: n, n: m, h }
}

/// Principal-value solid angle of a tiny piece's corner quad (the query lies on it to `f64`
/// resolution), oriented like the loop `(s,t) = (0,0) → (0,1) → (1,1) → (1,0)`.
fn corner_quad_solid_angle(net: &Net) -> f64 {
    let e = |k: usize| {
        let h = net.h[k];
        [h[0] / h[3], h[1] / h[3], h[2] / h[3]]
    };
    let (m, n) = (net.m, net.n);
    let c00 = e(0);
    let c01 = e(n);
    let c11 = e(m * (n + 1) + n);
    let c10 = e(m * (n + 1));
    // Same orientation as the loop (normal ∂S/∂t × ∂S/∂s), and Van Oosterom–Strackee counts
    // a face positively when its normal points away from the query, as the potentials do.
    triangle_solid_angle(c00, c01, c11) + triangle_solid_angle(c00, c11, c10)
}

/// Patch sets plug into grids and products like the triangle evaluators (no gradient yet).
impl crate::eval::Evaluator for PatchWindingNumber {
    fn eval(&self, q: [f64; 3]) -> f64 {
        PatchWindingNumber::eval(self, q)
    }
    fn name(&self) -> &'static str {
        "exact (patches)"
    }
    fn eval_batch(&self, points: &[[f64; 3]]) -> Vec<f64> {
        PatchWindingNumber::eval_batch(self, points)
    }
}
