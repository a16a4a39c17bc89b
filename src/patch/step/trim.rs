//! The trimming test: is a point `(u, v)` of a face's surface inside the face's loops?
//!
//! The loops are polygons in `(u, v)` (3D edge curves sampled and mapped to the surface).
//! A polygon winding number does not work directly on periodic surfaces, where a loop may run
//! once around the period (a cylinder band's circles, a sphere cap's latitude) and does not
//! close in the plane. So the test counts crossings of the vertical line `u = u*` (modulo the
//! period): the face lies to the left of every loop in `(u, v)` (right when the face's normal is
//! opposite to `S_u × S_v`), so crossing a segment that runs in `+u` upwards enters the face.
//! Above the topmost crossing the indicator is 1 exactly when that segment has the face above
//! it; below, each crossing changes it by its sign. For ordinary closed loops this is the
//! polygon winding number evaluated along a vertical ray; for bands and caps it is the only
//! consistent reading.

/// One polygon segment of a trimming loop.
#[derive(Clone, Copy, Debug)]
pub struct Segment {
    /// Start `(u, v)`.
    pub a: [f64; 2],
    /// End `(u, v)`.
    pub b: [f64; 2],
    /// A face boundary (counts for the near-boundary test); `false` for a seam (an edge the
    /// face uses twice, in opposite directions, so the face lies on both sides).
    pub real: bool,
}

/// The trimming loops of one face.
#[derive(Clone, Debug)]
pub struct Trim {
    /// All segments of all loops.
    pub segments: Vec<Segment>,
    /// Period of `u`, if any.
    pub period_u: Option<f64>,
    /// Period of `v`, if any (tori; periodic B-spline surfaces).
    pub period_v: Option<f64>,
    /// `+1` if the face normal is `S_u × S_v`, `−1` if opposite.
    pub sense: f64,
    /// Bounding box of the segments: `[u0, u1, v0, v1]`.
    pub bbox: [f64; 4],
    /// Segments by `u` column, so that a classification visits only the segments that can
    /// cross the point's vertical line or come within the margin of it.
    index: ColumnIndex,
    /// Doubly periodic surfaces: the indicator of a point whose row and column meet no face
    /// boundary (every boundary loop then closes in the plane): 1 unless the boundary loops
    /// enclose the face (positive signed area with the face's sense): a full torus or a torus
    /// with holes gives 1, a disk-shaped piece of a torus 0.
    free_inside: bool,
}

/// Fewest segments for which a face gets a [`ColumnIndex`] (below, a scan is as fast).
const INDEX_MIN_SEGMENTS: usize = 32;
/// Most columns of a [`ColumnIndex`].
const INDEX_MAX_COLUMNS: usize = 4096;
/// Most period copies of a query's `u` an indexed classification looks up; loops spanning more
/// periods than this are scanned.
const INDEX_MAX_COPIES: f64 = 64.0;

/// The segments of a trim sorted into equal-width columns of `u` (the segments' own
/// coordinates, before any period shift): segment `i` is listed, in increasing `i`, in every
/// column its `u` range meets. A column lookup is a superset of the segments whose `u` range
/// contains a given `u`, because [`ColumnIndex::column`] is monotone in `u`.
#[derive(Clone, Debug, Default)]
struct ColumnIndex {
    /// `u` of the left edge of column 0.
    u0: f64,
    /// Columns per unit of `u`.
    inv_width: f64,
    /// Column count (0: no index, classifications scan every segment).
    columns: usize,
    /// Start of each column's entries in `entries` (`columns + 1` offsets).
    offsets: Vec<u32>,
    /// Segment indices, column by column.
    entries: Vec<u32>,
}

impl ColumnIndex {
    fn new(segments: &[Segment], bbox: [f64; 4]) -> ColumnIndex {
        let (u0, u1) = (bbox[0], bbox[1]);
        let span = u1 - u0;
        if segments.len() < INDEX_MIN_SEGMENTS
            || segments.len() > u32::MAX as usize / 4
            || !(span.is_finite() && span > 0.0)
        {
            return ColumnIndex::default();
        }
        let columns = (segments.len() / 4).clamp(1, INDEX_MAX_COLUMNS);
        let mut index = ColumnIndex {
            u0,
            inv_width: columns as f64 / span,
            columns,
            offsets: Vec::new(),
            entries: Vec::new(),
        };
        let range = |s: &Segment| {
            let (a, b) = (s.a[0].min(s.b[0]), s.a[0].max(s.b[0]));
            (index.column(a), index.column(b))
        };
        let mut counts = vec![0u32; columns + 1];
        for s in segments {
            let (c0, c1) = range(s);
            for c in &mut counts[c0..=c1] {
                *c += 1;
            }
        }
        let mut offsets = Vec::with_capacity(columns + 1);
        let mut total = 0u32;
        for c in &counts[..columns] {
            offsets.push(total);
            total += c;
        }
        offsets.push(total);
        let mut fill: Vec<u32> = offsets[..columns].to_vec();
        let mut entries = vec![0u32; total as usize];
        for (i, s) in segments.iter().enumerate() {
            let (c0, c1) = range(s);
            for f in &mut fill[c0..=c1] {
                entries[*f as usize] = i as u32;
                *f += 1;
            }
        }
        index.offsets = offsets;
        index.entries = entries;
        index
    }

    /// The column of `u`, clamped to the index (monotone in `u`: `fl(u − u0)` and the product
    /// with a positive constant are monotone, and so are `floor` and the clamp).
    fn column(&self, u: f64) -> usize {
        let x = ((u - self.u0) * self.inv_width).floor();
        if x >= self.columns as f64 {
            self.columns - 1
        } else if x >= 0.0 {
            x as usize
        } else {
            0
        }
    }
}

/// Where a point lies relative to the loops.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Side {
    /// Inside the face.
    Inside,
    /// Outside.
    Outside,
    /// Within the margin of a boundary segment (or inconsistent loops): the ray should be
    /// chosen again.
    Near,
}

impl Trim {
    /// Builds the trim from segments (periodic in `u` at most).
    pub fn new(segments: Vec<Segment>, period_u: Option<f64>, sense: f64) -> Trim {
        Trim::with_periods(segments, period_u, None, sense)
    }

    /// Builds the trim from segments on a surface with the given periods.
    pub fn with_periods(
        segments: Vec<Segment>,
        period_u: Option<f64>,
        period_v: Option<f64>,
        sense: f64,
    ) -> Trim {
        let mut bbox = [
            f64::INFINITY,
            f64::NEG_INFINITY,
            f64::INFINITY,
            f64::NEG_INFINITY,
        ];
        for s in &segments {
            for p in [s.a, s.b] {
                bbox[0] = bbox[0].min(p[0]);
                bbox[1] = bbox[1].max(p[0]);
                bbox[2] = bbox[2].min(p[1]);
                bbox[3] = bbox[3].max(p[1]);
            }
        }
        // Doubly periodic faces are scanned (their column is a circle and the row may decide;
        // few segments in practice), so they get no index.
        let index = if period_v.is_none() {
            ColumnIndex::new(&segments, bbox)
        } else {
            ColumnIndex::default()
        };
        // Twice the signed area of the boundary loops (seams left out: a face crosses each
        // of its seams once each way).
        let area2: f64 = segments
            .iter()
            .filter(|s| s.real)
            .map(|s| s.a[0] * s.b[1] - s.b[0] * s.a[1])
            .sum();
        Trim {
            segments,
            period_u,
            period_v,
            sense,
            bbox,
            index,
            free_inside: area2 * sense <= 0.0,
        }
    }

    /// The indicator at `(u, v)` without the margin test: the value above the topmost
    /// crossing minus the signed crossings above `v`. `None` when no segment crosses the
    /// column (the point is outside).
    pub fn indicator(&self, uv: [f64; 2]) -> i64 {
        self.classify_with(uv, None, true).1
    }

    /// Inside/outside/near for a point with surface partials `su`, `sv` (to measure the
    /// distance to the loops in 3D): `Near` if some boundary segment is closer than `margin`.
    pub fn classify(&self, uv: [f64; 2], su: [f64; 3], sv: [f64; 3], margin: f64) -> Side {
        Self::side(self.classify_with(uv, Some((su, sv, margin)), true))
    }

    /// [`classify`](Self::classify) by a scan of every segment, without the column index: the
    /// index's oracle in tests.
    #[doc(hidden)]
    pub fn classify_by_scan(&self, uv: [f64; 2], su: [f64; 3], sv: [f64; 3], margin: f64) -> Side {
        Self::side(self.classify_with(uv, Some((su, sv, margin)), false))
    }

    fn side((near, ind): (bool, i64)) -> Side {
        if near {
            return Side::Near;
        }
        match ind {
            0 => Side::Outside,
            1 => Side::Inside,
            _ => Side::Near,
        }
    }

    /// For an indexed trim, the period copies `k` of `uv[0]` to look up (`uv[0] + k·period`)
    /// and the reach in `u` around each: every segment that can cross the vertical line at
    /// `uv[0]` or lie within the metric's margin of `uv` is in a looked-up column. `None`: scan
    /// every segment (no index: few segments or a doubly periodic face; a degenerate metric; or too
    /// many copies).
    ///
    /// The margin test measures `|J δ|` with `J = [S_u S_v]` and `δ` the offset in `(u, v)`
    /// to the segment, and `|J δ| ≥ σ_min |δ| ≥ σ_min |δ_u|`; so a segment whose `u` range is
    /// farther than `margin / σ_min` from the point's `u` cannot be near. The reach is that
    /// bound grown by 1 % (rounding of `σ_min`) plus a column width.
    fn candidate_columns(
        &self,
        uv: [f64; 2],
        metric: Option<([f64; 3], [f64; 3], f64)>,
    ) -> Option<(std::ops::RangeInclusive<i64>, f64)> {
        let idx = &self.index;
        if idx.columns == 0 || !(uv[0].is_finite() && uv[1].is_finite()) {
            return None;
        }
        let width = 1.0 / idx.inv_width;
        let mut reach = width;
        if let Some((su, sv, margin)) = metric {
            let dot = |a: [f64; 3], b: [f64; 3]| a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
            let (a, b, c) = (dot(su, su), dot(su, sv), dot(sv, sv));
            // Smallest eigenvalue of JᵀJ, as det / largest (no cancellation).
            let largest = 0.5 * (a + c) + (0.25 * (a - c) * (a - c) + b * b).sqrt();
            let det = a * c - b * b;
            let smallest = det / largest;
            // A nearly singular metric (a pole, a collapsed edge): the bound is useless.
            if !(smallest.is_finite() && smallest > 1e-12 * largest && margin.is_finite()) {
                return None;
            }
            reach += 1.01 * margin.abs() / smallest.sqrt();
        }
        let (u0, u1) = (idx.u0, idx.u0 + idx.columns as f64 * width);
        let copies = match self.period_u {
            None => 0..=0,
            Some(p) => {
                let lo = ((u0 - reach - uv[0]) / p).floor() - 1.0;
                let hi = ((u1 + reach - uv[0]) / p).ceil() + 1.0;
                if !(lo.is_finite() && hi.is_finite()) || hi - lo > INDEX_MAX_COPIES {
                    return None;
                }
                (lo as i64)..=(hi as i64)
            }
        };
        Some((copies, reach))
    }

    fn classify_with(
        &self,
        uv: [f64; 2],
        metric: Option<([f64; 3], [f64; 3], f64)>,
        indexed: bool,
    ) -> (bool, i64) {
        let mut top: Option<(f64, i64, usize)> = None;
        let mut above = 0i64;
        let mut near = false;
        // With a period in v the column is a circle: crossings are read in (v, v + period]
        // (all "above"), seams are left out (a face's seam along u is crossed once each way
        // at the same place, which would make the topmost crossing ambiguous).
        let v_wrap = |vc: f64| match self.period_v {
            Some(p) => vc - p * ((vc - uv[1]) / p).ceil() + p,
            None => vc,
        };
        // Two period copies of `uv[0]` per segment, as multiples `k` of the period
        // (`uv[0] + k·period`, exactly the `u` the tests below use):
        // - for the crossing, the copy in [lo, lo + period) of the segment's lower end `lo`
        //   (the nearest copy misses a segment spanning a whole period at its end);
        // - for the distance test, the copy nearest the segment's midpoint.
        let crossing_copy = |s: &Segment| match self.period_u {
            Some(p) => -((uv[0] - s.a[0].min(s.b[0])) / p).floor(),
            None => 0.0,
        };
        let distance_copy = |s: &Segment| match self.period_u {
            Some(p) => ((0.5 * (s.a[0] + s.b[0]) - uv[0]) / p).round(),
            None => 0.0,
        };
        let shift_of = |k: f64| self.period_u.map_or(0.0, |p| p * k);
        // The crossing test of segment `i` at the point's copy `uq`.
        let mut cross = |i: usize, uq: f64| {
            let s = &self.segments[i];
            let (ua, ub) = (s.a[0], s.b[0]);
            let counted = s.real || self.period_v.is_none();
            if counted && ((ua <= uq && uq < ub) || (ub <= uq && uq < ua)) {
                let vc = v_wrap(s.a[1] + (uq - ua) / (ub - ua) * (s.b[1] - s.a[1]));
                let sign = if ub > ua { 1 } else { -1 } * if self.sense < 0.0 { -1 } else { 1 };
                if vc > uv[1] {
                    above += sign;
                }
                // The first topmost segment in index order, whatever order they are visited in.
                if top.is_none_or(|(t, _, ti)| vc > t || (vc == t && i < ti)) {
                    top = Some((vc, sign, i));
                }
            }
        };
        // The distance test of segment `i` against the point's copy `u` (and, with a period
        // in v, the segment's copy nearest the point in v).
        let mut distance = |i: usize, u: f64| {
            let s = &self.segments[i];
            if let (Some((su, sv, margin)), true) = (metric, s.real) {
                let shift_v = match self.period_v {
                    Some(p) => p * ((0.5 * (s.a[1] + s.b[1]) - uv[1]) / p).round(),
                    None => 0.0,
                };
                // Closest point of the segment in (u, v), its offset mapped to 3D by the
                // surface's first derivatives at the point (a local, first-order distance).
                let d = [s.b[0] - s.a[0], s.b[1] - s.a[1]];
                let w = [u - s.a[0], uv[1] + shift_v - s.a[1]];
                let dd = d[0] * d[0] + d[1] * d[1];
                let t = if dd > 0.0 {
                    ((w[0] * d[0] + w[1] * d[1]) / dd).clamp(0.0, 1.0)
                } else {
                    0.0
                };
                let (du, dv) = (w[0] - t * d[0], w[1] - t * d[1]);
                let off = [
                    su[0] * du + sv[0] * dv,
                    su[1] * du + sv[1] * dv,
                    su[2] * du + sv[2] * dv,
                ];
                if off[0] * off[0] + off[1] * off[1] + off[2] * off[2] < margin * margin {
                    near = true;
                }
            }
        };
        let columns = if indexed {
            self.candidate_columns(uv, metric)
        } else {
            None
        };
        match columns {
            None => {
                for (i, s) in self.segments.iter().enumerate() {
                    cross(i, uv[0] + shift_of(crossing_copy(s)));
                    distance(i, uv[0] + shift_of(distance_copy(s)));
                }
            }
            Some((copies, reach)) => {
                // Each segment's crossing test runs in the lookup of its crossing copy, its
                // distance test in the lookup of its distance copy: both tests the scan runs
                // whose outcome can matter, at the same `u`. The crossing copy `uq` lies in the
                // segment's `u` range when it crosses, so a column of `uq` lists the segment; a
                // segment near the point lies within `reach` of its distance copy.
                let idx = &self.index;
                for k in copies {
                    let k = k as f64;
                    let u = uv[0] + shift_of(k);
                    let (c0, c1) = (idx.column(u - reach), idx.column(u + reach));
                    for c in c0..=c1 {
                        let (e0, e1) = (idx.offsets[c] as usize, idx.offsets[c + 1] as usize);
                        for &i in &idx.entries[e0..e1] {
                            let i = i as usize;
                            let s = &self.segments[i];
                            // Once per segment and copy: in the first looked-up column it is
                            // listed in.
                            if idx.column(s.a[0].min(s.b[0])).max(c0) != c {
                                continue;
                            }
                            if crossing_copy(s) == k {
                                cross(i, u);
                            }
                            if distance_copy(s) == k {
                                distance(i, u);
                            }
                        }
                    }
                }
            }
        }
        let ind = match (top, self.period_v) {
            (Some((_, sign, _)), _) => i64::from(sign > 0) - above,
            (None, None) => 0,
            // A column circle meeting no boundary is all inside or all outside: the row decides.
            (None, Some(_)) => self.row_indicator(uv),
        };
        (near, ind)
    }

    /// The indicator read along the row `v = v*` (surfaces periodic in `v`, for a column that
    /// meets no boundary): the side of the nearest boundary crossing to the right (modulo the
    /// period of `u`); the face lies left of its loops, so a loop running in `+v` has it at
    /// smaller `u`. No crossing: the row is a circle meeting no boundary either, and
    /// `free_inside` decides.
    fn row_indicator(&self, uv: [f64; 2]) -> i64 {
        let mut nearest: Option<(f64, i64)> = None;
        for s in self.segments.iter().filter(|s| s.real) {
            let (va, vb) = (s.a[1], s.b[1]);
            // The copy of the point in [lo, lo + period) of the segment's lower end.
            let v = match self.period_v {
                Some(p) => uv[1] - p * ((uv[1] - va.min(vb)) / p).floor(),
                None => uv[1],
            };
            if !((va <= v && v < vb) || (vb <= v && v < va)) {
                continue;
            }
            let uc = s.a[0] + (v - va) / (vb - va) * (s.b[0] - s.a[0]);
            let uc = match self.period_u {
                Some(p) => uc - p * ((uc - uv[0]) / p).ceil() + p,
                None if uc > uv[0] => uc,
                None => continue,
            };
            let sign = if vb > va { 1 } else { -1 } * if self.sense < 0.0 { -1 } else { 1 };
            if nearest.is_none_or(|(n, _)| uc < n) {
                nearest = Some((uc, sign));
            }
        }
        match nearest {
            Some((_, sign)) => i64::from(sign > 0),
            None if self.period_u.is_some() => i64::from(self.free_inside),
            None => 0,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn poly(pts: &[[f64; 2]], real: bool) -> Vec<Segment> {
        (0..pts.len())
            .map(|i| Segment {
                a: pts[i],
                b: pts[(i + 1) % pts.len()],
                real,
            })
            .collect()
    }

    #[test]
    fn square_with_hole_and_sense() {
        let mut s = poly(&[[0., 0.], [4., 0.], [4., 4.], [0., 4.]], true);
        s.extend(poly(&[[1., 1.], [1., 2.], [2., 2.], [2., 1.]], true));
        let t = Trim::new(s.clone(), None, 1.0);
        let (su, sv) = ([1., 0., 0.], [0., 1., 0.]);
        assert_eq!(t.classify([3., 3.], su, sv, 0.1), Side::Inside);
        assert_eq!(t.classify([1.5, 1.5], su, sv, 0.1), Side::Outside);
        assert_eq!(t.classify([5., 1.5], su, sv, 0.1), Side::Outside);
        assert_eq!(t.classify([3.95, 3.], su, sv, 0.1), Side::Near);
        // The same loops reversed describe a face whose normal is −S_u×S_v.
        let rev: Vec<Segment> = s
            .iter()
            .map(|g| Segment {
                a: g.b,
                b: g.a,
                real: true,
            })
            .collect();
        let t = Trim::new(rev, None, -1.0);
        assert_eq!(t.classify([3., 3.], su, sv, 0.1), Side::Inside);
        assert_eq!(t.classify([1.5, 1.5], su, sv, 0.1), Side::Outside);
    }

    #[test]
    fn periodic_band_and_cap() {
        use std::f64::consts::TAU;
        // Cylinder band 0 < v < 1: bottom +u, seam up, top −u, seam down.
        let band = vec![
            Segment {
                a: [0., 0.],
                b: [TAU, 0.],
                real: true,
            },
            Segment {
                a: [TAU, 0.],
                b: [TAU, 1.],
                real: false,
            },
            Segment {
                a: [TAU, 1.],
                b: [0., 1.],
                real: true,
            },
            Segment {
                a: [0., 1.],
                b: [0., 0.],
                real: false,
            },
        ];
        let t = Trim::new(band, Some(TAU), 1.0);
        for u in [-7.0, 0.0, 0.1, 3.0, 6.2, TAU, 20.0] {
            assert_eq!(t.indicator([u, 0.5]), 1, "{u}");
            assert_eq!(t.indicator([u, 1.5]), 0);
            assert_eq!(t.indicator([u, -0.5]), 0);
        }
        // A cap above v = 0.3 (one loop in +u, not closed in the plane).
        let cap = vec![Segment {
            a: [1.0, 0.3],
            b: [1.0 + TAU, 0.3],
            real: true,
        }];
        let t = Trim::new(cap, Some(TAU), 1.0);
        assert_eq!(t.indicator([0.2, 1.0]), 1);
        assert_eq!(t.indicator([0.2, 0.0]), 0);
    }

    #[test]
    fn doubly_periodic_domains() {
        use std::f64::consts::TAU;
        let seg = |a: [f64; 2], b: [f64; 2], real: bool| Segment { a, b, real };
        // Full torus: the loop is the two seams, each once each way.
        let full = vec![
            seg([0., 0.], [TAU, 0.], false),
            seg([TAU, 0.], [TAU, TAU], false),
            seg([TAU, TAU], [0., TAU], false),
            seg([0., TAU], [0., 0.], false),
        ];
        let t = Trim::with_periods(full, Some(TAU), Some(TAU), 1.0);
        for uv in [[0.1, 0.2], [3.0, -3.0], [-7.0, 9.0], [6.2, 6.2]] {
            assert_eq!(t.indicator(uv), 1, "{uv:?}");
        }
        // Band 0 < u < 1 around v: the loops are v-circles (−v at u = 0, +v at u = 1).
        let band = vec![
            seg([0., 0.], [0., -TAU], true),
            seg([1., 0.], [1., TAU], true),
        ];
        let t = Trim::with_periods(band, Some(TAU), Some(TAU), 1.0);
        for v in [-9.0, -1.0, 0.0, 2.0, 6.0, 13.0] {
            assert_eq!(t.indicator([0.5, v]), 1, "{v}");
            assert_eq!(t.indicator([0.5 + TAU, v]), 1, "{v}");
            assert_eq!(t.indicator([2.0, v]), 0, "{v}");
            assert_eq!(t.indicator([-0.5, v]), 0, "{v}");
        }
        // A square piece [1, 2]² of the torus (counter-clockwise) and the torus minus it.
        let square = |ccw: bool| {
            let p = [[1., 1.], [2., 1.], [2., 2.], [1., 2.]];
            (0..4)
                .map(|k| {
                    let (a, b) = (p[k], p[(k + 1) % 4]);
                    if ccw {
                        seg(a, b, true)
                    } else {
                        seg(b, a, true)
                    }
                })
                .collect::<Vec<_>>()
        };
        let piece = Trim::with_periods(square(true), Some(TAU), Some(TAU), 1.0);
        let holed = Trim::with_periods(square(false), Some(TAU), Some(TAU), 1.0);
        for (uv, inside) in [
            ([1.5, 1.5], true),
            ([1.5 + TAU, 1.5 - TAU], true),
            ([1.5, 4.0], false),
            ([4.0, 1.5], false),
            ([4.0, 4.0], false),
            ([-0.5, -3.0], false),
        ] {
            assert_eq!(piece.indicator(uv), i64::from(inside), "{uv:?}");
            assert_eq!(holed.indicator(uv), i64::from(!inside), "{uv:?}");
        }
        // A piece across the seam v = π as the inversion unwraps it: v ∈ [2.5, 3.8].
        let p = [[0.2, 2.5], [0.9, 2.5], [0.9, 3.8], [0.2, 3.8]];
        let across: Vec<Segment> = (0..4).map(|k| seg(p[k], p[(k + 1) % 4], true)).collect();
        let t = Trim::with_periods(across, Some(TAU), Some(TAU), 1.0);
        assert_eq!(t.indicator([0.5, 3.7 - TAU]), 1);
        assert_eq!(t.indicator([0.5, 2.6]), 1);
        assert_eq!(t.indicator([0.5, 0.0]), 0);
        assert_eq!(t.indicator([0.5, 2.4 - TAU]), 0);
    }

    /// The indexed classification equals the scan (same crossings, same copies, same tie
    /// rule) on a periodic band whose top is one segment spanning a whole period, where the
    /// crossing copy (`[lo, lo + period)`) and the distance copy (nearest the midpoint) differ;
    /// and the band's indicator is right at the period ends.
    #[test]
    fn index_equals_scan_with_the_crossing_copy_rule() {
        use std::f64::consts::TAU;
        let n = 40;
        let bottom = |u: f64| 0.3 + 0.2 * (3.0 * u).sin();
        let mut segs: Vec<Segment> = (0..n)
            .map(|k| {
                let (u0, u1) = (
                    1.0 + TAU * k as f64 / n as f64,
                    1.0 + TAU * (k + 1) as f64 / n as f64,
                );
                Segment {
                    a: [u0, bottom(u0)],
                    b: [u1, bottom(u1)],
                    real: true,
                }
            })
            .collect();
        segs.push(Segment {
            a: [1.0 + TAU, 2.0],
            b: [1.0, 2.0],
            real: true,
        });
        let t = Trim::new(segs.clone(), Some(TAU), 1.0);
        assert!(t.index.columns > 0, "the test needs an indexed trim");
        let mut state = 11u64;
        let mut rnd = || {
            state = state
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            (state >> 11) as f64 / (1u64 << 53) as f64
        };
        for k in 0..20000 {
            let copy = TAU * (rnd() * 6.0 - 3.0).round();
            let u = if k % 3 == 0 {
                // A vertex's u (the period ends included), in some period copy.
                segs[k % segs.len()].a[0] + copy
            } else {
                -20.0 + 40.0 * rnd()
            };
            let v = if k % 5 == 0 { 2.0 } else { -1.0 + 4.0 * rnd() };
            let su = [1.0 + rnd(), rnd(), rnd()];
            let sv = [rnd(), 1.0 + rnd(), rnd()];
            let metric = match k % 4 {
                0 => None,
                m => Some((su, sv, [1e-6, 1e-2, 0.3][m - 1] * rnd())),
            };
            assert_eq!(
                t.classify_with([u, v], metric, true),
                t.classify_with([u, v], metric, false),
                "{u} {v} {metric:?}"
            );
        }
        for c in -3..=3 {
            for u in [1.0, 1.0 + 1e-9, 1.0 + TAU - 1e-9, 2.5, 5.0] {
                let u = u + TAU * c as f64;
                assert_eq!(t.indicator([u, 1.5]), 1, "{u}");
                assert_eq!(t.indicator([u, 2.5]), 0, "{u}");
                assert_eq!(t.indicator([u, -0.5]), 0, "{u}");
            }
        }
    }
}
