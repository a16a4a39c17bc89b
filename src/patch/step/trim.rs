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
        Trim {
            segments,
            period_u,
            sense,
            bbox,
        }
    }

    /// The indicator at `(u, v)` without the margin test: the value above the topmost
    /// crossing minus the signed crossings above `v`. `None` when no segment crosses the
    /// column (the point is outside).
    pub fn indicator(&self, uv: [f64; 2]) -> i64 {
        self.classify_with(uv, None).1
    }

    /// Inside/outside/near for a point with surface partials `su`, `sv` (to measure the
    /// distance to the loops in 3D): `Near` if some boundary segment is closer than `margin`.
    pub fn classify(&self, uv: [f64; 2], su: [f64; 3], sv: [f64; 3], margin: f64) -> Side {
        let (near, ind) = self.classify_with(uv, Some((su, sv, margin)));
        if near {
            return Side::Near;
        }
        match ind {
            0 => Side::Outside,
            1 => Side::Inside,
            _ => Side::Near,
        }
    }

    fn classify_with(
        &self,
        uv: [f64; 2],
        metric: Option<([f64; 3], [f64; 3], f64)>,
    ) -> (bool, i64) {
        let mut top: Option<(f64, i64)> = None;
        let mut above = 0i64;
        let mut near = false;
        for s in &self.segments {
            let shift = match self.period_u {
                Some(p) => p * ((0.5 * (s.a[0] + s.b[0]) - uv[0]) / p).round(),
                None => 0.0,
            };
            let u = uv[0] + shift;
            let (ua, ub) = (s.a[0], s.b[0]);
            if (ua <= u && u < ub) || (ub <= u && u < ua) {
                let vc = s.a[1] + (u - ua) / (ub - ua) * (s.b[1] - s.a[1]);
                let sign = if ub > ua { 1 } else { -1 } * if self.sense < 0.0 { -1 } else { 1 };
                if vc > uv[1] {
                    above += sign;
                }
                if top.is_none_or(|(t, _)| vc > t) {
                    top = Some((vc, sign));
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
        }
        let ind = match top {
            None => 0,
            Some((_, sign)) => i64::from(sign > 0) - above,
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
