//! Plates thinner than a cell: where the input has, across an axis, widespread runs of one class
//! (solid, or a gap between solids) bounded by faces perpendicular to that axis and thinner than
//! a cell, the lattice's cells along that axis get finer (at most
//! [`MAX_PLATE_REFINEMENT`] times, all axes together).
//!
//! Why: a part that holds no lattice point is lost, and the box-extent rule of [`super::lattice`]
//! only sees a plate that is the whole box. A printer bed with a 0.5 mm top plate on 38 mm of
//! ribs (cura-voron0_120_bed) has cells of 0.60 mm across the plate at `res 256`: the plate
//! fell between two lattice planes over most of the bed (1 % of the box's volume lost, a
//! Hausdorff distance of 8 cells). Cells of 0.25 mm across it put a lattice plane inside it
//! everywhere, and its top and bottom are then placed within a tick like every vertex.
//!
//! How it is found: lines along each axis through a [`PROBE_LINES`]² grid of the box (at
//! irrational offsets, off the round coordinates of CAD models) cross the input triangles
//! ([`SegmentBvh`]); `w` is evaluated once between each pair of consecutive crossings, which
//! splits each line into runs of one class. A run bounded on both sides by faces within
//! [`PLATE_COSINE`] of perpendicular to the line is a plate run (an oblique thin part is not: a
//! finer axis would not resolve it). A run thicker than a cell holds a lattice plane wherever
//! it lies; the plate runs thinner than a cell estimate the volume the lattice may lose; where it is at least
//! [`MIN_LOST_FRACTION`] of the box, the cells get finer until their median thickness (weighted
//! by length) is [`CELLS_ACROSS_A_PLATE`] cells, the axis with the most volume at risk first
//! (a bed's top plate, not a single thin rib), and an axis only if the budget left takes its
//! cells below that thickness.
//!
//! Only the lattice's spacing depends on the probe (a rounding error or a missed triangle here
//! gives another lattice, never a wrong label), so every guarantee of the remesher holds
//! whatever it finds; what it costs is band cells on the faces not perpendicular to the refined
//! axis (the side walls of a bed: about the refinement factor times theirs).

use super::crossings::SegmentBvh;
use super::levels::Comparisons;
use crate::base::bounding_box::BoundingBox;
use crate::eval::Evaluator;

/// Probe lines per side of the grid, per axis (`PROBE_LINES²` lines along each axis).
pub const PROBE_LINES: usize = 32;

/// A face bounds a plate run when its unit normal's component along the line is at least this
/// (8°).
pub const PLATE_COSINE: f64 = 0.99;

/// The lattice resolves a plate run this many cells thick: with cells at most half the plate's
/// thickness, every line across the plate meets a lattice plane strictly inside it.
pub const CELLS_ACROSS_A_PLATE: f64 = 2.0;

/// A plate is refined for when the plate runs thinner than a cell along
/// an axis add up to at least this fraction of the box's volume (a tenth of what the remesher's
/// occupancy goal, 99.9 %, allows to lose).
pub const MIN_LOST_FRACTION: f64 = 1e-4;

/// Cells get at most this many times finer for plates, over all axes together (a product:
/// band cells, hence time and memory, grow at most about this much).
pub const MAX_PLATE_REFINEMENT: f64 = 4.0;

/// A refinement is made only if it takes the cell at least this far below its plates'
/// thickness (a plate a hair thicker than a cell can still miss every lattice plane by the
/// rounding of its faces).
const ENOUGH: f64 = 1.1;

/// Two crossings of a line closer than this (relative to the line's length) are one: faces
/// meeting at an edge or a vertex on the line, or duplicated faces.
const SAME_CROSSING: f64 = 1e-9;

/// A crossing of a probe line: its parameter along the line, and whether the face crossed is
/// within [`PLATE_COSINE`] of perpendicular to it.
type Crossing = (f64, bool);

/// What the probe found along each axis.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct PlateProbe {
    /// The thickness of the plate runs thinner than a cell (their median, weighted by length),
    /// world units; `None` where there are none.
    pub thickness: [Option<f64>; 3],
    /// The fraction of the box's volume in those runs (estimated from the probe lines).
    pub thin_fraction: [f64; 3],
    /// How many times finer the cells along each axis get (1: unchanged).
    pub refinement: [f64; 3],
}

impl PlateProbe {
    /// No refinement.
    pub fn none() -> PlateProbe {
        PlateProbe {
            thickness: [None; 3],
            thin_fraction: [0.0; 3],
            refinement: [1.0; 3],
        }
    }

    /// Whether some axis is refined.
    pub fn refines(&self) -> bool {
        self.refinement.iter().any(|&r| r > 1.0)
    }
}

/// The probe along each axis of `bounds`, for a lattice whose cell edges are `h` (see the
/// [module documentation](self)).
pub fn probe<E: Evaluator + ?Sized>(
    evaluator: &E,
    guide: &SegmentBvh,
    bounds: BoundingBox,
    h: [f64; 3],
) -> PlateProbe {
    let mut found = PlateProbe::none();
    if guide.is_empty() {
        return found;
    }
    let mut wanted = [1.0; 3];
    for a in 0..3 {
        // A run thicker than a cell holds a lattice plane wherever it is; a thinner one may fall
        // between two.
        let thin_below = h[a];
        let Some((mut runs, volume)) = plate_runs(evaluator, guide, bounds, a) else {
            continue;
        };
        runs.retain(|&t| t < thin_below);
        let lost: f64 = runs.iter().sum();
        found.thin_fraction[a] = lost / volume;
        if runs.is_empty() {
            continue;
        }
        // The median by length: the thickness of the runs holding half the volume at risk.
        runs.sort_by(f64::total_cmp);
        let mut sum = 0.0;
        let median = runs
            .iter()
            .copied()
            .find(|&t| {
                sum += t;
                sum >= 0.5 * lost
            })
            .unwrap_or(runs[runs.len() - 1]);
        found.thickness[a] = Some(median);
        if found.thin_fraction[a] >= MIN_LOST_FRACTION && median > 0.0 {
            wanted[a] = h[a] / median;
        }
    }
    // The axis with the most volume at risk first, each as far as the product allows, and
    // only if that is enough for a cell thinner than its plates (so that every one holds a
    // lattice plane): a refinement that falls short would cost band cells and still lose them.
    let mut order = [0, 1, 2];
    order.sort_by(|&x, &y| found.thin_fraction[y].total_cmp(&found.thin_fraction[x]));
    let mut left = MAX_PLATE_REFINEMENT;
    for a in order {
        if wanted[a] > 1.0 && wanted[a] * ENOUGH <= left {
            let r = (CELLS_ACROSS_A_PLATE * wanted[a]).min(left);
            found.refinement[a] = r;
            left /= r;
        }
    }
    found
}

/// The lengths (world units) of the plate runs of the probe lines along `axis`, and the volume
/// the lines stand for (lines × the box's extent along `axis`, in the same units: the runs'
/// sum over it is a fraction of the box's volume). `None` for a box flat along `axis`.
fn plate_runs<E: Evaluator + ?Sized>(
    evaluator: &E,
    guide: &SegmentBvh,
    bounds: BoundingBox,
    axis: usize,
) -> Option<(Vec<f64>, f64)> {
    let (b, c) = ((axis + 1) % 3, (axis + 2) % 3);
    let extent = [0, 1, 2].map(|k| bounds.max[k] - bounds.min[k]);
    if !(extent[axis] > 0.0 && extent[axis].is_finite()) {
        return None;
    }
    let pad = 0.01 * extent[axis];
    let (from, to) = (bounds.min[axis] - pad, bounds.max[axis] + pad);
    let length = to - from;
    // Per line: its crossings (sorted, merged) and whether each bounds a plate run.
    let mut lines: Vec<([f64; 3], Vec<Crossing>)> = Vec::new();
    for i in 0..PROBE_LINES {
        for j in 0..PROBE_LINES {
            let mut p = [0.0; 3];
            // Golden-ratio offsets: never a round fraction of the box.
            p[b] = bounds.min[b] + extent[b] * (i as f64 + 0.381_966) / PROBE_LINES as f64;
            p[c] = bounds.min[c] + extent[c] * (j as f64 + 0.618_034) / PROBE_LINES as f64;
            p[axis] = from;
            let mut q = p;
            q[axis] = to;
            let mut hits: Vec<Crossing> = Vec::new();
            guide.for_each_crossing(p, q, |t, tri| hits.push((t, perpendicular(tri, axis))));
            if hits.len() < 2 {
                continue;
            }
            hits.sort_by(|x, y| x.0.total_cmp(&y.0));
            let mut merged: Vec<Crossing> = Vec::with_capacity(hits.len());
            for (t, plate) in hits {
                match merged.last_mut() {
                    Some(last) if t - last.0 <= SAME_CROSSING => last.1 &= plate,
                    _ => merged.push((t, plate)),
                }
            }
            lines.push((p, merged));
        }
    }
    // One evaluation between each pair of consecutive crossings.
    let mut points = Vec::new();
    for (p, crossings) in &lines {
        for pair in crossings.windows(2) {
            let mut m = *p;
            m[axis] = from + length * 0.5 * (pair[0].0 + pair[1].0);
            points.push(m);
        }
    }
    let w = super::levels::decisive_values(evaluator, &points, Comparisons::Class);
    let mut next = 0;
    let mut runs = Vec::new();
    for (_, crossings) in &lines {
        let n = crossings.len() - 1;
        let classes: Vec<bool> = w[next..next + n]
            .iter()
            .map(|&x| super::inside(x))
            .collect();
        next += n;
        runs.extend(
            plate_runs_of_line(crossings, &classes)
                .into_iter()
                .map(|t| t * length),
        );
    }
    Some((runs, (PROBE_LINES * PROBE_LINES) as f64 * extent[axis]))
}

/// The runs (in line parameter) bounded on both sides by plate crossings, of the line whose
/// crossings are `crossings` (sorted) and whose classes between consecutive crossings are
/// `classes`; outside the first and last crossing the line is outside.
fn plate_runs_of_line(crossings: &[Crossing], classes: &[bool]) -> Vec<f64> {
    // Boundaries between runs: crossing `k` where the class changes (outside before the first
    // crossing and after the last).
    let class_before = |k: usize| k > 0 && classes[k - 1];
    let class_after = |k: usize| k < classes.len() && classes[k];
    let boundaries: Vec<usize> = (0..crossings.len())
        .filter(|&k| class_before(k) != class_after(k))
        .collect();
    boundaries
        .windows(2)
        .filter(|pair| crossings[pair[0]].1 && crossings[pair[1]].1)
        .map(|pair| crossings[pair[1]].0 - crossings[pair[0]].0)
        .collect()
}

/// Whether the triangle's unit normal is within [`PLATE_COSINE`] of `axis`.
fn perpendicular(tri: &[[f64; 3]; 3], axis: usize) -> bool {
    super::crossings::unit_normal(tri).is_some_and(|n| n[axis].abs() >= PLATE_COSINE)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn runs_between_class_changes_at_plate_faces() {
        // Crossings at 0.1, 0.2, 0.3, 0.6; inside from 0.1 to 0.3 (two intervals: the 0.2
        // crossing is an inner face), outside from 0.3 to 0.6, whose far side is oblique.
        let crossings = [(0.1, true), (0.2, true), (0.3, true), (0.6, false)];
        let runs = plate_runs_of_line(&crossings, &[true, true, false]);
        assert_eq!(runs.len(), 1);
        assert!((runs[0] - 0.2).abs() < 1e-12);
        // A double wall (w the same on both sides): no run.
        assert!(plate_runs_of_line(&[(0.1, true), (0.1 + 1e-3, true)], &[false]).is_empty());
        // Two solids and the thin gap between them: three runs.
        let gap = [(0.1, true), (0.4, true), (0.41, true), (0.8, true)];
        let runs = plate_runs_of_line(&gap, &[true, false, true]);
        assert_eq!(runs.len(), 3);
        assert!((runs[1] - 0.01).abs() < 1e-12);
    }

    #[test]
    fn perpendicular_faces() {
        let flat = [[0.0, 0.0, 1.0], [1.0, 0.0, 1.0], [0.0, 1.0, 1.0]];
        assert!(perpendicular(&flat, 2) && !perpendicular(&flat, 0));
        let tilted = [[0.0, 0.0, 0.0], [1.0, 0.0, 0.3], [0.0, 1.0, 0.0]];
        assert!(!perpendicular(&tilted, 2));
        let degenerate = [[0.0; 3], [1.0, 0.0, 0.0], [2.0, 0.0, 0.0]];
        assert!(!perpendicular(&degenerate, 2));
    }
}
