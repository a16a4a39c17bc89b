//! Corner classification: the coarse level with ray reuse, then an octree split only where
//! classes differ, closed under neighbours so that the labelling of the finest lattice is well
//! defined everywhere.
//!
//! # The invariant
//! Every leaf cell above the finest level is *uniform*: all classified lattice points on its
//! closed box have one class. A lattice point that was never classified then takes the class of
//! any leaf whose closed box holds it; two such leaves agree, because the smaller one's corner
//! on their common face, edge or vertex is classified and lies on both. So every finest cell
//! whose corners differ is a finest leaf, and the band [`Classified::band`] holds all of them.
//!
//! The invariant is kept by splitting (1) coarse cells whose corners differ, (2) every new
//! child whose closed box holds classified points of two classes, and (3) every leaf whose
//! closed box holds a newly classified point of the other class. Each round classifies the new
//! corners of all cells split in it with one parallel batch.
//!
//! # Refining where the input triangles are
//! With the input triangles at hand (`guide`), (1) and (2) also split every coarse cell and
//! every new child that a triangle meets ([`SegmentBvh::meets_box`], conservative), down to the
//! finest level. Splitting more cells keeps the invariant: rules (2) and (3) apply to them as to
//! any other. It finds what corner differences cannot: where `w` jumps only across the triangles
//! (a closed, consistently oriented input), a leaf above the finest level meets no triangle, so
//! `w` is constant on its closed box and the class it lends to its unclassified points is
//! right. Every finest lattice point is then labelled by its true class, and a part of the
//! solid that holds a finest lattice point is in the output, however far it is from any coarse
//! corner (a plate thinner than a coarse cell, say).
//!
//! # Below the regular cells (`Lattice::sub_levels`)
//! A part thinner than a regular cell (a horn, a fin, a tilted plate) can lie between a cell's
//! corners, which then agree. With `S` sub-levels the regular cells are `2^S` finest cells wide
//! and, with a guide, three rules split below them, level by level from `S` down to 1:
//! - **thin**: a leaf that a triangle *crosses* (meets its interior, shrunk by 10⁻⁶ cell: CAD
//!   faces lying in a cell's face do not count) while its corners agree, and where `w` just off
//!   one of (up to four of) the crossing triangles, on either side, has the other class: the
//!   evidence that something no corner sees is there (an inner face of overlapping parts, with
//!   the corners' class on both sides, is not worth eight children); and where that probe's
//!   `w` is at least [`THIN_PART_MARGIN`] from ½, so that the part is a solid the input
//!   bounds, not a fold of the level set ½ along an open sheet;
//! - **propagation**: a leaf next to a cell just split (across a face or an edge) whose shared
//!   face or edge holds a new point of a class that the corners around it do not explain (an
//!   edge's midpoint against both ends, a face's centre against its four corners), and that a
//!   triangle crosses, and whose `w` is at least [`THIN_PART_MARGIN`] from ½ — the thin part
//!   goes on into a cell whose corners differ for another reason;
//! - **balance**: every cell around a split cell of level `l ≤ S` is a leaf of level `l` or
//!   split, so leaves side by side differ by one level at most.
//!
//! With [`Lattice::planar_levels`] `P` the regular cells are `2^P` resolution cells wide, and a
//! fourth rule splits at the levels above the resolution's:
//! - **curved**: a leaf whose corners differ, unless it is flat ([`Classified::flat`]: `w` an
//!   integer at its corners, the triangles meeting it within [`PLANAR_TOLERANCE`] of a plane
//!   that separates the corners' classes), so that a flat face keeps its large cells and
//!   everything else comes down to the resolution.
//!
//! All four only split more cells, so rules (2) and (3) and the invariant hold as above. The
//! leaves of levels `0..S` next to a split cell of their level take the transition split of
//! [`super::transition`]; its extra points (cell and face centres) lie in leaves of level at
//! most `S`, off every larger leaf's closed box, so they are classified outright (on the
//! lattice's outer faces: declared outside, as every point there), or lent the leaf's class
//! where no triangle touches it (`Classified::lend_untouched_transitions`).

use rayon::prelude::*;

use super::crossings::SegmentBvh;
use super::lattice::{Corner, KeyMap, KeySet, Lattice, pack};
use super::levels::Comparisons;
use super::transition;
use crate::eval::Evaluator;
use crate::grid::GridSpec;

/// An octree cell: level (`2^level` finest cells wide) and packed minimum corner.
pub type Cell = (u32, u64);

/// A classified corner: its class and the `w` that decided it.
#[derive(Clone, Copy, Debug)]
pub struct CornerValue {
    /// `w > ½` (border corners: `false`).
    pub inside: bool,
    /// Whether `w` also decides integrality ([`super::levels::decisive_corner_values`]): the
    /// field's own value, or a first pass clear of an integer's slack. The planar levels and
    /// the lent transitions ask the field for the others (`Classified::settle`) before
    /// reading their integrality.
    pub settled: bool,
    /// `w` rounded to `f32` (within the first pass's bound where not `settled`); NaN at border
    /// corners, which are declared outside, never evaluated. Placement's interpolation reads
    /// it, and the margin and integrality tests; the class is `inside`, which the rounding
    /// could flip next to ½. (The three take the 16 bytes a hash entry of a `u64` key and a
    /// `bool` took already.)
    pub w: f32,
}

impl CornerValue {
    fn of((w, settled): (f64, bool)) -> CornerValue {
        CornerValue {
            inside: super::inside(w),
            settled,
            w: w as f32,
        }
    }

    const BORDER: CornerValue = CornerValue {
        inside: false,
        settled: true,
        w: f32::NAN,
    };
}

/// The classification of a lattice.
#[derive(Debug, Default)]
pub struct Classified {
    /// Every classified corner (packed key).
    pub labels: KeyMap<CornerValue>,
    /// The cells that were split.
    pub split: KeySet<Cell>,
    /// Minimum corners of the regular cells (edge [`Lattice::regular_cell`]) whose corners
    /// differ, Freudenthal-split (the band; all of it without sub-levels).
    pub band: Vec<Corner>,
    /// Level and minimum corner of the cells below the regular level whose corners differ,
    /// in the regular cells split for a part thinner than a cell; Freudenthal-split.
    pub fine_band: Vec<(u32, Corner)>,
    /// Level and minimum corner of the leaves (at most regular) across a face or an edge from
    /// a split cell of their level whose transition split ([`transition::tetrahedra`]) has
    /// vertices of both classes.
    pub transition: Vec<(u32, Corner)>,
    /// Minimum corners of the resolution's cells (level [`Lattice::resolution_level`]) split
    /// for a part thinner than a cell.
    pub refined: Vec<Corner>,
}

impl Classified {
    /// The class of a classified corner (`false` when it was never classified; callers only ask
    /// about classified ones).
    pub fn label(&self, c: Corner) -> bool {
        self.labels.get(&pack(c)).is_some_and(|v| v.inside)
    }

    /// `w` at a classified corner (NaN at border corners, and at unclassified ones, which
    /// callers never ask about).
    pub fn value(&self, c: Corner) -> f64 {
        self.labels
            .get(&pack(c))
            .map_or(f64::NAN, |v| f64::from(v.w))
    }

    /// `w` at both corners of each edge, for [`super::place::place_vertices`].
    pub fn edge_values(&self, edges: &[(Corner, Corner)]) -> Vec<[f64; 2]> {
        edges
            .par_iter()
            .map(|&(i, o)| [self.value(i), self.value(o)])
            .collect()
    }

    /// The leaf holding the finest cell with minimum corner `c`.
    fn leaf(&self, lattice: &Lattice, c: Corner) -> (u32, Corner) {
        let mut level = lattice.levels;
        loop {
            let m = c.map(|x| (x >> level) << level);
            if level > 0 && self.split.contains(&(level, pack(m))) {
                level -= 1;
            } else {
                return (level, m);
            }
        }
    }

    /// Whether the classified points on the closed box of the cell `(level, m)` (not split)
    /// differ.
    ///
    /// Found from the split cells, not by scanning the box: before the transition split, the
    /// classified points are the coarse corners and the 27 points of each split cell (its
    /// children's corners). On the closed box of a cell of edge `2^level` such a point is one
    /// of its corners, or one of the 27 of a split cell of at most its level whose closed box
    /// meets it (larger ones' points are spaced at least its edge apart). That cell is not
    /// inside the unsplit cell itself, so it is inside one of the 26 neighbours of its level,
    /// and every split cell is a child of a split cell or coarse: descending from the split
    /// neighbours through the split children that meet the box visits every such point. The
    /// cost grows with the points found, where a scan of the box grew with its area (quadratic
    /// in the cell's edge: at `--res 65536` the coarse cells are 1024 finest cells wide, and
    /// the scan never finished).
    fn closed_box_mixed(&self, lattice: &Lattice, level: u32, m: Corner) -> bool {
        debug_assert!(!self.split.contains(&(level, pack(m))));
        let size = 1u32 << level;
        let first = self.label(m);
        let differs = |p: Corner| self.labels.get(&pack(p)).is_some_and(|v| v.inside != first);
        if (1..8).any(|b| differs(offset(m, b, size))) {
            return true;
        }
        let hi = m.map(|x| x + size);
        let meets_box = |c: Corner, edge: u32| (0..3).all(|a| c[a] <= hi[a] && c[a] + edge >= m[a]);
        let on_box = |p: Corner| {
            (0..3).all(|a| p[a] >= m[a] && p[a] <= hi[a])
                && (0..3).any(|a| p[a] == m[a] || p[a] == hi[a])
        };
        let mut stack: Vec<(u32, Corner)> = neighbours(lattice, m, size)
            .filter(|&n| self.split.contains(&(level, pack(n))))
            .map(|n| (level, n))
            .collect();
        while let Some((l, c)) = stack.pop() {
            let half = 1u32 << (l - 1);
            for i in 0..27u32 {
                let p = [0, 1, 2].map(|a| c[a] + [i % 3, i / 3 % 3, i / 9][a] * half);
                if on_box(p) && differs(p) {
                    return true;
                }
            }
            if l > 1 {
                stack.extend(
                    (0..8)
                        .map(|b| offset(c, b, half))
                        .filter(|&child| {
                            meets_box(child, half) && self.split.contains(&(l - 1, pack(child)))
                        })
                        .map(|child| (l - 1, child)),
                );
            }
        }
        debug_assert!(
            level > 5 || !self.closed_box_mixed_by_scan(level, m),
            "{level} {m:?}"
        );
        false
    }

    /// [`Classified::closed_box_mixed`] by visiting every lattice point of the closed box: the
    /// definition, which debug builds check the descent against on small cells.
    fn closed_box_mixed_by_scan(&self, level: u32, m: Corner) -> bool {
        let size = 1u32 << level;
        let first = self.label(m);
        for dz in 0..=size {
            for dy in 0..=size {
                for dx in 0..=size {
                    let d = [dx, dy, dz];
                    if d.iter().all(|&x| x != 0 && x != size) {
                        continue;
                    }
                    let p = [0, 1, 2].map(|a| m[a] + d[a]);
                    if self.labels.get(&pack(p)).is_some_and(|v| v.inside != first) {
                        return true;
                    }
                }
            }
        }
        false
    }

    /// Whether the 8 corners of the cell `(level, m)` (all classified) differ.
    pub fn corners_mixed(&self, level: u32, m: Corner) -> bool {
        let size = 1u32 << level;
        let first = self.label(m);
        (1..8).any(|b| self.label(offset(m, b, size)) != first)
    }
}

/// Corner `b` (bit 0: x, bit 1: y, bit 2: z) of the cell with minimum `m` and edge `size`.
pub fn offset(m: Corner, b: usize, size: u32) -> Corner {
    [0, 1, 2].map(|a| m[a] + if b >> a & 1 == 1 { size } else { 0 })
}

/// Whether a triangle of `guide` meets the closed box of the cell `(level, m)`.
fn touched(guide: Option<&SegmentBvh>, lattice: &Lattice, level: u32, m: Corner) -> bool {
    let Some(guide) = guide else {
        return false;
    };
    let size = 1u32 << level;
    let lo = lattice.corner_position(m);
    let hi = lattice.corner_position(m.map(|x| x + size));
    // The pad only has to outgrow the rounding of the test (relative 1e-16 of coordinates at
    // most MAX_RESOLUTION cells from the box); a millionth of a cell does, and a triangle that
    // close to the box costs one needless split at worst.
    let scale = (0..3).fold(0.0f64, |s, a| s.max(lo[a].abs()).max(hi[a].abs()));
    let pad = 1e-6 * lattice.smallest_cell() + 1e-12 * scale;
    guide.meets_box(lo, hi, pad)
}

/// Why [`classify`] stopped before the end.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Stop {
    /// More than `max_points` lattice points would be classified.
    TooManyPoints,
    /// The deadline passed (checked between split rounds).
    TimeLimit,
}

/// Classifies the lattice (see the [module documentation](self)); [`Stop::TooManyPoints`] as
/// soon as more than `max_points` lattice points would be classified, [`Stop::TimeLimit`]
/// within one chunk of evaluations (4096 points) or one split round's
/// bookkeeping after `deadline`. `guide`: the input triangles, whose cells
/// are refined to the regular level too (and below it where a part is thinner than a cell,
/// when the lattice has [`Lattice::sub_levels`]).
pub fn classify<E: Evaluator + ?Sized>(
    evaluator: &E,
    lattice: &Lattice,
    guide: Option<&SegmentBvh>,
    max_points: usize,
    deadline: Option<std::time::Instant>,
) -> Result<Classified, Stop> {
    assert!(
        lattice.resolution_level() <= MAX_SUB_LEVELS && lattice.planar_levels <= MAX_PLANAR_LEVELS,
        "sub-levels beyond MAX_SUB_LEVELS or planar levels beyond MAX_PLANAR_LEVELS"
    );
    // Each batch stops at the deadline too (a round of a fine lattice is millions of points,
    // seconds of work on an inconsistently oriented input); its NaN answers are discarded by
    // the round's check that follows.
    let evaluator = &super::deadline::Deadlined::new(evaluator, deadline);
    let mut out = Classified::default();
    let levels = lattice.levels;
    let regular = lattice.sub_levels;
    let resolution = lattice.resolution_level();
    let coarse = 1u32 << levels;
    let cc = lattice.coarse_cells();
    // The coarse corners as a grid of cell-centre samples: a box half a coarse cell larger on
    // every side puts the sample centres on the corners.
    let ch = lattice.h.map(|h| h * f64::from(coarse));
    let bounds = crate::base::bounding_box::BoundingBox {
        min: [0, 1, 2].map(|a| lattice.origin[a] - 0.5 * ch[a]),
        max: [0, 1, 2].map(|a| lattice.origin[a] + (cc[a] as f64 + 0.5) * ch[a]),
    };
    let dims = cc.map(|n| n + 1);
    // The lattice is at most MAX_RESOLUTION-ish per axis and the coarse level ~COARSE_TARGET
    // cells: always a valid, small grid.
    let spec = GridSpec { bounds, dims };
    if spec.len() > max_points {
        return Err(Stop::TooManyPoints);
    }
    let values = super::levels::decisive_grid_values(evaluator, &spec);
    for k in 0..dims[2] {
        for j in 0..dims[1] {
            for i in 0..dims[0] {
                let c = [i, j, k].map(|x| x as u32 * coarse);
                let value = if lattice.is_border(c) {
                    CornerValue::BORDER
                } else {
                    CornerValue::of(values[spec.index(i, j, k)])
                };
                out.labels.insert(pack(c), value);
            }
        }
    }
    let coarse_cells: Vec<Corner> = (0..cc[2])
        .flat_map(|k| (0..cc[1]).flat_map(move |j| (0..cc[0]).map(move |i| [i, j, k])))
        .map(|c| c.map(|x| x as u32 * coarse))
        .collect();
    if levels > regular {
        let mut queue: Vec<(u32, Corner)> = coarse_cells
            .iter()
            .filter(|&&m| out.corners_mixed(levels, m))
            .map(|&m| (levels, m))
            .collect();
        // Coarse cells that a triangle meets, whatever their corners say.
        if guide.is_some() {
            queue.par_extend(
                coarse_cells
                    .par_iter()
                    .filter(|&&m| touched(guide, lattice, levels, m))
                    .map(|&m| (levels, m)),
            );
        }
        out.split_rounds(evaluator, lattice, guide, queue, max_points, deadline)?;
    }
    // The cells of the tree at `level` (split or leaves): the children of split cells one level
    // up, or the coarse cells.
    let cells_at = |out: &Classified, level: u32| -> Vec<Corner> {
        if level == levels {
            coarse_cells.clone()
        } else {
            out.children_of_split(level + 1).collect()
        }
    };
    if regular > 0
        && let Some(guide) = guide
    {
        // Parts thinner than a cell: a cell that a triangle crosses (not only touches: the box
        // is shrunk) while its corners agree holds a piece of surface that no corner sees.
        // Split it, level by level down to the finest.
        for level in (1..=regular).rev() {
            if deadline.is_some_and(|at| std::time::Instant::now() > at) {
                return Err(Stop::TimeLimit);
            }
            // Above the resolution's cell: a leaf whose corners differ stays whole only where
            // the input in it is flat (`Classified::flat`), cut to the resolution's cell
            // elsewhere.
            let mut curved: Vec<(u32, Corner)> = Vec::new();
            if level > resolution {
                // `flat` reads the integrality of the corners of these cells: the field's.
                let open: Vec<Corner> = cells_at(&out, level)
                    .into_par_iter()
                    .filter(|&m| {
                        !out.split.contains(&(level, pack(m)))
                            && out.corners_mixed(level, m)
                            && out.corners_integral(level, m).is_none()
                    })
                    .flat_map_iter(|m| out.unsettled_corners(level, m).collect::<Vec<_>>())
                    .collect();
                out.settle(evaluator, lattice, open);
                curved = cells_at(&out, level)
                    .into_par_iter()
                    .filter(|&m| {
                        !out.split.contains(&(level, pack(m)))
                            && out.corners_mixed(level, m)
                            && !out.flat(lattice, guide, level, m)
                    })
                    .map(|m| (level, m))
                    .collect();
                out.split_rounds(
                    evaluator,
                    lattice,
                    Some(guide),
                    curved.clone(),
                    max_points,
                    deadline,
                )?;
            }
            let crossed: Vec<Corner> = cells_at(&out, level)
                .into_par_iter()
                .filter(|&m| {
                    !out.split.contains(&(level, pack(m)))
                        && !out.corners_mixed(level, m)
                        && crosses(guide, lattice, level, m)
                })
                .collect();
            let thin: Vec<(u32, Corner)> = out
                .with_hidden_class(evaluator, lattice, guide, level, crossed)
                .into_iter()
                .map(|m| (level, m))
                .collect();
            let mut split_now: Vec<Corner> = thin.iter().chain(&curved).map(|&(_, m)| m).collect();
            out.split_rounds(evaluator, lattice, Some(guide), thin, max_points, deadline)?;
            // A thin part goes on into cells whose corners do not agree (a plate through a
            // corner of them): a leaf of this level next to a cell just split, where one of
            // the split's new points on their common face or edge has a class that the corners
            // around it do not explain (a regular edge crossed twice, a face pierced between
            // its corners), and that a triangle crosses, is split too, and so on along the
            // part.
            while !split_now.is_empty() {
                let size = 1u32 << level;
                let mut next: Vec<(u32, Corner)> = split_now
                    .par_iter()
                    .flat_map_iter(|&m| {
                        let out = &out;
                        neighbours(lattice, m, size)
                            .filter(move |&n| touches_edge(n, m))
                            .filter(move |&n| {
                                out.leaf(lattice, n) == (level, n)
                                    && out.unexplained_point_between(n, m, level)
                                    && crosses(guide, lattice, level, n)
                            })
                    })
                    .map(|n| (level, n))
                    .collect();
                next.sort_unstable_by_key(|&(l, c)| (l, pack(c)));
                next.dedup();
                split_now = next.iter().map(|&(_, m)| m).collect();
                out.split_rounds(evaluator, lattice, Some(guide), next, max_points, deadline)?;
            }
        }
        // Balance: the cells around a split cell of a level at most the regular one are
        // leaves of its level or split, so that leaves next to each other differ by one level
        // at most (what the transition split of `transition.rs` assumes).
        loop {
            let coarser: Vec<(u32, Corner)> = (1..=regular)
                .flat_map(|level| {
                    let out = &out;
                    cells_at(out, level)
                        .into_iter()
                        .filter(move |&m| out.split.contains(&(level, pack(m))))
                        .flat_map(move |m| neighbours(lattice, m, 1 << level))
                        .map(move |n| (level, out.leaf(lattice, n)))
                        .filter(|&(level, (leaf_level, _))| leaf_level > level)
                        .map(|(_, leaf)| leaf)
                })
                .collect();
            if coarser.is_empty() {
                break;
            }
            out.split_rounds(
                evaluator,
                lattice,
                Some(guide),
                coarser,
                max_points,
                deadline,
            )?;
        }
    }
    // Leaves next to a split cell of their level across a face or an edge get the transition
    // split; the other leaves at or below the regular level the Freudenthal split.
    let mut transition: Vec<(u32, Corner)> = Vec::new();
    let mut leaves: Vec<(u32, Corner)> = Vec::new();
    for level in 0..=regular {
        let cells = if level == 0 && regular == 0 {
            cells_at(&out, 0)
        } else if level == 0 {
            out.children_of_split(1).collect()
        } else {
            cells_at(&out, level)
        };
        for m in cells {
            if level == 0 || !out.split.contains(&(level, pack(m))) {
                leaves.push((level, m));
            } else {
                if level == resolution {
                    out.refined.push(m);
                }
                transition.extend(
                    neighbours(lattice, m, 1 << level)
                        .filter(|&n| touches_edge(n, m) && !out.split.contains(&(level, pack(n))))
                        .map(|n| (level, n)),
                );
            }
        }
    }
    transition.sort_unstable_by_key(|&(l, c)| (l, c[2], c[1], c[0]));
    transition.dedup();
    if deadline.is_some_and(|at| std::time::Instant::now() > at) {
        return Err(Stop::TimeLimit);
    }
    if let Some(guide) = guide {
        out.lend_untouched_transitions(evaluator, lattice, guide, &mut transition);
    }
    if !transition.is_empty() {
        let split = &out.split;
        let is_refined = |level: u32| move |c: Corner| split.contains(&(level, pack(c)));
        let mut fresh: Vec<Corner> = transition
            .iter()
            .flat_map(|&(l, m)| {
                transition::tetrahedra(m, 1 << l, is_refined(l))
                    .into_iter()
                    .flatten()
            })
            .filter(|p| !out.labels.contains_key(&pack(*p)))
            .collect();
        fresh.sort_unstable();
        fresh.dedup();
        if out.labels.len() + fresh.len() > max_points {
            return Err(Stop::TooManyPoints);
        }
        // Cell and face centres: inside leaves at most regular and on faces between two of
        // them, on no larger leaf's closed box, so the octree's invariant is not concerned. A
        // face centre on the lattice's outer faces is declared outside, like every point there.
        let (border, interior): (Vec<Corner>, Vec<Corner>) =
            fresh.into_iter().partition(|&p| lattice.is_border(p));
        let positions: Vec<[f64; 3]> = interior
            .par_iter()
            .map(|&p| lattice.corner_position(p))
            .collect();
        let values = super::levels::decisive_corner_values(evaluator, &positions);
        for (p, w) in interior.iter().zip(values) {
            out.labels.insert(pack(*p), CornerValue::of(w));
        }
        for p in border {
            out.labels.insert(pack(p), CornerValue::BORDER);
        }
        let split = &out.split;
        let is_refined = |level: u32| move |c: Corner| split.contains(&(level, pack(c)));
        transition.retain(|&(l, m)| {
            let first = out.label(m);
            transition::tetrahedra(m, 1 << l, is_refined(l))
                .iter()
                .flatten()
                .any(|&p| out.label(p) != first)
        });
    }
    let transition_set: KeySet<(u32, u64)> =
        transition.iter().map(|&(l, c)| (l, pack(c))).collect();
    let (band, mut fine_band): (Vec<_>, Vec<_>) = leaves
        .into_par_iter()
        .filter(|&(level, m)| {
            !transition_set.contains(&(level, pack(m))) && out.corners_mixed(level, m)
        })
        .partition(|&(level, _)| level == regular);
    let mut band: Vec<Corner> = band.into_iter().map(|(_, m)| m).collect();
    band.sort_unstable_by_key(|c| (c[2], c[1], c[0]));
    fine_band.sort_unstable_by_key(|&(l, c)| (l, c[2], c[1], c[0]));
    out.band = band;
    out.fine_band = fine_band;
    out.transition = transition;
    // Past the deadline some values above may be the deadlined evaluator's NaN.
    if deadline.is_some_and(|at| std::time::Instant::now() > at) {
        return Err(Stop::TimeLimit);
    }
    Ok(out)
}

/// Most sub-levels [`classify`] refines below the regular cells (each level costs up to 19
/// evaluations per cell split, and the finest lattice keeps 21 bits per axis).
pub const MAX_SUB_LEVELS: u32 = 3;

/// Most levels [`classify`] keeps above the resolution's cell where the input is flat
/// ([`Lattice::planar_levels`]).
pub const MAX_PLANAR_LEVELS: u32 = 3;

/// The cells of edge `size` around the cell with minimum `m` (26, fewer at the lattice's
/// border).
fn neighbours(lattice: &Lattice, m: Corner, size: u32) -> impl Iterator<Item = Corner> + '_ {
    (0..27).filter(|&i| i != 13).filter_map(move |i: i64| {
        let d = [i % 3 - 1, i / 3 % 3 - 1, i / 9 - 1];
        let c = [0, 1, 2].map(|a| i64::from(m[a]) + d[a] * i64::from(size));
        (0..3)
            .all(|a| c[a] >= 0 && (c[a] + i64::from(size)) as u64 <= lattice.cells[a] as u64)
            .then(|| c.map(|x| x as u32))
    })
}

/// Whether the cells with minimum corners `n` and `m` (same size, neighbours) share a face or
/// an edge, not only a corner.
fn touches_edge(n: Corner, m: Corner) -> bool {
    (0..3).filter(|&a| n[a] != m[a]).count() <= 2
}

/// Whether a triangle of `guide` meets the open interior of the cell `(level, m)`, shrunk by a
/// millionth of a cell: triangles in its faces, as on CAD models at round coordinates, do not.
fn crosses(guide: &SegmentBvh, lattice: &Lattice, level: u32, m: Corner) -> bool {
    let size = 1u32 << level;
    let lo = lattice.corner_position(m);
    let hi = lattice.corner_position(m.map(|x| x + size));
    guide.meets_box(lo, hi, -1e-6 * lattice.smallest_cell() * f64::from(size))
}

/// How far the input may stray from one plane in a cell above the resolution's that stays
/// whole ([`Classified::flat`]), in resolution cells: the marching tetrahedra of the cell put
/// their vertices on the input, so the surface in it is off the input by about this much, a
/// tenth of what the resolution's own cells may be off by.
pub const PLANAR_TOLERANCE: f64 = 0.1;

/// Most triangles a cell that stays whole may meet: more, and its input is detail worth the
/// resolution's cells (and the flatness test's cost stays bounded).
pub const PLANAR_MAX_TRIANGLES: usize = 32;

/// How close to an integer `w` must be at the corners of a cell that stays whole or lends its
/// class: across a closed input `w` is an integer off the triangles, so the triangles are where
/// it changes; near a hole or an open sheet it is not, and its level set may bend anywhere.
pub const INTEGRAL_W_SLACK: f64 = 1e-3;

/// Triangles probed per cell by [`Classified::with_hidden_class`]: a thin part shows on the
/// first one it has in the cell; more only costs evaluations where nothing is hidden.
const PROBED_TRIANGLES: usize = 4;

/// How far off a triangle [`Classified::with_hidden_class`] probes, in finest cells: far above
/// the rounding of the probe point, far below any part the lattice could resolve.
const PROBE_OFFSET: f64 = 1e-3;

/// How far from ½ `w` must be at the probe of the other class for
/// [`Classified::with_hidden_class`] to call the cell's part thin, and at the unexplained point
/// for the propagation to follow it (`w ≤ ¼` or `w ≥ ¾`): a solid that the input bounds,
/// whose `w` jumps by about one across its faces. Next to an open sheet `w` is near ½ on its
/// inner side, and the level set ½ folds on and off the sheet wherever the sheet bends (a
/// gently wavy sheet makes blisters a fraction of a cell thick all over it); following those
/// below the resolution cost up to 9× the time on open inputs (cgal-ALSTOM_TEST4 0.9 → 8.2 s at
/// two levels, cgal-fold 1.1 → 7.1 s) for a shape that no triangle pins down. Not an
/// integrality test: a closed input with flipped faces (cura-twotrees235x235_generic) has
/// fractional `w` over much of its solid and thin parts worth finding there.
pub const THIN_PART_MARGIN: f64 = 0.25;

impl Classified {
    /// The cells of `cells` (of `level`, corners of one class, crossed by a triangle) in which
    /// `w` has the other class next to a crossing triangle: probed on both sides of up to
    /// [`PROBED_TRIANGLES`] of them, one parallel batch. A cell crossed only by faces with the
    /// same class on both sides (inner faces of overlapping parts, double walls) hides nothing
    /// and is not worth eight children.
    fn with_hidden_class<E: Evaluator + ?Sized>(
        &self,
        evaluator: &E,
        lattice: &Lattice,
        guide: &SegmentBvh,
        level: u32,
        cells: Vec<Corner>,
    ) -> Vec<Corner> {
        let size = 1u32 << level;
        let shrink = 1e-6 * lattice.smallest_cell() * f64::from(size);
        let offset = PROBE_OFFSET * lattice.smallest_cell();
        let probes: Vec<Vec<[f64; 3]>> = cells
            .par_iter()
            .map(|&m| {
                let lo = lattice.corner_position(m).map(|x| x + shrink);
                let hi = lattice
                    .corner_position(m.map(|x| x + size))
                    .map(|x| x - shrink);
                guide
                    .surface_points_in_box(lo, hi, PROBED_TRIANGLES)
                    .into_iter()
                    .flat_map(|(p, n)| {
                        [1.0, -1.0].map(|s| [0, 1, 2].map(|a| p[a] + s * offset * n[a]))
                    })
                    .collect()
            })
            .collect();
        let classes: Vec<bool> = cells
            .iter()
            .zip(&probes)
            .flat_map(|(&m, points)| std::iter::repeat_n(self.label(m), points.len()))
            .collect();
        let flat: Vec<[f64; 3]> = probes.iter().flatten().copied().collect();
        let values = match guide.approximate_winding_number() {
            Some(approximate) if !flat.is_empty() => {
                screened(evaluator, approximate, &flat, &classes)
            }
            _ => super::levels::decisive_values(evaluator, &flat, Comparisons::ThinPart),
        };
        let mut next = 0;
        let mut hidden = Vec::new();
        for (&m, points) in cells.iter().zip(&probes) {
            let found = values[next..next + points.len()]
                .iter()
                .zip(&classes[next..])
                .any(|(&w, &class)| shows_hidden_part(w, class, THIN_PART_MARGIN));
            next += points.len();
            if found {
                hidden.push(m);
            }
        }
        hidden
    }

    /// Whether `w` is within [`INTEGRAL_W_SLACK`] of an integer at the 8 corners of the cell
    /// `(level, m)` (NaN at border corners: no); `None` while a corner that could make it so is
    /// not [`CornerValue::settled`].
    fn corners_integral(&self, level: u32, m: Corner) -> Option<bool> {
        let mut open = false;
        for b in 0..8 {
            let Some(v) = self.labels.get(&pack(offset(m, b, 1 << level))) else {
                return Some(false);
            };
            let w = f64::from(v.w);
            if !v.settled {
                open = true;
            } else if (w - w.round()).abs() > INTEGRAL_W_SLACK || w.is_nan() {
                return Some(false);
            }
        }
        (!open).then_some(true)
    }

    /// The corners of the cell `(level, m)` whose integrality is not settled.
    fn unsettled_corners(&self, level: u32, m: Corner) -> impl Iterator<Item = Corner> + '_ {
        (0..8)
            .map(move |b| offset(m, b, 1 << level))
            .filter(|c| self.labels.get(&pack(*c)).is_some_and(|v| !v.settled))
    }

    /// Asks the field for `w` at `corners` (classified, not settled; any order, repeats
    /// allowed), so that their integrality is the field's. Their class was decided already and
    /// does not change.
    fn settle<E: Evaluator + ?Sized>(
        &mut self,
        evaluator: &E,
        lattice: &Lattice,
        mut corners: Vec<Corner>,
    ) {
        corners.par_sort_unstable_by_key(|&c| pack(c));
        corners.dedup();
        if corners.is_empty() {
            return;
        }
        let positions: Vec<[f64; 3]> = corners
            .par_iter()
            .map(|&c| lattice.corner_position(c))
            .collect();
        for (c, w) in corners.iter().zip(evaluator.eval_batch(&positions)) {
            let value = CornerValue::of((w, true));
            let old = self.labels.insert(pack(*c), value);
            debug_assert!(old.is_some_and(|o| o.inside == value.inside), "{c:?}");
        }
    }

    /// Whether the cell `(level, m)` may stay whole above the resolution's cell: `w` is within
    /// [`INTEGRAL_W_SLACK`] of an integer at its corners, the input triangles meeting its closed
    /// box lie in it within [`PLANAR_TOLERANCE`] of one plane, and that plane separates the
    /// corners' classes (the corners on each side, farther than the tolerance, have one class).
    /// With an integer `w` the triangles are where it changes, so each side of the plane holds
    /// one value and the marching tetrahedra of the cell, whose vertices are placed on the
    /// input, follow the plane; the last condition catches a field whose surface is not the
    /// triangles' (thickened sheets: two planes at `±eps` from one).
    fn flat(&self, lattice: &Lattice, guide: &SegmentBvh, level: u32, m: Corner) -> bool {
        let size = 1u32 << level;
        if self.corners_integral(level, m) != Some(true) {
            return false;
        }
        let lo = lattice.corner_position(m);
        let hi = lattice.corner_position(m.map(|x| x + size));
        let cell = lattice.smallest_cell() * f64::from(lattice.resolution_cell());
        let tolerance = PLANAR_TOLERANCE * cell;
        let Some((n, p0)) = guide.flat_in_box(lo, hi, 1e-6 * cell, tolerance, PLANAR_MAX_TRIANGLES)
        else {
            return false;
        };
        // The class seen on each side: None until a corner there is met.
        let mut side_class = [None; 2];
        (0..8).all(|b| {
            let c = offset(m, b, size);
            let p = lattice.corner_position(c);
            let d: f64 = (0..3).map(|a| n[a] * (p[a] - p0[a])).sum();
            if d.abs() <= tolerance {
                return true;
            }
            let class = self.label(c);
            let seen = &mut side_class[usize::from(d > 0.0)];
            *seen.get_or_insert(class) == class
        })
    }

    /// Takes out of `transition` the leaves that no input triangle touches, whose classified
    /// points on the closed box agree and whose corners' `w` is an integer (within
    /// [`INTEGRAL_W_SLACK`]), and gives the points of their transition split that are not
    /// classified yet (their centre, fanned faces' centres) the leaf's class without evaluating
    /// them: the argument of the octree's invariant (`w` jumps only across the triangles, so it
    /// is constant on a box that none touches) for the leaves at most regular. Such a leaf holds
    /// no surface; around the refined band of a curved input most transition leaves are such.
    /// A lent point is labelled once, so every split that holds it reads one class, and the
    /// surface stays closed whatever the field (a leaf whose lent class would put an inside
    /// point on the lattice's border, which is outside, keeps its transition split).
    fn lend_untouched_transitions<E: Evaluator + ?Sized>(
        &mut self,
        evaluator: &E,
        lattice: &Lattice,
        guide: &SegmentBvh,
        transition: &mut Vec<(u32, Corner)>,
    ) {
        // The field's integrality at the corners of the leaves that pass every other test.
        let this = &*self;
        let open: Vec<Corner> = transition
            .par_iter()
            .filter(|&&(l, m)| {
                this.corners_integral(l, m).is_none()
                    && !this.closed_box_mixed(lattice, l, m)
                    && !touched(Some(guide), lattice, l, m)
            })
            .flat_map_iter(|&(l, m)| this.unsettled_corners(l, m))
            .collect();
        self.settle(evaluator, lattice, open);
        let this = &*self;
        // Per leaf: the points to lend, or `None` to keep its split.
        let lent: Vec<Option<(CornerValue, Vec<Corner>)>> = transition
            .par_iter()
            .map(|&(l, m)| {
                if this.corners_integral(l, m) != Some(true)
                    || this.closed_box_mixed(lattice, l, m)
                    || touched(Some(guide), lattice, l, m)
                {
                    return None;
                }
                let is_refined = |c: Corner| this.split.contains(&(l, pack(c)));
                let points: Vec<Corner> = transition::tetrahedra(m, 1 << l, is_refined)
                    .into_iter()
                    .flatten()
                    .filter(|p| !this.labels.contains_key(&pack(*p)))
                    .collect();
                let value = this.labels[&pack(m)];
                (!value.inside || !points.iter().any(|&p| lattice.is_border(p)))
                    .then_some((value, points))
            })
            .collect();
        let mut kept = Vec::with_capacity(transition.len());
        for (&leaf, lent) in transition.iter().zip(lent) {
            match lent {
                None => kept.push(leaf),
                Some((value, points)) => {
                    for p in points {
                        self.labels.entry(pack(p)).or_insert(value);
                    }
                }
            }
        }
        *transition = kept;
    }

    /// Whether a point of the split cell `m` (of `level`) on the closed box of its neighbour
    /// `n` (same level) has a class that the corners of `n` around it do not explain: an edge's
    /// midpoint of the other class than both ends, a face's centre of the other class than its
    /// four corners.
    fn unexplained_point_between(&self, n: Corner, m: Corner, level: u32) -> bool {
        let half = 1u32 << (level - 1);
        let size = 2 * half;
        let on_n = |p: Corner| (0..3).all(|a| p[a] >= n[a] && p[a] <= n[a] + size);
        for i in 0..27u32 {
            let step = [i % 3, i / 3 % 3, i / 9];
            let p: Corner = std::array::from_fn(|a| m[a] + step[a] * half);
            if !on_n(p) {
                continue;
            }
            let halves: Vec<usize> = (0..3)
                .filter(|&a| !(p[a] - n[a]).is_multiple_of(size))
                .collect();
            if halves.is_empty() || halves.len() == 3 {
                continue;
            }
            let around = (0..1u32 << halves.len()).map(|bits| {
                let mut c = p;
                for (k, &a) in halves.iter().enumerate() {
                    if bits >> k & 1 == 1 {
                        c[a] += half;
                    } else {
                        c[a] -= half;
                    }
                }
                self.label(c)
            });
            let own = self.label(p);
            // The margin last: one more lookup, only for the rare unexplained point.
            if around.clone().all(|x| x != own) && far_from_half(self.value(p), THIN_PART_MARGIN) {
                return true;
            }
        }
        false
    }

    /// The children of the split cells of `level`.
    fn children_of_split(&self, level: u32) -> impl Iterator<Item = Corner> + '_ {
        let half = 1u32 << (level - 1);
        self.split
            .iter()
            .filter(move |&&(l, _)| l == level)
            .flat_map(move |&(_, key)| (0..8).map(move |b| offset(unpack(key), b, half)))
    }

    /// Splits the cells of `queue` and whatever keeps the invariant of the [module
    /// documentation](self): mixed or touched children above the regular level, and leaves
    /// above it that a new point contradicts. [`Stop::TooManyPoints`] past `max_points`,
    /// [`Stop::TimeLimit`] at a round that starts after `deadline`.
    fn split_rounds<E: Evaluator + ?Sized>(
        &mut self,
        evaluator: &E,
        lattice: &Lattice,
        guide: Option<&SegmentBvh>,
        mut queue: Vec<(u32, Corner)>,
        max_points: usize,
        deadline: Option<std::time::Instant>,
    ) -> Result<(), Stop> {
        let regular = lattice.sub_levels;
        let out = self;
        while !queue.is_empty() {
            if deadline.is_some_and(|at| std::time::Instant::now() > at) {
                return Err(Stop::TimeLimit);
            }
            queue.sort_unstable_by_key(|&(l, m)| (l, pack(m)));
            queue.dedup();
            queue.retain(|&(level, m)| level > 0 && !out.split.contains(&(level, pack(m))));
            let cells = std::mem::take(&mut queue);
            // A lower bound on the points this round and the later ones add: each cell split
            // now adds its centre, a point no other cell has, and a cell split above the
            // regular level leaves a cell to split on every level down to it (its children
            // share the new centre, so a mixed closed box has a mixed child; a triangle meeting
            // a box meets a child; a contradicted leaf is mixed), each adding its centre too.
            // Checked before this round's new points are gathered (tens of millions at an
            // absurd `--res`), and again with them below: refusing on it is as certain as
            // refusing at the end, and can come levels earlier.
            let to_come: usize = cells
                .iter()
                .map(|&(level, _)| level.saturating_sub(regular + 1) as usize)
                .sum();
            if out.labels.len() + cells.len() + to_come > max_points {
                return Err(Stop::TooManyPoints);
            }
            // The new corners of the children of every cell split in this round.
            let labels = &out.labels;
            let mut new_points: Vec<Corner> = cells
                .par_iter()
                .flat_map_iter(|&(level, m)| {
                    let half = 1u32 << (level - 1);
                    (0..27u32)
                        .map(move |i| [i % 3, i / 3 % 3, i / 9].map(|d| d * half))
                        .map(move |d| [0, 1, 2].map(|a| m[a] + d[a]))
                })
                .filter(|&p| !labels.contains_key(&pack(p)))
                .collect();
            new_points.par_sort_unstable_by_key(|&p| pack(p));
            new_points.dedup();
            for &(level, m) in &cells {
                out.split.insert((level, pack(m)));
            }
            if out.labels.len() + new_points.len() + to_come > max_points {
                return Err(Stop::TooManyPoints);
            }
            let interior: Vec<Corner> = new_points
                .iter()
                .copied()
                .filter(|&p| !lattice.is_border(p))
                .collect();
            let positions: Vec<[f64; 3]> = interior
                .par_iter()
                .map(|&p| lattice.corner_position(p))
                .collect();
            let values = super::levels::decisive_corner_values(evaluator, &positions);
            // Past the deadline (the evaluations stopped, answering NaN) the rest of the round
            // is not worth doing.
            if deadline.is_some_and(|at| std::time::Instant::now() > at) {
                return Err(Stop::TimeLimit);
            }
            out.labels.reserve(new_points.len());
            for &p in &new_points {
                out.labels.insert(pack(p), CornerValue::BORDER);
            }
            for (p, w) in interior.iter().zip(values) {
                out.labels.insert(pack(*p), CornerValue::of(w));
            }
            // The insertions, and each of the two searches below, are up to a second of a
            // large round: the clock is read between them.
            if deadline.is_some_and(|at| std::time::Instant::now() > at) {
                return Err(Stop::TimeLimit);
            }
            // (2) new children above the regular level whose closed box is mixed or that a
            // triangle meets.
            let reader = &*out;
            queue = cells
                .par_iter()
                .filter(|&&(level, _)| level > regular + 1)
                .flat_map_iter(|&(level, m)| {
                    let half = 1u32 << (level - 1);
                    (0..8).filter_map(move |b| {
                        let child = offset(m, b, half);
                        (reader.closed_box_mixed(lattice, level - 1, child)
                            || touched(guide, lattice, level - 1, child))
                        .then_some((level - 1, child))
                    })
                })
                .collect();
            if deadline.is_some_and(|at| std::time::Instant::now() > at) {
                return Err(Stop::TimeLimit);
            }
            // (3) leaves above the regular level around each new point that it contradicts.
            // (In parallel: the lookups of eight leaves per point were the serial half of a
            // round; the queue is sorted before use.)
            queue.par_extend(new_points.par_iter().flat_map_iter(|&p| {
                let lp = reader.label(p);
                (0..8).filter_map(move |b| {
                    let mut min = [0u32; 3];
                    for a in 0..3 {
                        let back = (b >> a & 1) as u32;
                        if p[a] < back || (p[a] - back) as usize >= lattice.cells[a] {
                            return None;
                        }
                        min[a] = p[a] - back;
                    }
                    let (level, m) = reader.leaf(lattice, min);
                    (level > regular && reader.label(m) != lp).then_some((level, m))
                })
            }));
        }
        Ok(())
    }
}

/// Whether `w` is at least `margin` from ½ (NaN, at border points: no).
fn far_from_half(w: f64, margin: f64) -> bool {
    (w - 0.5).abs() >= margin
}

/// Whether `w` at a probe shows a part hidden in a cell whose corners have class `class`: the
/// other class, at least `margin` from ½.
pub(super) fn shows_hidden_part(w: f64, class: bool, margin: f64) -> bool {
    super::inside(w) != class && far_from_half(w, margin)
}

/// How far the Barnes–Hut approximation may be off `w` at a probe for [`screened`] to pass it
/// on: about 25× the largest error measured at β = 2, order 2 against the direct sum (4.7·10⁻³
/// on cgal-rotor; docs/fast.md, "Accuracy"; next to a triangle its own solid angle is summed
/// exactly), so a probe the field would call a hidden part is not screened out, and half of
/// [`THIN_PART_MARGIN`], so the screen still drops the probes next to sheets and flipped faces
/// (where `w` stays near ½ or on the corners' side). Only refinement reads the probes: were
/// the approximation ever off by more, a thin part would be missed as without sub-cell levels,
/// and every guarantee would still hold.
const SCREEN_SLACK: f64 = 0.125;

/// `w` at `points` as far as [`Classified::with_hidden_class`] needs it: the field (its
/// decisive values, [`super::levels`]) where the approximation shows a hidden part within
/// [`SCREEN_SLACK`], NaN (no part) elsewhere. The
/// exact field costs `O(B)` per point near the surface of an input whose signed boundary has
/// `B` edges (every edge of an inconsistently oriented one: cgal-blobby-shuffled at res 256
/// spent 6.9 s in 300k such probes, none of which found a part); the approximation costs
/// `O(log F)` (0.07 s there).
fn screened<E: Evaluator + ?Sized>(
    evaluator: &E,
    approximate: &crate::eval::fast::FastWindingNumber,
    points: &[[f64; 3]],
    classes: &[bool],
) -> Vec<f64> {
    let rough = approximate.eval_batch(points);
    let open: Vec<usize> = (0..points.len())
        .filter(|&i| shows_hidden_part(rough[i], classes[i], THIN_PART_MARGIN - SCREEN_SLACK))
        .collect();
    let exact = super::levels::decisive_values(
        evaluator,
        &open.iter().map(|&i| points[i]).collect::<Vec<_>>(),
        Comparisons::ThinPart,
    );
    let mut values = vec![f64::NAN; points.len()];
    for (&i, w) in open.iter().zip(exact) {
        values[i] = w;
    }
    values
}

/// Inverse of [`pack`].
pub fn unpack(key: u64) -> Corner {
    let mask = (1u64 << 21) - 1;
    [key & mask, (key >> 21) & mask, (key >> 42) & mask].map(|x| x as u32)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A small xorshift: the trees below need many random choices and no distribution.
    struct Random(u64);

    impl Random {
        fn below(&mut self, n: u64) -> u64 {
            self.0 ^= self.0 << 13;
            self.0 ^= self.0 >> 7;
            self.0 ^= self.0 << 17;
            self.0 % n
        }
    }

    /// Splits the cell `(level, m)` as `classify` does (its 27 points labelled where they were
    /// not), then each child with probability `percent`.
    fn split(out: &mut Classified, random: &mut Random, level: u32, m: Corner, percent: u64) {
        out.split.insert((level, pack(m)));
        let half = 1u32 << (level - 1);
        for i in 0..27u32 {
            let p = [0, 1, 2].map(|a| m[a] + [i % 3, i / 3 % 3, i / 9][a] * half);
            let inside = random.below(40) == 0;
            out.labels
                .entry(pack(p))
                .or_insert(CornerValue::of((f64::from(u8::from(inside)), true)));
        }
        if level > 1 {
            for b in 0..8 {
                if random.below(100) < percent {
                    split(out, random, level - 1, offset(m, b, half), percent);
                }
            }
        }
    }

    #[test]
    fn closed_box_mixed_finds_what_a_scan_of_the_box_finds() {
        // Random trees over 3×2×2 coarse cells of edge 16, with labels mostly of one class so
        // that most boxes agree and a point of the other class deep in a neighbour's subtree
        // is what decides; every unsplit tree cell asked both ways.
        let lattice = Lattice {
            origin: [0.0; 3],
            h: [1.0; 3],
            cells: [48, 32, 32],
            levels: 4,
            sub_levels: 0,
            planar_levels: 0,
        };
        let (mut mixed, mut agreeing) = (0, 0);
        for seed in 1..=60u64 {
            let mut random = Random(seed.wrapping_mul(0x9E37_79B9_7F4A_7C15));
            let mut out = Classified::default();
            for k in 0..=2u32 {
                for j in 0..=2u32 {
                    for i in 0..=3u32 {
                        let inside = random.below(40) == 0;
                        let value = CornerValue::of((f64::from(u8::from(inside)), true));
                        out.labels.insert(pack([i * 16, j * 16, k * 16]), value);
                    }
                }
            }
            let coarse: Vec<Corner> = (0..2u32)
                .flat_map(|k| (0..2u32).flat_map(move |j| (0..3u32).map(move |i| [i, j, k])))
                .map(|c| c.map(|x| x * 16))
                .collect();
            let percent = 20 + seed % 50;
            for &m in &coarse {
                if random.below(100) < 70 {
                    split(&mut out, &mut random, 4, m, percent);
                }
            }
            let mut cells: Vec<(u32, Corner)> = coarse.iter().map(|&m| (4, m)).collect();
            for level in (1..=4).rev() {
                cells.extend(out.children_of_split(level).map(|m| (level - 1, m)));
            }
            for (level, m) in cells {
                if out.split.contains(&(level, pack(m))) {
                    continue;
                }
                let by_scan = out.closed_box_mixed_by_scan(level, m);
                assert_eq!(
                    out.closed_box_mixed(&lattice, level, m),
                    by_scan,
                    "seed {seed}, cell {level} {m:?}"
                );
                if by_scan {
                    mixed += 1;
                } else {
                    agreeing += 1;
                }
            }
        }
        // Both answers common, so the comparison could fail either way.
        assert!(mixed > 1000 && agreeing > 1000, "{mixed} {agreeing}");
    }
}
