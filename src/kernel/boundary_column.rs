//! The boundary term for a *column* of queries: points with the same lattice `x, y` (a grid
//! column along the ray), which is how grids, slices and voxelizations ask for it.
//!
//! Everything in the boundary loop that involves only `x, y` — the offsets, `h = x² + y²`, the
//! orientation `d` and its filter, the dot product of the projected offsets — is the same for
//! every point of a column: it is computed once per block of slots and shared by four queries.
//! Each query keeps only its own `z` work (one `sqrt` per vertex) and its angle product. The
//! per-vertex values are staged in small buffers and read back at `j` and `j + 1` (two loads)
//! instead of the single-query loop's lane shifts (shuffles compete with the arithmetic for one
//! port).
//!
//! The arithmetic is the single-query loop's, operation for operation ([`BoundaryEdges::area_sum`]
//! is the reference): every query's value is bit-identical to its own `area_sum` (tested), so a
//! grid gives the same numbers as point-by-point evaluation.

use super::angle_sum::AngleSum;
#[cfg(target_arch = "x86_64")]
use super::angle_sum::AngleSumAvx2;
use super::boundary_sum::BoundaryEdges;
#[cfg(target_arch = "x86_64")]
use super::boundary_sum::shift_one_avx2;
use super::input_predicates::InputPoint;
#[cfg(target_arch = "x86_64")]
use super::lanes::{Avx2, edge_term, horizontal_sq, projected_dot, vertex_factors};
use super::predicates::Width;
#[cfg(target_arch = "x86_64")]
use super::predicates::orient2d_filter_lanes;

/// One query of a column: the exact point (its lattice `x, y`, residuals and world `x, y` those
/// of the whole column), and, when `z_exact` is false, the clamped `z` of a query outside the
/// grid along the ray with `qz_units` its `z` in cells (see [`BoundaryEdges::area_sum`]).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ColumnQuery {
    /// The query (frame; `r[2] = 0` when `z_exact` is false).
    pub point: InputPoint,
    /// Whether `point.n[2]` is the query's exact lattice coordinate.
    pub z_exact: bool,
    /// The query's `z` in cells when `z_exact` is false.
    pub qz_units: f64,
}

/// Queries per pass: the shared work is split four ways, and four angle products in flight hide
/// the latency of each one's multiply–add chain.
const QUERIES: usize = 4;

/// Slots per chunk of the shared pass (a multiple of 8, so that the rescaling schedule of the
/// single-query loop, every other block, is kept). The chunk's buffers stay in L1.
const CHUNK: usize = 64;

impl BoundaryEdges {
    /// [`BoundaryEdges::area_sum`] of every query of one column (the same lattice, residual
    /// and world `x, y`), written to `out` (same length as `queries`), each bit-identical to its
    /// own `area_sum`.
    pub fn column_area_sums<W: Width>(&self, queries: &[ColumnQuery], out: &mut [f64]) {
        assert_eq!(queries.len(), out.len());
        debug_assert!(queries.windows(2).all(|w| {
            let (a, b) = (&w[0].point, &w[1].point);
            a.n[..2] == b.n[..2] && a.r[..2] == b.r[..2] && a.world[..2] == b.world[..2]
        }));
        let single = |c: &ColumnQuery| self.area_sum::<W>(&c.point, c.z_exact, c.qz_units);
        #[cfg(target_arch = "x86_64")]
        if !self.is_empty() && std::arch::is_x86_feature_detected!("avx2") {
            for (batch, out) in queries.chunks(QUERIES).zip(out.chunks_mut(QUERIES)) {
                // A short last batch repeats its last query (the extra results are dropped).
                let pick = |k: usize| batch[k.min(batch.len() - 1)];
                let frame = self.frame();
                let at = |c: &ColumnQuery| frame.query(&c.point, c.z_exact, c.qz_units);
                let zs: [f64; QUERIES] = std::array::from_fn(|k| at(&pick(k))[2]);
                let xy = at(&batch[0]);
                let mut undecided = Vec::new();
                // SAFETY: `column_angles_avx2` only needs the AVX2 instructions it is compiled
                // with, and the CPU was just checked to have them.
                #[allow(unsafe_code)]
                let angles = unsafe {
                    self.column_angles_avx2([xy[0], xy[1]], zs, 0..self.slots(), &mut |e| {
                        undecided.push(e)
                    })
                };
                for (k, out) in out.iter_mut().enumerate() {
                    let c = &batch[k];
                    // The single-query loop adds the exact terms in slot order too.
                    let mut scalar = 0.0;
                    for &e in &undecided {
                        scalar +=
                            self.exact_edge_area::<W>(e as usize, &c.point, c.z_exact, c.qz_units);
                    }
                    *out = 2.0 * angles[k].total()
                        + scalar
                        + self.heavy_area_sum::<W>(&c.point, c.z_exact, c.qz_units);
                }
            }
            return;
        }
        for (c, out) in queries.iter().zip(out.iter_mut()) {
            *out = single(c);
        }
    }

    /// The angle products of four queries `(x, y, zs[k])` (grid units) over `slots`, each
    /// bit-identical to [`BoundaryEdges::range_area_sum`]'s; `undecided(e)` is called once per
    /// edge the filter cannot sign (the filter involves `x, y` only, so the same edges for all).
    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx2")]
    fn column_angles_avx2(
        &self,
        xy: [f64; 2],
        zs: [f64; QUERIES],
        slots: std::ops::Range<usize>,
        undecided: &mut impl FnMut(u32),
    ) -> [AngleSum; QUERIES] {
        use std::arch::x86_64::*;
        let (xs, ys, vz, link) = self.vertex_arrays();
        let load = |v: &[f64], j: usize| -> __m256d {
            bytemuck::cast(<[f64; 4]>::try_from(&v[j..j + 4]).unwrap())
        };
        let store = |v: &mut [f64], j: usize, x: __m256d| {
            let x: [f64; 4] = bytemuck::cast(x);
            v[j..j + 4].copy_from_slice(&x);
        };
        let o = Avx2;
        let (qx, qy) = (o.splat(xy[0]), o.splat(xy[1]));
        let (conv, rel) = self.filter_constants();
        let (conv, rel) = (o.splat(conv), o.splat(rel));
        let zero = o.splat(0.0);
        // Shared per chunk: h of each vertex; per edge the filter mask, the dot product and
        // −d (see `chain_angles`).
        let mut h = [0.0; CHUNK + 8];
        let mut ok = [0.0; CHUNK];
        let mut dot = [0.0; CHUNK];
        let mut neg_d = [0.0; CHUNK];
        let mut acc = [AngleSumAvx2::new(); QUERIES];
        let mut j0 = slots.start;
        while j0 < slots.end {
            let blocks = (slots.end - j0).min(CHUNK).div_ceil(4);
            // Vertices j0 .. j0 + 4·blocks + 4: every block's edges end one vertex further.
            for b in 0..=blocks {
                let (i, j) = (4 * b, j0 + 4 * b);
                let x = o.sub(load(xs, j), qx);
                let y = o.sub(load(ys, j), qy);
                store(&mut h, i, horizontal_sq!(o, x, y));
            }
            for b in 0..blocks {
                let (i, j) = (4 * b, j0 + 4 * b);
                // The edge ends' offsets straight from the vertex arrays (unaligned loads of
                // data not written here: no store forwarding, no shuffles).
                let (ax, ay) = (o.sub(load(xs, j), qx), o.sub(load(ys, j), qy));
                let (bx, by) = (o.sub(load(xs, j + 1), qx), o.sub(load(ys, j + 1), qy));
                let real = o.gt(load(link, j), zero);
                let (d, lane_ok) = orient2d_filter_lanes!(o, [ax, ay, bx, by], real, conv, rel);
                store(&mut ok, i, lane_ok);
                store(&mut dot, i, projected_dot!(o, ax, ay, bx, by));
                store(&mut neg_d, i, o.sub(zero, d));
                let mask = _mm256_movemask_pd(real) & !_mm256_movemask_pd(lane_ok);
                self.report_undecided(j, mask, undecided);
            }
            for (k, acc) in acc.iter_mut().enumerate() {
                let qz = o.splat(zs[k]);
                // s and p of vertex block `b` (one `sqrt` per vertex), kept in registers: the
                // next block's are computed before this block's products, so that the square
                // roots overlap with them, and the edge ends come by lane shifts (a load
                // straddling two recent stores stalls on store forwarding: 0.6× when tried).
                macro_rules! vertices {
                    ($b:expr) => {{
                        let (i, j) = (4 * $b, j0 + 4 * $b);
                        vertex_factors!(o, load(&h, i), o.sub(load(vz, j), qz))
                    }};
                }
                let mut cur = vertices!(0);
                for b in 0..blocks {
                    let next = vertices!(b + 1);
                    let (i, j) = (4 * b, j0 + 4 * b);
                    let (sa, pa) = cur;
                    let (sb, pb) = (shift_one_avx2(cur.0, next.0), shift_one_avx2(cur.1, next.1));
                    cur = next;
                    let (t_re, t_im) = edge_term!(
                        o,
                        (sa, pa),
                        (sb, pb),
                        load(&dot, i),
                        load(&neg_d, i),
                        load(&ok, i)
                    );
                    acc.push(t_re, t_im);
                    if j % 8 == 4 {
                        // AngleSum::rescale, on the single-query loop's schedule.
                        acc.rescale();
                    }
                }
            }
            j0 += 4 * blocks;
        }
        acc.map(AngleSumAvx2::finish)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::kernel::predicates::W128;

    /// Every query of a column equals its own `area_sum` to the bit: small grids (queries on
    /// vertices and edges, undecided lanes, vertical edges), 60-bit coordinates, boundaries long
    /// enough for several chunks, columns of 1 to 11 queries (short last batches), heavy edges,
    /// queries outside the grid along the ray; in the lattice frame and, with residuals on the
    /// vertices and the queries, in the unshifted frame.
    #[test]
    fn column_sums_are_bit_identical_to_single_queries() {
        use crate::kernel::input_predicates::LatticeFrame;
        let mut rng = crate::kernel::test_rng::TestRng::new(3);
        let mut next = |m: u64| rng.below(m);
        let mut undecided_seen = false;
        // A residual of up to 20 bits (cells), or none.
        let residual = |next: &mut dyn FnMut(u64) -> u64, on: bool| {
            if on {
                (next(1 << 20) as f64 - 524288.0) / 1048576.0
            } else {
                0.0
            }
        };
        // With the unshifted frame of shift 0 and origin 0, a point's world value is `n + r`.
        let point = |n: [i64; 3], r: [f64; 3]| InputPoint {
            n,
            r,
            world: std::array::from_fn(|k| n[k] as f64 + r[k]),
            exact: [true; 3],
        };
        for case in 0..240 {
            let big = case % 2 == 1;
            let unshifted = case % 4 >= 2;
            let coord = |next: &mut dyn FnMut(u64) -> u64| {
                if big {
                    ((next(1 << 31) << 29) as i64) - (1_i64 << 59)
                } else {
                    next(9) as i64 - 4
                }
            };
            let n = 1 + next(if case % 3 == 0 { 400 } else { 40 }) as usize;
            let pts: Vec<InputPoint> = (0..=n)
                .map(|_| {
                    let p = [coord(&mut next), coord(&mut next), coord(&mut next)];
                    let on = unshifted && !big && next(2) == 0;
                    point(p, std::array::from_fn(|_| residual(&mut next, on)))
                })
                .collect();
            let a: Vec<InputPoint> = (0..n).map(|i| pts[i]).collect();
            let b: Vec<InputPoint> = (0..n)
                .map(|i| pts[(i + 1 + next(2) as usize) % (n + 1)])
                .collect();
            let weight: Vec<f64> = (0..n)
                .map(|_| [1.0, 2.0, 3.0, 6.0][next(4) as usize])
                .collect();
            let lattice = |v: &[InputPoint]| v.iter().map(|p| p.n).collect::<Vec<_>>();
            let edges = if unshifted {
                let frame = LatticeFrame {
                    shift: 0,
                    origin_cells: [0; 3],
                };
                BoundaryEdges::unshifted(lattice(&a), lattice(&b), weight, (a, b), frame)
            } else {
                BoundaryEdges::new(lattice(&a), lattice(&b), weight, 60)
            };
            for _ in 0..6 {
                let on_vertex = pts[next(pts.len() as u64) as usize].n;
                let qxy = if next(3) == 0 {
                    [on_vertex[0], on_vertex[1]]
                } else {
                    [coord(&mut next), coord(&mut next)]
                };
                let off = unshifted && !big && next(2) == 0;
                let rxy = [residual(&mut next, off), residual(&mut next, off)];
                let queries: Vec<ColumnQuery> = (0..1 + next(11))
                    .map(|_| {
                        let z_exact = next(5) != 0;
                        let z = if next(3) == 0 {
                            on_vertex[2]
                        } else {
                            coord(&mut next)
                        };
                        let rz = residual(&mut next, off && z_exact);
                        ColumnQuery {
                            point: point([qxy[0], qxy[1], z], [rxy[0], rxy[1], rz]),
                            z_exact,
                            qz_units: if z_exact { 0.0 } else { z as f64 * 3.0 + 0.5 },
                        }
                    })
                    .collect();
                let mut got = vec![0.0; queries.len()];
                edges.column_area_sums::<W128>(&queries, &mut got);
                for (c, got) in queries.iter().zip(&got) {
                    let want = edges.area_sum::<W128>(&c.point, c.z_exact, c.qz_units);
                    assert_eq!(
                        got.to_bits(),
                        want.to_bits(),
                        "case {case} {qxy:?} {c:?}: {got} vs {want}"
                    );
                }
                undecided_seen |= !big && qxy == [on_vertex[0], on_vertex[1]];
            }
        }
        assert!(undecided_seen);
    }
}
