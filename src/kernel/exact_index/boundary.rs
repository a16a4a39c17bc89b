//! The boundary part `Σ k·Area(A, B, x1)`: the exact loop (or the certified hierarchy) at a
//! snapped query, the plain floating-point sum for queries whose ray cannot approach the mesh, the
//! batch of a column's flat-loop queries, and the gradient's Biot–Savart sum.

use super::ExactIndex;
use crate::base::compensated::NeumaierSum;
use crate::kernel::boundary_column::ColumnQuery;
use crate::kernel::boundary_sum::{LoopFrame, scaled_by_power_of_two};
use crate::kernel::boundary_tree::{BoundaryTree, TreeQuery};
use crate::kernel::input_predicates::InputPoint;
use crate::kernel::predicates::{Width, far_query_numerator_sign};
use crate::kernel::quantize::Snap;
use crate::kernel::spherical::{
    EdgeSigns, INV_4PI, antipodal_edge_area, binary_exponent, segment_gradient_with_moment,
};

impl<W: Width> ExactIndex<W> {
    /// `Σ k·Area(A, B, x1)` with exact branch signs at the query `qi + r` (lattice point and
    /// residual), and the bound (on `w`) of its expanded far part. `z_exact` is false when the
    /// query's frame z lies outside the grid (then `qz` is used in floating point for the
    /// magnitudes). The edges a query is near, or whose sign its residual may change, take the
    /// double-double terms (the rest the loop), and such a query never the hierarchy `tree`.
    pub(super) fn boundary_sum(
        &self,
        q: &InputPoint,
        z_exact: bool,
        qz: f64,
        tree: Option<&BoundaryTree>,
    ) -> (f64, f64) {
        let qz_units = self.z_in_cells(qz);
        let (qi, r) = (q.n, q.r);
        if !self.boundary.is_empty() {
            // A residual the grid scaling could not hold: every edge on the exact inputs.
            if !q.residual_exact() {
                let area = self.boundary.area_sum_accurate::<W>(q, z_exact, qz_units);
                return (area, 0.0);
            }
            let accurate = self.boundary.accurate_edges::<W>(qi, r, z_exact);
            if !accurate.is_empty() {
                let area = self
                    .boundary
                    .area_sum_with_accurate_edges::<W>(q, z_exact, qz_units, &accurate);
                return (area, 0.0);
            }
        }
        match tree {
            Some(tree) => {
                let sum = tree.area_sum::<W>(&self.boundary, q, z_exact, qz_units);
                (sum.area, sum.bound)
            }
            None => (self.boundary.area_sum::<W>(q, z_exact, qz_units), 0.0),
        }
    }

    /// Boundary sum for a query whose ray cannot approach the mesh: plain floating point (and
    /// the hierarchy `tree`, whose every node the ray misses).
    pub(super) fn far_boundary_sum(&self, qf: [f64; 3], tree: Option<&BoundaryTree>) -> (f64, f64) {
        let term = |a: [i64; 3], b: [i64; 3]| {
            let ra = self.rel_f64(a, qf);
            let rb = self.rel_f64(b, qf);
            let signs = EdgeSigns {
                numerator: far_query_numerator_sign(ra, rb),
                query_inside_segment: false,
                flat_denominator: 0,
            };
            antipodal_edge_area(ra, rb, signs)
        };
        let limit = self.boundary.limit();
        let q = std::array::from_fn(|k| (qf[k] - self.origin[k]) / self.cell / limit);
        let Some(tree) = tree.filter(|t| t.reaches(&TreeQuery::Far(q))) else {
            let mut sum = 0.0;
            for i in 0..self.boundary.len() {
                let (a, b, weight) = self.boundary.edge(i);
                sum += weight * term(a, b);
            }
            return (sum, 0.0);
        };
        let mut exact_sum = 0.0;
        let mut exact = |range: std::ops::Range<usize>| {
            for j in range {
                if let Some(e) = self.boundary.slot_edge(j) {
                    let (a, b, _) = self.boundary.edge(e);
                    exact_sum += term(a, b);
                }
            }
        };
        let mut spokes = 0.0;
        // Far from the mesh: the lattice points are accurate enough (see `TreeQuery::Far`).
        let mut spoke = |p: &InputPoint, v: &InputPoint, m: i32| {
            spokes -= f64::from(m) * term(p.n, v.n);
        };
        let sum = tree.traverse(&TreeQuery::Far(q), |_, _| true, &mut exact, &mut spoke);
        let mut area = sum.area + exact_sum + spokes;
        for e in self.boundary.heavy_edges() {
            let (a, b, weight) = self.boundary.edge(e);
            area += weight * term(a, b);
        }
        (area, sum.bound)
    }

    /// Offset of lattice point `p` from the frame query `qf`, in world units (floating point).
    #[inline]
    fn rel_f64(&self, p: [i64; 3], qf: [f64; 3]) -> [f64; 3] {
        std::array::from_fn(|k| (p[k] as f64 * self.cell + self.origin[k]) - qf[k])
    }

    /// Gradient `∇w` at a world query: the integer part is locally constant, so only the boundary
    /// contributes (the Biot–Savart sum of
    /// [`crate::kernel::spherical::segment_gradient`]). NaN for a non-finite query.
    pub fn gradient(&self, q: [f64; 3]) -> [f64; 3] {
        if q.iter().any(|c| !c.is_finite()) {
            return [f64::NAN; 3];
        }
        let qg = self.grid.in_grid_space(q);
        if qg.iter().any(|c| !c.is_finite()) {
            // Beyond `f64::MAX` in grid space (extent ≥ 1): the world gradient is below
            // `1e-616 / extent`, i.e. it underflows.
            return [0.0; 3];
        }
        let qf = self.ray.to_frame(qg);
        // ∇w is homogeneous of degree −1 in lengths: evaluate on offsets scaled by an exact power
        // of two that brings them to ~1 and scale back, so queries at 1e300 neither overflow
        // |r|² nor turn into NaN (the true gradient there underflows to 0).
        let half_width = self.grid.limit() as f64 * self.cell;
        let span = (0..3).fold(half_width, |m, k| {
            m.max((0.5 * qf[k] - 0.5 * self.origin[k]).abs())
        });
        let exponent = (span.to_bits() >> 52) & 0x7ff;
        let scale = f64::from_bits((2046 - exponent) << 52);
        // At 60 bits the offsets are the exact inputs' differences rounded once (the loops'
        // unshifted frame, cells, times the cell: a power of two); the lattice points' were off
        // by up to `2^6` cells whatever the distance (a small part of a huge mesh). A query too
        // far for the frame's range takes the lattice points, relative to its distance.
        let unshifted_query = match self.boundary.frame() {
            LoopFrame::Unshifted { shift, .. } => {
                let qu = self
                    .ray
                    .to_frame(q)
                    .map(|c| scaled_by_power_of_two(c, shift));
                qu.iter().all(|c| c.abs() < 1e300).then_some(qu)
            }
            LoopFrame::Lattice => None,
        };
        // Next to an edge's interior the term takes `(a − q) × (b − q)` on the exact inputs
        // (cells squared; the offsets are cells times `cell·scale`, a power of two): the exact
        // query, where it snaps inside the grid (a query outside is far from every edge).
        let exact_query = unshifted_query.and(self.query_point(qg, q));
        let moment_exponent =
            2 * (i64::from(binary_exponent(self.cell)) + i64::from(binary_exponent(scale)));
        let mut g = [NeumaierSum::new(); 3];
        for i in 0..self.boundary.len() {
            let (a, b, weight) = self.boundary.edge(i);
            let (ra, rb) = match unshifted_query {
                Some(qu) => {
                    let (au, bu) = self.boundary.edge_in_frame(i);
                    let offset = |p: [f64; 3]| -> [f64; 3] {
                        std::array::from_fn(|k| (p[k] - qu[k]) * self.cell * scale)
                    };
                    (offset(au), offset(bu))
                }
                None => (
                    self.rel_f64(a, qf).map(|v| v * scale),
                    self.rel_f64(b, qf).map(|v| v * scale),
                ),
            };
            let e = segment_gradient_with_moment(ra, rb, || {
                let (m, k) = self.boundary.edge_moment(i, exact_query.as_ref()?)?;
                Some((m, k + moment_exponent))
            });
            for k in 0..3 {
                g[k].add(weight * e[k]);
            }
        }
        let g = self.ray.to_world(g.map(|s| s.value() * scale * INV_4PI));
        self.grid.gradient_to_world(g)
    }

    /// The world query `world` (grid space `qg`) as an exact point of the frame, when it snaps
    /// inside the grid on every axis.
    fn query_point(&self, qg: [f64; 3], world: [f64; 3]) -> Option<InputPoint> {
        let snapped = self.snap_frame(qg, world);
        let [Snap::In(x), Snap::In(y), Snap::In(z)] = snapped.snap else {
            return None;
        };
        Some(InputPoint {
            n: [x, y, z],
            r: snapped.residual,
            world: self.ray.to_frame(world),
            exact: snapped.exact,
        })
    }

    /// The boundary sums of a column's points (one lattice `x, y`) whose sum is the flat loop,
    /// all in one pass of the column loop (shared `x, y` work; each value bit-identical to its
    /// own [`ExactIndex::boundary_sum`]).
    pub(super) fn column_area_sums(&self, queries: &[ColumnQuery]) -> Vec<f64> {
        let mut areas = vec![0.0; queries.len()];
        self.boundary.column_area_sums::<W>(queries, &mut areas);
        areas
    }

    /// Whether the boundary sum at `qi + r` (lattice point and exact residual) is the flat loop:
    /// no edge needs the accurate path and the hierarchy `tree` expands nothing there. Such
    /// queries of a column are batched ([`ExactIndex::column_area_sums`]).
    pub(super) fn boundary_sum_is_flat(
        &self,
        qi: [i64; 3],
        r: [f64; 3],
        z_exact: bool,
        qz_units: f64,
        tree: Option<&BoundaryTree>,
    ) -> bool {
        !self.boundary.needs_accurate_sum::<W>(qi, r, z_exact)
            && tree.is_none_or(|t| {
                let q = InputPoint {
                    n: qi,
                    r,
                    world: [0.0; 3],
                    exact: [true; 3],
                };
                t.is_flat_at(q, z_exact, qz_units)
            })
    }

    /// The query's frame `z` in grid units (the magnitude of a query clamped along the ray).
    #[inline]
    pub(super) fn z_in_cells(&self, qz: f64) -> f64 {
        (qz - self.origin[2]) / self.cell
    }
}
