//! Four `f64` lanes: the operations the boundary loops are written in, for the portable
//! `wide::f64x4` ([`Portable`]) and AVX2 ([`Avx2`]), and the boundary loop's per-vertex algebra
//! and edge term written once over them ([`vertex_factors!`], [`edge_term!`]; the orientation
//! filter is a predicate and lives beside [`super::predicates::orient2d_filtered`]).
//!
//! The algebra is a macro, not a generic function: the AVX2 operations are `#[target_feature]`
//! functions, which a trait method cannot be, and a macro expands inside the caller's
//! `#[target_feature(enable = "avx2")]` body, where calling them is safe. Both expansions perform
//! the same IEEE operations in the same order, so the portable and AVX2 loops are bit-identical
//! (tested in `boundary_sum` and `boundary_column`).

use wide::{CmpGt, f64x4};

/// The portable lanes (`wide::f64x4`: two SSE2 halves on x86-64).
#[derive(Clone, Copy, Debug)]
pub(super) struct Portable;

#[allow(missing_docs)]
impl Portable {
    #[inline(always)]
    pub fn splat(self, v: f64) -> f64x4 {
        f64x4::splat(v)
    }
    #[inline(always)]
    pub fn add(self, a: f64x4, b: f64x4) -> f64x4 {
        a + b
    }
    #[inline(always)]
    pub fn sub(self, a: f64x4, b: f64x4) -> f64x4 {
        a - b
    }
    #[inline(always)]
    pub fn mul(self, a: f64x4, b: f64x4) -> f64x4 {
        a * b
    }
    #[inline(always)]
    pub fn sqrt(self, a: f64x4) -> f64x4 {
        a.sqrt()
    }
    #[inline(always)]
    pub fn abs(self, a: f64x4) -> f64x4 {
        a.abs()
    }
    /// All-ones lanes where `a > b` (ordered), else zero.
    #[inline(always)]
    pub fn gt(self, a: f64x4, b: f64x4) -> f64x4 {
        a.cmp_gt(b)
    }
    #[inline(always)]
    pub fn and(self, a: f64x4, b: f64x4) -> f64x4 {
        a & b
    }
    /// `yes` where `mask` is set, else `no`.
    #[inline(always)]
    pub fn select(self, mask: f64x4, yes: f64x4, no: f64x4) -> f64x4 {
        mask.blend(yes, no)
    }
}

/// The AVX2 lanes. Its operations are `#[target_feature(enable = "avx2")]`: callable (safely)
/// only from functions compiled with AVX2, which the loops reach after a run-time CPU check.
#[cfg(target_arch = "x86_64")]
#[derive(Clone, Copy, Debug)]
pub(super) struct Avx2;

#[cfg(target_arch = "x86_64")]
#[allow(missing_docs)]
impl Avx2 {
    #[target_feature(enable = "avx2")]
    #[inline]
    pub fn splat(self, v: f64) -> std::arch::x86_64::__m256d {
        std::arch::x86_64::_mm256_set1_pd(v)
    }
    #[target_feature(enable = "avx2")]
    #[inline]
    pub fn add(
        self,
        a: std::arch::x86_64::__m256d,
        b: std::arch::x86_64::__m256d,
    ) -> std::arch::x86_64::__m256d {
        std::arch::x86_64::_mm256_add_pd(a, b)
    }
    #[target_feature(enable = "avx2")]
    #[inline]
    pub fn sub(
        self,
        a: std::arch::x86_64::__m256d,
        b: std::arch::x86_64::__m256d,
    ) -> std::arch::x86_64::__m256d {
        std::arch::x86_64::_mm256_sub_pd(a, b)
    }
    #[target_feature(enable = "avx2")]
    #[inline]
    pub fn mul(
        self,
        a: std::arch::x86_64::__m256d,
        b: std::arch::x86_64::__m256d,
    ) -> std::arch::x86_64::__m256d {
        std::arch::x86_64::_mm256_mul_pd(a, b)
    }
    #[target_feature(enable = "avx2")]
    #[inline]
    pub fn sqrt(self, a: std::arch::x86_64::__m256d) -> std::arch::x86_64::__m256d {
        std::arch::x86_64::_mm256_sqrt_pd(a)
    }
    #[target_feature(enable = "avx2")]
    #[inline]
    pub fn abs(self, a: std::arch::x86_64::__m256d) -> std::arch::x86_64::__m256d {
        use std::arch::x86_64::*;
        _mm256_andnot_pd(_mm256_set1_pd(-0.0), a)
    }
    /// All-ones lanes where `a > b` (ordered, non-signalling), else zero.
    #[target_feature(enable = "avx2")]
    #[inline]
    pub fn gt(
        self,
        a: std::arch::x86_64::__m256d,
        b: std::arch::x86_64::__m256d,
    ) -> std::arch::x86_64::__m256d {
        use std::arch::x86_64::*;
        _mm256_cmp_pd::<_CMP_GT_OQ>(a, b)
    }
    #[target_feature(enable = "avx2")]
    #[inline]
    pub fn and(
        self,
        a: std::arch::x86_64::__m256d,
        b: std::arch::x86_64::__m256d,
    ) -> std::arch::x86_64::__m256d {
        std::arch::x86_64::_mm256_and_pd(a, b)
    }
    /// `yes` where `mask` is set, else `no`.
    #[target_feature(enable = "avx2")]
    #[inline]
    pub fn select(
        self,
        mask: std::arch::x86_64::__m256d,
        yes: std::arch::x86_64::__m256d,
        no: std::arch::x86_64::__m256d,
    ) -> std::arch::x86_64::__m256d {
        std::arch::x86_64::_mm256_blendv_pd(no, yes, mask)
    }
}

/// The per-vertex factors of the boundary loop, from a vertex's offsets `h = x² + y²` (see
/// [`horizontal_sq!`]) and `z` from the query: `s = |r| + |r_z|` and `p` with
/// `(|r| − r_z)·s = p`, i.e. `p = h` when `r_z > 0` and `s²` otherwise (no cancellation in
/// `|r| − r_z` either way). One `sqrt` per vertex, shared by the two edges that meet there.
macro_rules! vertex_factors {
    ($o:expr, $h:expr, $z:expr) => {{
        let (o, h, z) = ($o, $h, $z);
        let s = o.add(o.sqrt(o.add(h, o.mul(z, z))), o.abs(z));
        let p = o.select(o.gt(z, o.splat(0.0)), h, o.mul(s, s));
        (s, p)
    }};
}
pub(super) use vertex_factors;

/// `x² + y²` of a vertex's offsets from the query (shared by a column's queries).
macro_rules! horizontal_sq {
    ($o:expr, $x:expr, $y:expr) => {{
        let (o, x, y) = ($o, $x, $y);
        o.add(o.mul(x, x), o.mul(y, y))
    }};
}
pub(super) use horizontal_sq;

/// The projected dot product `a_x b_x + a_y b_y` of an edge's end offsets.
macro_rules! projected_dot {
    ($o:expr, $ax:expr, $ay:expr, $bx:expr, $by:expr) => {{
        let o = $o;
        o.add(o.mul($ax, $bx), o.mul($ay, $by))
    }};
}
pub(super) use projected_dot;

/// The edge term `den + i·num` of `Area(A, B, x1)` (antipodal paper, Eq. 9, as one factor of the
/// angle product): `den = (|a| − a_z)(|b| − b_z) + a_x b_x + a_y b_y` and `num = −d`, both scaled
/// by the positive `s_a·s_b` (no division, no cancellation): `den·s_a s_b = p_a p_b + dot·s_a s_b`.
/// `num` carries the exact sign of `−d` where the orientation filter decided it (`ok`); lanes it
/// did not (and non-edges) give the identity `1 + 0i`.
macro_rules! edge_term {
    ($o:expr, ($sa:expr, $pa:expr), ($sb:expr, $pb:expr), $dot:expr, $neg_d:expr, $ok:expr) => {{
        let o = $o;
        let s2 = o.mul($sa, $sb);
        let den = o.add(o.mul($pa, $pb), o.mul($dot, s2));
        let ok = $ok;
        (
            o.select(ok, den, o.splat(1.0)),
            o.select(ok, o.mul($neg_d, s2), o.splat(0.0)),
        )
    }};
}
pub(super) use edge_term;
