//! Axis-aligned boxes of `f64` points.

/// An axis-aligned bounding box in `f64`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct BoundingBox {
    /// Smallest coordinate along each axis.
    pub min: [f64; 3],
    /// Largest coordinate along each axis.
    pub max: [f64; 3],
}

impl BoundingBox {
    /// The box of a set of points, `None` when the set is empty.
    pub fn of_points<'a>(points: impl IntoIterator<Item = &'a [f64; 3]>) -> Option<Self> {
        let mut it = points.into_iter();
        let first = *it.next()?;
        let mut b = BoundingBox {
            min: first,
            max: first,
        };
        for p in it {
            for (k, &c) in p.iter().enumerate() {
                b.min[k] = b.min[k].min(c);
                b.max[k] = b.max[k].max(c);
            }
        }
        Some(b)
    }

    /// The smallest box holding both boxes.
    pub fn union(&self, other: &Self) -> Self {
        BoundingBox {
            min: std::array::from_fn(|k| self.min[k].min(other.min[k])),
            max: std::array::from_fn(|k| self.max[k].max(other.max[k])),
        }
    }

    /// Length of the diagonal, also for boxes of extent 1e-300 or 1e300 (where the squared
    /// lengths under- or overflow; `gwn info` printed `diagonal 0` for a cube of side 1e-300).
    pub fn diagonal(&self) -> f64 {
        crate::base::vec3::norm_safe([
            self.max[0] - self.min[0],
            self.max[1] - self.min[1],
            self.max[2] - self.min[2],
        ])
    }

    /// Centre of the box.
    pub fn center(&self) -> [f64; 3] {
        [
            0.5 * (self.min[0] + self.max[0]),
            0.5 * (self.min[1] + self.max[1]),
            0.5 * (self.min[2] + self.max[2]),
        ]
    }

    /// The box grown by `factor` times its largest extent on every side (at least `1e-300`, so a
    /// point-sized box still grows).
    pub fn enlarged(&self, factor: f64) -> Self {
        let ext = (0..3)
            .map(|k| self.max[k] - self.min[k])
            .fold(0.0_f64, f64::max)
            .max(1e-300);
        let pad = factor * ext;
        BoundingBox {
            min: [self.min[0] - pad, self.min[1] - pad, self.min[2] - pad],
            max: [self.max[0] + pad, self.max[1] + pad, self.max[2] + pad],
        }
    }
}

/// Whether the segment `q + τ d`, `0 ≤ τ ≤ reach` (`reach` infinite for a ray), meets the box
/// `lo..hi` grown by `pad` on every side: the slab test (an axis with `d = 0` needs `q` inside
/// the slab). With `pad = 0`, `lo − pad − q` is `lo − q` exactly, so the unpadded callers (the
/// remesher's segment hierarchy) get the plain test.
#[cfg(any(feature = "patch", feature = "products"))]
pub fn segment_meets_box(
    q: [f64; 3],
    d: [f64; 3],
    reach: f64,
    lo: [f64; 3],
    hi: [f64; 3],
    pad: f64,
) -> bool {
    let (mut t0, mut t1) = (0.0f64, reach);
    for k in 0..3 {
        let (a, b) = (lo[k] - pad - q[k], hi[k] + pad - q[k]);
        if d[k] == 0.0 {
            if a > 0.0 || b < 0.0 {
                return false;
            }
            continue;
        }
        let (mut ta, mut tb) = (a / d[k], b / d[k]);
        if ta > tb {
            std::mem::swap(&mut ta, &mut tb);
        }
        t0 = t0.max(ta);
        t1 = t1.min(tb);
        if t0 > t1 {
            return false;
        }
    }
    true
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn union_holds_both_boxes() {
        let a = BoundingBox::of_points(&[[0.0, -1.0, 2.0], [1.0, 0.0, 3.0]]).unwrap();
        let b = BoundingBox::of_points(&[[-2.0, 0.5, 2.5]]).unwrap();
        let u = a.union(&b);
        assert_eq!(u.min, [-2.0, -1.0, 2.0]);
        assert_eq!(u.max, [1.0, 0.5, 3.0]);
        assert_eq!(b.union(&a), u);
    }
}
