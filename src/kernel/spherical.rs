//! Signed areas of spherical triangles: the only place where an `atan2` of a solid angle is taken.
//!
//! Two formulas live here:
//! - [`triangle_solid_angle`]: Van Oosterom & Strackee (1983), the signed solid angle of a
//!   planar triangle seen from the origin, in plain `f64` (the direct evaluator);
//! - [`antipodal_edge_area`]: the Antipodal method's per-boundary-edge term
//!   `Area(A, B, x1) = 2·atan2(x1·(A×B), 1 + A·B + A·x1 + B·x1)` (paper Alg. 1 / Eq. 9), with the
//!   ray fixed to `+z` (so `x1 = −z`), its numerator's sign supplied by the exact perturbed
//!   predicate and the symbolic limits of the degenerate configurations written out.

use super::double_double::{DoubleDouble, dot3};

use super::boundary_sum::scaled_by_power_of_two;
use super::input_predicates::exact_moment_of_points;
use super::quantize::decompose;
use crate::base::vec3::{cross, dot, norm};

/// `1/(4π)`: a solid angle (or a sum of spherical areas) as a winding number.
pub const INV_4PI: f64 = 1.0 / FOUR_PI;

/// `4π`, the solid angle of the whole sphere: integrals of solid angle divide by it to give `w`.
pub const FOUR_PI: f64 = 4.0 * std::f64::consts::PI;

/// `2·atan2(s·mag, den)` where the sign `s ∈ {−1, 0, 1}` of the numerator was decided exactly.
///
/// Never lets a rounding-signed `±0.0` choose the branch: a zero magnitude with `den < 0` gives
/// `s·2π` (the side the exact predicate chose), with `den ≥ 0` it gives 0.
#[inline]
pub fn signed_double_atan2(s: i32, mag: f64, den: f64) -> f64 {
    if s == 0 {
        return 0.0;
    }
    let sf = f64::from(s);
    if mag == 0.0 {
        return if den < 0.0 {
            sf * std::f64::consts::TAU
        } else {
            0.0
        };
    }
    2.0 * (sf * mag).atan2(den)
}

/// Signed solid angle subtended at the origin by the triangle with corners `a, b, c` (positions
/// relative to the query point), in `[-2π, 2π]`.
///
/// Van Oosterom & Strackee on the unit vectors `â, b̂, ĉ`:
/// `tan(Ω/2) = â·(b̂×ĉ) / (1 + â·b̂ + b̂·ĉ + ĉ·â)`. Normalizing first (each vector scaled by a power
/// of two before its norm) makes the formula indifferent to magnitude: the unnormalized form's
/// `|a||b||c|` overflowed for meshes at 1e103 and underflowed for a query 1e-300 from a vertex
/// (issue 11, section 4).
///
/// On-surface semantics: when the triple product is exactly zero (the query lies in the plane of
/// the triangle, on an edge, or on a vertex) the result is 0, the principal value. This is what
/// makes the direct sum return 1/2 on a face of a closed mesh and the solid-angle fraction
/// (e.g. 1/8) at a convex corner. Never NaN for finite input. The tests' reference (the direct
/// evaluator has its own loop).
#[cfg(test)]
#[inline]
pub fn triangle_solid_angle(a: [f64; 3], b: [f64; 3], c: [f64; 3]) -> f64 {
    if let Some(w) = solid_angle_moderate(a, b, c, 0.0) {
        return w;
    }
    match solid_angle_parts(a, b, c) {
        Some((sign, det, den)) => signed_double_atan2(sign, det.abs(), den),
        None => 0.0,
    }
}

/// The common case in the textbook form (no normalization, as fast as before the magnitude
/// fixes): when every `|r|²` is a normal `f64` far from over- and underflow, and
/// `√(det² + den²) ≥ condition·|a||b||c|`. `None` sends the triangle to the careful path
/// ([`solid_angle_parts`], double-double). With `condition > 0` the offsets are rounded ones
/// ([`triangle_solid_angle_at`]): a triple product within [`ZERO_AREA_SUSPECT`] of zero may
/// have its sign (or its zero) from their rounding, and goes to the careful path too.
#[inline]
fn solid_angle_moderate(a: [f64; 3], b: [f64; 3], c: [f64; 3], condition: f64) -> Option<f64> {
    let (la2, lb2, lc2) = (dot(a, a), dot(b, b), dot(c, c));
    let (lo, hi) = (la2.min(lb2).min(lc2), la2.max(lb2).max(lc2));
    if !(lo > SQUARED_NORM_LO && hi < SQUARED_NORM_HI) {
        return None;
    }
    let det = dot(a, cross(b, c));
    if det == 0.0 && condition == 0.0 {
        return Some(0.0);
    }
    let (la, lb, lc) = (la2.sqrt(), lb2.sqrt(), lc2.sqrt());
    let labc = la * lb * lc;
    let den = labc + dot(a, b) * lc + dot(b, c) * la + dot(c, a) * lb;
    if det.abs() <= ZERO_AREA_SUSPECT * labc {
        if condition > 0.0 {
            return None;
        }
        // See the zero-area test of `solid_angle_parts`.
        let e1 = [b[0] - a[0], b[1] - a[1], b[2] - a[2]];
        let e2 = [c[0] - a[0], c[1] - a[1], c[2] - a[2]];
        if cross(e1, e2) == [0.0; 3] {
            return Some(0.0);
        }
    }
    if det * det + den * den < (condition * labc) * (condition * labc) {
        return None;
    }
    Some(2.0 * det.atan2(den))
}

/// `(sign, â·(b̂×ĉ), 1 + â·b̂ + b̂·ĉ + ĉ·â)`, or `None` when the triangle subtends nothing
/// (coplanar query, zero-area triangle). `sign` is the exact sign of `a·(b×c)`, which the `f64`
/// triple product may have lost to underflow (a query `5e-324` off a face).
#[cfg(test)]
fn solid_angle_parts(a: [f64; 3], b: [f64; 3], c: [f64; 3]) -> Option<(i32, f64, f64)> {
    // The exact-zero test on the raw offsets (brought to magnitude ~1 by one common power of
    // two, so that it neither underflows nor overflows), before normalizing rounds it away.
    let m = [a, b, c]
        .iter()
        .flatten()
        .fold(0.0_f64, |m, x| m.max(x.abs()));
    // Products of three components stay in range below 2^300: no scaling needed (the common case).
    let (a, b, c) = if (MODERATE_LO..=MODERATE_HI).contains(&m) {
        (a, b, c)
    } else {
        let s = power_of_two_scale(m);
        let scaled = |v: [f64; 3]| v.map(|x| x * s[0] * s[1]);
        (scaled(a), scaled(b), scaled(c))
    };
    let raw = dot(a, cross(b, c));
    let sign = if raw != 0.0 {
        if raw > 0.0 { 1 } else { -1 }
    } else {
        exact_triple_product_sign(a, b, c)
    };
    if sign == 0 {
        return None;
    }
    let (ua, ub, uc) = (unit(a), unit(b), unit(c));
    let det = dot(ua, cross(ub, uc));
    let den = 1.0 + dot(ua, ub) + dot(ub, uc) + dot(uc, ua);
    if det.abs() <= ZERO_AREA_SUSPECT {
        // A zero-area triangle subtends no solid angle. Without this test, a collinear triangle
        // seen from a point close to its line gives det ≈ ±tiny against den ≤ 0 or den ≈ 0,
        // i.e. up to ±2π (found by the kernel fuzz target: the direct sum returned −1/4 next to
        // a degenerate face). Only a relatively tiny det can be rounding noise, so the exact
        // zero-area test runs only then.
        let e1 = [b[0] - a[0], b[1] - a[1], b[2] - a[2]];
        let e2 = [c[0] - a[0], c[1] - a[1], c[2] - a[2]];
        if cross(e1, e2) == [0.0; 3] {
            return None;
        }
    }
    Some((sign, det, den))
}

/// Exact sign of `a·(b×c)` for any finite `f64` vectors. The rare path of an underflowed `f64`
/// triple product.
#[cfg(test)]
fn exact_triple_product_sign(a: [f64; 3], b: [f64; 3], c: [f64; 3]) -> i32 {
    exact_orientation_sign([0.0; 3], [a, b, c])
}

/// Below this `|â·(b̂×ĉ)|` the double-double triple product of the unit offsets (each within
/// `~2^-104`) may have the wrong sign: [`triangle_solid_angle_at`] decides it exactly.
const DD_TRIPLE_PRODUCT_ROUNDING: f64 = 1.0 / (1u128 << 96) as f64;

/// Exact sign of `(a − q)·((b − q)×(c − q))` for finite `f64` points `[a, b, c]` (every `f64` is
/// `m·2^e`: scaled to integers, big-integer arithmetic).
#[cold]
fn exact_orientation_sign(q: [f64; 3], [a, b, c]: [[f64; 3]; 3]) -> i32 {
    use num_bigint::BigInt;
    let min_exp = [q, a, b, c]
        .iter()
        .flatten()
        .filter(|x| **x != 0.0)
        .map(|&x| decompose(x).1)
        .min()
        .unwrap_or(0);
    let big = |x: f64| -> BigInt {
        let (m, e) = decompose(x);
        BigInt::from(m) << (e - min_exp) as usize
    };
    let offset = |v: [f64; 3]| -> [BigInt; 3] { std::array::from_fn(|k| big(v[k]) - big(q[k])) };
    let (a, b, c) = (offset(a), offset(b), offset(c));
    let cx = &b[1] * &c[2] - &b[2] * &c[1];
    let cy = &b[2] * &c[0] - &b[0] * &c[2];
    let cz = &b[0] * &c[1] - &b[1] * &c[0];
    let d = &a[0] * cx + &a[1] * cy + &a[2] * cz;
    match d.sign() {
        num_bigint::Sign::Plus => 1,
        num_bigint::Sign::Minus => -1,
        num_bigint::Sign::NoSign => 0,
    }
}

/// Below this `√(det² + den²)` (unit vectors) the `f64` solid angle is ill-conditioned: both
/// arguments cancel when the query is near an edge (`≈` distance / edge scale), and the `f64`
/// result errs by `≈ 8u / √(det² + den²)`, `u = 2^-53`; above it by less than `1e-13`.
pub const SOLID_ANGLE_CONDITION: f64 = 1.0 / 64.0;

/// [`triangle_solid_angle`] of the triangle with corners `p` seen from `q` (world coordinates),
/// accurate to `~1e-15` at any distance from its edges, with the exact sign: the offsets `p − q`
/// are exact double-doubles (no loss when `|p| ≫ |p − q|`), ill-conditioned triangles
/// ([`SOLID_ANGLE_CONDITION`]) are evaluated in double-double, and next to an edge's interior
/// with its exact moment ([`solid_angle_next_to_edge`]). Where the triple product is within
/// rounding of zero its sign is decided on the exact offsets: `0` (the principal value) only
/// with `q` exactly in the triangle's plane, or a triangle of exactly zero area.
#[inline]
pub fn triangle_solid_angle_at(p: [[f64; 3]; 3], q: [f64; 3]) -> f64 {
    // The rounded offsets are the leading parts of the exact ones: the fast path needs no more.
    let f = p.map(|v| [v[0] - q[0], v[1] - q[1], v[2] - q[2]]);
    if let Some(w) = solid_angle_moderate(f[0], f[1], f[2], SOLID_ANGLE_CONDITION) {
        return w;
    }
    let r: [[DoubleDouble; 3]; 3] =
        p.map(|v| std::array::from_fn(|k| DoubleDouble::diff(v[k], q[k])));
    if r.iter().any(|v| v.iter().all(|c| c.hi == 0.0))
        || (0..3).any(|k| r.iter().all(|v| v[k].hi == 0.0))
    {
        // `q` at a corner, or in the triangle's axis-aligned plane (a zero column of the triple
        // product; a box's faces sampled at their own coordinate): exactly in its plane,
        // without the exact sign's big integers.
        return 0.0;
    }
    // Unit vectors in `f64` (offsets of any magnitude) where that is well conditioned and the
    // triple product's sign is far above its rounding (`≲ 1.1e-15`, see [`ZERO_AREA_SUSPECT`]).
    let [ua, ub, uc] = r.map(|v| unit(v.map(|c| c.hi)));
    let det = dot(ua, cross(ub, uc));
    let den = 1.0 + dot(ua, ub) + dot(ub, uc) + dot(uc, ua);
    if det.abs() > ZERO_AREA_SUSPECT
        && det * det + den * den >= SOLID_ANGLE_CONDITION * SOLID_ANGLE_CONDITION
    {
        return 2.0 * det.atan2(den);
    }
    let units = r.map(unit_dd);
    let [a, b, c] = &units;
    let det = dot3(a, &cross_dd(b, c)).value();
    let den = (DoubleDouble::from_f64(1.0) + dot3(a, b) + dot3(b, c) + dot3(c, a)).value();
    let sign = if det.abs() > DD_TRIPLE_PRODUCT_ROUNDING {
        if det > 0.0 { 1 } else { -1 }
    } else {
        exact_orientation_sign(q, p)
    };
    if sign == 0 {
        return 0.0;
    }
    if det * det + den * den < NEAR_EDGE_SOLID_ANGLE * NEAR_EDGE_SOLID_ANGLE {
        // The edge the query is next to: the pair of corners seen most nearly opposite. Its
        // corners in cyclic order, so the triple product keeps its sign.
        let [i, j, k] = [[0, 1, 2], [1, 2, 0], [2, 0, 1]]
            .into_iter()
            .min_by(|x, y| {
                let opposite = |[i, j, _]: [usize; 3]| dot3(&units[i], &units[j]).value();
                opposite(*x).total_cmp(&opposite(*y))
            })
            .unwrap_or([0, 1, 2]);
        if let Some((det, den)) = solid_angle_next_to_edge(p[i], p[j], p[k], q) {
            return signed_double_atan2(sign, det.abs(), den);
        }
    }
    signed_double_atan2(sign, det.abs(), den)
}

/// Below this `√(det² + den²)` (unit vectors, double-double) the query is within `~2^-40` of an
/// edge's length from its interior: double-double keeps `~106 − 40` bits there, and fewer
/// closer in (a query `1e-300` from an edge of the unit cube got `w = −0.25` for `0`), so the
/// triangle takes [`solid_angle_next_to_edge`].
const NEAR_EDGE_SOLID_ANGLE: f64 = 1.0 / (1u64 << 40) as f64;

/// `(det, den)` of `tan(Ω/2) = det/den` for the triangle `pa pb pc` seen from `q` next to the
/// interior of its edge `pa pb` (world points), both divided by one positive factor; `None` when
/// `q` is on the edge's line.
///
/// Van Oosterom–Strackee on the offsets `a, b, c` from `q`: `det = a·(b×c) = c·m` with the exact
/// moment `m = a × b`, and `den = |a||b||c| + (a·b)|c| + (b·c)|a| + (c·a)|b|`, where
/// `|a||b| + a·b` and `|a| b + |b| a` cancel to the query's angle from the edge. With `e = b − a`,
/// `t = −(a·e)/|e|²` (so `1 − t = (b·e)/|e|²`) and `a⊥ = a + t e = (e × m)/|e|²` (the offset
/// across the edge): `|a||b| + a·b = |m|²/(|a||b| − a·b)`, and `|a| b + |b| a = X e + (|a| +
/// |b|) a⊥` with `X = |a|(1 − t) − |b| t = |a⊥|²(1 − 2t)/(|a|(1 − t) + |b| t)`, `|a⊥|² =
/// |m|²/|e|²`. So
/// `den = (c·(e × m))(|a| + |b|)/|e|² + |m|²(|c|/(|a||b| − a·b) + (c·e)(b·e + a·e)/(|e|²(|a|(b·e) − |b|(a·e))))`:
/// every remaining difference is of two positive terms (`a`, `b` nearly opposite make
/// `a·b, a·e < 0 < b·e`), and the first-order term and `det` carry the exact moment's relative
/// accuracy at any distance.
#[cold]
fn solid_angle_next_to_edge(
    pa: [f64; 3],
    pb: [f64; 3],
    pc: [f64; 3],
    q: [f64; 3],
) -> Option<(f64, f64)> {
    let (m, mk) = exact_moment_of_points(q, pa, pb)?;
    let diff = |p: [f64; 3], o: [f64; 3]| -> [DoubleDouble; 3] {
        std::array::from_fn(|k| DoubleDouble::diff(p[k], o[k]))
    };
    let (a, b, c, e) = (diff(pa, q), diff(pb, q), diff(pc, q), diff(pb, pa));
    // `det` and `den` are of degree 2 in `(a, b, e, m^½)` jointly and 1 in `c`: each group is
    // brought to unit size by its own power of two (exact), `m` by twice the first.
    let largest = |vs: &[&[DoubleDouble; 3]]| {
        vs.iter()
            .flat_map(|v| v.iter())
            .fold(0.0_f64, |x, c| x.max(c.hi.abs()))
    };
    let s1 = -i64::from(binary_exponent(largest(&[&a, &b, &e])));
    let s2 = -i64::from(binary_exponent(largest(&[&c])));
    let scaled = |v: [DoubleDouble; 3], s: i64| v.map(|x| times_power_of_two(x, s));
    let (a, b, e, c) = (scaled(a, s1), scaled(b, s1), scaled(e, s1), scaled(c, s2));
    let (la, lb, lc) = (length_dd(&a), length_dd(&b), length_dd(&c));
    let ee = dot3(&e, &e);
    let first = dot3(&c, &cross_dd(&e, &m)) * (la + lb) / ee;
    // The second-order terms divide by the nearer end's distance, which may be `2^-1000` of the
    // edge (a query next to a vertex, beside the edge): the nearer offset and its length are
    // brought to unit size by `2^σ` before any product, and `2^σ` joins the moment's `2^k`.
    let (ae, be) = (dot3(&a, &e), dot3(&b, &e));
    let a_is_nearer = la.hi <= lb.hi;
    let sigma = -i64::from(binary_exponent(if a_is_nearer { la.hi } else { lb.hi }));
    // `(|a||b| − a·b)·2^σ` and `(|a|(b·e) − |b|(a·e))·2^σ` (a subnormal offset's length taken
    // after the scaling, where it has all its bits).
    let (d1, d2) = if a_is_nearer {
        let a_up = scaled(a, sigma);
        let la_up = length_dd(&a_up);
        (
            la_up * lb - dot3(&a_up, &b),
            la_up * be - lb * dot3(&a_up, &e),
        )
    } else {
        let b_up = scaled(b, sigma);
        let lb_up = length_dd(&b_up);
        (
            la * lb_up - dot3(&a, &b_up),
            la * dot3(&b_up, &e) - lb_up * ae,
        )
    };
    let second = dot3(&m, &m) * (lc / d1 + dot3(&c, &e) * (be + ae) / (ee * d2));
    // Summed in double-double: for a sliver (`c` near the edge's line too) the two parts cancel.
    let den = (first + times_power_of_two(second, mk + 2 * s1 + sigma)).value();
    Some((dot3(&c, &m).value(), den))
}

/// `|v|` in double-double, `v` scaled by a power of two first (no under- or overflow of the
/// squares).
fn length_dd(v: &[DoubleDouble; 3]) -> DoubleDouble {
    let s = power_of_two_scale(v[0].hi.abs().max(v[1].hi.abs()).max(v[2].hi.abs()));
    let w = v.map(|c| DoubleDouble {
        hi: c.hi * s[0] * s[1],
        lo: c.lo * s[0] * s[1],
    });
    let len = dot3(&w, &w).sqrt();
    DoubleDouble {
        hi: len.hi / s[0] / s[1],
        lo: len.lo / s[0] / s[1],
    }
}

/// `v/|v|`, scaled by a power of two first when needed so that `|v|²` neither overflows nor
/// underflows.
#[inline]
fn unit(v: [f64; 3]) -> [f64; 3] {
    let m = v[0].abs().max(v[1].abs()).max(v[2].abs());
    if (MODERATE_LO..=MODERATE_HI).contains(&m) {
        return normalized(v);
    }
    let s = power_of_two_scale(m);
    normalized(v.map(|c| c * s[0] * s[1]))
}

/// Magnitudes between which products of three offset components stay normal `f64`s.
const MODERATE_LO: f64 = 1e-90;
const MODERATE_HI: f64 = 1e90;

/// The range of `|r|²` in which the textbook solid angle ([`solid_angle_moderate`], and the fast
/// method's lanes that copy it) runs: the squared norms of offsets in `[MODERATE_LO, MODERATE_HI]`,
/// so that `|a||b||c|` and the triple product neither overflow nor lose bits to subnormals.
pub(crate) const SQUARED_NORM_LO: f64 = MODERATE_LO * MODERATE_LO;
/// Upper end of the range of [`SQUARED_NORM_LO`].
pub(crate) const SQUARED_NORM_HI: f64 = MODERATE_HI * MODERATE_HI;

/// `|det| ≤ ZERO_AREA_SUSPECT·|a||b||c|` (relative to the unit vectors' scale) sends a triangle to
/// the exact zero-area test before its `atan2`. Why a relative threshold: a collinear triangle
/// has `det = 0` exactly, but rounding leaves `|det| ≲ 10u·|a||b||c|` (`u = 2^-53`: three
/// rounded products and two sums in the triple product, each relative `u` of the permanent,
/// which is `≤ 3|a||b||c|`), i.e. `≲ 1.1e-15`; `1e-12` is a thousand times that, so every
/// rounding-born `det` of a degenerate triangle is tested, while a genuine triangle seen at a
/// normal angle never pays the test.
pub(crate) const ZERO_AREA_SUSPECT: f64 = 1e-12;

/// [`unit`] in double-double.
fn unit_dd(v: [DoubleDouble; 3]) -> [DoubleDouble; 3] {
    let s = power_of_two_scale(v[0].hi.abs().max(v[1].hi.abs()).max(v[2].hi.abs()));
    let v = v.map(|c| DoubleDouble {
        hi: c.hi * s[0] * s[1],
        lo: c.lo * s[0] * s[1],
    });
    let len = dot3(&v, &v).sqrt();
    v.map(|c| c / len)
}

/// Two powers of two whose product brings `m > 0` to `[1, 2)` (`[1, 1]` for `m = 0`).
#[inline]
fn power_of_two_scale(m: f64) -> [f64; 2] {
    if m == 0.0 || !m.is_finite() {
        return [1.0, 1.0];
    }
    let e = if m >= f64::MIN_POSITIVE {
        ((m.to_bits() >> 52) & 0x7ff) as i32 - 1023
    } else {
        // Subnormal: exponent from the leading bit of the significand.
        -1023 - (m.to_bits().leading_zeros() as i32 - 12)
    };
    let half = -e / 2;
    let pow = |k: i32| f64::from_bits(((k + 1023) as u64) << 52);
    [pow(half), pow(-e - half)]
}

/// What the exact predicates established about one boundary edge `a → b` relative to the
/// symbolically perturbed query `q_ε = q + (ε1, ε2, ε3)`, `ε3 ≪ ε2 ≪ ε1`, with the ray along `+z`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct EdgeSigns {
    /// Exact sign of the numerator `x1·(A×B) = −(A×B)_z` at `q_ε`: minus the perturbed 2D
    /// orientation of `(a − q_ε, b − q_ε)` (the same predicate the crossing test uses). Zero
    /// only for edges parallel to the ray.
    pub numerator: i32,
    /// `q_ε` lies strictly inside the segment to first order (exact collinearity), so `A` and
    /// `B` are antipodal and the area is a limit.
    pub query_inside_segment: bool,
    /// When `A`, `B` and `x1` lie on one great circle — `q`, `a`, `b` collinear seen along the
    /// ray, neither end at `q` or on its vertical line, `q_ε` not inside the segment — the exact
    /// sign of the denominator, which alone decides the term: `0` when it is positive, `±2π`
    /// when negative (the numerator is `0⁺` with the perturbation's sign). `0` otherwise. A
    /// rounded denominator decided it before, and lost its sign where the segment passes the
    /// ray line within `2^-104` of its length from `q` (`w` off by `0.5` on one ray).
    pub flat_denominator: i32,
}

/// The Antipodal method's term for one boundary edge (before the weight and the `1/4π`):
/// the signed area of the spherical triangle `(A, B, x1)`, `A = (a−q)/|a−q|`, `B` likewise,
/// `x1 = −z` (the antipode of the ray direction).
///
/// `ra = a − q`, `rb = b − q` are in the ray frame and must be exactly zero in a component
/// exactly when the quantized coordinates agree (the callers build them from exact integer
/// differences). The degenerate configurations take the limit at `q_ε`:
/// - `a == q`: `A = −x̂` (the direction from `q_ε` back to `a`);
/// - `a` on the ray (`ra_xy = 0`, `ra_z > 0`): `Area = 2·atan2(B_y, −B_x)` (first order in ε);
/// - `q_ε` inside the segment: `Area = 2·atan2(x1·(u×p), −x1·p)`, `u` the edge direction and
///   `p` the direction of the perturbation perpendicular to it.
///
/// In each case the magnitude comes from floating point and the branch from `signs.numerator`.
pub fn antipodal_edge_area(ra: [f64; 3], rb: [f64; 3], signs: EdgeSigns) -> f64 {
    let s = signs.numerator;
    if s == 0 {
        // Edge parallel to the ray: A, B and x1 lie on one great half-circle; area 0.
        return 0.0;
    }
    if signs.flat_denominator != 0 {
        return signed_double_atan2(s, 0.0, f64::from(signs.flat_denominator));
    }
    if signs.query_inside_segment {
        let u = normalized([rb[0] - ra[0], rb[1] - ra[1], rb[2] - ra[2]]);
        // Dominant perpendicular part of (ε1, ε2, ε3): e1 − (u·e1)u = (u_y² + u_z², −u_x u_y,
        // −u_x u_z), or e2 when u = ±e1. Divided by h = max(|u_y|, |u_z|) before normalizing:
        // for an edge 1e-234 off the x axis its squares underflowed, |p| was 0 and the term NaN.
        let h = u[1].abs().max(u[2].abs());
        let p = if h == 0.0 {
            [0.0, 1.0, 0.0]
        } else {
            let (y, z) = (u[1] / h, u[2] / h);
            normalized([h * (y * y + z * z), -u[0] * y, -u[0] * z])
        };
        let n = -(u[0] * p[1] - u[1] * p[0]);
        return signed_double_atan2(s, n.abs(), p[2]);
    }
    let a_on_ray = ra[0] == 0.0 && ra[1] == 0.0 && ra[2] > 0.0;
    let b_on_ray = rb[0] == 0.0 && rb[1] == 0.0 && rb[2] > 0.0;
    let a_dir = limit_direction(ra);
    let b_dir = limit_direction(rb);
    if a_on_ray {
        return signed_double_atan2(s, b_dir[1].abs(), -b_dir[0]);
    }
    if b_on_ray {
        return signed_double_atan2(s, a_dir[1].abs(), -a_dir[0]);
    }
    if let Some(other) = other_end_of_edge_at_query(&ra, &rb) {
        let r = if other == 0 { ra } else { rb };
        let (n, den) = edge_at_query_arguments(&r.map(DoubleDouble::from_f64));
        return signed_double_atan2(s, n, den);
    }
    // Generic case, with unit A, B and x1 = −z:
    //   n = −(A × B)_z,   den = 1 + A·B − A_z − B_z = (1 − A_z)(1 − B_z) + A_x B_x + A_y B_y,
    // where 1 − A_z is evaluated without cancellation (len_minus_z).
    let (ra, la) = if ra == [0.0; 3] {
        ([-1.0, 0.0, 0.0], 1.0)
    } else {
        (ra, norm(ra))
    };
    let (rb, lb) = if rb == [0.0; 3] {
        ([-1.0, 0.0, 0.0], 1.0)
    } else {
        (rb, norm(rb))
    };
    let n = ra[0] * rb[1] - ra[1] * rb[0];
    let den = len_minus_z(ra, la) * len_minus_z(rb, lb) + ra[0] * rb[0] + ra[1] * rb[1];
    signed_double_atan2(s, n.abs(), den)
}

/// [`antipodal_edge_area`] with the offsets given exactly as double-doubles (`a − q − r` from the
/// integer lattice and the query's residual), for the edges the `f64` loop cannot serve to 1e-12:
/// the query within a small fraction of the edge's length from the edge, where both `atan2`
/// arguments cancel (`|n|, den ≈ |a−q||b−q|·θ` with `θ ≈ distance/length`, so `f64` loses
/// `log2(1/θ)` bits; double-double keeps ~106 − log2(1/θ)). The degenerate limits (exact zero
/// components) are directions only and take the `f64` formulas.
///
/// A query within [`NEAR_SEGMENT_ANGLE`] of the segment's interior loses every bit even there
/// (a query `1e-30` from an edge of a unit triangle erred by `1e-4`; `1e-300` from it, by
/// `0.125`, and differently on every ray). Where this formula's own error bound says so, the
/// term comes from the expansion in that angle ([`near_segment_area`]) instead, with
/// `exact_moment` giving `ra × rb` exactly ([`super::input_predicates::exact_edge_moment`];
/// `None` when the query is on the edge's line, or when it cannot be computed), whichever of the
/// two has the smaller error bound.
pub fn antipodal_edge_area_accurate(
    ra: [DoubleDouble; 3],
    rb: [DoubleDouble; 3],
    signs: EdgeSigns,
    exact_moment: impl FnOnce() -> Option<([DoubleDouble; 3], i64)>,
) -> f64 {
    // The term depends on the directions of `ra` and `rb` only (numerator and denominator are
    // both homogeneous of degree 1 in each): scaled by powers of two to unit size, offsets of
    // `1e-300` (a query next to a boundary vertex) neither underflow their squares nor lose the
    // formula's bits (issue 21: the open box returned 0.875 for 0.5 below ~1e-172).
    if signs.flat_denominator != 0 {
        return signed_double_atan2(signs.numerator, 0.0, f64::from(signs.flat_denominator));
    }
    let offsets = (ra, rb);
    let (ra, rb) = unit_scaled(ra, rb);
    let hi = |r: &[DoubleDouble; 3]| r.map(|c| c.hi);
    let (fa, fb) = (hi(&ra), hi(&rb));
    let degenerate = signs.numerator == 0
        || signs.query_inside_segment
        || fa == [0.0; 3]
        || fb == [0.0; 3]
        || (fa[0] == 0.0 && fa[1] == 0.0)
        || (fb[0] == 0.0 && fb[1] == 0.0);
    if signs.numerator != 0
        && !signs.query_inside_segment
        && let Some(other) = other_end_of_edge_at_query(&fa, &fb)
    {
        let r = if other == 0 { &ra } else { &rb };
        let (n, den) = edge_at_query_arguments(r);
        return signed_double_atan2(signs.numerator, n, den);
    }
    if degenerate {
        return antipodal_edge_area(fa, fb, signs);
    }
    let la = dot3(&ra, &ra).sqrt();
    let lb = dot3(&rb, &rb).sqrt();
    let len_minus_z = |r: &[DoubleDouble; 3], len: DoubleDouble| {
        if r[2].hi > 0.0 {
            (r[0] * r[0] + r[1] * r[1]) / (len + r[2])
        } else {
            len - r[2]
        }
    };
    let (n0, n1) = (ra[0] * rb[1], ra[1] * rb[0]);
    let lengths = len_minus_z(&ra, la) * len_minus_z(&rb, lb);
    let (d0, d1) = (ra[0] * rb[0], ra[1] * rb[1]);
    let (n, den) = ((n0 - n1).value(), (lengths + d0 + d1).value());
    // Both arguments are sums of products of the (exact, unit-scaled) offsets, each rounded by
    // far less than DD_TERM_ROUNDING; where they cancel (the query near the segment's interior)
    // the result can be worse than the expansion of `near_segment_area`, which is then taken.
    let error = DD_TERM_ROUNDING
        * (n0.hi.abs() + n1.hi.abs() + lengths.hi.abs() + d0.hi.abs() + d1.hi.abs())
        + f64::MIN_POSITIVE;
    // Relative errors compared as quotients: both sides of the cross-multiplied form underflowed
    // to 0 for a query 2^-409 from a unit edge 2^-326 off the ray (the near term erred by 1e-55
    // of itself, the double-double one by 4e-7; `0 < 0` kept the latter, 1.2e-9 off in w).
    let relative =
        |error: f64, numerator: f64, denominator: f64| error / numerator.hypot(denominator);
    if error > WELL_CONDITIONED * n.hypot(den)
        && let Some(near) = near_segment_area((&ra, &rb), (&offsets.0, &offsets.1), exact_moment)
        && relative(near.error, near.numerator, near.denominator) < relative(error, n, den)
    {
        return signed_double_atan2(signs.numerator, near.numerator, near.denominator);
    }
    signed_double_atan2(signs.numerator, n.abs(), den)
}

/// A bound on the relative rounding of one double-double product or sum of the edge term's
/// offsets (`2^-104` each, a few of them in a row), with margin: `2^-100`.
const DD_TERM_ROUNDING: f64 = 1.0 / (1u128 << 100) as f64;

/// The relative error of the double-double edge term above which the near-segment expansion is
/// tried (`2^-50`: below it the term is as good as `f64` can hold).
const WELL_CONDITIONED: f64 = 1.0 / (1u64 << 50) as f64;

/// The `atan2` arguments of [`near_segment_area`] (magnitude of the numerator, denominator) and
/// a bound on the error of the denominator, in the same units.
struct NearSegmentTerm {
    numerator: f64,
    denominator: f64,
    error: f64,
}

/// The angle (radians, `2^-56`) between a query and the segment it projects inside of, below
/// which an edge term may come from [`near_segment_area`]. Above it the double-double formula
/// keeps at least `106 − 60` bits (its offsets are unit-scaled, so `|ra × rb| ≥ sin θ`, and it
/// loses `log2(1/θ)` bits to cancellation); below it the expansion errs by `O(θ²)`.
pub const NEAR_SEGMENT_ANGLE: f64 = 1.0 / (1u64 << 56) as f64;

/// The term of a query within [`NEAR_SEGMENT_ANGLE`] of the interior of the segment (`scaled`:
/// the unit-scaled offsets, nearly antiparallel; `offsets`: the same unscaled, cells) as `atan2`
/// arguments with an error bound, or `None` when it is farther (or `exact_moment` has no answer).
///
/// With `u` the segment's direction, `p` the unit offset of the query from the segment's line and
/// `d` its distance, `ra = α·u − d·p`, `rb = β·u − d·p` (`α < 0 < β`), so `m = ra × rb = (β − α)·
/// d·(u × p)` exactly and `p = (m × u)/|m|`. Expanding `|ra|`, `|rb|` in `d` and dividing both
/// `atan2` arguments by `(β − α)·d`:
///
/// `Area = 2·atan2(|m_z|/|m|, p_z + d·K)`, `K = ((β − α) − u_z·(β + α)) / (2|α|β)`,
///
/// to `O(θ²)` (`θ ≈ d/min(|α|, β)`; `K ≤ 1/min(|α|, β)`), branch from the exact numerator sign.
/// As `d → 0` it is the inside-segment limit of [`antipodal_edge_area`] with the query's own `p`
/// for the perturbation's; the `d·K` term decides it where `p_z` vanishes (an offset across the
/// ray: the plain limit gave `−0.75` for a value in `[−0.5, 0]`). Where the ray from the query
/// also grazes the edge's line, `p_z` and `d·K` cancel, and the numerator is tiny too: both come
/// from the exact `m` in double-double (in `f64` that case erred by `2·10⁻⁸`). Where the ray
/// passes within `~10⁻⁴²` rad of an endpoint as well, even double-double cannot hold their
/// difference, and the caller keeps its own formula, whose terms are then that small too.
fn near_segment_area(
    scaled: (&[DoubleDouble; 3], &[DoubleDouble; 3]),
    offsets: (&[DoubleDouble; 3], &[DoubleDouble; 3]),
    exact_moment: impl FnOnce() -> Option<([DoubleDouble; 3], i64)>,
) -> Option<NearSegmentTerm> {
    let (ra, rb) = scaled;
    let (fa, fb) = (ra.map(|c| c.hi), rb.map(|c| c.hi));
    if dot(fa, fb) >= 0.0 {
        return None;
    }
    // A cheap screen in `f64` (its cross product errs by ~2^-50 here), then double-double.
    let largest = |m: [f64; 3]| m[0].abs().max(m[1].abs()).max(m[2].abs());
    if largest(cross(fa, fb)) > 1e-12 {
        return None;
    }
    if largest(cross_dd(ra, rb).map(|c| c.hi)) > NEAR_SEGMENT_ANGLE {
        return None;
    }
    let (m, exponent) = exact_moment()?;
    // Every length carries its own power of two (`Wide`): the edge can be `1e-166` cells long
    // (its `|e|²` underflowed to 0 and dropped the expansion: `−π` for a term near 0), and one
    // end can be `2^-1100` of the edge from the query (in the edge's units that end's `β`
    // underflowed to 0 and dropped it: `0.225` for `0` in `w`, an edge `1e15` long with the
    // query `5e-324` from its end). Only sums align their terms, where a part that underflows
    // is below the other's rounding.
    let e: [DoubleDouble; 3] = std::array::from_fn(|k| offsets.1[k] - offsets.0[k]);
    let (u, le) = Wide::split(&e)?;
    let (alpha, beta) = (Wide::along(offsets.0, &u)?, Wide::along(offsets.1, &u)?);
    if !(alpha.mantissa.hi < 0.0 && beta.mantissa.hi > 0.0) {
        return None;
    }
    let alpha = alpha.negated();
    let lm = Wide {
        mantissa: dot3(&m, &m).sqrt(),
        exponent,
    };
    let pz = cross_dd(&m, &u)[2] / lm.mantissa;
    // `(β − α) − u_z·(β + α) = β·(1 − u_z) + |α|·(1 + u_z)`: two terms ≥ 0, no cancellation
    // (`1 ∓ u_z` from `u_x² + u_y²` where it is small: an edge along the ray).
    let across = u[0] * u[0] + u[1] * u[1];
    let one = DoubleDouble::from_f64(1.0);
    let (below, above) = if u[2].hi > 0.0 {
        (across / (one + u[2]), one + u[2])
    } else {
        (one - u[2], across / (one - u[2]))
    };
    let near_end = alpha.min(beta);
    // d·K = |m|·(β(1 − u_z) + |α|(1 + u_z)) / ((β + |α|)·2|α|β) and θ = |m|/(|e|·min(|α|, β)),
    // scaled once at the end: next to an endpoint `|α|` can be `2^-1000` of the edge and `|m|`
    // `2^-1100`, where double-double overflowed to NaN (`K ~ 1e300`) and the expansion was
    // dropped (`0` for a term of `2π`).
    let weighted = beta.times(below).plus(alpha.times(above));
    let dk = lm
        .product(weighted)
        .quotient(
            beta.plus(alpha)
                .product(alpha)
                .product(beta)
                .times(DoubleDouble::from_f64(2.0)),
        )
        .value()?;
    let theta = lm
        .quotient(le.product(near_end))
        .value()
        .map_or(f64::INFINITY, |t| t.hi);
    let lm = lm.mantissa;
    let n = (m[2] / lm).hi.abs();
    let denominator = (pz + dk).value();
    let (pz, dk) = (pz.hi, dk.hi);
    Some(NearSegmentTerm {
        numerator: n,
        denominator,
        error: DD_TERM_ROUNDING * (pz.abs() + dk.abs())
            + 4.0 * theta * theta * (pz.abs() + 2.0 * theta),
    })
}

/// A double-double with its own power of two, `mantissa·2^exponent`, for the lengths of
/// [`near_segment_area`]: their ratios span more than the `f64` exponent range (an end
/// `2^-1100` of its edge from the query), so products and quotients keep mantissas in `[1, 2)`
/// and add exponents, and only the final value is scaled (rounded into the subnormals there).
#[derive(Clone, Copy, Debug)]
struct Wide {
    mantissa: DoubleDouble,
    exponent: i64,
}

impl Wide {
    /// Zero, with an exponent below every other so that a sum aligns to the other term.
    const ZERO: Wide = Wide {
        mantissa: DoubleDouble { hi: 0.0, lo: 0.0 },
        exponent: i64::MIN / 4,
    };

    /// `v·2^e` with the mantissa brought to `[1, 2)`; `None` for zero or a non-finite `v`.
    fn normalized(v: DoubleDouble, e: i64) -> Option<Wide> {
        if v.hi == 0.0 || !v.hi.is_finite() {
            return None;
        }
        let k = i64::from(binary_exponent(v.hi));
        Some(Wide {
            mantissa: times_power_of_two(v, -k),
            exponent: e + k,
        })
    }

    /// `v` as `w·2^k` with `w`'s largest component in `[1, 2)`; `None` for a zero or
    /// non-finite vector.
    fn scaled_to_unit(v: &[DoubleDouble; 3]) -> Option<([DoubleDouble; 3], i64)> {
        let top = v.iter().fold(0.0_f64, |m, c| m.max(c.hi.abs()));
        if top == 0.0 || !top.is_finite() {
            return None;
        }
        let k = i64::from(binary_exponent(top));
        Some((v.map(|c| times_power_of_two(c, -k)), k))
    }

    /// A vector's direction and its length.
    fn split(v: &[DoubleDouble; 3]) -> Option<([DoubleDouble; 3], Wide)> {
        let (v, k) = Wide::scaled_to_unit(v)?;
        let length = dot3(&v, &v).sqrt();
        Some((v.map(|c| c / length), Wide::normalized(length, k)?))
    }

    /// `v·u` for the unit vector `u`.
    fn along(v: &[DoubleDouble; 3], u: &[DoubleDouble; 3]) -> Option<Wide> {
        let (v, k) = Wide::scaled_to_unit(v)?;
        Wide::normalized(dot3(&v, u), k)
    }

    fn negated(self) -> Wide {
        Wide {
            mantissa: -self.mantissa,
            exponent: self.exponent,
        }
    }

    fn product(self, o: Wide) -> Wide {
        let p = self.mantissa * o.mantissa;
        Wide::normalized(p, self.exponent + o.exponent).unwrap_or(Wide::ZERO)
    }

    fn quotient(self, o: Wide) -> Wide {
        let q = self.mantissa / o.mantissa;
        Wide::normalized(q, self.exponent - o.exponent).unwrap_or(Wide::ZERO)
    }

    /// `self·f` for a double-double factor `f ≥ 0` of moderate size (zero stays zero).
    fn times(self, f: DoubleDouble) -> Wide {
        let p = self.mantissa * f;
        Wide::normalized(p, self.exponent).unwrap_or(Wide::ZERO)
    }

    /// The sum of two values `≥ 0`, aligned to the larger exponent (the smaller term's bits
    /// below its rounding may underflow).
    fn plus(self, o: Wide) -> Wide {
        let e = self.exponent.max(o.exponent);
        let sum = times_power_of_two(self.mantissa, self.exponent - e)
            + times_power_of_two(o.mantissa, o.exponent - e);
        Wide::normalized(sum, e).unwrap_or(Wide::ZERO)
    }

    /// The smaller of two positive values.
    fn min(self, o: Wide) -> Wide {
        let smaller = if self.exponent != o.exponent {
            self.exponent < o.exponent
        } else {
            self.mantissa.hi < o.mantissa.hi
        };
        if smaller { self } else { o }
    }

    /// The value as a double-double (rounded into the subnormals or to 0 below them); `None`
    /// when it overflows.
    fn value(self) -> Option<DoubleDouble> {
        let v = times_power_of_two(self.mantissa, self.exponent);
        v.hi.is_finite().then_some(v)
    }
}

/// `a × b` in double-double.
fn cross_dd(a: &[DoubleDouble; 3], b: &[DoubleDouble; 3]) -> [DoubleDouble; 3] {
    [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ]
}

/// `∇_q` of the solid-angle contribution of the directed segment from `q + ra` to `q + rb`:
/// `(ra × rb)(|ra| + |rb|) / (|ra||rb|(|ra||rb| + ra·rb))` (Biot–Savart for a straight segment),
/// shared by every evaluator's gradient.
///
/// The gradient of a surface's solid angle depends only on its boundary, so summing this over
/// the signed boundary edges (a cycle) gives `4π ∇w`. The exact evaluator uses it instead of the
/// antipodal paper's Supp. Alg. 3, which differentiates `Area(A, B, x1)` and so divides by
/// quantities that vanish when a boundary vertex is seen near the ray direction. Below an open
/// mesh, along the ray, its x and y components were off by 2e-3 (relative) at 100 mesh sizes
/// (`tests/exact/gradient.rs`), and garbage from ~1e6 (−19.6 where the true value is 7.6e-27, bundled
/// lion head), while this form stays accurate to ~1e-9 relative.
/// Not finite when `q` is on the segment; within [`NEAR_SEGMENT_GRADIENT`] of its interior the
/// offsets' rounding decides `ra × rb` (see [`segment_gradient_with_moment`]), and
/// `|ra||rb| + ra·rb` cancels from [`TEXTBOOK_GRADIENT_MIN`] on (see
/// [`segment_gradient_careful`]).
#[inline]
pub fn segment_gradient(ra: [f64; 3], rb: [f64; 3]) -> [f64; 3] {
    segment_gradient_with_moment(ra, rb, || None)
}

/// Below this `1 + cos∠(ra, rb)` the textbook form's denominator `|ra||rb| + ra·rb =
/// |ra||rb|(1 + cos)` has cancelled by more than 24 bits: its rounding (`≲ 5u·|ra||rb|`, `u =
/// 2^-53`) is then above `6e-10` of it, so the term takes `|ra × rb|²/(|ra||rb| − ra·rb)`
/// instead. Measured: 3.5e-5 relative error at `1 + cos = 4e-12`, a query `1e-9` from a
/// boundary edge of cgal-blobby-shuffled (docs/benchmarks.md).
const TEXTBOOK_GRADIENT_MIN: f64 = 1.0 / (1u64 << 24) as f64;

/// Below this `1 + cos∠(ra, rb)` (`≈ sin²/2`: the query within `2^-20` radians of the
/// segment's interior, seen from its ends) the cross product of offsets rounded once has lost
/// more than `2^-32` of its relative accuracy (its error is `~2u` against `sin`), so
/// [`segment_gradient_with_moment`] takes the exact one.
pub const NEAR_SEGMENT_GRADIENT: f64 = 1.0 / (1u64 << 41) as f64;

/// [`segment_gradient`] with `exact_moment` giving `ra × rb` exactly as `(m, k)`, the vector
/// `m·2^k` in the units of `ra` and `rb` (`m`'s largest component in `[1, 2)`; `None` when the
/// query is on the segment's line, or when it cannot be computed), called only where the query
/// is within [`NEAR_SEGMENT_GRADIENT`] of the segment's interior. There both offsets are nearly
/// antiparallel and every product of `ra × rb` cancels to the angle: from offsets rounded once
/// the term was NaN within `~1e-16` of an edge's length (the rounded offsets exactly
/// antiparallel) and pointed the wrong way a little farther. With `|ra||rb| + ra·rb =
/// |ra × rb|²/(|ra||rb| − ra·rb)` the term is `(ra × rb)/|ra × rb|² · (|ra| + |rb|)(1 − â·b̂)`,
/// whose only cancelling factor is the exact moment.
#[inline]
pub fn segment_gradient_with_moment(
    ra: [f64; 3],
    rb: [f64; 3],
    exact_moment: impl FnOnce() -> Option<([DoubleDouble; 3], i64)>,
) -> [f64; 3] {
    let la = norm(ra);
    let lb = norm(rb);
    let c = cross(ra, rb);
    let p = la * lb;
    let den = p * (p + dot(ra, rb));
    // Past the range of normal f64 (an offset below ~1e-77 or above ~1e77 of the other's
    // scale), or `1 + cos` cancelled (the query near the segment's interior): the careful
    // forms. The range branch costs 5–9 % of the gradient of a mesh whose every edge is a
    // boundary edge (docs/benchmarks.md).
    if !(f64::MIN_POSITIVE..f64::INFINITY).contains(&den) || den < p * p * TEXTBOOK_GRADIENT_MIN {
        return segment_gradient_careful(ra, rb, exact_moment);
    }
    let f = (la + lb) / den;
    [c[0] * f, c[1] * f, c[2] * f]
}

/// [`segment_gradient`] as `(â×b̂)/(1 + â·b̂)·(1/|ra| + 1/|rb|)`, each offset brought to unit
/// length by its own power of two, where the textbook form fails: a query `1e-268` from a vertex
/// of an edge of length 1 made `|ra||rb|(|ra||rb| + ra·rb)` underflow to 0, and the gradient
/// was NaN (a third of the off-surface queries next to mixed-magnitude edges); `1 + â·b̂` is
/// `|â×b̂|²/(1 − â·b̂)` where `â·b̂ < 0`, as in the textbook form, and `â × b̂` the exact moment's
/// direction next to the segment's interior ([`segment_gradient_with_moment`]). Overflows to
/// `±∞` only where the gradient does; NaN only with an end at the query, or on the segment (or
/// within rounding of it when no exact moment is given).
#[cold]
fn segment_gradient_careful(
    ra: [f64; 3],
    rb: [f64; 3],
    exact_moment: impl FnOnce() -> Option<([DoubleDouble; 3], i64)>,
) -> [f64; 3] {
    let (Some((a, la)), Some((b, lb))) = (direction_and_length(ra), direction_and_length(rb))
    else {
        return [f64::NAN; 3];
    };
    let d = dot(a, b);
    // A zero component stays zero when the scale overflows (not 0·∞).
    let times = |v: [f64; 3], s: f64| v.map(|x| if x == 0.0 { 0.0 } else { x * s });
    if 1.0 + d < NEAR_SEGMENT_GRADIENT
        && let Some((m, k)) = exact_moment()
    {
        let m = m.map(|x| x.hi);
        let lm = norm(m);
        // `|ra × rb| = lm·2^k`; the factor before the power of two is within `[2^-2, 2^3]`
        // of the lengths' sum, so only the power of two can overflow (where the gradient does).
        let f = (la + lb) * (1.0 - d) / (lm * lm);
        return m.map(|x| scaled_by_power_of_two(x * f, -k));
    }
    let c = cross(a, b);
    let (direction, magnitude) = if d >= 0.0 {
        (c, 1.0 / (1.0 + d))
    } else {
        match direction_and_length(c) {
            Some((u, lc)) => (u, (1.0 - d) / lc),
            None => return [f64::NAN; 3],
        }
    };
    times(direction, magnitude * (1.0 / la + 1.0 / lb))
}

/// `(v/|v|, |v|)`, `v` scaled by a power of two before its norm (no under- or overflow of the
/// squares); `None` for a zero or non-finite `v`.
fn direction_and_length(v: [f64; 3]) -> Option<([f64; 3], f64)> {
    let m = v[0].abs().max(v[1].abs()).max(v[2].abs());
    if m == 0.0 || !m.is_finite() {
        return None;
    }
    let s = power_of_two_scale(m);
    let w = v.map(|c| c * s[0] * s[1]);
    let l = norm(w);
    Some((w.map(|c| c / l), l / s[0] / s[1]))
}

/// `ra` and `rb`, each times the power of two that brings its largest component into `[1, 2)`
/// (exact; unchanged when zero or not finite): the edge term depends on their directions only.
///
/// Their transverse parts `r_xy` are scaled up further where their products would underflow
/// below `2^-1022` (a vertex seen almost exactly along the ray):
/// - **One offset near the ray** (`|r_xy| ≪ |r|`, the other not): the term depends on the
///   azimuth of its `r_xy` (the on-ray limit of §3 of docs/robustness.md, with the actual
///   direction instead of the perturbation's), so its `r_xy` is scaled out to `2^-500·|r|`
///   ([`NEAR_RAY_FLOOR_EXPONENT`]) along its own azimuth: the term moves by about that angle
///   over the other's angle from the ray, `2^-400` at most (below).
/// - **Both near the ray line**, not both below the query (an edge nearly along the ray,
///   passing near the query): then the term depends on how their transverse parts compare, not
///   on their azimuths alone, and scaling each out to the floor on its own replaced their ratio
///   by 1 (a query `3e-260` beside an edge `6e-153` off vertical got `−0.133` for `−0.25`).
///   Both are scaled by one power of two until the larger is `2^-100·|r|`
///   ([`NEAR_RAY_COMMON_EXPONENT`]): with one offset up, the numerator and both terms of the
///   denominator are homogeneous of degree 2 in the transverse parts (`|r| − r_z =
///   |r_xy|²/(|r| + r_z)` for the one up, `≈ 2|r_z|` for one down), so the term changes by
///   `O(2^-200)` relative; the smaller then takes the floor only if it is below `2^-400` of
///   the larger.
/// - Both below the query (near the antipode): the term is the area of a triangle of size
///   `|r_xy|/|r|` at most, below `2^-1000`; the floors stand.
///
/// Each component is scaled once, from its own exponent: a transverse part of `5e-324` scaled
/// down with its offset first would underflow to 0 and lose its azimuth.
fn unit_scaled(
    ra: [DoubleDouble; 3],
    rb: [DoubleDouble; 3],
) -> ([DoubleDouble; 3], [DoubleDouble; 3]) {
    // Per offset: the isotropic exponent, and the transverse part's exponent after it.
    let exponents = |r: &[DoubleDouble; 3]| {
        let m = r.iter().fold(0.0_f64, |m, c| m.max(c.hi.abs()));
        if m == 0.0 || !m.is_finite() {
            return None;
        }
        let down = -binary_exponent(m);
        let h = r[0].hi.abs().max(r[1].hi.abs());
        Some((down, (h > 0.0).then(|| binary_exponent(h) + down)))
    };
    let (ea, eb) = (exponents(&ra), exponents(&rb));
    let common = match (ea, eb) {
        (Some((_, Some(ha))), Some((_, Some(hb))))
            if (ra[2].hi > 0.0 || rb[2].hi > 0.0) && ha.max(hb) < NEAR_RAY_COMMON_EXPONENT =>
        {
            NEAR_RAY_COMMON_EXPONENT - ha.max(hb)
        }
        _ => 0,
    };
    let scaled = |r: [DoubleDouble; 3], e: Option<(i32, Option<i32>)>| {
        let Some((down, h)) = e else { return r };
        let across = h.map_or(0, |h| common.max(NEAR_RAY_FLOOR_EXPONENT - h).max(0));
        [
            times_power_of_two(r[0], i64::from(down + across)),
            times_power_of_two(r[1], i64::from(down + across)),
            times_power_of_two(r[2], i64::from(down)),
        ]
    };
    (scaled(ra, ea), scaled(rb, eb))
}

/// `c·2^k` for a double-double: [`scaled_by_power_of_two`] on both parts (exact unless the
/// result is subnormal; `|k|` may exceed 1022 for subnormal parts).
fn times_power_of_two(c: DoubleDouble, k: i64) -> DoubleDouble {
    DoubleDouble {
        hi: scaled_by_power_of_two(c.hi, k),
        lo: scaled_by_power_of_two(c.lo, k),
    }
}

/// `⌊log2 |x|⌋` for finite non-zero `x` (subnormals included).
pub(crate) fn binary_exponent(x: f64) -> i32 {
    let (mant, e) = decompose(x);
    e + 63 - mant.unsigned_abs().leading_zeros() as i32
}

/// `log2` of the smallest transverse size `|r_xy|/|r|` an accurate edge term computes with
/// ([`unit_scaled`]): far above the underflow of its products (squares of `2^-511`), far
/// below any error that matters (`2^-500` radians).
const NEAR_RAY_FLOOR_EXPONENT: i32 = -500;

/// `log2` of the transverse size `|r_xy|/|r|` to which [`unit_scaled`] scales the larger
/// of two offsets that are both near the ray line: small enough that the term's homogeneity
/// holds to `2^-200`, large enough that the other keeps `2^-400` of it above the floor.
const NEAR_RAY_COMMON_EXPONENT: i32 = -100;

/// Which end (`0` for `a`, `1` for `b`) is the other one of an edge with exactly one end at the
/// query, that end off the ray line (an end on it takes the on-ray lune).
#[inline]
fn other_end_of_edge_at_query(ra: &[f64; 3], rb: &[f64; 3]) -> Option<usize> {
    let off_ray = |r: &[f64; 3]| r[0] != 0.0 || r[1] != 0.0;
    match (*ra == [0.0; 3], *rb == [0.0; 3]) {
        (false, true) if off_ray(ra) => Some(0),
        (true, false) if off_ray(rb) => Some(1),
        _ => None,
    }
}

/// The `atan2` arguments `(|n|, den)` of an edge with one end at the query and the other at
/// offset `r`. The end at the query is seen from `q_ε` in the direction `−x̂`, so the generic
/// formula's `|n| = |r_y|` and `den = |r| − r_x − r_z` (up to the common factor `|r|`). That
/// difference cancels where the edge leaves the query almost along `x̂` (the first perturbation
/// direction, along which `q_ε` approaches the vertex): there the term is decided by `r`'s
/// transverse parts, and `|r| − r_x` in `f64` loses them (an edge of length `1e15` whose far end
/// is `O(1)` off the `x̂` line erred by `3·10⁻⁴` in `w`). Rationalized,
/// `|r| − (r_x + r_z) = (r_y² − 2 r_x r_z) / (|r| + r_x + r_z)` where `r_x + r_z > 0`: no
/// cancellation unless `r_x, r_z > 0` and `r_y² ≈ 2 r_x r_z`, and there `|n| = |r_y|` is the
/// larger argument by far, so the angle keeps its relative accuracy.
///
/// In double-double: the accurate path passes the exact, unit-scaled offset; the `f64` path
/// (which meets an end at the query only where the accurate path would have been taken) its
/// rounded offset, exactly converted.
fn edge_at_query_arguments(r: &[DoubleDouble; 3]) -> (f64, f64) {
    let len = dot3(r, r).sqrt();
    let along = r[0] + r[2];
    let den = if along.hi > 0.0 {
        (r[1] * r[1] - DoubleDouble::from_f64(2.0) * r[0] * r[2]) / (len + along)
    } else {
        len - along
    };
    (r[1].hi.abs(), den.value())
}

/// `|r| − r_z` without cancellation when `r` points up.
#[inline]
fn len_minus_z(r: [f64; 3], len: f64) -> f64 {
    if r[2] > 0.0 {
        (r[0] * r[0] + r[1] * r[1]) / (len + r[2])
    } else {
        len - r[2]
    }
}

/// Unit direction from `q_ε` towards a point at offset `r` from `q`: `r/|r|`, or `−x̂` when
/// `r = 0` (then `a − q_ε = −(ε1, ε2, ε3)` whose direction tends to `−x̂`).
#[inline]
fn limit_direction(r: [f64; 3]) -> [f64; 3] {
    if r == [0.0; 3] {
        [-1.0, 0.0, 0.0]
    } else {
        normalized(r)
    }
}

#[inline]
fn normalized(a: [f64; 3]) -> [f64; 3] {
    let l = norm(a);
    [a[0] / l, a[1] / l, a[2] / l]
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::f64::consts::PI;

    #[test]
    fn octant_triangle_subtends_an_eighth_of_the_sphere() {
        let w = triangle_solid_angle([1., 0., 0.], [0., 1., 0.], [0., 0., 1.]);
        assert!((w - 4.0 * PI / 8.0).abs() < 1e-15);
        let w = triangle_solid_angle([1., 0., 0.], [0., 0., 1.], [0., 1., 0.]);
        assert!((w + 4.0 * PI / 8.0).abs() < 1e-15);
    }

    #[test]
    fn degenerate_triangle_near_the_query_subtends_nothing() {
        // Collinear corners on the x axis, query 1e-8 off the line between them.
        let q = [0.7501, 1e-8, 1e-12];
        let p = [[0.0, 0.0, 0.0], [2.0, 0.0, 0.0], [-1.0, 0.0, 0.0]];
        let r = p.map(|v| [v[0] - q[0], v[1] - q[1], v[2] - q[2]]);
        let w = triangle_solid_angle(r[0], r[1], r[2]);
        assert!(w.abs() < 1e-12, "{w}");
        // The same from the other side of the line, and with the corners in another order.
        let q = [0.7501, -1e-8, 1e-12];
        let r = p.map(|v| [v[0] - q[0], v[1] - q[1], v[2] - q[2]]);
        for (i, j, k) in [(0, 1, 2), (1, 0, 2), (2, 1, 0)] {
            let w = triangle_solid_angle(r[i], r[j], r[k]);
            assert!(w.abs() < 1e-12, "{w}");
        }
    }

    #[test]
    fn coplanar_query_gives_zero_not_nan() {
        assert_eq!(
            triangle_solid_angle([0.; 3], [1., 0., 0.], [0., 1., 0.]),
            0.0
        );
        assert_eq!(
            triangle_solid_angle([-1., 0., 0.], [1., 0., 0.], [0., 1., 0.]),
            0.0
        );
        assert_eq!(triangle_solid_angle([0.; 3], [0.; 3], [0.; 3]), 0.0);
    }

    #[test]
    fn zero_magnitude_takes_the_exact_side() {
        assert_eq!(signed_double_atan2(1, 0.0, -1.0), 2.0 * PI);
        assert_eq!(signed_double_atan2(-1, 0.0, -1.0), -2.0 * PI);
        assert_eq!(signed_double_atan2(-1, 0.0, 1.0), 0.0);
        assert_eq!(signed_double_atan2(0, 1.0, -1.0), 0.0);
    }

    #[test]
    fn generic_edge_matches_the_paper_formula() {
        // Paper: 2·atan2(x1·(A×B), 1 + A·B + A·x1 + B·x1) with x1 = −z.
        let ra = [0.3, -0.7, 0.2];
        let rb = [-0.4, 0.1, 0.9];
        let a = normalized(ra);
        let b = normalized(rb);
        let x1 = [0.0, 0.0, -1.0];
        let paper = 2.0 * dot(x1, cross(a, b)).atan2(1.0 + dot(a, b) + dot(a, x1) + dot(b, x1));
        let s = if dot(x1, cross(a, b)) > 0.0 { 1 } else { -1 };
        let ours = antipodal_edge_area(
            ra,
            rb,
            EdgeSigns {
                numerator: s,
                query_inside_segment: false,
                flat_denominator: 0,
            },
        );
        assert!((paper - ours).abs() < 1e-14, "{paper} vs {ours}");
    }
}
