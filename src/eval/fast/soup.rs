//! The fast winding number of a triangle mesh or soup (Barill et al. 2018, Section 3.3).

use super::InputScale;
use super::barnes_hut::{FastParams, Hierarchy, NearLeaf};
use super::moments::Moments;
use super::packet::{PACKET, eval_in_packets, prefetch};
use super::tree::Tree;
use wide::{CmpGe, CmpGt, CmpLt, f64x4};

use crate::base::bounding_box::BoundingBox;
pub(crate) use crate::base::vec3::dist2;
use crate::base::vec3::{cross, dot, sub};
use crate::kernel::angle_sum::AngleSum;
use crate::kernel::spherical::{SOLID_ANGLE_CONDITION, segment_gradient, triangle_solid_angle_at};
use crate::mesh::Mesh;

use crate::kernel::spherical::INV_4PI;

/// Largest number of triangles in a leaf (summed exactly when the leaf is near the query).
pub const TRIANGLE_LEAF_SIZE: usize = 4;
// A leaf is one `f64x4` per coordinate, and `used_lanes` one bit per lane in a `u8`.
const _: () = assert!(TRIANGLE_LEAF_SIZE == 4);

/// Barnes–Hut evaluator of the generalized winding number of a triangle mesh (connectivity is
/// ignored: soups, open and non-manifold meshes are all fine). Owns a copy of the triangles, so it
/// does not borrow the mesh. `Send + Sync`; evaluation is read-only.
///
/// ```
/// use gwn::{Mesh, eval::fast::{FastParams, FastWindingNumber}};
/// let tet = Mesh::from_slices(
///     &[[0., 0., 0.], [1., 0., 0.], [0., 1., 0.], [0., 0., 1.]],
///     &[[0, 2, 1], [0, 1, 3], [1, 2, 3], [2, 0, 3]],
/// )?;
/// let fast = FastWindingNumber::new(&tet);
/// assert!((fast.eval([0.1, 0.1, 0.1]) - 1.0).abs() < 1e-12); // near: exact solid angles
/// let far = fast.eval_with([30.0, 0.0, 0.0], FastParams::barill(2.0, 2));
/// assert!(far.abs() < 1e-6);
/// # Ok::<(), gwn::error::MeshError>(())
/// ```
#[derive(Clone, Debug)]
pub struct FastWindingNumber {
    hierarchy: Hierarchy,
    /// Triangle corners in leaf order.
    triangles: Vec<[[f64; 3]; 3]>,
    /// The same corners leaf by leaf, one triangle per lane (`x, y, z` of `a`, `b`, `c`);
    /// unused lanes are zero, a triangle with `det = 0` that adds nothing.
    leaves: Vec<[f64x4; 9]>,
    /// Per leaf, the mask of its used lanes (`0b111` for three triangles): a leaf whose used
    /// lanes all took the fast path needs nothing else. (Its element range, 16 bytes per leaf
    /// in a second array, cost a cache miss per near leaf of fewer than four triangles.)
    used_lanes: Vec<u8>,
    params: FastParams,
    /// World → the scaled coordinates everything above is stored in.
    scale: InputScale,
}

impl FastWindingNumber {
    /// Builds the tree and the moments with the default parameters (β = 2, order 2).
    pub fn new(mesh: &Mesh) -> Self {
        Self::with_params(mesh, FastParams::default())
    }

    /// Builds the tree and the moments; `params` become the defaults of [`Self::eval`].
    pub fn with_params(mesh: &Mesh, params: FastParams) -> Self {
        let tris: Vec<[[f64; 3]; 3]> = (0..mesh.triangles().len())
            .map(|f| mesh.triangle_positions(f))
            .collect();
        Self::from_triangles(tris, params)
    }

    /// Builds from triangle corner triples (a soup).
    pub fn from_triangles(mut tris: Vec<[[f64; 3]; 3]>, params: FastParams) -> Self {
        let scale = InputScale::new(BoundingBox::of_points(tris.iter().flatten()));
        // In place: a copy was a fresh 72 bytes per triangle, paid in page faults.
        for t in &mut tris {
            *t = t.map(|v| scale.point(v));
        }
        let centroids: Vec<[f64; 3]> = tris.iter().map(centroid).collect();
        let boxes: Vec<([f64; 3], [f64; 3])> = tris
            .iter()
            .map(|t| {
                (
                    [0, 1, 2].map(|k| t[0][k].min(t[1][k]).min(t[2][k])),
                    [0, 1, 2].map(|k| t[0][k].max(t[1][k]).max(t[2][k])),
                )
            })
            .collect();
        let mut tree = Tree::build(&centroids, &boxes, TRIANGLE_LEAF_SIZE);
        drop((centroids, boxes));
        // The moments pass reads the triangles leaf by leaf: in leaf order (one gather here)
        // its reads are sequential, where by element id they were a cache miss each on large
        // meshes (docs/benchmarks.md, "The tree build at 0.8M triangles"). So the hierarchy is
        // built over positions in leaf order, an identity order, and gets the real one back.
        let triangles: Vec<[[f64; 3]; 3]> = tree.order.iter().map(|&e| tris[e as usize]).collect();
        drop(tris);
        let order = std::mem::replace(&mut tree.order, (0..triangles.len() as u32).collect());
        let mut hierarchy = Hierarchy::build(
            tree,
            |i| (triangle_area(&triangles[i]), centroid(&triangles[i])),
            |i, c| {
                let t = &triangles[i];
                Moments::of_triangle(t[0], t[1], t[2], c)
            },
            |i, c| {
                triangles[i]
                    .iter()
                    .map(|&v| dist2(v, c))
                    .fold(0.0, f64::max)
            },
        );
        hierarchy.tree.order = order;
        let leaves = hierarchy
            .leaves
            .iter()
            .map(|range| {
                let t = &triangles[range.clone()];
                std::array::from_fn(|i| {
                    f64x4::from(std::array::from_fn::<f64, 4, _>(|l| {
                        t.get(l).map_or(0.0, |t| t[i / 3][i % 3])
                    }))
                })
            })
            .collect();
        let used_lanes = hierarchy
            .leaves
            .iter()
            .map(|range| ((1u32 << range.len().min(TRIANGLE_LEAF_SIZE)) - 1) as u8)
            .collect();
        FastWindingNumber {
            hierarchy,
            triangles,
            leaves,
            used_lanes,
            params,
            scale,
        }
    }

    /// The parameters [`Self::eval`] uses.
    pub fn params(&self) -> FastParams {
        self.params
    }

    /// Changes the parameters [`Self::eval`] uses (no rebuild needed).
    pub fn set_params(&mut self, params: FastParams) {
        self.params = params;
    }

    /// The approximate winding number at `q` with the stored parameters.
    pub fn eval(&self, q: [f64; 3]) -> f64 {
        self.eval_with(q, self.params)
    }

    /// The approximate winding number at `q` with explicit parameters (Barill's form:
    /// `FastParams::barill(beta, order)`).
    pub fn eval_with(&self, q: [f64; 3], params: FastParams) -> f64 {
        let q = self.scale.query(q);
        let mut angles = AngleSum::new();
        let far_and_rare =
            self.hierarchy
                .eval(q, &params, self.leaf_terms(q, &mut angles, Simd::detect()));
        // Σ 2·atan2(det, den) / (4π).
        far_and_rare + angles.total() * (2.0 * INV_4PI)
    }

    /// [`Self::eval_with`] on the portable path only (the test of the run-time dispatch).
    #[cfg(test)]
    fn eval_portable(&self, q: [f64; 3], params: FastParams) -> f64 {
        let q = self.scale.query(q);
        let mut angles = AngleSum::new();
        let far_and_rare =
            self.hierarchy
                .eval_lanes(q, &params, self.leaf_terms(q, &mut angles, Simd::PORTABLE));
        far_and_rare + angles.total() * (2.0 * INV_4PI)
    }

    /// The exact terms of a near leaf seen from the (scaled) query `q`: the solid angles go into
    /// `angles`, the few that need the careful scalar formula into the sum.
    #[inline(always)]
    fn leaf_terms<'a>(
        &'a self,
        q: [f64; 3],
        angles: &'a mut AngleSum,
        simd: Simd,
    ) -> impl FnMut(usize, std::ops::Range<usize>, &mut f64) + 'a {
        move |k, _, sum| self.add_leaf_terms(simd, angles, q, k, sum)
    }

    /// The body of [`Self::leaf_terms`], shared with the packets of [`Self::eval_batch_with`].
    #[inline(always)]
    fn add_leaf_terms(
        &self,
        simd: Simd,
        angles: &mut AngleSum,
        q: [f64; 3],
        k: usize,
        sum: &mut f64,
    ) {
        let ok = simd.push_solid_angles(angles, &self.leaves[k], q);
        if ok & u32::from(self.used_lanes[k]) != u32::from(self.used_lanes[k]) {
            let range = self.hierarchy.leaves[k].clone();
            for (l, t) in self.triangles[range].iter().enumerate() {
                if ok & (1 << l) == 0 {
                    // The direct sum's term: exact offsets and double-double where the f64
                    // formula is ill-conditioned (next to an edge).
                    *sum += triangle_solid_angle_at(*t, q) * INV_4PI;
                }
            }
        }
    }

    /// [`Self::eval`] for many points, in parallel (rayon).
    pub fn eval_batch(&self, points: &[[f64; 3]]) -> Vec<f64> {
        self.eval_batch_with(points, self.params)
    }

    /// Gradient of the approximation at `q` with the stored parameters.
    pub fn gradient(&self, q: [f64; 3]) -> [f64; 3] {
        self.gradient_with(q, self.params)
    }

    /// Gradient of the approximation [`Self::eval_with`] computes: each admissible node's
    /// expansion differentiated ([`Moments::far_field_gradient`]), and near triangles by the
    /// Biot–Savart segment sum of the direct gradient
    /// (the exact kernel's `segment_gradient`). Tends to the exact gradient as β
    /// grows; not finite on the triangles' edges.
    pub fn gradient_with(&self, q: [f64; 3], params: FastParams) -> [f64; 3] {
        self.scale.gradient(q, |q| {
            self.hierarchy.gradient(q, &params, |range, g| {
                for t in &self.triangles[range] {
                    for (i, j) in [(0, 1), (1, 2), (2, 0)] {
                        if t[i] == t[j] {
                            continue;
                        }
                        let e = segment_gradient(sub(t[i], q), sub(t[j], q));
                        for k in 0..3 {
                            g[k] += e[k] * INV_4PI;
                        }
                    }
                }
            })
        })
    }

    /// [`Self::eval_with`] for many points, in parallel (rayon): equal to it point by point,
    /// bit for bit, and faster, as neighbouring points walk the tree together in packets of
    /// eight (see `docs/fast.md`).
    pub fn eval_batch_with(&self, points: &[[f64; 3]], params: FastParams) -> Vec<f64> {
        self.eval_in_packets(points, params, false)
    }

    /// [`Self::eval_batch_with`], on the portable instantiation of the packet walk when
    /// `portable` (the test of the run-time dispatch).
    fn eval_in_packets(&self, points: &[[f64; 3]], params: FastParams, portable: bool) -> Vec<f64> {
        eval_in_packets(
            points,
            self.hierarchy.packets_need_order(),
            |packet, active| {
                let q = packet.map(|p| self.scale.query(p));
                let mut angles: [AngleSum; PACKET] = std::array::from_fn(|_| AngleSum::new());
                let simd = if portable {
                    Simd::PORTABLE
                } else {
                    Simd::detect()
                };
                let mut touched = 0u32;
                let leaf = NearTriangles {
                    fast: self,
                    simd,
                    angles: &mut angles,
                    q: &q,
                    touched: &mut touched,
                };
                let far_and_rare = if portable {
                    self.hierarchy.eval_packet_lanes::<super::packet::Lanes8>(
                        (),
                        &q,
                        active,
                        &params,
                        leaf,
                    )
                } else {
                    self.hierarchy.eval_packet(&q, active, &params, leaf)
                };
                // A query that met no near leaf has an empty angle sum, whose total is +0.0: adding
                // it changes nothing (`far_and_rare` is never −0.0), so its `atan2` is skipped.
                std::array::from_fn(|i| {
                    if touched & (1 << i) != 0 {
                        far_and_rare[i] + angles[i].total() * (2.0 * INV_4PI)
                    } else {
                        far_and_rare[i]
                    }
                })
            },
        )
    }

    /// A world point in the coordinates of [`Self::node_box`] and [`Self::node_moments`]: the
    /// input scaled by a power of two to extent `[1, 2)` (exact; see `InputScale`).
    pub fn internal_point(&self, p: [f64; 3]) -> [f64; 3] {
        self.scale.point(p)
    }

    /// Number of triangles.
    pub fn len(&self) -> usize {
        self.triangles.len()
    }

    /// True when there are no triangles (every query evaluates to 0).
    pub fn is_empty(&self) -> bool {
        self.triangles.is_empty()
    }

    /// Number of tree nodes (node 0 is the root).
    pub fn node_count(&self) -> usize {
        self.hierarchy.tree.len()
    }

    /// The expansion of node `id` (centre, radius, order 0–2 coefficients), in the coordinates of
    /// [`Self::internal_point`].
    pub fn node_moments(&self, id: usize) -> &Moments {
        &self.hierarchy.moments[id]
    }

    /// The two children of node `id`, `None` for a leaf.
    pub fn node_children(&self, id: usize) -> Option<[usize; 2]> {
        let node = &self.hierarchy.tree.nodes[id];
        (!node.is_leaf()).then(|| [node.left as usize, node.left as usize + 1])
    }

    /// Indices (into the input triangles) of the triangles below node `id`.
    pub fn node_triangles(&self, id: usize) -> &[u32] {
        &self.hierarchy.tree.order[self.hierarchy.tree.nodes[id].range()]
    }

    /// Bounding box of the triangles below node `id` ([`Self::internal_point`] coordinates).
    pub fn node_box(&self, id: usize) -> BoundingBox {
        let n = &self.hierarchy.tree.nodes[id];
        BoundingBox {
            min: n.min,
            max: n.max,
        }
    }
}

/// The near leaves of a packet ([`Hierarchy::eval_packet`]): their exact solid angles.
struct NearTriangles<'a> {
    fast: &'a FastWindingNumber,
    simd: Simd,
    angles: &'a mut [AngleSum; PACKET],
    q: &'a [[f64; 3]; PACKET],
    /// Bit `i` set once query `i` met a near leaf.
    touched: &'a mut u32,
}

impl NearLeaf for NearTriangles<'_> {
    #[inline(always)]
    fn prefetch(&self, leaf: usize) {
        prefetch(&self.fast.leaves[leaf]);
    }

    #[inline(always)]
    fn add(&mut self, query: usize, leaf: usize, sum: &mut f64) {
        let q = self.q[query];
        *self.touched |= 1 << query;
        self.fast
            .add_leaf_terms(self.simd, &mut self.angles[query], q, leaf, sum);
    }
}

/// Which instructions the near leaves' solid angles run on: AVX2 registers where the CPU has
/// them (the walks run compiled for AVX2, but `wide`'s `f64x4` is two SSE halves in a portable
/// build), else `wide`. Both do the same IEEE operations in the same order: the same bits.
#[derive(Clone, Copy, Debug)]
struct Simd {
    #[cfg(target_arch = "x86_64")]
    avx2: Option<super::packet::Avx2>,
}

impl Simd {
    /// `wide` only (the portable path, and the test of the dispatch).
    const PORTABLE: Simd = Simd {
        #[cfg(target_arch = "x86_64")]
        avx2: None,
    };

    #[inline]
    fn detect() -> Simd {
        Simd {
            #[cfg(target_arch = "x86_64")]
            avx2: super::packet::Avx2::detect(),
        }
    }

    /// [`push_solid_angles`] on this instruction set.
    #[inline(always)]
    fn push_solid_angles(self, angles: &mut AngleSum, t: &[f64x4; 9], q: [f64; 3]) -> u32 {
        #[cfg(target_arch = "x86_64")]
        if self.avx2.is_some() {
            // SAFETY: the token proves the CPU has AVX2.
            #[allow(unsafe_code)]
            return unsafe { push_solid_angles_avx2(angles, t, q) };
        }
        push_solid_angles(angles, t, q)
    }
}

/// [`push_solid_angles`] in AVX2 registers: the same operations in the same order, `wide`'s
/// `min`/`max` NaN rule included, so the same bits (tested through the dispatch).
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2")]
#[inline]
fn push_solid_angles_avx2(angles: &mut AngleSum, t: &[f64x4; 9], q: [f64; 3]) -> u32 {
    use crate::kernel::angle_sum::AngleSumAvx2;
    use std::arch::x86_64::*;
    // Macros, not closures: the intrinsics are safe to call only in this AVX2 function's body.
    macro_rules! dot {
        ($x0:expr, $y0:expr, $z0:expr, $x1:expr, $y1:expr, $z1:expr) => {
            _mm256_add_pd(
                _mm256_add_pd(_mm256_mul_pd($x0, $x1), _mm256_mul_pd($y0, $y1)),
                _mm256_mul_pd($z0, $z1),
            )
        };
    }
    // `wide`'s min/max: the left operand where the right one is NaN.
    macro_rules! min_max {
        ($op:ident, $a:expr, $b:expr) => {{
            let (a, b) = ($a, $b);
            _mm256_blendv_pd($op(a, b), a, _mm256_cmp_pd::<_CMP_UNORD_Q>(b, b))
        }};
    }
    let v: [__m256d; 9] = std::array::from_fn(|i| bytemuck::cast(t[i]));
    let (qx, qy, qz) = (
        _mm256_set1_pd(q[0]),
        _mm256_set1_pd(q[1]),
        _mm256_set1_pd(q[2]),
    );
    let (ax, ay, az) = (
        _mm256_sub_pd(v[0], qx),
        _mm256_sub_pd(v[1], qy),
        _mm256_sub_pd(v[2], qz),
    );
    let (bx, by, bz) = (
        _mm256_sub_pd(v[3], qx),
        _mm256_sub_pd(v[4], qy),
        _mm256_sub_pd(v[5], qz),
    );
    let (cx, cy, cz) = (
        _mm256_sub_pd(v[6], qx),
        _mm256_sub_pd(v[7], qy),
        _mm256_sub_pd(v[8], qz),
    );
    let la2 = dot!(ax, ay, az, ax, ay, az);
    let lb2 = dot!(bx, by, bz, bx, by, bz);
    let lc2 = dot!(cx, cy, cz, cx, cy, cz);
    let (la, lb, lc) = (
        _mm256_sqrt_pd(la2),
        _mm256_sqrt_pd(lb2),
        _mm256_sqrt_pd(lc2),
    );
    let det = _mm256_add_pd(
        _mm256_add_pd(
            _mm256_mul_pd(
                ax,
                _mm256_sub_pd(_mm256_mul_pd(by, cz), _mm256_mul_pd(bz, cy)),
            ),
            _mm256_mul_pd(
                ay,
                _mm256_sub_pd(_mm256_mul_pd(bz, cx), _mm256_mul_pd(bx, cz)),
            ),
        ),
        _mm256_mul_pd(
            az,
            _mm256_sub_pd(_mm256_mul_pd(bx, cy), _mm256_mul_pd(by, cx)),
        ),
    );
    let labc = _mm256_mul_pd(_mm256_mul_pd(la, lb), lc);
    let den = _mm256_add_pd(
        _mm256_add_pd(
            _mm256_add_pd(labc, _mm256_mul_pd(dot!(ax, ay, az, bx, by, bz), lc)),
            _mm256_mul_pd(dot!(bx, by, bz, cx, cy, cz), la),
        ),
        _mm256_mul_pd(dot!(cx, cy, cz, ax, ay, az), lb),
    );
    let cond = _mm256_mul_pd(_mm256_set1_pd(SOLID_ANGLE_CONDITION), labc);
    let sign = _mm256_set1_pd(-0.0);
    let ok = _mm256_and_pd(
        _mm256_and_pd(
            _mm256_and_pd(
                _mm256_and_pd(
                    _mm256_cmp_pd::<_CMP_GT_OQ>(
                        _mm256_andnot_pd(sign, det),
                        _mm256_mul_pd(_mm256_set1_pd(1e-12), labc),
                    ),
                    _mm256_cmp_pd::<_CMP_LT_OQ>(
                        _mm256_andnot_pd(sign, den),
                        _mm256_set1_pd(f64::INFINITY),
                    ),
                ),
                _mm256_cmp_pd::<_CMP_GT_OQ>(
                    min_max!(_mm256_min_pd, min_max!(_mm256_min_pd, la2, lb2), lc2),
                    _mm256_set1_pd(1e-180),
                ),
            ),
            _mm256_cmp_pd::<_CMP_LT_OQ>(
                min_max!(_mm256_max_pd, min_max!(_mm256_max_pd, la2, lb2), lc2),
                _mm256_set1_pd(1e180),
            ),
        ),
        _mm256_cmp_pd::<_CMP_GE_OQ>(
            _mm256_add_pd(_mm256_mul_pd(det, det), _mm256_mul_pd(den, den)),
            _mm256_mul_pd(cond, cond),
        ),
    );
    let mut acc = AngleSumAvx2::load(angles);
    acc.push(
        _mm256_blendv_pd(_mm256_set1_pd(1.0), den, ok),
        _mm256_blendv_pd(_mm256_setzero_pd(), det, ok),
    );
    acc.rescale();
    *angles = acc.finish();
    _mm256_movemask_pd(ok) as u32
}

/// Pushes `atan2(det, den)` of the Van Oosterom–Strackee formula (half the solid angle; see
/// [`triangle_solid_angle_at`]) for the four triangles of a leaf seen from `q`, computed exactly
/// as that function's `f64` fast path does, lane by lane, and only on the lanes where it would
/// take that path. Returns the mask of the lanes done; the caller recomputes the others with the
/// scalar function: `det = 0` (coplanar query, zero-area triangle, underflow), the zero-area
/// test (`|det| ≤ 1e-12·|a||b||c|`), `|r|²` outside `(1e-180, 1e180)`, an overflow, and the
/// ill-conditioned triangles (`√(det² + den²) < SOLID_ANGLE_CONDITION·|a||b||c|`, a query near
/// an edge), whose `f64` value errs by `≈ 2e-17/d` at distance `d` (issue 22: 0.44 at 1e-17).
// Always inlined: called from the AVX2 walks, an out-of-line copy runs as the portable build's
// SSE code (with the 4-triangle leaves it was half of all query time on a soup when the
// inliner left it out).
#[inline(always)]
fn push_solid_angles(angles: &mut AngleSum, t: &[f64x4; 9], q: [f64; 3]) -> u32 {
    let [qx, qy, qz] = q.map(f64x4::splat);
    let (ax, ay, az) = (t[0] - qx, t[1] - qy, t[2] - qz);
    let (bx, by, bz) = (t[3] - qx, t[4] - qy, t[5] - qz);
    let (cx, cy, cz) = (t[6] - qx, t[7] - qy, t[8] - qz);
    let la2 = ax * ax + ay * ay + az * az;
    let lb2 = bx * bx + by * by + bz * bz;
    let lc2 = cx * cx + cy * cy + cz * cz;
    let (la, lb, lc) = (la2.sqrt(), lb2.sqrt(), lc2.sqrt());
    let det = ax * (by * cz - bz * cy) + ay * (bz * cx - bx * cz) + az * (bx * cy - by * cx);
    let labc = la * lb * lc;
    let den = labc
        + (ax * bx + ay * by + az * bz) * lc
        + (bx * cx + by * cy + bz * cz) * la
        + (cx * ax + cy * ay + cz * az) * lb;
    // The conditions of the scalar function's f64 path, so that a lane is summed here exactly
    // when the direct sum would use the same f64 formula: every `|r|²` a normal `f64` far from
    // over- and underflow (a query within ~1e-90 of a vertex, or a far one, goes to the
    // magnitude-free scalar form), no zero-area doubt, and a well-conditioned `(det, den)`.
    // Far from the leaf all of these hold: the compares are the only cost on far queries.
    let cond = f64x4::splat(SOLID_ANGLE_CONDITION) * labc;
    let ok = det.abs().cmp_gt(f64x4::splat(1e-12) * labc)
        & den.abs().cmp_lt(f64x4::splat(f64::INFINITY))
        & la2.min(lb2).min(lc2).cmp_gt(f64x4::splat(1e-180))
        & la2.max(lb2).max(lc2).cmp_lt(f64x4::splat(1e180))
        & (det * det + den * den).cmp_ge(cond * cond);
    angles.push(ok.blend(den, f64x4::ONE), ok.blend(det, f64x4::ZERO));
    // World coordinates have any magnitude: keep the products near 1 after every factor.
    angles.rescale();
    // Lanes with `det = 0` (query in the plane, zero-area triangle, or a product that underflowed
    // for a query ~1e-300 off a face) go to the scalar formula too, which tells them apart.
    ok.move_mask() as u32
}

/// The area of a triangle, as [`Moments::of_triangle`] computes it (same operations, same
/// value), without the moments.
#[inline]
fn triangle_area(t: &[[f64; 3]; 3]) -> f64 {
    let n = cross(sub(t[1], t[0]), sub(t[2], t[0])).map(|v| 0.5 * v);
    dot(n, n).sqrt()
}

#[inline]
fn centroid(t: &[[f64; 3]; 3]) -> [f64; 3] {
    [0, 1, 2].map(|k| (t[0][k] + t[1][k] + t[2][k]) / 3.0)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::eval::direct::winding_number_direct;

    fn mid(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
        [0, 1, 2].map(|k| 0.5 * (a[k] + b[k]))
    }

    fn octahedron() -> Mesh {
        let p = [
            [1.0, 0.0, 0.0],
            [-1.0, 0.0, 0.0],
            [0.0, 1.0, 0.0],
            [0.0, -1.0, 0.0],
            [0.0, 0.0, 1.0],
            [0.0, 0.0, -1.0],
        ];
        Mesh::from_slices(&p, &crate::testing::OCTAHEDRON_FACES).unwrap()
    }

    /// A sphere-like closed mesh with many triangles (subdivided octahedron).
    fn subdivided(levels: usize) -> Mesh {
        let mut tris: Vec<[[f64; 3]; 3]> =
            (0..8).map(|f| octahedron().triangle_positions(f)).collect();
        let norm = |p: [f64; 3]| {
            let l = (p[0] * p[0] + p[1] * p[1] + p[2] * p[2]).sqrt();
            p.map(|v| v / l)
        };
        let mid = |a: [f64; 3], b: [f64; 3]| norm([0, 1, 2].map(|k| 0.5 * (a[k] + b[k])));
        for _ in 0..levels {
            tris = tris
                .iter()
                .flat_map(|&[a, b, c]| {
                    let (ab, bc, ca) = (mid(a, b), mid(b, c), mid(c, a));
                    [[a, ab, ca], [ab, b, bc], [ca, bc, c], [ab, bc, ca]]
                })
                .collect();
        }
        let positions: Vec<[f64; 3]> = tris.iter().flatten().copied().collect();
        let triangles = (0..tris.len() as u32)
            .map(|i| [3 * i, 3 * i + 1, 3 * i + 2])
            .collect();
        Mesh::new(positions, triangles).unwrap()
    }

    #[test]
    fn evaluator_is_send_and_sync() {
        fn check<T: Send + Sync>() {}
        check::<FastWindingNumber>();
    }

    #[test]
    fn empty_mesh_gives_zero() {
        let fast = FastWindingNumber::new(&Mesh::default());
        assert_eq!(fast.eval([0.0; 3]), 0.0);
        assert!(fast.is_empty());
    }

    /// `RadiusOrBoxCorner`'s size is, lane by lane, the smaller of the radius and 6/7 of the box
    /// corner distance: it admits exactly what either test admits (at β and 6β/7).
    #[test]
    fn radius_or_box_corner_size_is_the_smaller_of_the_two() {
        use super::super::{Admissibility, BOX_CORNER_SCALE};
        let fast = FastWindingNumber::new(&subdivided(3));
        let h = &fast.hierarchy;
        let radius = h.lane_sizes(Admissibility::Radius);
        let corner = h.lane_sizes(Admissibility::BoxCorner);
        let either = h.lane_sizes(Admissibility::RadiusOrBoxCorner);
        assert_eq!(radius.len(), either.len());
        assert!(radius.len() > 100);
        let (mut by_radius, mut by_corner) = (0, 0);
        for ((&r, &c), &e) in radius.iter().zip(&corner).zip(&either) {
            assert!(r <= c, "the corner distance bounds the radius: {r} {c}");
            let scaled = (BOX_CORNER_SCALE * f64::from(c)) as f32;
            // `f32` rounding of the `f64` sizes: within an ulp or two of the `f32` inputs.
            assert!(
                e <= r && (e - r.min(scaled)).abs() <= 2e-7 * r,
                "{e} {r} {c}"
            );
            if e == r {
                by_radius += 1;
            } else {
                by_corner += 1;
            }
        }
        // Both tests decide somewhere, or the rule would be one of the two.
        assert!(by_radius > 0 && by_corner > 0, "{by_radius} {by_corner}");
    }

    /// The AVX2 instantiation of the traversal (taken on this machine when it has AVX2) and the
    /// portable one give the same bits, near and far, at every order and rule.
    #[test]
    fn dispatched_and_portable_paths_agree_bit_for_bit() {
        let mesh = subdivided(4);
        let fast = FastWindingNumber::new(&mesh);
        let mut state = 0x2545_f491_4f6c_dd1d_u64;
        let mut unit = || {
            state ^= state << 13;
            state ^= state >> 7;
            state ^= state << 17;
            (state >> 11) as f64 / (1u64 << 53) as f64 * 2.0 - 1.0
        };
        for _ in 0..2000 {
            let s = 0.2 + 2.0 * unit().abs();
            let q = [unit() * s, unit() * s, unit() * s];
            for params in [
                FastParams::barill(2.0, 2),
                FastParams::barill(1.0, 1),
                FastParams::barill(4.0, 0),
                FastParams::fossil(2.0),
            ] {
                let (a, b) = (fast.eval_with(q, params), fast.eval_portable(q, params));
                assert_eq!(a.to_bits(), b.to_bits(), "{q:?} {params:?}: {a} vs {b}");
            }
        }
    }

    #[test]
    fn batches_equal_points_one_by_one_bit_for_bit() {
        // An open, partly duplicated soup: a sphere with every seventh face missing and a few
        // faces repeated flipped, so that w takes fractional values and leaves are near.
        let sphere = subdivided(3);
        let mut tris: Vec<[[f64; 3]; 3]> = (0..sphere.triangles().len())
            .filter(|f| f % 7 != 3)
            .map(|f| sphere.triangle_positions(f))
            .collect();
        tris.extend((0..40).map(|f| {
            let [a, b, c] = sphere.triangle_positions(5 * f);
            [a, c, b]
        }));
        let fast = FastWindingNumber::from_triangles(tris.clone(), FastParams::default());
        let mut points: Vec<[f64; 3]> = Vec::new();
        for i in 0..9 {
            for j in 0..9 {
                for k in 0..9 {
                    points.push([i, j, k].map(|v| -1.6 + 0.4 * f64::from(v) + 1e-3));
                }
            }
        }
        // On the surface: corners, edge midpoints, centroids; and rare inputs.
        for t in tris.iter().step_by(9) {
            points.extend([t[0], mid(t[0], t[1]), centroid(t)]);
        }
        points.extend([
            [f64::NAN, 0.0, 0.0],
            [f64::INFINITY, 0.0, 0.0],
            [1e30, -1e30, 5.0],
            [0.0; 3],
            [1e-300, 0.0, 0.0],
        ]);
        let same = |a: f64, b: f64| a.to_bits() == b.to_bits() || (a.is_nan() && b.is_nan());
        for params in [
            FastParams::barill(2.0, 2),
            FastParams::barill(2.8, 1),
            FastParams::barill(1.5, 0),
            FastParams::fossil(2.0),
            FastParams {
                beta: 2.4,
                order: 2,
                admissibility: super::super::Admissibility::BoxCorner,
            },
            FastParams {
                beta: 2.8,
                order: 2,
                admissibility: super::super::Admissibility::RadiusOrBoxCorner,
            },
            FastParams::barill(0.0, 2),
            FastParams::barill(-1.0, 2),
            FastParams::barill(f64::NAN, 2),
            FastParams::barill(f64::INFINITY, 2),
        ] {
            // Every prefix length mod 8 gives a short last packet somewhere.
            for n in [points.len(), points.len() - 3, 5, 1, 0] {
                let batch = fast.eval_batch_with(&points[..n], params);
                let portable = fast.eval_in_packets(&points[..n], params, true);
                for ((q, &b), &p) in points.iter().zip(&batch).zip(&portable) {
                    let one = fast.eval_with(*q, params);
                    assert!(same(b, one), "{q:?} {params:?}: batch {b} vs alone {one}");
                    assert!(same(p, one), "{q:?} {params:?}: portable {p} vs {one}");
                }
            }
        }
        // Not vacuous: the far field and the near field both contribute.
        let w = fast.eval_batch(&points);
        assert!(w.iter().any(|v| v.fract().abs() > 0.05 && v.is_finite()));
    }

    #[test]
    fn huge_beta_is_the_direct_sum() {
        let mesh = subdivided(4);
        let fast = FastWindingNumber::new(&mesh);
        for q in [[0.1, 0.2, -0.3], [0.9, 0.3, 0.1], [2.0, -1.0, 0.5]] {
            let a = fast.eval_with(q, FastParams::barill(1e12, 2));
            let b = winding_number_direct(&mesh, q);
            assert!((a - b).abs() < 1e-13, "{a} vs {b}");
        }
    }

    #[test]
    fn node_radius_bounds_its_triangles_and_area_matches() {
        let mesh = subdivided(3);
        let fast = FastWindingNumber::new(&mesh);
        for id in 0..fast.node_count() {
            let m = fast.node_moments(id);
            let mut area = 0.0;
            let mut reached = 0.0_f64;
            for &f in fast.node_triangles(id) {
                let t = mesh
                    .triangle_positions(f as usize)
                    .map(|v| fast.internal_point(v));
                area += Moments::of_triangle(t[0], t[1], t[2], m.center).area;
                for v in t {
                    reached = reached.max(dist2(v, m.center).sqrt());
                }
            }
            assert!((m.area - area).abs() < 1e-12);
            assert_eq!(m.radius, reached);
        }
    }

    #[test]
    fn far_field_matches_direct_on_a_sphere() {
        let mesh = subdivided(4);
        let fast = FastWindingNumber::new(&mesh);
        for (q, w) in [([0.0, 0.1, 0.2], 1.0), ([3.0, 1.0, 0.0], 0.0)] {
            for order in 0..=2 {
                let v = fast.eval_with(q, FastParams::barill(2.0, order));
                let tol = [5e-2, 1e-1, 5e-3][order as usize];
                assert!((v - w).abs() < tol, "order {order}: {v}");
            }
        }
    }

    /// The root expansion of a curved open cap (assembled from its children by re-centring):
    /// the order-p error falls like `d^-(p+3)` once far away.
    #[test]
    fn root_expansion_of_a_curved_cap_has_the_right_rates() {
        let sphere = subdivided(3);
        let tris: Vec<[[f64; 3]; 3]> = (0..sphere.triangles().len())
            .map(|f| sphere.triangle_positions(f))
            .filter(|t| (t[0][0] + t[1][0] + t[2][0]) / 3.0 > 0.3)
            .collect();
        let positions: Vec<[f64; 3]> = tris.iter().flatten().copied().collect();
        let triangles = (0..tris.len() as u32)
            .map(|i| [3 * i, 3 * i + 1, 3 * i + 2])
            .collect();
        let cap = Mesh::new(positions, triangles).unwrap();
        let fast = FastWindingNumber::new(&cap);
        assert!(fast.node_children(0).is_some());
        let m = fast.node_moments(0);
        let dir = [0.48, -0.6, 0.64];
        for order in 0..=2u8 {
            let err = |d: f64| {
                let q = [0, 1, 2].map(|k| m.center[k] + d * m.radius * dir[k]);
                (m.far_field(q, order) - winding_number_direct(&cap, q)).abs()
            };
            let rate = (err(16.0) / err(32.0)).log2();
            let expected = f64::from(order) + 3.0;
            assert!((rate - expected).abs() < 0.2, "order {order}: rate {rate}");
        }
    }
}
