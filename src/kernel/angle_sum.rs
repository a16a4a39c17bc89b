//! Sums of many angles `Σ atan2(y_i, x_i)` with one `atan2` per lane instead of one per term.
//!
//! `Σ arg z_i = arg Π z_i + 2π·k`: the terms `z_i = x_i + i·y_i` are *multiplied* into four
//! complex accumulators, and the number of turns `k` each accumulator's argument makes past ±π is
//! counted from sign bits as the product proceeds (both factors in the upper half plane and the
//! product in the lower: +1 turn; both lower and the product upper: −1). Since every factor's
//! argument lies in (−π, π], one product step can wrap at most once, and the wrap is read from the
//! signs of the *computed* values — exactly the quadrants `atan2` would read — so rounding moves
//! the result by rounding-sized amounts only, never by 2π.
//!
//! Used by the Antipodal boundary loop (spherical-triangle areas) and by the near field of the
//! fast evaluator (triangle solid angles), where `atan2` was about half of the time.

use wide::{f64x4, u64x4};

/// Four running complex products and their turn counts.
#[derive(Clone, Copy, Debug)]
pub struct AngleSum {
    re: f64x4,
    im: f64x4,
    /// Turns past +π (counterclockwise) and past −π (clockwise), per lane.
    turns_up: u64x4,
    turns_down: u64x4,
}

impl Default for AngleSum {
    fn default() -> Self {
        Self::new()
    }
}

impl AngleSum {
    /// The empty sum (four accumulators equal to 1).
    #[inline]
    pub fn new() -> Self {
        AngleSum {
            re: f64x4::ONE,
            im: f64x4::ZERO,
            turns_up: u64x4::ZERO,
            turns_down: u64x4::ZERO,
        }
    }

    /// The state of four accumulators computed elsewhere ([`AngleSumAvx2`]).
    fn from_lanes(re: [f64; 4], im: [f64; 4], up: [u64; 4], down: [u64; 4]) -> Self {
        AngleSum {
            re: f64x4::from(re),
            im: f64x4::from(im),
            turns_up: u64x4::from(up),
            turns_down: u64x4::from(down),
        }
    }

    /// Adds `atan2(y, x)` of each lane. A lane with `x = 1, y = 0` adds nothing (use it for
    /// padding and masked lanes). `(x, y)` must be finite and not both zero; its magnitude is
    /// free, but the accumulators grow by it: call [`AngleSum::rescale`] before the product of
    /// the magnitudes pushed since the last rescale can leave the `f64` range.
    #[inline]
    pub fn push(&mut self, x: f64x4, y: f64x4) {
        let n_re = self.re * x - self.im * y;
        let n_im = self.re * y + self.im * x;
        // On the sign bits (as atan2 reads them, −0.0 included): a turn happens when the
        // accumulator and the factor lie in the same half plane and the product leaves it;
        // upwards (+1) from the upper half, downwards (−1) from the lower. Integer operations
        // only: about half the instructions of float compares and blends.
        let a: u64x4 = bytemuck::cast(self.im);
        let t: u64x4 = bytemuck::cast(y);
        let n: u64x4 = bytemuck::cast(n_im);
        let turn = !(a ^ t) & (n ^ a);
        self.turns_up += (turn & !a) >> 63;
        self.turns_down += (turn & a) >> 63;
        self.re = n_re;
        self.im = n_im;
    }

    /// Brings the accumulators back to modulus in [1, 4) (the arguments are unchanged).
    ///
    /// Multiplies by the power of two `2^-E`, `E` the exponent of `max(|re|, |im|)`, built from
    /// the exponent bits: exact, and a few integer operations instead of a division, whose latency
    /// was measurable in the boundary loop (docs/benchmarks.md, "Design measurements"). `2^-E` is a normal number for every finite
    /// non-zero `E` (its biased exponent `2046 − (E + 1023)` lies in `1..=2045`).
    #[inline]
    pub fn rescale(&mut self) {
        const EXPONENT: u64 = 0x7ff0_0000_0000_0000;
        const TWICE_BIAS: u64 = 2046 << 52;
        let m = self.re.abs().max(self.im.abs());
        let bits: u64x4 = bytemuck::cast(m);
        let scale: f64x4 =
            bytemuck::cast(u64x4::splat(TWICE_BIAS) - (bits & u64x4::splat(EXPONENT)));
        self.re *= scale;
        self.im *= scale;
    }

    /// Adds every angle of `other` (lane by lane: the product of the two accumulators, with the
    /// same turn counting as [`AngleSum::push`], plus `other`'s turns).
    #[inline]
    pub fn absorb(&mut self, other: &AngleSum) {
        let mut o = *other;
        o.rescale();
        self.rescale();
        self.push(o.re, o.im);
        self.turns_up += o.turns_up;
        self.turns_down += o.turns_down;
    }

    /// `Σ atan2(y_i, x_i)` over every lane of every push.
    ///
    /// The four lanes are multiplied together (with the same turn counting) so that one `atan2`
    /// serves the whole sum: on meshes with a few dozen boundary edges, four `atan2` calls were
    /// a sixth of a query.
    pub fn total(&self) -> f64 {
        let mut lanes = *self;
        lanes.rescale();
        let (re, im) = (lanes.re.to_array(), lanes.im.to_array());
        let (up, down) = (lanes.turns_up.to_array(), lanes.turns_down.to_array());
        let turns: [f64; 4] = std::array::from_fn(|l| up[l] as f64 - down[l] as f64);
        let (mut ar, mut ai) = (re[0], im[0]);
        let mut total_turns: f64 = turns.iter().sum();
        for l in 1..4 {
            let (br, bi) = (re[l], im[l]);
            let nr = ar * br - ai * bi;
            let ni = ar * bi + ai * br;
            let (up_a, up_b, up_n) = (
                !ai.is_sign_negative(),
                !bi.is_sign_negative(),
                !ni.is_sign_negative(),
            );
            total_turns += f64::from(u8::from(up_a && up_b && !up_n))
                - f64::from(u8::from(!up_a && !up_b && up_n));
            (ar, ai) = (nr, ni);
        }
        ai.atan2(ar) + std::f64::consts::TAU * total_turns
    }
}

/// [`AngleSum`]'s four accumulators in AVX2 registers, for the boundary loops' run-time AVX2
/// paths: the operations of [`AngleSum::push`] and [`AngleSum::rescale`] in the same order, so
/// the results are bit-identical to the portable type (tested through the loops).
#[cfg(target_arch = "x86_64")]
#[derive(Clone, Copy)]
pub(crate) struct AngleSumAvx2 {
    re: std::arch::x86_64::__m256d,
    im: std::arch::x86_64::__m256d,
    up: std::arch::x86_64::__m256i,
    down: std::arch::x86_64::__m256i,
}

#[cfg(target_arch = "x86_64")]
impl AngleSumAvx2 {
    /// The empty sum.
    #[target_feature(enable = "avx2")]
    #[inline]
    pub(crate) fn new() -> Self {
        use std::arch::x86_64::*;
        AngleSumAvx2 {
            re: _mm256_set1_pd(1.0),
            im: _mm256_setzero_pd(),
            up: _mm256_setzero_si256(),
            down: _mm256_setzero_si256(),
        }
    }

    /// `sum` in registers.
    #[target_feature(enable = "avx2")]
    #[inline]
    pub(crate) fn load(sum: &AngleSum) -> Self {
        AngleSumAvx2 {
            re: bytemuck::cast(sum.re),
            im: bytemuck::cast(sum.im),
            up: bytemuck::cast(sum.turns_up),
            down: bytemuck::cast(sum.turns_down),
        }
    }

    /// [`AngleSum::push`].
    #[target_feature(enable = "avx2")]
    #[inline]
    pub(crate) fn push(&mut self, x: std::arch::x86_64::__m256d, y: std::arch::x86_64::__m256d) {
        use std::arch::x86_64::*;
        let (re, im) = (self.re, self.im);
        let n_re = _mm256_sub_pd(_mm256_mul_pd(re, x), _mm256_mul_pd(im, y));
        let n_im = _mm256_add_pd(_mm256_mul_pd(re, y), _mm256_mul_pd(im, x));
        let a = _mm256_castpd_si256(im);
        let t = _mm256_castpd_si256(y);
        let n = _mm256_castpd_si256(n_im);
        let turn = _mm256_andnot_si256(_mm256_xor_si256(a, t), _mm256_xor_si256(n, a));
        self.up = _mm256_add_epi64(
            self.up,
            _mm256_srli_epi64::<63>(_mm256_andnot_si256(a, turn)),
        );
        self.down = _mm256_add_epi64(
            self.down,
            _mm256_srli_epi64::<63>(_mm256_and_si256(turn, a)),
        );
        self.re = n_re;
        self.im = n_im;
    }

    /// [`AngleSum::rescale`].
    #[target_feature(enable = "avx2")]
    #[inline]
    pub(crate) fn rescale(&mut self) {
        use std::arch::x86_64::*;
        let sign = _mm256_set1_pd(-0.0);
        let m = _mm256_castpd_si256(_mm256_max_pd(
            _mm256_andnot_pd(sign, self.re),
            _mm256_andnot_pd(sign, self.im),
        ));
        let scale = _mm256_castsi256_pd(_mm256_sub_epi64(
            _mm256_set1_epi64x(2046 << 52),
            _mm256_and_si256(m, _mm256_set1_epi64x(0x7ff0_0000_0000_0000)),
        ));
        self.re = _mm256_mul_pd(self.re, scale);
        self.im = _mm256_mul_pd(self.im, scale);
    }

    /// The same sum as an [`AngleSum`].
    pub(crate) fn finish(self) -> AngleSum {
        AngleSum::from_lanes(
            bytemuck::cast(self.re),
            bytemuck::cast(self.im),
            bytemuck::cast(self.up),
            bytemuck::cast(self.down),
        )
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn matches_the_sum_of_atan2_through_many_turns() {
        // Angles near ±π (the branch cut) and of both signs, many of them: the product winds
        // around the origin several times per lane.
        let mut sum = AngleSum::new();
        let mut want = 0.0;
        let mut state = 12345_u64;
        for i in 0..400 {
            let mut xs = [0.0; 4];
            let mut ys = [0.0; 4];
            for l in 0..4 {
                state = state
                    .wrapping_mul(6364136223846793005)
                    .wrapping_add(1442695040888963407);
                let t = (state >> 11) as f64 / (1u64 << 53) as f64;
                let angle = if i % 3 == 0 {
                    std::f64::consts::PI * (1.0 - 1e-9 * t)
                } else {
                    std::f64::consts::PI * (2.0 * t - 1.0)
                };
                let r = 1e-3 + 1e3 * t;
                xs[l] = r * angle.cos();
                ys[l] = r * angle.sin();
                want += ys[l].atan2(xs[l]);
            }
            sum.push(f64x4::from(xs), f64x4::from(ys));
            sum.rescale();
        }
        let got = sum.total();
        assert!((got - want).abs() < 1e-9, "{got} vs {want}");
        assert!(
            want.abs() > 20.0,
            "the test should wind several times: {want}"
        );
    }

    #[test]
    fn identity_lanes_add_nothing() {
        let mut sum = AngleSum::new();
        sum.push(
            f64x4::from([1.0, -1.0, 0.0, 1.0]),
            f64x4::from([0.0, 0.0, 2.0, 0.0]),
        );
        let want = std::f64::consts::PI + std::f64::consts::FRAC_PI_2;
        assert!((sum.total() - want).abs() < 1e-15);
    }
}
