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

use crate::kernel::spherical::FOUR_PI;

use rayon::prelude::*;

use super::boundary::{EdgeLink, edge_counts, edge_indices, link_edges};
use super::curve::{
    Form, Homogeneous, azimuth_change, eval_with_derivative, evaluation_rounding,
    integrand_with_rounding, split_half, split_half_with,
};
use super::model::{Patch, PatchSet};
use super::quadrature::{Budget, GK_EVALUATIONS, integrate, integrate_dyadic};
use super::ray_hits::{BoxedPatch, PatchHit, RayFrame, SurfaceEdges, patch_hits};
use super::samples::{CACHE_LEVELS, CurveSamples};
use crate::base::bounding_box::segment_meets_box;
use crate::base::compensated::NeumaierSum;
use crate::base::vec3::{cross, norm, sub};
use crate::eval::SurfaceCrossing;
use crate::kernel::frame::RayAxis;

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
/// Size (as a depth: `2^-26` of its patch, ≈ 1.5e-8) of the hole cut around an on-surface
/// query. When a piece at this depth contains a sub-piece that stays mixed to [`MAX_DEPTH`],
/// the whole piece is left out and the value is the solid angle of the rest of the surface,
/// i.e. the principal value (`docs/patches.md`, "On the surface"). Not `MAX_DEPTH` itself: the
/// rest is bounded by curves about the hole's size from the query, and their integrals carry
/// rounding `≈ ε·(patch size)/(hole size)` (`2^-26` here; `1/16` at `2^-48`), while leaving the
/// hole out changes the value by about its curvature times its size (also `≈ 2^-26`).
const HOLE_DEPTH: u32 = 26;
/// Error charged per on-surface hole piece, in units of `w`: the principal value's deviation
/// from the hole's left-out solid angle, `≈ κ h / 4π ≤ h / L` for a smooth surface (`h` the
/// hole's size, `L` its patch's, `κ ≲ 1/L`).
const HOLE_ERROR: f64 = 1.0 / (1u64 << HOLE_DEPTH) as f64;
/// Error charged per hole piece of a patch that has a surface-boundary edge: a query on an open
/// boundary curve sits where `w` spans an interval of length 1 around it, and the value left
/// after cutting the hole is only known to lie in that interval.
const HOLE_ERROR_AT_BOUNDARY: f64 = 0.5;
/// At most this many mixed pieces are subdivided per query. With the collapsed-side rule of
/// [`split_net`] the pieces that stay mixed are those around the query, a few per level, so
/// this is never reached by a real query; past it the remaining mixed pieces are left out like
/// a hole and the evaluation is marked `capped`.
pub const MAX_PIECES: usize = 4096;
/// At most about this many integrand evaluations per query ([`Budget`]): past it no
/// Gauss–Kronrod interval is bisected and no boundary curve is split any more, and the
/// evaluation is marked `capped`. With the work of classification and subdivision
/// ([`MAX_PIECES`]) this bounds the time of every query (`docs/patches.md`, "Time bound").
pub const MAX_EVALUATIONS: usize = 200_000;
/// A boundary curve is halved (exact de Casteljau) until each piece's control box is at most
/// this many times its distance from the query, before the quadrature sees it. The integrand
/// of a piece is then smooth at the piece's own scale, and its rounding, relative `≈ ε·size /
/// distance`, stays at `ε` level (evaluated on the whole curve, it is `ε·(curve size)/ρ`,
/// 1e-10 relative for a curve 1e-6 from the query: the cause of the issue-23 hangs).
const CURVE_SPLIT_RATIO: f64 = 1.0;
/// Halving depth limit of a boundary curve (`2^-60` of it: a query on the curve itself).
const CURVE_MAX_DEPTH: u32 = 60;
/// A certified value of a closed set is rounded to the integer it approximates when its error
/// estimate is below this (any value below ½ identifies the integer; a quarter leaves the
/// estimate a factor of two of slack).
const CLOSED_ROUNDING_LIMIT: f64 = 0.25;

/// Options of the patch evaluator.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Options {
    /// Ray direction (default `+z`); every choice gives the same `w` off the surface.
    pub ray: RayAxis,
    /// Target absolute error of `w` (default `1e-10`): the boundary integrals of a query share
    /// it (each gets `tolerance / count`, split further by parameter length), so the total
    /// [`Evaluation::error_estimate`] stays below it unless rounding or the work cap prevents
    /// that — then the evaluation is not `certified`.
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
    /// Sum of the error estimates of the boundary integrals (`max(|K15 − G7|, rounding)` per
    /// accepted interval) and, per on-surface hole piece, [`HOLE_ERROR`] (or
    /// [`HOLE_ERROR_AT_BOUNDARY`] in a patch with an open boundary edge), in units of `w`.
    pub error_estimate: f64,
    /// Boundary integrals computed.
    pub integrals: usize,
    /// Integrand evaluations.
    pub evaluations: usize,
    /// Patches that had to be subdivided.
    pub mixed_patches: usize,
    /// Pieces left out as the hole around an on-surface query (a sub-piece stayed mixed to the
    /// depth limit: the query is on the surface to `f64` resolution); the value is then the
    /// principal value of the rest (`docs/patches.md`, "On the surface").
    pub uncertified_pieces: usize,
    /// The work cap ([`MAX_EVALUATIONS`] or [`MAX_PIECES`]) was reached.
    pub capped: bool,
    /// The value is certified: no hole, no cap, and `error_estimate ≤ tolerance`.
    pub certified: bool,
}

/// The winding-number evaluator of a patch set.
#[derive(Clone, Debug)]
pub struct PatchWindingNumber {
    set: PatchSet,
    /// The set with coordinates scaled by `2^-coord_exp` and each patch's weights by a power
    /// of two (exact), so that the largest coordinate and weight are in `[0.5, 1)`.
    scaled: PatchSet,
    /// The coordinate scale exponent (see `scaled`).
    coord_exp: i32,
    links: Vec<[EdgeLink; 4]>,
    edges: Vec<[Vec<usize>; 4]>,
    /// World bounding box of each patch's control points.
    boxes: Vec<([f64; 3], [f64; 3])>,
    /// No edge is a surface boundary (every one is paired with a reversed twin, bit for bit,
    /// or collapsed): the set bounds a solid, and `w` off the surface is an integer.
    closed: bool,
    /// Precomputed quadrature samples of the surface-boundary edges (`links` = `Boundary`), in
    /// the ray frame of `options.ray`: the query-independent part of their integrals.
    samples: Vec<[Option<CurveSamples>; 4]>,
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
        Self::build(set, Options::default())
    }

    /// An evaluator with the given options; a tolerance that is not a finite positive number
    /// is refused.
    pub fn with_options(set: &PatchSet, options: Options) -> Result<Self, super::ToleranceError> {
        super::ToleranceError::check(options.tolerance)?;
        Ok(Self::build(set, options))
    }

    fn build(set: &PatchSet, options: Options) -> Self {
        let links = link_edges(set);
        let (scaled, coord_exp) = rescaled(set);
        let edges = set
            .patches()
            .iter()
            .map(|p| {
                let (m, n) = p.degree();
                std::array::from_fn(|e| edge_indices(m, n, e))
            })
            .collect();
        let boxes = scaled
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
        let samples = scaled
            .patches()
            .iter()
            .enumerate()
            .map(|(p, patch)| {
                std::array::from_fn(|e| {
                    if links[p][e] != EdgeLink::Boundary {
                        return None;
                    }
                    let ctrl = edges_of(patch, e)
                        .map(|(pt, w)| {
                            let f = options.ray.to_frame(pt);
                            [w * f[0], w * f[1], w * f[2], w]
                        })
                        .collect();
                    Some(CurveSamples::new(ctrl))
                })
            })
            .collect();
        let closed = links.iter().flatten().all(|l| *l != EdgeLink::Boundary);
        PatchWindingNumber {
            set: set.clone(),
            scaled,
            coord_exp,
            links,
            edges,
            boxes,
            closed,
            samples,
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

    /// Where the segment `a → b` crosses the patches, sorted along it, each with the unit normal
    /// `S_s × S_t` there: the ray hit search of the trimmed B-rep evaluator
    /// (`StepWindingNumber::segment_crossings`, without the trimming), on every patch whose box the
    /// segment meets, up to the segment's end. Proposals for a caller that verifies them with
    /// the field ([`crate::eval::Evaluator::segment_crossings`]; the remesher's placement): a
    /// crossing on the shared edge of two patches is listed once; one the search cannot
    /// resolve (a tangency, a collapsed patch edge such as a sphere's pole) is not listed.
    /// Empty for a degenerate or non-finite segment.
    pub fn segment_crossings(&self, a: [f64; 3], b: [f64; 3]) -> Vec<SurfaceCrossing> {
        // In the scaled set's coordinates: a power of two, exact, so the hits are the world
        // set's, scaled (the boxes are the scaled set's).
        let [a, b] = [a, b].map(|p| p.map(|c| scale_by_pow2(c, -self.coord_exp)));
        let d = sub(b, a);
        let length = norm(d);
        if !(length.is_finite() && length > 0.0) || a.iter().any(|c| !c.is_finite()) {
            return Vec::new();
        }
        let frame = RayFrame::new(d.map(|x| x / length));
        let mut hits = Vec::new();
        let mut diagonal = 0.0f64;
        for (patch, &(lo, hi)) in self.scaled.patches().iter().zip(&self.boxes) {
            // The pad of the STEP faces' box test, relative to the patch.
            let size = norm(sub(hi, lo));
            diagonal = diagonal.max(size);
            if segment_meets_box(a, frame.d, length, lo, hi, 1e-9 * size) {
                let patch = BoxedPatch { patch, lo, hi };
                let edges = SurfaceEdges::NONE;
                patch_hits(patch, edges, a, &frame, length, &mut hits, &mut Vec::new());
            }
        }
        hits.retain(|h| (0.0..=length).contains(&h.tau));
        hits.sort_by(|x, y| x.tau.total_cmp(&y.tau));
        // A crossing on the shared edge of two patches is found by both: one crossing (the
        // STEP faces' rule, a point within 1e-9 of the largest patch's size).
        let mut kept: Vec<PatchHit> = Vec::with_capacity(hits.len());
        for h in hits {
            if kept
                .last()
                .is_none_or(|k| norm(sub(k.point, h.point)) > 1e-9 * diagonal)
            {
                kept.push(h);
            }
        }
        kept.into_iter()
            .map(|h| {
                let n = cross(h.ds, h.dt);
                let l = norm(n);
                SurfaceCrossing {
                    t: h.tau / length,
                    normal: if l > 0.0 && l.is_finite() {
                        n.map(|x| x / l)
                    } else {
                        [0.0; 3]
                    },
                }
            })
            .collect()
    }

    /// [`evaluate`](Self::evaluate) at many points, in parallel.
    pub fn evaluate_batch(&self, points: &[[f64; 3]]) -> Vec<Evaluation> {
        points.par_iter().map(|&q| self.evaluate(q)).collect()
    }

    /// The winding number at `q` with its error estimate and work counters. Bounded work:
    /// at most [`MAX_PIECES`] subdivided pieces and about [`MAX_EVALUATIONS`] integrand
    /// evaluations (`docs/patches.md`, "Time bound").
    pub fn evaluate(&self, q: [f64; 3]) -> Evaluation {
        if q.iter().any(|c| !c.is_finite()) {
            return Evaluation {
                value: f64::NAN,
                ..Evaluation::default()
            };
        }
        // The same exact power-of-two scaling as the set's (the mesh path's `Rescale`).
        let q = q.map(|c| scale_by_pow2(c, -self.coord_exp));
        if q.iter().any(|c| !c.is_finite()) {
            // Beyond 2^1023 from a set of size ≤ 1: |w| < 2^-2000.
            return Evaluation {
                certified: true,
                ..Evaluation::default()
            };
        }
        let mut acc = Accumulator {
            sum: NeumaierSum::new(),
            out: Evaluation::default(),
            tasks: Vec::new(),
            pieces: 0,
            hole_error: HOLE_ERROR,
            holes_error: 0.0,
        };
        let ray = self.options.ray;
        let patches = self.scaled.patches();
        let frame_point = |p: usize, k: usize| -> [f64; 3] {
            let pt = patches[p].points()[k];
            ray.to_frame([pt[0] - q[0], pt[1] - q[1], pt[2] - q[2]])
        };
        let forms: Vec<Option<Form>> = (0..patches.len())
            .map(|p| {
                let z = self.frame_z_range(p, q);
                classify_points(
                    (0..patches[p].points().len()).map(|k| frame_point(p, k)),
                    Some(z),
                )
            })
            .collect();
        let edge_ctrl = |p: usize, e: usize| -> Vec<Homogeneous> {
            let weights = patches[p].weights();
            self.edges[p][e]
                .iter()
                .map(|&k| {
                    let d = frame_point(p, k);
                    let w = weights[k];
                    [w * d[0], w * d[1], w * d[2], w]
                })
                .collect()
        };
        // Edges of classified patches next to a mixed one join the mixed patch's leaf edges:
        // the leaves along the shared edge are its dyadic pieces, bit for bit (de Casteljau
        // halving of the net halves its boundary rows as `split_half` halves the edge), so
        // `leaf_edges` can cancel them piece by piece instead of integrating both sides.
        let mut leaf_edges = Vec::new();
        for (p, form) in forms.iter().enumerate() {
            let Some(form) = *form else { continue };
            for e in 0..4 {
                match self.links[p][e] {
                    EdgeLink::Degenerate => {}
                    EdgeLink::Boundary => acc.tasks.push(Task::Edge(p, e, form)),
                    EdgeLink::Shared { patch: o, .. } => match forms[o] {
                        None => leaf_edges.push(LeafEdge::new(edge_ctrl(p, e), form)),
                        Some(g) if g == form => {}
                        Some(_) if p < o => acc.interface(&edge_ctrl(p, e), form, None),
                        Some(_) => {}
                    },
                }
            }
        }
        for (p, patch) in patches.iter().enumerate() {
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
                acc.hole_error = if self.links[p].contains(&EdgeLink::Boundary) {
                    HOLE_ERROR_AT_BOUNDARY
                } else {
                    HOLE_ERROR
                };
                acc.refine(Net { m, n, h }, 0, &mut leaf_edges);
            }
        }
        acc.leaf_edges(leaf_edges);
        let q_frame = ray.to_frame(q);
        let mut out = acc.finish(self.options.tolerance, |task, acc, tol, budget| {
            let (p, e, form) = task;
            match &self.samples[p][e] {
                Some(s) => acc.integrate_sampled(s, || edge_ctrl(p, e), form, q_frame, tol, budget),
                None => acc.integrate_curve(edge_ctrl(p, e), form, tol, budget),
            }
        });
        // A closed set's `w` is an integer off the surface (its boundary is empty), and a
        // certified value is within its estimate of it: that integer, exactly, as the mesh and
        // STEP evaluators give (the sum itself is an integer only up to the rounding of its
        // interface terms). Values on the surface are not certified and stay the principal value.
        if self.closed && out.certified && out.error_estimate < CLOSED_ROUNDING_LIMIT {
            out.value = out.value.round() + 0.0; // `+ 0.0`: −0 is 0
        }
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
}

/// The sum under construction.
struct Accumulator {
    sum: NeumaierSum,
    out: Evaluation,
    /// Boundary curves to integrate (with their piece's form), deferred so that the tolerance
    /// can be shared among them.
    tasks: Vec<Task>,
    /// Mixed pieces subdivided so far (capped by [`MAX_PIECES`]).
    pieces: usize,
    /// Error charged per hole piece of the patch being refined ([`HOLE_ERROR`] or
    /// [`HOLE_ERROR_AT_BOUNDARY`]), and the sum charged so far (units of `w`).
    hole_error: f64,
    holes_error: f64,
}

impl Accumulator {
    /// Adds one integral (or azimuth) term and its error. A term that is not finite (rounding
    /// gone past `f64`'s range: a fuzzed unit cube with one control point at `1.2·10^155`,
    /// queried at a corner, whose pieces shrink below the smallest normal number after the
    /// set's scaling) is left out of the sum and flags the value with an infinite estimate:
    /// the value stays finite and is not certified.
    fn add_term(&mut self, value: f64, error: f64) {
        if value.is_finite() {
            self.sum.add(value);
            self.out.error_estimate += error;
        } else {
            self.out.uncertified_pieces += 1;
            self.out.error_estimate = f64::INFINITY;
        }
    }

    fn integrate(&mut self, ctrl: Vec<Homogeneous>, form: Form) {
        self.tasks.push(Task::Curve(ctrl, form));
    }

    /// Integrates the deferred curves, each with `tolerance / count` (in units of `w`), and
    /// returns the evaluation. `edge` integrates a [`Task::Edge`] (patch, edge, form).
    fn finish(
        mut self,
        tolerance: f64,
        edge: impl Fn((usize, usize, Form), &mut Accumulator, f64, &mut Budget),
    ) -> Evaluation {
        let tasks = std::mem::take(&mut self.tasks);
        let tol = tolerance * FOUR_PI / tasks.len().max(1) as f64;
        let mut budget = Budget {
            remaining: MAX_EVALUATIONS,
        };
        for task in tasks {
            match task {
                Task::Curve(ctrl, form) => self.integrate_curve(ctrl, form, tol, &mut budget),
                Task::Edge(p, e, form) => edge((p, e, form), &mut self, tol, &mut budget),
            }
        }
        let mut out = self.out;
        out.value = self.sum.value() / FOUR_PI;
        out.error_estimate = out.error_estimate / FOUR_PI + self.holes_error;
        out.certified =
            out.uncertified_pieces == 0 && !out.capped && out.error_estimate <= tolerance;
        out
    }

    /// `∫ α_form` over one boundary curve to absolute tolerance `tol` (units of `4π w`). The
    /// curve is first halved where it is large compared with its distance from the query
    /// (`CURVE_SPLIT_RATIO`), each piece getting the tolerance share of its parameter length;
    /// then adaptive Gauss–Kronrod with the integrand's rounding bound.
    fn integrate_curve(
        &mut self,
        ctrl: Vec<Homogeneous>,
        form: Form,
        tol: f64,
        budget: &mut Budget,
    ) {
        self.out.integrals += 1;
        self.integrate_pieces(vec![(ctrl, 1.0, 0)], form, tol, budget);
    }

    /// [`integrate_curve`](Self::integrate_curve) for a surface-boundary edge with
    /// precomputed samples `s` (`super::samples`): the same splitting of the curve where it is
    /// large compared with its distance from the query (`q_frame`: the query in the ray frame),
    /// but pieces down to [`CACHE_LEVELS`] are dyadic intervals of the curve's own parameter,
    /// integrated from the samples. A piece that must be split deeper, or that lies too close
    /// to the query for the centred samples' rounding ([`CurveSamples::usable_at`]), takes
    /// the uncached path on its control points relative to the query (`relative()`: the
    /// whole edge, halved as that path halves it).
    fn integrate_sampled(
        &mut self,
        s: &CurveSamples,
        relative: impl Fn() -> Vec<Homogeneous>,
        form: Form,
        q_frame: [f64; 3],
        tol: f64,
        budget: &mut Budget,
    ) {
        self.out.integrals += 1;
        let delta = s.offset(q_frame);
        let (en, edn) = s.rounding(delta);
        // Depth first over the levels `0..=CACHE_LEVELS` (at most one pending piece per level
        // plus the root); pieces for the uncached path, in order (at most `2^CACHE_LEVELS`).
        let mut stack = [(0u32, 0u64); CACHE_LEVELS as usize + 2];
        let mut pending = 1;
        let mut uncached = [(0u32, 0u64); 1 << CACHE_LEVELS];
        let mut uncached_count = 0;
        while pending > 0 {
            pending -= 1;
            let (level, index) = stack[pending];
            let (distance, size) = s.piece_distance_and_size(level, index, delta);
            let split = size > CURVE_SPLIT_RATIO * distance
                && level < CURVE_MAX_DEPTH
                && budget.remaining > GK_EVALUATIONS;
            if split && level < CACHE_LEVELS {
                stack[pending] = (level + 1, 2 * index + 1);
                stack[pending + 1] = (level + 1, 2 * index);
                pending += 2;
                continue;
            }
            if !split && s.usable_at(distance) {
                let r = integrate_dyadic(
                    |l, i| s.rule(form, l, i, delta, en, edn),
                    level,
                    index,
                    tol * 0.5f64.powi(level as i32),
                    budget,
                );
                self.add_term(r.value, r.error);
                self.out.evaluations += r.evaluations;
                self.out.capped |= r.capped > 0;
            } else {
                uncached[uncached_count] = (level, index);
                uncached_count += 1;
            }
        }
        if uncached_count == 0 {
            if budget.remaining <= GK_EVALUATIONS {
                self.out.capped = true;
            }
            return;
        }
        // The uncached pieces, cut from the query-relative edge by exact halving (the same
        // bits as the uncached path's own splitting), in the stack's order.
        let whole = relative();
        let pieces = uncached[..uncached_count]
            .iter()
            .rev()
            .map(|&(level, index)| {
                let mut ctrl = whole.clone();
                for bit in (0..level).rev() {
                    let (a, b) = split_half(&ctrl);
                    ctrl = if (index >> bit) & 1 == 0 { a } else { b };
                }
                (ctrl, 0.5f64.powi(level as i32), level)
            })
            .collect();
        self.integrate_pieces(pieces, form, tol, budget);
    }

    /// The splitting and quadrature loop of [`integrate_curve`](Self::integrate_curve), from
    /// the pieces `stack` (control points, tolerance share, depth).
    fn integrate_pieces(
        &mut self,
        mut stack: Vec<(Vec<Homogeneous>, f64, u32)>,
        form: Form,
        tol: f64,
        budget: &mut Budget,
    ) {
        while let Some((ctrl, share, depth)) = stack.pop() {
            let (distance, size) = distance_and_size(&ctrl);
            if size > CURVE_SPLIT_RATIO * distance
                && depth < CURVE_MAX_DEPTH
                && budget.remaining > GK_EVALUATIONS
            {
                let (a, b) = split_half(&ctrl);
                stack.push((b, 0.5 * share, depth + 1));
                stack.push((a, 0.5 * share, depth + 1));
                continue;
            }
            let (en, edn) = evaluation_rounding(&ctrl);
            let r = integrate(
                |t| {
                    let (n, dn) = eval_with_derivative(&ctrl, t);
                    integrand_with_rounding(form, n, dn, en, edn)
                },
                0.0,
                1.0,
                tol * share,
                budget,
            );
            self.add_term(r.value, r.error);
            self.out.evaluations += r.evaluations;
            self.out.capped |= r.capped > 0;
        }
        if budget.remaining <= GK_EVALUATIONS {
            self.out.capped = true;
        }
    }

    /// Halves a mixed net until its pieces are classified and records their edges. Returns
    /// `false` if a piece deeper than [`HOLE_DEPTH`] stayed mixed to [`MAX_DEPTH`] (the query
    /// is on it): its ancestor at `HOLE_DEPTH` then drops its whole subtree as the hole.
    fn refine(&mut self, net: Net, depth: u32, leaves: &mut Vec<LeafEdge>) -> bool {
        if let Some(form) = classify(&net) {
            for e in 0..4 {
                let (m, n) = (net.m, net.n);
                let at = |i: usize, j: usize| net.h[i * (n + 1) + j];
                // Loop order of `edge_indices`, without its index vector.
                let ctrl: Vec<Homogeneous> = match e {
                    0 => (0..=n).map(|j| at(0, j)).collect(),
                    1 => (0..=m).map(|i| at(i, n)).collect(),
                    2 => (0..=n).rev().map(|j| at(m, j)).collect(),
                    _ => (0..=m).rev().map(|i| at(i, 0)).collect(),
                };
                if ctrl.iter().all(|c| *c == ctrl[0]) {
                    continue;
                }
                leaves.push(LeafEdge::new(ctrl, form));
            }
            return true;
        }
        if depth >= MAX_DEPTH {
            return false;
        }
        if self.pieces >= MAX_PIECES {
            self.out.capped = true;
            if depth > HOLE_DEPTH {
                return false;
            }
            self.out.uncertified_pieces += 1;
            self.holes_error += self.hole_error;
            return true;
        }
        self.pieces += 1;
        let mark = leaves.len();
        for piece in split_net(net) {
            if !self.refine(piece, depth + 1, leaves) {
                if depth > HOLE_DEPTH {
                    return false;
                }
                // The hole: this piece's pieces already recorded are dropped with it, so the
                // rest of the surface sees one hole bounded by this piece's edges.
                leaves.truncate(mark);
                self.out.uncertified_pieces += 1;
                self.holes_error += self.hole_error;
                return true;
            }
        }
        true
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
            Some(a) => self.add_term(sign * a, 0.0),
            None => {
                // Unreachable when the classification holds (the edge then avoids the ray's
                // line); kept so that a violated assumption costs time, not correctness.
                let other = match form {
                    Form::Up => Form::Down,
                    Form::Down => Form::Up,
                };
                self.integrate(ctrl.to_vec(), form);
                let reversed: Vec<Homogeneous> = match other_ctrl {
                    Some(c) => c.to_vec(),
                    None => ctrl.iter().rev().copied().collect(),
                };
                self.integrate(reversed, other);
            }
        }
    }

    /// Cancels leaf edges against each other and integrates the rest.
    fn leaf_edges(&mut self, mut edges: Vec<LeafEdge>) {
        edges.sort_by(|a, b| a.key.cmp(&b.key).then(a.form.cmp(&b.form)));
        let mut unpaired = Vec::new();
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
            for (i, &used) in used.iter().enumerate() {
                if !used {
                    unpaired.push(i + start);
                }
            }
            start = end;
        }
        self.match_halves(&edges, unpaired);
    }

    /// The leaf edges that found no partner of the same extent: an edge of a piece next to
    /// two or more smaller pieces (or a patch edge next to a subdivided neighbour) is halved
    /// (exact de Casteljau) as long as a half is some other unpaired edge traversed the other
    /// way; matched halves cancel or become interfaces as in [`leaf_edges`](Self::leaf_edges),
    /// the rest is integrated. Longer edges first, so that an edge is cut to the pieces of its
    /// finer neighbours rather than the reverse.
    fn match_halves(&mut self, edges: &[LeafEdge], unpaired: Vec<usize>) {
        if unpaired.is_empty() {
            return;
        }
        // `unpaired` is in key order (`edges` is sorted): lookups are binary searches.
        let lookup = Lookup {
            edges,
            sorted: unpaired.clone(),
        };
        let extent = |e: &LeafEdge| {
            let (a, b) = (e.ctrl[0], e.ctrl[e.ctrl.len() - 1]);
            (0..3)
                .map(|k| (a[k] / a[3] - b[k] / b[3]).powi(2))
                .sum::<f64>()
        };
        let mut order = unpaired;
        order.sort_by(|&a, &b| {
            extent(&edges[b])
                .total_cmp(&extent(&edges[a]))
                .then(a.cmp(&b))
        });
        let mut consumed = vec![false; edges.len()];
        for &i in &order {
            if consumed[i] {
                continue;
            }
            consumed[i] = true;
            let e = &edges[i];
            self.resolve_or_integrate(e.ctrl.clone(), e.form, 0, &lookup, &mut consumed);
        }
    }

    /// Halves `ctrl` if a half has an unconsumed partner (see
    /// [`match_halves`](Self::match_halves)), pairing each matched half, else integrates it.
    fn resolve_or_integrate(
        &mut self,
        ctrl: Vec<Homogeneous>,
        form: Form,
        depth: u32,
        lookup: &Lookup,
        consumed: &mut [bool],
    ) {
        if depth < MAX_DEPTH {
            let (a, b) = split_half(&ctrl);
            let (ka, fa) = canonical_key(&a);
            let (kb, fb) = canonical_key(&b);
            let pa = lookup.partner(&ka, fa, consumed);
            let pb = lookup.partner(&kb, fb, consumed);
            if pa.is_some() || pb.is_some() {
                for (half, partner) in [(a, pa), (b, pb)] {
                    match partner {
                        Some(j) => {
                            consumed[j] = true;
                            let other = &lookup.edges[j];
                            if other.form != form {
                                self.interface(&half, form, Some(&other.ctrl));
                            }
                        }
                        None => self.resolve_or_integrate(half, form, depth + 1, lookup, consumed),
                    }
                }
                return;
            }
        }
        self.integrate(ctrl, form);
    }
}

/// The unpaired leaf edges of [`Accumulator::match_halves`], sorted by key.
struct Lookup<'a> {
    edges: &'a [LeafEdge],
    sorted: Vec<usize>,
}

impl Lookup<'_> {
    /// An unconsumed edge with key `key` traversed against `forward`.
    fn partner(&self, key: &[u64], forward: bool, consumed: &[bool]) -> Option<usize> {
        let start = self
            .sorted
            .partition_point(|&i| self.edges[i].key.as_slice() < key);
        self.sorted[start..]
            .iter()
            .copied()
            .take_while(|&i| self.edges[i].key.as_slice() == key)
            .find(|&i| !consumed[i] && self.edges[i].forward != forward)
    }
}

/// A deferred boundary integral.
enum Task {
    /// A curve by its control points (query-relative, ray frame) with its piece's form.
    Curve(Vec<Homogeneous>, Form),
    /// Edge `e` of patch `p`, a surface-boundary edge (it may have precomputed samples).
    Edge(usize, usize, Form),
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
        let (key, forward) = canonical_key(&ctrl);
        LeafEdge {
            key,
            forward,
            form,
            ctrl,
        }
    }
}

/// The bits of a curve's control points in its canonical direction (the lexicographically
/// smaller of the two traversals), and whether that is `ctrl`'s own direction.
fn canonical_key(ctrl: &[Homogeneous]) -> (Vec<u64>, bool) {
    // `+ 0.0` turns −0.0 into +0.0, so the two zeros compare equal as in f64.
    let bits = |h: &Homogeneous| h.map(|c| (c + 0.0).to_bits());
    let forward = ctrl
        .iter()
        .map(bits)
        .cmp(ctrl.iter().rev().map(bits))
        .is_le();
    let key = if forward {
        ctrl.iter().flat_map(bits).collect()
    } else {
        ctrl.iter().rev().flat_map(bits).collect()
    };
    (key, forward)
}

/// The control points and weights of edge `e` of `patch`, in loop order.
fn edges_of(patch: &Patch, e: usize) -> impl Iterator<Item = ([f64; 3], f64)> + '_ {
    let (m, n) = patch.degree();
    edge_indices(m, n, e)
        .into_iter()
        .map(move |k| (patch.points()[k], patch.weights()[k]))
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
    // The same with the points at the query's height allowed (a rim lying in the query's
    // plane, issue 23): every point either clears the height test or is at the right side's
    // height (sign exact) and at least `asin μ` away from the ray's line in the direction of
    // one `h`. The hull then meets the ray's line only at heights of the right sign (a point of
    // it on the line mixes in a point that clears the height test), and the potential's
    // denominator `ρ ± z ≥ ρ` keeps its integrand smooth at the scale of `ρ`.
    if z0 >= 0.0 || z1 <= 0.0 {
        let up = z0 >= 0.0;
        let m2 = MARGIN * MARGIN;
        for h in DIRECTIONS {
            let nn = h[0] * h[0] + h[1] * h[1];
            let ok = pts.clone().all(|p| {
                let clears = if up { p[2] > slack } else { p[2] < -slack };
                let d = h[0] * p[0] + h[1] * p[1];
                clears || (d > 0.0 && d * d >= m2 * nn * (p[0] * p[0] + p[1] * p[1] + p[2] * p[2]))
            });
            if ok {
                return Some(if up { Form::Up } else { Form::Down });
            }
        }
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

/// Relative distance below which the control points of a side count as one point (see
/// [`split_net`]).
const COLLAPSE_TOLERANCE: f64 = 1e-12;

/// The pieces of a mixed net: halved in `s` and in `t` (a direction of degree 0 is not split),
/// except that a net with a collapsed side (a row or column of equal control points, like the
/// teapot's knob and bottom poles) is halved only across it. A query at such a pole is a
/// control point of every piece along the collapsed side, so halving along the side would
/// double the mixed pieces at every level (2^48 pieces: one of the issue-23 hangs); halving
/// across it keeps one mixed piece per level.
fn split_net(net: Net) -> Vec<Net> {
    let (m, n) = (net.m, net.n);
    // Collapsed: the Euclidean points agree (a pole's homogeneous points differ by their
    // weights), to a relative [`COLLAPSE_TOLERANCE`] for the rounding of `H / w`. Only the
    // splitting direction depends on it, never a value.
    let euclid = |k: usize| {
        let h = net.h[k];
        [h[0] / h[3], h[1] / h[3], h[2] / h[3]]
    };
    let scale = (0..net.h.len()).fold(0.0f64, |a, k| {
        let e = euclid(k);
        a.max(e[0].abs()).max(e[1].abs()).max(e[2].abs())
    });
    let all_equal = |idx: &mut dyn Iterator<Item = usize>| {
        let Some(first) = idx.next().map(euclid) else {
            return true;
        };
        let mut same = true;
        for k in idx {
            let e = euclid(k);
            for a in 0..3 {
                same &= (e[a] - first[a]).abs() <= COLLAPSE_TOLERANCE * scale;
            }
        }
        same
    };
    let collapsed_row =
        n > 0 && (all_equal(&mut (0..=n)) || all_equal(&mut (0..=n).map(|j| m * (n + 1) + j)));
    let collapsed_column = m > 0
        && (all_equal(&mut (0..=m).map(|i| i * (n + 1)))
            || all_equal(&mut (0..=m).map(|i| i * (n + 1) + n)));
    let split_s = m > 0 && (collapsed_row || !collapsed_column);
    let split_t = n > 0 && (collapsed_column || !collapsed_row);
    let halves_s = if split_s {
        let (a, b) = split_rows(&net);
        vec![a, b]
    } else {
        vec![net]
    };
    let mut out = Vec::with_capacity(4);
    for h in halves_s {
        if split_t {
            let (a, b) = split_columns(&h);
            out.push(a);
            out.push(b);
        } else {
            out.push(h);
        }
    }
    out
}

/// Halves a net in `s` (each column halved by [`split_half_with`], bit for bit as
/// [`split_half`] would).
fn split_rows(net: &Net) -> (Net, Net) {
    let (m, n) = (net.m, net.n);
    let mut a = vec![[0.0; 4]; net.h.len()];
    let mut b = vec![[0.0; 4]; net.h.len()];
    for j in 0..=n {
        split_half_with(
            m,
            |i| net.h[i * (n + 1) + j],
            |i, l, r| {
                a[i * (n + 1) + j] = l;
                b[i * (n + 1) + j] = r;
            },
        );
    }
    (Net { m, n, h: a }, Net { m, n, h: b })
}

/// Halves a net in `t` (each row halved likewise).
fn split_columns(net: &Net) -> (Net, Net) {
    let (m, n) = (net.m, net.n);
    let mut a = vec![[0.0; 4]; net.h.len()];
    let mut b = vec![[0.0; 4]; net.h.len()];
    for i in 0..=m {
        split_half_with(
            n,
            |j| net.h[i * (n + 1) + j],
            |j, l, r| {
                a[i * (n + 1) + j] = l;
                b[i * (n + 1) + j] = r;
            },
        );
    }
    (Net { m, n, h: a }, Net { m, n, h: b })
}

/// Distance from the origin (the query) to the box of a curve's Euclidean control points (a
/// lower bound on the curve's distance, by the convex-hull property), and the box's diagonal.
fn distance_and_size(ctrl: &[Homogeneous]) -> (f64, f64) {
    let (lo, hi) = super::curve::control_box(ctrl);
    let mut d2 = 0.0;
    let mut s2 = 0.0;
    for a in 0..3 {
        let gap = lo[a].max(-hi[a]).max(0.0);
        d2 += gap * gap;
        s2 += (hi[a] - lo[a]) * (hi[a] - lo[a]);
    }
    (d2.sqrt(), s2.sqrt())
}

/// `x · 2^e`, exact unless the result over- or underflows (then the rounded value).
fn scale_by_pow2(x: f64, e: i32) -> f64 {
    // Two steps: 2^e alone may not be representable for |e| > 1023.
    let half = e / 2;
    x * 2f64.powi(half) * 2f64.powi(e - half)
}

/// The exponent `e` with `2^(e-1) ≤ x < 2^e` for a positive finite `x` (0 for 0).
fn exponent_of(x: f64) -> i32 {
    if x == 0.0 || !x.is_finite() {
        return 0;
    }
    let mut e = x.log2().floor() as i32 + 1;
    // Correct the rounding of log2 near powers of two.
    while scale_by_pow2(x, -e) >= 1.0 {
        e += 1;
    }
    while scale_by_pow2(x, -e) < 0.5 {
        e -= 1;
    }
    e
}

/// The set scaled exactly by powers of two, as the mesh path's `Rescale` does: coordinates by
/// `2^-e` so the largest magnitude is in `[0.5, 1)` (products of coordinates and weights can
/// then neither overflow nor lose the small end of the range to underflow, which made sets
/// beyond ~1e150 or below ~1e-160 return 0), and all weights by one power of two so the largest
/// is in `[0.5, 1)` (a rational patch does not change when all its weights are scaled; all-equal
/// extreme weights overflowed `w·x`). One factor for all patches keeps shared edges' homogeneous
/// control points bit-identical, which the leaf-edge cancellation relies on. The winding number is scale invariant, so no result is scaled back.
fn rescaled(set: &PatchSet) -> (PatchSet, i32) {
    let max = set
        .patches()
        .iter()
        .flat_map(|p| p.points())
        .fold(0.0f64, |a, p| {
            a.max(p[0].abs()).max(p[1].abs()).max(p[2].abs())
        });
    let e = exponent_of(max);
    let wmax = set
        .patches()
        .iter()
        .flat_map(|p| p.weights())
        .fold(0.0f64, |a, &w| a.max(w));
    let ew = exponent_of(wmax);
    let patches = set
        .patches()
        .iter()
        .map(|p| {
            let (m, n) = p.degree();
            let points: Vec<[f64; 3]> = p
                .points()
                .iter()
                .map(|x| x.map(|c| scale_by_pow2(c, -e)))
                .collect();
            let weights = p.weights().iter().map(|&w| scale_by_pow2(w, -ew)).collect();
            // Scaled weights stay positive unless one underflows to 0 (a weight ratio beyond
            // 2^1074 in the set); such a patch keeps its weights.
            Patch::rational(m, n, points.clone(), weights)
                .or_else(|_| Patch::rational(m, n, points, p.weights().to_vec()))
                .unwrap_or_else(|_| p.clone())
        })
        .collect();
    (PatchSet::new(patches).unwrap_or_else(|_| set.clone()), e)
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
    fn segment_crossings(&self, a: [f64; 3], b: [f64; 3]) -> Option<Vec<SurfaceCrossing>> {
        Some(PatchWindingNumber::segment_crossings(self, a, b))
    }
}
