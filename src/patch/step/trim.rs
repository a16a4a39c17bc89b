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
    /// `+1` if the face normal is `S_u × S_v`, `−1` if opposite.
    pub sense: f64,
    /// Bounding box of the segments: `[u0, u1, v0, v1]`.
    pub bbox: [f64; 4],
    /// Segments by `u` column, so that a classification visits only the segments that can
    /// cross the point's vertical line or come within the margin of it.
    index: ColumnIndex,
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
    /// Builds the trim from segments.
    pub fn new(segments: Vec<Segment>, period_u: Option<f64>, sense: f64) -> Trim {
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
        let index = ColumnIndex::new(&segments, bbox);
        Trim {
            segments,
            period_u,
            sense,
            bbox,
            index,
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
    /// every segment (no index, a degenerate metric, or too many copies).
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
        let mut visit = |i: usize, shift: f64| {
            let s = &self.segments[i];
            let u = uv[0] + shift;
            let (ua, ub) = (s.a[0], s.b[0]);
            if (ua <= u && u < ub) || (ub <= u && u < ua) {
                let vc = s.a[1] + (u - ua) / (ub - ua) * (s.b[1] - s.a[1]);
                let sign = if ub > ua { 1 } else { -1 } * if self.sense < 0.0 { -1 } else { 1 };
                if vc > uv[1] {
                    above += sign;
                }
                // The first topmost segment in index order, whatever order they are visited in.
                if top.is_none_or(|(t, _, ti)| vc > t || (vc == t && i < ti)) {
                    top = Some((vc, sign, i));
                }
            }
            if let (Some((su, sv, margin)), true) = (metric, s.real) {
                // Closest point of the segment in (u, v), its offset mapped to 3D by the
                // surface's first derivatives at the point (a local, first-order distance).
                let d = [s.b[0] - ua, s.b[1] - s.a[1]];
                let w = [u - ua, uv[1] - s.a[1]];
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
        // The period copy of `uv[0]` each segment is tested at: the one nearest its midpoint.
        let copy = |s: &Segment| match self.period_u {
            Some(p) => ((0.5 * (s.a[0] + s.b[0]) - uv[0]) / p).round(),
            None => 0.0,
        };
        let shift_of = |k: f64| self.period_u.map_or(0.0, |p| p * k);
        let columns = if indexed {
            self.candidate_columns(uv, metric)
        } else {
            None
        };
        match columns {
            None => {
                for (i, s) in self.segments.iter().enumerate() {
                    visit(i, shift_of(copy(s)));
                }
            }
            Some((copies, reach)) => {
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
                            // Once per segment: in the first looked-up column it is listed in,
                            // and only for its own period copy.
                            if idx.column(s.a[0].min(s.b[0])).max(c0) != c || copy(s) != k {
                                continue;
                            }
                            visit(i, shift_of(k));
                        }
                    }
                }
            }
        }
        let ind = match top {
            None => 0,
            Some((_, sign, _)) => i64::from(sign > 0) - above,
        };
        (near, ind)
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
        for u in [-7.0, 0.1, 3.0, 6.2, 20.0] {
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
}
