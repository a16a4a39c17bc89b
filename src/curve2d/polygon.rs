//! 2D polygons (one or more closed loops, possibly self-intersecting and overlapping) and the exact
//! plain winding number.
//!
//! Exactness: the only geometric decision is the sign of the orientation determinant
//! `orient(a, b, c) = (b − a) × (c − a)`. It is decided by a floating-point filter with a
//! rigorous error bound, and, when the filter cannot tell, exactly: every `f64` is an integer
//! times a power of two, so the six products of the expanded determinant are summed exactly as
//! big integers. Queries are symbolically perturbed to `q + (ε, ε²)` (`0 < ε ≪ 1`), so a query on
//! a vertex or an edge gets the value of a point just off it, consistently for every edge.

use num_bigint::BigInt;
use std::fmt;

/// A point of the plane.
pub type Point = [f64; 2];

/// Largest accepted coordinate magnitude: products of two coordinates stay far from overflow.
/// Query points obey the same limit ([`query_in_range`]): beyond it values would be NaN.
pub const MAX_COORD: f64 = 1e100;

/// Whether a query point is one the 2D evaluators answer: both coordinates finite and at most
/// [`MAX_COORD`] in magnitude. Readers and bindings refuse the others with an error (a query at
/// 1e101 evaluated to NaN).
#[inline]
pub fn query_in_range(q: Point) -> bool {
    q.iter().all(|c| c.abs() <= MAX_COORD)
}

/// A polygon that cannot be used as given.
#[derive(Clone, Debug, PartialEq)]
pub enum PolygonError {
    /// No loop at all.
    Empty,
    /// A coordinate is NaN, infinite, or larger in magnitude than [`MAX_COORD`].
    BadCoordinate {
        /// Loop (0-based).
        loop_index: usize,
        /// Vertex within the loop (0-based).
        vertex: usize,
        /// The value found.
        value: f64,
    },
    /// A loop with fewer than two distinct vertices (it bounds nothing and has no direction).
    DegenerateLoop {
        /// Loop (0-based).
        loop_index: usize,
        /// Number of distinct vertices found.
        distinct: usize,
    },
}

impl fmt::Display for PolygonError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            PolygonError::Empty => write!(f, "the polygon has no loop"),
            PolygonError::BadCoordinate {
                loop_index,
                vertex,
                value,
            } => write!(
                f,
                "loop {loop_index}, vertex {vertex}: coordinate {value} is not finite or exceeds {MAX_COORD:e} in magnitude"
            ),
            PolygonError::DegenerateLoop {
                loop_index,
                distinct,
            } => write!(
                f,
                "loop {loop_index} has {distinct} distinct vertices; a closed loop needs at least 2"
            ),
        }
    }
}

impl std::error::Error for PolygonError {}

/// One or more closed loops. Loop `k` is `points[starts[k]..starts[k + 1]]`; its last vertex is
/// joined back to its first. Edge `i` goes from vertex `i` to [`Polygon::next`]`(i)`, so edges and
/// vertices share indices.
#[derive(Clone, Debug, PartialEq)]
pub struct Polygon {
    points: Vec<Point>,
    starts: Vec<usize>,
}

impl Polygon {
    /// A polygon from its loops (each implicitly closed).
    pub fn new(loops: Vec<Vec<Point>>) -> Result<Self, PolygonError> {
        let mut points = Vec::new();
        let mut starts = vec![0];
        for l in loops {
            points.extend_from_slice(&l);
            starts.push(points.len());
        }
        Self::from_flat(points, starts)
    }

    /// A polygon from a flat vertex array and loop offsets (`starts[0] == 0`, last == `len`).
    pub fn from_flat(points: Vec<Point>, starts: Vec<usize>) -> Result<Self, PolygonError> {
        if starts.len() < 2 {
            return Err(PolygonError::Empty);
        }
        assert!(
            starts[0] == 0
                && *starts.last().unwrap_or(&0) == points.len()
                && starts.windows(2).all(|w| w[0] <= w[1]),
            "loop offsets must be non-decreasing from 0 to the vertex count"
        );
        for k in 0..starts.len() - 1 {
            let l = &points[starts[k]..starts[k + 1]];
            for (v, p) in l.iter().enumerate() {
                for &c in p {
                    if !c.is_finite() || c.abs() > MAX_COORD {
                        return Err(PolygonError::BadCoordinate {
                            loop_index: k,
                            vertex: v,
                            value: c,
                        });
                    }
                }
            }
            let distinct = match l.first() {
                None => 0,
                Some(f) => {
                    if l.iter().any(|p| p != f) {
                        2
                    } else {
                        1
                    }
                }
            };
            if distinct < 2 {
                return Err(PolygonError::DegenerateLoop {
                    loop_index: k,
                    distinct,
                });
            }
        }
        Ok(Polygon { points, starts })
    }

    /// The same loops with new vertex positions (same count; must be finite).
    pub fn with_points(&self, points: Vec<Point>) -> Result<Self, PolygonError> {
        assert_eq!(
            points.len(),
            self.points.len(),
            "vertex count must not change"
        );
        Self::from_flat(points, self.starts.clone())
    }

    /// All vertices, loop after loop.
    pub fn points(&self) -> &[Point] {
        &self.points
    }

    /// Loop offsets: loop `k` is `points()[starts()[k]..starts()[k + 1]]`.
    pub fn starts(&self) -> &[usize] {
        &self.starts
    }

    /// Number of vertices (= number of edges).
    pub fn len(&self) -> usize {
        self.points.len()
    }

    /// Always false for a validated polygon (kept for API symmetry).
    pub fn is_empty(&self) -> bool {
        self.points.is_empty()
    }

    /// Number of loops.
    pub fn num_loops(&self) -> usize {
        self.starts.len() - 1
    }

    /// The vertices of loop `k`.
    pub fn loop_points(&self, k: usize) -> &[Point] {
        &self.points[self.starts[k]..self.starts[k + 1]]
    }

    /// The loop that vertex `i` belongs to.
    pub fn loop_of(&self, i: usize) -> usize {
        self.starts.partition_point(|&s| s <= i) - 1
    }

    /// The vertex after `i` in its loop (wrapping).
    pub fn next(&self, i: usize) -> usize {
        let k = self.loop_of(i);
        if i + 1 == self.starts[k + 1] {
            self.starts[k]
        } else {
            i + 1
        }
    }

    /// The vertex before `i` in its loop (wrapping).
    pub fn prev(&self, i: usize) -> usize {
        let k = self.loop_of(i);
        if i == self.starts[k] {
            self.starts[k + 1] - 1
        } else {
            i - 1
        }
    }

    /// All directed edges `(i, next(i))`.
    pub fn edges(&self) -> impl Iterator<Item = (usize, usize)> + '_ {
        (0..self.num_loops()).flat_map(move |k| {
            let (s, e) = (self.starts[k], self.starts[k + 1]);
            (s..e).map(move |i| (i, if i + 1 == e { s } else { i + 1 }))
        })
    }

    /// Axis-aligned bounding box `[min_x, min_y, max_x, max_y]`.
    pub fn bbox(&self) -> [f64; 4] {
        let mut b = [f64::INFINITY, f64::INFINITY, -f64::INFINITY, -f64::INFINITY];
        for p in &self.points {
            b[0] = b[0].min(p[0]);
            b[1] = b[1].min(p[1]);
            b[2] = b[2].max(p[0]);
            b[3] = b[3].max(p[1]);
        }
        b
    }

    /// Signed area (shoelace; positive for counter-clockwise loops, overlaps counted with their
    /// winding number).
    pub fn signed_area(&self) -> f64 {
        self.edges()
            .map(|(i, j)| {
                let (a, b) = (self.points[i], self.points[j]);
                a[0] * b[1] - a[1] * b[0]
            })
            .sum::<f64>()
            * 0.5
    }

    /// Total length of all edges.
    pub fn perimeter(&self) -> f64 {
        self.edges()
            .map(|(i, j)| dist(self.points[i], self.points[j]))
            .sum()
    }

    /// The polygon with every loop reversed.
    pub fn reversed(&self) -> Self {
        let mut points = Vec::with_capacity(self.points.len());
        for k in 0..self.num_loops() {
            points.extend(self.loop_points(k).iter().rev());
        }
        Polygon {
            points,
            starts: self.starts.clone(),
        }
    }

    /// The exact winding number of the polygon around `q + (ε, ε²)` (symbolic perturbation), by
    /// counting signed crossings of the ray from the perturbed query along +x.
    pub fn winding_number(&self, q: Point) -> i64 {
        self.edges()
            .map(|(i, j)| crossing(self.points[i], self.points[j], q))
            .sum()
    }

    /// Whether any two edges intersect, other than consecutive edges meeting at their shared
    /// vertex (exact). A zero-length edge or a loop folding back on itself counts.
    pub fn has_self_intersections(&self) -> bool {
        !self.self_intersections(1).is_empty()
    }

    /// Up to `limit` pairs of intersecting edges (see [`Polygon::has_self_intersections`]), by
    /// exact predicates; `O(n²)` with bounding-box pruning after sorting by `min_x`.
    pub fn self_intersections(&self, limit: usize) -> Vec<(usize, usize)> {
        let n = self.len();
        let mut order: Vec<usize> = (0..n).collect();
        let boxes: Vec<[f64; 4]> = (0..n)
            .map(|i| {
                let (a, b) = (self.points[i], self.points[self.next(i)]);
                [
                    a[0].min(b[0]),
                    a[1].min(b[1]),
                    a[0].max(b[0]),
                    a[1].max(b[1]),
                ]
            })
            .collect();
        order.sort_by(|&a, &b| boxes[a][0].total_cmp(&boxes[b][0]));
        let mut out = Vec::new();
        for (oi, &e) in order.iter().enumerate() {
            for &f in &order[oi + 1..] {
                if boxes[f][0] > boxes[e][2] {
                    break;
                }
                if boxes[f][1] > boxes[e][3] || boxes[e][1] > boxes[f][3] {
                    continue;
                }
                if self.edges_conflict(e, f) {
                    out.push((e.min(f), e.max(f)));
                    if out.len() >= limit {
                        return out;
                    }
                }
            }
        }
        out
    }

    fn edges_conflict(&self, e: usize, f: usize) -> bool {
        let (a, b) = (self.points[e], self.points[self.next(e)]);
        let (c, d) = (self.points[f], self.points[self.next(f)]);
        if a == b || c == d {
            // A zero-length edge touching anything else is a degenerate contact.
            return segments_intersect(a, b, c, d);
        }
        let e_then_f = self.next(e) == f;
        let f_then_e = self.next(f) == e;
        if e_then_f && f_then_e {
            // A two-vertex loop: the two edges overlap entirely.
            return true;
        }
        if e_then_f || f_then_e {
            // Consecutive edges share a vertex; they conflict only if they fold back onto each
            // other (collinear with opposite directions), or meet elsewhere, which for two
            // segments sharing an endpoint also requires collinearity.
            let (p, s, t) = if e_then_f { (a, b, d) } else { (c, d, b) };
            // p -> s -> t: conflict iff t lies on line(p, s) and folds back.
            return orient2d(p, s, t) == 0
                && (t[0] - s[0]) * (s[0] - p[0]) + (t[1] - s[1]) * (s[1] - p[1]) < 0.0;
        }
        segments_intersect(a, b, c, d)
    }
}

/// Euclidean distance.
pub fn dist(a: Point, b: Point) -> f64 {
    (b[0] - a[0]).hypot(b[1] - a[1])
}

/// Signed crossing of the +x ray from `q + (ε, ε²)` with the directed edge `a → b`: +1 upward
/// crossing with the query on the left, −1 downward with the query on the right, 0 otherwise.
pub fn crossing(a: Point, b: Point, q: Point) -> i64 {
    // Perturbed comparison: p.y > q.y + ε² ⟺ p.y > q.y (no ties).
    let above_a = a[1] > q[1];
    let above_b = b[1] > q[1];
    if above_a == above_b {
        return 0;
    }
    // orient(a, b, q + (ε, ε²)) = orient(a, b, q) − ε (b.y − a.y) + ε² (b.x − a.x); here
    // b.y ≠ a.y, so the ε term decides when the exact determinant is zero.
    let mut s = orient2d(a, b, q);
    if s == 0 {
        s = if b[1] > a[1] { -1 } else { 1 };
    }
    match (above_b, s) {
        (true, 1) => 1,
        (false, -1) => -1,
        _ => 0,
    }
}

/// Exact sign of `(b − a) × (c − a)`: +1 if `a, b, c` turn counter-clockwise, −1 clockwise, 0
/// collinear.
pub fn orient2d(a: Point, b: Point, c: Point) -> i8 {
    let l = (b[0] - a[0]) * (c[1] - a[1]);
    let r = (b[1] - a[1]) * (c[0] - a[0]);
    let det = l - r;
    let perm = l.abs() + r.abs();
    // Rounding of the 2 differences, 2 products and 1 subtraction: |err| ≤ (3u + 16u²)·perm
    // (Shewchuk's ccwerrboundA); valid while nothing underflows, hence the floor on `perm`.
    const U: f64 = f64::EPSILON * 0.5;
    let bound = (3.0 * U + 16.0 * U * U) * perm;
    if perm > 1e-280 && det.abs() > bound {
        return if det > 0.0 { 1 } else { -1 };
    }
    orient2d_exact(a, b, c)
}

/// `x = m · 2^e` exactly, with `m` an integer.
fn decompose(x: f64) -> (i64, i32) {
    let bits = x.to_bits();
    let sign = if bits >> 63 == 1 { -1 } else { 1 };
    let exp = ((bits >> 52) & 0x7ff) as i32;
    let frac = (bits & ((1u64 << 52) - 1)) as i64;
    if exp == 0 {
        (sign * frac, -1074)
    } else {
        (sign * (frac | (1i64 << 52)), exp - 1075)
    }
}

fn orient2d_exact(a: Point, b: Point, c: Point) -> i8 {
    // (b−a)×(c−a) = bx·cy − bx·ay − ax·cy − by·cx + by·ax + ay·cx (the ax·ay terms cancel).
    let terms: [(f64, f64, i64); 6] = [
        (b[0], c[1], 1),
        (b[0], a[1], -1),
        (a[0], c[1], -1),
        (b[1], c[0], -1),
        (b[1], a[0], 1),
        (a[1], c[0], 1),
    ];
    let parts: Vec<(BigInt, i32)> = terms
        .iter()
        .map(|&(x, y, s)| {
            let (mx, ex) = decompose(x);
            let (my, ey) = decompose(y);
            (BigInt::from(mx) * BigInt::from(my) * s, ex + ey)
        })
        .collect();
    let emin = parts.iter().map(|p| p.1).min().unwrap_or(0);
    let sum: BigInt = parts
        .into_iter()
        .map(|(m, e)| m << ((e - emin) as usize))
        .sum();
    match sum.sign() {
        num_bigint::Sign::Plus => 1,
        num_bigint::Sign::Minus => -1,
        num_bigint::Sign::NoSign => 0,
    }
}

/// Whether the closed segments `ab` and `cd` share a point (exact).
pub fn segments_intersect(a: Point, b: Point, c: Point, d: Point) -> bool {
    let o1 = orient2d(a, b, c);
    let o2 = orient2d(a, b, d);
    let o3 = orient2d(c, d, a);
    let o4 = orient2d(c, d, b);
    if o1 * o2 < 0 && o3 * o4 < 0 {
        return true;
    }
    let on = |p: Point, q: Point, r: Point| {
        // r on segment pq, given collinear.
        r[0] >= p[0].min(q[0])
            && r[0] <= p[0].max(q[0])
            && r[1] >= p[1].min(q[1])
            && r[1] <= p[1].max(q[1])
    };
    (o1 == 0 && on(a, b, c))
        || (o2 == 0 && on(a, b, d))
        || (o3 == 0 && on(c, d, a))
        || (o4 == 0 && on(c, d, b))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn square() -> Polygon {
        Polygon::new(vec![vec![[0., 0.], [1., 0.], [1., 1.], [0., 1.]]]).unwrap()
    }

    #[test]
    fn orient_exact_on_tiny_differences() {
        let a = [0.1, 0.1];
        let b = [0.3, 0.3];
        // c exactly on the line only if representable; nudge by one ulp and check sign flips.
        let c = [0.2, 0.2];
        let s = orient2d(a, b, c);
        assert_eq!(s, orient2d_exact(a, b, c));
        let c2 = [0.2, f64::from_bits(0.2f64.to_bits() + 1)];
        assert_eq!(orient2d(a, b, c2), orient2d_exact(a, b, c2));
        assert_eq!(orient2d([0., 0.], [1., 1.], [2., 2.]), 0);
        assert_eq!(orient2d([0., 0.], [1., 0.], [0., 1e-300]), 1);
    }

    #[test]
    fn winding_of_square_and_degenerate_queries() {
        let s = square();
        assert_eq!(s.winding_number([0.5, 0.5]), 1);
        assert_eq!(s.winding_number([1.5, 0.5]), 0);
        // Vertex (0,0): perturbed point (ε, ε²) is inside.
        assert_eq!(s.winding_number([0., 0.]), 1);
        // Right edge: perturbed point is outside; left edge: inside.
        assert_eq!(s.winding_number([1., 0.5]), 0);
        assert_eq!(s.winding_number([0., 0.5]), 1);
        // Top edge: (x, 1 + ε²) outside.
        assert_eq!(s.winding_number([0.5, 1.]), 0);
        assert_eq!(s.reversed().winding_number([0.5, 0.5]), -1);
    }

    #[test]
    fn validation() {
        assert_eq!(Polygon::new(vec![]), Err(PolygonError::Empty));
        assert!(matches!(
            Polygon::new(vec![vec![[0., 0.], [0., 0.]]]),
            Err(PolygonError::DegenerateLoop { distinct: 1, .. })
        ));
        assert!(matches!(
            Polygon::new(vec![vec![[0., 0.], [f64::NAN, 0.]]]),
            Err(PolygonError::BadCoordinate { vertex: 1, .. })
        ));
    }

    #[test]
    fn self_intersections() {
        assert!(!square().has_self_intersections());
        let bowtie = Polygon::new(vec![vec![[0., 0.], [1., 1.], [1., 0.], [0., 1.]]]).unwrap();
        assert!(bowtie.has_self_intersections());
        let fold = Polygon::new(vec![vec![[0., 0.], [2., 0.], [1., 0.], [1., 1.]]]).unwrap();
        assert!(fold.has_self_intersections());
    }
}
