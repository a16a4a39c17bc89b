//! The exact query: a mesh's quantized triangles and signed boundary in one ray frame, with the
//! ray BVH beside them, answering the two parts of the Antipodal formula (antipodal paper, Eq. 9 /
//! Alg. 1) at a world query:
//! - χ, the signed crossings of the axis-aligned ray from the perturbed query `q_ε`
//!   (`crossings.rs`);
//! - `Σ k·Area(A, B, x1)` over the signed boundary edges, its atan2 branches decided by the same
//!   perturbed predicate (`boundary.rs`).
//!
//! Everything that decides a sign on the way from a world query to `perturbed_orient2d` is in this
//! folder: the per-point snap and the query clamp (`snap.rs`), the crossings, the boundary sums,
//! and the column of queries sharing one ray (`column.rs`). The evaluator above
//! (`eval::antipodal`) hands in already-quantized vertices and the boundary list, and keeps only
//! options and batch dispatch.
//!
//! **On-surface semantics.** A query on the surface (face, edge, vertex, boundary) gets the value
//! at the symbolically perturbed point `q + (ε1, ε2, ε3)`, `ε3 ≪ ε2 ≪ ε1`, along the axes of the
//! ray frame ([`RayAxis`]); with the default ray `+z` that is the side towards `+x` (then `+y`,
//! then `+z`). For a closed mesh a query on a face thus returns 0 or 1 (an integer), never 1/2.
//!
//! **Query clamp.** Queries inside the padded box (the mesh's bounding box grown by its extent on
//! every side) are snapped to the 60-bit (or 30-bit) grid. Outside it, along the ray's transverse
//! axes the ray cannot meet the mesh: χ = 0 and the boundary term is computed in plain `f64`
//! (no branch is near). Beyond the box along the ray χ is 0 (above) or the crossing count of the
//! ray from the box's lower face (below), which is the same set of crossings.

mod boundary;
mod column;
mod crossings;
mod snap;
mod snapping;

pub use snapping::Snapping;

use std::marker::PhantomData;

use crate::base::bounding_box::BoundingBox;
use crate::bvh::RayBvh;
use crate::kernel::boundary_sum::BoundaryEdges;
use crate::kernel::boundary_tree::BoundaryTree;
use crate::kernel::frame::RayAxis;
use crate::kernel::input_predicates::{InputPoint, LatticeFrame};
use crate::kernel::predicates::Width;
use crate::kernel::quantize::{Grid, GridRangeError, Precision};
use crate::kernel::spherical::INV_4PI;

/// One signed boundary edge, by vertex index (the mesh layer's boundary, handed in as plain data
/// so that the kernel imports nothing above it).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct IndexedEdge {
    /// Start vertex.
    pub from: u32,
    /// End vertex.
    pub to: u32,
    /// Net number of traversals `from → to`.
    pub weight: u32,
}

/// The exact index of one mesh in one ray frame: integer vertices, the exact inputs of those off
/// the lattice, the boundary edges as structure of arrays, the BVH. Built once, queried from many
/// threads.
#[derive(Clone, Debug)]
pub struct ExactIndex<W: Width> {
    grid: Grid,
    ray: RayAxis,
    /// Grid origin in frame coordinates.
    origin: [f64; 3],
    cell: f64,
    /// Scale from grid integers to normalized BVH coordinates.
    to_unit: f64,
    /// Triangle corners in grid coordinates (frame), in BVH leaf order.
    tri_pts: Vec<[[i64; 3]; 3]>,
    /// Per triangle (leaf order): index into `input_tris` when a corner is off the lattice, else
    /// [`ON_LATTICE`]; empty when every vertex snapped without loss.
    tri_input: Vec<u32>,
    /// The exact corners of the triangles with a corner off the lattice.
    input_tris: Vec<[InputPoint; 3]>,
    /// How exact values are rebuilt from world coordinates (see `kernel::input_predicates`).
    lattice: LatticeFrame,
    /// What the snapping of the vertices lost.
    snapping: Snapping,
    boundary: BoundaryEdges,
    /// Tolerance of the certified hierarchy over `boundary`.
    tolerance: f64,
    /// The hierarchy, built on first use (`None`: tolerance 0, or no node can ever pay). Lazy so
    /// that the evaluator's precompute is the flat loop's: the tree costs up to as much again on
    /// large boundaries (docs/benchmarks.md), paid by the first query instead.
    tree: std::sync::OnceLock<Option<BoundaryTree>>,
    /// Hierarchies at looser tolerances ([`ExactIndex::hierarchy_within`]), built on first use.
    looser: LooserTrees,
    bvh: RayBvh,
    _width: PhantomData<W>,
}

/// `w = χ + (1/4π) Σ k·Area` (antipodal paper, Eq. 9): the winding number of the two parts.
#[inline]
pub fn w_of_parts(chi: i64, area: f64) -> f64 {
    chi as f64 + area * INV_4PI
}

/// `tri_input` of a triangle whose corners are all on the lattice.
const ON_LATTICE: u32 = u32::MAX;

/// The quantized vertices of a mesh, as [`ExactIndex::build`] takes them.
#[derive(Clone, Debug)]
pub struct QuantizedVertices {
    /// The grid of the mesh's bounding box.
    pub grid: Grid,
    /// The frame the vertices are expressed in.
    pub ray: RayAxis,
    /// Each vertex: its lattice point and exact residual (frame coordinates).
    pub inputs: Vec<InputPoint>,
}

impl QuantizedVertices {
    /// Quantizes `positions` (world) on the `precision` grid of `bbox`, in `ray`'s frame.
    pub fn new(
        bbox: &BoundingBox,
        positions: &[[f64; 3]],
        precision: Precision,
        ray: RayAxis,
    ) -> Result<Self, GridRangeError> {
        let grid = Grid::new(bbox, precision)?;
        let map = ray.map();
        let inputs = positions
            .iter()
            .map(|&p| grid.input_vertex(p, map))
            .collect();
        Ok(QuantizedVertices { grid, ray, inputs })
    }

    /// The lattice points (what the 30-bit evaluator computes with, and the keys it welds by).
    pub fn lattice_points(&self) -> Vec<[i64; 3]> {
        self.inputs.iter().map(|p| p.n).collect()
    }
}

impl<W: Width> ExactIndex<W> {
    /// Indexes the triangles `tris` over `vertices` (quantized on a `W::PRECISION` grid) with the
    /// signed `boundary` (edges over the same vertex indices), and the certified hierarchy's
    /// `tolerance` (0: the flat loop).
    pub fn build(
        vertices: QuantizedVertices,
        tris: &[[u32; 3]],
        boundary: &[IndexedEdge],
        tolerance: f64,
    ) -> Self {
        let QuantizedVertices {
            grid,
            ray,
            mut inputs,
        } = vertices;
        debug_assert_eq!(grid.precision(), W::PRECISION);
        let lattice = grid.lattice_frame(ray.map());
        let verts: Vec<[i64; 3]> = inputs.iter().map(|p| p.n).collect();
        let snapping = Snapping::of(&inputs, grid.cell_in_world());
        if W::PRECISION == Precision::Bits30 {
            // The 30-bit grid is the documented approximation: it evaluates the snapped mesh.
            inputs
                .iter_mut()
                .for_each(|p| *p = InputPoint::lattice(p.n));
        }
        let boundary = BoundaryEdges::with_inputs(
            boundary.iter().map(|e| verts[e.from as usize]).collect(),
            boundary.iter().map(|e| verts[e.to as usize]).collect(),
            boundary.iter().map(|e| f64::from(e.weight)).collect(),
            grid.precision().bits(),
            (
                boundary.iter().map(|e| inputs[e.from as usize]).collect(),
                boundary.iter().map(|e| inputs[e.to as usize]).collect(),
            ),
            lattice,
        );
        let off_lattice = |t: &[u32; 3]| t.iter().any(|&i| !inputs[i as usize].on_lattice());
        let to_unit = 1.0 / (1_i64 << (grid.precision().bits() - 1)) as f64;
        let boxes: Vec<([f32; 3], [f32; 3])> = tris
            .iter()
            .map(|t| {
                let p = t.map(|i| verts[i as usize]);
                // A triangle off the lattice lies within half a cell of its lattice corners: one
                // cell of margin keeps the box conservative for every exact query it contains.
                let pad = i64::from(off_lattice(t));
                let lo = std::array::from_fn(|k| {
                    ((p[0][k].min(p[1][k]).min(p[2][k]) - pad) as f64 * to_unit) as f32
                });
                let hi = std::array::from_fn(|k| {
                    ((p[0][k].max(p[1][k]).max(p[2][k]) + pad) as f64 * to_unit) as f32
                });
                (lo, hi)
            })
            .collect();
        let mut bvh = RayBvh::build(&boxes);
        let order = bvh.renumber_in_leaf_order();
        let tri_pts = order
            .iter()
            .map(|&f| tris[f as usize].map(|i| verts[i as usize]))
            .collect();
        let mut input_tris = Vec::new();
        let mut tri_input = Vec::new();
        if inputs.iter().any(|p| !p.on_lattice()) {
            tri_input = order
                .iter()
                .map(|&f| {
                    let t = &tris[f as usize];
                    if off_lattice(t) {
                        input_tris.push(t.map(|i| inputs[i as usize]));
                        (input_tris.len() - 1) as u32
                    } else {
                        ON_LATTICE
                    }
                })
                .collect();
        }
        ExactIndex {
            tri_input,
            input_tris,
            lattice,
            snapping,
            origin: ray.to_frame(grid.origin()),
            cell: grid.cell(),
            grid,
            ray,
            to_unit,
            tri_pts,
            boundary,
            tolerance,
            tree: std::sync::OnceLock::new(),
            looser: LooserTrees::default(),
            bvh,
            _width: PhantomData,
        }
    }

    /// The index of a mesh without triangles (`w = 0` everywhere), on a unit grid that keeps the
    /// code paths uniform.
    pub fn empty(ray: RayAxis) -> Result<Self, GridRangeError> {
        let unit = BoundingBox {
            min: [0.0; 3],
            max: [1.0; 3],
        };
        let grid = Grid::new(&unit, W::PRECISION)?;
        Ok(ExactIndex {
            origin: ray.to_frame(grid.origin()),
            cell: grid.cell(),
            grid,
            ray,
            to_unit: 1.0,
            tri_pts: Vec::new(),
            tri_input: Vec::new(),
            input_tris: Vec::new(),
            lattice: LatticeFrame::default(),
            snapping: Snapping::default(),
            boundary: BoundaryEdges::default(),
            tolerance: 0.0,
            tree: std::sync::OnceLock::new(),
            looser: LooserTrees::default(),
            bvh: RayBvh::default(),
            _width: PhantomData,
        })
    }

    /// The parts at a finite world query: χ and `Σ k·Area` (not yet divided by 4π).
    pub fn parts(&self, q: [f64; 3]) -> (i64, f64) {
        let (chi, area, _) = self.parts_with_bound(q);
        (chi, area)
    }

    /// The parts and the bound of the expanded boundary (on `w`) at a finite world query.
    pub fn parts_with_bound(&self, q: [f64; 3]) -> (i64, f64, f64) {
        self.parts_with_bound_using(q, self.tree())
    }

    /// [`ExactIndex::parts_with_bound`] with the boundary hierarchy `tree` (one of
    /// [`ExactIndex::hierarchy_within`]; `None`: the flat loop).
    pub fn parts_with_bound_using(
        &self,
        q: [f64; 3],
        tree: Option<&BoundaryTree>,
    ) -> (i64, f64, f64) {
        self.parts_in_grid_space(self.grid.pull_in_far(self.grid.in_grid_space(q)), q, tree)
    }

    /// The boundary hierarchy at `tolerance` (absolute, on `w`): the evaluator's own when
    /// `tolerance` is its tolerance, else one built on first use for that tolerance and kept
    /// (the last [`LOOSER_TREES`] of them). `None` inside: no node could ever pay.
    pub fn hierarchy_within(&self, tolerance: f64) -> Hierarchy<'_> {
        if tolerance.to_bits() == self.tolerance.to_bits() {
            return Hierarchy::Own(self.tree());
        }
        Hierarchy::Looser(
            self.looser
                .get_or_build(tolerance, || BoundaryTree::build(&self.boundary, tolerance)),
        )
    }

    /// What snapping the vertices to the lattice lost.
    pub fn snapping(&self) -> Snapping {
        self.snapping
    }

    /// Number of signed boundary edges.
    pub fn boundary_len(&self) -> usize {
        self.boundary.len()
    }

    /// The exact corners of triangle `f` (leaf order) when one is off the lattice.
    #[inline]
    fn input_triangle(&self, f: usize) -> Option<&[InputPoint; 3]> {
        self.input_triangle_index(f).map(|i| &self.input_tris[i])
    }

    /// The index into `input_tris` of triangle `f` (leaf order) when a corner is off the lattice.
    #[inline(always)]
    fn input_triangle_index(&self, f: usize) -> Option<usize> {
        match self.tri_input.get(f) {
            Some(&i) if i != ON_LATTICE => Some(i as usize),
            _ => None,
        }
    }

    /// Normalized BVH coordinate of a lattice coordinate.
    #[inline(always)]
    fn unit(&self, v: i64) -> f32 {
        (v as f64 * self.to_unit) as f32
    }

    /// The boundary hierarchy at the evaluator's tolerance, built on first use.
    fn tree(&self) -> Option<&BoundaryTree> {
        self.tree
            .get_or_init(|| BoundaryTree::build(&self.boundary, self.tolerance))
            .as_ref()
    }
}

/// A boundary hierarchy of [`ExactIndex::hierarchy_within`], held for a batch of queries.
pub enum Hierarchy<'a> {
    /// The index's own (at its tolerance).
    Own(Option<&'a BoundaryTree>),
    /// One at another tolerance.
    Looser(std::sync::Arc<Option<BoundaryTree>>),
}

impl Hierarchy<'_> {
    /// The tree (`None`: no node can pay, the flat loop).
    pub fn tree(&self) -> Option<&BoundaryTree> {
        match self {
            Hierarchy::Own(tree) => *tree,
            Hierarchy::Looser(tree) => tree.as_ref().as_ref(),
        }
    }
}

/// How many hierarchies at other tolerances an index keeps ([`ExactIndex::hierarchy_within`]):
/// a caller alternating between more tolerances rebuilds, but memory stays bounded.
pub const LOOSER_TREES: usize = 2;

/// The hierarchies an index built at tolerances other than its own, newest last.
#[derive(Default)]
struct LooserTrees(std::sync::Mutex<Vec<(u64, std::sync::Arc<Option<BoundaryTree>>)>>);

impl LooserTrees {
    /// The hierarchy at `tolerance`, built by `build` (under the lock: concurrent callers wait
    /// for one build instead of repeating it; the build runs on scoped threads, not rayon's, so
    /// a waiting rayon worker cannot be asked to help it) when not kept.
    fn get_or_build(
        &self,
        tolerance: f64,
        build: impl FnOnce() -> Option<BoundaryTree>,
    ) -> std::sync::Arc<Option<BoundaryTree>> {
        let mut kept = self.0.lock().unwrap_or_else(|e| e.into_inner());
        let key = tolerance.to_bits();
        if let Some((_, tree)) = kept.iter().find(|(k, _)| *k == key) {
            return tree.clone();
        }
        let tree = std::sync::Arc::new(build());
        if kept.len() >= LOOSER_TREES {
            kept.remove(0);
        }
        kept.push((key, tree.clone()));
        tree
    }
}

impl Clone for LooserTrees {
    fn clone(&self) -> Self {
        LooserTrees(std::sync::Mutex::new(
            self.0.lock().unwrap_or_else(|e| e.into_inner()).clone(),
        ))
    }
}

impl std::fmt::Debug for LooserTrees {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let kept = self.0.lock().unwrap_or_else(|e| e.into_inner());
        f.debug_list()
            .entries(kept.iter().map(|(k, _)| f64::from_bits(*k)))
            .finish()
    }
}
