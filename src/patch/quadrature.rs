//! Adaptive Gauss–Kronrod (7/15 points) on an interval, with an error estimate (the paper's
//! `AdaptiveGaussKronrod15`, Alg. 2).

use crate::base::compensated::NeumaierSum;

/// Kronrod nodes on `[-1, 1]` (non-negative half; the rule is symmetric), QUADPACK `qk15`.
const XGK: [f64; 8] = [
    0.991_455_371_120_812_6,
    0.949_107_912_342_758_5,
    0.864_864_423_359_769_1,
    0.741_531_185_599_394_4,
    0.586_087_235_467_691_1,
    0.405_845_151_377_397_2,
    0.207_784_955_007_898_5,
    0.0,
];
/// Kronrod weights for [`XGK`].
const WGK: [f64; 8] = [
    0.022_935_322_010_529_22,
    0.063_092_092_629_978_55,
    0.104_790_010_322_250_2,
    0.140_653_259_715_525_9,
    0.169_004_726_639_267_9,
    0.190_350_578_064_785_4,
    0.204_432_940_075_298_9,
    0.209_482_141_084_727_8,
];
/// Gauss weights for the odd-indexed Kronrod nodes `XGK[1], XGK[3], XGK[5], XGK[7]`.
const WG: [f64; 4] = [
    0.129_484_966_168_869_7,
    0.279_705_391_489_276_7,
    0.381_830_050_505_118_9,
    0.417_959_183_673_469_4,
];

/// For each of the 15 nodes of [`gauss_kronrod_nodes`], its index among the 7 Gauss nodes.
pub const XG_INDEX: [Option<usize>; 15] = [
    None,
    Some(0),
    None,
    Some(1),
    None,
    Some(2),
    None,
    Some(3),
    None,
    Some(2),
    None,
    Some(1),
    None,
    Some(0),
    None,
];

/// The 15 Kronrod nodes on `[-1, 1]` in increasing order, their weights, and the 7 Gauss
/// weights (indexed by [`XG_INDEX`]).
pub fn gauss_kronrod_nodes() -> ([f64; 15], [f64; 15], [f64; 4]) {
    let mut x = [0.0; 15];
    let mut w = [0.0; 15];
    for i in 0..8 {
        x[i] = -XGK[i];
        w[i] = WGK[i];
        x[14 - i] = XGK[i];
        w[14 - i] = WGK[i];
    }
    (x, w, WG)
}

/// Bisection depth limit: an interval of length `2^-50` is below `f64` resolution of `[0, 1]`.
const MAX_DEPTH: u32 = 50;

/// Integrand evaluations of one 15-point Kronrod rule.
pub const GK_EVALUATIONS: usize = 15;

/// The result of an adaptive integration.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Integral {
    /// The integral (sum of the accepted Kronrod values).
    pub value: f64,
    /// Sum over the accepted intervals of `max(|K15 − G7|, rounding bound)`; an upper estimate
    /// of the error of the value when the integrand is resolved (the Kronrod value is far more
    /// accurate than G7).
    pub error: f64,
    /// Integrand evaluations.
    pub evaluations: usize,
    /// Intervals accepted because the evaluation budget ran out (not because they converged).
    pub capped: usize,
}

/// A shared cap on the integrand evaluations of one query. Once `remaining` is 0 no interval is
/// bisected any more; each interval already pending (at most one per level, 51) still gets one
/// 15-point rule, so the work of a query is bounded by the budget plus `15 · 51` evaluations per
/// integral.
#[derive(Clone, Copy, Debug)]
pub struct Budget {
    /// Evaluations left.
    pub remaining: usize,
}

/// One 15-point Kronrod and embedded 7-point Gauss value on `[a, b]`, the Kronrod value of
/// `|f|` (the scale of the rounding in the sums) and the Kronrod value of the integrand's own
/// rounding bound (`f` returns `(value, bound on its rounding error)`).
#[inline]
pub fn gk15(f: &mut impl FnMut(f64) -> (f64, f64), a: f64, b: f64) -> (f64, f64, f64, f64) {
    let c = 0.5 * (a + b);
    let h = 0.5 * (b - a);
    let (fc, nc) = f(c);
    let mut k = WGK[7] * fc;
    let mut g = WG[3] * fc;
    let mut kabs = WGK[7] * fc.abs();
    let mut noise = WGK[7] * nc;
    for i in 0..7 {
        let x = h * XGK[i];
        let ((fl, nl), (fr, nr)) = (f(c - x), f(c + x));
        k += WGK[i] * (fl + fr);
        kabs += WGK[i] * (fl.abs() + fr.abs());
        noise += WGK[i] * (nl + nr);
        if i % 2 == 1 {
            g += WG[i / 2] * (fl + fr);
        }
    }
    (k * h, g * h, kabs * h.abs(), noise * h.abs())
}

/// `|K15 − G7|` below this multiple of `ε·∫|f|` is rounding in the sums, not truncation:
/// splitting further cannot reduce it (without this floor a tolerance below rounding bisects to
/// the depth limit everywhere).
const ROUNDING_FLOOR: f64 = 50.0 * f64::EPSILON;

/// `|K15 − G7|` below this multiple of the integrand's own rounding bound (integrated) is
/// noise in the integrand values: near a point where the curve passes `ρ` from the query, the
/// values carry a relative error `≈ ε·|control points|/ρ`, far above `ε`, and G7 and K15 sample
/// that noise at different nodes. Bisecting cannot reduce it either; before this floor such
/// intervals bisected to depth 50 in every direction (2^30 intervals for an edge 1e-6 from the
/// query, issue 23). The factor 2 allows for the noise of both rules.
const NOISE_FLOOR: f64 = 2.0;

/// `∫_a^b f` to absolute tolerance `tol` by adaptive bisection. `f` returns the integrand and
/// a bound on its rounding error. An interval is accepted when `|K15 − G7| ≤ tol · length /
/// (b − a)` (so the accepted errors sum to at most `tol`), when the difference is at the
/// rounding level of the interval (of the sums or of the integrand), at the depth limit, or
/// when `budget` is spent; the reported error of an interval is `max(|K15 − G7|, its rounding
/// bound)`, so it is honest also where the tolerance was not reached.
pub fn integrate(
    mut f: impl FnMut(f64) -> (f64, f64),
    a: f64,
    b: f64,
    tol: f64,
    budget: &mut Budget,
) -> Integral {
    let total = b - a;
    let mut value = NeumaierSum::new();
    let mut error = 0.0;
    let mut evaluations = 0;
    let mut capped = 0;
    let mut stack = vec![(a, b, 0u32)];
    while let Some((lo, hi, depth)) = stack.pop() {
        let (k, g, kabs, noise) = gk15(&mut f, lo, hi);
        evaluations += GK_EVALUATIONS;
        budget.remaining = budget.remaining.saturating_sub(GK_EVALUATIONS);
        let err = (k - g).abs();
        let rounding = (ROUNDING_FLOOR * kabs).max(NOISE_FLOOR * noise);
        let allowed = (tol * ((hi - lo) / total)).max(rounding);
        let out_of_budget = budget.remaining == 0;
        if err <= allowed || depth >= MAX_DEPTH || !err.is_finite() || out_of_budget {
            if out_of_budget && err > allowed {
                capped += 1;
            }
            value.add(k);
            error += err.max(rounding);
        } else {
            let mid = 0.5 * (lo + hi);
            stack.push((mid, hi, depth + 1));
            stack.push((lo, mid, depth + 1));
        }
    }
    Integral {
        value: value.value(),
        error,
        evaluations,
        capped,
    }
}

/// The sums of one 15-point rule on an interval of half-length `h`, from the integrand values
/// `f` and rounding bounds `noise` at the nodes of [`gauss_kronrod_nodes`] (increasing order):
/// `(K15, G7, K15 of |f|, K15 of the rounding bound)`, as [`gk15`] returns them. For callers
/// that evaluate the 15 nodes in one vectorisable loop (`super::samples`).
#[inline]
pub fn gk15_sums(f: &[f64; 15], noise: &[f64; 15], h: f64) -> (f64, f64, f64, f64) {
    // The same summation order as `gk15` (centre, then symmetric pairs outwards-in).
    let mut k = WGK[7] * f[7];
    let mut g = WG[3] * f[7];
    let mut kabs = WGK[7] * f[7].abs();
    let mut nsum = WGK[7] * noise[7];
    for i in 0..7 {
        let (fl, fr) = (f[i], f[14 - i]);
        k += WGK[i] * (fl + fr);
        kabs += WGK[i] * (fl.abs() + fr.abs());
        nsum += WGK[i] * (noise[i] + noise[14 - i]);
        if i % 2 == 1 {
            g += WG[i / 2] * (fl + fr);
        }
    }
    (k * h, g * h, kabs * h.abs(), nsum * h.abs())
}

/// [`integrate`] over the dyadic interval `[index·2^-level, (index+1)·2^-level]` of `[0, 1]`,
/// with the 15-point rule of each (dyadic) sub-interval supplied by `rule(level, index)` as
/// [`gk15_sums`] returns it. The same acceptance tests as [`integrate`] (tolerance shared by
/// length, rounding floors, depth limit [`MAX_DEPTH`] below the root, budget); knowing an
/// interval by its level and index lets `rule` read precomputed samples.
pub fn integrate_dyadic(
    mut rule: impl FnMut(u32, u64) -> (f64, f64, f64, f64),
    level: u32,
    index: u64,
    tol: f64,
    budget: &mut Budget,
) -> Integral {
    let mut value = NeumaierSum::new();
    let mut error = 0.0;
    let mut evaluations = 0;
    let mut capped = 0;
    // Depth first: at most one pending interval per level below the root, plus the root.
    let mut stack = [(0u32, 0u64); MAX_DEPTH as usize + 2];
    stack[0] = (level, index);
    let mut pending = 1;
    while pending > 0 {
        pending -= 1;
        let (l, i) = stack[pending];
        let (k, g, kabs, noise) = rule(l, i);
        evaluations += GK_EVALUATIONS;
        budget.remaining = budget.remaining.saturating_sub(GK_EVALUATIONS);
        let err = (k - g).abs();
        let rounding = (ROUNDING_FLOOR * kabs).max(NOISE_FLOOR * noise);
        // This interval's share of the root's tolerance: its length relative to the root's.
        let share = 0.5f64.powi((l - level) as i32);
        let allowed = (tol * share).max(rounding);
        let out_of_budget = budget.remaining == 0;
        if err <= allowed || l - level >= MAX_DEPTH || !err.is_finite() || out_of_budget {
            if out_of_budget && err > allowed {
                capped += 1;
            }
            value.add(k);
            error += err.max(rounding);
        } else {
            stack[pending] = (l + 1, 2 * i + 1);
            stack[pending + 1] = (l + 1, 2 * i);
            pending += 2;
        }
    }
    Integral {
        value: value.value(),
        error,
        evaluations,
        capped,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn weights_and_polynomial_exactness() {
        let sk: f64 = 2.0 * WGK[..7].iter().sum::<f64>() + WGK[7];
        let sg: f64 = 2.0 * WG[..3].iter().sum::<f64>() + WG[3];
        assert!((sk - 2.0).abs() < 1e-15 && (sg - 2.0).abs() < 1e-15);
        // K15 is exact to degree 22, G7 to degree 13.
        let (k, g, _, _) = gk15(&mut |x: f64| (x.powi(22), 0.0), 0.0, 1.0);
        assert!((k - 1.0 / 23.0).abs() < 1e-15);
        assert!((g - 1.0 / 23.0).abs() > 1e-8);
        let (k, g, _, _) = gk15(&mut |x: f64| (x.powi(13), 0.0), -1.0, 2.0);
        let exact = (2f64.powi(14) - 1.0) / 14.0;
        assert!((k - exact).abs() < 1e-11 && (g - exact).abs() < 1e-11);
    }

    #[test]
    fn adaptive_resolves_a_peak_and_reports_its_error() {
        // ∫_0^1 δ/(x² + δ²) dx = atan(1/δ): a peak of width 1e-6 at the end.
        let d = 1e-6;
        let mut budget = Budget { remaining: 1 << 20 };
        let r = integrate(|x| (d / (x * x + d * d), 0.0), 0.0, 1.0, 1e-12, &mut budget);
        assert!((r.value - (1.0 / d).atan()).abs() < 1e-11, "{r:?}");
        assert!(r.error < 1e-11 && r.capped == 0);
    }

    #[test]
    fn noisy_integrand_stops_at_its_noise_and_reports_it() {
        // A peak whose values carry relative noise 1e-8 (as a curve 1e-8 from the query does):
        // without the noise floor every interval near the peak bisects to depth 50.
        let d = 1e-6;
        let mut state = 1u64;
        let mut budget = Budget { remaining: 1 << 24 };
        let r = integrate(
            |x| {
                state = state.wrapping_mul(6364136223846793005).wrapping_add(1);
                let jitter = (state >> 11) as f64 / (1u64 << 53) as f64 - 0.5;
                let f = d / (x * x + d * d);
                (f * (1.0 + 1e-8 * jitter), 1e-8 * f.abs())
            },
            0.0,
            1.0,
            1e-14,
            &mut budget,
        );
        assert!(r.evaluations < 20_000, "{r:?}");
        assert!((r.value - (1.0 / d).atan()).abs() <= r.error, "{r:?}");
        assert!(r.error < 1e-6, "{r:?}");
    }

    #[test]
    fn budget_caps_the_work() {
        // An integrand that never converges (a jump whose position G7/K15 cannot resolve below
        // the tolerance): the budget stops it.
        // (A jump at 1/3 is bisected ~2 intervals per level down to depth 50, 1500 evaluations;
        // the budget of 300 stops it first.)
        let mut budget = Budget { remaining: 300 };
        let r = integrate(
            |x| (if x < 1.0 / 3.0 { 0.0 } else { 1e300 }, 0.0),
            0.0,
            1.0,
            1e-300,
            &mut budget,
        );
        // Past the budget each pending interval (at most one per level) gets one rule.
        assert!(r.evaluations <= 300 + 15 * 51, "{r:?}");
        assert!(r.capped > 0 && r.error > 0.0, "{r:?}");
    }
}
