//! A column of queries: the points of one line parallel to the ray (a grid column), which share
//! one BVH traversal for χ and the `x, y` work of the boundary loop. Every value equals the
//! point's own [`ExactIndex::parts`] bit for bit (the column tests compare them).

use super::snap::SnappedQuery;
use super::{ExactIndex, w_of_parts};
use crate::kernel::boundary_column::ColumnQuery;
use crate::kernel::boundary_tree::BoundaryTree;
use crate::kernel::input_predicates::InputPoint;
use crate::kernel::predicates::Width;
use crate::kernel::quantize::Snap;

/// One finite point of a column, snapped: its lattice `z` (clamped when outside the grid along
/// the ray), and what the crossings and the boundary sum need of it.
struct ColumnPoint {
    z: i64,
    /// Whether `z` is the point's own lattice coordinate (not the clamp's).
    z_exact: bool,
    /// Frame `z` (grid space).
    qz: f64,
    /// Residual along `z` (cells).
    rz: f64,
    /// Whether `rz` is exact (false where the world → grid scaling underflowed).
    rz_exact: bool,
    /// Beyond the grid's top: no crossing.
    high: bool,
    /// The world point, for the exact path.
    world: [f64; 3],
}

impl<W: Width> ExactIndex<W> {
    /// Winding numbers along one line parallel to the ray: at the world points `q` with the
    /// coordinate along the ray axis replaced by each `ts[k]` (NaN where that is not finite).
    pub fn column(&self, q: [f64; 3], ts: &[f64]) -> Vec<f64> {
        self.column_with_bounds(q, ts, self.tree())
            .into_iter()
            .map(|(w, _)| w)
            .collect()
    }

    /// [`ExactIndex::column`] with the boundary hierarchy `tree`, and each value's bound (on `w`)
    /// of its expanded boundary (`(NaN, 0)` where not finite).
    pub fn column_with_bounds(
        &self,
        q: [f64; 3],
        ts: &[f64],
        tree: Option<&BoundaryTree>,
    ) -> Vec<(f64, f64)> {
        if q.iter().any(|c| !c.is_finite()) {
            return vec![(f64::NAN, 0.0); ts.len()];
        }
        let axis = self.ray.map()[2].0;
        let world_at = |t: f64| {
            let mut p = q;
            p[axis] = t;
            p
        };
        // Grid-space point of the column at world coordinate `t` (pulled in like `parts`).
        let at = |t: f64| self.grid.pull_in_far(self.grid.in_grid_space(world_at(t)));
        let one_by_one = || {
            ts.iter()
                .map(|&t| {
                    if t.is_finite() {
                        let (chi, area, bound) = self.parts_in_grid_space(at(t), world_at(t), tree);
                        (w_of_parts(chi, area), bound)
                    } else {
                        (f64::NAN, 0.0)
                    }
                })
                .collect()
        };
        let SnappedQuery {
            snap,
            residual,
            exact,
        } = self.snap_frame(self.grid.pull_in_far(self.grid.in_grid_space(q)), q);
        let (Snap::In(x), Snap::In(y)) = (snap[0], snap[1]) else {
            // Beyond the grid across the ray: far queries, one by one.
            return one_by_one();
        };
        if !(exact[0] && exact[1]) {
            // A transverse coordinate the grid scaling could not hold (a tiny coordinate of a
            // huge mesh): the exact query path, point by point.
            return one_by_one();
        }
        // Every point of the column has these lattice x, y and residuals (the pull-in and the
        // snap act axis by axis).
        let (rx, ry) = (residual[0], residual[1]);
        let points: Vec<Option<ColumnPoint>> = ts
            .iter()
            .map(|&t| t.is_finite().then(|| self.column_point(at(t), world_at(t))))
            .collect();
        let input_point = |p: &ColumnPoint| InputPoint {
            n: [x, y, p.z],
            r: [rx, ry, p.rz],
            world: self.ray.to_frame(p.world),
            exact: [true, true, p.rz_exact],
        };
        let chis = self.column_chis([x, y], (rx, ry), &points, input_point);
        // The boundary term: the points whose boundary sum is the flat loop go through the
        // column loop together (shared x, y work, bit-identical values), the others one by one.
        let mut batch: Vec<(usize, ColumnQuery)> = Vec::new();
        let mut out = vec![(f64::NAN, 0.0); ts.len()];
        for (k, p) in points.iter().enumerate() {
            let Some(p) = p else { continue };
            let qi = [x, y, p.z];
            let r = [rx, ry, if p.z_exact { p.rz } else { 0.0 }];
            let qz_units = self.z_in_cells(p.qz);
            if p.rz_exact && self.boundary_sum_is_flat(qi, r, p.z_exact, qz_units, tree) {
                let query = ColumnQuery {
                    point: input_point(p),
                    z_exact: p.z_exact,
                    qz_units,
                };
                batch.push((k, query));
            } else {
                let (area, bound) = self.boundary_sum(&input_point(p), p.z_exact, p.qz, tree);
                out[k] = (w_of_parts(chis[k], area), bound);
            }
        }
        let queries: Vec<ColumnQuery> = batch.iter().map(|&(_, c)| c).collect();
        let areas = self.column_area_sums(&queries);
        for (&(k, _), area) in batch.iter().zip(areas) {
            out[k] = (w_of_parts(chis[k], area), 0.0);
        }
        out
    }

    /// The per-point snap of the column point at grid-space `p` (world `world`).
    fn column_point(&self, p: [f64; 3], world: [f64; 3]) -> ColumnPoint {
        let qz = self.ray.to_frame(p)[2];
        let limit = self.grid.limit();
        let SnappedQuery {
            snap,
            residual,
            exact,
        } = self.snap_frame(p, world);
        let (z, z_exact, rz, high) = match snap[2] {
            Snap::In(z) => (z, true, residual[2], false),
            Snap::Low => (-limit, false, 0.0, false),
            Snap::High => (limit, false, 0.0, true),
        };
        ColumnPoint {
            z,
            z_exact,
            qz,
            rz,
            rz_exact: exact[2] || !z_exact,
            high,
            world,
        }
    }

    /// χ of every point of the column (0 where not finite): lattice points share one traversal
    /// ([`ExactIndex::column_crossings`]); points off the lattice take their own.
    fn column_chis(
        &self,
        xy: [i64; 2],
        (rx, ry): (f64, f64),
        points: &[Option<ColumnPoint>],
        input_point: impl Fn(&ColumnPoint) -> InputPoint,
    ) -> Vec<i64> {
        let transverse_residual = rx != 0.0 || ry != 0.0;
        let shared = |p: &ColumnPoint| !transverse_residual && p.rz == 0.0 && p.rz_exact;
        let mut chis = vec![0i64; points.len()];
        for (chi, p) in chis.iter_mut().zip(points) {
            if let Some(p) = p.as_ref().filter(|p| !shared(p) && !p.high) {
                *chi = self.signed_crossings(&input_point(p));
            }
        }
        let mut order: Vec<usize> = (0..points.len())
            .filter(|&k| points[k].as_ref().is_some_and(shared))
            .collect();
        order.sort_by_key(|&k| points[k].as_ref().map_or(0, |p| p.z));
        let limit = self.grid.limit();
        // Points strictly above the grid never see a crossing.
        let zs: Vec<i64> = order
            .iter()
            .map(|&k| points[k].as_ref().expect("finite"))
            .take_while(|p| p.z < limit || p.z_exact)
            .map(|p| p.z)
            .collect();
        for (&k, chi) in order.iter().zip(self.column_crossings(xy, &zs)) {
            chis[k] = chi;
        }
        chis
    }
}
