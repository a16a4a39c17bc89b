//! The per-point snap: a world query (already in grid space) becomes a lattice point, an exact
//! residual and the clamp rule's proxy (module doc of [`super`]).

use super::ExactIndex;
use crate::kernel::boundary_tree::BoundaryTree;
use crate::kernel::input_predicates::InputPoint;
use crate::kernel::predicates::Width;
use crate::kernel::quantize::{Precision, Snap};

/// A query snapped into the frame, axis by axis.
#[derive(Clone, Copy, Debug)]
pub(super) struct SnappedQuery {
    /// Lattice coordinates, or which side of the grid the query lies beyond.
    pub snap: [Snap; 3],
    /// The exact residuals (cells).
    pub residual: [f64; 3],
    /// Whether each residual is exact (it is not where the world → grid scaling underflowed; see
    /// [`crate::kernel::quantize::Grid::kept_exactly`]).
    pub exact: [bool; 3],
}

impl<W: Width> ExactIndex<W> {
    /// Snaps the grid-space query `q` (of the world query `world`) into the frame.
    #[inline(always)]
    pub(super) fn snap_frame(&self, q: [f64; 3], world: [f64; 3]) -> SnappedQuery {
        // Written out (not `array::map`): the closure version was not inlined into the hot path.
        let [m0, m1, m2] = self.ray.map();
        let (s0, r0, e0) = self.snap_axis(q, world, m0);
        let (s1, r1, e1) = self.snap_axis(q, world, m1);
        let (s2, r2, e2) = self.snap_axis(q, world, m2);
        let snap = [s0, s1, s2];
        if W::PRECISION == Precision::Bits30 {
            // The 30-bit grid is the documented fast approximation: queries (like vertices) are
            // evaluated at their lattice points, `≤ 1.5e-9·extent` away.
            return SnappedQuery {
                snap,
                residual: [0.0; 3],
                exact: [true; 3],
            };
        }
        SnappedQuery {
            snap,
            residual: [r0, r1, r2],
            exact: [e0, e1, e2],
        }
    }

    /// One frame axis of [`ExactIndex::snap_frame`].
    #[inline(always)]
    fn snap_axis(
        &self,
        q: [f64; 3],
        world: [f64; 3],
        (axis, neg): (usize, bool),
    ) -> (Snap, f64, bool) {
        let (s, r, exact) =
            if q[axis].abs() >= f64::MIN_POSITIVE || self.grid.kept_exactly(world[axis], q[axis]) {
                let (s, r) = self.grid.snap_with_residual(q[axis], axis);
                (s, r, true)
            } else {
                self.grid.snap_underflowed(world[axis], axis)
            };
        if neg {
            (s.negated(), -r, exact)
        } else {
            (s, r, exact)
        }
    }

    /// The parts at a grid-space query already pulled in
    /// ([`crate::kernel::quantize::Grid::pull_in_far`]) from the world query `world`, and the
    /// bound, with the boundary hierarchy `tree`.
    pub(super) fn parts_in_grid_space(
        &self,
        q: [f64; 3],
        world: [f64; 3],
        tree: Option<&BoundaryTree>,
    ) -> (i64, f64, f64) {
        let qf = self.ray.to_frame(q);
        let SnappedQuery {
            snap,
            residual,
            exact,
        } = self.snap_frame(q, world);
        let (Snap::In(x), Snap::In(y)) = (snap[0], snap[1]) else {
            let (area, bound) = self.far_boundary_sum(qf, tree);
            return (0, area, bound);
        };
        let limit = self.grid.limit();
        let (z, z_exact) = match snap[2] {
            Snap::In(z) => (z, true),
            Snap::Low => (-limit, false),
            Snap::High => (limit, false),
        };
        let qi = [x, y, z];
        let r = [
            residual[0],
            residual[1],
            if z_exact { residual[2] } else { 0.0 },
        ];
        // A clamped z is the lattice proxy of the query (same crossings, see the module doc).
        let query = InputPoint {
            n: qi,
            r,
            world: self.ray.to_frame(world),
            exact: [exact[0], exact[1], exact[2] || !z_exact],
        };
        let chi = if snap[2] == Snap::High {
            0
        } else {
            self.signed_crossings(&query)
        };
        let (area, bound) = self.boundary_sum(&query, z_exact, qf[2], tree);
        (chi, area, bound)
    }
}
