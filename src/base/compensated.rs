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

    /// The compensated total.
    #[inline]
    pub fn value(&self) -> f64 {
        self.sum + self.compensation
    }
}

#[cfg(test)]
mod tests {
    use super::*;

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
