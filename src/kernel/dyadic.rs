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
}
