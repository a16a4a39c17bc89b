//! Exact self-intersection count of a triangle surface with integer (fixed-point) vertices.
//!
//! Two faces *self-intersect* when they meet anywhere other than in what they share: nothing,
//! one common vertex, or one common edge (coincident positions count as shared, whatever the
//! indices). Every sign is exact: `orient3d` and `orient2d` are the kernel's 60-bit integer
//! predicates (`kernel::predicates::W128`: a floating-point filter, then exact integers), so
//! coordinates must be below `2^60` in magnitude.
//!
//! - no shared vertex: they meet iff an edge of one meets the other (closed sets; this covers
//!   the coplanar case too, containment included);
//! - one shared vertex: iff the edge opposite it in one meets the other;
//! - one shared edge: iff both lie in one plane with the opposite vertices on the same side of
//!   the edge (a fold);
//! - three: a duplicated face.
//!
//! Degenerate faces (collinear vertices) are counted apart and not tested.
//!
//! Broad phase: every face is bucketed by the cell of its box's minimum corner, on a grid whose
//! cell is the largest box extent; two faces whose boxes overlap then sit in the same or
//! neighbouring cells. This is linear for surfaces of evenly sized faces (the remesher's output:
//! every face lies in one lattice cell) and refuses, with [`IntersectError::TooManyCandidates`],
//! when uneven face sizes would make it quadratic beyond a budget.

use std::sync::atomic::{AtomicBool, Ordering};

use rayon::prelude::*;

use crate::kernel::predicates::{W128, Width, det2_sign_wide, orient3d_sign_wide};
use crate::kernel::quantize::common_fixed_point;

/// Largest accepted coordinate magnitude (the 60-bit predicates need differences below `2^61`).
pub const MAX_COORDINATE: i64 = 1 << 60;

/// The result of [`self_intersections`].
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct SelfIntersections {
    /// Pairs of faces that meet outside their common vertices and edge.
    pub pairs: usize,
    /// Faces whose three vertices are collinear (not tested).
    pub degenerate_faces: usize,
    /// Pairs of faces whose boxes overlap (the exact tests run).
    pub tested_pairs: usize,
}

/// Why [`self_intersections`] refused.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum IntersectError {
    /// A coordinate is `MAX_COORDINATE` or more in magnitude.
    CoordinateTooLarge {
        /// Vertex index.
        vertex: usize,
    },
    /// The coordinates span more bits than the wide predicates take, in one fixed-point scale
    /// ([`self_intersections_of_positions`]).
    CoordinateSpan,
    /// A face refers to a vertex that does not exist.
    BadIndex {
        /// Face index.
        face: usize,
    },
    /// The broad phase would test more than the budget of candidate pairs.
    TooManyCandidates {
        /// The candidate pairs counted.
        candidates: u64,
        /// The budget.
        budget: u64,
    },
}

impl std::fmt::Display for IntersectError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            IntersectError::CoordinateTooLarge { vertex } => write!(
                f,
                "vertex {vertex} has a coordinate of magnitude 2^60 or more"
            ),
            IntersectError::CoordinateSpan => write!(
                f,
                "the coordinates span more than 125 bits as integers in one scale"
            ),
            IntersectError::BadIndex { face } => {
                write!(f, "face {face} refers to a vertex that does not exist")
            }
            IntersectError::TooManyCandidates { candidates, budget } => write!(
                f,
                "{candidates} candidate face pairs exceed the budget of {budget} (face sizes too \
                 uneven for the grid broad phase)"
            ),
        }
    }
}

impl std::error::Error for IntersectError {}

type P = [i64; 3];

/// What the tests call with each intersecting pair of faces.
type OnPair<'a> = dyn Fn(u32, u32) + Sync + 'a;

/// Counts the self-intersecting face pairs of `triangles` over the exact integer `points`,
/// testing at most `budget` candidate pairs (grid neighbours, before the box test).
pub fn self_intersections(
    points: &[P],
    triangles: &[[u32; 3]],
    budget: u64,
) -> Result<SelfIntersections, IntersectError> {
    narrow_intersections(points, triangles, budget, None)
}

/// [`self_intersections`], calling `on_pair` with every intersecting pair when given.
fn narrow_intersections(
    points: &[P],
    triangles: &[[u32; 3]],
    budget: u64,
    on_pair: Option<&OnPair<'_>>,
) -> Result<SelfIntersections, IntersectError> {
    if let Some(vertex) = points
        .iter()
        .position(|p| p.iter().any(|c| c.unsigned_abs() >= MAX_COORDINATE as u64))
    {
        return Err(IntersectError::CoordinateTooLarge { vertex });
    }
    check_indices(points.len(), triangles)?;
    let boxes: Vec<(P, P)> = triangles
        .iter()
        .map(|t| {
            let t = t.map(|v| points[v as usize]);
            (
                std::array::from_fn(|a| t[0][a].min(t[1][a]).min(t[2][a])),
                std::array::from_fn(|a| t[0][a].max(t[1][a]).max(t[2][a])),
            )
        })
        .collect();
    count_intersecting_pairs(points, triangles, &boxes, budget, on_pair)
}

/// [`self_intersections`] of a surface with `f64` vertices, exact on those very coordinates
/// (an input kept as it is, [`super::keep_input`]): they are written as integers in one scale
/// ([`common_fixed_point`]), which the 60-bit predicates take when they fit and the wide ones
/// otherwise; the broad phase then runs on the boxes rounded outward to 60 bits.
pub fn self_intersections_of_positions(
    positions: &[[f64; 3]],
    triangles: &[[u32; 3]],
    budget: u64,
) -> Result<SelfIntersections, IntersectError> {
    let wide_bits = MAX_WIDE_COORDINATE.trailing_zeros();
    let wide = common_fixed_point(positions, wide_bits).ok_or(IntersectError::CoordinateSpan)?;
    self_intersections_wide(&wide, triangles, budget)
}

/// [`self_intersections`] of integer points below [`MAX_WIDE_COORDINATE`]: the 60-bit
/// predicates when they fit, the wide ones otherwise (what
/// [`self_intersections_of_positions`] runs on an input's coordinates in one scale).
pub fn self_intersections_wide(
    wide: &[[i128; 3]],
    triangles: &[[u32; 3]],
    budget: u64,
) -> Result<SelfIntersections, IntersectError> {
    wide_intersections(wide, triangles, budget, None)
}

/// Which faces of [`self_intersections_wide`]'s surface meet another outside what they share.
pub fn intersecting_faces_wide(
    wide: &[[i128; 3]],
    triangles: &[[u32; 3]],
    budget: u64,
) -> Result<Vec<bool>, IntersectError> {
    let marks: Vec<AtomicBool> = triangles.iter().map(|_| AtomicBool::new(false)).collect();
    let mark = |f: u32, g: u32| {
        marks[f as usize].store(true, Ordering::Relaxed);
        marks[g as usize].store(true, Ordering::Relaxed);
    };
    wide_intersections(wide, triangles, budget, Some(&mark))?;
    Ok(marks.into_iter().map(AtomicBool::into_inner).collect())
}

/// The pairs of faces of [`self_intersections_wide`]'s surface that meet outside what they
/// share (each as `(f, g)` with `f < g`, in increasing order), or `Ok(None)` when there are
/// more than `max_pairs`.
pub fn intersecting_pairs_wide(
    wide: &[[i128; 3]],
    triangles: &[[u32; 3]],
    budget: u64,
    max_pairs: usize,
) -> Result<Option<Vec<(u32, u32)>>, IntersectError> {
    let pairs = std::sync::Mutex::new(Vec::new());
    let collect = |f: u32, g: u32| {
        let mut pairs = pairs.lock().unwrap_or_else(|e| e.into_inner());
        if pairs.len() <= max_pairs {
            pairs.push((f.min(g), f.max(g)));
        }
    };
    wide_intersections(wide, triangles, budget, Some(&collect))?;
    let mut pairs = pairs.into_inner().unwrap_or_else(|e| e.into_inner());
    if pairs.len() > max_pairs {
        return Ok(None);
    }
    pairs.sort_unstable();
    Ok(Some(pairs))
}

/// [`self_intersections_wide`], marking as [`narrow_intersections`] does.
fn wide_intersections(
    wide: &[[i128; 3]],
    triangles: &[[u32; 3]],
    budget: u64,
    on_pair: Option<&OnPair<'_>>,
) -> Result<SelfIntersections, IntersectError> {
    if wide
        .iter()
        .flatten()
        .any(|c| c.unsigned_abs() >= MAX_WIDE_COORDINATE as u128)
    {
        return Err(IntersectError::CoordinateSpan);
    }
    let top = wide
        .iter()
        .flatten()
        .map(|c| 128 - c.unsigned_abs().leading_zeros())
        .max()
        .unwrap_or(0);
    let narrow_bits = MAX_COORDINATE.trailing_zeros();
    if top < narrow_bits {
        let narrow: Vec<P> = wide.iter().map(|p| p.map(|c| c as i64)).collect();
        return narrow_intersections(&narrow, triangles, budget, on_pair);
    }
    check_indices(wide.len(), triangles)?;
    let shift = top - (narrow_bits - 1);
    // Arithmetic shifts round towards −∞: the minimum down, the maximum (negated) up.
    let floor = |c: i128| (c >> shift) as i64;
    let ceil = |c: i128| -((-c) >> shift) as i64;
    let boxes: Vec<(P, P)> = triangles
        .iter()
        .map(|t| {
            let t = t.map(|v| wide[v as usize]);
            (
                std::array::from_fn(|a| floor(t[0][a].min(t[1][a]).min(t[2][a]))),
                std::array::from_fn(|a| ceil(t[0][a].max(t[1][a]).max(t[2][a]))),
            )
        })
        .collect();
    count_intersecting_pairs(wide, triangles, &boxes, budget, on_pair)
}

fn check_indices(points: usize, triangles: &[[u32; 3]]) -> Result<(), IntersectError> {
    match triangles
        .iter()
        .position(|t| t.iter().any(|&v| v as usize >= points))
    {
        Some(face) => Err(IntersectError::BadIndex { face }),
        None => Ok(()),
    }
}

/// The pairs of [`self_intersections`], with each face's box (exact, or rounded outward),
/// `on_pair` called with each when given.
fn count_intersecting_pairs<T: ExactPoint>(
    points: &[T],
    triangles: &[[u32; 3]],
    boxes: &[(P, P)],
    budget: u64,
    on_pair: Option<&OnPair<'_>>,
) -> Result<SelfIntersections, IntersectError> {
    let tri = |f: usize| triangles[f].map(|v| points[v as usize]);
    // One grid at the largest extent; by size classes only when that is over the budget.
    // Classes have fewer candidates but cost more hash lookups per cell: on the bunny at res
    // 256 (157k faces) one grid has 34.7M candidates and checks in 0.14–0.22 s, classes 8.3M
    // and 0.46 s; cura-predator_platform at res 256 is over its budget with one grid (304M, a
    // flat bed's large faces among small ones) and checks by classes in 0.77 s.
    let mut grids = SizeClassGrids::new(boxes, false);
    let mut candidates = grids.candidates();
    if candidates > budget {
        let classes = SizeClassGrids::new(boxes, true);
        let c = classes.candidates();
        if c < candidates {
            (grids, candidates) = (classes, c);
        }
    }
    if candidates > budget {
        return Err(IntersectError::TooManyCandidates { candidates, budget });
    }
    let overlap = |f: usize, g: usize| {
        let ((alo, ahi), (blo, bhi)) = (boxes[f], boxes[g]);
        (0..3).all(|a| alo[a] <= bhi[a] && blo[a] <= ahi[a])
    };
    let degenerate: Vec<bool> = (0..triangles.len())
        .into_par_iter()
        .map(|f| {
            let t = tri(f);
            T::projection_axis(t[0], t[1], t[2]).is_none()
        })
        .collect();
    // `acc`: intersecting pairs, tested pairs.
    let test = |f: usize, g: usize, acc: &mut [u64; 2]| {
        if degenerate[f] || degenerate[g] || !overlap(f, g) {
            return;
        }
        acc[1] += 1;
        if faces_intersect(tri(f), tri(g)) {
            acc[0] += 1;
            if let Some(on_pair) = on_pair {
                on_pair(f as u32, g as u32);
            }
        }
    };
    let [pairs, tested_pairs] = grids.pairs_of_cells(|a, b| {
        let mut acc = [0, 0];
        for (i, &(_, f)) in a.iter().enumerate() {
            for &(_, g) in b.unwrap_or(&a[i + 1..]) {
                test(f as usize, g as usize, &mut acc);
            }
        }
        acc
    });
    let (pairs, tested_pairs) = (pairs as usize, tested_pairs as usize);
    Ok(SelfIntersections {
        pairs,
        degenerate_faces: degenerate.iter().filter(|&&d| d).count(),
        tested_pairs,
    })
}

/// The broad phase of [`self_intersections`]: faces by size class, class `k` holding the faces
/// whose box extent is at most `base·2^k` (`base` the median extent), each class in a grid of
/// that cell size keyed by the cell of the box's minimum corner. One grid at the largest
/// extent put a flat bed's many small faces in the cells of its few large ones
/// (cura-predator_platform at res 256: 304M candidate pairs; by classes a few million).
struct SizeClassGrids<'a> {
    classes: Vec<Grid>,
    boxes: &'a [(P, P)],
}

/// Faces of one size class sorted by cell, and each cell's range.
struct Grid {
    cell: i64,
    order: Vec<(P, u32)>,
    ranges: std::collections::HashMap<P, (usize, usize)>,
}

impl Grid {
    fn key(&self, p: P) -> P {
        p.map(|c| c.div_euclid(self.cell))
    }

    fn faces_in(&self, key: P) -> Option<&[(P, u32)]> {
        self.ranges.get(&key).map(|&(s, e)| &self.order[s..e])
    }
}

impl<'a> SizeClassGrids<'a> {
    /// By size classes, or (`by_size` false) one class: one grid at the largest extent.
    fn new(boxes: &'a [(P, P)], by_size: bool) -> SizeClassGrids<'a> {
        let extent = |(lo, hi): &(P, P)| (0..3).map(|a| hi[a] - lo[a]).max().unwrap_or(0);
        let mut extents: Vec<i64> = boxes.iter().map(extent).collect();
        let base = if extents.is_empty() {
            1
        } else if by_size {
            let middle = extents.len() / 2;
            *extents.select_nth_unstable(middle).1
        } else {
            extents.iter().copied().max().unwrap_or(1)
        }
        .max(1);
        let class_of = |e: i64| {
            let mut k = 0;
            while (base << k) < e {
                k += 1;
            }
            k
        };
        let mut members: Vec<Vec<u32>> = Vec::new();
        for (f, b) in boxes.iter().enumerate() {
            let k = class_of(extent(b));
            if members.len() <= k {
                members.resize_with(k + 1, Vec::new);
            }
            members[k].push(f as u32);
        }
        let classes = members
            .into_iter()
            .enumerate()
            .map(|(k, faces)| {
                let cell = base << k;
                let mut order: Vec<(P, u32)> = faces
                    .iter()
                    .map(|&f| (boxes[f as usize].0.map(|c| c.div_euclid(cell)), f))
                    .collect();
                order.par_sort_unstable();
                let mut ranges = std::collections::HashMap::default();
                let mut start = 0;
                while start < order.len() {
                    let key = order[start].0;
                    let mut end = start + 1;
                    while end < order.len() && order[end].0 == key {
                        end += 1;
                    }
                    ranges.insert(key, (start, end));
                    start = end;
                }
                Grid {
                    cell,
                    order,
                    ranges,
                }
            })
            .collect();
        SizeClassGrids { classes, boxes }
    }

    /// Candidate pairs: the pairs of faces in the cell pairs of [`SizeClassGrids::pairs_of_cells`].
    fn candidates(&self) -> u64 {
        self.pairs_of_cells(|a, b| match b {
            None => [(a.len() * a.len().saturating_sub(1) / 2) as u64, 0],
            Some(b) => [(a.len() * b.len()) as u64, 0],
        })[0]
    }

    /// Sums `visit` over pairs of cells that together hold every pair of faces whose boxes
    /// overlap, each such pair once: `(a, None)` for the pairs within one cell's faces `a`,
    /// `(a, Some(b))` for the pairs of a face of `a` and one of `b`.
    ///
    /// Within a class both extents are at most the cell, so overlapping boxes have their
    /// minimum corners in the same or neighbouring cells (the cell and the 13 neighbours
    /// "after" it visit each unordered pair of cells once). Across classes `k < j`, a face `g`
    /// of class `j` meets a face `f` of class `k` only if `g`'s minimum corner lies in
    /// `f.lo − cell_j ..= f.hi`; for the faces of one cell of class `k` that is within
    /// `key·cell_k − cell_j ..= (key + 2)·cell_k` (each face's class-`j` cell pair from its own
    /// cell only, so once), and only if `g`'s box meets `key·cell_k ..= (key + 2)·cell_k`, which
    /// holds the boxes of that cell's faces: without this filter a small output with a few
    /// large flat faces among small ones went over its budget (cura-arjunpro300_platform at res
    /// 256 with 32-cell flat faces: 37.5M candidate pairs for 32,620 faces).
    fn pairs_of_cells(
        &self,
        visit: impl Fn(&[(P, u32)], Option<&[(P, u32)]>) -> [u64; 2] + Sync,
    ) -> [u64; 2] {
        let add = |a: [u64; 2], b: [u64; 2]| [a[0] + b[0], a[1] + b[1]];
        let forward: Vec<P> = (-1..=1i64)
            .flat_map(|z| (-1..=1i64).flat_map(move |y| (-1..=1i64).map(move |x| [x, y, z])))
            .filter(|d| (d[2], d[1], d[0]) > (0, 0, 0))
            .collect();
        self.classes
            .iter()
            .enumerate()
            .map(|(k, grid)| {
                let cells: Vec<(&P, &(usize, usize))> = grid.ranges.iter().collect();
                cells
                    .par_iter()
                    .map(|&(key, &(s, e))| {
                        let a = &grid.order[s..e];
                        let mut sum = visit(a, None);
                        let mut more = |b: &[(P, u32)]| sum = add(sum, visit(a, Some(b)));
                        for d in &forward {
                            if let Some(b) = grid.faces_in([0, 1, 2].map(|i| key[i] + d[i])) {
                                more(b);
                            }
                        }
                        // Saturating: coordinates below 2^60, cells up to 2^62.
                        let region_lo = key.map(|c| c.saturating_mul(grid.cell));
                        let region_hi = key.map(|c| c.saturating_add(2).saturating_mul(grid.cell));
                        let meets_region = |&(_, g): &(P, u32)| {
                            let (glo, ghi) = self.boxes[g as usize];
                            (0..3).all(|i| glo[i] <= region_hi[i] && region_lo[i] <= ghi[i])
                        };
                        let mut near: Vec<(P, u32)> = Vec::new();
                        for larger in &self.classes[k + 1..] {
                            let lo = larger.key(region_lo.map(|c| c.saturating_sub(larger.cell)));
                            let hi = larger.key(region_hi);
                            for z in lo[2]..=hi[2] {
                                for y in lo[1]..=hi[1] {
                                    for x in lo[0]..=hi[0] {
                                        if let Some(b) = larger.faces_in([x, y, z]) {
                                            near.clear();
                                            near.extend(b.iter().filter(|g| meets_region(g)));
                                            if !near.is_empty() {
                                                more(&near);
                                            }
                                        }
                                    }
                                }
                            }
                        }
                        sum
                    })
                    .reduce(|| [0, 0], add)
            })
            .fold([0, 0], add)
    }
}

fn sub(a: P, b: P) -> P {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}

/// Exact `(b − a) × (c − a)` (differences below `2^61`, products below `2^122`).
fn normal(a: P, b: P, c: P) -> [i128; 3] {
    let (u, v) = (sub(b, a), sub(c, a));
    let m = |x: i64, y: i64| i128::from(x) * i128::from(y);
    [
        m(u[1], v[2]) - m(u[2], v[1]),
        m(u[2], v[0]) - m(u[0], v[2]),
        m(u[0], v[1]) - m(u[1], v[0]),
    ]
}

/// The points the exact tests run on: the remesher's fixed point (`[i64; 3]`, below
/// [`MAX_COORDINATE`], the kernel's 60-bit predicates) or an input's own coordinates as integers
/// in one scale (`[i128; 3]`, below [`MAX_WIDE_COORDINATE`], the kernel's wide predicates).
pub trait ExactPoint: Copy + PartialEq + Send + Sync {
    /// One coordinate.
    type Coordinate: Copy + Ord;
    /// Coordinate `k`.
    fn at(self, k: usize) -> Self::Coordinate;
    /// Sign of `(d − a) · ((b − a) × (c − a))`.
    fn orient(a: Self, b: Self, c: Self, d: Self) -> i32;
    /// Sign of the 2D orientation of `(a, b, c)` in the plane of axes `(i, j)`.
    fn orient2(a: Self, b: Self, c: Self, axes: (usize, usize)) -> i32;
    /// An axis along which the triangle's normal is nonzero, `None` when its corners are
    /// collinear (component `k` of the normal is the orientation in the plane of the other two).
    fn projection_axis(a: Self, b: Self, c: Self) -> Option<usize> {
        (0..3).find(|&k| Self::orient2(a, b, c, plane_axes(k)) != 0)
    }
}

impl ExactPoint for P {
    type Coordinate = i64;
    #[inline]
    fn at(self, k: usize) -> i64 {
        self[k]
    }
    #[inline]
    fn orient(a: P, b: P, c: P, d: P) -> i32 {
        W128::orient3d_sign(sub(d, a), sub(b, a), sub(c, a))
    }
    #[inline]
    fn orient2(a: P, b: P, c: P, (i, j): (usize, usize)) -> i32 {
        W128::det2_sign(b[i] - a[i], b[j] - a[j], c[i] - a[i], c[j] - a[j])
    }
    #[inline]
    fn projection_axis(a: P, b: P, c: P) -> Option<usize> {
        let n = normal(a, b, c);
        (0..3).find(|&k| n[k] != 0)
    }
}

/// Largest accepted magnitude of a wide coordinate (differences stay below `2^126`).
pub const MAX_WIDE_COORDINATE: i128 = 1 << 125;

impl ExactPoint for [i128; 3] {
    type Coordinate = i128;
    #[inline]
    fn at(self, k: usize) -> i128 {
        self[k]
    }
    fn orient(a: Self, b: Self, c: Self, d: Self) -> i32 {
        let sub = |p: Self, q: Self| [p[0] - q[0], p[1] - q[1], p[2] - q[2]];
        orient3d_sign_wide(sub(d, a), sub(b, a), sub(c, a))
    }
    fn orient2(a: Self, b: Self, c: Self, (i, j): (usize, usize)) -> i32 {
        det2_sign_wide(b[i] - a[i], b[j] - a[j], c[i] - a[i], c[j] - a[j])
    }
}

fn orient<T: ExactPoint>(a: T, b: T, c: T, d: T) -> i32 {
    T::orient(a, b, c, d)
}

fn orient2<T: ExactPoint>(a: T, b: T, c: T, axes: (usize, usize)) -> i32 {
    T::orient2(a, b, c, axes)
}

/// The two axes kept when projecting along `axis`.
pub(super) fn plane_axes(axis: usize) -> (usize, usize) {
    ((axis + 1) % 3, (axis + 2) % 3)
}

/// The plane of projection of a non-degenerate triangle.
fn projection_axes<T: ExactPoint>(a: T, b: T, c: T) -> (usize, usize) {
    plane_axes(T::projection_axis(a, b, c).unwrap_or(2))
}

/// Whether the faces `s` and `t` (non-degenerate) meet outside what they share.
pub fn faces_intersect<T: ExactPoint>(s: [T; 3], t: [T; 3]) -> bool {
    // At most three shared corners (no allocation: this runs for every candidate pair, and for
    // every collapse the simplification tries).
    let mut shared = [(0usize, 0usize); 3];
    let mut count = 0;
    for (i, p) in s.iter().enumerate() {
        for (j, q) in t.iter().enumerate() {
            if p == q && count < 3 {
                shared[count] = (i, j);
                count += 1;
            }
        }
    }
    match count {
        0 => {
            // Quick rejection: one face strictly on one side of the other's plane.
            let side = t.map(|p| orient(s[0], s[1], s[2], p));
            if side.iter().all(|&x| x > 0) || side.iter().all(|&x| x < 0) {
                return false;
            }
            if side == [0; 3] {
                // Coplanar (a flat region of the remesher's output: most pairs the
                // simplification tests there, and most of them apart).
                let axes = projection_axes(s[0], s[1], s[2]);
                return coplanar_triangles_meet(s, t, axes);
            }
            let side = s.map(|p| orient(t[0], t[1], t[2], p));
            if side.iter().all(|&x| x > 0) || side.iter().all(|&x| x < 0) {
                return false;
            }
            (0..3).any(|k| segment_meets_triangle(s[k], s[(k + 1) % 3], t))
                || (0..3).any(|k| segment_meets_triangle(t[k], t[(k + 1) % 3], s))
        }
        1 => {
            let (i, j) = shared[0];
            let (p, q) = (s[(i + 1) % 3], s[(i + 2) % 3]);
            let sides = (orient(t[0], t[1], t[2], p), orient(t[0], t[1], t[2], q));
            // `s` off `t`'s plane but for the shared corner: `s` meets that plane, hence `t`,
            // only there (most pairs the simplification tests share a corner, and this saves
            // the second segment's two orientations).
            if sides.0 == sides.1 && sides.0 != 0 {
                return false;
            }
            segment_meets_triangle_on_sides(p, q, t, sides)
                || segment_meets_triangle(t[(j + 1) % 3], t[(j + 2) % 3], s)
        }
        2 => {
            let (u, v) = (s[shared[0].0], s[shared[1].0]);
            let a = s[3 - shared[0].0 - shared[1].0];
            let b = t[3 - shared[0].1 - shared[1].1];
            if orient(u, v, a, b) != 0 {
                return false;
            }
            let axes = projection_axes(u, v, a);
            orient2(u, v, a, axes) == orient2(u, v, b, axes)
        }
        _ => true,
    }
}

/// Whether the closed segment `p q` meets the closed (non-degenerate) triangle `t`.
pub fn segment_meets_triangle<T: ExactPoint>(p: T, q: T, t: [T; 3]) -> bool {
    let sides = (orient(t[0], t[1], t[2], p), orient(t[0], t[1], t[2], q));
    segment_meets_triangle_on_sides(p, q, t, sides)
}

/// [`segment_meets_triangle`] with the sides of `p` and `q` of `t`'s plane known.
fn segment_meets_triangle_on_sides<T: ExactPoint>(
    p: T,
    q: T,
    t: [T; 3],
    (op, oq): (i32, i32),
) -> bool {
    if op == oq && op != 0 {
        return false;
    }
    if op == 0 && oq == 0 {
        let axes = projection_axes(t[0], t[1], t[2]);
        return coplanar_segment_meets_triangle(p, q, t, axes);
    }
    // The segment meets the plane in one point; the line through it passes through the closed
    // triangle iff the three edge volumes have no two opposite strict signs.
    let s = [
        orient(p, q, t[0], t[1]),
        orient(p, q, t[1], t[2]),
        orient(p, q, t[2], t[0]),
    ];
    !(s.contains(&1) && s.contains(&-1))
}

/// Whether the closed triangles `s` and `t`, non-degenerate and in one plane, meet (projected on
/// `axes`, along which their normals are nonzero).
fn coplanar_triangles_meet<T: ExactPoint>(s: [T; 3], t: [T; 3], axes: (usize, usize)) -> bool {
    // A line that leaves one closed set strictly on one side and the other touching or on the
    // other side separates them; the lines through the edges are the first ones tried, at 3
    // orientations each, since the edge-by-edge test below takes 108 when they are apart
    // (on the README's cube at res 256 the coplanar tests were 26 % of the run).
    if strictly_outside_an_edge(&t, s, axes) || strictly_outside_an_edge(&s, t, axes) {
        return false;
    }
    (0..3).any(|k| coplanar_segment_meets_triangle(s[k], s[(k + 1) % 3], t, axes))
        || (0..3).any(|k| coplanar_segment_meets_triangle(t[k], t[(k + 1) % 3], s, axes))
}

/// Whether every point of `points` lies strictly on the far side, from `t`, of the line through
/// one edge of `t` (all in one plane, projected on `axes`; `t` non-degenerate there): then the
/// convex hull of `points` and the closed triangle are apart.
fn strictly_outside_an_edge<T: ExactPoint>(points: &[T], t: [T; 3], axes: (usize, usize)) -> bool {
    let inside = orient2(t[0], t[1], t[2], axes);
    (0..3).any(|k| {
        points
            .iter()
            .all(|&p| orient2(t[k], t[(k + 1) % 3], p, axes) == -inside)
    })
}

/// Whether the closed segment `p q` meets the closed triangle `t`, all in one plane, projected on
/// `axes` (a plane of projection along which the triangle's normal is nonzero).
fn coplanar_segment_meets_triangle<T: ExactPoint>(
    p: T,
    q: T,
    t: [T; 3],
    axes: (usize, usize),
) -> bool {
    if strictly_outside_an_edge(&[p, q], t, axes) {
        return false;
    }
    let line_side = t.map(|c| orient2(p, q, c, axes));
    if line_side.iter().all(|&x| x > 0) || line_side.iter().all(|&x| x < 0) {
        return false;
    }
    segment_meets_triangle_2d(p, q, t, axes)
}

/// [`coplanar_segment_meets_triangle`] without the separating lines: an end inside, or a
/// crossing or touching edge.
fn segment_meets_triangle_2d<T: ExactPoint>(p: T, q: T, t: [T; 3], axes: (usize, usize)) -> bool {
    point_in_triangle_2d(p, t, axes)
        || point_in_triangle_2d(q, t, axes)
        || (0..3).any(|k| segments_meet_2d(p, q, t[k], t[(k + 1) % 3], axes))
}

fn point_in_triangle_2d<T: ExactPoint>(p: T, t: [T; 3], axes: (usize, usize)) -> bool {
    let s = [
        orient2(t[0], t[1], p, axes),
        orient2(t[1], t[2], p, axes),
        orient2(t[2], t[0], p, axes),
    ];
    !(s.contains(&1) && s.contains(&-1))
}

/// Whether the closed segments `a b` and `c d`, coplanar, meet (projected on `axes`).
fn segments_meet_2d<T: ExactPoint>(a: T, b: T, c: T, d: T, axes: (usize, usize)) -> bool {
    let d1 = orient2(c, d, a, axes);
    let d2 = orient2(c, d, b, axes);
    let d3 = orient2(a, b, c, axes);
    let d4 = orient2(a, b, d, axes);
    if d1 * d2 < 0 && d3 * d4 < 0 {
        return true;
    }
    let within = |x: T, y: T, z: T| {
        (0..3).all(|k| x.at(k).min(y.at(k)) <= z.at(k) && z.at(k) <= x.at(k).max(y.at(k)))
    };
    (d1 == 0 && within(c, d, a))
        || (d2 == 0 && within(c, d, b))
        || (d3 == 0 && within(a, b, c))
        || (d4 == 0 && within(a, b, d))
}

#[cfg(test)]
mod tests {
    use super::*;

    const T: [P; 3] = [[0, 0, 0], [10, 0, 0], [0, 10, 0]];

    #[test]
    fn piercing_and_separate() {
        // A vertical triangle through T's interior.
        assert!(faces_intersect(T, [[2, 2, -5], [3, 2, 5], [2, 3, 5]]));
        // The same, lifted above the plane.
        assert!(!faces_intersect(T, [[2, 2, 1], [3, 2, 5], [2, 3, 5]]));
        // Touching T's interior with one vertex.
        assert!(faces_intersect(T, [[2, 2, 0], [3, 2, 5], [2, 3, 5]]));
    }

    #[test]
    fn shared_edge_fold_and_hinge() {
        // Same plane, opposite sides of the common edge: a flat hinge, no intersection.
        assert!(!faces_intersect(T, [[10, 0, 0], [0, 0, 0], [5, -5, 0]]));
        // Same plane, same side: folded over.
        assert!(faces_intersect(T, [[10, 0, 0], [0, 0, 0], [2, 2, 0]]));
        // Out of plane: a proper dihedral.
        assert!(!faces_intersect(T, [[10, 0, 0], [0, 0, 0], [2, 2, 3]]));
    }

    #[test]
    fn shared_vertex() {
        // A fan neighbour in the plane, outside T.
        assert!(!faces_intersect(T, [[0, 0, 0], [-5, 5, 0], [-5, -5, 0]]));
        // Overlapping sector in the plane.
        assert!(faces_intersect(T, [[0, 0, 0], [5, 1, 0], [5, 2, 0]]));
        // Its opposite edge passing through T from above to below.
        assert!(faces_intersect(T, [[0, 0, 0], [3, 3, 4], [3, 4, -4]]));
        // Rising out of the plane.
        assert!(!faces_intersect(T, [[0, 0, 0], [3, 3, 4], [3, 4, 4]]));
    }

    #[test]
    fn coplanar_disjoint_and_contained() {
        assert!(!faces_intersect(T, [[20, 20, 0], [30, 20, 0], [20, 30, 0]]));
        assert!(faces_intersect(T, [[1, 1, 0], [3, 1, 0], [1, 3, 0]]));
    }

    /// The separating lines tried first by the coplanar tests decide as the edge-by-edge test
    /// alone does, on triangles and segments of a small grid (coincident corners, touching and
    /// collinear edges, containment) in an axis plane and in a tilted one.
    #[test]
    fn separating_lines_agree_with_the_edge_by_edge_test() {
        let mut state = 0x9e37_79b9_7f4a_7c15u64;
        let mut next = |m: i64| {
            state ^= state << 13;
            state ^= state >> 7;
            state ^= state << 17;
            (state % m as u64) as i64
        };
        // Integer points of two planes: z = 3, and o + a·u + b·v (normal (1, 1, 1)).
        let planes: [(P, P, P); 2] = [
            ([0, 0, 3], [1, 0, 0], [0, 1, 0]),
            ([5, -2, 7], [1, -1, 0], [0, 1, -1]),
        ];
        let (mut apart, mut meeting, mut segments) = (0, 0, 0);
        for (o, u, v) in planes {
            let mut point = || {
                let (a, b) = (next(7), next(7));
                std::array::from_fn(|k| o[k] + a * u[k] + b * v[k])
            };
            for _ in 0..20_000 {
                let s: [P; 3] = [point(), point(), point()];
                let t: [P; 3] = [point(), point(), point()];
                let ns = normal(s[0], s[1], s[2]);
                if ns == [0; 3] || normal(t[0], t[1], t[2]) == [0; 3] {
                    continue;
                }
                let axes = projection_axes(s[0], s[1], s[2]);
                let by_edges = (0..3)
                    .any(|k| segment_meets_triangle_2d(s[k], s[(k + 1) % 3], t, axes))
                    || (0..3).any(|k| segment_meets_triangle_2d(t[k], t[(k + 1) % 3], s, axes));
                assert_eq!(coplanar_triangles_meet(s, t, axes), by_edges, "{s:?} {t:?}");
                if by_edges {
                    meeting += 1;
                } else {
                    apart += 1;
                }
                for k in 0..3 {
                    let (p, q) = (s[k], s[(k + 1) % 3]);
                    let expected = segment_meets_triangle_2d(p, q, t, axes);
                    assert_eq!(
                        coplanar_segment_meets_triangle(p, q, t, axes),
                        expected,
                        "{p:?} {q:?} {t:?}"
                    );
                    segments += usize::from(expected);
                }
            }
        }
        assert!(apart > 5_000 && meeting > 5_000 && segments > 10_000);
    }

    /// The wide predicates decide every pair of a small grid's triangles (shared corners,
    /// coplanar, touching) as the 60-bit ones do on the grid itself, after an invertible integer
    /// map with 61-bit entries (meeting is invariant under it): the images need ~64 bits, the
    /// `f64` filters round them, and the degenerate cases reach the arbitrary-precision
    /// fallbacks (each of which, broken, fails this test).
    #[test]
    fn wide_coordinates_decide_as_the_narrow_ones() {
        let mut state = 0x2545_f491_4f6c_dd1du64;
        let mut next = |m: u64| {
            state ^= state << 13;
            state ^= state >> 7;
            state ^= state << 17;
            state % m
        };
        let (mut meeting, mut apart) = (0, 0);
        for round in 0..200 {
            // A fresh map every 100 pairs; entries below 2^61, images below 2^64.
            let m: [[i128; 3]; 3] =
                std::array::from_fn(|_| std::array::from_fn(|_| i128::from(next(1 << 61))));
            let big = |r: usize, c: usize| num_bigint::BigInt::from(m[r][c]);
            let det = big(0, 0) * (big(1, 1) * big(2, 2) - big(1, 2) * big(2, 1))
                - big(0, 1) * (big(1, 0) * big(2, 2) - big(1, 2) * big(2, 0))
                + big(0, 2) * (big(1, 0) * big(2, 1) - big(1, 1) * big(2, 0));
            if det == num_bigint::BigInt::from(0) {
                continue;
            }
            let map = |p: P| -> [i128; 3] {
                std::array::from_fn(|r| (0..3).map(|c| m[r][c] * i128::from(p[c])).sum())
            };
            for _ in 0..100 {
                let mut point = || -> P { [0, 1, 2].map(|_| next(4) as i64) };
                let s: [P; 3] = [point(), point(), point()];
                let t: [P; 3] = [point(), point(), point()];
                if P::projection_axis(s[0], s[1], s[2]).is_none()
                    || P::projection_axis(t[0], t[1], t[2]).is_none()
                {
                    continue;
                }
                let narrow = faces_intersect(s, t);
                assert_eq!(
                    faces_intersect(s.map(map), t.map(map)),
                    narrow,
                    "round {round}: {s:?} {t:?}"
                );
                if narrow {
                    meeting += 1;
                } else {
                    apart += 1;
                }
            }
        }
        assert!(meeting > 1_000 && apart > 1_000, "{meeting} {apart}");
    }

    /// On `f64` vertices: the octahedron at `1 + 2^-70`-fine coordinates (past the 60-bit
    /// range) is clean, and the spike through it counts twice, as on integers.
    #[test]
    fn positions_beyond_sixty_bits_are_tested_exactly() {
        let tiny = 2f64.powi(-70);
        let p = [
            [1.0, tiny, 0.0],
            [-1.0, 0.0, tiny],
            [0.0, 1.0, 0.0],
            [tiny, -1.0, 0.0],
            [0.0, 0.0, 1.0],
            [0.0, tiny, -1.0],
        ];
        let f = crate::testing::OCTAHEDRON_FACES;
        let r = self_intersections_of_positions(&p, &f, u64::MAX).unwrap();
        assert_eq!((r.pairs, r.degenerate_faces), (0, 0));
        let mut p2 = p.to_vec();
        p2.extend([[0.1, 0.1, -2.0], [0.2, 0.1, 2.0], [0.1, 0.2, 2.0]]);
        let mut f2 = f.to_vec();
        f2.push([6, 7, 8]);
        assert_eq!(
            self_intersections_of_positions(&p2, &f2, u64::MAX)
                .unwrap()
                .pairs,
            2
        );
        // A face through a vertex `2^-70` off its plane: apart; on it: touching.
        let q = [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]];
        for (z, pairs) in [(tiny, 0), (0.0, 1)] {
            let mut pts = q.to_vec();
            pts.extend([[0.25, 0.25, z], [0.3, 0.25, 1.0], [0.25, 0.3, 1.0]]);
            let r = self_intersections_of_positions(&pts, &[[0, 1, 2], [3, 4, 5]], u64::MAX);
            assert_eq!(r.unwrap().pairs, pairs, "z = {z}");
        }
        assert_eq!(
            self_intersections_of_positions(&[[1.0, 1e-300, 0.0]], &[], 10),
            Err(IntersectError::CoordinateSpan)
        );
    }

    #[test]
    fn octahedron_is_clean_and_a_crossed_pair_counts_once() {
        let p = [
            [10, 0, 0],
            [-10, 0, 0],
            [0, 10, 0],
            [0, -10, 0],
            [0, 0, 10],
            [0, 0, -10],
        ];
        let f = crate::testing::OCTAHEDRON_FACES;
        let r = self_intersections(&p, &f, u64::MAX).unwrap();
        assert_eq!((r.pairs, r.degenerate_faces), (0, 0));
        let mut p2 = p.to_vec();
        p2.extend([[1, 1, -20], [2, 1, 20], [1, 2, 20]]);
        let mut f2 = f.to_vec();
        f2.push([6, 7, 8]);
        // The spike pierces the top and the bottom face it passes through.
        assert_eq!(self_intersections(&p2, &f2, u64::MAX).unwrap().pairs, 2);
        assert!(matches!(
            self_intersections(&p2, &f2, 1),
            Err(IntersectError::TooManyCandidates { .. })
        ));
        assert_eq!(
            self_intersections(&[[1 << 61, 0, 0]], &[], 10),
            Err(IntersectError::CoordinateTooLarge { vertex: 0 })
        );
        assert_eq!(
            self_intersections(&p, &[[0, 1, 9]], 10),
            Err(IntersectError::BadIndex { face: 0 })
        );
    }

    /// A few large faces far from many small ones are no candidates for them: 100 small
    /// triangles in a plane 500 ticks above three large ones (each small face in a cell of its
    /// own) make 3 candidate pairs by size classes (the large ones among themselves), not 303 (the large ones' cell was paired
    /// with every small cell it could reach before the boxes were compared with the cell's).
    #[test]
    fn large_faces_pair_only_with_the_small_cells_their_boxes_meet() {
        let mut p: Vec<P> = Vec::new();
        let mut f: Vec<[u32; 3]> = Vec::new();
        for z in [0, 10, 20] {
            let n = p.len() as u32;
            p.extend([[0, 0, z], [1000, 0, z], [0, 1000, z]]);
            f.push([n, n + 1, n + 2]);
        }
        for i in 0..10 {
            for j in 0..10 {
                let n = p.len() as u32;
                let (x, y) = (100 * i, 100 * j);
                p.extend([[x, y, 500], [x + 1, y, 500], [x, y + 1, 500]]);
                f.push([n, n + 1, n + 2]);
            }
        }
        let r = self_intersections(&p, &f, 50).unwrap();
        assert_eq!((r.pairs, r.tested_pairs), (0, 0));
    }

    /// Both broad phases (one grid, size classes) visit every pair of faces whose boxes overlap
    /// exactly once, on soups of triangles from a tick to ten thousand ticks across; and the
    /// counts of tested and intersecting pairs are those of testing all pairs.
    #[test]
    fn the_broad_phase_misses_no_pair_of_any_sizes() {
        let mut state = 0x2545_f491_4f6c_dd1du64;
        let mut next = |m: i64| {
            state ^= state << 13;
            state ^= state >> 7;
            state ^= state << 17;
            (state % m as u64) as i64
        };
        let bx = |t: [P; 3]| -> (P, P) {
            (
                std::array::from_fn(|i| t[0][i].min(t[1][i]).min(t[2][i])),
                std::array::from_fn(|i| t[0][i].max(t[1][i]).max(t[2][i])),
            )
        };
        let meet = |(alo, ahi): (P, P), (blo, bhi): (P, P)| {
            (0..3).all(|i| alo[i] <= bhi[i] && blo[i] <= ahi[i])
        };
        for round in 0..6 {
            let mut points = Vec::new();
            let mut faces = Vec::new();
            for f in 0..300u32 {
                let size = [1, 3, 10, 100, 1000, 10_000][next(6) as usize] + round;
                let corner: P = std::array::from_fn(|_| next(8_000) - 4_000);
                for _ in 0..3 {
                    points.push(std::array::from_fn(|a| corner[a] + next(size + 1)));
                }
                faces.push([3 * f, 3 * f + 1, 3 * f + 2]);
            }
            let tri = |f: usize| faces[f].map(|v| points[v as usize]);
            let boxes: Vec<(P, P)> = (0..faces.len()).map(|f| bx(tri(f))).collect();
            let (mut overlapping, mut tested, mut pairs) = (0u64, 0, 0);
            for f in 0..faces.len() {
                for g in f + 1..faces.len() {
                    if !meet(boxes[f], boxes[g]) {
                        continue;
                    }
                    overlapping += 1;
                    let (a, b) = (tri(f), tri(g));
                    if normal(a[0], a[1], a[2]) != [0; 3] && normal(b[0], b[1], b[2]) != [0; 3] {
                        tested += 1;
                        pairs += usize::from(faces_intersect(a, b));
                    }
                }
            }
            for by_size in [false, true] {
                let found = SizeClassGrids::new(&boxes, by_size).pairs_of_cells(|a, b| {
                    let mut n = 0;
                    for (i, &(_, f)) in a.iter().enumerate() {
                        for &(_, g) in b.unwrap_or(&a[i + 1..]) {
                            n += u64::from(meet(boxes[f as usize], boxes[g as usize]));
                        }
                    }
                    [n, 0]
                })[0];
                assert_eq!(found, overlapping, "round {round}, by size {by_size}");
            }
            let r = self_intersections(&points, &faces, u64::MAX).unwrap();
            assert_eq!((r.tested_pairs, r.pairs), (tested, pairs), "round {round}");
            assert!(
                tested > 300 && pairs > 10,
                "round {round}: {tested} {pairs}"
            );
        }
    }
}
