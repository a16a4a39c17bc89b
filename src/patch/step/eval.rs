//! The winding number of a trimmed B-rep model (paper Eq. 15 with trimming):
//!
//! `w(q) = χ + (1/4π) ∮_{∂S} α↓`,
//!
//! with `χ` the signed number of crossings of a ray from `q` with the *trimmed* faces (a ray
//! hit on a patch counts only if its `(u, v)` is inside the face's loops, [`super::trim`]) and
//! `∂S` the surface boundary (edge uses no other use cancels; empty for a closed model, whose
//! `w` is then exactly the integer `χ`). `α↓ = −(1 + cos θ) dφ` is the potential of the
//! solid-angle form singular on the ray (`super::super::curve`), integrated by adaptive
//! Gauss–Kronrod.
//!
//! The ray is chosen per query among fixed directions so that the decision is well posed:
//! - every boundary curve is certified to stay at an angle of at least `asin μ` from the ray
//!   (a plane through `q` separates the curve's control hull from the ray with that margin;
//!   pieces are halved up to [`CERT_DEPTH`] times), so the integrand is smooth and `χ` cannot
//!   jump without the integral jumping with it;
//! - every hit is transversal (`|n̂·d| ≥` [`MIN_COSINE`]) and farther than the margin
//!   [`super::model::HIT_MARGIN`] from its face's trimming loops, so rounding in the loops'
//!   polygons cannot move it across a shared edge; and no piece of a patch near the ray is
//!   left unresolved (a tangency at the subdivision limit, or the ray passing within
//!   `EDGE_GAP` of the edge of a face's untrimmed surface, where it may slip through a gap
//!   between two faces).
//!
//! A direction failing a test is dropped and the next is tried. A certified ray with a hit
//! within `CLEAR_MARGIN` of its face's loops (where two faces' loops can disagree by more
//! than the hit margin) is taken only if another certified ray agrees with it or no ray clears
//! the margin. If every direction fails
//! (the query is on the surface, within the margin of an edge, or surrounded by boundary
//! curves), a relaxed second pass runs and the result is flagged `uncertified`.

use crate::eval::SurfaceCrossing;
use crate::kernel::spherical::FOUR_PI;

use rayon::prelude::*;

use super::super::curve::{
    Form, Homogeneous, evaluation_rounding, integrand_with_rounding, split_half,
};
use super::super::eval::MAX_EVALUATIONS;
use super::super::quadrature::{Budget, integrate, integrate_dyadic};
use super::super::ray_hits::{PatchHit, RayFrame, SurfaceEdges, patch_hits};
use super::super::samples::CurveSamples;
use super::model::{Face, FacePatch, HIT_MARGIN, StepModel};
use super::trim::Side;
use crate::base::bounding_box::segment_meets_box;
use crate::base::compensated::NeumaierSum;
use crate::base::vec3::{cross, dot, norm, sub};

/// Angular margin of the boundary certificate (`sin` of the angle), first pass.
const MU: f64 = 0.25;
/// Relaxed margin of the second pass.
const MU_RELAXED: f64 = 0.02;
/// Halvings of a boundary piece when looking for its certificate.
pub const CERT_DEPTH: u32 = 5;
/// Smallest `|cos|` between a hit's normal and the ray (grazing hits are ambiguous).
pub const MIN_COSINE: f64 = 1e-4;
/// Trimming margin of the hits shared by a grid column, relative to the diagonal
/// ([`StepWindingNumber::evaluate_column`]). Far above [`HIT_MARGIN`]: a column's line is
/// axis-aligned, and so are the edges of CAD models, so a whole row of columns can pass
/// through a tangent junction of two faces (a fillet meeting a plane in `boxed_sphere.step`),
/// where the two faces' loop polygons disagree by up to 1e-4 × diagonal and a hit can fall
/// between them (the per-point rays, turned irrationally, meet such a junction only at
/// isolated points). A point whose ray has a hit this close to its face's loops is answered
/// by the line's other half or on its own.
const COLUMN_HIT_MARGIN: f64 = 1e-3;
/// A certified ray with a hit ahead this close to its face's loops (relative to the diagonal,
/// as [`COLUMN_HIT_MARGIN`], for the same reason) passes near an edge where the faces' loops
/// may disagree by more than [`HIT_MARGIN`]: its value is taken only when a second direction
/// agrees or no ray clears the margin ([`StepWindingNumber::evaluate`]).
const CLEAR_MARGIN: f64 = COLUMN_HIT_MARGIN;
/// A query this close to a surface-boundary curve (relative to the diagonal) is *on* it and
/// gets the principal value ([`StepWindingNumber::evaluate`], docs/patches.md "On an open
/// boundary curve"). Chosen far below the distances at which values are certified (a query
/// 1e-9 × diagonal from a rim is certified, and its `w` differs from the principal value by up
/// to 1/2) and far above the rounding of a point computed on a curve (~1e-16).
pub const ON_BOUNDARY: f64 = 1e-12;
/// Smallest `|cos|` between the ray and the face's normal at a boundary point for the
/// on-boundary rule: the ray leaves the face at an angle, and the tangent-plane arc of the rule
/// stays `asin 0.2 ≈ 11.5°` from the ray.
const ON_BOUNDARY_COSINE: f64 = 0.2;
/// Edge curves lie off their faces by the modelling tolerance (up to 2.7·10⁻⁵ in
/// `open_cylinder.step`, whose rim has radius 10 and its cylinders 9.99997 and 10.0000038): for
/// the on-boundary rule the face's normal is taken at its point nearest the query, and the
/// ray's crossing of the surface next to the query is left out, within this distance relative
/// to the diagonal.
const ON_BOUNDARY_GAP: f64 = 1e-4;
/// A ray passing this close (relative to the diagonal) to the edge of a face's untrimmed
/// surface, where the face may end, may pass through a modelling gap between that face and its
/// neighbour and cross neither: the span is unresolved ([`patch_hits`]). Faces meeting at an
/// edge are apart by up to 4.9·10⁻⁶ × diagonal in `boxed_sphere.step` (a corner blend and the
/// wall below it), where a ray through the gap gave a certified `w = 1` outside the solid.
const EDGE_GAP: f64 = 1e-5;

/// Options of the trimmed-model evaluator.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct StepOptions {
    /// Target absolute error of `w` from the boundary integral (default `1e-10`; closed
    /// models have no boundary and are exact integers off the surface).
    pub tolerance: f64,
}

impl Default for StepOptions {
    fn default() -> Self {
        StepOptions { tolerance: 1e-10 }
    }
}

/// One evaluation with diagnostics.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct StepEvaluation {
    /// The winding number.
    pub value: f64,
    /// The crossing count `χ`.
    pub crossings: i64,
    /// Error estimate of the boundary integral (units of `w`).
    pub error_estimate: f64,
    /// Ray directions tried.
    pub rays: usize,
    /// No direction passed the tests (query on or within the margins of the surface or an
    /// edge): the value is a best effort.
    pub uncertified: bool,
}

/// The evaluator.
#[derive(Clone, Debug)]
pub struct StepWindingNumber {
    model: StepModel,
    options: StepOptions,
    dirs: Vec<[f64; 3]>,
    margin: f64,
    /// Per face, the union of its patches' boxes: a ray that misses it (with the same padding)
    /// misses every patch box of the face, so the face's patches are not visited.
    face_boxes: Vec<([f64; 3], [f64; 3])>,
    /// Per face and patch, which sides of the patch (`s = 0`, `s = 1`, `t = 0`, `t = 1`) lie on
    /// an edge of the face's untrimmed surface ([`EDGE_GAP`]).
    surface_edges: Vec<Vec<[bool; 4]>>,
    /// Precomputed quadrature samples of the surface-boundary curves (world coordinates,
    /// `super::super::samples`), rotated into each ray's frame per query.
    boundary_samples: Vec<CurveSamples>,
}

impl RayFrame {
    /// The homogeneous point `h` relative to `q`, in this frame (weight kept).
    fn hom(&self, h: Homogeneous, q: [f64; 3]) -> Homogeneous {
        let r = [h[0] - h[3] * q[0], h[1] - h[3] * q[1], h[2] - h[3] * q[2]];
        let f = self.map(r);
        [f[0], f[1], f[2], h[3]]
    }
}

/// 14 directions: the axes and the cube diagonals, turned by a fixed irrational rotation so
/// that none is parallel to the coordinate planes CAD models are full of.
fn directions() -> Vec<[f64; 3]> {
    let (a, b, c) = (0.3125_f64, 0.6875_f64, 1.0625_f64);
    let rot = |v: [f64; 3]| {
        let (s, co) = a.sin_cos();
        let v = [v[0], co * v[1] - s * v[2], s * v[1] + co * v[2]];
        let (s, co) = b.sin_cos();
        let v = [co * v[0] + s * v[2], v[1], -s * v[0] + co * v[2]];
        let (s, co) = c.sin_cos();
        [co * v[0] - s * v[1], s * v[0] + co * v[1], v[2]]
    };
    let mut out = Vec::new();
    for v in [
        [0.0, 0.0, 1.0],
        [0.0, 0.0, -1.0],
        [1.0, 0.0, 0.0],
        [-1.0, 0.0, 0.0],
        [0.0, 1.0, 0.0],
        [0.0, -1.0, 0.0],
    ] {
        out.push(rot(v));
    }
    let k = 1.0 / 3f64.sqrt();
    for sx in [1.0, -1.0] {
        for sy in [1.0, -1.0] {
            for sz in [1.0, -1.0] {
                out.push(rot([sx * k, sy * k, sz * k]));
            }
        }
    }
    out
}

/// One ray hit for diagnostics: face `#id`, point, `(u, v)`, trimming side, distance to the
/// face's loops (to a factor of 2).
pub type HitReport = (u64, [f64; 3], [f64; 2], Side, f64);

/// Why a direction was rejected.
enum Reject {
    Boundary,
    Hit,
}

impl StepWindingNumber {
    /// An evaluator with default options.
    pub fn new(model: &StepModel) -> Self {
        Self::build(model, StepOptions::default())
    }

    /// An evaluator with the given options; a tolerance that is not a finite positive number
    /// is refused.
    pub fn with_options(
        model: &StepModel,
        options: StepOptions,
    ) -> Result<Self, crate::patch::ToleranceError> {
        crate::patch::ToleranceError::check(options.tolerance)?;
        Ok(Self::build(model, options))
    }

    fn build(model: &StepModel, options: StepOptions) -> Self {
        let face_boxes = model
            .faces
            .iter()
            .map(|face| {
                let mut lo = [f64::INFINITY; 3];
                let mut hi = [f64::NEG_INFINITY; 3];
                for fp in &face.patches {
                    for k in 0..3 {
                        lo[k] = lo[k].min(fp.lo[k]);
                        hi[k] = hi[k].max(fp.hi[k]);
                    }
                }
                (lo, hi)
            })
            .collect();
        let boundary_samples = model
            .boundary
            .iter()
            .map(|c| CurveSamples::new(c.clone()))
            .collect();
        StepWindingNumber {
            margin: HIT_MARGIN * model.diagonal(),
            face_boxes,
            surface_edges: model.faces.iter().map(surface_edges).collect(),
            boundary_samples,
            model: model.clone(),
            options,
            dirs: directions(),
        }
    }

    /// [`EDGE_GAP`] in model units.
    fn edge_gap(&self) -> f64 {
        EDGE_GAP * self.model.diagonal()
    }

    /// The model.
    pub fn model(&self) -> &StepModel {
        &self.model
    }

    /// The winding number at `q` (NaN for a non-finite query).
    pub fn eval(&self, q: [f64; 3]) -> f64 {
        self.evaluate(q).value
    }

    /// Winding numbers at many points, in parallel.
    pub fn eval_batch(&self, points: &[[f64; 3]]) -> Vec<f64> {
        points.par_iter().map(|&q| self.eval(q)).collect()
    }

    /// The winding number with diagnostics.
    pub fn evaluate(&self, q: [f64; 3]) -> StepEvaluation {
        if q.iter().any(|c| !c.is_finite()) {
            return StepEvaluation {
                value: f64::NAN,
                ..StepEvaluation::default()
            };
        }
        let mut rays = 0;
        for (mu, margin, strict) in [(MU, self.margin, true), (MU_RELAXED, 0.0, false)] {
            if !strict {
                // No ray passed: on the surface, near an edge, or on a boundary curve, which
                // has its own rule.
                if let Some(point) = self.boundary_point(q) {
                    for &d in &self.dirs {
                        rays += 1;
                        if let Some(mut e) = self.on_boundary_along(&point, d) {
                            e.rays = rays;
                            return e;
                        }
                    }
                }
            }
            // A certified ray clear of every loop by `CLEAR_MARGIN` is taken; one that passes
            // closer to an edge (through a modelling gap, its count can be off by one: a ray
            // of sliced_cylinder gave −1 outside the solid, its hits 2·10⁻⁴ and 8·10⁻⁴ from the
            // loops of the rim's two faces) only when another certified ray agrees with it, or
            // when no ray is clear and none agree (the first then).
            let mut unclear: Vec<StepEvaluation> = Vec::new();
            for &d in &self.dirs {
                rays += 1;
                match self.try_ray(q, d, mu, margin, strict) {
                    Ok((mut e, clear)) => {
                        e.uncertified = !strict;
                        let agrees = unclear.iter().any(|u| (u.value - e.value).abs() < 0.5);
                        if clear || !strict || agrees {
                            e.rays = rays;
                            return e;
                        }
                        unclear.push(e);
                    }
                    Err(Reject::Boundary) | Err(Reject::Hit) => continue,
                }
            }
            if let Some(mut e) = unclear.into_iter().next() {
                e.rays = rays;
                return e;
            }
        }
        // Nothing passed even relaxed: the first direction without any test.
        let mut e = self
            .try_ray(q, self.dirs[0], 0.0, 0.0, false)
            .map(|(e, _)| e)
            .unwrap_or_default();
        e.rays = rays + 1;
        e.uncertified = true;
        e
    }

    /// The value along one given ray direction `d` (unit), without choosing: `None` if the
    /// direction fails the certificates. For diagnostics and tests of direction independence.
    pub fn evaluate_along(&self, q: [f64; 3], d: [f64; 3]) -> Option<StepEvaluation> {
        self.try_ray(q, d, MU, self.margin, true)
            .ok()
            .map(|(e, _)| e)
    }

    /// The on-boundary rule at `q` along the ray `d`, if `q` is on a surface-boundary curve (within
    /// [`ON_BOUNDARY`] `×` diagonal) and `d` qualifies (see [`evaluate`](Self::evaluate)):
    /// `None` otherwise. For tests of direction independence.
    pub fn evaluate_on_boundary_along(&self, q: [f64; 3], d: [f64; 3]) -> Option<StepEvaluation> {
        let point = self.boundary_point(q)?;
        self.on_boundary_along(&point, d)
    }

    /// Every hit of the ray from `q` along `d` on every face's patches: `(face #id, point,
    /// (u, v), trimming side)`, before any test. For diagnostics.
    pub fn hits_along(&self, q: [f64; 3], d: [f64; 3]) -> Vec<HitReport> {
        let frame = RayFrame::new(d);
        let mut out = Vec::new();
        for (face, edges) in self.model.faces.iter().zip(&self.surface_edges) {
            let dedup = 1e-9 * self.model.diagonal();
            let hits = face_hits(
                face,
                edges,
                q,
                &frame,
                f64::INFINITY,
                dedup,
                self.edge_gap(),
            )
            .hits;
            for h in hits {
                let side = face.trim.classify(h.uv, h.su, h.sv, self.margin);
                // Distance to the loops, to a factor of 2 (first smallest margin that is near).
                let mut dist = f64::INFINITY;
                let mut m = self.model.diagonal();
                while m > 1e-12 * self.model.diagonal() {
                    if face.trim.classify(h.uv, h.su, h.sv, m) == Side::Near {
                        dist = m;
                    }
                    m *= 0.5;
                }
                out.push((face.id, h.point, h.uv, side, dist));
            }
        }
        out
    }

    /// Where the segment `a → b` crosses the trimmed faces, in order along it, with the
    /// surface's unit normal there: the hits of its ray at most `|b − a|` along it (pieces of
    /// patches beyond the segment are culled, so this costs a fraction of a ray's hits),
    /// inside a face's loops or within [`COLUMN_HIT_MARGIN`] of them. Proposals for a caller
    /// that verifies them ([`crate::eval::Evaluator::segment_crossings`]): a hit near a loop
    /// is kept, a span the subdivision left unresolved is not reported. Empty for a degenerate
    /// or non-finite segment.
    pub fn segment_crossings(&self, a: [f64; 3], b: [f64; 3]) -> Vec<SurfaceCrossing> {
        let d = sub(b, a);
        let length = norm(d);
        if !(length.is_finite() && length > 0.0) || a.iter().any(|c| !c.is_finite()) {
            return Vec::new();
        }
        let frame = RayFrame::new(d.map(|x| x / length));
        let margin = COLUMN_HIT_MARGIN * self.model.diagonal();
        let mut out = Vec::new();
        for (face, found) in self.hits_by_face(a, &frame, length) {
            for h in found.hits {
                if !(0.0..=length).contains(&h.tau)
                    || face.trim.classify(h.uv, h.su, h.sv, margin) == Side::Outside
                {
                    continue;
                }
                let n = cross(h.su, h.sv);
                let nn = norm(n);
                let normal = if nn > 0.0 && nn.is_finite() {
                    n.map(|x| x / nn)
                } else {
                    [0.0; 3]
                };
                out.push(SurfaceCrossing {
                    t: h.tau / length,
                    normal,
                });
            }
        }
        out.sort_by(|x, y| x.t.total_cmp(&y.t));
        out
    }

    /// The candidate ray directions, in the order they are tried.
    pub fn directions(&self) -> &[[f64; 3]] {
        &self.dirs
    }

    fn try_ray(
        &self,
        q: [f64; 3],
        d: [f64; 3],
        mu: f64,
        margin: f64,
        strict: bool,
    ) -> Result<(StepEvaluation, bool), Reject> {
        let frame = RayFrame::new(d);
        // Certify the boundary first (cheap), then the hits.
        let pieces = self.certify_boundary(q, &frame, mu, strict)?;
        let (chi, clear) = self.crossings(q, &frame, margin, strict)?;
        Ok((self.with_boundary(chi, &pieces, q, &frame), clear))
    }

    /// The surface boundary in the ray frame of `q`, halved into pieces certified against the
    /// ray with margin `mu`; `Err` (when `strict`) if some piece cannot be certified.
    fn certify_boundary(
        &self,
        q: [f64; 3],
        frame: &RayFrame,
        mu: f64,
        strict: bool,
    ) -> Result<Vec<BoundaryPiece>, Reject> {
        let mut pieces = Vec::new();
        for (curve, c) in self.model.boundary.iter().enumerate() {
            let h: Vec<Homogeneous> = c.iter().map(|&p| frame.hom(p, q)).collect();
            let mut out = Vec::new();
            let ok = certify(h, mu, 0, 0, false, &mut out);
            if !ok && strict {
                return Err(Reject::Boundary);
            }
            pieces.extend(out.into_iter().map(|(ctrl, level, index)| BoundaryPiece {
                curve: Some(curve),
                level,
                index,
                ctrl,
            }));
        }
        Ok(pieces)
    }

    /// `χ` plus the boundary integral over the certified `pieces` (empty for a closed model).
    /// A piece far enough from `q` for the centred samples (`CurveSamples::usable_at`) is
    /// integrated from them, rotated into `frame`; a nearer one from its control points.
    fn with_boundary(
        &self,
        chi: i64,
        pieces: &[BoundaryPiece],
        q: [f64; 3],
        frame: &RayFrame,
    ) -> StepEvaluation {
        let mut sum = NeumaierSum::new();
        let mut err = 0.0;
        let tol = self.options.tolerance * FOUR_PI / (pieces.len().max(1) as f64);
        // The patch evaluator's work cap and rounding-aware integrand (docs/patches.md: a
        // bounded time per query; an integral that hits the cap is reported uncertified).
        let mut budget = Budget {
            remaining: MAX_EVALUATIONS,
        };
        let mut capped = 0;
        let rotation = [frame.e1, frame.e2, frame.d];
        for piece in pieces {
            let c = &piece.ctrl;
            let samples = piece
                .curve
                .map(|i| &self.boundary_samples[i])
                .filter(|samples| {
                    samples.usable_at(super::super::curve::distance_to_control_box(c))
                });
            if let Some(samples) = samples {
                let delta = samples.offset(q);
                let rounding = samples.rounding_rotated(delta);
                let r = integrate_dyadic(
                    |l, i| samples.rule_rotated(Form::Down, l, i, delta, &rotation, rounding),
                    piece.level,
                    piece.index,
                    tol,
                    &mut budget,
                );
                sum.add(r.value);
                err += r.error;
                capped += r.capped;
                continue;
            }
            let (en, edn) = evaluation_rounding(c);
            let r = integrate(
                |t| {
                    let (n, dn) = super::super::curve::eval_with_derivative(c, t);
                    integrand_with_rounding(Form::Down, n, dn, en, edn)
                },
                0.0,
                1.0,
                tol,
                &mut budget,
            );
            sum.add(r.value);
            err += r.error;
            capped += r.capped;
        }
        StepEvaluation {
            value: chi as f64 + sum.value() / FOUR_PI,
            crossings: chi,
            error_estimate: err / FOUR_PI,
            rays: 0,
            uncertified: capped > 0,
        }
    }

    /// [`evaluate`](Self::evaluate) at the points `q` with coordinate `axis` replaced by each
    /// `ts[k]` (a grid column), sharing one ray: the paper's ray reuse (Sec. 4.3.1).
    ///
    /// The ray of every point is the column's line in `+axis` (or, second choice, `−axis`); the
    /// line's hits on the trimmed faces are found once, and a point's `χ` is the signed count
    /// of the inside hits above (below) it. A point is answered from the shared hits only when
    /// its own ray passes the tests of [`evaluate`](Self::evaluate) (the module docs): no hit
    /// ahead of it is grazing or within the margin of its face's loops, no hit is within the
    /// margin of the point, and, for an open model, its surface boundary is certified against
    /// the ray. Any other point is evaluated on its own. A closed model's values are then the same integers as
    /// [`evaluate`](Self::evaluate)'s; an open model's differ by the quadrature error (both
    /// within the tolerance). `axis > 2` or non-finite input evaluates point by point.
    pub fn evaluate_column(&self, q: [f64; 3], axis: usize, ts: &[f64]) -> Vec<StepEvaluation> {
        let point = |t: f64| {
            let mut p = q;
            if axis < 3 {
                p[axis] = t;
            }
            p
        };
        let one_by_one = || ts.iter().map(|&t| self.evaluate(point(t))).collect();
        if axis > 2 || ts.len() < 2 || q.iter().chain(ts).any(|c| !c.is_finite()) {
            return one_by_one();
        }
        let mut d = [0.0; 3];
        d[axis] = 1.0;
        let up = RayFrame::new(d);
        d[axis] = -1.0;
        let down = RayFrame::new(d);
        // The line's hits as seen from a point just below the model: all of them are ahead of
        // it, at heights `τ` along `+axis` from it. Not below every `ts`: Newton's acceptance
        // of a hit scales with the distance from the ray's origin, so that origin stays near
        // the model however far the column's points reach.
        let base_height = self.model.lo[axis] - 0.01 * self.model.diagonal() - self.margin;
        if !base_height.is_finite() {
            return one_by_one();
        }
        let hits = self.line_hits(point(base_height), &up);
        // A closed model's line enters as often as it leaves: otherwise some hit was missed or
        // counted twice (loops that disagree at a junction), and every point is on its own.
        if self.model.boundary.is_empty()
            && !hits.iter().any(|h| h.ambiguous)
            && hits.iter().map(|h| h.sign).sum::<i64>() != 0
        {
            return one_by_one();
        }
        ts.iter()
            .map(|&t| {
                let p = point(t);
                let tau = t - base_height;
                // `χ` along `+axis` (hits above) and along `−axis` (hits below, crossed the
                // other way); `None` where a hit makes that ray ambiguous.
                let (mut chi_up, mut chi_down) = (Some(0i64), Some(0i64));
                for h in &hits {
                    if (h.tau - tau).abs() <= self.margin {
                        return self.evaluate(p);
                    }
                    if h.tau > tau {
                        chi_up = chi_up.filter(|_| !h.ambiguous).map(|c| c + h.sign);
                    } else {
                        chi_down = chi_down.filter(|_| !h.ambiguous).map(|c| c - h.sign);
                    }
                }
                // For an open model the boundary must be certified against the ray too; the
                // line's other half is the second choice.
                for (chi, frame) in [(chi_up, &up), (chi_down, &down)] {
                    let Some(chi) = chi else { continue };
                    if let Ok(pieces) = self.certify_boundary(p, frame, MU, true) {
                        let mut e = self.with_boundary(chi, &pieces, p, frame);
                        e.rays = 1;
                        return e;
                    }
                }
                self.evaluate(p)
            })
            .collect()
    }

    /// The faces whose box the ray from `q` meets (grown by the edge gap), each with its hits
    /// ([`face_hits`]), found as the iterator is advanced. Conservative: the slab test is
    /// monotone in the box, so a ray meeting a patch's padded box meets the face's.
    fn hits_by_face<'a>(
        &'a self,
        q: [f64; 3],
        frame: &'a RayFrame,
        reach: f64,
    ) -> impl Iterator<Item = (&'a Face, FaceHits)> + 'a {
        let dedup = 1e-9 * self.model.diagonal();
        let gap = self.edge_gap();
        self.model
            .faces
            .iter()
            .zip(&self.face_boxes)
            .zip(&self.surface_edges)
            .filter(move |((_, (lo, hi)), _)| {
                segment_meets_box(q, frame.d, reach, *lo, *hi, dedup.max(gap))
            })
            .map(move |((face, _), edges)| {
                (face, face_hits(face, edges, q, frame, reach, dedup, gap))
            })
    }

    /// Every hit of the ray from `q` along `frame.d` on the trimmed faces, classified once:
    /// sign of the crossing (0 outside the face's loops) or ambiguous (grazing, or within
    /// [`COLUMN_HIT_MARGIN`] of the loops), at its distance `τ` from `q`.
    fn line_hits(&self, q: [f64; 3], frame: &RayFrame) -> Vec<LineHit> {
        let mut out = Vec::new();
        let column_margin = COLUMN_HIT_MARGIN * self.model.diagonal();
        for (face, found) in self.hits_by_face(q, frame, f64::INFINITY) {
            // A span where a crossing may hide blocks the line's rays through it, as an
            // ambiguous hit at each of its ends would.
            for [a, b] in found.unresolved {
                for tau in [a, b] {
                    out.push(LineHit {
                        tau,
                        sign: 0,
                        ambiguous: true,
                    });
                }
            }
            for h in found.hits {
                let n = cross(h.su, h.sv);
                let nn = norm(n);
                let c = face.sense * dot(n, frame.d) / nn;
                let grazing = nn.is_nan() || nn <= 0.0 || c.abs() < MIN_COSINE;
                let side = if grazing {
                    Side::Near
                } else {
                    face.trim.classify(h.uv, h.su, h.sv, column_margin)
                };
                out.push(LineHit {
                    tau: h.tau,
                    sign: match side {
                        Side::Inside if c > 0.0 => 1,
                        Side::Inside => -1,
                        _ => 0,
                    },
                    ambiguous: side == Side::Near,
                });
            }
        }
        out
    }

    /// Signed count of trimmed-face crossings of the ray, and whether every hit ahead is
    /// [`CLEAR_MARGIN`] from its face's loops; `Err` if some hit is ambiguous.
    fn crossings(
        &self,
        q: [f64; 3],
        frame: &RayFrame,
        margin: f64,
        strict: bool,
    ) -> Result<(i64, bool), Reject> {
        let mut chi = 0i64;
        let mut clear = true;
        let clear_margin = CLEAR_MARGIN * self.model.diagonal();
        for (face, found) in self.hits_by_face(q, frame, f64::INFINITY) {
            if strict && found.unresolved.iter().any(|&[_, hi]| hi >= -margin) {
                return Err(Reject::Hit);
            }
            for h in found.hits {
                let n = cross(h.su, h.sv);
                let nn = norm(n);
                let c = face.sense * dot(n, frame.d) / nn;
                if strict
                    && (nn.is_nan() || nn <= 0.0 || c.abs() < MIN_COSINE || h.tau.abs() <= margin)
                {
                    return Err(Reject::Hit);
                }
                if h.tau <= 0.0 {
                    continue;
                }
                // Off the wide margin the side is the one within the narrow margin too (the
                // margin only decides `Near`); one classification for most hits.
                let side = match face.trim.classify(h.uv, h.su, h.sv, clear_margin) {
                    Side::Near => {
                        clear = false;
                        face.trim.classify(h.uv, h.su, h.sv, margin)
                    }
                    side => side,
                };
                match side {
                    Side::Inside => chi += if c > 0.0 { 1 } else { -1 },
                    Side::Outside => {}
                    Side::Near if strict => return Err(Reject::Hit),
                    Side::Near => {
                        if face.trim.indicator(h.uv) == 1 {
                            chi += if c > 0.0 { 1 } else { -1 };
                        }
                    }
                }
            }
        }
        Ok((chi, clear))
    }
}

/// A query on the surface boundary, prepared for the on-boundary rule: the boundary curves
/// with the ones through the point split there and their end points at the point set to it
/// exactly, the tangents in and out, and the face's unit normal there.
struct BoundaryPoint {
    /// The point (the query moved onto the curve, by at most [`ON_BOUNDARY`] `×` diagonal).
    c: [f64; 3],
    /// Curves not through `c`.
    others: Vec<Vec<Homogeneous>>,
    /// The curve ending at `c` and the one starting there.
    incident: [Vec<Homogeneous>; 2],
    /// Unit tangents of the boundary arriving at and leaving `c`.
    tangent_in: [f64; 3],
    tangent_out: [f64; 3],
    /// Unit normal of the face at `c`.
    normal: [f64; 3],
}

impl StepWindingNumber {
    /// `q` as a [`BoundaryPoint`] if it lies within [`ON_BOUNDARY`] `×` diagonal of exactly one
    /// surface-boundary curve's point (one curve through it, or one ending and one starting
    /// there), on a face with a normal there; `None` otherwise.
    fn boundary_point(&self, q: [f64; 3]) -> Option<BoundaryPoint> {
        let boundary = &self.model.boundary;
        if boundary.is_empty() {
            return None;
        }
        let tol = ON_BOUNDARY * self.model.diagonal();
        let mut near: Vec<(usize, f64, [f64; 3])> = Vec::new();
        for (i, c) in boundary.iter().enumerate() {
            let t = super::surface::invert_curve(&[(0.0, 1.0, c.clone())], q);
            let p = super::nurbs::point_at(c, t);
            if norm(sub(p, q)) <= tol {
                near.push((i, t, p));
            }
        }
        let &(first, _, c) = near.first()?;
        let snap = |h: Homogeneous| [h[3] * c[0], h[3] * c[1], h[3] * c[2], h[3]];
        let end_tol = 1e-9;
        let (mut arriving, mut leaving) = (Vec::new(), Vec::new());
        for &(i, t, _) in &near {
            let curve = &boundary[i];
            if t >= 1.0 - end_tol || norm(sub(super::nurbs::point_at(curve, 1.0), c)) <= tol {
                let mut a = curve.clone();
                let last = a.len() - 1;
                a[last] = snap(a[last]);
                arriving.push((i, a));
            } else if t <= end_tol || norm(sub(super::nurbs::point_at(curve, 0.0), c)) <= tol {
                let mut b = curve.clone();
                b[0] = snap(b[0]);
                leaving.push((i, b));
            } else {
                let (mut a, mut b) = super::nurbs::split_at(curve, t);
                let last = a.len() - 1;
                a[last] = snap(a[last]);
                b[0] = snap(b[0]);
                arriving.push((i, a));
                leaving.push((i, b));
            }
        }
        if arriving.len() != 1 || leaving.len() != 1 {
            return None;
        }
        let (ia, a) = arriving.pop()?;
        let (ib, b) = leaving.pop()?;
        // The tangent from the control polygon at the end (the Bézier end tangent's direction).
        let euc = |h: &Homogeneous| [h[0] / h[3], h[1] / h[3], h[2] / h[3]];
        let tangent_in = a
            .iter()
            .rev()
            .map(|h| sub(c, euc(h)))
            .find(|d| norm(*d) > tol)?;
        let tangent_out = b.iter().map(|h| sub(euc(h), c)).find(|d| norm(*d) > tol)?;
        let unit = |v: [f64; 3]| {
            let n = norm(v);
            [v[0] / n, v[1] / n, v[2] / n]
        };
        let face = &self.model.faces[self.model.boundary_faces[first]];
        let normal = face_normal(face, c, self.model.diagonal())?;
        let others = boundary
            .iter()
            .enumerate()
            .filter(|(i, _)| *i != ia && *i != ib)
            .map(|(_, c)| c.clone())
            .collect();
        Some(BoundaryPoint {
            c,
            others,
            incident: [a, b],
            tangent_in: unit(tangent_in),
            tangent_out: unit(tangent_out),
            normal,
        })
    }

    /// The principal value at a boundary point along the ray `d`:
    /// `χ + (1/4π) (∮_{∂S} α↓ + ∫_arc α↓)`, where `χ` counts the ray's crossings other than at
    /// `c`, the boundary integral runs through `c` (its integrand is bounded there), and `arc`
    /// is the arc of directions in the face's tangent plane from `−tangent_in` through the face
    /// to `tangent_out` (a half circle on a smooth curve). This is the formula for the surface
    /// with a small disk around `c` cut out, in the limit: the solid angle of the rest, i.e. the
    /// mean of `w` over the directions of approach. `None` if `d` is within `asin 0.2` of the
    /// tangent plane, or a boundary curve or hit fails the certificates of a regular query.
    fn on_boundary_along(&self, point: &BoundaryPoint, d: [f64; 3]) -> Option<StepEvaluation> {
        if dot(point.normal, d).abs() < ON_BOUNDARY_COSINE {
            return None;
        }
        let c = point.c;
        let frame = RayFrame::new(d);
        let mut pieces = Vec::new();
        for (curves, through) in [(&point.others[..], false), (&point.incident[..], true)] {
            for curve in curves {
                let h: Vec<Homogeneous> = curve.iter().map(|&p| frame.hom(p, c)).collect();
                let mut out = Vec::new();
                if !certify(h, MU, 0, 0, through, &mut out) {
                    return None;
                }
                // Not the model's curves (the incident ones are split at `c`): no cached samples.
                pieces.extend(out.into_iter().map(|(ctrl, level, index)| BoundaryPiece {
                    curve: None,
                    level,
                    index,
                    ctrl,
                }));
            }
        }
        let chi = self.crossings_from_boundary(c, &frame)?;
        let mut e = self.with_boundary(chi, &pieces, c, &frame);
        // The arc, in the ray frame: γ(ψ) = cos ψ a + sin ψ b, a = −tangent_in, b the inward
        // direction in the tangent plane, ψ from 0 to the face's angle at c.
        let n = point.normal;
        let t_in = point.tangent_in;
        let inward = cross(n, t_in);
        let a = frame.map([-t_in[0], -t_in[1], -t_in[2]]);
        let b = frame.map(inward);
        let t_out = point.tangent_out;
        let angle = (dot(t_out, inward))
            .atan2(-dot(t_out, t_in))
            .rem_euclid(std::f64::consts::TAU);
        if angle.is_nan() || angle <= 0.0 {
            return None;
        }
        let mut budget = Budget {
            remaining: MAX_EVALUATIONS,
        };
        let arc = integrate(
            |psi| {
                let (s, co) = psi.sin_cos();
                let r = [
                    co * a[0] + s * b[0],
                    co * a[1] + s * b[1],
                    co * a[2] + s * b[2],
                ];
                let dr = [
                    -s * a[0] + co * b[0],
                    -s * a[1] + co * b[1],
                    -s * a[2] + co * b[2],
                ];
                // α↓ = −(r × r')_z / (ρ (ρ − r_z)) with ρ = 1; the arc keeps the margin angle from
                // the ray, so 1 − r_z ≥ 1 − cos(asin 0.2).
                let f = -(r[0] * dr[1] - r[1] * dr[0]) / (1.0 - r[2]);
                (f, 8.0 * f64::EPSILON * f.abs())
            },
            0.0,
            angle,
            self.options.tolerance * FOUR_PI,
            &mut budget,
        );
        e.value += arc.value / FOUR_PI;
        e.error_estimate += arc.error / FOUR_PI;
        e.uncertified = e.uncertified || arc.capped > 0;
        Some(e)
    }

    /// Signed count of trimmed-face crossings of the ray from a boundary point `c`, leaving out
    /// the hits within [`ON_BOUNDARY_GAP`] `× diagonal` of `c` (the surface at the point itself);
    /// `None` if another hit is grazing or within the margin of its face's loops.
    fn crossings_from_boundary(&self, c: [f64; 3], frame: &RayFrame) -> Option<i64> {
        let mut chi = 0i64;
        let dedup = 1e-9 * self.model.diagonal();
        let gap = ON_BOUNDARY_GAP * self.model.diagonal();
        for (face, edges) in self.model.faces.iter().zip(&self.surface_edges) {
            let found = face_hits(face, edges, c, frame, f64::INFINITY, dedup, self.edge_gap());
            if found.unresolved.iter().any(|&[_, hi]| hi > gap) {
                return None;
            }
            for h in found.hits {
                if h.tau.abs() <= gap {
                    continue;
                }
                let n = cross(h.su, h.sv);
                let nn = norm(n);
                let cosine = face.sense * dot(n, frame.d) / nn;
                if nn.is_nan() || nn <= 0.0 || cosine.abs() < MIN_COSINE {
                    return None;
                }
                if h.tau < 0.0 {
                    continue;
                }
                match face.trim.classify(h.uv, h.su, h.sv, self.margin) {
                    Side::Inside => chi += if cosine > 0.0 { 1 } else { -1 },
                    Side::Outside => {}
                    Side::Near => return None,
                }
            }
        }
        Some(chi)
    }
}

/// The unit normal (`sense × S_u × S_v`) of `face` at its point `c`: Gauss–Newton for the
/// closest point on each patch whose box holds `c`, from the nearest of 9 × 9 samples; `None`
/// if no patch comes within [`ON_BOUNDARY_GAP`] `× diag` (the normal at the closest point is off
/// by about that distance over the radius of curvature) or the normal degenerates there (a pole).
fn face_normal(face: &Face, c: [f64; 3], diag: f64) -> Option<[f64; 3]> {
    let pad = ON_BOUNDARY_GAP * diag;
    let mut best: Option<(f64, [f64; 3])> = None;
    for fp in &face.patches {
        if (0..3).any(|k| c[k] < fp.lo[k] - pad || c[k] > fp.hi[k] + pad) {
            continue;
        }
        let mut st = [0.5, 0.5];
        let mut nearest = f64::INFINITY;
        for i in 0..=8 {
            for j in 0..=8 {
                let x = [i as f64 / 8.0, j as f64 / 8.0];
                let dist = norm(sub(fp.patch.eval(x[0], x[1]), c));
                if dist < nearest {
                    (nearest, st) = (dist, x);
                }
            }
        }
        for _ in 0..30 {
            let (p, ds, dt) = fp.patch.eval_with_partials(st[0], st[1]);
            let r = sub(p, c);
            let (a, b, cc) = (dot(ds, ds), dot(ds, dt), dot(dt, dt));
            let det = a * cc - b * b;
            if det.is_nan() || det <= 0.0 {
                break;
            }
            let (g0, g1) = (dot(ds, r), dot(dt, r));
            let next = [
                (st[0] - (cc * g0 - b * g1) / det).clamp(0.0, 1.0),
                (st[1] - (a * g1 - b * g0) / det).clamp(0.0, 1.0),
            ];
            let moved = (next[0] - st[0]).abs() + (next[1] - st[1]).abs();
            st = next;
            if moved < 1e-15 {
                break;
            }
        }
        let (p, ds, dt) = fp.patch.eval_with_partials(st[0], st[1]);
        let dist = norm(sub(p, c));
        let n = cross(ds, dt);
        let len = norm(n);
        if dist <= pad && len > 1e-12 * norm(ds) * norm(dt) && best.is_none_or(|(bd, _)| dist < bd)
        {
            let s = face.sense / len;
            best = Some((dist, [n[0] * s, n[1] * s, n[2] * s]));
        }
    }
    best.map(|(_, n)| n)
}

/// Certifies a boundary piece (homogeneous, ray frame) against the ray `+z` with margin `mu`,
/// halving it up to [`CERT_DEPTH`] times; certified pieces go to `out`. Returns `false` (and
/// still pushes the pieces) if some part could not be certified.
/// Each piece is recorded with its dyadic `(level, index)` in the curve's parameter.
fn certify(
    h: Vec<Homogeneous>,
    mu: f64,
    depth: u32,
    index: u64,
    through_query: bool,
    out: &mut Vec<(Vec<Homogeneous>, u32, u64)>,
) -> bool {
    // `through_query`: control points exactly at the query (a boundary curve through a
    // boundary query's own point, `BoundaryPoint`) are left out: the hull of the origin and the
    // other points lies in the cone of the others, which each test below certifies.
    let pts: Vec<[f64; 3]> = h
        .iter()
        .map(|p| [p[0] / p[3], p[1] / p[3], p[2] / p[3]])
        .filter(|p| !(through_query && *p == [0.0; 3]))
        .collect();
    if pts.iter().all(|p| p[2] < 0.0) {
        out.push((h, depth, index));
        return true;
    }
    let (mut mx, mut my) = (0.0, 0.0);
    for p in &pts {
        let r = norm(*p);
        if r > 0.0 {
            mx += p[0] / r;
            my += p[1] / r;
        }
    }
    let m = (mx * mx + my * my).sqrt();
    if m > 0.0 {
        let (hx, hy) = (mx / m, my / m);
        let s = std::f64::consts::FRAC_1_SQRT_2;
        for n in [[hx, hy, 0.0], [s * hx, s * hy, -s]] {
            if pts
                .iter()
                .all(|p| dot(n, *p) >= mu * norm(*p) && dot(n, *p) > 0.0)
            {
                out.push((h, depth, index));
                return true;
            }
        }
    }
    if depth >= CERT_DEPTH {
        out.push((h, depth, index));
        return false;
    }
    let (a, b) = split_half(&h);
    let ok_a = certify(a, mu, depth + 1, 2 * index, through_query, out);
    let ok_b = certify(b, mu, depth + 1, 2 * index + 1, through_query, out);
    ok_a && ok_b
}

/// The ray's hits on the patches of `face` (patches whose box it misses by more than `gap` are
/// skipped), with hits closer than `dedup` to an earlier one dropped (a hit on the seam of two
/// patches is one hit), and the spans `[τ_lo, τ_hi]` along the ray of the pieces whose
/// crossings are unknown, among them where the ray passes within `gap` of the edge of the
/// face's untrimmed surface (`edges`: [`surface_edges`]; [`patch_hits`]). The ray stops at
/// `τ = reach` (infinite for a ray; a segment's length for
/// [`StepWindingNumber::segment_crossings`]): patches and pieces wholly beyond it are skipped.
fn face_hits(
    face: &Face,
    edges: &[[bool; 4]],
    q: [f64; 3],
    frame: &RayFrame,
    reach: f64,
    dedup: f64,
    gap: f64,
) -> FaceHits {
    let mut hits: Vec<Hit> = Vec::new();
    let mut unresolved = Vec::new();
    // One buffer for the patches' own hits (this runs for every face every ray meets).
    let mut found = Vec::new();
    for (fp, &edges) in face.patches.iter().zip(edges) {
        if segment_meets_box(q, frame.d, reach, fp.lo, fp.hi, dedup) {
            let edges = SurfaceEdges {
                sides: edges,
                gap,
                only: false,
            };
            patch_hits(
                fp.boxed(),
                edges,
                q,
                frame,
                reach,
                &mut found,
                &mut unresolved,
            );
            hits.extend(found.drain(..).map(|h| face_hit(fp, h)));
        } else if edges.contains(&true) && segment_meets_box(q, frame.d, reach, fp.lo, fp.hi, gap) {
            // Only near the patch: what it can hold is a gap at an edge, not a hit ahead (a
            // hit behind `q` within the margin would reject the ray only because of the
            // padding).
            let edges = SurfaceEdges {
                sides: edges,
                gap,
                only: true,
            };
            patch_hits(
                fp.boxed(),
                edges,
                q,
                frame,
                reach,
                &mut found,
                &mut unresolved,
            );
            found.clear();
        }
    }
    let mut kept: Vec<Hit> = Vec::new();
    for h in hits {
        if kept.iter().all(|k| norm(sub(k.point, h.point)) > dedup) {
            kept.push(h);
        }
    }
    FaceHits {
        hits: kept,
        unresolved,
    }
}

/// A patch hit in the face's surface parameters: `(u, v)`, the parameters the trimming loops are
/// in, and the partial derivatives along them.
fn face_hit(fp: &FacePatch, h: PatchHit) -> Hit {
    let (uv, [du, dv]) = fp.uv_at(h.st);
    let (ds, dt) = (h.ds, h.dt);
    Hit {
        point: h.point,
        uv,
        su: [ds[0] / du, ds[1] / du, ds[2] / du],
        sv: [dt[0] / dv, dt[1] / dv, dt[2] / dv],
        tau: h.tau,
    }
}

/// [`face_hits`]' answer.
struct FaceHits {
    hits: Vec<Hit>,
    /// Spans along the ray where a crossing may have been missed.
    unresolved: Vec<[f64; 2]>,
}

/// Which sides of each patch of `face` (`s = 0`, `s = 1`, `t = 0`, `t = 1`) lie on the edge of
/// its untrimmed surface: the patches tile the face's parameter rectangle, and a side on the
/// rectangle's border is an edge unless the surface closes up there (a full period).
fn surface_edges(face: &Face) -> Vec<[bool; 4]> {
    let (mut u, mut v) = (
        [f64::INFINITY, f64::NEG_INFINITY],
        [f64::INFINITY, f64::NEG_INFINITY],
    );
    for fp in &face.patches {
        u = [u[0].min(fp.u[0]), u[1].max(fp.u[1])];
        v = [v[0].min(fp.v[0]), v[1].max(fp.v[1])];
    }
    let open = |period: Option<f64>, span: [f64; 2]| {
        period.is_none_or(|p| span[1] - span[0] < p * (1.0 - 1e-9))
    };
    let (open_u, open_v) = (open(face.trim.period_u, u), open(face.trim.period_v, v));
    face.patches
        .iter()
        .map(|fp| {
            [
                open_u && fp.u[0] <= u[0],
                open_u && fp.u[1] >= u[1],
                open_v && fp.v[0] <= v[0],
                open_v && fp.v[1] >= v[1],
            ]
        })
        .collect()
}

/// A certified piece of a surface-boundary curve: curve, dyadic `(level, index)` in its
/// parameter, control points in the ray frame relative to the query.
struct BoundaryPiece {
    /// The model's boundary curve the piece was cut from (its cached samples); `None` for a
    /// curve of a boundary point's own (`on_boundary_along`), integrated from its control points.
    curve: Option<usize>,
    level: u32,
    index: u64,
    ctrl: Vec<Homogeneous>,
}

/// A hit of a grid column's line ([`StepWindingNumber::evaluate_column`]).
struct LineHit {
    /// Distance along the line from its base point.
    tau: f64,
    /// Crossing sign if inside the face's loops, else 0.
    sign: i64,
    /// Grazing or within the margin of the loops: no ray from a point towards it may use it.
    ambiguous: bool,
}

struct Hit {
    point: [f64; 3],
    uv: [f64; 2],
    su: [f64; 3],
    sv: [f64; 3],
    tau: f64,
}

/// Trimmed models plug into grids and products like the other evaluators.
impl crate::eval::Evaluator for StepWindingNumber {
    fn eval(&self, q: [f64; 3]) -> f64 {
        StepWindingNumber::eval(self, q)
    }
    fn name(&self) -> &'static str {
        "exact (trimmed B-rep)"
    }
    fn eval_batch(&self, points: &[[f64; 3]]) -> Vec<f64> {
        StepWindingNumber::eval_batch(self, points)
    }
    fn eval_column(&self, q: [f64; 3], axis: usize, ts: &[f64]) -> Vec<f64> {
        self.evaluate_column(q, axis, ts)
            .into_iter()
            .map(|e| e.value)
            .collect()
    }
    fn segment_crossings(&self, a: [f64; 3], b: [f64; 3]) -> Option<Vec<SurfaceCrossing>> {
        Some(StepWindingNumber::segment_crossings(self, a, b))
    }
}
