//! Exact dyadic rationals `m·2^e` (big-integer significand, unbounded exponent): the number type
//! of the predicates' last resort on the input values exactly as given. Every finite `f64` is one,
//! so is a lattice coordinate plus its residual, and so is a world coordinate scaled into cell
//! units by any power of two (no underflow, unlike `f64` grid space). Only the rare fallback of
//! [`super::input_predicates`] computes with it; `i128` cannot hold these values in general (a
//! coordinate `1e-20` next to `10` needs ~120 bits, their products ~240).

use num_bigint::{BigInt, Sign};

use super::quantize::decompose;

/// The exact value `m·2^e`.
#[derive(Clone, Debug)]
pub(crate) struct Dyadic {
    m: BigInt,
    e: i64,
}

impl Dyadic {
    /// The finite `f64` `x`, exactly.
    pub(crate) fn from_f64(x: f64) -> Dyadic {
        debug_assert!(x.is_finite());
        let (m, e) = decompose(x);
        Dyadic {
            m: BigInt::from(m),
            e: i64::from(e),
        }
    }

    /// The integer `v`, exactly.
    pub(crate) fn from_int(v: i128) -> Dyadic {
        Dyadic {
            m: BigInt::from(v),
            e: 0,
        }
    }

    /// `self · 2^k`, exactly.
    pub(crate) fn scaled(self, k: i64) -> Dyadic {
        Dyadic {
            m: self.m,
            e: self.e + k,
        }
    }

    /// `−1`, `0` or `1`.
    pub(crate) fn sign(&self) -> i32 {
        match self.m.sign() {
            Sign::Plus => 1,
            Sign::Minus => -1,
            Sign::NoSign => 0,
        }
    }

    /// `⌊log2 |self|⌋`, or `None` for zero.
    pub(crate) fn exponent(&self) -> Option<i64> {
        (self.m.sign() != Sign::NoSign).then(|| self.e + self.m.bits() as i64 - 1)
    }

    /// `self · 2^-k` rounded to `f64` (relative error `≤ 2^-52`), for `|self · 2^-k| < 2^1000`;
    /// values below `2^-1000` come out as subnormals or zero. For a direction given by exact
    /// components: `k` the largest [`Dyadic::exponent`] brings it to unit size without ever
    /// overflowing, whatever the components' range.
    pub(crate) fn to_f64_scaled(&self, k: i64) -> f64 {
        let bits = self.m.bits() as i64;
        // The leading 63 bits of the significand fit an `i64` exactly; dropping the rest rounds
        // by at most one unit in the 63rd bit, then the conversion to `f64` by half an ulp.
        let drop = (bits - 63).max(0);
        let top = i64::try_from(&self.m >> drop as usize).unwrap_or(0);
        let e = self.e + drop - k;
        if e < -1100 - 63 {
            return 0.0;
        }
        super::boundary_sum::scaled_by_power_of_two(top as f64, e.min(1100))
    }

    /// `self · 2^-k` as a double-double (leading and trailing parts each rounded once: within
    /// `2^-104` relative), under the same range conditions as [`Dyadic::to_f64_scaled`].
    pub(crate) fn to_double_double_scaled(&self, k: i64) -> (f64, f64) {
        let hi = self.to_f64_scaled(k);
        let rest = self - &Dyadic::from_f64(hi).scaled(k);
        (hi, rest.to_f64_scaled(k))
    }

    /// Both significands over the smaller exponent.
    fn aligned(a: &Dyadic, b: &Dyadic) -> (BigInt, BigInt, i64) {
        if a.m.sign() == Sign::NoSign {
            return (BigInt::default(), b.m.clone(), b.e);
        }
        if b.m.sign() == Sign::NoSign {
            return (a.m.clone(), BigInt::default(), a.e);
        }
        let e = a.e.min(b.e);
        (&a.m << (a.e - e) as usize, &b.m << (b.e - e) as usize, e)
    }
}

impl std::ops::Add for &Dyadic {
    type Output = Dyadic;
    fn add(self, o: &Dyadic) -> Dyadic {
        let (a, b, e) = Dyadic::aligned(self, o);
        Dyadic { m: a + b, e }
    }
}

impl std::ops::Sub for &Dyadic {
    type Output = Dyadic;
    fn sub(self, o: &Dyadic) -> Dyadic {
        let (a, b, e) = Dyadic::aligned(self, o);
        Dyadic { m: a - b, e }
    }
}

impl std::ops::Mul for &Dyadic {
    type Output = Dyadic;
    fn mul(self, o: &Dyadic) -> Dyadic {
        Dyadic {
            m: &self.m * &o.m,
            e: self.e + o.e,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn arithmetic_is_exact_across_any_exponent_range() {
        // 1 + 2^-1074 − 1 = 2^-1074: f64 loses it, the dyadic keeps it.
        let one = Dyadic::from_f64(1.0);
        let tiny = Dyadic::from_f64(f64::from_bits(1));
        assert_eq!((&(&one + &tiny) - &one).sign(), 1);
        assert_eq!((&(&(&one + &tiny) - &one) - &tiny).sign(), 0);
        // (2^60 + 1)(2^60 − 1) − 2^120 = −1.
        let t = Dyadic::from_int(1 << 60);
        let p = &(&t + &Dyadic::from_int(1)) * &(&t - &Dyadic::from_int(1));
        assert_eq!((&p - &(&t * &t)).sign(), -1);
        // Scaling far beyond the f64 range.
        let big = Dyadic::from_f64(f64::MAX).scaled(5000);
        assert_eq!((&big - &Dyadic::from_f64(f64::MAX)).sign(), 1);
        assert_eq!(Dyadic::from_f64(-0.0).sign(), 0);
    }

    #[test]
    fn scaled_conversion_keeps_the_leading_bits_at_any_exponent() {
        assert_eq!(Dyadic::from_f64(0.0).exponent(), None);
        assert_eq!(Dyadic::from_f64(1.0).exponent(), Some(0));
        assert_eq!(Dyadic::from_f64(-3.0).exponent(), Some(1));
        assert_eq!(Dyadic::from_f64(f64::from_bits(1)).exponent(), Some(-1074));
        // A subnormal times a normal number, exactly, then back to unit size.
        let tiny = Dyadic::from_f64(3.0 * f64::from_bits(1));
        let p = &tiny * &Dyadic::from_f64(0.7);
        let k = p.exponent().unwrap();
        let x = p.to_f64_scaled(k);
        assert!((1.0..2.0).contains(&x));
        assert!((x - 2.1 / 2.0).abs() < 1e-15, "{x}");
        // More than 63 significant bits, negative: rounded to within 2^-52.
        let wide = &(&Dyadic::from_int(-(1 << 100)) - &Dyadic::from_int(12345)) * &tiny;
        let k = wide.exponent().unwrap();
        assert!((wide.to_f64_scaled(k) + 1.5).abs() < 1e-15);
        // Double-double: the trailing part holds the bits past the leading 53.
        let (hi, lo) = wide.to_double_double_scaled(k);
        let exact = &Dyadic::from_f64(hi).scaled(k) + &Dyadic::from_f64(lo).scaled(k);
        let err = (&wide - &exact).to_f64_scaled(k);
        assert!(lo != 0.0 && err.abs() < 1e-30, "{lo:e} {err:e}");
        // Far below the unit: zero, not a panic.
        assert_eq!(tiny.to_f64_scaled(2000), 0.0);
        assert_eq!(Dyadic::from_f64(0.0).to_f64_scaled(0), 0.0);
    }
}
