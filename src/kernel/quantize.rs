//! The fixed-point grid that makes the predicates exact.
//!
//! Every mesh vertex is snapped to the integer lattice `origin + cell·ℤ³`, where `cell` is a power
//! of two and `origin` a multiple of `cell`, chosen so that the mesh's bounding box grown by its
//! largest extent on every side (the *padded box*) fits in `±2^(bits−1)`. Because `cell` is a
//! power of two, dyadic coordinates with few significant bits (integer test meshes, most CAD
//! output) snap without error, so degenerate configurations in the input stay degenerate on the
//! grid and the perturbation resolves them exactly as it would in real arithmetic.
//!
//! Queries inside the padded box are snapped the same way: a query within half a cell of the
//! surface is evaluated at its snapped position (`cell ≈ 3·extent/2^bits`: about `3e-9·extent`
//! for [`Precision::Bits30`], `3e-18·extent` for [`Precision::Bits60`], below `f64` resolution of
//! the mesh's own coordinates). Queries outside the padded box are *not* snapped in the
//! offending axis: the evaluator treats them by the clamp rules in `eval::antipodal`.
//!
//! Queries farther than `2^30` padded-box half-widths from the origin along an axis are first
//! moved to that distance along that axis ([`Grid::pull_in_far`]): beyond it the boundary
//! term's products would overflow `f64` (w was NaN at 1e100), and the move changes `w` by less
//! than `2^-60` (see there).

use crate::BoundingBox;

/// Width of the fixed-point grid, and with it the integer type of the predicates.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub enum Precision {
    /// 30-bit grid: the 2D orientation fits `i64`, the depth test `i128`. Fastest; queries are
    /// snapped to about `3e-9` of the mesh extent.
    Bits30,
    /// 60-bit grid: the 2D orientation fits `i128`; the degree-3 depth test uses a floating
    /// filter with an exact big-integer fallback. Snapping is below `f64` resolution. Default.
    #[default]
    Bits60,
}

impl Precision {
    /// Number of bits of the grid.
    pub fn bits(self) -> u32 {
        match self {
            Precision::Bits30 => 30,
            Precision::Bits60 => 60,
        }
    }
}

/// Where a query coordinate falls relative to the grid's range along one axis.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Snap {
    /// Inside the padded box: the snapped integer coordinate.
    In(i64),
    /// Below the padded box.
    Low,
    /// Above the padded box.
    High,
}

impl Snap {
    /// The same position seen along the negated axis.
    pub fn negated(self) -> Snap {
        match self {
            Snap::In(v) => Snap::In(-v),
            Snap::Low => Snap::High,
            Snap::High => Snap::Low,
        }
    }
}

/// The fixed-point grid of one mesh.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Grid {
    origin: [f64; 3],
    cell: f64,
    inv_cell: f64,
    limit: i64,
    precision: Precision,
}

/// The mesh's coordinates are too large to grid (their extent overflows `f64`).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct GridRangeError;

impl Grid {
    /// The grid for a mesh with bounding box `bbox`.
    pub fn new(bbox: &BoundingBox, precision: Precision) -> Result<Grid, GridRangeError> {
        let center = bbox.center();
        let mut extent = (0..3)
            .map(|k| bbox.max[k] - bbox.min[k])
            .fold(0.0_f64, f64::max);
        if !extent.is_finite() || center.iter().any(|c| !c.is_finite()) {
            return Err(GridRangeError);
        }
        if extent == 0.0 {
            // All vertices coincide: any cell works; keep it representable near the point.
            let mag = center.iter().fold(0.0_f64, |m, c| m.max(c.abs()));
            extent = if mag > 0.0 { mag * 1e-9 } else { 1.0 };
        }
        // Padded box: bbox grown by `extent` per side ⇒ half-width ≤ 1.5·extent around the centre.
        let half_width = 1.5 * extent;
        let limit: i64 = (1_i64 << (precision.bits() - 1)) - 4;
        let target = half_width / limit as f64;
        let mut cell = 2f64.powi(target.log2().ceil() as i32);
        while cell < target {
            cell *= 2.0;
        }
        // A cell so small that its reciprocal overflows (extent below ~1e-290) is refused too.
        if !(cell.is_finite() && cell > 0.0 && (1.0 / cell).is_finite()) {
            return Err(GridRangeError);
        }
        let origin = center.map(|c| (c / cell).round() * cell);
        if origin.iter().any(|o| !o.is_finite()) {
            return Err(GridRangeError);
        }
        Ok(Grid {
            origin,
            cell,
            inv_cell: 1.0 / cell,
            limit,
            precision,
        })
    }

    /// The precision the grid was built for.
    pub fn precision(&self) -> Precision {
        self.precision
    }

    /// Edge length of a grid cell.
    pub fn cell(&self) -> f64 {
        self.cell
    }

    /// The grid origin (a multiple of the cell).
    pub fn origin(&self) -> [f64; 3] {
        self.origin
    }

    /// Largest absolute integer coordinate a snapped query may have.
    pub fn limit(&self) -> i64 {
        self.limit
    }

    /// Moves a query farther than `R = 2^30` padded-box half-widths from the origin along any
    /// axis to distance `R` along that axis (each coordinate clamped to `origin ± R`).
    ///
    /// Why this is harmless: every clamped coordinate stays outside the padded box along the
    /// whole segment from the query to the moved point, so the segment meets no triangle and `w`
    /// is continuous along it; both ends lie at distance `≥ R` from the mesh, where `|w|` and its
    /// change are bounded by the solid angle of the mesh, `O((extent/R)²) < 2^-60`. (Closed
    /// meshes: `w = 0` at both ends exactly.)
    #[inline]
    pub fn pull_in_far(&self, q: [f64; 3]) -> [f64; 3] {
        let r = FAR * self.limit as f64 * self.cell;
        std::array::from_fn(|k| {
            let o = self.origin[k];
            // `q − o` cannot overflow in halves.
            if 0.5 * q[k] - 0.5 * o > 0.5 * r {
                o + r
            } else if 0.5 * q[k] - 0.5 * o < -0.5 * r {
                o - r
            } else {
                q[k]
            }
        })
    }

    /// Snaps one coordinate along `axis`.
    #[inline]
    pub fn snap(&self, x: f64, axis: usize) -> Snap {
        // `cell` is a power of two, so multiplying by its reciprocal is exact like the division.
        let v = (x - self.origin[axis]) * self.inv_cell;
        let r = if v.abs() < TRUNC_EXACT {
            round_half_away(v)
        } else {
            // Huge or NaN: no fast path needed (and `as` would saturate).
            let r = v.round();
            if r > self.limit as f64 {
                return Snap::High;
            } else if r < -(self.limit as f64) {
                return Snap::Low;
            }
            r as i64
        };
        if r > self.limit {
            Snap::High
        } else if r < -self.limit {
            Snap::Low
        } else {
            Snap::In(r)
        }
    }

    /// Snaps a mesh vertex (always inside the padded box by construction).
    pub fn snap_vertex(&self, p: [f64; 3]) -> [i64; 3] {
        std::array::from_fn(|k| match self.snap(p[k], k) {
            Snap::In(v) => v,
            Snap::Low => -self.limit,
            Snap::High => self.limit,
        })
    }

    /// The position of integer coordinate `v` along `axis`.
    #[inline]
    pub fn unsnap(&self, v: i64, axis: usize) -> f64 {
        v as f64 * self.cell + self.origin[axis]
    }
}

/// Distance, in padded-box half-widths, beyond which queries are pulled in.
const FAR: f64 = (1_u64 << 30) as f64;

/// Below this magnitude `v as i64` is exact truncation.
const TRUNC_EXACT: f64 = (1_u64 << 62) as f64;

/// `v.round()` (ties away from zero) as an integer, for `|v| < 2^62`. Without SSE4.1, `round` is
/// a libm call that was ~5 % of a closed-mesh query; truncation and an exact remainder are not:
/// `v − trunc(v)` is exact because both lie in the same binade (or `trunc(v) = 0`).
#[inline]
fn round_half_away(v: f64) -> i64 {
    let t = v as i64;
    let frac = v - t as f64;
    t + i64::from(frac >= 0.5) - i64::from(frac <= -0.5)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn fast_rounding_matches_round() {
        let mut vals = vec![
            0.0,
            -0.0,
            0.5,
            -0.5,
            1.5,
            -1.5,
            2.5,
            0.49999999999999994,
            -0.49999999999999994,
        ];
        for e in [
            1.0,
            1e3,
            4503599627370495.5,
            4503599627370496.0,
            2.0f64.powi(61) + 1024.0,
        ] {
            for d in [-1.0, -0.5, -0.25, 0.0, 0.25, 0.5, 1.0] {
                vals.push(e + d);
                vals.push(-e + d);
            }
        }
        for v in vals {
            assert_eq!(round_half_away(v), v.round() as i64, "{v}");
        }
    }

    #[test]
    fn small_integer_coordinates_snap_exactly() {
        let b = BoundingBox {
            min: [-4.0, -4.0, -3.0],
            max: [4.0, 3.0, 4.0],
        };
        for p in [Precision::Bits30, Precision::Bits60] {
            let g = Grid::new(&b, p).unwrap();
            for x in [-4.0, -1.0, 0.0, 0.5, 3.0, 4.0] {
                let Snap::In(v) = g.snap(x, 0) else { panic!() };
                assert_eq!(g.unsnap(v, 0), x, "{p:?}");
            }
            assert!(matches!(g.snap(1e6, 1), Snap::High));
            assert!(matches!(g.snap(-1e6, 2), Snap::Low));
            // The padded box (one extent beyond the bbox) is inside the grid.
            assert!(matches!(g.snap(-11.9, 0), Snap::In(_)));
        }
    }

    #[test]
    fn degenerate_and_huge_boxes() {
        let point = BoundingBox {
            min: [1.0; 3],
            max: [1.0; 3],
        };
        assert!(Grid::new(&point, Precision::Bits60).is_ok());
        let huge = BoundingBox {
            min: [-1e308; 3],
            max: [1e308; 3],
        };
        assert_eq!(Grid::new(&huge, Precision::Bits60), Err(GridRangeError));
    }
}
