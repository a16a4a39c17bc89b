//! The symbolically perturbed predicates on grid coordinates (ray frame, ray along `+z`).
//!
//! The query is `q_ε = q + (ε1, ε2, ε3)` with `0 < ε3 ≪ ε2 ≪ ε1` infinitesimal (Edelsbrunner &
//! Mücke's simulation of simplicity; antipodal paper, Supp. Sec. 2.1). Every predicate is a
//! polynomial in ε whose sign is the sign of its first non-zero coefficient in the order
//! (real, ε1, ε2, ε3). Since all predicates are evaluated at the *same* symbolic point, their
//! answers are those of one actual point `q + (t, t², t³)` for small `t > 0`: they can never
//! contradict one another.
//!
//! [`perturbed_orient2d`] is THE shared sign: the ray–triangle test uses it for each triangle
//! edge, and the Antipodal boundary term uses minus it as the sign of the atan2 numerator
//! `x1·(A×B)`. That is why the integer part (crossings) and the fractional part (areas) jump
//! together and the sum never jumps.

use num_bigint::BigInt;

use super::quantize::{Precision, decompose};

/// Integer width of the predicates: `i64` arithmetic on a 30-bit grid, `i128` on a 60-bit grid.
pub trait Width: Copy + Send + Sync + std::fmt::Debug + 'static {
    /// The grid precision this width serves.
    const PRECISION: Precision;
    /// `sign(a0·b1 − a1·b0)` for grid differences `a`, `b`.
    fn det2_sign(a0: i64, a1: i64, b0: i64, b1: i64) -> i32;
    /// `sign(d·(e1×e2))` for grid differences `d`, `e1`, `e2` (the unperturbed depth test).
    fn orient3d_sign(d: [i64; 3], e1: [i64; 3], e2: [i64; 3]) -> i32;
}

/// 30-bit grid: differences < 2^31, so 2×2 determinants fit `i64` and the depth test `i128`.
#[derive(Clone, Copy, Debug, Default)]
pub struct W64;

/// 60-bit grid: differences < 2^61, so 2×2 determinants fit `i128`; the depth test needs ~185 bits
/// and runs a floating-point filter with an exact `BigInt` fallback.
#[derive(Clone, Copy, Debug, Default)]
pub struct W128;

impl Width for W64 {
    const PRECISION: Precision = Precision::Bits30;
    #[inline]
    fn det2_sign(a0: i64, a1: i64, b0: i64, b1: i64) -> i32 {
        // |a|,|b| < 2^31 ⇒ each product < 2^62, the difference < 2^63.
        let d = a0 * b1 - a1 * b0;
        d.signum() as i32
    }
    #[inline]
    fn orient3d_sign(d: [i64; 3], e1: [i64; 3], e2: [i64; 3]) -> i32 {
        // |n_k| < 2^63 for n = e1×e2, |d_k| < 2^31 ⇒ |d·n| < 3·2^94.
        let n = cross_exact(e1, e2);
        let v = i128::from(d[0]) * n[0] + i128::from(d[1]) * n[1] + i128::from(d[2]) * n[2];
        v.signum() as i32
    }
}

impl Width for W128 {
    const PRECISION: Precision = Precision::Bits60;
    #[inline]
    fn det2_sign(a0: i64, a1: i64, b0: i64, b1: i64) -> i32 {
        if let Some(sign) = det2_filtered(a0 as f64, a1 as f64, b0 as f64, b1 as f64) {
            return sign;
        }
        // Exact fallback: |a|,|b| < 2^61 ⇒ each product < 2^122, the difference < 2^123.
        let d = i128::from(a0) * i128::from(b1) - i128::from(a1) * i128::from(b0);
        d.signum() as i32
    }
    #[inline]
    fn orient3d_sign(d: [i64; 3], e1: [i64; 3], e2: [i64; 3]) -> i32 {
        // Filter in f64 straight from the differences (no i128 products, no i128 → f64
        // conversion, which was measurable: docs/benchmarks.md, "Design measurements"); see
        // ORIENT3D_FILTER_RELATIVE. Exact otherwise: i128 cross product, BigInt dot product.
        let f = |v: [i64; 3]| v.map(|c| c as f64);
        if let Some(sign) = orient3d_filtered(f(d), f(e1), f(e2)) {
            return sign;
        }
        exact_dot3_sign(d, cross_exact(e1, e2))
    }
}

/// Relative bound of the 60-bit `det2` filter on `|p1| + |p2|`: the four conversions of 61-bit
/// integers (relative error `≤ u = 2^-53` each), the two products and the difference bound the
/// error of `d = p1 − p2` by `4u·(|p1| + |p2|)`; the filter tests twice that, `8u`.
pub const DET2_FILTER_RELATIVE: f64 = 8.0 * (f64::EPSILON * 0.5);

/// The `f64` filter of the `det2` tests on integer differences converted to `f64` (each rounded
/// once): `sign(a0·b1 − a1·b0)` when it clears [`DET2_FILTER_RELATIVE`], else `None`.
#[inline]
fn det2_filtered(a0: f64, a1: f64, b0: f64, b1: f64) -> Option<i32> {
    let p1 = a0 * b1;
    let p2 = a1 * b0;
    let d = p1 - p2;
    let bound = DET2_FILTER_RELATIVE * (p1.abs() + p2.abs());
    if d > bound {
        Some(1)
    } else if d < -bound {
        Some(-1)
    } else {
        None
    }
}

/// The `f64` filter of the `orient3d` tests, `sign(x·(a×b))`, on integer differences converted
/// to `f64` (each rounded once; see [`ORIENT3D_FILTER_RELATIVE`]), else `None`.
#[inline]
fn orient3d_filtered(x: [f64; 3], a: [f64; 3], b: [f64; 3]) -> Option<i32> {
    let n0a = a[1] * b[2];
    let n0b = a[2] * b[1];
    let n1a = a[2] * b[0];
    let n1b = a[0] * b[2];
    let n2a = a[0] * b[1];
    let n2b = a[1] * b[0];
    let v = x[0] * (n0a - n0b) + x[1] * (n1a - n1b) + x[2] * (n2a - n2b);
    let permanent = x[0].abs() * (n0a.abs() + n0b.abs())
        + x[1].abs() * (n1a.abs() + n1b.abs())
        + x[2].abs() * (n2a.abs() + n2b.abs());
    let bound = ORIENT3D_FILTER_RELATIVE * permanent;
    if v > bound {
        return Some(1);
    }
    if v < -bound {
        return Some(-1);
    }
    // Below 2^53 every step was exact (a nonzero integer `x_k` bounds its products by the
    // permanent; `x_k = 0` zeroes its term whatever the rounding): `v` is the determinant.
    // Coplanar points (v = 0) land here, and the remesher's flat regions test thousands.
    if permanent < EXACT_F64_INTEGER {
        return Some(if v > 0.0 {
            1
        } else if v < 0.0 {
            -1
        } else {
            0
        });
    }
    None
}

/// `2^53`: integers below it, and sums and products of them that stay below it, are exact in
/// `f64`.
const EXACT_F64_INTEGER: f64 = 9_007_199_254_740_992.0;

/// Relative bound of the 60-bit `orient3d` filter on the permanent
/// `Σ |d_k|·(|e1_i e2_j| + |e1_j e2_i|)`: each difference (`< 2^61`) is rounded once on
/// conversion, relative error `≤ u = 2^-53`, which is the error model of Shewchuk's orient3d, whose
/// first-stage bound `(7 + 56u)·u·permanent` therefore holds; the filter tests `8u·permanent`.
pub const ORIENT3D_FILTER_RELATIVE: f64 = 8.0 * (f64::EPSILON * 0.5);

/// Exact sign of `d·n` (the fallback of the 60-bit depth test): in `i128` when no product or
/// sum overflows, else in arbitrary precision. The fallback is rare on general inputs, but not
/// on coplanar ones (the remesher's flat regions test coplanar faces by the thousand), whose
/// small coordinates fit `i128`.
pub fn exact_dot3_sign(d: [i64; 3], n: [i128; 3]) -> i32 {
    let small = (0..3).try_fold(0i128, |sum, k| {
        i128::from(d[k])
            .checked_mul(n[k])
            .and_then(|p| sum.checked_add(p))
    });
    if let Some(v) = small {
        return v.signum() as i32;
    }
    exact_dot3_sign_big(d, n)
}

#[cold]
fn exact_dot3_sign_big(d: [i64; 3], n: [i128; 3]) -> i32 {
    let v: BigInt = (0..3)
        .map(|k| BigInt::from(d[k]) * BigInt::from(n[k]))
        .sum();
    match v.sign() {
        num_bigint::Sign::Plus => 1,
        num_bigint::Sign::Minus => -1,
        num_bigint::Sign::NoSign => 0,
    }
}

/// The `f64` filter of [`perturbed_orient2d`], as the boundary loop (`kernel::boundary_sum`, both its
/// portable and its AVX2 form) evaluates it four edges at a time; the loop uses these constants and
/// this formula, so "one predicate decides both parts" stays visible here.
///
/// Inputs are the offsets `a − q`, `b − q` formed in `f64` from grid integers of magnitude
/// `≤ limit = 2^(bits−1)`: each conversion errs by `≤ u·limit` and the subtraction by
/// `≤ u·|offset|` (`u = 2^-53`), and `d = ax·by − ay·bx` adds `3u·(|ax·by| + |ay·bx|)`. The bound
/// takes twice that: `CONVERSION·limit·(|ax| + |ay| + |bx| + |by|) + RELATIVE·(|p1| + |p2|)`.
/// When `|d|` clears it, `sign(d)` is the exact sign (the ε terms are infinitesimal); otherwise
/// `None`: the exact integer predicate decides.
#[inline]
pub fn orient2d_filtered(ra: [f64; 2], rb: [f64; 2], limit: f64) -> Option<i32> {
    let p1 = ra[0] * rb[1];
    let p2 = ra[1] * rb[0];
    let d = p1 - p2;
    let bound = ORIENT2D_FILTER_CONVERSION
        * limit
        * (ra[0].abs() + ra[1].abs() + rb[0].abs() + rb[1].abs())
        + ORIENT2D_FILTER_RELATIVE * (p1.abs() + p2.abs());
    if d > bound {
        Some(1)
    } else if d < -bound {
        Some(-1)
    } else {
        None
    }
}

/// [`orient2d_filtered`] on four edges at once, as the boundary loops evaluate it (written over the
/// lane operations of `kernel::lanes`, so the portable and AVX2 loops share it): from the offsets
/// `[ax, ay, bx, by]`, the mask `real` of lanes that are edges, and the splatted
/// `conv = CONVERSION·limit` and `rel = RELATIVE`, gives `d` and the mask of the lanes where `|d|`
/// clears the bound, i.e. where `sign(d)` is the exact sign.
macro_rules! orient2d_filter_lanes {
    ($o:expr, [$ax:expr, $ay:expr, $bx:expr, $by:expr], $real:expr, $conv:expr, $rel:expr) => {{
        let (o, ax, ay, bx, by) = ($o, $ax, $ay, $bx, $by);
        let p1 = o.mul(ax, by);
        let p2 = o.mul(ay, bx);
        let d = o.sub(p1, p2);
        let sum_abs = o.add(o.add(o.add(o.abs(ax), o.abs(ay)), o.abs(bx)), o.abs(by));
        let bound = o.add(
            o.mul($conv, sum_abs),
            o.mul($rel, o.add(o.abs(p1), o.abs(p2))),
        );
        (d, o.and(o.gt(o.abs(d), bound), $real))
    }};
}
pub(crate) use orient2d_filter_lanes;

/// Conversion term of [`orient2d_filtered`]'s bound, per unit of `limit`: `2·2u`.
pub const ORIENT2D_FILTER_CONVERSION: f64 = 2.0 * 2.0 * (f64::EPSILON * 0.5);

/// Rounding term of [`orient2d_filtered`]'s bound, relative to `|p1| + |p2|`: `2·4u`.
pub const ORIENT2D_FILTER_RELATIVE: f64 = 2.0 * 4.0 * (f64::EPSILON * 0.5);

// Why a sign [`orient2d_filtered`] gives on the 60-bit lattice is also the sign for the exact
// inputs, whose vertices and query lie up to half a cell per coordinate off their lattice points
// (issue 21): with `Σ = |ax| + |ay| + |bx| + |by|` (lattice offsets, integers), moving both ends
// of each offset by `≤ 1/2` changes `D` by at most `Σ + 2 ≤ 3Σ` (`Σ ≥ 1`; `Σ = 0` gives `d = 0`,
// never decided). A decided `|d|` exceeds the bound, twice the rounding error, so the lattice
// `|D| >` half the bound `≥ CONVERSION/2 · limit · Σ = 128·Σ` at `limit = 2^59`: the snapping
// cannot reach zero. So only the filter's undecided edges need the exact inputs. (At 60 bits the
// boundary loops now take their offsets from the exact inputs themselves,
// `boundary_sum::LoopFrame::Unshifted`, one rounding of the exact difference: their `d` is
// closer still to the inputs' `D`.)
// (Checked at compile time: a constant only a `const _` reads counts as unused on Rust 1.88.)
const _: () = assert!(ORIENT2D_FILTER_CONVERSION * 0.5 * ((1_u64 << 59) as f64) >= 3.0);

/// The atan2 numerator's sign `−sign((a−q)×(b−q))_z` for a query whose ray cannot meet the mesh
/// (outside the padded box across the ray): `q` is farther than the mesh's extent from every
/// edge, so the edge's projected line is not near `q` and the boundary term has no branch cut
/// nearby; the `f64` sign is the one the formula needs (a rounding-signed zero contributes 0).
#[inline]
pub fn far_query_numerator_sign(ra: [f64; 3], rb: [f64; 3]) -> i32 {
    let n = -(ra[0] * rb[1] - ra[1] * rb[0]);
    if n > 0.0 {
        1
    } else if n < 0.0 {
        -1
    } else {
        0
    }
}

/// Result of the perturbed 2D orientation: the sign, and whether the unperturbed determinant was
/// exactly zero (the query's projection is on the line through the edge's projection).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Orient2d {
    /// Sign of `det(a − q_ε, b − q_ε)` restricted to x, y: +1 when `(q, a, b)` turn
    /// counter-clockwise seen from `+z`. Zero only when `a` and `b` project to the same point.
    pub sign: i32,
    /// The real (ε-free) part was zero.
    pub degenerate: bool,
}

/// THE shared predicate: orientation of `(q_ε, a, b)` projected along the ray (`+z`).
///
/// `det(a − q_ε, b − q_ε) = D0 + ε1·(a_y − b_y) + ε2·(b_x − a_x)` exactly (the ε1·ε2 terms
/// cancel), so the sign is that of the first non-zero of `D0`, `a_y − b_y`, `b_x − a_x`.
#[inline]
pub fn perturbed_orient2d<W: Width>(q: [i64; 2], a: [i64; 2], b: [i64; 2]) -> Orient2d {
    let s = W::det2_sign(a[0] - q[0], a[1] - q[1], b[0] - q[0], b[1] - q[1]);
    if s != 0 {
        return Orient2d {
            sign: s,
            degenerate: false,
        };
    }
    orient2d_perturbation(a, b)
}

/// The sign of `det(a − q_ε, b − q_ε)` when its real part is zero: the first non-zero of the ε1
/// and ε2 coefficients `a_y − b_y`, `b_x − a_x` (they do not depend on `q`).
#[inline]
fn orient2d_perturbation(a: [i64; 2], b: [i64; 2]) -> Orient2d {
    let s1 = (a[1] - b[1]).signum() as i32;
    let sign = if s1 != 0 {
        s1
    } else {
        (b[0] - a[0]).signum() as i32
    };
    Orient2d {
        sign,
        degenerate: true,
    }
}

/// Signed crossing of the ray from `q_ε` along `+z` with triangle `(p0, p1, p2)`: `+1` when the
/// ray leaves through the side the triangle's normal points to (`n_z > 0`), `−1` when it enters,
/// `0` when it misses. Exact for every input (no tolerance), consistent with
/// [`perturbed_orient2d`] on the triangle's edges.
#[inline]
pub fn ray_crossing<W: Width>(q: [i64; 3], p: [[i64; 3]; 3]) -> i32 {
    let s0 = projected_containment::<W>([q[0], q[1]], p);
    if s0 == 0 {
        return 0;
    }
    // The projection of q_ε is strictly inside the projected triangle, whose orientation s0 is
    // sign(n_z). The ray hits the triangle iff q_ε is strictly below its plane along z, i.e.
    // sign((q_ε − p0)·n) = −sign(n_z).
    if perturbed_plane_side::<W>(q, p) == -s0 {
        s0
    } else {
        0
    }
}

/// The 2D half of [`ray_crossing`]: `sign(n_z)` when the projection of `q_ε` lies strictly inside
/// the projected triangle, else 0. All three edge tests are [`perturbed_orient2d`].
#[inline]
pub fn projected_containment<W: Width>(q2: [i64; 2], p: [[i64; 3]; 3]) -> i32 {
    // Exact, conservative early-out: q_ε = q + (ε1, ε2) can only be strictly inside if q lies in
    // the closed xy-box of the projected triangle.
    for k in 0..2 {
        let (lo, hi) = (
            p[0][k].min(p[1][k]).min(p[2][k]),
            p[0][k].max(p[1][k]).max(p[2][k]),
        );
        if q2[k] < lo || q2[k] > hi {
            return 0;
        }
    }
    let s0 = perturbed_orient2d::<W>(q2, [p[0][0], p[0][1]], [p[1][0], p[1][1]]).sign;
    if s0 == 0 {
        return 0;
    }
    let s1 = perturbed_orient2d::<W>(q2, [p[1][0], p[1][1]], [p[2][0], p[2][1]]).sign;
    if s1 != s0 {
        return 0;
    }
    let s2 = perturbed_orient2d::<W>(q2, [p[2][0], p[2][1]], [p[0][0], p[0][1]]).sign;
    if s2 != s0 {
        return 0;
    }
    s0
}

/// Sign of `(q_ε − p0)·n`, `n = (p1 − p0)×(p2 − p0)`: real part, then the ε1, ε2, ε3
/// coefficients `n_x`, `n_y`, `n_z`. Zero only for a degenerate triangle (`n = 0`).
#[inline]
pub fn perturbed_plane_side<W: Width>(q: [i64; 3], p: [[i64; 3]; 3]) -> i32 {
    let e1 = sub(p[1], p[0]);
    let e2 = sub(p[2], p[0]);
    let s = W::orient3d_sign(sub(q, p[0]), e1, e2);
    if s != 0 {
        return s;
    }
    for c in cross_exact(e1, e2) {
        if c != 0 {
            return c.signum() as i32;
        }
    }
    0
}

/// The query's exact position is `q + r` (lattice point `q`, residual `r` in cells, dyadic,
/// `|r_k| ≤ 1/2`; see [`super::quantize::Grid::snap_with_residual`]). The `_at` predicates below
/// are the predicates above evaluated at that exact point, perturbed the same way: every predicate
/// is affine in the query, so its ε coefficients do not depend on `r` and a query with `r = 0`
/// takes the lattice code path unchanged. This is what makes `w` exact to the last bit of the
/// query's coordinates, not only up to half a cell.
///
/// `sign(det(a − q − r, b − q − r))` perturbed: `det` is affine in the query,
/// `D(q + r) = D(q) + (b_x − a_x)·r_y − (b_y − a_y)·r_x`.
#[inline]
pub fn perturbed_orient2d_at<W: Width>(
    q: [i64; 2],
    r: [f64; 2],
    a: [i64; 2],
    b: [i64; 2],
) -> Orient2d {
    if r == [0.0, 0.0] {
        return perturbed_orient2d::<W>(q, a, b);
    }
    let (u0, u1, v0, v1) = (a[0] - q[0], a[1] - q[1], b[0] - q[0], b[1] - q[1]);
    // Exact: |u|, |v| < 2^61, products < 2^122.
    let lattice = i128::from(u0) * i128::from(v1) - i128::from(u1) * i128::from(v0);
    let e = [b[0] - a[0], b[1] - a[1]];
    let c0 = e[0] as f64 * r[1];
    let c1 = e[1] as f64 * r[0];
    let lf = lattice as f64;
    let total = lf + (c0 - c1);
    // Conversions (u each), two products, two sums: 4u of the permanent covers them; ×2.
    let bound = RESIDUAL_FILTER * (lf.abs() + c0.abs() + c1.abs());
    let s = if total > bound {
        1
    } else if total < -bound {
        -1
    } else {
        exact_sign_with_residual(
            BigInt::from(lattice),
            &[i128::from(e[0]), -i128::from(e[1])],
            &[r[1], r[0]],
        )
    };
    if s != 0 {
        return Orient2d {
            sign: s,
            degenerate: false,
        };
    }
    orient2d_perturbation(a, b)
}

/// Relative bound of the residual predicates' `f64` filters: `8u`, twice the `4u` that covers
/// the conversions, products and sums of a permanent of at most six terms (`u = 2^-53`).
const RESIDUAL_FILTER: f64 = 8.0 * (f64::EPSILON * 0.5);

/// [`perturbed_plane_side`] at the exact query `q + r`: `(q + r − p0)·n = (q − p0)·n + r·n`.
#[inline]
pub fn perturbed_plane_side_at<W: Width>(q: [i64; 3], r: [f64; 3], p: [[i64; 3]; 3]) -> i32 {
    if r == [0.0; 3] {
        return perturbed_plane_side::<W>(q, p);
    }
    let e1 = sub(p[1], p[0]);
    let e2 = sub(p[2], p[0]);
    let n = cross_exact(e1, e2);
    let d = sub(q, p[0]);
    let mut total = 0.0;
    let mut permanent = 0.0;
    for k in 0..3 {
        let nk = n[k] as f64;
        let t = d[k] as f64 * nk + r[k] * nk;
        total += t;
        permanent += (d[k] as f64).abs() * nk.abs() + (r[k] * nk).abs();
    }
    let bound = RESIDUAL_FILTER * permanent;
    let s = if total > bound {
        1
    } else if total < -bound {
        -1
    } else {
        let lattice: BigInt = (0..3)
            .map(|k| BigInt::from(d[k]) * BigInt::from(n[k]))
            .sum();
        exact_sign_with_residual(lattice, &n, &r)
    };
    if s != 0 {
        return s;
    }
    for c in n {
        if c != 0 {
            return c.signum() as i32;
        }
    }
    0
}

/// [`ray_crossing`] from the exact query `q + r`.
#[inline]
pub fn ray_crossing_at<W: Width>(q: [i64; 3], r: [f64; 3], p: [[i64; 3]; 3]) -> i32 {
    let s0 = projected_containment_at::<W>([q[0], q[1]], [r[0], r[1]], p);
    if s0 == 0 {
        return 0;
    }
    if perturbed_plane_side_at::<W>(q, r, p) == -s0 {
        s0
    } else {
        0
    }
}

/// [`projected_containment`] of the exact query `q + r`.
#[inline]
pub fn projected_containment_at<W: Width>(q2: [i64; 2], r2: [f64; 2], p: [[i64; 3]; 3]) -> i32 {
    if r2 == [0.0, 0.0] {
        return projected_containment::<W>(q2, p);
    }
    for k in 0..2 {
        let (lo, hi) = (
            p[0][k].min(p[1][k]).min(p[2][k]),
            p[0][k].max(p[1][k]).max(p[2][k]),
        );
        // `q + r < lo` ⟺ `q < lo`, or `q = lo` and `r < 0` (|r| ≤ 1/2, lattice integers).
        if q2[k] < lo || q2[k] > hi || (q2[k] == lo && r2[k] < 0.0) || (q2[k] == hi && r2[k] > 0.0)
        {
            return 0;
        }
    }
    let edge = |i: usize, j: usize| {
        perturbed_orient2d_at::<W>(q2, r2, [p[i][0], p[i][1]], [p[j][0], p[j][1]]).sign
    };
    let s0 = edge(0, 1);
    if s0 == 0 || edge(1, 2) != s0 || edge(2, 0) != s0 {
        return 0;
    }
    s0
}

/// [`query_inside_segment`] for the exact query `q + r` (exact big-integer arithmetic on the
/// offsets scaled to integers; only reached for degenerate orientations).
pub fn query_inside_segment_at(q: [i64; 3], r: [f64; 3], a: [i64; 3], b: [i64; 3]) -> bool {
    if r == [0.0; 3] {
        return query_inside_segment(q, a, b);
    }
    // With r ≠ 0 the query is not a lattice point, so neither offset is zero.
    let shift = residual_scale(&r);
    let offset = |p: [i64; 3]| -> [BigInt; 3] {
        std::array::from_fn(|k| (BigInt::from(p[k] - q[k]) << shift) - scaled_dyadic(r[k], shift))
    };
    let (ra, rb) = (offset(a), offset(b));
    let zero = BigInt::from(0);
    for (i, j) in [(1, 2), (2, 0), (0, 1)] {
        if &ra[i] * &rb[j] - &ra[j] * &rb[i] != zero {
            return false;
        }
    }
    let dot: BigInt = (0..3).map(|k| &ra[k] * &rb[k]).sum();
    dot < zero
}

/// Exact sign of `lattice + Σ c_k·r_k` for integers `lattice`, `c_k` and dyadic `r_k`: everything
/// is scaled by the power of two that makes every `r_k` an integer.
#[cold]
pub fn exact_sign_with_residual(lattice: BigInt, c: &[i128], r: &[f64]) -> i32 {
    let shift = residual_scale(r);
    let mut v = lattice << shift;
    for (ck, rk) in c.iter().zip(r) {
        v += BigInt::from(*ck) * scaled_dyadic(*rk, shift);
    }
    match v.sign() {
        num_bigint::Sign::Plus => 1,
        num_bigint::Sign::Minus => -1,
        num_bigint::Sign::NoSign => 0,
    }
}

/// The smallest `s ≥ 0` with every `r_k·2^s` an integer.
fn residual_scale(r: &[f64]) -> usize {
    r.iter()
        .filter(|x| **x != 0.0)
        .map(|&x| {
            let (m, e) = decompose(x);
            let e = e + m.trailing_zeros() as i32;
            (-e).max(0) as usize
        })
        .max()
        .unwrap_or(0)
}

/// `x·2^shift` as an integer (exact when `shift ≥ residual_scale(x)`).
fn scaled_dyadic(x: f64, shift: usize) -> BigInt {
    let (m, e) = decompose(x);
    let total = e + shift as i32;
    if total >= 0 {
        BigInt::from(m) << total as usize
    } else {
        BigInt::from(m) >> (-total) as usize
    }
}

/// Relative bound of the `f64` filter of [`closed_surface_orientation`] on `Σ` of the faces'
/// permanents: each face's determinant errs by `ORIENT3D_FILTER_RELATIVE·permanent`, and a running
/// sum of `F` terms by `F·u` times the sum of their magnitudes (`u = 2^-53`), each at most its
/// permanent; the filter takes twice `(8 + F)·u` (the permanents' own sum is rounded too).
#[cfg(feature = "products")] // The remesher's exact tests on an input's own coordinates.
pub const VOLUME_FILTER_RELATIVE: f64 = 2.0 * (f64::EPSILON * 0.5);

/// Exact sign of `Σ det(a − o, b − o, c − o)` over the faces `(a, b, c)`: six times the signed
/// volume a closed, consistently oriented surface encloses (the same for every apex `o`), so `+1`
/// when it is oriented outward and `−1` inward. Coordinates below `2^125` in magnitude. An `f64` sum with its error bound decides unless
/// the volume is within rounding of zero; then the sum is made in integers.
#[cfg(feature = "products")] // The remesher's exact tests on an input's own coordinates.
pub fn closed_surface_orientation(
    points: &[[i128; 3]],
    faces: impl Iterator<Item = [u32; 3]> + Clone,
    apex: [i128; 3],
) -> i32 {
    let offset = |v: u32| {
        let p = points[v as usize];
        [p[0] - apex[0], p[1] - apex[1], p[2] - apex[2]]
    };
    let (mut sum, mut permanents, mut count) = (0.0f64, 0.0f64, 0.0f64);
    for [a, b, c] in faces.clone() {
        let [d, e1, e2] = [offset(a), offset(b), offset(c)].map(|p| p.map(|x| x as f64));
        let m = |i: usize, j: usize| (e1[i] * e2[j], e1[j] * e2[i]);
        let (x, y, z) = (m(1, 2), m(2, 0), m(0, 1));
        sum += d[0] * (x.0 - x.1) + d[1] * (y.0 - y.1) + d[2] * (z.0 - z.1);
        permanents += d[0].abs() * (x.0.abs() + x.1.abs())
            + d[1].abs() * (y.0.abs() + y.1.abs())
            + d[2].abs() * (z.0.abs() + z.1.abs());
        count += 1.0;
    }
    let bound = (ORIENT3D_FILTER_RELATIVE + (8.0 + count) * VOLUME_FILTER_RELATIVE) * permanents;
    if sum.abs() > bound {
        return if sum > 0.0 { 1 } else { -1 };
    }
    let exact: BigInt = faces
        .map(|[a, b, c]| {
            let [d, e1, e2] = [offset(a), offset(b), offset(c)].map(|p| p.map(BigInt::from));
            &d[0] * (&e1[1] * &e2[2] - &e1[2] * &e2[1])
                + &d[1] * (&e1[2] * &e2[0] - &e1[0] * &e2[2])
                + &d[2] * (&e1[0] * &e2[1] - &e1[1] * &e2[0])
        })
        .sum();
    sign_of(&exact)
}

/// `sign(a0·b1 − a1·b0)` for integer differences below `2^126` (an input's own coordinates as
/// integers, wider than the 60-bit grid): the [`DET2_FILTER_RELATIVE`] filter (each conversion
/// to `f64` rounds once, as in the 60-bit test), then arbitrary precision.
#[cfg(feature = "products")] // The remesher's exact tests on an input's own coordinates.
pub fn det2_sign_wide(a0: i128, a1: i128, b0: i128, b1: i128) -> i32 {
    if let Some(sign) = det2_filtered(a0 as f64, a1 as f64, b0 as f64, b1 as f64) {
        return sign;
    }
    let exact = BigInt::from(a0) * BigInt::from(b1) - BigInt::from(a1) * BigInt::from(b0);
    sign_of(&exact)
}

/// `sign(d·(e1×e2))` for integer differences below `2^126`: the [`ORIENT3D_FILTER_RELATIVE`]
/// filter, exact below `2^53` as in the 60-bit test, then arbitrary precision.
#[cfg(feature = "products")] // The remesher's exact tests on an input's own coordinates.
pub fn orient3d_sign_wide(d: [i128; 3], e1: [i128; 3], e2: [i128; 3]) -> i32 {
    let f = |v: [i128; 3]| v.map(|c| c as f64);
    if let Some(sign) = orient3d_filtered(f(d), f(e1), f(e2)) {
        return sign;
    }
    let big = |v: [i128; 3]| v.map(BigInt::from);
    let (x, a, b) = (big(d), big(e1), big(e2));
    let exact = &x[0] * (&a[1] * &b[2] - &a[2] * &b[1])
        + &x[1] * (&a[2] * &b[0] - &a[0] * &b[2])
        + &x[2] * (&a[0] * &b[1] - &a[1] * &b[0]);
    sign_of(&exact)
}

#[cfg(feature = "products")] // The remesher's exact tests on an input's own coordinates.
fn sign_of(v: &BigInt) -> i32 {
    match v.sign() {
        num_bigint::Sign::Plus => 1,
        num_bigint::Sign::Minus => -1,
        num_bigint::Sign::NoSign => 0,
    }
}

/// Exact cross product of grid differences (< 2^61 each ⇒ components < 2^123).
#[inline]
pub fn cross_exact(a: [i64; 3], b: [i64; 3]) -> [i128; 3] {
    let m = |x: i64, y: i64| i128::from(x) * i128::from(y);
    [
        m(a[1], b[2]) - m(a[2], b[1]),
        m(a[2], b[0]) - m(a[0], b[2]),
        m(a[0], b[1]) - m(a[1], b[0]),
    ]
}

/// Whether `q_ε` lies strictly inside the segment `a b` to first order in ε: `q` on the open
/// segment (exact collinearity and opposite directions), or `q` equal to an endpoint with the
/// segment leaving it along `+x` (the dominant perturbation direction). Only meaningful when the
/// 2D orientation was degenerate.
#[inline]
pub fn query_inside_segment(q: [i64; 3], a: [i64; 3], b: [i64; 3]) -> bool {
    let ra = sub(a, q);
    let rb = sub(b, q);
    let along_pos_x = |r: [i64; 3]| r[0] > 0 && r[1] == 0 && r[2] == 0;
    if ra == [0; 3] {
        return along_pos_x(rb);
    }
    if rb == [0; 3] {
        return along_pos_x(ra);
    }
    let c = cross_exact(ra, rb);
    if c != [0; 3] {
        return false;
    }
    let dot = i128::from(ra[0]) * i128::from(rb[0])
        + i128::from(ra[1]) * i128::from(rb[1])
        + i128::from(ra[2]) * i128::from(rb[2]);
    dot < 0
}

#[inline]
fn sub(a: [i64; 3], b: [i64; 3]) -> [i64; 3] {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn orient2d_resolves_collinear_cases_by_the_perturbation() {
        // Proper left turn.
        let o = perturbed_orient2d::<W64>([0, 0], [1, 0], [0, 1]);
        assert_eq!(
            o,
            Orient2d {
                sign: 1,
                degenerate: false
            }
        );
        // q on the line through a horizontal edge: decided by ε2 (b_x − a_x).
        let o = perturbed_orient2d::<W128>([5, 0], [1, 0], [3, 0]);
        assert_eq!(
            o,
            Orient2d {
                sign: 1,
                degenerate: true
            }
        );
        // q on the line through a vertical edge: decided by ε1 (a_y − b_y).
        let o = perturbed_orient2d::<W64>([0, 7], [0, 1], [0, 3]);
        assert_eq!(o.sign, -1);
        // Edge projecting to a point.
        assert_eq!(perturbed_orient2d::<W64>([0, 0], [2, 2], [2, 2]).sign, 0);
    }

    #[test]
    fn det2_filter_defers_to_exact_when_f64_cannot_decide() {
        let t = 1_i64 << 60;
        // (2^60+1)(2^60−1) − 2^60·2^60 = −1, but every f64 product rounds to 2^120.
        assert_eq!(W128::det2_sign(t + 1, t, t, t - 1), -1);
        assert_eq!(W128::det2_sign(t, t + 1, t - 1, t), 1);
        assert_eq!(W128::det2_sign(t, t, t, t), 0);
    }

    #[test]
    fn widths_agree_on_small_inputs_and_the_filter_falls_back() {
        for (a, b) in [([3, -2], [5, 7]), ([0, 0], [1, 1]), ([-4, 2], [2, -1])] {
            assert_eq!(
                W64::det2_sign(a[0], a[1], b[0], b[1]),
                W128::det2_sign(a[0], a[1], b[0], b[1])
            );
        }
        // Large values where f64 cannot decide: d·n = 2^60·(2^62+1) − (2^122 + 2^60 − 1) = 1.
        let big = 1_i64 << 60;
        let d = [big, -1, 0];
        let n = [
            (1_i128 << 62) + 1,
            (big as i128) * (1 << 62) + big as i128 - 1,
            0,
        ];
        assert_eq!(exact_dot3_sign(d, n), 1);
        assert_eq!(exact_dot3_sign_big(d, n), 1);
        // Products beyond i128 take the arbitrary-precision path:
        // 2^62·2^123 + 2^62·(1 − 2^123) = 2^62.
        let (d, n) = (
            [1_i64 << 62, 1 << 62, 0],
            [1_i128 << 123, 1 - (1_i128 << 123), 0],
        );
        assert_eq!(exact_dot3_sign(d, n), 1);
        assert_eq!(exact_dot3_sign([-(1_i64 << 62), -(1 << 62), 0], n), -1);
        // orient3d: e1 × e2 = (0, 0, 2^60 − (2^60 − 1)) = (0, 0, 1), but in f64 2^60 − 1 rounds to
        // 2^60 and the filtered value is 0: only the exact fallback can answer.
        let e1 = [big, 1, 0];
        let e2 = [big - 1, 1, 0];
        assert_eq!(W128::orient3d_sign([0, 0, 1], e1, e2), 1);
        assert_eq!(W128::orient3d_sign([5, -7, -1], e1, e2), -1);
        assert_eq!(W128::orient3d_sign([big, big, 0], e1, e2), 0);
        // Both widths agree with the exact sign on small random inputs (filter decides).
        let mut state = 7_u64;
        let mut next = || {
            state = state
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            ((state >> 33) % 9) as i64 - 4
        };
        for _ in 0..2000 {
            let d = [next(), next(), next()];
            let e1 = [next(), next(), next()];
            let e2 = [next(), next(), next()];
            let want = exact_dot3_sign(d, cross_exact(e1, e2));
            assert_eq!(exact_dot3_sign_big(d, cross_exact(e1, e2)), want);
            assert_eq!(W64::orient3d_sign(d, e1, e2), want);
            assert_eq!(W128::orient3d_sign(d, e1, e2), want);
        }
    }

    #[test]
    fn ray_hits_interior_and_counts_shared_vertices_once() {
        // Two triangles sharing the edge (0,0)-(4,4) at height 1, normals +z; q below the
        // shared edge's midpoint: the perturbation assigns the ray to exactly one of them.
        let q = [2, 2, -3];
        let t1 = [[0, 0, 1], [4, 0, 1], [4, 4, 1]];
        let t2 = [[0, 0, 1], [4, 4, 1], [0, 4, 1]];
        let c = ray_crossing::<W64>(q, t1) + ray_crossing::<W64>(q, t2);
        assert_eq!(c, 1);
        // Through the shared vertex of a fan of 4 triangles around (0,0): exactly one hit.
        let fan = [
            [[0, 0, 1], [2, 0, 1], [0, 2, 1]],
            [[0, 0, 1], [0, 2, 1], [-2, 0, 1]],
            [[0, 0, 1], [-2, 0, 1], [0, -2, 1]],
            [[0, 0, 1], [0, -2, 1], [2, 0, 1]],
        ];
        let c: i32 = fan
            .iter()
            .map(|&t| ray_crossing::<W128>([0, 0, 0], t))
            .sum();
        assert_eq!(c, 1);
        // Query above the plane: no hit; flipped triangle: −1.
        assert_eq!(ray_crossing::<W64>([1, 1, 5], t1), 0);
        assert_eq!(ray_crossing::<W64>([3, 1, 0], [t1[0], t1[2], t1[1]]), -1);
        // Query exactly on the triangle: decided by ε (n_x = n_y = 0, n_z > 0 ⇒ above).
        assert_eq!(ray_crossing::<W64>([3, 1, 1], t1), 0);
    }

    #[test]
    fn inside_segment_detection() {
        assert!(query_inside_segment([1, 1, 1], [0, 0, 0], [2, 2, 2]));
        assert!(!query_inside_segment([3, 3, 3], [0, 0, 0], [2, 2, 2]));
        assert!(query_inside_segment([0, 0, 0], [0, 0, 0], [5, 0, 0]));
        assert!(!query_inside_segment([0, 0, 0], [0, 0, 0], [-5, 0, 0]));
        assert!(query_inside_segment([0, 0, 0], [5, 0, 0], [0, 0, 0]));
    }
}
