//! Normal distribution functions: the 1D CDF (via `erfc`) and the bivariate normal CDF
//! `BvN(h, k; ρ) = P(X ≤ h, Y ≤ k)` for standard normals with correlation ρ, with two back ends
//! behind [`BvnMethod`]:
//!
//! - [`BvnMethod::Precise`] (default): Drezner–Wesolowsky as refined by Genz. For |ρ| < 0.925,
//!   Gauss–Legendre quadrature of the arcsine form
//!   `P(X > h, Y > k) = Φ(−h)Φ(−k) + (1/2π) ∫₀^{asin ρ} exp(−(h² + k² − 2hk sin θ)/(2cos²θ)) dθ`
//!   with 6, 12 or 20 points for |ρ| < 0.3, < 0.75, otherwise; for |ρ| ≥ 0.925 the integral from
//!   ρ to ±1 in the variable `√(1 − r²)` with its singular part subtracted in closed form (the
//!   asymptotic branch). Measured absolute error ≲ 1e-15 (see `docs/gauwn.md`).
//! - [`BvnMethod::Fast`]: Tsay & Ke (2023): `BvN = ∫_{−∞}^{k} φ(y) Φ((h − ρy)/√(1−ρ²)) dy` with
//!   the inner Φ replaced by `1 − ½exp(c₁z/√2 + c₂z²/2)` (z ≥ 0, mirrored for z < 0), which
//!   integrates in closed form. Absolute error ≈ 1e-3.
//!
//! Both accept `√(1 − ρ²)` separately ([`BvnMethod::cdf_with_s`]) so that callers that know it
//! exactly (nearly horizontal segments in GauWN, where ρ → ±1) lose no precision to `1 − ρ²`.

use std::f64::consts::{FRAC_1_SQRT_2, PI, SQRT_2};
use std::sync::OnceLock;

/// Standard normal density.
pub fn norm_pdf(x: f64) -> f64 {
    const INV_SQRT_2PI: f64 = 0.398_942_280_401_432_7;
    INV_SQRT_2PI * (-0.5 * x * x).exp()
}

/// Standard normal CDF `Φ(x) = ½ erfc(−x/√2)`, accurate in relative terms in both tails.
pub fn norm_cdf(x: f64) -> f64 {
    0.5 * libm::erfc(-x * FRAC_1_SQRT_2)
}

/// `Φ(b) − Φ(a)`, evaluated on the side of the upper tails when both arguments are positive, so
/// that the difference keeps its relative accuracy.
pub fn norm_cdf_diff(a: f64, b: f64) -> f64 {
    if a > 0.0 && b > 0.0 {
        norm_cdf(-a) - norm_cdf(-b)
    } else {
        norm_cdf(b) - norm_cdf(a)
    }
}

/// Which bivariate normal CDF back end to use.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum BvnMethod {
    /// Genz's Drezner–Wesolowsky algorithm (≈1e-15).
    #[default]
    Precise,
    /// Tsay & Ke's closed-form approximation (≈1e-3).
    Fast,
}

impl BvnMethod {
    /// `P(X ≤ h, Y ≤ k)` with correlation `rho ∈ [−1, 1]`.
    pub fn cdf(self, h: f64, k: f64, rho: f64) -> f64 {
        let rho = rho.clamp(-1.0, 1.0);
        let s = ((1.0 - rho) * (1.0 + rho)).sqrt();
        self.cdf_with_s(h, k, rho, s)
    }

    /// As [`BvnMethod::cdf`] with `s = √(1 − ρ²)` supplied by the caller (ρ² + s² = 1). Only
    /// `s == 0` selects the degenerate limits `X = ±Y`: a ρ that rounded to ±1 with `s > 0` is
    /// evaluated as the smooth function it is.
    pub fn cdf_with_s(self, h: f64, k: f64, rho: f64, s: f64) -> f64 {
        match self {
            BvnMethod::Precise => bvn_precise(h, k, rho, s),
            BvnMethod::Fast => bvn_fast(h, k, rho, s),
        }
    }
}

/// Gauss–Legendre rules with 6, 12 and 20 points on [−1, 1], as (positive node, weight) pairs,
/// computed once by Newton's method on the Legendre recurrence.
fn gauss_legendre() -> &'static [Vec<(f64, f64)>; 3] {
    static RULES: OnceLock<[Vec<(f64, f64)>; 3]> = OnceLock::new();
    RULES.get_or_init(|| [gl_rule(6), gl_rule(12), gl_rule(20)])
}

/// The 20-point Gauss–Legendre rule on [−1, 1] as (positive node, weight) pairs.
pub(crate) fn gauss_legendre_20() -> &'static [(f64, f64)] {
    &gauss_legendre()[2]
}

fn gl_rule(n: usize) -> Vec<(f64, f64)> {
    let mut out = Vec::with_capacity(n / 2);
    for i in 1..=n / 2 {
        let mut x = (PI * (i as f64 - 0.25) / (n as f64 + 0.5)).cos();
        let mut dp = 0.0;
        for _ in 0..100 {
            // P_n(x) and P_n'(x) by the three-term recurrence.
            let (mut p0, mut p1) = (1.0, x);
            for m in 2..=n {
                let m = m as f64;
                let p2 = ((2.0 * m - 1.0) * x * p1 - (m - 1.0) * p0) / m;
                p0 = p1;
                p1 = p2;
            }
            dp = n as f64 * (x * p1 - p0) / (x * x - 1.0);
            let dx = p1 / dp;
            x -= dx;
            if dx.abs() < 1e-17 {
                break;
            }
        }
        out.push((x, 2.0 / ((1.0 - x * x) * dp * dp)));
    }
    out
}

/// Upper orthant `P(X > h, Y > k)` (Drezner–Wesolowsky / Genz); `s = √(1 − ρ²)`.
fn bvn_upper(h: f64, k: f64, r: f64, s: f64) -> f64 {
    let rules = gauss_legendre();
    let rule = if r.abs() < 0.3 {
        &rules[0]
    } else if r.abs() < 0.75 {
        &rules[1]
    } else {
        &rules[2]
    };
    if s <= 0.0 {
        // Exact limits: X = ±Y.
        return if r > 0.0 {
            norm_cdf(-h.max(k))
        } else {
            (norm_cdf(-k) - norm_cdf(h)).max(0.0)
        };
    }
    let hk = h * k;
    if r.abs() < 0.925 {
        let hs = 0.5 * (h * h + k * k);
        let asr = r.asin();
        let mut sum = 0.0;
        for &(x, w) in rule {
            for sgn in [-1.0, 1.0] {
                let sn = (0.5 * asr * (sgn * x + 1.0)).sin();
                sum += w * ((sn * hk - hs) / ((1.0 - sn) * (1.0 + sn))).exp();
            }
        }
        return sum * asr / (4.0 * PI) + norm_cdf(-h) * norm_cdf(-k);
    }
    // |ρ| ≥ 0.925: reduce to ρ > 0 (flip Y) and integrate from ρ to 1 in the variable
    // x = √(1 − r²); the singular part of the integrand is integrated in closed form.
    let (kk, hk) = if r < 0.0 { (-k, -hk) } else { (k, hk) };
    let a_s = s * s;
    let a = s;
    let bs = (h - kk) * (h - kk);
    let c = (4.0 - hk) / 8.0;
    let d = (12.0 - hk) / 16.0;
    let mut bvn = 0.0;
    let asr = -0.5 * (bs / a_s + hk);
    if asr > -100.0 {
        bvn = a
            * asr.exp()
            * (1.0 - c * (bs - a_s) * (1.0 - d * bs / 5.0) / 3.0 + c * d * a_s * a_s / 5.0);
    }
    if -hk < 100.0 {
        let b = bs.sqrt();
        bvn -= (-0.5 * hk).exp()
            * (2.0 * PI).sqrt()
            * norm_cdf(-b / a)
            * b
            * (1.0 - c * bs * (1.0 - d * bs / 5.0) / 3.0);
    }
    let a2 = 0.5 * a;
    for &(x, w) in rule {
        for sgn in [-1.0, 1.0] {
            let t = a2 * (sgn * x + 1.0);
            let xs = t * t;
            let rs = (1.0 - xs).sqrt();
            let asr = -0.5 * (bs / xs + hk);
            if asr > -100.0 {
                bvn += a2
                    * w
                    * asr.exp()
                    * ((-hk * xs / (2.0 * (1.0 + rs) * (1.0 + rs))).exp() / rs
                        - (1.0 + c * xs * (1.0 + d * xs)));
            }
        }
    }
    bvn = -bvn / (2.0 * PI);
    if r > 0.0 {
        bvn + norm_cdf(-h.max(kk))
    } else {
        // P(X>h, Y>k) = Φ(−h) − P(X>h, −Y ≥ −k) with corr(X, −Y) = −ρ > 0.
        -bvn + (norm_cdf(-h) - norm_cdf(-kk)).max(0.0)
    }
}

/// Precise lower CDF `P(X ≤ h, Y ≤ k)`.
fn bvn_precise(h: f64, k: f64, r: f64, s: f64) -> f64 {
    if h == f64::NEG_INFINITY || k == f64::NEG_INFINITY {
        return 0.0;
    }
    if h == f64::INFINITY {
        return norm_cdf(k);
    }
    if k == f64::INFINITY {
        return norm_cdf(h);
    }
    if r == 0.0 {
        return norm_cdf(h) * norm_cdf(k);
    }
    bvn_upper(-h, -k, r, s)
}

/// Tsay & Ke's error-function approximation `erf(x) ≈ 1 − exp(c₁x + c₂x²)` for x ≥ 0.
const TK_C1: f64 = -1.095_008_147_033_3;
const TK_C2: f64 = -0.756_511_383_838_54;

/// `∫_L^U φ(y) E(±(a·y + b)) dy` with `E(t) = exp(c₁t/√2 + c₂t²/2)`, in closed form by completing
/// the square. The exponent `−y²/2 + c₁(±z)/√2 + c₂z²/2` (z = ay + b) is a concave quadratic with
/// curvature `1/v = 1 − c₂a²`; its maximum is evaluated directly at the vertex (not as
/// `c + β²v/2`), which stays accurate when `|a|, |b|` are huge (ρ → ±1).
fn tk_piece(lo: f64, hi: f64, a: f64, b: f64, sign: f64) -> f64 {
    if hi <= lo {
        return 0.0;
    }
    let v = 1.0 / (1.0 - TK_C2 * a * a);
    let sd = v.sqrt();
    // Vertex: y_m = β v with β = a(±c₁/√2 + c₂b); z_m = a y_m + b = v(±c₁a²/√2 + b).
    let ym = a * (sign * TK_C1 / SQRT_2 + TK_C2 * b) * v;
    let zm = v * (sign * TK_C1 * a * a / SQRT_2 + b);
    let em = -0.5 * ym * ym + sign * TK_C1 * zm / SQRT_2 + 0.5 * TK_C2 * zm * zm;
    em.exp() * sd * norm_cdf_diff((lo - ym) / sd, (hi - ym) / sd)
}

/// Fast lower CDF (Tsay & Ke 2023 construction, derived here in closed form).
fn bvn_fast(h: f64, k: f64, r: f64, s: f64) -> f64 {
    if h == f64::NEG_INFINITY || k == f64::NEG_INFINITY {
        return 0.0;
    }
    if h == f64::INFINITY {
        return norm_cdf(k);
    }
    if k == f64::INFINITY {
        return norm_cdf(h);
    }
    if r == 0.0 {
        return norm_cdf(h) * norm_cdf(k);
    }
    if s <= 0.0 {
        return if r > 0.0 {
            norm_cdf(h.min(k))
        } else {
            (norm_cdf(h) + norm_cdf(k) - 1.0).max(0.0)
        };
    }
    // BvN = ∫_{−∞}^{k} φ(y) Φ(a·y + b) dy with a = −ρ/s, b = h/s.
    let a = -r / s;
    let b = h / s;
    // Φ(z) ≈ 1 − ½E(z) for z ≥ 0 and ½E(−z) for z < 0, E(t) = exp(c₁t/√2 + c₂t²/2);
    // z = a·y + b changes sign at y* = −b/a = h/ρ.
    let ystar = h / r;
    let (pos_lo, pos_hi, neg_lo, neg_hi) = if a > 0.0 {
        (ystar, k, f64::NEG_INFINITY, ystar.min(k))
    } else {
        (f64::NEG_INFINITY, ystar.min(k), ystar, k)
    };
    let mut total = 0.0;
    if pos_hi > pos_lo {
        total += norm_cdf_diff(pos_lo, pos_hi) - 0.5 * tk_piece(pos_lo, pos_hi, a, b, 1.0);
    }
    if neg_hi > neg_lo {
        total += 0.5 * tk_piece(neg_lo, neg_hi, a, b, -1.0);
    }
    total.clamp(0.0, 1.0)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn gauss_legendre_integrates_polynomials() {
        for rule in gauss_legendre() {
            let n = 2 * rule.len();
            // ∫_{-1}^{1} x^{2m} = 2/(2m+1), exact up to degree 2n − 1.
            for m in 0..n {
                let exact = 2.0 / (2.0 * m as f64 + 1.0);
                let q: f64 = rule
                    .iter()
                    .map(|&(x, w)| 2.0 * w * x.powi(2 * m as i32))
                    .sum();
                assert!((q - exact).abs() < 1e-14, "n={n} m={m} {q} {exact}");
            }
        }
    }

    #[test]
    fn norm_cdf_values() {
        assert_eq!(norm_cdf(0.0), 0.5);
        assert!((norm_cdf(1.0) - 0.841_344_746_068_542_9).abs() < 3e-16);
        assert!((norm_cdf(-5.0) / 2.866_515_718_791_939e-7 - 1.0).abs() < 1e-14);
    }

    #[test]
    fn orthant_identity_both_branches() {
        for &r in &[
            -0.999_999, -0.99, -0.93, -0.8, -0.5, -0.1, 0.1, 0.5, 0.8, 0.93, 0.99, 0.999_999,
        ] {
            let exact = 0.25 + f64::asin(r) / (2.0 * PI);
            let v = BvnMethod::Precise.cdf(0.0, 0.0, r);
            assert!((v - exact).abs() < 2e-16, "rho {r}: {v} vs {exact}");
            let f = BvnMethod::Fast.cdf(0.0, 0.0, r);
            assert!((f - exact).abs() < 5e-3, "fast rho {r}: {f} vs {exact}");
        }
    }
}

#[cfg(test)]
mod reference_tests {
    use super::*;

    /// ∫_{-∞}^{k} φ(y) Φ((h − ρy)/s) dy by composite Gauss–Legendre (20 points per panel).
    pub(crate) fn bvn_reference(h: f64, k: f64, r: f64) -> f64 {
        let s = ((1.0 - r) * (1.0 + r)).sqrt();
        let lo = -40.0f64;
        let hi = k.min(40.0);
        if hi <= lo {
            return 0.0;
        }
        let panels = 4000;
        let rule = &gauss_legendre()[2];
        let w = (hi - lo) / panels as f64;
        let mut sum = crate::curve2d::gauwn::Neumaier::default();
        for p in 0..panels {
            let c = lo + (p as f64 + 0.5) * w;
            for &(x, wt) in rule {
                for sg in [-1.0, 1.0] {
                    let y = c + 0.5 * w * sg * x;
                    sum.add(0.5 * w * wt * norm_pdf(y) * norm_cdf((h - r * y) / s));
                }
            }
        }
        sum.value()
    }

    #[test]
    fn precise_matches_quadrature() {
        let mut worst: f64 = 0.0;
        let mut worst_fast: f64 = 0.0;
        let mut seed = 12345u64;
        let mut rnd = || {
            seed = seed
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            (seed >> 11) as f64 / (1u64 << 53) as f64
        };
        for _ in 0..300 {
            let h = rnd() * 8.0 - 4.0;
            let k = rnd() * 8.0 - 4.0;
            let r = (rnd() * 2.0 - 1.0) * 0.999;
            let reference = bvn_reference(h, k, r);
            let v = BvnMethod::Precise.cdf(h, k, r);
            let f = BvnMethod::Fast.cdf(h, k, r);
            worst = worst.max((v - reference).abs());
            worst_fast = worst_fast.max((f - reference).abs());
            assert!(
                (v - reference).abs() < 5e-15,
                "h {h} k {k} r {r}: {v} vs {reference}"
            );
        }
        eprintln!("precise worst {worst:e}, fast worst {worst_fast:e}");
        assert!(worst_fast < 5e-3);
    }
}
