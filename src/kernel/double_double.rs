//! Double-double arithmetic (`hi + lo`, about 106 significant bits): the extended precision of the
//! few terms whose `f64` evaluation is ill-conditioned — a query within a small fraction of an
//! edge's length from that edge, where `atan2(num, den)` has both arguments cancelling (issue 11,
//! section 5). Error-free transformations after Dekker (1971) and Knuth (TAOCP 4.2.2); written
//! here because the few operations needed (no transcendental functions) do not justify a crate,
//! and Dekker's split avoids `f64::mul_add`, a slow libm call on CPUs built without FMA.

/// `hi + lo` with `|lo| ≤ ulp(hi)/2`.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct DoubleDouble {
    /// Leading part.
    pub hi: f64,
    /// Trailing part.
    pub lo: f64,
}

/// `a + b = s + e` exactly (Knuth's two-sum, any magnitudes).
#[inline]
pub fn two_sum(a: f64, b: f64) -> (f64, f64) {
    let s = a + b;
    let bp = s - a;
    let ap = s - bp;
    (s, (a - ap) + (b - bp))
}

/// Dekker's split of `a` into two halves of 26 bits each (`a = hi + lo` exactly).
#[inline]
fn split(a: f64) -> (f64, f64) {
    const SPLITTER: f64 = 134_217_729.0; // 2^27 + 1
    let t = SPLITTER * a;
    let hi = t - (t - a);
    (hi, a - hi)
}

/// `a·b = p + e` exactly (Dekker's two-product; inputs below `2^996` so the split cannot
/// overflow — the callers work in grid units or on unit vectors).
#[inline]
pub fn two_prod(a: f64, b: f64) -> (f64, f64) {
    let p = a * b;
    let (ah, al) = split(a);
    let (bh, bl) = split(b);
    (p, ((ah * bh - p) + ah * bl + al * bh) + al * bl)
}

impl DoubleDouble {
    /// The value `x` exactly.
    #[inline]
    pub fn from_f64(x: f64) -> Self {
        DoubleDouble { hi: x, lo: 0.0 }
    }

    /// An integer exactly (`|v| < 2^63`: the remainder after rounding to `f64` has < 11 bits).
    #[inline]
    pub fn from_i64(v: i64) -> Self {
        let hi = v as f64;
        // `hi` is within 2^10 of `v`, and `v − hi` is computed in i128 without overflow.
        let lo = (i128::from(v) - hi as i128) as f64;
        DoubleDouble { hi, lo }
    }

    /// `a − b` exactly.
    #[inline]
    pub fn diff(a: f64, b: f64) -> Self {
        let (hi, lo) = two_sum(a, -b);
        DoubleDouble { hi, lo }
    }

    #[inline]
    fn renormalize(hi: f64, lo: f64) -> Self {
        let (hi, lo) = two_sum(hi, lo);
        DoubleDouble { hi, lo }
    }

    /// `√self` for `self ≥ 0` (one Newton step from the `f64` root).
    #[inline]
    pub fn sqrt(self) -> Self {
        if self.hi <= 0.0 {
            return Self::default();
        }
        let s = self.hi.sqrt();
        let (p, e) = two_prod(s, s);
        let r = (self.hi - p - e + self.lo) / (2.0 * s);
        Self::renormalize(s, r)
    }

    /// The nearest `f64`.
    #[inline]
    pub fn value(self) -> f64 {
        self.hi + self.lo
    }
}

impl std::ops::Add for DoubleDouble {
    type Output = Self;
    #[inline]
    fn add(self, o: Self) -> Self {
        let (s, e) = two_sum(self.hi, o.hi);
        let (t, f) = two_sum(self.lo, o.lo);
        let (s, e) = two_sum(s, e + t);
        Self::renormalize(s, e + f)
    }
}

impl std::ops::Neg for DoubleDouble {
    type Output = Self;
    #[inline]
    fn neg(self) -> Self {
        DoubleDouble {
            hi: -self.hi,
            lo: -self.lo,
        }
    }
}

impl std::ops::Sub for DoubleDouble {
    type Output = Self;
    #[inline]
    fn sub(self, o: Self) -> Self {
        self + (-o)
    }
}

impl std::ops::Mul for DoubleDouble {
    type Output = Self;
    #[inline]
    fn mul(self, o: Self) -> Self {
        let (p, e) = two_prod(self.hi, o.hi);
        Self::renormalize(p, e + (self.hi * o.lo + self.lo * o.hi))
    }
}

impl std::ops::Div for DoubleDouble {
    type Output = Self;
    /// One Newton correction of the `f64` quotient.
    #[inline]
    fn div(self, o: Self) -> Self {
        let q1 = self.hi / o.hi;
        let r = self - o * Self::from_f64(q1);
        let q2 = r.hi / o.hi;
        Self::renormalize(q1, q2)
    }
}

/// `a·b` of two vectors in double-double.
#[inline]
pub fn dot3(a: &[DoubleDouble; 3], b: &[DoubleDouble; 3]) -> DoubleDouble {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn recovers_what_f64_rounds_away() {
        // (1 + 2^-40)(1 − 2^-40) − 1 = −2^-80: in f64 the product rounds to 1.
        let x = DoubleDouble::from_f64(1.0 + 2f64.powi(-40));
        let y = DoubleDouble::from_f64(1.0 - 2f64.powi(-40));
        assert_eq!((1.0 + 2f64.powi(-40)) * (1.0 - 2f64.powi(-40)) - 1.0, 0.0);
        let d = x * y - DoubleDouble::from_f64(1.0);
        assert_eq!((d.hi, d.lo), (-2f64.powi(-80), 0.0));
        // Integers beyond 2^53 are held exactly.
        let v = (1_i64 << 60) + 1;
        let dv = DoubleDouble::from_i64(v);
        assert_eq!(dv.hi as i128 + dv.lo as i128, i128::from(v));
        // √2 to ~1e-32.
        let s = DoubleDouble::from_f64(2.0).sqrt();
        let err = s * s - DoubleDouble::from_f64(2.0);
        assert!(err.hi.abs() < 1e-30, "{err:?}");
        // 1/3 to ~1e-32.
        let t = DoubleDouble::from_f64(1.0) / DoubleDouble::from_f64(3.0);
        let back = t * DoubleDouble::from_f64(3.0) - DoubleDouble::from_f64(1.0);
        assert!(back.hi.abs() < 1e-31, "{back:?}");
        // Exact differences of far-apart values.
        let d = DoubleDouble::diff(1e20, 1e-20);
        assert_eq!((d.hi, d.lo), (1e20, -1e-20));
    }
}
