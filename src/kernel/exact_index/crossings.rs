//! χ: the signed crossings of the ray from the perturbed query, one query at a time and for the
//! points of a column sharing one traversal.

use super::ExactIndex;
use crate::kernel::input_predicates::{
    InputPoint, input_plane_side, input_projected_containment, input_ray_crossing,
    snapped_plane_side, snapped_projected_containment,
};
use crate::kernel::predicates::{
    Width, perturbed_plane_side, projected_containment, ray_crossing, ray_crossing_at,
};

impl<W: Width> ExactIndex<W> {
    /// χ: signed crossings of the ray from the exact query `q_ε` along `+z` (every candidate, no
    /// early exit). The candidates of a query off the lattice are its lattice point's (a box
    /// containing `n + r` contains `n`, by monotone rounding; boxes of triangles off the lattice
    /// carry one cell of margin). Each triangle is decided by the lattice predicates when the
    /// lattice holds it and the query exactly, otherwise on the exact inputs.
    #[inline(always)]
    pub(super) fn signed_crossings(&self, q: &InputPoint) -> i64 {
        let (qi, r) = (q.n, q.r);
        let residual_exact = q.exact[0] && q.exact[1] && q.exact[2];
        let on_lattice = residual_exact && r[0] == 0.0 && r[1] == 0.0 && r[2] == 0.0;
        let mut chi = 0i64;
        let (x, y, z) = (self.unit(qi[0]), self.unit(qi[1]), self.unit(qi[2]));
        // Separate loops, so that a mesh the lattice holds runs the lattice loop unchanged.
        if self.tri_input.is_empty() && on_lattice {
            self.bvh.for_each_on_ray(x, y, z, |f| {
                chi += i64::from(ray_crossing::<W>(qi, self.tri_pts[f as usize]));
            });
        } else if self.tri_input.is_empty() && residual_exact {
            self.bvh.for_each_on_ray(x, y, z, |f| {
                chi += i64::from(ray_crossing_at::<W>(qi, r, self.tri_pts[f as usize]));
            });
        } else {
            self.bvh.for_each_on_ray(x, y, z, |f| {
                let f = f as usize;
                let p = self.tri_pts[f];
                let c = match self.input_triangle_index(f) {
                    // Triangles off the lattice: the lattice points with the snapping slack
                    // first (the common case), the exact points only when that cannot decide.
                    Some(i) => match snapped_projected_containment([qi[0], qi[1]], &p) {
                        Some(0) => 0,
                        Some(s0) => match snapped_plane_side(qi, &p) {
                            Some(side) => i32::from(side == -s0) * s0,
                            None => input_ray_crossing(q, &self.input_tris[i], &self.lattice),
                        },
                        None => input_ray_crossing(q, &self.input_tris[i], &self.lattice),
                    },
                    None if !residual_exact => {
                        input_ray_crossing(q, &p.map(InputPoint::lattice), &self.lattice)
                    }
                    None if on_lattice => ray_crossing::<W>(qi, p),
                    None => ray_crossing_at::<W>(qi, r, p),
                };
                chi += i64::from(c);
            });
        }
        chi
    }

    /// χ at lattice points of the column `x, y` with lattice depths `zs`, sorted ascending, every
    /// one inside the grid or clamped below it: one traversal of the whole column. Each crossing
    /// triangle is placed among the points by a binary search on the same exact perturbed depth
    /// test, so every value equals its own [`ExactIndex::signed_crossings`].
    pub(super) fn column_crossings(&self, [x, y]: [i64; 2], zs: &[i64]) -> Vec<i64> {
        if zs.is_empty() {
            return Vec::new();
        }
        // chi_diff[j]: change of χ between sorted points j−1 and j.
        let mut chi_diff = vec![0i64; zs.len() + 1];
        self.bvh
            .for_each_on_ray(self.unit(x), self.unit(y), f32::NEG_INFINITY, |f| {
                let p = self.tri_pts[f as usize];
                let input = self.input_triangle(f as usize);
                let s = match input {
                    Some(t) => input_projected_containment(
                        &InputPoint::lattice([x, y, 0]),
                        t,
                        &self.lattice,
                    ),
                    None => projected_containment::<W>([x, y], p),
                };
                if s == 0 {
                    return;
                }
                // Hit for the sorted points strictly below the plane: a prefix (the plane side is
                // monotone in z for a triangle whose projection contains the column).
                let below = |z: i64| {
                    let side = match input {
                        Some(t) => {
                            input_plane_side(&InputPoint::lattice([x, y, z]), t, &self.lattice)
                        }
                        None => perturbed_plane_side::<W>([x, y, z], p),
                    };
                    side == -s
                };
                let hits = zs.partition_point(|&z| below(z));
                chi_diff[0] += i64::from(s);
                chi_diff[hits] -= i64::from(s);
            });
        let mut chi = 0i64;
        zs.iter()
            .zip(&chi_diff)
            .map(|(_, d)| {
                chi += d;
                chi
            })
            .collect()
    }
}
