//! Far-field (multipole) expansions of clusters of dipoles: Barill et al. 2018, Eqs. 13–21, with
//! the closed-form triangle integrals of their Appendix B and the Green's-function derivatives of
//! Appendix A.
//!
//! With `G(q, x) = −1/(4π‖x − q‖)` and `r = p̃ − q`, the winding number of a cluster expanded about
//! its centre `p̃` is
//!
//! ```text
//! w̃(q) = N·∇G + M1 : ∇²G + ½ M2 ⋮ ∇³G
//! ∇G   = r / (4π d³)
//! ∇²G  = I / (4π d³) − 3 r⊗r / (4π d⁵)
//! ∇³G  = −3 (r⊗eᵢ⊗eᵢ + eᵢ⊗r⊗eᵢ + eᵢ⊗eᵢ⊗r) / (4π d⁵) + 15 r⊗r⊗r / (4π d⁷)
//! ```
//!
//! where `N = ∫ n dA`, `M1 = ∫ (x − p̃)⊗n dA`, `M2 = ∫ (x − p̃)⊗(x − p̃)⊗n dA`.
//!
//! Note on Appendix A: the paper prints the first term of `∇³G` without the factor 3. Without it
//! `∇³G` is not trace-free (`G` is harmonic, so every contraction of two indices of `∇³G` must
//! vanish); with it, the trace is `(−3·5 + 15)·r_k/d⁵ = 0`. The unit tests check the factor
//! numerically (the order-2 error must fall like `(r/d)⁵`).

// The tensor code indexes like the formulas it transcribes (`M1[i][j] += δᵢ Nⱼ`).
#![allow(clippy::needless_range_loop)]

use crate::base::vec3::sub;
use wide::f32x4;

use super::packet::{EightLanes, Lanes8};

use crate::base::vec3::{cross, dot};

use crate::kernel::spherical::INV_4PI;

/// Index pairs `(i, j)` of the six independent entries of a symmetric 3×3 matrix, in the order
/// `M2` stores them: the diagonal first, then `xy, xz, yz`.
pub const SYM_PAIRS: [(usize, usize); 6] = [(0, 0), (1, 1), (2, 2), (0, 1), (0, 2), (1, 2)];

/// The expansion coefficients of a cluster of oriented surface elements about a centre.
///
/// For a cluster of triangles the integrals are exact (Appendix B of Barill et al.); for a point
/// cloud each point `pᵢ` with area `aᵢ` and unit normal `n̂ᵢ` contributes the point mass
/// `aᵢ n̂ᵢ` at `pᵢ`.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Moments {
    /// Expansion centre `p̃`: the area-weighted centroid of the cluster (the centre of its
    /// bounding box when the total area is zero).
    pub center: [f64; 3],
    /// Largest distance from `center` to any point of any element of the cluster (triangle
    /// corners, or the points of a cloud).
    pub radius: f64,
    /// Total (unsigned) area `Σ aₜ`.
    pub area: f64,
    /// Order 0: `N = ∫ n dA`, the total area-weighted normal.
    pub n: [f64; 3],
    /// Order 1: `M1[i][j] = ∫ (x − p̃)ᵢ nⱼ dA`.
    pub m1: [[f64; 3]; 3],
    /// Order 2: `M2[s][k] = ∫ (x − p̃)ᵢ (x − p̃)ⱼ n_k dA` with `(i, j) = SYM_PAIRS[s]`
    /// (symmetric in `i, j`, so six of the nine rows are stored).
    pub m2: [[f64; 3]; 6],
}

impl Moments {
    /// The exact moments of the triangle `a, b, c` (counter-clockwise about its normal) about
    /// `center`. The radius is left 0 (it belongs to a cluster, not to a moment).
    ///
    /// Order 0 and 1 use the one-point (centroid) rule and order 2 the edge-midpoint rule, both
    /// exact for the constant, linear and quadratic integrands.
    pub fn of_triangle(a: [f64; 3], b: [f64; 3], c: [f64; 3], center: [f64; 3]) -> Self {
        let ab = sub(b, a);
        let ac = sub(c, a);
        let n = cross(ab, ac).map(|v| 0.5 * v);
        let area = dot(n, n).sqrt();
        let g = [
            (a[0] + b[0] + c[0]) / 3.0 - center[0],
            (a[1] + b[1] + c[1]) / 3.0 - center[1],
            (a[2] + b[2] + c[2]) / 3.0 - center[2],
        ];
        let mut m1 = [[0.0; 3]; 3];
        for i in 0..3 {
            for j in 0..3 {
                m1[i][j] = g[i] * n[j];
            }
        }
        let mids = [mid(a, b, center), mid(b, c, center), mid(c, a, center)];
        let mut m2 = [[0.0; 3]; 6];
        for (s, &(i, j)) in SYM_PAIRS.iter().enumerate() {
            let cij =
                (mids[0][i] * mids[0][j] + mids[1][i] * mids[1][j] + mids[2][i] * mids[2][j]) / 3.0;
            for k in 0..3 {
                m2[s][k] = cij * n[k];
            }
        }
        Moments {
            center,
            radius: 0.0,
            area,
            n,
            m1,
            m2,
        }
    }

    /// The moments of one oriented point `p` carrying the area-weighted normal `an = a·n̂` (its
    /// area is `|an|`) about `center`.
    pub fn of_point(p: [f64; 3], an: [f64; 3], center: [f64; 3]) -> Self {
        let d = sub(p, center);
        let mut m1 = [[0.0; 3]; 3];
        for i in 0..3 {
            for j in 0..3 {
                m1[i][j] = d[i] * an[j];
            }
        }
        let mut m2 = [[0.0; 3]; 6];
        for (s, &(i, j)) in SYM_PAIRS.iter().enumerate() {
            for k in 0..3 {
                m2[s][k] = d[i] * d[j] * an[k];
            }
        }
        Moments {
            center,
            radius: 0.0,
            area: dot(an, an).sqrt(),
            n: an,
            m1,
            m2,
        }
    }

    /// The same moments expanded about `new_center` (parallel-axis shift; exact). With
    /// `δ = center − new_center`:
    /// `M1' = M1 + δ⊗N`, `M2'ᵢⱼₖ = M2ᵢⱼₖ + δᵢ M1ⱼₖ + δⱼ M1ᵢₖ + δᵢδⱼ Nₖ`.
    /// The radius is kept (it is not a moment; callers recompute it).
    pub fn recentred(&self, new_center: [f64; 3]) -> Self {
        let d = sub(self.center, new_center);
        let mut m1 = self.m1;
        for i in 0..3 {
            for j in 0..3 {
                m1[i][j] += d[i] * self.n[j];
            }
        }
        let mut m2 = self.m2;
        for (s, &(i, j)) in SYM_PAIRS.iter().enumerate() {
            for k in 0..3 {
                m2[s][k] += d[i] * self.m1[j][k] + d[j] * self.m1[i][k] + d[i] * d[j] * self.n[k];
            }
        }
        Moments {
            center: new_center,
            radius: self.radius,
            area: self.area,
            n: self.n,
            m1,
            m2,
        }
    }

    /// Adds the coefficients of `other`, which must be expanded about the same centre.
    pub fn accumulate(&mut self, other: &Moments) {
        debug_assert_eq!(self.center, other.center);
        self.area += other.area;
        for k in 0..3 {
            self.n[k] += other.n[k];
        }
        for i in 0..3 {
            for j in 0..3 {
                self.m1[i][j] += other.m1[i][j];
            }
        }
        for s in 0..6 {
            for k in 0..3 {
                self.m2[s][k] += other.m2[s][k];
            }
        }
    }

    /// The far-field approximation of the winding number at `q` with the expansion truncated
    /// after `order` (0: dipole, 1: + quadrupole, 2: + octupole; larger values act as 2).
    #[inline]
    pub fn far_field(&self, q: [f64; 3], order: u8) -> f64 {
        let r = sub(self.center, q);
        let d2 = dot(r, r);
        let inv_d2 = 1.0 / d2;
        let inv_d = inv_d2.sqrt();
        let inv_d3 = inv_d * inv_d2;
        let mut w = dot(self.n, r) * inv_d3;
        if order >= 1 {
            let m = &self.m1;
            let tr = m[0][0] + m[1][1] + m[2][2];
            let mut rmr = 0.0;
            for i in 0..3 {
                rmr += r[i] * (m[i][0] * r[0] + m[i][1] * r[1] + m[i][2] * r[2]);
            }
            let inv_d5 = inv_d3 * inv_d2;
            w += tr * inv_d3 - 3.0 * rmr * inv_d5;
            if order >= 2 {
                let m2 = &self.m2;
                // A = Σ_k (Σ_i M2_iik) r_k
                let mut a = 0.0;
                for k in 0..3 {
                    a += (m2[0][k] + m2[1][k] + m2[2][k]) * r[k];
                }
                // B = Σ_ij M2_iji r_j (equal to Σ_ij M2_ijj r_i by symmetry in i, j)
                let mut b = m2[0][0] * r[0] + m2[1][1] * r[1] + m2[2][2] * r[2];
                for (s, &(i, j)) in SYM_PAIRS.iter().enumerate().skip(3) {
                    b += m2[s][i] * r[j] + m2[s][j] * r[i];
                }
                // D = Σ_ijk M2_ijk r_i r_j r_k
                let mut dd = 0.0;
                for (s, &(i, j)) in SYM_PAIRS.iter().enumerate() {
                    let mult = if i == j { 1.0 } else { 2.0 };
                    dd +=
                        mult * r[i] * r[j] * (m2[s][0] * r[0] + m2[s][1] * r[1] + m2[s][2] * r[2]);
                }
                let inv_d7 = inv_d5 * inv_d2;
                w += 0.5 * (-3.0 * (a + 2.0 * b) * inv_d5 + 15.0 * dd * inv_d7);
            }
        }
        w * INV_4PI
    }
}

impl Moments {
    /// `∇_q` of [`Moments::far_field`]: the expansion differentiated term by term (Barill et
    /// al. 2018 expand `w` in derivatives of `G`; the gradient is the next derivative of each).
    /// With `r = p̃ − q`, `d = ‖r‖` and `∇_q = −∇_r`:
    ///
    /// ```text
    /// ∇_r (N·r/d³)          = N/d³ − 3 (N·r) r/d⁵
    /// ∇_r (tr/d³)           = −3 tr r/d⁵
    /// ∇_r (rᵀM1r/d⁵)        = (M1 + M1ᵀ) r/d⁵ − 5 (rᵀM1r) r/d⁷
    /// ∇_r ((a+2b)·r/d⁵)     = (a+2b)/d⁵ − 5 ((a+2b)·r) r/d⁷
    /// ∇_r (D/d⁷)            = ∇D/d⁷ − 7 D r/d⁹,   ∂D/∂rₘ = 2 Σⱼₖ M2ₘⱼₖ rⱼ rₖ + Σᵢⱼ M2ᵢⱼₘ rᵢ rⱼ
    /// ```
    ///
    /// (`aₖ = Σᵢ M2ᵢᵢₖ`, `bⱼ = Σᵢ M2ᵢⱼᵢ`, `D = Σ M2ᵢⱼₖ rᵢrⱼrₖ`, the terms of `far_field`).
    pub fn far_field_gradient(&self, q: [f64; 3], order: u8) -> [f64; 3] {
        let r = sub(self.center, q);
        let d2 = dot(r, r);
        let inv_d2 = 1.0 / d2;
        let inv_d = inv_d2.sqrt();
        let inv_d3 = inv_d * inv_d2;
        let inv_d5 = inv_d3 * inv_d2;
        let inv_d7 = inv_d5 * inv_d2;
        let nr = dot(self.n, r);
        let mut g: [f64; 3] =
            std::array::from_fn(|k| self.n[k] * inv_d3 - 3.0 * nr * r[k] * inv_d5);
        if order >= 1 {
            let m = &self.m1;
            let tr = m[0][0] + m[1][1] + m[2][2];
            let mut rmr = 0.0;
            let mut sym_r = [0.0; 3];
            for i in 0..3 {
                for j in 0..3 {
                    rmr += r[i] * m[i][j] * r[j];
                    sym_r[i] += (m[i][j] + m[j][i]) * r[j];
                }
            }
            for k in 0..3 {
                g[k] += -3.0 * tr * r[k] * inv_d5
                    - 3.0 * (sym_r[k] * inv_d5 - 5.0 * rmr * r[k] * inv_d7);
            }
            if order >= 2 {
                let full = |i: usize, j: usize| {
                    let s = SYM_PAIRS
                        .iter()
                        .position(|&(a, b)| (a, b) == (i.min(j), i.max(j)))
                        .unwrap_or(0);
                    self.m2[s]
                };
                let mut ab = [0.0; 3];
                for k in 0..3 {
                    for i in 0..3 {
                        ab[k] += full(i, i)[k] + 2.0 * full(i, k)[i];
                    }
                }
                let ab_r = dot(ab, r);
                let mut cubic = 0.0;
                let mut grad_cubic = [0.0; 3];
                for i in 0..3 {
                    for j in 0..3 {
                        let row = full(i, j);
                        for k in 0..3 {
                            cubic += row[k] * r[i] * r[j] * r[k];
                            // 2 Σⱼₖ M2ₘⱼₖ rⱼ rₖ with m = i, and Σᵢⱼ M2ᵢⱼₘ rᵢ rⱼ with m = k.
                            grad_cubic[i] += 2.0 * row[k] * r[j] * r[k];
                            grad_cubic[k] += row[k] * r[i] * r[j];
                        }
                    }
                }
                let inv_d9 = inv_d7 * inv_d2;
                for k in 0..3 {
                    g[k] += 0.5
                        * (-3.0 * (ab[k] * inv_d5 - 5.0 * ab_r * r[k] * inv_d7)
                            + 15.0 * (grad_cubic[k] * inv_d7 - 7.0 * cubic * r[k] * inv_d9));
                }
            }
        }
        g.map(|v| -v * INV_4PI)
    }
}

/// The far-field coefficients of one node in the form the query evaluates, precomputed from its
/// [`Moments`] and pre-scaled by `1/(4π)`: with `r = p̃ − q` and `d = ‖r‖`,
///
/// ```text
/// w̃ = n·r / d³                                       (order 0)
///   + tr / d³ − 3 rᵀ M1 r / d⁵                          (order 1)
///   − 3/2 v·r / d⁵ + 15/2 Σ M2ᵢⱼₖ rᵢ rⱼ rₖ / d⁷           (order 2)
/// ```
///
/// where `tr = tr M1`, `vₖ = Σᵢ M2ᵢᵢₖ + 2 Σᵢ M2ᵢₖᵢ`, `M1` is kept as the six coefficients of its
/// quadratic form and `M2` as the ten coefficients of its cubic form.
///
/// The coefficients are stored for `u = r / s`, `s` the node radius: `n/s²`, `tr/s³`, `M1/s³`,
/// `v/s⁴`, `M2/s⁴` (each term of `w̃` is homogeneous of degree 0). They are then of order 1
/// whatever the mesh's units, so the `f32` lanes neither underflow (a mesh in metres of size
/// 1e-2 has `M2 ≈ 1e-10`, and `M2/d⁷` runs into subnormals) nor overflow.
///
/// `T` is `f64` (one node), `f32x4` (the four lanes of a node of the 4-wide query tree, as stored
/// and as one query evaluates them) or [`Lanes8`] (one lane, splat, for the eight queries of a
/// packet): one generic formula serves all three. `f32` halves the arithmetic and the memory of the far field; its
/// rounding (~1e-7 relative per node) is four orders below the truncation error of the
/// expansion (~1e-3), and the near field, which decides the β → ∞ limit, stays `f64`.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub(crate) struct FarField<T = f64> {
    /// `1/s`.
    inv_s: T,
    n: [T; 3],
    tr: T,
    /// Coefficients of `r0², r1², r2², r0r1, r0r2, r1r2`.
    q: [T; 6],
    v: [T; 3],
    /// Coefficients of `r0³, r1³, r2³, r0²r1, r0²r2, r1²r0, r1²r2, r2²r0, r2²r1, r0r1r2`.
    c: [T; 10],
}

/// The arithmetic [`FarField::eval`] needs: `f64` (the reference [`Moments::far_field`] is
/// checked against), four `f32` lanes (one query, the four lanes of a query-tree node) and
/// eight `f32` lanes (one lane of a node, eight queries of a packet). Every implementation
/// rounds each operation lane by lane as IEEE `f32`, so a lane's value does not depend on
/// the width it was computed in: a batch equals the same points evaluated one by one.
pub(crate) trait Lanes:
    Copy + std::ops::Add<Output = Self> + std::ops::Mul<Output = Self>
{
    /// `1/√x`.
    fn rsqrt(self) -> Self;
}

impl Lanes for f64 {
    #[inline]
    fn rsqrt(self) -> Self {
        1.0 / self.sqrt()
    }
}

impl Lanes for f32x4 {
    #[inline(always)]
    fn rsqrt(self) -> Self {
        f32x4::ONE / self.sqrt()
    }
}

impl Lanes for Lanes8 {
    #[inline(always)]
    fn rsqrt(self) -> Self {
        Lanes8::splat((), 1.0) / self.sqrt()
    }
}

/// The slot in [`FarField`]'s cubic coefficients `c` of the term `xᵢ xⱼ x_k`: the slot of the
/// sorted triple, in the order `xxx, yyy, zzz, xxy, xxz, xyy, yyz, xzz, yzz, xyz`. A table
/// because [`FarField::new`] looked it up by sorting the triple 27 times per node, a tenth of
/// a 0.8M-triangle build (docs/benchmarks.md, "The tree build at 0.8M triangles").
const CUBIC_INDEX: [[[usize; 3]; 3]; 3] = {
    let mut table = [[[0; 3]; 3]; 3];
    let mut i = 0;
    while i < 3 {
        let mut j = 0;
        while j < 3 {
            let mut k = 0;
            while k < 3 {
                // The counts of 0s, 1s and 2s name the monomial.
                let mut count = [0; 3];
                count[i] += 1;
                count[j] += 1;
                count[k] += 1;
                table[i][j][k] = match count {
                    [3, 0, 0] => 0,
                    [0, 3, 0] => 1,
                    [0, 0, 3] => 2,
                    [2, 1, 0] => 3,
                    [2, 0, 1] => 4,
                    [1, 2, 0] => 5,
                    [0, 2, 1] => 6,
                    [1, 0, 2] => 7,
                    [0, 1, 2] => 8,
                    _ => 9,
                };
                k += 1;
            }
            j += 1;
        }
        i += 1;
    }
    table
};

impl FarField {
    pub fn new(m: &Moments) -> Self {
        let s = INV_4PI;
        let m1 = &m.m1;
        let q = [
            m1[0][0],
            m1[1][1],
            m1[2][2],
            m1[0][1] + m1[1][0],
            m1[0][2] + m1[2][0],
            m1[1][2] + m1[2][1],
        ];
        // Full M2ᵢⱼₖ from the stored symmetric rows (a table, not a search per entry: this
        // runs once per node of the tree).
        let mut full = [[[0.0; 3]; 3]; 3];
        for (s, &(i, j)) in SYM_PAIRS.iter().enumerate() {
            full[i][j] = m.m2[s];
            full[j][i] = m.m2[s];
        }
        let row = |i: usize, j: usize| full[i][j];
        let mut v = [0.0; 3];
        for k in 0..3 {
            for i in 0..3 {
                v[k] += row(i, i)[k] + 2.0 * row(i, k)[i];
            }
        }
        let mut c = [0.0; 10];
        for i in 0..3 {
            for j in 0..3 {
                for k in 0..3 {
                    let idx = CUBIC_INDEX[i][j][k];
                    c[idx] += row(i, j)[k];
                }
            }
        }
        // Any positive scale is exact; a zero radius (coincident points) takes 1.
        let inv = 1.0 / m.radius;
        let (scale, inv_s) = if m.radius > 0.0 && inv.is_finite() {
            (m.radius, inv)
        } else {
            (1.0, 1.0)
        };
        let (s2, s3, s4) = (s / scale.powi(2), s / scale.powi(3), s / scale.powi(4));
        FarField {
            inv_s,
            n: m.n.map(|x| x * s2),
            tr: (m1[0][0] + m1[1][1] + m1[2][2]) * s3,
            q: q.map(|x| -3.0 * s3 * x),
            v: v.map(|x| -1.5 * s4 * x),
            c: c.map(|x| 7.5 * s4 * x),
        }
    }
}

impl FarField<f32x4> {
    /// Up to four records side by side, one per lane, rounded to `f32` (missing lanes zero).
    pub fn lanes(f: &[&FarField]) -> Self {
        fn pack<const N: usize>(
            f: &[&FarField],
            get: impl Fn(&FarField) -> [f64; N],
        ) -> [f32x4; N] {
            std::array::from_fn(|i| {
                f32x4::from(std::array::from_fn::<f32, 4, _>(|l| {
                    f.get(l).map_or(0.0, |x| get(x)[i] as f32)
                }))
            })
        }
        FarField {
            inv_s: pack(f, |x| [x.inv_s])[0],
            n: pack(f, |x| x.n),
            tr: pack(f, |x| [x.tr])[0],
            q: pack(f, |x| x.q),
            v: pack(f, |x| x.v),
            c: pack(f, |x| x.c),
        }
    }

    /// `1/s` of each lane.
    #[inline(always)]
    pub fn inv_s(&self) -> &f32x4 {
        &self.inv_s
    }

    /// Lane `l` of the record, the same coefficients in every lane of `T`.
    #[inline(always)]
    pub fn lane<T: Copy>(&self, l: usize, splat: impl Fn(f32) -> T) -> FarField<T> {
        let get = |v: &f32x4| splat(v.as_array_ref()[l]);
        // Element by element, not `array::map`: this runs inside the packet walks' AVX2
        // instantiations, and when the inliner left `map`'s closure out of line (which a change
        // elsewhere in the crate could decide), the splats in it ran as calls compiled without
        // AVX: the walk took 2.3× as long (docs/benchmarks.md, "Radix-sorted packets").
        let (n, q, v, c) = (&self.n, &self.q, &self.v, &self.c);
        FarField {
            inv_s: get(&self.inv_s),
            n: [get(&n[0]), get(&n[1]), get(&n[2])],
            tr: get(&self.tr),
            q: [
                get(&q[0]),
                get(&q[1]),
                get(&q[2]),
                get(&q[3]),
                get(&q[4]),
                get(&q[5]),
            ],
            v: [get(&v[0]), get(&v[1]), get(&v[2])],
            c: [
                get(&c[0]),
                get(&c[1]),
                get(&c[2]),
                get(&c[3]),
                get(&c[4]),
                get(&c[5]),
                get(&c[6]),
                get(&c[7]),
                get(&c[8]),
                get(&c[9]),
            ],
        }
    }
}

impl<T: Lanes> FarField<T> {
    /// The same value as [`Moments::far_field`] at `q = p̃ − r` (per lane).
    #[inline(always)]
    pub fn eval(&self, r: [T; 3], order: u8) -> T {
        let (scaled, inv_d) = Self::scale(r, self.inv_s);
        self.eval_scaled(scaled, inv_d, order)
    }

    /// The first half of [`FarField::eval`]: `r/s` and `s/|r|`, given `1/s`. Apart from the
    /// polynomial so that the packet walk can start every lane's square root and division
    /// before it needs the first: the walk was waiting on them (docs/benchmarks.md, "Far field
    /// by Horner, square roots first").
    #[inline(always)]
    pub fn scale(r: [T; 3], inv_s: T) -> ([T; 3], T) {
        let (x, y, z) = (r[0] * inv_s, r[1] * inv_s, r[2] * inv_s);
        let inv_d = (x * x + y * y + z * z).rsqrt();
        ([x, y, z], inv_d)
    }

    /// The second half of [`FarField::eval`], from [`FarField::scale`]'s values.
    #[inline(always)]
    pub fn eval_scaled(&self, [x, y, z]: [T; 3], inv_d: T, order: u8) -> T {
        let (xx, yy, zz) = (x * x, y * y, z * z);
        let inv_d2 = inv_d * inv_d;
        let inv_d3 = inv_d * inv_d2;
        let mut w3 = self.n[0] * x + self.n[1] * y + self.n[2] * z;
        if order == 0 {
            return w3 * inv_d3;
        }
        // The products of two coordinates once, shared by the quadrupole and octupole terms,
        // and the powers of 1/d by Horner: the far field is most of a walk on the meshes where
        // it is cheap for libigl (docs/benchmarks.md, "Far field by Horner").
        let (xy, xz, yz) = (x * y, x * z, y * z);
        let q = &self.q;
        w3 = w3 + self.tr;
        let mut w5 = q[0] * xx + q[1] * yy + q[2] * zz + q[3] * xy + q[4] * xz + q[5] * yz;
        if order == 1 {
            return (w3 + w5 * inv_d2) * inv_d3;
        }
        w5 = w5 + self.v[0] * x + self.v[1] * y + self.v[2] * z;
        let c = &self.c;
        let w7 = x * (c[0] * xx + c[3] * xy + c[4] * xz + c[5] * yy + c[7] * zz)
            + y * (c[1] * yy + c[6] * yz + c[8] * zz)
            + z * (c[2] * zz + c[9] * xy);
        (w3 + (w5 + w7 * inv_d2) * inv_d2) * inv_d3
    }
}

#[inline]
fn mid(a: [f64; 3], b: [f64; 3], c: [f64; 3]) -> [f64; 3] {
    [
        0.5 * (a[0] + b[0]) - c[0],
        0.5 * (a[1] + b[1]) - c[1],
        0.5 * (a[2] + b[2]) - c[2],
    ]
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::kernel::spherical::triangle_solid_angle;

    /// Tensor-product Gauss–Legendre (3 points per direction) on the square mapped to the
    /// triangle by `x = a + u(b − a) + v(1 − u)(c − a)`: exact for polynomials of degree ≤ 5 in
    /// each of `u, v`, an independent check of the centroid and edge-midpoint rules.
    fn quadrature(a: [f64; 3], b: [f64; 3], c: [f64; 3], f: impl Fn([f64; 3]) -> f64) -> f64 {
        let s = (0.6_f64).sqrt();
        let nodes = [0.5 * (1.0 - s), 0.5, 0.5 * (1.0 + s)];
        let weights = [5.0 / 18.0, 8.0 / 18.0, 5.0 / 18.0];
        let ab = sub(b, a);
        let ac = sub(c, a);
        let n = cross(ab, ac);
        let jac = dot(n, n).sqrt(); // |∂x/∂u × ∂x/∂v| = (1 − u)·|ab × ac|
        let mut total = 0.0;
        for (iu, &u) in nodes.iter().enumerate() {
            for (iv, &v) in nodes.iter().enumerate() {
                let x = [0, 1, 2].map(|k| a[k] + u * ab[k] + v * (1.0 - u) * ac[k]);
                total += weights[iu] * weights[iv] * (1.0 - u) * jac * f(x);
            }
        }
        total
    }

    const A: [f64; 3] = [0.3, -0.2, 0.1];
    const B: [f64; 3] = [1.4, 0.35, -0.5];
    const C: [f64; 3] = [0.1, 0.9, 0.7];
    const P: [f64; 3] = [0.4, 0.1, -0.3];

    #[test]
    fn triangle_moments_match_quadrature() {
        let m = Moments::of_triangle(A, B, C, P);
        let nn = cross(sub(B, A), sub(C, A));
        let unit = nn.map(|v| v / dot(nn, nn).sqrt());
        let area = quadrature(A, B, C, |_| 1.0);
        assert!((m.area - area).abs() < 1e-14);
        for k in 0..3 {
            let q = quadrature(A, B, C, |_| unit[k]);
            assert!((m.n[k] - q).abs() < 1e-14, "N[{k}]");
        }
        for i in 0..3 {
            for j in 0..3 {
                let q = quadrature(A, B, C, |x| (x[i] - P[i]) * unit[j]);
                assert!((m.m1[i][j] - q).abs() < 1e-14, "M1[{i}][{j}] {q}");
            }
        }
        for (s, &(i, j)) in SYM_PAIRS.iter().enumerate() {
            for k in 0..3 {
                let q = quadrature(A, B, C, |x| (x[i] - P[i]) * (x[j] - P[j]) * unit[k]);
                assert!((m.m2[s][k] - q).abs() < 1e-14, "M2[{i}{j}][{k}] {q}");
            }
        }
    }

    #[test]
    fn recentring_equals_direct_expansion() {
        let other = [2.0, -1.0, 0.5];
        let shifted = Moments::of_triangle(A, B, C, P).recentred(other);
        let direct = Moments::of_triangle(A, B, C, other);
        for i in 0..3 {
            for j in 0..3 {
                assert!((shifted.m1[i][j] - direct.m1[i][j]).abs() < 1e-13);
            }
        }
        for s in 0..6 {
            for k in 0..3 {
                assert!((shifted.m2[s][k] - direct.m2[s][k]).abs() < 1e-13);
            }
        }
    }

    /// The error of the order-p expansion of one triangle decays like `d^-(p+3)`: doubling the
    /// distance divides it by about `2^(p+3)`. A wrong coefficient or sign in any order shows up
    /// as the wrong rate (the error would be dominated by a lower-order term).
    #[test]
    fn expansion_error_decays_with_the_right_order() {
        // Expanded about a point off the centroid, so that no order vanishes identically (about
        // the centroid M1 = 0 and the order-0 error would already fall like d^-4).
        let g = [0, 1, 2].map(|k| (A[k] + B[k] + C[k]) / 3.0 + 0.1);
        let m = Moments::of_triangle(A, B, C, g);
        let dir = [0.48, -0.6, 0.64];
        let exact = |d: f64| {
            let q = [0, 1, 2].map(|k| g[k] + d * dir[k]);
            let r = [A, B, C].map(|v| sub(v, q));
            (triangle_solid_angle(r[0], r[1], r[2]) * INV_4PI, q)
        };
        for order in 0..=2u8 {
            let err = |d: f64| {
                let (w, q) = exact(d);
                (m.far_field(q, order) - w).abs()
            };
            let (e1, e2) = (err(32.0), err(64.0));
            let rate = (e1 / e2).log2();
            let expected = f64::from(order) + 3.0;
            assert!(
                (rate - expected).abs() < 0.3,
                "order {order}: rate {rate}, expected {expected} ({e1:e} → {e2:e})"
            );
        }
    }

    #[test]
    fn compact_far_field_equals_the_moment_form() {
        let m = Moments::of_triangle(A, B, C, P).recentred([0.2, 0.5, -0.1]);
        let f = FarField::new(&m);
        for q in [[3.0, -2.0, 1.5], [-0.7, 4.0, 2.2], [0.1, 0.2, -5.0]] {
            let r = sub(m.center, q);
            for order in 0..=3u8 {
                let (a, b) = (m.far_field(q, order), f.eval(r, order));
                assert!(
                    (a - b).abs() <= 1e-14 * a.abs().max(1e-3),
                    "{order}: {a} vs {b}"
                );
            }
        }
    }

    #[test]
    fn f32_lanes_equal_the_scalar_far_field_and_each_other_bit_for_bit() {
        let centres = [P, [0.2, 0.5, -0.1], [-1.0, 0.3, 0.2], [0.7, -0.4, 0.9]];
        let nodes = centres.map(|c| Moments::of_triangle(A, B, C, P).recentred(c));
        let far = nodes.map(|m| FarField::new(&m));
        let lanes = FarField::<f32x4>::lanes(&[&far[0], &far[1], &far[2]]);
        let queries: [[f64; 3]; 8] = std::array::from_fn(|i| {
            let t = i as f64;
            [3.0 - 0.7 * t, -2.0 + 0.3 * t * t, 1.5 + (0.9 * t).sin()]
        });
        for order in 0..=2u8 {
            // One query, four lanes (lane 3 missing: zero coefficients, NaN, never admitted).
            for q in queries {
                let r = [0, 1, 2].map(|k| {
                    f32x4::from(std::array::from_fn::<f32, 4, _>(|l| {
                        (nodes[l].center[k] - q[k]) as f32
                    }))
                });
                let got = lanes.eval(r, order).to_array();
                for l in 0..3 {
                    let want = nodes[l].far_field(q, order);
                    assert!(
                        (f64::from(got[l]) - want).abs() <= 1e-6 * want.abs().max(1e-3),
                        "order {order}, lane {l}: {} vs {want}",
                        got[l]
                    );
                    // The same lane for eight queries: the same f32 operations, lane by lane.
                    let r8 = [0, 1, 2].map(|k| {
                        Lanes8::from_array((), queries.map(|p| (nodes[l].center[k] - p[k]) as f32))
                    });
                    let w8 = lanes
                        .lane(l, |v| Lanes8::splat((), v))
                        .eval(r8, order)
                        .to_array();
                    let i = queries.iter().position(|p| *p == q).expect("a query");
                    assert_eq!(w8[i].to_bits(), got[l].to_bits(), "order {order}, lane {l}");
                    // And in one AVX register, where the CPU has AVX2.
                    #[cfg(target_arch = "x86_64")]
                    if let Some(t) = super::super::packet::Avx2::detect() {
                        use super::super::packet::Avx8;
                        let r8 = [0, 1, 2].map(|k| {
                            Avx8::from_array(t, queries.map(|p| (nodes[l].center[k] - p[k]) as f32))
                        });
                        let w8 = lanes
                            .lane(l, |v| Avx8::splat(t, v))
                            .eval(r8, order)
                            .to_array();
                        assert_eq!(
                            w8[i].to_bits(),
                            got[l].to_bits(),
                            "AVX, order {order}, lane {l}"
                        );
                    }
                }
            }
        }
    }

    #[test]
    fn far_field_gradient_matches_finite_differences() {
        let (a, b, c) = ([0.1, -0.2, 0.05], [0.4, 0.3, -0.1], [-0.2, 0.25, 0.3]);
        let mut m = Moments::of_triangle(a, b, c, [0.05, 0.0, 0.02]);
        m.accumulate(&Moments::of_triangle(c, b, [0.3, -0.3, 0.4], m.center));
        for order in 0..=2u8 {
            for q in [[2.0, 1.0, -0.5], [-1.3, 0.4, 1.7], [0.2, -2.5, 0.1]] {
                let g = m.far_field_gradient(q, order);
                let h = 1e-5;
                for k in 0..3 {
                    let (mut hi, mut lo) = (q, q);
                    hi[k] += h;
                    lo[k] -= h;
                    let fd = (m.far_field(hi, order) - m.far_field(lo, order)) / (2.0 * h);
                    let scale = g.iter().map(|v| v.abs()).fold(0.0, f64::max);
                    assert!(
                        (fd - g[k]).abs() <= 1e-7 * scale,
                        "order {order}, q {q:?}, axis {k}: {fd} vs {}",
                        g[k]
                    );
                }
            }
        }
    }

    #[test]
    fn dipole_sign_points_outward() {
        // A triangle in z = 0 with normal +z: seen from below (q.z < 0) it subtends a positive
        // solid angle (w > 0), from above a negative one. FOSSIL's published far field has the
        // sign of (c − q) flipped; ours must agree with the exact solid angle.
        let (a, b, c) = ([0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]);
        let m = Moments::of_triangle(a, b, c, [1.0 / 3.0, 1.0 / 3.0, 0.0]);
        for z in [-20.0, 20.0] {
            let q = [0.2, 0.3, z];
            let exact = triangle_solid_angle(sub(a, q), sub(b, q), sub(c, q)) * INV_4PI;
            for order in 0..=2 {
                let w = m.far_field(q, order);
                assert_eq!(w.signum(), exact.signum());
                assert!((w - exact).abs() < 1e-3 * exact.abs());
            }
        }
    }
}
