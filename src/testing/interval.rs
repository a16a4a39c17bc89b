//! Minimal outward-rounded interval arithmetic on `f64`.
//!
//! IEEE 754 `+ − × ÷ √` are correctly rounded (round to nearest), so the exact result of one
//! operation on representable inputs lies in `[next_down(r), next_up(r)]` of the rounded result
//! `r` (also under overflow to ±∞ and underflow to 0). Every operation below widens its result by
//! that one step on each side, which makes every interval a rigorous enclosure of the exact
//! real value. The only non-IEEE function is `atan2` ([`atan2_hull`]), see there.

use num_bigint::{BigInt, Sign};

/// A closed interval `[lo, hi]` enclosing an exact real number.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Iv {
    /// Lower bound.
    pub lo: f64,
    /// Upper bound.
    pub hi: f64,
}

/// The next representable `f64` above `x` (`+∞` stays, NaN stays).
pub fn next_up(x: f64) -> f64 {
    if x.is_nan() || x == f64::INFINITY {
        return x;
    }
    if x == 0.0 {
        return f64::from_bits(1);
    }
    let b = x.to_bits();
    f64::from_bits(if x > 0.0 { b + 1 } else { b - 1 })
}

/// The next representable `f64` below `x`.
pub fn next_down(x: f64) -> f64 {
    -next_up(-x)
}

impl Iv {
    /// The exact point `x` (no widening: `x` is the exact value).
    pub fn point(x: f64) -> Iv {
        Iv { lo: x, hi: x }
    }

    /// The interval around a correctly rounded result `r`.
    fn rounded(lo: f64, hi: f64) -> Iv {
        Iv {
            lo: next_down(lo),
            hi: next_up(hi),
        }
    }

    /// Product.
    fn product(self, o: Iv) -> Iv {
        let p = [
            self.lo * o.lo,
            self.lo * o.hi,
            self.hi * o.lo,
            self.hi * o.hi,
        ];
        let lo = p.iter().copied().fold(f64::INFINITY, f64::min);
        let hi = p.iter().copied().fold(f64::NEG_INFINITY, f64::max);
        Iv::rounded(lo, hi)
    }

    /// Quotient; the whole line when the divisor's interval contains 0.
    fn quotient(self, o: Iv) -> Iv {
        if o.lo <= 0.0 && o.hi >= 0.0 {
            return Iv {
                lo: f64::NEG_INFINITY,
                hi: f64::INFINITY,
            };
        }
        let p = [
            self.lo / o.lo,
            self.lo / o.hi,
            self.hi / o.lo,
            self.hi / o.hi,
        ];
        let lo = p.iter().copied().fold(f64::INFINITY, f64::min);
        let hi = p.iter().copied().fold(f64::NEG_INFINITY, f64::max);
        Iv::rounded(lo, hi)
    }

    /// Square root of the non-negative part.
    pub fn sqrt(self) -> Iv {
        Iv {
            lo: next_down(self.lo.max(0.0).sqrt()).max(0.0),
            hi: next_up(self.hi.max(0.0).sqrt()),
        }
    }

    /// `|x|`.
    pub fn abs(self) -> Iv {
        if self.lo >= 0.0 {
            self
        } else if self.hi <= 0.0 {
            Iv {
                lo: -self.hi,
                hi: -self.lo,
            }
        } else {
            Iv {
                lo: 0.0,
                hi: (-self.lo).max(self.hi),
            }
        }
    }

    /// The smallest interval containing both.
    pub fn hull(self, o: Iv) -> Iv {
        Iv {
            lo: self.lo.min(o.lo),
            hi: self.hi.max(o.hi),
        }
    }

    /// `self · 2^k` (exact scaling, widened only for over/underflow).
    pub fn scale2(self, k: i64) -> Iv {
        let mut r = self;
        let mut k = k;
        while k != 0 {
            let step = k.clamp(-1000, 1000);
            let f = f64::from_bits(((step + 1023) as u64) << 52);
            // Exact unless bits are lost to underflow or overflow (checked by the round trip).
            let exact = |x: f64| {
                let y = x * f;
                (y.is_finite() && y / f == x).then_some(y)
            };
            r = match (exact(r.lo), exact(r.hi)) {
                (Some(lo), Some(hi)) => Iv { lo, hi },
                _ => r * Iv::point(f),
            };
            k -= step;
        }
        r
    }
}

impl std::ops::Add for Iv {
    type Output = Iv;
    /// Sum.
    fn add(self, o: Iv) -> Iv {
        Iv::rounded(self.lo + o.lo, self.hi + o.hi)
    }
}

impl std::ops::Sub for Iv {
    type Output = Iv;
    /// Difference.
    fn sub(self, o: Iv) -> Iv {
        Iv::rounded(self.lo - o.hi, self.hi - o.lo)
    }
}

impl std::ops::Mul for Iv {
    type Output = Iv;
    /// Product.
    fn mul(self, o: Iv) -> Iv {
        self.product(o)
    }
}

impl std::ops::Div for Iv {
    type Output = Iv;
    /// Quotient; the whole line when the divisor's interval contains 0.
    fn div(self, o: Iv) -> Iv {
        self.quotient(o)
    }
}

/// An enclosure of the integer `x · 2^-shift`.
pub fn big(x: &BigInt, shift: i64) -> Iv {
    let bits = x.bits() as i64;
    if bits <= 53 {
        let v = i64::try_from(x).expect("53-bit integer fits i64") as f64; // exact
        return Iv::point(v).scale2(-shift);
    }
    // |x| ∈ [y, y + 1]·2^drop with y = floor(|x| / 2^drop) < 2^60. (54 to 60 bits: drop = 0;
    // a negative drop used to shift everything out and enclose 0, which made the rational oracle
    // wrong for queries with 27–31 significant bits on small integer meshes.)
    let drop = (bits - 60).max(0);
    let y = u64::try_from(&(x.magnitude() >> (drop as usize))).expect("60-bit integer fits u64");
    let lo = Iv::rounded(y as f64, y as f64).lo;
    let hi = Iv::rounded((y + 1) as f64, (y + 1) as f64).hi;
    let m = Iv { lo, hi }.scale2(drop - shift);
    if x.sign() == Sign::Minus {
        Iv {
            lo: -m.hi,
            hi: -m.lo,
        }
    } else {
        m
    }
}

/// An enclosure of `atan2(n, d)` over the box `n × d` with `n ≥ 0` (values in `[0, π]`).
///
/// On the closed upper half-plane minus the origin `atan2` is continuous, has no critical point
/// and is monotone along every axis-parallel segment (`∂/∂n = d/r²` has the sign of `d`,
/// `∂/∂d = −n/r² ≤ 0`), so its extrema over the box are at the corners. A box containing the
/// origin gives `[0, π]`. Corner values come from the `libm` crate (a port of musl/FreeBSD msun,
/// whose `atan2` is documented with an error below 1 ulp); each is widened by 4 ulp of `π`
/// (≈ 1.8e-15) — the only assumption of this module that is not an IEEE guarantee.
pub fn atan2_hull(n: Iv, d: Iv) -> Iv {
    let pi_hi = next_up(std::f64::consts::PI);
    let n = Iv {
        lo: n.lo.max(0.0),
        hi: n.hi,
    };
    if n.lo <= 0.0 && d.lo <= 0.0 && d.hi >= 0.0 {
        return Iv { lo: 0.0, hi: pi_hi };
    }
    let c = [
        libm::atan2(n.lo, d.lo),
        libm::atan2(n.lo, d.hi),
        libm::atan2(n.hi, d.lo),
        libm::atan2(n.hi, d.hi),
    ];
    let lo = c.iter().copied().fold(f64::INFINITY, f64::min);
    let hi = c.iter().copied().fold(f64::NEG_INFINITY, f64::max);
    let slack = 4.0 * f64::EPSILON * std::f64::consts::PI;
    Iv {
        lo: (lo - slack).max(0.0),
        hi: (hi + slack).min(pi_hi),
    }
}

/// An enclosure of `π`.
pub fn pi() -> Iv {
    // The f64 constant is the nearest double to π and lies below it.
    Iv {
        lo: std::f64::consts::PI,
        hi: next_up(std::f64::consts::PI),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn enclosures_contain_exact_values() {
        let third = Iv::point(1.0) / Iv::point(3.0);
        assert!(third.lo < third.hi && third.lo <= 1.0 / 3.0 && 1.0 / 3.0 <= third.hi);
        let x = BigInt::from(1u64 << 62) * BigInt::from(3) + BigInt::from(1);
        let e = big(&x, 0);
        let xf = (3u128 << 62) + 1;
        assert!(e.lo <= xf as f64 && xf as f64 <= e.hi);
        // 54 to 60 bits (the range that enclosed 0 before): tight and containing the value.
        for bits in 54..=60 {
            let x = (1i64 << (bits - 1)) + 12345;
            let e = big(&BigInt::from(-x), 0);
            assert!(
                e.lo <= -(x as f64) && -(x as f64) <= e.hi && e.hi - e.lo <= 512.0,
                "{bits}"
            );
        }
        let e = big(&BigInt::from(-5), 2);
        assert_eq!(e, Iv::point(-1.25));
        assert!(pi().lo < pi().hi);
        let a = atan2_hull(Iv::point(1.0), Iv::point(-1.0));
        let want = 0.75 * std::f64::consts::PI;
        assert!(a.lo <= want && want <= a.hi && a.hi - a.lo < 1e-14);
        let s = Iv::point(2.0).sqrt();
        assert!(s.lo * s.lo <= 2.0 && s.hi * s.hi >= 2.0);
        assert_eq!(next_up(0.0), f64::from_bits(1));
        assert_eq!(next_down(1.0), 1.0 - f64::EPSILON / 2.0);
    }
}
