//! The boundary term of the Antipodal formula for one query: `Σ_k w_k·Area(A_k, B_k, x1)` over all
//! signed boundary edges — the hot loop (≈ 90 % of the time in the paper).
//!
//! Four edges at a time (`wide::f64x4`): offsets from the query, the `f64` orientation `d` with a
//! rigorous error bound, lengths and the cancellation-free denominator. Instead of one `atan2`
//! per edge, the terms `den + i·num` go into one [`AngleSum`] (a complex product with turn
//! counting; four `atan2` calls at the end). (Profiling showed `atan2` at 53 % of the time
//! before this change.)
//!
//! Lanes whose `|d|` does not clear the bound (the query is within ~1e-15·extent of the edge's
//! line through the ray, or a degenerate configuration) and edges of weight ≠ 1 are recomputed
//! one by one with the exact integer predicate and the limit formulas of
//! [`super::spherical::antipodal_edge_area`]. Either way the numerator's sign is the exact sign of
//! [`super::predicates::perturbed_orient2d`], so the branch agrees with the crossing test.

use wide::{CmpGt, f64x4};

use super::angle_sum::AngleSum;
use super::predicates::{Width, perturbed_orient2d, query_inside_segment};
use super::spherical::{EdgeSigns, antipodal_edge_area};

/// Boundary edges of one mesh in the ray frame, in grid units (structure of arrays, padded to a
/// multiple of 4 with zero-weight edges).
#[derive(Clone, Debug, Default)]
pub struct BoundaryEdges {
    a: Vec<[i64; 3]>,
    b: Vec<[i64; 3]>,
    coords: Vec<[f64x4; 6]>,
    /// 1 for real lanes, 0 for padding.
    weights: Vec<f64x4>,
    /// Edges `simd_len..` have weight ≠ 1 and take the scalar path.
    simd_len: usize,
    weight: Vec<f64>,
    /// `2^(bits−1)`: the largest grid coordinate, for the error bound of the `f64` conversions.
    limit: f64,
}

impl BoundaryEdges {
    /// Packs edges `a[i] → b[i]` with weights `weight[i]` (grid coordinates, ray frame).
    pub fn new(a: Vec<[i64; 3]>, b: Vec<[i64; 3]>, weight: Vec<f64>, bits: u32) -> Self {
        // Weight-1 edges first (the SIMD product path), heavier ones after (scalar path).
        let mut order: Vec<usize> = (0..a.len()).collect();
        order.sort_by_key(|&i| weight[i] != 1.0);
        let a: Vec<[i64; 3]> = order.iter().map(|&i| a[i]).collect();
        let b: Vec<[i64; 3]> = order.iter().map(|&i| b[i]).collect();
        let weight: Vec<f64> = order.iter().map(|&i| weight[i]).collect();
        let n = weight.iter().take_while(|&&w| w == 1.0).count();
        let chunks = n.div_ceil(4);
        let mut coords = Vec::with_capacity(chunks);
        let mut weights = Vec::with_capacity(chunks);
        for c in 0..chunks {
            let lane = |f: &dyn Fn(usize) -> f64| -> f64x4 {
                f64x4::from(std::array::from_fn::<f64, 4, _>(|l| {
                    let i = 4 * c + l;
                    if i < n { f(i) } else { 0.0 }
                }))
            };
            coords.push([
                lane(&|i| a[i][0] as f64),
                lane(&|i| a[i][1] as f64),
                lane(&|i| a[i][2] as f64),
                lane(&|i| b[i][0] as f64),
                lane(&|i| b[i][1] as f64),
                lane(&|i| b[i][2] as f64),
            ]);
            // Padding lanes have weight 0: they contribute the identity factor.
            weights.push(lane(&|_| 1.0));
        }
        BoundaryEdges {
            a,
            b,
            coords,
            weights,
            simd_len: n,
            weight,
            limit: (1_i64 << (bits - 1)) as f64,
        }
    }

    /// Number of edges.
    pub fn len(&self) -> usize {
        self.a.len()
    }

    /// True when there is no boundary.
    pub fn is_empty(&self) -> bool {
        self.a.is_empty()
    }

    /// Edge `i` as (start, end, weight) in grid coordinates.
    pub fn edge(&self, i: usize) -> ([i64; 3], [i64; 3], f64) {
        (self.a[i], self.b[i], self.weight[i])
    }

    /// `Σ w·Area` for the query `qi` (grid coordinates, frame). When `z_exact` is false the
    /// query's z lies outside the grid: `qz_units` (its z in grid units, `f64`) is used for the
    /// magnitudes and `qi[2]` (clamped) for nothing but the predicates, which do not involve z.
    pub fn area_sum<W: Width>(&self, qi: [i64; 3], z_exact: bool, qz_units: f64) -> f64 {
        if self.a.is_empty() {
            return 0.0;
        }
        let qx = f64x4::splat(qi[0] as f64);
        let qy = f64x4::splat(qi[1] as f64);
        let qz = f64x4::splat(if z_exact { qi[2] as f64 } else { qz_units });
        // Error of an offset: conversions of a and q (≤ u·L each) and the subtraction
        // (≤ u·|offset|), u = 2^-53. Error of d = ax·by − ay·bx: Σ |other factor|·(offset error)
        // + 3u(|p1| + |p2|). We use twice that.
        let u = f64::EPSILON * 0.5;
        let conv = f64x4::splat(2.0 * 2.0 * u * self.limit);
        let rel = f64x4::splat(2.0 * 4.0 * u);
        let zero = f64x4::ZERO;
        let one = f64x4::ONE;
        let mut angles = AngleSum::new();
        let mut scalar = 0.0;
        for (c, (p, real)) in self.coords.iter().zip(&self.weights).enumerate() {
            let ax = p[0] - qx;
            let ay = p[1] - qy;
            let az = p[2] - qz;
            let bx = p[3] - qx;
            let by = p[4] - qy;
            let bz = p[5] - qz;
            let p1 = ax * by;
            let p2 = ay * bx;
            let d = p1 - p2;
            let bound =
                conv * (ax.abs() + ay.abs() + bx.abs() + by.abs()) + rel * (p1.abs() + p2.abs());
            let ok = d.abs().cmp_gt(bound) & real.cmp_gt(zero);
            let ha = ax * ax + ay * ay;
            let hb = bx * bx + by * by;
            let la = (ha + az * az).sqrt();
            let lb = (hb + bz * bz).sqrt();
            // den = (|a| − a_z)(|b| − b_z) + a_x b_x + a_y b_y, and num = −d, both scaled by the
            // positive s_a·s_b with s = |r| + |r_z| (no division, no cancellation):
            // (|r| − r_z)·s = h² when r_z > 0, and s² otherwise.
            let sa = la + az.abs();
            let sb = lb + bz.abs();
            let pa = az.cmp_gt(zero).blend(ha, sa * sa);
            let pb = bz.cmp_gt(zero).blend(hb, sb * sb);
            let s2 = sa * sb;
            // Term den + i·num (num carries the exact sign of −d); identity 1 + 0i where unused.
            let t_re = ok.blend(pa * pb + (ax * bx + ay * by) * s2, one);
            let t_im = ok.blend((zero - d) * s2, zero);
            angles.push(t_re, t_im);
            if c % 2 == 1 {
                // Terms are at most ~2^250 (grid units): two pushes stay in range.
                angles.rescale();
            }
            let mask = ok.move_mask();
            if mask != 0b1111 {
                for l in 0..4 {
                    let i = 4 * c + l;
                    if mask & (1 << l) == 0 && i < self.simd_len {
                        scalar += self.exact_edge_area::<W>(i, qi, z_exact, qz_units);
                    }
                }
            }
        }
        for i in self.simd_len..self.a.len() {
            scalar += self.weight[i] * self.exact_edge_area::<W>(i, qi, z_exact, qz_units);
        }
        2.0 * angles.total() + scalar
    }

    /// One edge through the exact predicate and the limit formulas.
    #[cold]
    fn exact_edge_area<W: Width>(
        &self,
        i: usize,
        qi: [i64; 3],
        z_exact: bool,
        qz_units: f64,
    ) -> f64 {
        let a = self.a[i];
        let b = self.b[i];
        let o = perturbed_orient2d::<W>([qi[0], qi[1]], [a[0], a[1]], [b[0], b[1]]);
        let dz = |p: [i64; 3]| {
            if z_exact {
                (p[2] - qi[2]) as f64
            } else {
                p[2] as f64 - qz_units
            }
        };
        let ra = [(a[0] - qi[0]) as f64, (a[1] - qi[1]) as f64, dz(a)];
        let rb = [(b[0] - qi[0]) as f64, (b[1] - qi[1]) as f64, dz(b)];
        let signs = EdgeSigns {
            numerator: -o.sign,
            query_inside_segment: o.degenerate && z_exact && query_inside_segment(qi, a, b),
        };
        antipodal_edge_area(ra, rb, signs)
    }
}
