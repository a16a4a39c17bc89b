//! Rational Bézier curves in homogeneous form `(w·x, w·y, w·z, w)`, expressed in the ray frame
//! relative to the query point, and the two boundary-integral potentials.
//!
//! With `r(t)` the curve relative to the query, `ρ = |r|`, and `φ` the azimuth around the ray
//! axis `+z`, the solid-angle 2-form of the unit sphere has two potentials (`docs/patches.md`):
//! - [`Form::Down`]: `α↓ = −(1 + cos θ) dφ = −(r × r')_z / (ρ (ρ − r_z)) dt`, regular except on
//!   the ray `+z` itself. It is the continuous form of the triangle kernel's edge term
//!   `Area(A, B, x1)` (paper Eq. 9, Alg. 1; `x1 = −z`), i.e. the paper's `−dη + w` of Alg. 2 for
//!   the axis field.
//! - [`Form::Up`]: `α↑ = α↓ + 2 dφ = (1 − cos θ) dφ = (r × r')_z / (ρ (ρ + r_z)) dt`, regular
//!   except on the opposite ray `−z`.
//!
//! In homogeneous coordinates `N(t) = Σ B_k(t) H_k`, `r = N_xyz / N_w`, and `r × r' = N × N' / N_w²`,
//! so both integrands are the same expressions in `N` and `N'` (the weight cancels).

/// A homogeneous control point `(w·x, w·y, w·z, w)`.
pub type Homogeneous = [f64; 4];

/// Which potential of the solid-angle form a piece of surface uses on its boundary.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum Form {
    /// `α↓`, singular only on the ray `+z` (pieces that the ray cannot meet).
    Down,
    /// `α↑ = α↓ + 2dφ`, singular only on `−z` (pieces that `−z` cannot meet).
    Up,
}

/// `N(t)` and `N'(t)` by de Casteljau (the last level gives the derivative).
#[inline]
pub fn eval_with_derivative(ctrl: &[Homogeneous], t: f64) -> (Homogeneous, Homogeneous) {
    let d = ctrl.len() - 1;
    if d == 0 {
        return (ctrl[0], [0.0; 4]);
    }
    let mut buf = [[0.0f64; 4]; super::model::MAX_DEGREE + 1];
    buf[..=d].copy_from_slice(ctrl);
    let s = 1.0 - t;
    for level in 1..d {
        for i in 0..=(d - level) {
            for c in 0..4 {
                buf[i][c] = s * buf[i][c] + t * buf[i + 1][c];
            }
        }
    }
    let (a, b) = (buf[0], buf[1]);
    let df = d as f64;
    let mut n = [0.0; 4];
    let mut dn = [0.0; 4];
    for c in 0..4 {
        n[c] = s * a[c] + t * b[c];
        dn[c] = df * (b[c] - a[c]);
    }
    (n, dn)
}

/// The integrand of `form` at `N`, `N'` (see the module docs). Zero where the curve passes
/// through the query (`ρ = 0`: the query is on the boundary, where `w` is undefined) and, as a
/// guard, on the form's singular ray (which the callers' certificates exclude).
#[inline]
pub fn integrand(form: Form, n: Homogeneous, dn: Homogeneous) -> f64 {
    integrand_with_rounding(form, n, dn, 0.0, 0.0).0
}

/// Relative rounding of one de Casteljau level (a convex combination: two products and a sum).
const CASTELJAU_LEVEL_ROUNDING: f64 = 3.0 * f64::EPSILON;

/// Bounds on the rounding error of `N` and of `N'` (each component) as evaluated by
/// [`eval_with_derivative`] on `ctrl` (degree `d`): `d` convex-combination levels, each adding
/// at most [`CASTELJAU_LEVEL_ROUNDING`] times the largest control coordinate `M`; the
/// derivative `d·(b − a)` amplifies the error of its two points by `2d`.
pub fn evaluation_rounding(ctrl: &[Homogeneous]) -> (f64, f64) {
    let d = (ctrl.len() - 1) as f64;
    let m = ctrl.iter().fold(0.0f64, |a, h| {
        a.max(h[0].abs()).max(h[1].abs()).max(h[2].abs())
    });
    let e = (d + 1.0) * CASTELJAU_LEVEL_ROUNDING * m;
    (e, 2.0 * d.max(1.0) * e + CASTELJAU_LEVEL_ROUNDING * d * m)
}

/// The integrand of `form` and a bound on its rounding error, given bounds `en`, `edn` on the
/// error of each component of `N`, `N'` (from [`evaluation_rounding`]). The error propagates as
/// `δ(num)/den + |f|·(δρ/ρ + δ(ρ ∓ z)/(ρ ∓ z))` with `num = (N × N')_z`; near a point where the
/// curve passes `ρ` from the query this is `≈ ε·M/ρ` relative, which is why the quadrature needs
/// it (see `quadrature::NOISE_FLOOR`).
#[inline]
pub fn integrand_with_rounding(
    form: Form,
    n: Homogeneous,
    dn: Homogeneous,
    en: f64,
    edn: f64,
) -> (f64, f64) {
    let cross_z = n[0] * dn[1] - n[1] * dn[0];
    let xy2 = n[0] * n[0] + n[1] * n[1];
    let rho = (xy2 + n[2] * n[2]).sqrt();
    // ρ ∓ z without cancellation: when the subtraction would cancel, use ρ² − z² = x² + y².
    let (num_sign, z) = match form {
        Form::Down => (-1.0, n[2]),
        Form::Up => (1.0, -n[2]),
    };
    let rho_minus_z = if z <= 0.0 { rho - z } else { xy2 / (rho + z) };
    let den = rho * rho_minus_z;
    if den == 0.0 || !den.is_finite() {
        return (0.0, 0.0);
    }
    let f = num_sign * cross_z / den;
    let dn_abs = dn[0].abs().max(dn[1].abs());
    let n_abs = n[0].abs().max(n[1].abs());
    let num_err = 2.0 * (en * dn_abs + n_abs * edn);
    // √3·en bounds the error of ρ; ρ ∓ z moves by at most twice that.
    let noise =
        num_err / den + f.abs() * (1.8 * en / rho + 3.5 * en / rho_minus_z + 8.0 * f64::EPSILON);
    (f, noise)
}

/// The box of a curve's Euclidean control points (the curve lies in it: convex-hull property).
pub fn control_box(ctrl: &[Homogeneous]) -> ([f64; 3], [f64; 3]) {
    let mut lo = [f64::INFINITY; 3];
    let mut hi = [f64::NEG_INFINITY; 3];
    for h in ctrl {
        for a in 0..3 {
            let x = h[a] / h[3];
            lo[a] = lo[a].min(x);
            hi[a] = hi[a].max(x);
        }
    }
    (lo, hi)
}

/// Distance from the origin (the query, in query-centred coordinates) to [`control_box`]: a
/// lower bound on the curve's distance.
pub fn distance_to_control_box(ctrl: &[Homogeneous]) -> f64 {
    let (lo, hi) = control_box(ctrl);
    let mut d2 = 0.0;
    for a in 0..3 {
        let gap = lo[a].max(-hi[a]).max(0.0);
        d2 += gap * gap;
    }
    d2.sqrt()
}

/// Splits a curve at `t = 1/2` (de Casteljau). The two halves share the middle point bit for bit.
pub fn split_half(ctrl: &[Homogeneous]) -> (Vec<Homogeneous>, Vec<Homogeneous>) {
    let d = ctrl.len() - 1;
    let mut work = ctrl.to_vec();
    let mut left = Vec::with_capacity(d + 1);
    let mut right = Vec::with_capacity(d + 1);
    left.push(work[0]);
    right.push(work[d]);
    for level in 1..=d {
        for i in 0..=(d - level) {
            for c in 0..4 {
                work[i][c] = 0.5 * (work[i][c] + work[i + 1][c]);
            }
        }
        left.push(work[0]);
        right.push(work[d - level]);
    }
    right.reverse();
    (left, right)
}

/// [`split_half`] of the `d + 1` points `get(0..=d)` without allocating: `put(i, left_i,
/// right_i)` receives the halves' control points, bit for bit those of [`split_half`] (the same
/// operations in the same order). For halving the rows and columns of a net in place.
#[inline]
pub fn split_half_with(
    d: usize,
    get: impl Fn(usize) -> Homogeneous,
    mut put: impl FnMut(usize, Homogeneous, Homogeneous),
) {
    let mut work = [[0.0f64; 4]; super::model::MAX_DEGREE + 1];
    let mut left = [[0.0f64; 4]; super::model::MAX_DEGREE + 1];
    let mut right = [[0.0f64; 4]; super::model::MAX_DEGREE + 1];
    for (i, w) in work[..=d].iter_mut().enumerate() {
        *w = get(i);
    }
    left[0] = work[0];
    right[d] = work[d];
    for level in 1..=d {
        for i in 0..=(d - level) {
            for c in 0..4 {
                work[i][c] = 0.5 * (work[i][c] + work[i + 1][c]);
            }
        }
        left[level] = work[0];
        right[d - level] = work[d - level];
    }
    for i in 0..=d {
        put(i, left[i], right[i]);
    }
}

/// The eight axis and diagonal directions tried as half-plane centres.
const HALF_PLANES: [[f64; 2]; 8] = [
    [1.0, 0.0],
    [0.0, 1.0],
    [-1.0, 0.0],
    [0.0, -1.0],
    [1.0, 1.0],
    [-1.0, 1.0],
    [-1.0, -1.0],
    [1.0, -1.0],
];

/// `∫ dφ` along a curve whose convex hull (in xy) avoids the origin: the azimuth change around
/// the ray axis, in `(−π, π)` per certified piece.
///
/// A piece is certified when all its control points satisfy `h·p > 0` for one of eight
/// directions `h` whose components are 0 or ±1; `h·p` is a sum of two floats, so its sign is
/// exact. Then the curve lies in that open half-plane and its azimuth, measured from `h`, stays in
/// `(−π/2, π/2)`: the change is the difference of the end values, with no branch to choose.
/// Otherwise the curve is halved (its pieces' hulls shrink towards the curve). Returns `None` if
/// no certificate was found within the depth limit (the hull is then within rounding of the
/// origin; the callers' classification rules this out).
/// Certified pieces are `≤ 2 × depth` for a curve that approaches the axis at isolated points;
/// a curve lying along the axis would halve everywhere, so the pieces are also capped.
pub fn azimuth_change(ctrl: &[Homogeneous]) -> Option<f64> {
    let mut pieces = 0;
    azimuth_change_at(ctrl, 0, &mut pieces)
}

/// Halving depth of [`azimuth_change`] (a piece `2^-40` of the curve).
const AZIMUTH_MAX_DEPTH: u32 = 40;
/// Pieces [`azimuth_change`] may examine before it gives up (returns `None`).
const AZIMUTH_MAX_PIECES: usize = 1024;

fn azimuth_change_at(ctrl: &[Homogeneous], depth: u32, pieces: &mut usize) -> Option<f64> {
    *pieces += 1;
    for h in HALF_PLANES {
        let inside = ctrl.iter().all(|p| h[0] * p[0] + h[1] * p[1] > 0.0);
        if inside {
            let azimuth = |p: &Homogeneous| {
                let along = h[0] * p[0] + h[1] * p[1];
                let across = h[0] * p[1] - h[1] * p[0];
                across.atan2(along)
            };
            return Some(azimuth(&ctrl[ctrl.len() - 1]) - azimuth(&ctrl[0]));
        }
    }
    if depth >= AZIMUTH_MAX_DEPTH || *pieces >= AZIMUTH_MAX_PIECES {
        return None;
    }
    let (a, b) = split_half(ctrl);
    Some(azimuth_change_at(&a, depth + 1, pieces)? + azimuth_change_at(&b, depth + 1, pieces)?)
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::f64::consts::{FRAC_1_SQRT_2, FRAC_PI_2, PI};

    /// The quarter circle from (1,0) to (0,1) at height z, as a rational quadratic.
    fn quarter(z: f64) -> Vec<Homogeneous> {
        let w = FRAC_1_SQRT_2;
        vec![[1.0, 0.0, z, 1.0], [w, w, w * z, w], [0.0, 1.0, z, 1.0]]
    }

    #[test]
    fn rational_quarter_circle_is_exact() {
        for t in [0.0, 0.1, 0.5, 0.77, 1.0] {
            let (n, dn) = eval_with_derivative(&quarter(0.0), t);
            let (x, y) = (n[0] / n[3], n[1] / n[3]);
            assert!((x * x + y * y - 1.0).abs() < 1e-15);
            // r × r' has z component (N × N')_z / W², positive (counterclockwise).
            assert!(n[0] * dn[1] - n[1] * dn[0] > 0.0);
        }
        let (l, r) = split_half(&quarter(0.3));
        assert_eq!(l[2], r[0]);
        let m = eval_with_derivative(&quarter(0.3), 0.5).0;
        for c in 0..4 {
            assert!((l[2][c] - m[c]).abs() < 1e-16);
        }
    }

    #[test]
    fn potentials_integrate_to_the_cap_areas() {
        // A circle of latitude seen from its axis at height z: ∮ dφ = 2π, the cap below it
        // (towards −z) has area 2π(1 + cos θ), above 2π(1 − cos θ).
        let z: f64 = 0.6;
        let cos = z / (1.0 + z * z).sqrt();
        let mut down = 0.0;
        let mut up = 0.0;
        let mut turn = 0.0;
        for k in 0..4 {
            let c: Vec<Homogeneous> = quarter(z)
                .iter()
                .map(|p| {
                    // rotate by k quarter turns
                    let (mut x, mut y) = (p[0], p[1]);
                    for _ in 0..k {
                        (x, y) = (-y, x);
                    }
                    [x, y, p[2], p[3]]
                })
                .collect();
            let f = |form| {
                crate::patch::quadrature::integrate(
                    |t| {
                        let (n, dn) = eval_with_derivative(&c, t);
                        (integrand(form, n, dn), 0.0)
                    },
                    0.0,
                    1.0,
                    1e-14,
                    &mut crate::patch::quadrature::Budget { remaining: 1 << 20 },
                )
                .value
            };
            down += f(Form::Down);
            up += f(Form::Up);
            turn += azimuth_change(&c).unwrap();
        }
        assert!((turn - 2.0 * PI).abs() < 1e-14);
        assert!((down + 2.0 * PI * (1.0 + cos)).abs() < 1e-12, "{down}");
        assert!((up - 2.0 * PI * (1.0 - cos)).abs() < 1e-12, "{up}");
        assert!((up - down - 2.0 * turn).abs() < 1e-12);
        assert!((azimuth_change(&quarter(0.0)).unwrap() - FRAC_PI_2).abs() < 1e-15);
    }

    #[test]
    fn split_half_with_is_split_half_bit_for_bit() {
        let c: Vec<Homogeneous> = (0..5)
            .map(|i| {
                let x = i as f64;
                [0.1 * x.sin(), 0.3 + x.cos() / 7.0, x / 3.0, 1.0 + 0.1 * x]
            })
            .collect();
        let (l, r) = split_half(&c);
        let mut l2 = vec![[0.0; 4]; 5];
        let mut r2 = vec![[0.0; 4]; 5];
        split_half_with(
            4,
            |i| c[i],
            |i, a, b| {
                l2[i] = a;
                r2[i] = b;
            },
        );
        assert_eq!((l, r), (l2, r2));
    }

    #[test]
    fn azimuth_change_halves_until_certified() {
        // A segment passing 1e-13 beside the origin: no axis half-plane holds the whole
        // segment, its halves are certified, and the change is nearly +π.
        let seg = vec![[1.0, 1e-13, 0.0, 1.0], [-1.0, 1e-13, 0.0, 1.0]];
        let a = azimuth_change(&seg).unwrap();
        assert!((a - PI).abs() < 1e-12 && a < PI, "{a}");
        let below = vec![[1.0, -1e-13, 0.0, 1.0], [-1.0, -1e-13, 0.0, 1.0]];
        assert!((azimuth_change(&below).unwrap() + PI).abs() < 1e-12);
        let through = vec![[1.0, 0.0, 0.0, 1.0], [-1.0, 0.0, 0.0, 1.0]];
        assert_eq!(azimuth_change(&through), None);
    }
}
