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
