//! Fast approximate winding numbers: the Barnes–Hut method of Barill, Dickson, Schmidt, Levin &
//! Jacobson, *Fast Winding Numbers for Soups and Clouds* (SIGGRAPH 2018), for triangle soups and
//! oriented point clouds (the FOSSIL-style `winding_number(point, beta)` API that picks fast or
//! exact is [`crate::eval::fossil`]).
//!
//! # Method
//!
//! A binary median-split AABB tree ([`FastWindingNumber`], [`PointCloudWindingNumber`]) stores
//! per node the area-weighted centre `p̃`, the radius `r` (largest distance from `p̃` to any
//! triangle corner or point below the node) and the [`Moments`] of order 0, 1 and 2 (exact
//! closed forms for triangles: centroid rule and edge-midpoint rule), built bottom-up by
//! re-centring the children's moments (parallel-axis shifts). For the queries the binary tree is
//! collapsed into a 4-wide one: one `f32x4` test decides a node's four admissibilities and one
//! `f32x4` evaluation computes its four expansions (AVX2 when the CPU has it, chosen at run time;
//! bit-identical either way). Batches walk the tree in Morton-sorted packets of eight queries,
//! one lane of an 8-lane `f32` vector per query (one AVX register on CPUs with AVX2), with the
//! values of the queries one by one, bit for bit
//! (`packet.rs`). `FASTWN(q)` (Algorithm 1) uses a node's
//! expansion when `‖q − p̃‖ > β r`, sums exact Van Oosterom–Strackee solid angles (four triangles
//! at a time, one complex product instead of one `atan2` per triangle) or exact dipoles over a
//! near leaf, and otherwise opens the node. Per query the cost is
//! `O(log F)` with an error controlled by `β` and the order: each far node's relative error is
//! about `β^-(order+1)`.
//!
//! Defaults: β = 2, order 2 for triangles (RMS error 4e-4 – 1e-3 on the shared meshes); β = 2.3,
//! order 2 for points.
//!
//! # Choosing β: FOSSIL vs Barill
//!
//! FOSSIL admits a node when `‖q − c‖ > β_F · D`, `D` the diagonal of the node's bounding box, and
//! then uses a first-order dipole (`N · ∇G`, Barill's order 0). Barill admits it when
//! `‖q − p̃‖ > β_B · r`. Both `p̃` and the element points lie in the box, so `r ≤ D`; and two element
//! points sit on opposite faces of the box along its longest side (≥ `D/√3`), so by the triangle
//! inequality `2r ≥ D/√3`. Hence
//!
//! ```text
//! FOSSIL(β_F)  ≡  Barill(β_B = β_F · D/r),   1 ≤ D/r ≤ 2√3,
//! ```
//!
//! node by node: the FOSSIL test is Barill's test with a per-node β between `β_F` and `3.46 β_F`.
//! For a flat square patch centred on `p̃`, `D/r = 2`; for a ball-like cluster `D/r = 2√3`. On the
//! trees built here for real meshes `D/r` ranges over about 1.2–2.7 with a median of 1.7–2.1 (see
//! `docs/fast.md`), so FOSSIL's default `β_F = 2` recurses about as far as Barill `β_B ≈ 4`, but
//! then uses order 0, whose error falls only like `β^-1`: measured RMS 1e-3 – 4e-3, where
//! Barill's order 2 at `β_B = 2` reaches ≤ 1e-3 about 2.5–3× faster (it opens far fewer nodes).
//! libigl's rule ([`Admissibility::BoxCorner`]: `size` = distance from `p̃` to the farthest corner
//! of the node's box, `≥ r`) is Barill's with the per-node β `β·ρ/r ≥ β`. Against libigl's default
//! (accuracy_scale 2), Barill β = 2.8 is the smallest β whose max error was at most libigl's on
//! every mesh of the shared corpus libigl reads (`tests/fast_vs_libigl.rs`, `docs/fast.md`).
//! [`FastOrExact::winding_number`](crate::eval::fossil::FastOrExact::winding_number) interprets `beta` as Barill's `β_B` (order 2); [`FastParams::fossil`] reproduces FOSSIL's rule
//! (with the far field's sign right: FOSSIL's published dipole takes `c − q` with the wrong sign;
//! ours is tested against the direct sum).
//!
//! Note on the paper's Appendix A: `∇³G` is printed without the factor 3 on its first term;
//! the code uses the harmonic (trace-free) form, see [`Moments`].
//!
//! # Exact vs fast
//!
//! | input | use |
//! |---|---|
//! | closed or nearly closed meshes (boundary edges ≪ faces) | exact (`eval::antipodal`) |
//! | triangle soups, scans with many holes (boundary ≈ faces) | fast, β = 2, order 2 |
//! | oriented point clouds | fast ([`PointCloudWindingNumber`]), β = 2.3, order 2 |
//! | ground truth for tests | `eval::direct` |

mod area;
mod barnes_hut;
mod cloud;
mod moments;
mod packet;
mod soup;
mod tree;

pub use area::estimate_areas;
pub use barnes_hut::{Admissibility, BOX_CORNER_SCALE, FastParams};
pub use cloud::{
    DEFAULT_AREA_NEIGHBOURS, POINT_LEAF_SIZE, PointCloudWindingNumber, winding_number_points_direct,
};
pub use moments::{Moments, SYM_PAIRS};
pub use soup::{FastWindingNumber, TRIANGLE_LEAF_SIZE};

use crate::base::bounding_box::BoundingBox;
use crate::kernel::quantize::{Rescale, pull_in};

/// How the fast evaluators keep their `f64`/`f32` arithmetic in range (issue 11, section 4): the
/// input is scaled by a power of two to extent `[1, 2)` (exact; the expansions overflowed for
/// meshes at 1e103 and underflowed at 1e-110), and queries farther than `2^30` extents are pulled
/// in to that distance (the `f32` far field overflowed beyond ~1e19), which changes `w` by less
/// than `2^-60` (see `kernel::quantize::Grid::pull_in_far`).
#[derive(Clone, Copy, Debug)]
pub(crate) struct InputScale {
    rescale: Rescale,
    center: [f64; 3],
    far: f64,
}

impl InputScale {
    /// The scaling for input points with bounding box `b` (world coordinates).
    pub(crate) fn new(b: Option<BoundingBox>) -> Self {
        let Some(b) = b else {
            return InputScale {
                rescale: Rescale::for_box(&BoundingBox {
                    min: [0.0; 3],
                    max: [0.0; 3],
                }),
                center: [0.0; 3],
                far: f64::INFINITY,
            };
        };
        let rescale = Rescale::for_box(&b);
        let (lo, hi) = (rescale.apply(b.min), rescale.apply(b.max));
        InputScale {
            rescale,
            center: std::array::from_fn(|k| 0.5 * lo[k] + 0.5 * hi[k]),
            far: (1u64 << 31) as f64,
        }
    }

    /// An input point (or a normal-times-area vector's length scale: see the callers).
    #[inline]
    pub(crate) fn point(&self, p: [f64; 3]) -> [f64; 3] {
        self.rescale.apply(p)
    }

    /// A query: scaled, then pulled in.
    #[inline]
    pub(crate) fn query(&self, q: [f64; 3]) -> [f64; 3] {
        pull_in(self.rescale.apply(q), self.center, self.far)
    }

    /// The gradient at world query `q` from `gradient`, which evaluates it in the scaled
    /// coordinates: `∇w` has degree −1 in lengths, so it scales back by the same power of two.
    /// Beyond the pull-in distance (`2^31` extents) the gradient is below `2^-62/extent` and
    /// returned as 0 (the expansions would overflow there).
    #[inline]
    pub(crate) fn gradient(
        &self,
        q: [f64; 3],
        gradient: impl FnOnce([f64; 3]) -> [f64; 3],
    ) -> [f64; 3] {
        let s = self.rescale.apply(q);
        // (NaN compares as far.)
        let within = |k: usize| (0.5 * s[k] - 0.5 * self.center[k]).abs() <= 0.5 * self.far;
        if !(within(0) && within(1) && within(2)) {
            return if q.iter().all(|c| c.is_finite()) {
                [0.0; 3]
            } else {
                [f64::NAN; 3]
            };
        }
        self.rescale.apply(gradient(s))
    }
}
