//! The perturbed predicates on the input values **exactly as given**, for points that do not lie
//! on the lattice (issue 21).
//!
//! The 60-bit lattice holds every coordinate of a mesh whose significant bits fit it, and then the
//! integer predicates of [`super::predicates`] are exact. A coordinate much smaller than the
//! extent (`1e-20` next to `10`), or with more significant bits than the lattice holds, is not on
//! it: snapping moves such a vertex by up to half a cell, and a query one ulp from it could then
//! be decided for the snapped surface instead of the input. Here a point is its lattice point `n`
//! plus its residual `r` (cells, `|r| ≤ 1/2`, a dyadic rational: exact unless the world → grid
//! scaling underflowed, in which case the world coordinates rebuild it), and each predicate is
//! - an `f64` filter on the offsets `(n_p − n_q) + (r_p − r_q)`, whose rigorous error bound
//!   includes the rounding of every input offset (`INPUT_OFFSET_*`), so a sign it gives is the
//!   sign of the exact input value; otherwise
//! - the exact evaluation in [`Dyadic`] arithmetic (big-integer significands, unbounded
//!   exponents), counted by [`exact_fallbacks`].
//!
//! **The perturbation is the lattice one, coefficient for coefficient** (docs/robustness.md §2):
//! `orient2d` is decided by `D0`, then `a_y − b_y`, then `b_x − a_x`; the plane side by
//! `(q − p0)·n`, then `n_x`, `n_y`, `n_z`; the on-segment limit by the same rules as
//! [`super::predicates::query_inside_segment`]. On the lattice (all residuals zero) every value
//! here equals the lattice one, because the lattice is an exact affine image of the input (a
//! translation and a positive power-of-two scaling) — so the two paths can be mixed freely, one
//! per triangle or edge, and still decide every sign for the same symbolic point `q_ε`.

use std::sync::atomic::{AtomicU64, Ordering};

use super::double_double::DoubleDouble;
use super::dyadic::Dyadic;
use super::predicates::Orient2d;

/// A point exactly as the user gave it, in the ray frame and in cell units: the lattice point
/// `n` and the residual `r` (`x = n + r`, `|r_k| ≤ 1/2`, dyadic).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct InputPoint {
    /// Lattice coordinates relative to the grid origin (frame).
    pub n: [i64; 3],
    /// Residuals in cells (frame); exact where `exact[k]`, else within `2^-1000` cells.
    pub r: [f64; 3],
    /// The world coordinates in frame order (axes permuted and negated, so exact), from which a
    /// residual that underflowed is rebuilt exactly.
    pub world: [f64; 3],
    /// Per axis: whether `n + r` is the exact value (false only where the world → grid scaling
    /// of a coordinate underflowed: a huge mesh and a tiny coordinate).
    pub exact: [bool; 3],
}

impl InputPoint {
    /// A lattice point (an input that snapped without loss, or a clamped query's proxy).
    #[inline]
    pub fn lattice(n: [i64; 3]) -> InputPoint {
        InputPoint {
            n,
            r: [0.0; 3],
            world: [0.0; 3],
            exact: [true; 3],
        }
    }

    /// Whether the point is its lattice point.
    #[inline]
    pub fn on_lattice(&self) -> bool {
        self.residual_exact() && self.r[0] == 0.0 && self.r[1] == 0.0 && self.r[2] == 0.0
    }

    /// Whether `n + r` is exact on every axis.
    #[inline]
    pub fn residual_exact(&self) -> bool {
        self.exact[0] && self.exact[1] && self.exact[2]
    }
}

/// How a frame coordinate's exact value in cells is rebuilt from its world value:
/// `x_cells = x_world · 2^shift − origin_cells` (the grid's power-of-two rescaling and cell, and
/// its origin, in frame order).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct LatticeFrame {
    /// `log2(rescale) − log2(cell)`.
    pub shift: i64,
    /// The grid origin in cells, frame order and signs.
    pub origin_cells: [i128; 3],
}

impl LatticeFrame {
    fn coordinate(&self, p: &InputPoint, k: usize) -> Dyadic {
        if p.exact[k] {
            &Dyadic::from_int(i128::from(p.n[k])) + &Dyadic::from_f64(p.r[k])
        } else {
            &Dyadic::from_f64(p.world[k]).scaled(self.shift)
                - &Dyadic::from_int(self.origin_cells[k])
        }
    }

    fn point(&self, p: &InputPoint) -> [Dyadic; 3] {
        std::array::from_fn(|k| self.coordinate(p, k))
    }

    /// `a − q` and `b − q`, exactly.
    fn offsets(
        &self,
        q: &InputPoint,
        a: &InputPoint,
        b: &InputPoint,
    ) -> ([Dyadic; 3], [Dyadic; 3]) {
        let q = self.point(q);
        let from_q = |p: &InputPoint| -> [Dyadic; 3] {
            let p = self.point(p);
            std::array::from_fn(|k| &p[k] - &q[k])
        };
        (from_q(a), from_q(b))
    }
}

const U: f64 = f64::EPSILON * 0.5;

/// Relative part of the error bound of an `f64` offset `fl(fl(n_p − n_q) + fl(r_p − r_q))`.
/// Each of the three roundings errs by `u` of its result; `|n_p − n_q| ≤ |offset| + 1`, so the
/// total is `≤ 2u·|offset| + 2u` plus `2^-1000` for a residual that underflowed. We use `3u`.
pub const INPUT_OFFSET_RELATIVE: f64 = 3.0 * U;

/// Absolute part of the offset's error bound, in cells (see [`INPUT_OFFSET_RELATIVE`]).
pub const INPUT_OFFSET_ABSOLUTE: f64 = 3.0 * U;

/// The filters' bounds are doubled: this covers the rounding of the bound's own evaluation
/// (relative `O(u)`) with a wide margin.
pub const INPUT_FILTER_SAFETY: f64 = 2.0;

/// Relative rounding of a difference of two `f64` products: `γ2 ≤ 3u` of the permanent.
const PRODUCT_DIFFERENCE: f64 = 3.0 * U;

/// Relative rounding of [`input_orient2d`]'s lattice stage: two conversions (`u` each) per
/// product and the difference of the products (`3u`), `≤ 5u` of the permanent; we use `6u`.
const LATTICE_STAGE_ROUNDING: f64 = 6.0 * U;

/// Relative rounding of a dot product of three terms (three products, two sums): `≤ 4u`.
const DOT3: f64 = 4.0 * U;

static EXACT_FALLBACKS: AtomicU64 = AtomicU64::new(0);

/// How many times, since the process started, an input predicate could not be decided by its
/// `f64` filter and ran in exact big-integer arithmetic (the slow path of issue 21; `gwn bench`
/// reports it per mesh).
pub fn exact_fallbacks() -> u64 {
    EXACT_FALLBACKS.load(Ordering::Relaxed)
}

#[cold]
fn count_fallback() {
    EXACT_FALLBACKS.fetch_add(1, Ordering::Relaxed);
}

/// `p − q` in `f64` (cells) and its error bound per axis.
#[inline]
fn offset(p: &InputPoint, q: &InputPoint) -> ([f64; 3], [f64; 3]) {
    let v: [f64; 3] = std::array::from_fn(|k| (p.n[k] - q.n[k]) as f64 + (p.r[k] - q.r[k]));
    let e = v.map(|x| INPUT_OFFSET_RELATIVE * x.abs() + INPUT_OFFSET_ABSOLUTE);
    (v, e)
}

/// `x·y` with `|x − x̃| ≤ ex`, `|y − ỹ| ≤ ey`: the bound on `|x̃ỹ − xy|`.
#[inline]
fn product_error(x: f64, ex: f64, y: f64, ey: f64) -> f64 {
    x.abs() * ey + ex * y.abs() + ex * ey
}

/// Stage 0 of [`input_orient2d`], from the lattice points alone (as cheap as the lattice
/// filter, and it needs no more memory): the determinant of the lattice offsets, with the slack
/// of the residuals (each offset moves by at most 1 per axis, so `D` by at most
/// `Σ|lattice offsets| + 2`) and of the roundings (`2u` per converted offset, `3u` for the
/// products' difference). It decides unless the query is within a few cells of the edge's line.
#[inline(always)]
fn snapped_orient2d(q: [i64; 2], a: [i64; 2], b: [i64; 2]) -> Option<i32> {
    let (u0, u1) = ((a[0] - q[0]) as f64, (a[1] - q[1]) as f64);
    let (v0, v1) = ((b[0] - q[0]) as f64, (b[1] - q[1]) as f64);
    let (p1, p2) = (u0 * v1, u1 * v0);
    let d = p1 - p2;
    let bound = INPUT_FILTER_SAFETY
        * (LATTICE_STAGE_ROUNDING * (p1.abs() + p2.abs())
            + (u0.abs() + u1.abs() + v0.abs() + v1.abs())
            + 2.0);
    if d > bound {
        Some(1)
    } else if d < -bound {
        Some(-1)
    } else {
        None
    }
}

/// [`input_projected_containment`] from the lattice points of the query and the triangle alone,
/// when [`snapped_orient2d`] decides it: `Some(0)` when the query is outside (the lattice box
/// grown by a cell misses it, or two edges disagree), `Some(sign(n_z))` when every edge puts it
/// inside, `None` when the exact points are needed. The crossing loop asks this first, so a
/// triangle off the lattice costs about what a lattice one does.
#[inline]
pub fn snapped_projected_containment(q: [i64; 2], p: &[[i64; 3]; 3]) -> Option<i32> {
    for k in 0..2 {
        let lo = p[0][k].min(p[1][k]).min(p[2][k]);
        let hi = p[0][k].max(p[1][k]).max(p[2][k]);
        if q[k] < lo - 1 || q[k] > hi + 1 {
            return Some(0);
        }
    }
    let edge = |i: usize, j: usize| snapped_orient2d(q, [p[i][0], p[i][1]], [p[j][0], p[j][1]]);
    let signs = [edge(0, 1), edge(1, 2), edge(2, 0)];
    let mut seen = 0;
    for s in signs.into_iter().flatten() {
        if seen != 0 && s != seen {
            return Some(0);
        }
        seen = s;
    }
    if signs.iter().all(Option::is_some) {
        Some(seen)
    } else {
        None
    }
}

/// Stage 0 of [`input_plane_side`] from the lattice points alone: `T = (q − p0)·(e1 × e2)` of the
/// lattice offsets, with the slack of moving every offset coordinate by at most 1 (the residuals
/// of both ends) and the roundings of the conversions and products. `None` when the query is
/// within that slack of the triangle's plane.
#[inline]
pub fn snapped_plane_side(q: [i64; 3], p: &[[i64; 3]; 3]) -> Option<i32> {
    let f =
        |a: [i64; 3], b: [i64; 3]| -> [f64; 3] { std::array::from_fn(|k| (a[k] - b[k]) as f64) };
    let (d, e1, e2) = (f(q, p[0]), f(p[1], p[0]), f(p[2], p[0]));
    let mut t = 0.0;
    let mut slack = 0.0;
    for (k, dk) in d.into_iter().enumerate() {
        let (i, j) = ((k + 1) % 3, (k + 2) % 3);
        let (pa, pb) = (e1[i] * e2[j], e1[j] * e2[i]);
        let c = pa - pb;
        // |Δc| ≤ |e1_i| + |e1_j| + |e2_i| + |e2_j| + 2 from the offsets, plus rounding.
        let dc = e1[i].abs()
            + e1[j].abs()
            + e2[i].abs()
            + e2[j].abs()
            + 2.0
            + LATTICE_STAGE_ROUNDING * (pa.abs() + pb.abs());
        t += dk * c;
        slack += (dk.abs() + 1.0) * dc + c.abs() + LATTICE_STAGE_ROUNDING * (dk * c).abs();
    }
    let bound = INPUT_FILTER_SAFETY * slack;
    if t > bound {
        Some(1)
    } else if t < -bound {
        Some(-1)
    } else {
        None
    }
}

/// The perturbed 2D orientation of `(q_ε, a, b)` seen along the ray, on the exact inputs (the
/// same definition as [`super::predicates::perturbed_orient2d`]).
#[inline]
pub fn input_orient2d(
    q: &InputPoint,
    a: &InputPoint,
    b: &InputPoint,
    lattice: &LatticeFrame,
) -> Orient2d {
    if let Some(sign) = snapped_orient2d([q.n[0], q.n[1]], [a.n[0], a.n[1]], [b.n[0], b.n[1]]) {
        return Orient2d {
            sign,
            degenerate: false,
        };
    }
    let (u, eu) = offset(a, q);
    let (v, ev) = offset(b, q);
    let p1 = u[0] * v[1];
    let p2 = u[1] * v[0];
    let d = p1 - p2;
    let bound = INPUT_FILTER_SAFETY
        * (product_error(u[0], eu[0], v[1], ev[1])
            + product_error(u[1], eu[1], v[0], ev[0])
            + PRODUCT_DIFFERENCE * (p1.abs() + p2.abs()));
    if d > bound || d < -bound {
        return Orient2d {
            sign: if d > 0.0 { 1 } else { -1 },
            degenerate: false,
        };
    }
    exact_orient2d(q, a, b, lattice)
}

/// Whether the segment `a b` is parallel to the ray (its ends project along it to one point) and
/// `q` is at least two cells from that point on a horizontal axis. Then [`input_orient2d`] is
/// `{ sign: 0, degenerate: true }` for `q` without arithmetic: `det(a − q, b − q)` has two equal
/// columns, and both ε coefficients, `a_y − b_y` and `b_x − a_x`, are zero; and `q_ε` is not inside
/// the segment ([`input_inside_segment`]: `q` is off the segment's line, so `a − q` and `b − q`
/// are not parallel). Exact from the lattice points and residuals alone: equal `n` and exact `r`
/// on an axis are one value, and `|n_q − n_a| ≥ 2` with `|r| ≤ ½` leaves at least a cell between
/// the two values. Why it is worth asking: such an edge's orientation is 0 for every query, which
/// no `f64` filter can sign, so off the lattice each of its terms took the exact (`Dyadic`)
/// orientation and inside-segment tests: a wall's vertical boundary edge under the default `+z`
/// ray, at every evaluation (assimp-regr01 at res 256: 18 M such terms, half the remesh's CPU).
#[inline]
pub fn along_the_ray_off_its_line(q: &InputPoint, a: &InputPoint, b: &InputPoint) -> bool {
    parallel_to_the_ray(a, b) && (0..2).any(|k| q.n[k].abs_diff(a.n[k]) >= 2)
}

/// Whether `a` and `b` have the same exact frame `x` and `y` (the segment is parallel to the ray,
/// or has zero length): equal lattice points and exact, equal residuals on both axes.
#[inline]
pub fn parallel_to_the_ray(a: &InputPoint, b: &InputPoint) -> bool {
    let same = |k: usize| a.n[k] == b.n[k] && a.r[k] == b.r[k] && a.exact[k] && b.exact[k];
    same(0) && same(1)
}

#[cold]
fn exact_orient2d(q: &InputPoint, a: &InputPoint, b: &InputPoint, l: &LatticeFrame) -> Orient2d {
    count_fallback();
    let (q, a, b) = (l.point(q), l.point(a), l.point(b));
    let (u0, u1) = (&a[0] - &q[0], &a[1] - &q[1]);
    let (v0, v1) = (&b[0] - &q[0], &b[1] - &q[1]);
    let d = &(&u0 * &v1) - &(&u1 * &v0);
    if d.sign() != 0 {
        return Orient2d {
            sign: d.sign(),
            degenerate: false,
        };
    }
    // The ε1 and ε2 coefficients, as on the lattice.
    let s1 = (&a[1] - &b[1]).sign();
    Orient2d {
        sign: if s1 != 0 { s1 } else { (&b[0] - &a[0]).sign() },
        degenerate: true,
    }
}

/// `sign((q_ε − p0)·n)`, `n = (p1 − p0)×(p2 − p0)`, on the exact inputs (the same definition as
/// [`super::predicates::perturbed_plane_side`]).
#[inline]
pub fn input_plane_side(q: &InputPoint, p: &[InputPoint; 3], lattice: &LatticeFrame) -> i32 {
    let (d, ed) = offset(q, &p[0]);
    let (e1, ee1) = offset(&p[1], &p[0]);
    let (e2, ee2) = offset(&p[2], &p[0]);
    let mut t = 0.0;
    let mut permanent = 0.0;
    let mut propagated = 0.0;
    for k in 0..3 {
        let (i, j) = ((k + 1) % 3, (k + 2) % 3);
        let pa = e1[i] * e2[j];
        let pb = e1[j] * e2[i];
        let c = pa - pb;
        let ec = product_error(e1[i], ee1[i], e2[j], ee2[j])
            + product_error(e1[j], ee1[j], e2[i], ee2[i])
            + PRODUCT_DIFFERENCE * (pa.abs() + pb.abs());
        t += d[k] * c;
        permanent += (d[k] * c).abs();
        propagated += product_error(d[k], ed[k], c, ec);
    }
    let bound = INPUT_FILTER_SAFETY * (propagated + DOT3 * permanent);
    if t > bound {
        return 1;
    }
    if t < -bound {
        return -1;
    }
    exact_plane_side(q, p, lattice)
}

#[cold]
fn exact_plane_side(q: &InputPoint, p: &[InputPoint; 3], l: &LatticeFrame) -> i32 {
    count_fallback();
    let q = l.point(q);
    let p = p.map(|v| l.point(&v));
    let sub = |a: &[Dyadic; 3], b: &[Dyadic; 3]| -> [Dyadic; 3] {
        std::array::from_fn(|k| &a[k] - &b[k])
    };
    let (d, e1, e2) = (sub(&q, &p[0]), sub(&p[1], &p[0]), sub(&p[2], &p[0]));
    let n: [Dyadic; 3] = std::array::from_fn(|k| {
        let (i, j) = ((k + 1) % 3, (k + 2) % 3);
        &(&e1[i] * &e2[j]) - &(&e1[j] * &e2[i])
    });
    let t = &(&(&d[0] * &n[0]) + &(&d[1] * &n[1])) + &(&d[2] * &n[2]);
    if t.sign() != 0 {
        return t.sign();
    }
    // The ε1, ε2, ε3 coefficients n_x, n_y, n_z, as on the lattice.
    n.iter().map(Dyadic::sign).find(|&s| s != 0).unwrap_or(0)
}

/// The ray from `q_ε` along `+z` against triangle `p` on the exact inputs (the same definition
/// as [`super::predicates::ray_crossing`]).
#[inline]
pub fn input_ray_crossing(q: &InputPoint, p: &[InputPoint; 3], lattice: &LatticeFrame) -> i32 {
    let s0 = input_projected_containment(q, p, lattice);
    if s0 == 0 {
        return 0;
    }
    if input_plane_side(q, p, lattice) == -s0 {
        s0
    } else {
        0
    }
}

/// `sign(n_z)` when the projection of `q_ε` lies strictly inside the projected triangle, else 0
/// (the same definition as [`super::predicates::projected_containment`]).
#[inline]
pub fn input_projected_containment(
    q: &InputPoint,
    p: &[InputPoint; 3],
    lattice: &LatticeFrame,
) -> i32 {
    // Conservative early-out on the lattice: every exact coordinate is within half a cell of its
    // lattice value, so a query strictly inside lies in the lattice box grown by one cell.
    for k in 0..2 {
        let lo = p[0].n[k].min(p[1].n[k]).min(p[2].n[k]);
        let hi = p[0].n[k].max(p[1].n[k]).max(p[2].n[k]);
        if q.n[k] < lo - 1 || q.n[k] > hi + 1 {
            return 0;
        }
    }
    let edge = |i: usize, j: usize| input_orient2d(q, &p[i], &p[j], lattice).sign;
    let s0 = edge(0, 1);
    if s0 == 0 || edge(1, 2) != s0 || edge(2, 0) != s0 {
        return 0;
    }
    s0
}

/// Whether `q_ε` lies strictly inside segment `a b` to first order in ε, on the exact inputs (the
/// same definition as [`super::predicates::query_inside_segment`]; only asked after a degenerate
/// orientation, so always exact arithmetic).
#[cold]
pub fn input_inside_segment(
    q: &InputPoint,
    a: &InputPoint,
    b: &InputPoint,
    lattice: &LatticeFrame,
) -> bool {
    count_fallback();
    let (ra, rb) = lattice.offsets(q, a, b);
    let zero = |r: &[Dyadic; 3]| r.iter().all(|c| c.sign() == 0);
    let along_pos_x = |r: &[Dyadic; 3]| r[0].sign() > 0 && r[1].sign() == 0 && r[2].sign() == 0;
    if zero(&ra) {
        return along_pos_x(&rb);
    }
    if zero(&rb) {
        return along_pos_x(&ra);
    }
    if cross(&ra, &rb).iter().any(|c| c.sign() != 0) {
        return false;
    }
    let dot = &(&(&ra[0] * &rb[0]) + &(&ra[1] * &rb[1])) + &(&ra[2] * &rb[2]);
    dot.sign() < 0
}

/// After a degenerate orientation (`q`, `a`, `b` collinear seen along the ray) with `q_ε` not
/// inside the segment: the exact sign of the edge term's denominator
/// `(|ra| − ra_z)(|rb| − rb_z) + ra_x rb_x + ra_y rb_y`, or `0` when it is not decided here
/// (an end at `q` or on its vertical line: the limit formulas take those).
///
/// Both ends then lie in one vertical plane through `q`, at signed horizontal positions `s_a`,
/// `s_b` along it. On one side (`s_a s_b > 0`) every term of the denominator is `≥ 0` and the
/// planar product `> 0`: `+1`. On both sides the segment crosses `q`'s vertical line at height
/// `z* = (z_b s_a − z_a s_b)/(s_a − s_b)` above `q`, and the arc from `A` to `B` passes over
/// the ray's direction exactly when `z* > 0`, where the denominator is negative (its two terms
/// are `|ra_xy||rb_xy|·(tan(θa/2)·tan(θb/2) − 1)`, `θ` the angles from `+z`, and
/// `θa + θb < π` there). `z* = 0` puts `q` on the segment, the inside-segment limit: `0`.
///
/// The side of each end along the line and the crossing height's sign do not depend on the
/// horizontal axis they are read on (both carry the line direction's component on it), so the
/// `f64` filter takes any axis on which both offsets are certainly non-zero.
#[inline]
pub fn input_flat_denominator_sign(
    q: &InputPoint,
    a: &InputPoint,
    b: &InputPoint,
    lattice: &LatticeFrame,
) -> i32 {
    let (u, eu) = offset(a, q);
    let (v, ev) = offset(b, q);
    let certain = |x: f64, e: f64| x.abs() > e;
    if let Some(k) = (0..2).find(|&k| certain(u[k], eu[k]) && certain(v[k], ev[k])) {
        let (sa, sb) = (u[k].signum(), v[k].signum());
        if sa == sb {
            return 1;
        }
        let (p1, p2) = (v[2] * u[k], u[2] * v[k]);
        let height = p1 - p2;
        let bound = INPUT_FILTER_SAFETY
            * (product_error(v[2], ev[2], u[k], eu[k])
                + product_error(u[2], eu[2], v[k], ev[k])
                + PRODUCT_DIFFERENCE * (p1.abs() + p2.abs()));
        if height.abs() > bound {
            return if height.signum() == sa { -1 } else { 1 };
        }
    }
    exact_flat_denominator_sign(q, a, b, lattice)
}

#[cold]
fn exact_flat_denominator_sign(
    q: &InputPoint,
    a: &InputPoint,
    b: &InputPoint,
    lattice: &LatticeFrame,
) -> i32 {
    count_fallback();
    let (ra, rb) = lattice.offsets(q, a, b);
    let on_vertical_line = |r: &[Dyadic; 3]| r[0].sign() == 0 && r[1].sign() == 0;
    if on_vertical_line(&ra) || on_vertical_line(&rb) {
        return 0;
    }
    // The common horizontal line through q: along x unless it is the y axis.
    let k = if ra[0].sign() != 0 || rb[0].sign() != 0 {
        0
    } else {
        1
    };
    let (sa, sb) = (ra[k].sign(), rb[k].sign());
    if sa == sb {
        return 1;
    }
    // sign(z*) = sign(z_b s_a − z_a s_b)·sign(s_a − s_b), and sign(s_a − s_b) = sign(s_a).
    let height = &(&rb[2] * &ra[k]) - &(&ra[2] * &rb[k]);
    -height.sign() * sa
}

/// `a × b`, exactly.
fn cross(a: &[Dyadic; 3], b: &[Dyadic; 3]) -> [Dyadic; 3] {
    std::array::from_fn(|k| {
        let (i, j) = ((k + 1) % 3, (k + 2) % 3);
        &(&a[i] * &b[j]) - &(&a[j] * &b[i])
    })
}

/// `(a − q) × (b − q)` on the exact inputs as `(v, k)` with the vector `v·2^k`: `v`'s largest
/// component in `[1, 2)`, each a double-double within `2^-104` (components `2^-1000` below the
/// largest come out as zero), or `None` when it is zero (`q` on the line `a b`).
///
/// For the edge term of a query within a tiny angle of the segment's interior
/// ([`super::spherical::antipodal_edge_area_accurate`]): there both offsets are nearly
/// antiparallel, every product in the cross product cancels to that angle, and the offsets' own
/// roundings (even in double-double) would decide its direction.
#[cold]
pub fn exact_edge_moment(
    q: &InputPoint,
    a: &InputPoint,
    b: &InputPoint,
    lattice: &LatticeFrame,
) -> Option<([DoubleDouble; 3], i64)> {
    let (ra, rb) = lattice.offsets(q, a, b);
    scaled_to_double_double(cross(&ra, &rb))
}

/// An exact vector as `(v, k)`, `v·2^k` with `v`'s largest component in `[1, 2)` in
/// double-double; `None` for zero.
fn scaled_to_double_double(m: [Dyadic; 3]) -> Option<([DoubleDouble; 3], i64)> {
    let top = m.iter().filter_map(Dyadic::exponent).max()?;
    let m = m.map(|c| {
        let (hi, lo) = c.to_double_double_scaled(top);
        DoubleDouble { hi, lo }
    });
    Some((m, top))
}

/// `(a − q) × (b − q)` of `f64` points exactly, as [`exact_edge_moment`] gives it (`m·2^k`, `m`'s
/// largest component in `[1, 2)`; `None` when `q` is on the line `a b`): for the direct sum's
/// solid angle next to an edge ([`super::spherical::triangle_solid_angle_at`]).
#[cold]
pub fn exact_moment_of_points(
    q: [f64; 3],
    a: [f64; 3],
    b: [f64; 3],
) -> Option<([DoubleDouble; 3], i64)> {
    let offset = |p: [f64; 3]| -> [Dyadic; 3] {
        std::array::from_fn(|k| &Dyadic::from_f64(p[k]) - &Dyadic::from_f64(q[k]))
    };
    scaled_to_double_double(cross(&offset(a), &offset(b)))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::kernel::predicates::{
        W128, perturbed_orient2d, perturbed_plane_side, query_inside_segment, ray_crossing,
    };
    use crate::kernel::test_rng::TestRng;

    /// A point with residual `r` (exact).
    fn at(n: [i64; 3], r: [f64; 3]) -> InputPoint {
        InputPoint {
            n,
            r,
            world: [0.0; 3],
            exact: [true; 3],
        }
    }

    #[test]
    fn on_the_lattice_the_input_predicates_are_the_lattice_predicates() {
        let l = LatticeFrame::default();
        let mut rng = TestRng::new(11);
        for round in 0..4000 {
            // Small coordinates make every degeneracy common; large ones exercise the filter.
            let big = round % 2 == 1;
            let mut c = || {
                let v = rng.below(7) as i64 - 3;
                if big { v << 58 } else { v }
            };
            let mut pt = || [c(), c(), c()];
            let (q, a, b, d) = (pt(), pt(), pt(), pt());
            let ip = InputPoint::lattice;
            assert_eq!(
                input_orient2d(&ip(q), &ip(a), &ip(b), &l),
                perturbed_orient2d::<W128>([q[0], q[1]], [a[0], a[1]], [b[0], b[1]]),
                "{q:?} {a:?} {b:?}"
            );
            let t = [a, b, d];
            assert_eq!(
                input_plane_side(&ip(q), &t.map(ip), &l),
                perturbed_plane_side::<W128>(q, t)
            );
            assert_eq!(
                input_ray_crossing(&ip(q), &t.map(ip), &l),
                ray_crossing::<W128>(q, t)
            );
            assert_eq!(
                input_inside_segment(&ip(q), &ip(a), &ip(b), &l),
                query_inside_segment(q, a, b)
            );
        }
    }

    /// The shortcut's claim, against the exact predicates it skips: for segments parallel to the
    /// ray (off the lattice or on it) and queries around them, whenever it applies the perturbed
    /// orientation is `{0, degenerate}` and `q_ε` is not inside the segment; and it applies to
    /// no segment that is not parallel to the ray, and to no query within a cell of its line.
    #[test]
    fn segments_along_the_ray_seen_from_off_their_line() {
        let l = LatticeFrame::default();
        let mut rng = TestRng::new(23);
        let mut applied = 0;
        for round in 0..20_000 {
            let mut c = |m: u64| rng.below(m) as i64 - (m / 2) as i64;
            let residual = |v: i64| match v.rem_euclid(4) {
                0 => 0.0,
                1 => 2f64.powi(-70) * v as f64,
                2 => 0.5 - 2f64.powi(-40),
                _ => -0.25,
            };
            let (x, y) = (c(7), c(7));
            let (rx, ry) = (residual(c(8)), residual(c(8)));
            let a = at([x, y, c(9)], [rx, ry, residual(c(8))]);
            let mut b = at([x, y, c(9)], [rx, ry, residual(c(8))]);
            // One in four: not quite parallel (a residual or a lattice step apart).
            match round % 8 {
                0 => b.r[0] += 2f64.powi(-60),
                1 => b.n[1] += 1,
                _ => {}
            }
            let q = at([c(11), c(11), c(9)], [residual(c(8)), residual(c(8)), 0.0]);
            let parallel = a.n[..2] == b.n[..2] && a.r[..2] == b.r[..2];
            if along_the_ray_off_its_line(&q, &a, &b) {
                applied += 1;
                assert!(parallel, "{a:?} {b:?}");
                assert_eq!(
                    exact_orient2d(&q, &a, &b, &l),
                    Orient2d {
                        sign: 0,
                        degenerate: true
                    },
                    "{q:?} {a:?} {b:?}"
                );
                assert!(!input_inside_segment(&q, &a, &b, &l), "{q:?} {a:?} {b:?}");
            } else if parallel {
                assert!((0..2).all(|k| q.n[k].abs_diff(a.n[k]) < 2), "{q:?} {a:?}");
            }
        }
        assert!(applied > 5_000, "{applied}");
    }

    #[test]
    fn flat_denominators_take_the_side_the_segment_passes_the_ray_line() {
        let l = LatticeFrame::default();
        let ip = InputPoint::lattice;
        let q = ip([0, 0, 0]);
        // Ends on both sides of q's vertical line: the segment crosses it above q (the arc
        // passes over the ray: negative), below (positive); on one side: positive.
        for (a, b, want) in [
            ([2, 0, 1], [-2, 0, 1], -1),
            ([2, 0, -1], [-2, 0, -1], 1),
            ([2, 0, 1], [-1, 0, -3], 1),
            ([0, 3, 5], [0, -1, -1], -1),
            ([2, 2, 1], [4, 4, -7], 1),
            // Crossing 2^-59 above / below q: beyond the filter's reach on the lattice too.
            ([1 << 58, 0, 1], [-(1 << 58) - 1, 0, -1], -1),
            ([1 << 58, 0, 1], [-(1 << 58) + 1, 0, -1], 1),
        ] {
            let s = input_flat_denominator_sign(&q, &ip(a), &ip(b), &l);
            assert_eq!(s, want, "{a:?} {b:?}");
            assert_eq!(exact_flat_denominator_sign(&q, &ip(a), &ip(b), &l), want);
        }
        // Residuals below the filter: the segment from (-1, 0, 2^-60) to (1, 0, -2^-60 + r)
        // crosses q's line at height r/2 (cells), decided exactly.
        for (r, want) in [(2f64.powi(-80), -1), (-(2f64.powi(-80)), 1)] {
            let a = at([-1, 0, 0], [0.0, 0.0, 2f64.powi(-60)]);
            let b = at([1, 0, 0], [0.0, 0.0, -(2f64.powi(-60)) + r]);
            assert_eq!(input_flat_denominator_sign(&q, &a, &b, &l), want);
        }
        // An end on q's vertical line is left to the limit formulas.
        assert_eq!(
            input_flat_denominator_sign(&q, &ip([0, 0, 4]), &ip([1, 0, 1]), &l),
            0
        );
        // The filter agrees with the exact evaluation on random collinear configurations.
        let mut rng = TestRng::new(5);
        for _ in 0..4000 {
            let mut c = |m: u64| rng.below(m) as i64 - (m / 2) as i64;
            let d = [c(5), c(5)];
            if d == [0, 0] {
                continue;
            }
            let (la, lb) = (c(9), c(9));
            let (a, b) = (
                ip([la * d[0], la * d[1], c(9)]),
                ip([lb * d[0], lb * d[1], c(9)]),
            );
            assert_eq!(
                input_flat_denominator_sign(&q, &a, &b, &l),
                exact_flat_denominator_sign(&q, &a, &b, &l),
                "{a:?} {b:?}"
            );
        }
    }

    #[test]
    fn residuals_below_the_filter_are_decided_exactly() {
        let l = LatticeFrame::default();
        // Edge from (0,0) to (2^58, 2 + 2^-58) and a query at (2^57, 1 + 2^-59): exactly on the
        // edge's line; the f64 offsets round the residuals away, so only the exact path sees it.
        let a = at([0, 0, 0], [0.0; 3]);
        let b = at([1 << 58, 2, 0], [0.0, 2f64.powi(-58), 0.0]);
        let q = at([1 << 57, 1, 0], [0.0, 2f64.powi(-59), 0.0]);
        let before = exact_fallbacks();
        let o = input_orient2d(&q, &a, &b, &l);
        assert!(exact_fallbacks() > before);
        // D = 0: decided by ε1, a_y − b_y < 0.
        assert_eq!(
            o,
            Orient2d {
                sign: -1,
                degenerate: true
            }
        );
        // Below the line by 2^-59 cells, and above it by as much.
        let q2 = at(q.n, [0.0; 3]);
        assert_eq!(input_orient2d(&q2, &a, &b, &l).sign, -1);
        let q3 = at(q.n, [0.0, 2f64.powi(-58), 0.0]);
        assert_eq!(input_orient2d(&q3, &a, &b, &l).sign, 1);
    }

    #[test]
    fn underflowed_residuals_are_rebuilt_from_the_world_value() {
        // A lattice of cell 2^-10 (shift 10), origin 0: a world coordinate 2^-1074 is far below
        // any f64 residual in cells of a coarse grid once scaled down; with exact = false the
        // predicate rebuilds it from `world`.
        let l = LatticeFrame {
            shift: -2000,
            origin_cells: [0; 3],
        };
        let w = f64::from_bits(1);
        let q = InputPoint {
            n: [0; 3],
            r: [0.0; 3],
            world: [0.0, w, 0.0],
            exact: [true, false, true],
        };
        let a = InputPoint::lattice([-1, 0, 0]);
        let b = InputPoint::lattice([1, 0, 0]);
        // q is above the x axis by 2^-3074 cells: left of a → b.
        assert_eq!(input_orient2d(&q, &a, &b, &l).sign, 1);
        let below = InputPoint {
            world: [0.0, -w, 0.0],
            ..q
        };
        assert_eq!(input_orient2d(&below, &a, &b, &l).sign, -1);
    }
}
