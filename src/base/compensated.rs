//! Compensated (Neumaier) summation: the accumulator of every sum of many signed terms, so that
//! cancelling solid angles of a closed mesh leave no rounding residue.

/// A running sum with Neumaier's error compensation (an improved Kahan sum that also handles
/// terms larger than the running total).
#[derive(Clone, Copy, Debug, Default)]
pub struct NeumaierSum {
    sum: f64,
    compensation: f64,
}

impl NeumaierSum {
    /// An empty sum.
    pub fn new() -> Self {
        Self::default()
    }

    /// Adds one term.
    #[inline]
    pub fn add(&mut self, x: f64) {
        let t = self.sum + x;
        if self.sum.abs() >= x.abs() {
            self.compensation += (self.sum - t) + x;
        } else {
            self.compensation += (x - t) + self.sum;
        }
        self.sum = t;
    }

    /// The compensated total; `±∞` when the plain sum overflowed or took an infinite term (the
    /// compensation is then `∞ − ∞`, NaN, and means nothing).
    #[inline]
    pub fn value(&self) -> f64 {
        if self.sum.is_finite() {
            self.sum + self.compensation
        } else {
            self.sum
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn infinite_terms_and_overflow_give_infinity() {
        for terms in [
            &[1.0, f64::INFINITY, -3.0][..],
            &[f64::MAX, f64::MAX, 1.0],
            &[2.0, f64::NEG_INFINITY],
        ] {
            let mut s = NeumaierSum::new();
            terms.iter().for_each(|&t| s.add(t));
            let naive: f64 = terms.iter().sum();
            assert_eq!(s.value(), naive, "{terms:?}");
        }
        let mut s = NeumaierSum::new();
        [f64::INFINITY, f64::NEG_INFINITY]
            .iter()
            .for_each(|&t| s.add(t));
        assert!(s.value().is_nan());
    }

    #[test]
    fn recovers_what_naive_summation_loses() {
        let terms = [1.0, 1e100, 1.0, -1e100];
        let naive: f64 = terms.iter().sum();
        let mut s = NeumaierSum::new();
        terms.iter().for_each(|&t| s.add(t));
        assert_eq!(naive, 0.0);
        assert_eq!(s.value(), 2.0);
    }
}
