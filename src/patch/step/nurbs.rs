//! NURBS to rational Bézier by knot insertion (Boehm), circular arcs as rational quadratics,
//! and small helpers on homogeneous Bézier curves.

use super::super::curve::Homogeneous;

/// Largest degree accepted for a B-spline (the patch model's limit).
pub const MAX_DEGREE: usize = super::super::model::MAX_DEGREE;
/// Largest number of control points along one parameter of a B-spline, and of knots. Bounds
/// the knot-insertion work and memory for hostile counts.
pub const MAX_CONTROL: usize = 1 << 16;

/// The full knot vector from STEP's (multiplicities, distinct knots). Checks the counts
/// against `n_ctrl` control points of degree `p`; `Err` is a message.
pub fn expand_knots(
    mults: &[i64],
    knots: &[f64],
    n_ctrl: usize,
    p: usize,
) -> Result<Vec<f64>, String> {
    if mults.len() != knots.len() {
        return Err(format!(
            "{} knot multiplicities for {} knots",
            mults.len(),
            knots.len()
        ));
    }
    if p == 0 || p > MAX_DEGREE {
        return Err(format!("degree {p} (supported: 1 to {MAX_DEGREE})"));
    }
    if n_ctrl <= p || n_ctrl > MAX_CONTROL {
        return Err(format!("{n_ctrl} control points for degree {p}"));
    }
    let mut out = Vec::new();
    for (&m, &k) in mults.iter().zip(knots) {
        if !(1..=(p as i64 + 1)).contains(&m) || !k.is_finite() {
            return Err(format!("knot {k} with multiplicity {m}"));
        }
        if out.len() + m as usize > n_ctrl + p + 1 {
            return Err("more knots than control points + degree + 1".into());
        }
        if out.last().is_some_and(|&l: &f64| l >= k) {
            return Err("knots are not increasing".into());
        }
        out.extend(std::iter::repeat_n(k, m as usize));
    }
    if out.len() != n_ctrl + p + 1 {
        return Err(format!(
            "{} knots (with multiplicity) for {} control points of degree {p}; expected {}",
            out.len(),
            n_ctrl,
            n_ctrl + p + 1
        ));
    }
    Ok(out)
}

/// Bézier extraction along one parameter. `ctrl[i]` is the `i`-th control "point" along the
/// knot direction; each is a row of homogeneous points (one for a curve, a whole row of the net
/// for a surface), all sharing the knot vector `u` (full, length `ctrl.len() + p + 1`).
/// Returns the spans `(u_lo, u_hi, p+1 rows)` of the domain `[u_p, u_{n+1}]` in order.
pub fn extract(
    p: usize,
    u: &[f64],
    ctrl: &[Vec<Homogeneous>],
) -> Vec<(f64, f64, Vec<Vec<Homogeneous>>)> {
    let mut u = u.to_vec();
    let mut ctrl = ctrl.to_vec();
    let (lo, hi) = (u[p], u[ctrl.len()]);
    // Distinct knot values in the domain, each raised to multiplicity p (Boehm insertion).
    let mut values: Vec<f64> = u.iter().copied().filter(|&k| k >= lo && k <= hi).collect();
    values.dedup();
    for &k in &values {
        loop {
            let mult = u.iter().filter(|&&x| x == k).count();
            if mult >= p {
                break;
            }
            // Span index: U_s ≤ k < U_{s+1} (the right end: U_s < k ≤ U_{s+1}).
            let s = if k < hi {
                u.iter().rposition(|&x| x <= k).unwrap_or(p)
            } else {
                u.iter().rposition(|&x| x < k).unwrap_or(p)
            };
            let width = ctrl[0].len();
            let mut next = Vec::with_capacity(ctrl.len() + 1);
            for i in 0..=ctrl.len() {
                if i + p <= s {
                    next.push(ctrl[i].clone());
                } else if i > s {
                    next.push(ctrl[i - 1].clone());
                } else {
                    let a = (k - u[i]) / (u[i + p] - u[i]);
                    let row: Vec<Homogeneous> = (0..width)
                        .map(|c| {
                            let (x, y) = (ctrl[i][c], ctrl[i - 1][c]);
                            [
                                a * x[0] + (1.0 - a) * y[0],
                                a * x[1] + (1.0 - a) * y[1],
                                a * x[2] + (1.0 - a) * y[2],
                                a * x[3] + (1.0 - a) * y[3],
                            ]
                        })
                        .collect();
                    next.push(row);
                }
            }
            u.insert(s + 1, k);
            ctrl = next;
        }
    }
    let mut out = Vec::new();
    for s in p..ctrl.len() {
        if u[s] < u[s + 1] && u[s] >= lo && u[s + 1] <= hi {
            out.push((u[s], u[s + 1], ctrl[s - p..=s].to_vec()));
        }
    }
    out
}

/// Rational quadratic arcs of the unit circle from angle `a0` to `a1` (either direction), each
/// at most 90°: per arc its three control points `(x, y)` and weights.
pub fn unit_arcs(a0: f64, a1: f64) -> Vec<[([f64; 2], f64); 3]> {
    let span = a1 - a0;
    let n = ((span.abs() / std::f64::consts::FRAC_PI_2) - 1e-9)
        .ceil()
        .max(1.0) as usize;
    (0..n)
        .map(|k| {
            let b0 = a0 + span * k as f64 / n as f64;
            let b1 = if k + 1 == n {
                a1
            } else {
                a0 + span * (k + 1) as f64 / n as f64
            };
            let half = 0.5 * (b1 - b0);
            let mid = 0.5 * (b0 + b1);
            let c = half.cos();
            [
                ([b0.cos(), b0.sin()], 1.0),
                ([mid.cos() / c, mid.sin() / c], c),
                ([b1.cos(), b1.sin()], 1.0),
            ]
        })
        .collect()
}

/// Homogeneous form of a Euclidean point with weight `w`.
pub fn hom(p: [f64; 3], w: f64) -> Homogeneous {
    [w * p[0], w * p[1], w * p[2], w]
}

/// Euclidean point of a homogeneous one.
pub fn euc(h: Homogeneous) -> [f64; 3] {
    [h[0] / h[3], h[1] / h[3], h[2] / h[3]]
}

/// The two parts of a homogeneous Bézier curve split at `tau` (de Casteljau).
pub fn split_at(ctrl: &[Homogeneous], tau: f64) -> (Vec<Homogeneous>, Vec<Homogeneous>) {
    let d = ctrl.len() - 1;
    let mut work = ctrl.to_vec();
    let mut left = vec![work[0]];
    let mut right = vec![work[d]];
    for level in 1..=d {
        for i in 0..=(d - level) {
            for c in 0..4 {
                work[i][c] = (1.0 - tau) * work[i][c] + tau * work[i + 1][c];
            }
        }
        left.push(work[0]);
        right.push(work[d - level]);
    }
    right.reverse();
    (left, right)
}

/// The part of a Bézier curve between local parameters `t0 < t1` in `[0, 1]`.
pub fn sub_curve(ctrl: &[Homogeneous], t0: f64, t1: f64) -> Vec<Homogeneous> {
    let right = if t0 > 0.0 {
        split_at(ctrl, t0).1
    } else {
        ctrl.to_vec()
    };
    if t1 < 1.0 {
        let tau = (t1 - t0) / (1.0 - t0);
        split_at(&right, tau).0
    } else {
        right
    }
}

/// The point of a homogeneous Bézier curve at `t`.
pub fn point_at(ctrl: &[Homogeneous], t: f64) -> [f64; 3] {
    euc(super::super::curve::eval_with_derivative(ctrl, t).0)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn arcs_are_on_the_circle() {
        for (a0, a1) in [(0.0, 2.0 * std::f64::consts::PI), (1.0, -2.5), (0.3, 0.4)] {
            for arc in unit_arcs(a0, a1) {
                let ctrl: Vec<Homogeneous> = arc
                    .iter()
                    .map(|(p, w)| hom([p[0], p[1], 0.0], *w))
                    .collect();
                for t in [0.0, 0.3, 0.5, 0.9] {
                    let p = point_at(&ctrl, t);
                    assert!((p[0].hypot(p[1]) - 1.0).abs() < 1e-14);
                }
            }
            let arcs = unit_arcs(a0, a1);
            let end = arcs.last().unwrap()[2].0;
            assert!((end[0] - a1.cos()).abs() < 1e-15 && (end[1] - a1.sin()).abs() < 1e-15);
        }
    }

    #[test]
    fn extraction_reproduces_the_bspline() {
        // Uniform cubic with 6 control points: 3 spans.
        let u = expand_knots(&[4, 1, 1, 4], &[0.0, 1.0, 2.0, 3.0], 6, 3).unwrap();
        let pts: Vec<Vec<Homogeneous>> = (0..6)
            .map(|i| {
                vec![hom(
                    [i as f64, ((i * i) % 5) as f64, 0.0],
                    1.0 + 0.1 * i as f64,
                )]
            })
            .collect();
        let spans = extract(3, &u, &pts);
        assert_eq!(spans.len(), 3);
        // de Boor at x = 1.5 against the extracted span [1, 2] at its middle.
        let x = 1.5;
        let mut d: Vec<Homogeneous> = (1..=4).map(|i| pts[i][0]).collect();
        let k = 4; // u[4] = 1 ≤ x < u[5] = 2
        for r in 1..=3 {
            for j in (r..=3).rev() {
                let i = j + k - 3;
                let a = (x - u[i]) / (u[i + 3 + 1 - r] - u[i]);
                for c in 0..4 {
                    d[j][c] = (1.0 - a) * d[j - 1][c] + a * d[j][c];
                }
            }
        }
        let want = euc(d[3]);
        let (lo, hi, rows) = &spans[1];
        assert_eq!((*lo, *hi), (1.0, 2.0));
        let ctrl: Vec<Homogeneous> = rows.iter().map(|r| r[0]).collect();
        let got = point_at(&ctrl, 0.5);
        for c in 0..3 {
            assert!((got[c] - want[c]).abs() < 1e-13, "{got:?} {want:?}");
        }
        assert!(expand_knots(&[4, 4], &[0.0, 1.0], 5, 3).is_err());
        assert!(expand_knots(&[4, 1, 4], &[0.0, 2.0, 1.0], 5, 3).is_err());
    }
}
