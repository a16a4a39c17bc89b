//! What snapping a mesh's vertices to the lattice lost.

use crate::base::bounding_box::BoundingBox;
use crate::kernel::frame::RayAxis;
use crate::kernel::input_predicates::InputPoint;
use crate::kernel::quantize::Precision;

use super::QuantizedVertices;

/// What snapping the mesh's vertices to the lattice lost (`WindingNumber::snapping`). The
/// exact evaluator computes on the input values either way (issue 21); this says how often it
/// needs to: triangles and boundary edges with a vertex off the lattice take the input
/// predicates' filter.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Snapping {
    /// Vertices not on the lattice (their coordinates have bits below the cell).
    pub off_lattice: usize,
    /// The largest distance along one axis from a vertex to its lattice point, in world units
    /// (at most half a cell; 0 when the mesh snapped without loss).
    pub max_displacement: f64,
    /// The lattice's cell in world units.
    pub cell: f64,
}

impl Snapping {
    /// The snapping of the quantized vertices `inputs` on a lattice of `cell` (world units).
    pub(super) fn of(inputs: &[InputPoint], cell: f64) -> Snapping {
        let mut out = Snapping {
            cell,
            ..Snapping::default()
        };
        for p in inputs.iter().filter(|p| !p.on_lattice()) {
            out.off_lattice += 1;
            let r = p.r.iter().fold(0.0_f64, |m, r| m.max(r.abs()));
            // An underflowed residual is within 2^-1000 cells of the true one; report the true
            // bound, half a cell, if it rounded to zero.
            let r = if p.residual_exact() {
                r
            } else {
                r.max(f64::MIN_POSITIVE)
            };
            out.max_displacement = out.max_displacement.max(r * cell);
        }
        out
    }

    /// The snapping of the vertices `positions` (world) to the default (60-bit) lattice of
    /// `bbox`, without building an index. `None` for coordinates the grid cannot hold.
    pub fn of_vertices(bbox: &BoundingBox, positions: &[[f64; 3]]) -> Option<Snapping> {
        let v = QuantizedVertices::new(bbox, positions, Precision::Bits60, RayAxis::PosZ).ok()?;
        Some(Snapping::of(&v.inputs, v.grid.cell_in_world()))
    }

    /// Whether every vertex lies on the lattice (the mesh snapped without loss).
    pub fn lossless(&self) -> bool {
        self.off_lattice == 0
    }
}
