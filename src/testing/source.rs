//! Where the generators read their choices from: a byte slice (fuzzers, proptest, committed
//! corpora) or a 64-bit seed (SplitMix64). Every generator is written once against [`Source`], so
//! the three front ends (seeded function, byte decoder, proptest strategy) produce the same
//! families of meshes.

/// A stream of bytes driving a generator. Never runs dry: a slice reads as zeros after its end.
#[derive(Clone, Debug)]
pub struct Source<'a> {
    inner: Inner<'a>,
}

#[derive(Clone, Debug)]
enum Inner<'a> {
    Bytes(&'a [u8], usize),
    Seed(SplitMix64),
}

impl<'a> Source<'a> {
    /// Reads `bytes` in order, then zeros.
    pub fn from_bytes(bytes: &'a [u8]) -> Self {
        Source {
            inner: Inner::Bytes(bytes, 0),
        }
    }

    /// Pseudo-random bytes from SplitMix64 seeded with `seed` (platform independent).
    pub fn from_seed(seed: u64) -> Source<'static> {
        Source {
            inner: Inner::Seed(SplitMix64(seed)),
        }
    }

    /// The next byte.
    pub fn byte(&mut self) -> u8 {
        match &mut self.inner {
            Inner::Bytes(b, pos) => {
                let v = b.get(*pos).copied().unwrap_or(0);
                *pos = pos.saturating_add(1);
                v
            }
            Inner::Seed(r) => (r.next_u64() >> 56) as u8,
        }
    }

    /// `byte() % n` as `usize` (`n ≥ 1`).
    pub fn below(&mut self, n: usize) -> usize {
        usize::from(self.byte()) % n.max(1)
    }
}

pub use crate::base::splitmix::SplitMix64;

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn slices_read_zeros_after_the_end_and_seeds_are_reproducible() {
        let mut s = Source::from_bytes(&[7, 9]);
        assert_eq!([s.byte(), s.byte(), s.byte(), s.byte()], [7, 9, 0, 0]);
        let a: Vec<u8> = {
            let mut s = Source::from_seed(42);
            (0..16).map(|_| s.byte()).collect()
        };
        let b: Vec<u8> = {
            let mut s = Source::from_seed(42);
            (0..16).map(|_| s.byte()).collect()
        };
        assert_eq!(a, b);
        assert_eq!(SplitMix64(0).next_u64(), 0xE220_A839_7B1D_CDAF);
    }
}
