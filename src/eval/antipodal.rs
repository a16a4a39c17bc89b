//! The exact Antipodal evaluator: `w(q) = χ(q) + (1/4π) Σ_{(a,b) ∈ ∂M} k·Area(A, B, x1)`
//! (antipodal paper, Eq. 9 / Alg. 1), with
//! - χ the signed number of crossings of one axis-aligned ray from `q_ε` (BVH, `O(log F)`),
//! - the sum over the signed boundary edges (weight `k`) of the spherical-triangle areas, whose
//!   atan2 branch is decided by the same perturbed predicate as the crossings (`O(B)`).
//!
//! Closed (consistently oriented) meshes have no boundary: `w = χ`, an exact integer.
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

use std::marker::PhantomData;
use std::time::{Duration, Instant};

use rayon::prelude::*;

use crate::Mesh;
use crate::bvh::RayBvh;
use crate::kernel::boundary_column::ColumnQuery;
use crate::kernel::boundary_sum::BoundaryEdges;
use crate::kernel::boundary_tree::BoundaryTree;
use crate::kernel::compensated::NeumaierSum;
use crate::kernel::frame::RayAxis;
use crate::kernel::input_predicates::{
    InputPoint, LatticeFrame, input_plane_side, input_projected_containment, input_ray_crossing,
    snapped_plane_side, snapped_projected_containment,
};
use crate::kernel::predicates::{
    W64, W128, Width, far_query_numerator_sign, perturbed_plane_side, projected_containment,
    ray_crossing, ray_crossing_at,
};
use crate::kernel::quantize::{Grid, GridRangeError, Precision, Snap};
use crate::kernel::spherical::{EdgeSigns, antipodal_edge_area, segment_gradient};
use crate::mesh::{boundary_edges, boundary_welded_by};

use crate::kernel::spherical::INV_4PI;

/// Options of the exact evaluator.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Options {
    /// Grid width (default 60 bits with `i128` predicates).
    pub precision: Precision,
    /// Ray direction (default `+z`); any choice gives the same `w` off the surface.
    pub ray: RayAxis,
    /// How boundary edges are matched (default: by position).
    pub boundary: BoundaryBy,
    /// Absolute tolerance on `w` for the far boundary (docs/boundary.md): boundary clusters far
    /// from the query may be replaced by a multipole expansion whose certified error bound, summed
    /// over the query, stays `≤ tolerance` ([`WindingNumber::eval_with_bound`] returns it). The
    /// integer part is never approximated. `0` is the flat exact loop. Default
    /// [`DEFAULT_TOLERANCE`].
    pub tolerance: f64,
}

/// The default [`Options::tolerance`]: the documented error of the exact evaluator stays
/// `≤ 1e-10` (docs/robustness.md); a node is expanded only where that is cheaper than its loop.
pub const DEFAULT_TOLERANCE: f64 = 1e-10;

impl Default for Options {
    fn default() -> Self {
        Options {
            precision: Precision::default(),
            ray: RayAxis::default(),
            boundary: BoundaryBy::default(),
            tolerance: DEFAULT_TOLERANCE,
        }
    }
}

/// Which boundary the Antipodal sum runs over. Both give the same `w` (up to rounding off the
/// surface): opposite edges that are not matched cancel term by term. Matching by position only
/// removes those pairs up front, which is where an open mesh's cost is: a mesh split at UV seams,
/// or an indexed soup, has thousands of index-boundary edges and no geometric boundary at all
/// (closed-mesh speed).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum BoundaryBy {
    /// Edges match when their endpoints have the same *quantized* position — the geometry every
    /// predicate and term of this evaluator computes with, so the cancellation is exact (with
    /// `Bits60` the quantization of a vertex is below `f64` resolution for any coordinate larger
    /// than ~1/64 of the extent, i.e. this is bit-identical welding in practice).
    #[default]
    Position,
    /// Edges match by vertex index (the mesh's own topology; CLI `--no-weld`).
    Index,
}

/// Why an evaluator could not be built.
#[derive(Clone, Debug, PartialEq)]
pub enum BuildError {
    /// The mesh's coordinates span more than `f64` can grid.
    CoordinateRange,
    /// [`Options::tolerance`] is NaN, infinite or negative (the value as written).
    Tolerance(String),
}

impl std::fmt::Display for BuildError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            BuildError::CoordinateRange => {
                write!(
                    f,
                    "mesh coordinates are too large to quantize (extent overflows f64)"
                )
            }
            BuildError::Tolerance(t) => {
                write!(f, "tolerance must be a finite number >= 0, got {t}")
            }
        }
    }
}

impl std::error::Error for BuildError {}

impl From<GridRangeError> for BuildError {
    fn from(_: GridRangeError) -> Self {
        BuildError::CoordinateRange
    }
}

/// The exact winding-number evaluator of one mesh: build once, query from many threads.
///
/// ```
/// use gwn::{Mesh, eval::antipodal::WindingNumber};
/// // A unit cube with its top face (z = 1) removed.
/// let p = [[0.,0.,0.],[1.,0.,0.],[1.,1.,0.],[0.,1.,0.],[0.,0.,1.],[1.,0.,1.],[1.,1.,1.],[0.,1.,1.]];
/// let t = [[0,2,1],[0,3,2],[0,1,5],[0,5,4],[1,2,6],[1,6,5],[2,3,7],[2,7,6],[3,0,4],[3,4,7]];
/// let open_box = Mesh::from_slices(&p, &t)?;
/// let w = WindingNumber::new(&open_box)?;
/// // Seen from the centre, the missing face covers 1/6 of the sphere: w = 5/6.
/// assert!((w.eval([0.5, 0.5, 0.5]) - 5.0 / 6.0).abs() < 1e-14);
/// # Ok::<(), Box<dyn std::error::Error>>(())
/// ```
#[derive(Clone, Debug)]
pub struct WindingNumber {
    core: Dispatch,
    faces: usize,
    boundary: usize,
    precompute: Duration,
    options: Options,
}

#[derive(Clone, Debug)]
enum Dispatch {
    Narrow(FrameEvaluator<W64>),
    Wide(FrameEvaluator<W128>),
}

impl WindingNumber {
    /// Builds the evaluator with default [`Options`] (60-bit grid, ray along `+z`).
    pub fn new(mesh: &Mesh) -> Result<Self, BuildError> {
        Self::with_options(mesh, Options::default())
    }

    /// Builds the evaluator: quantizes the mesh, extracts the signed boundary, builds the BVH.
    /// A NaN, infinite or negative [`Options::tolerance`] is an error.
    pub fn with_options(mesh: &Mesh, options: Options) -> Result<Self, BuildError> {
        if !(options.tolerance.is_finite() && options.tolerance >= 0.0) {
            return Err(BuildError::Tolerance(options.tolerance.to_string()));
        }
        let start = Instant::now();
        let core = match options.precision {
            Precision::Bits30 => Dispatch::Narrow(FrameEvaluator::build(mesh, options)?),
            Precision::Bits60 => Dispatch::Wide(FrameEvaluator::build(mesh, options)?),
        };
        let boundary = match &core {
            Dispatch::Narrow(c) => c.boundary.len(),
            Dispatch::Wide(c) => c.boundary.len(),
        };
        Ok(WindingNumber {
            core,
            faces: mesh.triangles().len(),
            boundary,
            precompute: start.elapsed(),
            options,
        })
    }

    /// Winding number at `q`. NaN if `q` is not finite.
    pub fn eval(&self, q: [f64; 3]) -> f64 {
        let (chi, area) = self.parts(q);
        chi as f64 + area * INV_4PI
    }

    /// Winding number at `q` and a certified bound on its difference from the flat exact loop
    /// (tolerance 0): `0` unless far boundary clusters were expanded ([`Options::tolerance`]),
    /// and never above the tolerance. `(NaN, 0)` if `q` is not finite.
    ///
    /// ```
    /// use gwn::{Mesh, eval::antipodal::{Options, WindingNumber}};
    /// let p = [[0.,0.,0.],[1.,0.,0.],[0.,1.,0.]];
    /// let w = WindingNumber::with_options(&Mesh::from_slices(&p, &[[0, 1, 2]])?,
    ///     Options { tolerance: 1e-6, ..Default::default() })?;
    /// let (value, bound) = w.eval_with_bound([0.2, 0.2, 0.5]);
    /// assert!(bound <= 1e-6 && (value - w.eval([0.2, 0.2, 0.5])).abs() <= bound);
    /// # Ok::<(), Box<dyn std::error::Error>>(())
    /// ```
    pub fn eval_with_bound(&self, q: [f64; 3]) -> (f64, f64) {
        if q.iter().any(|c| !c.is_finite()) {
            return (f64::NAN, 0.0);
        }
        let (chi, area, bound) = match &self.core {
            Dispatch::Narrow(c) => c.parts_with_bound(q),
            Dispatch::Wide(c) => c.parts_with_bound(q),
        };
        (chi as f64 + area * INV_4PI, bound)
    }

    /// Winding numbers at many points, in parallel.
    ///
    /// Runs of consecutive points on one line parallel to the ray (a numpy grid whose last axis is
    /// the ray's, e.g. `np.mgrid[...].reshape(3, -1).T` with the default ray `+z`) are evaluated
    /// as columns ([`WindingNumber::eval_column`]: one crossing traversal per run and the boundary
    /// loop shared), which gives the same bits as point by point.
    pub fn eval_batch(&self, points: &[[f64; 3]]) -> Vec<f64> {
        let axis = self.options.ray.map()[2].0;
        let same_line = |a: &[f64; 3], b: &[f64; 3]| {
            (0..3).all(|k| k == axis || a[k].to_bits() == b[k].to_bits())
        };
        let mut out = vec![0.0; points.len()];
        // Parallel over chunks (a run that crosses a chunk's end is simply split), so no
        // allocation grows with the number of runs; small batches still get several chunks per
        // thread.
        let chunk = (points.len() / (4 * rayon::current_num_threads())).clamp(16, BATCH_CHUNK);
        out.par_chunks_mut(chunk)
            .zip(points.par_chunks(chunk))
            .for_each(|(out, points)| {
                let mut start = 0;
                while start < points.len() {
                    let mut end = start + 1;
                    while end < points.len()
                        && end - start < MAX_RUN
                        && same_line(&points[end - 1], &points[end])
                    {
                        end += 1;
                    }
                    if end - start == 1 {
                        out[start] = self.eval(points[start]);
                    } else {
                        // The column's own coordinate is replaced by each point's (a non-finite
                        // one gives NaN for that point only).
                        let mut q = points[start];
                        q[axis] = 0.0;
                        let ts: Vec<f64> = points[start..end].iter().map(|p| p[axis]).collect();
                        out[start..end].copy_from_slice(&self.eval_column(q, &ts));
                    }
                    start = end;
                }
            });
        out
    }

    /// The two parts of the formula: the signed crossing count χ and the boundary sum
    /// `Σ k·Area` (not yet divided by 4π). `(0, NaN)` for a non-finite query. For a query more
    /// than `2^30` box sizes away, the parts of the point pulled in to that distance
    /// (the kernel's `Grid::pull_in_far`; same `w` to `2^-60`).
    pub fn parts(&self, q: [f64; 3]) -> (i64, f64) {
        if q.iter().any(|c| !c.is_finite()) {
            return (0, f64::NAN);
        }
        match &self.core {
            Dispatch::Narrow(c) => c.parts(q),
            Dispatch::Wide(c) => c.parts(q),
        }
    }

    /// The value split into its integer and fractional parts: `(χ, w − χ)`, with the crossing
    /// count χ of [`WindingNumber::parts`] and the boundary term `Σ k·Area / 4π`, so that
    /// `χ as f64 + fraction` is [`WindingNumber::eval`] to the bit. `(0, NaN)` for a non-finite
    /// query.
    ///
    /// ```
    /// use gwn::{Mesh, eval::antipodal::WindingNumber};
    /// let p = [[0.,0.,0.],[1.,0.,0.],[1.,1.,0.],[0.,1.,0.],[0.,0.,1.],[1.,0.,1.],[1.,1.,1.],[0.,1.,1.]];
    /// let t = [[0,2,1],[0,3,2],[0,1,5],[0,5,4],[1,2,6],[1,6,5],[2,3,7],[2,7,6],[3,0,4],[3,4,7]];
    /// let w = WindingNumber::new(&Mesh::from_slices(&p, &t)?)?;
    /// let (chi, fraction) = w.integer_and_fraction([0.5, 0.5, 0.5]);
    /// assert_eq!(chi as f64 + fraction, w.eval([0.5, 0.5, 0.5]));
    /// assert!((fraction - (5.0 / 6.0 - chi as f64)).abs() < 1e-14);
    /// # Ok::<(), Box<dyn std::error::Error>>(())
    /// ```
    pub fn integer_and_fraction(&self, q: [f64; 3]) -> (i64, f64) {
        let (chi, area) = self.parts(q);
        (chi, area * INV_4PI)
    }

    /// Winding numbers along one line parallel to the ray: at the points `q` with the world
    /// coordinate along the ray axis ([`Options::ray`]) replaced by each `ts[k]`. One BVH
    /// traversal serves the whole column, and each crossing triangle is placed among the points by
    /// a binary search with the same exact perturbed depth test, so the result is identical to
    /// calling [`WindingNumber::eval`] point by point (this is the ray reuse of voxel grids).
    pub fn eval_column(&self, q: [f64; 3], ts: &[f64]) -> Vec<f64> {
        match &self.core {
            Dispatch::Narrow(c) => c.column(q, ts),
            Dispatch::Wide(c) => c.column(q, ts),
        }
    }

    /// Gradient `∇w(q)`: the integer part is locally constant, so only the boundary contributes:
    /// the Biot–Savart sum over the signed boundary edges
    /// (the kernel's `segment_gradient`; better conditioned than the antipodal
    /// paper's Supp. Alg. 3, see there). Not finite on the boundary curve; NaN for a non-finite
    /// query.
    pub fn gradient(&self, q: [f64; 3]) -> [f64; 3] {
        match &self.core {
            Dispatch::Narrow(c) => c.gradient(q),
            Dispatch::Wide(c) => c.gradient(q),
        }
    }

    /// Gradients at many points, in parallel.
    pub fn gradient_batch(&self, points: &[[f64; 3]]) -> Vec<[f64; 3]> {
        points.par_iter().map(|&q| self.gradient(q)).collect()
    }

    /// Number of triangles.
    pub fn face_count(&self) -> usize {
        self.faces
    }

    /// Number of signed boundary edges (the `B` of the `O(B + log F)` cost).
    pub fn boundary_edge_count(&self) -> usize {
        self.boundary
    }

    /// Time spent in [`WindingNumber::new`].
    pub fn precompute_time(&self) -> Duration {
        self.precompute
    }

    /// The options the evaluator was built with.
    pub fn options(&self) -> Options {
        self.options
    }

    /// What snapping the vertices to the lattice lost (`gwn info` reports it). Values never
    /// depend on it: off-lattice vertices are evaluated exactly as given.
    pub fn snapping(&self) -> Snapping {
        match &self.core {
            Dispatch::Narrow(c) => c.snapping,
            Dispatch::Wide(c) => c.snapping,
        }
    }

    /// The quantization grid (world coordinates).
    pub fn grid(&self) -> &Grid {
        match &self.core {
            Dispatch::Narrow(c) => &c.grid,
            Dispatch::Wide(c) => &c.grid,
        }
    }
}

/// Everything in the ray frame: integer vertices, boundary edges as structure of arrays, BVH.
#[derive(Clone, Debug)]
struct FrameEvaluator<W: Width> {
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
    bvh: RayBvh,
    _width: PhantomData<W>,
}

impl<W: Width> FrameEvaluator<W> {
    fn build(mesh: &Mesh, options: Options) -> Result<Self, BuildError> {
        let ray = options.ray;
        let Some(bbox) = mesh.bounding_box() else {
            // No triangles: w = 0 everywhere. A unit grid keeps the code paths uniform.
            let unit = crate::BoundingBox {
                min: [0.0; 3],
                max: [1.0; 3],
            };
            let grid = Grid::new(&unit, W::PRECISION)?;
            return Ok(Self::empty(grid, ray));
        };
        let grid = Grid::new(&bbox, W::PRECISION)?;
        let map = ray.map();
        let lattice = grid.lattice_frame(map);
        let mut inputs: Vec<InputPoint> = mesh
            .positions()
            .iter()
            .map(|&p| grid.input_vertex(p, map))
            .collect();
        let verts: Vec<[i64; 3]> = inputs.iter().map(|p| p.n).collect();
        let snapping = Snapping::of(&inputs, grid.cell_in_world());
        if W::PRECISION == Precision::Bits30 {
            // The 30-bit grid is the documented approximation: it evaluates the snapped mesh.
            inputs
                .iter_mut()
                .for_each(|p| *p = InputPoint::lattice(p.n));
        }
        let tris = mesh.triangles();
        let boundary = match options.boundary {
            // The 60-bit evaluator computes on the input values, so it welds equal input
            // positions (`+ 0.0` identifies −0 with 0); the 30-bit one on the snapped mesh.
            BoundaryBy::Position if W::PRECISION == Precision::Bits60 => {
                let keys: Vec<[u64; 3]> = mesh
                    .positions()
                    .iter()
                    .map(|p| p.map(|c| (c + 0.0).to_bits()))
                    .collect();
                boundary_welded_by(tris, &keys)
            }
            BoundaryBy::Position => boundary_welded_by(tris, &verts),
            BoundaryBy::Index => boundary_edges(mesh),
        };
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
        Ok(FrameEvaluator {
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
            tolerance: options.tolerance,
            tree: std::sync::OnceLock::new(),
            bvh,
            _width: PhantomData,
        })
    }

    fn empty(grid: Grid, ray: RayAxis) -> Self {
        FrameEvaluator {
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
            bvh: RayBvh::default(),
            _width: PhantomData,
        }
    }

    /// Snaps the grid-space query `q` (of the world query `world`) into the frame, axis by axis:
    /// lattice coordinates, the exact residuals (cells), and whether each residual is exact (it
    /// is not where the world → grid scaling underflowed; see [`Grid::kept_exactly`]).
    #[inline(always)]
    fn snap_frame(&self, q: [f64; 3], world: [f64; 3]) -> ([Snap; 3], [f64; 3], [bool; 3]) {
        // Written out (not `array::map`): the closure version was not inlined into the hot path.
        let [m0, m1, m2] = self.ray.map();
        let (s0, r0, e0) = self.snap_axis(q, world, m0);
        let (s1, r1, e1) = self.snap_axis(q, world, m1);
        let (s2, r2, e2) = self.snap_axis(q, world, m2);
        if W::PRECISION == Precision::Bits30 {
            // The 30-bit grid is the documented fast approximation: queries (like vertices) are
            // evaluated at their lattice points, `≤ 1.5e-9·extent` away.
            return ([s0, s1, s2], [0.0; 3], [true; 3]);
        }
        ([s0, s1, s2], [r0, r1, r2], [e0, e1, e2])
    }

    /// One frame axis of [`FrameEvaluator::snap_frame`].
    #[inline(always)]
    fn snap_axis(
        &self,
        q: [f64; 3],
        world: [f64; 3],
        (axis, neg): (usize, bool),
    ) -> (Snap, f64, bool) {
        let (s, r, exact) =
            if q[axis].abs() >= f64::MIN_POSITIVE || self.grid.kept_exactly(world[axis], q[axis]) {
                let (s, r) = self.grid.snap_with_residual(q[axis], axis);
                (s, r, true)
            } else {
                self.grid.snap_underflowed(world[axis], axis)
            };
        if neg {
            (s.negated(), -r, exact)
        } else {
            (s, r, exact)
        }
    }

    /// The parts at a world query (finite).
    fn parts(&self, q: [f64; 3]) -> (i64, f64) {
        let (chi, area, _) = self.parts_with_bound(q);
        (chi, area)
    }

    /// The parts and the bound of the expanded boundary (on `w`) at a world query (finite).
    fn parts_with_bound(&self, q: [f64; 3]) -> (i64, f64, f64) {
        self.parts_in_grid_space(self.grid.pull_in_far(self.grid.to_grid_space(q)), q)
    }

    /// The parts at a grid-space query already pulled in ([`Grid::pull_in_far`]) from the world
    /// query `world`, and the bound.
    fn parts_in_grid_space(&self, q: [f64; 3], world: [f64; 3]) -> (i64, f64, f64) {
        let qf = self.ray.to_frame(q);
        let (snap, residual, exact) = self.snap_frame(q, world);
        let (Snap::In(x), Snap::In(y)) = (snap[0], snap[1]) else {
            let (area, bound) = self.far_boundary_sum(qf);
            return (0, area, bound);
        };
        let limit = self.grid.limit();
        let (z, z_exact) = match snap[2] {
            Snap::In(z) => (z, true),
            Snap::Low => (-limit, false),
            Snap::High => (limit, false),
        };
        let qi = [x, y, z];
        let r = [
            residual[0],
            residual[1],
            if z_exact { residual[2] } else { 0.0 },
        ];
        // A clamped z is the lattice proxy of the query (same crossings, see the module doc).
        let query = InputPoint {
            n: qi,
            r,
            world: self.ray.to_frame(world),
            exact: [exact[0], exact[1], exact[2] || !z_exact],
        };
        let chi = if snap[2] == Snap::High {
            0
        } else {
            self.signed_crossings(&query)
        };
        let (area, bound) = self.boundary_sum(&query, z_exact, qf[2]);
        (chi, area, bound)
    }

    fn column(&self, q: [f64; 3], ts: &[f64]) -> Vec<f64> {
        if q.iter().any(|c| !c.is_finite()) {
            return vec![f64::NAN; ts.len()];
        }
        let axis = self.ray.map()[2].0;
        // Grid-space point of the column at world coordinate `t` (pulled in like `parts`).
        let at = |t: f64| {
            let mut p = q;
            p[axis] = t;
            self.grid.pull_in_far(self.grid.to_grid_space(p))
        };
        let world_at = |t: f64| {
            let mut p = q;
            p[axis] = t;
            p
        };
        let one_by_one = || {
            ts.iter()
                .map(|&t| {
                    if t.is_finite() {
                        let (chi, area, _) = self.parts_in_grid_space(at(t), world_at(t));
                        chi as f64 + area * INV_4PI
                    } else {
                        f64::NAN
                    }
                })
                .collect()
        };
        let (snap, residual, exact) =
            self.snap_frame(self.grid.pull_in_far(self.grid.to_grid_space(q)), q);
        let (Snap::In(x), Snap::In(y)) = (snap[0], snap[1]) else {
            // Beyond the grid across the ray: far queries, one by one.
            return one_by_one();
        };
        if !(exact[0] && exact[1]) {
            // A transverse coordinate the grid scaling could not hold (a tiny coordinate of a
            // huge mesh): the exact query path, point by point.
            return one_by_one();
        }
        // Every point of the column has these lattice x, y and residuals (the pull-in and the
        // snap act axis by axis).
        let (rx, ry) = (residual[0], residual[1]);
        let transverse_residual = rx != 0.0 || ry != 0.0;
        let limit = self.grid.limit();
        // Per finite point: lattice z (clamped when outside the grid along the ray), whether it
        // is exact, the frame z, the residual along z, and whether it lies beyond the grid's top.
        struct Point {
            z: i64,
            z_exact: bool,
            qz: f64,
            rz: f64,
            high: bool,
            /// The world value, for the exact path when the residual along z is not exact.
            world: [f64; 3],
            rz_exact: bool,
        }
        let points: Vec<Option<Point>> = ts
            .iter()
            .map(|&t| {
                if !t.is_finite() {
                    return None;
                }
                let p = at(t);
                let qz = self.ray.to_frame(p)[2];
                let (snap, residual, exact) = self.snap_frame(p, world_at(t));
                let (z, z_exact, rz, high) = match snap[2] {
                    Snap::In(z) => (z, true, residual[2], false),
                    Snap::Low => (-limit, false, 0.0, false),
                    Snap::High => (limit, false, 0.0, true),
                };
                Some(Point {
                    z,
                    z_exact,
                    qz,
                    rz,
                    high,
                    world: world_at(t),
                    rz_exact: exact[2] || !z_exact,
                })
            })
            .collect();
        // χ. Lattice points share one traversal (below); points off the lattice take their own.
        let shared = |p: &Point| !transverse_residual && p.rz == 0.0 && p.rz_exact;
        let frame_world = |p: &Point| self.ray.to_frame(p.world);
        let input_point = |p: &Point| InputPoint {
            n: [x, y, p.z],
            r: [rx, ry, p.rz],
            world: frame_world(p),
            exact: [true, true, p.rz_exact],
        };
        let mut chis = vec![0i64; ts.len()];
        for (chi, p) in chis.iter_mut().zip(&points) {
            if let Some(p) = p.as_ref().filter(|p| !shared(p) && !p.high) {
                *chi = self.signed_crossings(&input_point(p));
            }
        }
        let mut order: Vec<usize> = (0..ts.len())
            .filter(|&k| points[k].as_ref().is_some_and(&shared))
            .collect();
        order.sort_by_key(|&k| points[k].as_ref().map_or(0, |p| p.z));
        let at_k = |j: usize| points[order[j]].as_ref().expect("finite");
        // Points strictly above the grid never see a crossing.
        let active = (0..order.len())
            .take_while(|&j| at_k(j).z < limit || at_k(j).z_exact)
            .count();
        if active > 0 {
            // chi_diff[j]: change of χ between sorted points j−1 and j.
            let mut chi_diff = vec![0i64; active + 1];
            let u = |v: i64| (v as f64 * self.to_unit) as f32;
            self.bvh
                .for_each_on_ray(u(x), u(y), f32::NEG_INFINITY, |f| {
                    let p = self.tri_pts[f as usize];
                    let input = self.input_triangle(f as usize);
                    let s = match input {
                        Some(t) => input_projected_containment(
                            &InputPoint::lattice([x, y, 0]),
                            t,
                            &self.lattice,
                        ),
                        None => projected_containment::<W>([x, y], p),
                    };
                    if s == 0 {
                        return;
                    }
                    // Hit for the sorted points strictly below the plane: a prefix (the plane side is
                    // monotone in z for a triangle whose projection contains the column).
                    let below = |j: usize| {
                        let z = at_k(j).z;
                        let side = match input {
                            Some(t) => {
                                input_plane_side(&InputPoint::lattice([x, y, z]), t, &self.lattice)
                            }
                            None => perturbed_plane_side::<W>([x, y, z], p),
                        };
                        side == -s
                    };
                    let (mut lo, mut hi) = (0, active);
                    while lo < hi {
                        let mid = (lo + hi) / 2;
                        if below(mid) {
                            lo = mid + 1;
                        } else {
                            hi = mid;
                        }
                    }
                    chi_diff[0] += i64::from(s);
                    chi_diff[lo] -= i64::from(s);
                });
            let mut chi = 0i64;
            for (j, &k) in order.iter().take(active).enumerate() {
                chi += chi_diff[j];
                chis[k] = chi;
            }
        }
        // The boundary term: the points whose `boundary_sum` is the flat loop go through the
        // column loop together (shared x, y work, bit-identical values), the others one by one.
        let mut batch: Vec<(usize, ColumnQuery)> = Vec::new();
        let mut out = vec![f64::NAN; ts.len()];
        for (k, p) in points.iter().enumerate() {
            let Some(p) = p else { continue };
            let qi = [x, y, p.z];
            let r = [rx, ry, if p.z_exact { p.rz } else { 0.0 }];
            let qz_units = (p.qz - self.origin[2]) / self.cell;
            let flat = p.rz_exact
                && !self.boundary.needs_accurate_sum::<W>(qi, r, p.z_exact)
                && self
                    .tree()
                    .is_none_or(|t| t.is_flat_at(&self.boundary, qi, p.z_exact, qz_units));
            if flat {
                let query = ColumnQuery {
                    z: p.z,
                    z_exact: p.z_exact,
                    qz_units,
                    r,
                };
                batch.push((k, query));
            } else {
                let area = self.boundary_sum(&input_point(p), p.z_exact, p.qz).0;
                out[k] = chis[k] as f64 + area * INV_4PI;
            }
        }
        let queries: Vec<ColumnQuery> = batch.iter().map(|&(_, c)| c).collect();
        let mut areas = vec![0.0; queries.len()];
        self.boundary
            .column_area_sums::<W>([x, y], &queries, &mut areas);
        for (&(k, _), area) in batch.iter().zip(areas) {
            out[k] = chis[k] as f64 + area * INV_4PI;
        }
        out
    }

    /// χ: signed crossings of the ray from the exact query `q_ε` along `+z` (every candidate, no
    /// early exit). The candidates of a query off the lattice are its lattice point's (a box
    /// containing `n + r` contains `n`, by monotone rounding; boxes of triangles off the lattice
    /// carry one cell of margin). Each triangle is decided by the lattice predicates when the
    /// lattice holds it and the query exactly, otherwise on the exact inputs.
    #[inline(always)]
    fn signed_crossings(&self, q: &InputPoint) -> i64 {
        let (qi, r) = (q.n, q.r);
        let residual_exact = q.exact[0] && q.exact[1] && q.exact[2];
        let on_lattice = residual_exact && r[0] == 0.0 && r[1] == 0.0 && r[2] == 0.0;
        let mut chi = 0i64;
        let u = |v: i64| (v as f64 * self.to_unit) as f32;
        let (x, y, z) = (u(qi[0]), u(qi[1]), u(qi[2]));
        // Separate loops, so that a mesh the lattice holds runs the lattice loop unchanged.
        if self.tri_input.is_empty() && on_lattice {
            self.bvh.for_each_on_ray(x, y, z, |f| {
                chi += i64::from(ray_crossing::<W>(qi, self.tri_pts[f as usize]));
            });
        } else if self.tri_input.is_empty() && residual_exact {
            self.bvh.for_each_on_ray(x, y, z, |f| {
                chi += i64::from(ray_crossing_at::<W>(qi, r, self.tri_pts[f as usize]));
            });
        } else {
            self.bvh.for_each_on_ray(x, y, z, |f| {
                let f = f as usize;
                let p = self.tri_pts[f];
                let c = match self.input_triangle_index(f) {
                    // Triangles off the lattice: the lattice points with the snapping slack
                    // first (the common case), the exact points only when that cannot decide.
                    Some(i) => match snapped_projected_containment([qi[0], qi[1]], &p) {
                        Some(0) => 0,
                        Some(s0) => match snapped_plane_side(qi, &p) {
                            Some(side) => i32::from(side == -s0) * s0,
                            None => input_ray_crossing(q, &self.input_tris[i], &self.lattice),
                        },
                        None => input_ray_crossing(q, &self.input_tris[i], &self.lattice),
                    },
                    None if !residual_exact => {
                        input_ray_crossing(q, &p.map(InputPoint::lattice), &self.lattice)
                    }
                    None if on_lattice => ray_crossing::<W>(qi, p),
                    None => ray_crossing_at::<W>(qi, r, p),
                };
                chi += i64::from(c);
            });
        }
        chi
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

    /// `Σ k·Area(A, B, x1)` with exact branch signs at the query `qi + r` (lattice point and
    /// residual), and the bound (on `w`) of its expanded far part. `z_exact` is false when the
    /// query's frame z lies outside the grid (then `qz` is used in floating point for the
    /// magnitudes). Queries near a boundary edge, or whose residual matters for a sign, take the
    /// double-double path, never the hierarchy.
    fn boundary_sum(&self, q: &InputPoint, z_exact: bool, qz: f64) -> (f64, f64) {
        let qz_units = (qz - self.origin[2]) / self.cell;
        let (qi, r) = (q.n, q.r);
        // A residual the grid scaling could not hold: every edge on the exact inputs.
        if !self.boundary.is_empty()
            && (!q.residual_exact() || self.boundary.needs_accurate_sum::<W>(qi, r, z_exact))
        {
            let area = self.boundary.area_sum_accurate::<W>(q, z_exact, qz_units);
            return (area, 0.0);
        }
        match self.tree() {
            Some(tree) => {
                let sum = tree.area_sum::<W>(&self.boundary, qi, r, z_exact, qz_units);
                (sum.area, sum.bound)
            }
            None => (self.boundary.area_sum::<W>(qi, r, z_exact, qz_units), 0.0),
        }
    }

    /// The boundary hierarchy, built on first use.
    fn tree(&self) -> Option<&BoundaryTree> {
        self.tree
            .get_or_init(|| BoundaryTree::build(&self.boundary, self.tolerance))
            .as_ref()
    }

    /// Boundary sum for a query whose ray cannot approach the mesh: plain floating point (and
    /// the hierarchy, whose every node the ray misses).
    fn far_boundary_sum(&self, qf: [f64; 3]) -> (f64, f64) {
        let term = |a: [i64; 3], b: [i64; 3]| {
            let ra = self.rel_f64(a, qf);
            let rb = self.rel_f64(b, qf);
            let signs = EdgeSigns {
                numerator: far_query_numerator_sign(ra, rb),
                query_inside_segment: false,
            };
            antipodal_edge_area(ra, rb, signs)
        };
        let limit = self.boundary.limit();
        let q = std::array::from_fn(|k| (qf[k] - self.origin[k]) / self.cell / limit);
        let Some(tree) = self.tree().filter(|t| t.reaches(q)) else {
            let mut sum = 0.0;
            for i in 0..self.boundary.len() {
                let (a, b, weight) = self.boundary.edge(i);
                sum += weight * term(a, b);
            }
            return (sum, 0.0);
        };
        let mut exact_sum = 0.0;
        let mut exact = |range: std::ops::Range<usize>| {
            for j in range {
                if let Some(e) = self.boundary.slot_edge(j) {
                    let (a, b, _) = self.boundary.edge(e);
                    exact_sum += term(a, b);
                }
            }
        };
        let mut spokes = 0.0;
        let mut spoke = |p: [i64; 3], v: [i64; 3], m: i32| spokes -= f64::from(m) * term(p, v);
        let sum = tree.traverse(q, |_, _| true, &mut exact, &mut spoke);
        let mut area = sum.area + exact_sum + spokes;
        for e in self.boundary.heavy_edges() {
            let (a, b, weight) = self.boundary.edge(e);
            area += weight * term(a, b);
        }
        (area, sum.bound)
    }

    #[inline]
    fn rel_f64(&self, p: [i64; 3], qf: [f64; 3]) -> [f64; 3] {
        std::array::from_fn(|k| (p[k] as f64 * self.cell + self.origin[k]) - qf[k])
    }

    fn gradient(&self, q: [f64; 3]) -> [f64; 3] {
        if q.iter().any(|c| !c.is_finite()) {
            return [f64::NAN; 3];
        }
        let qg = self.grid.to_grid_space(q);
        if qg.iter().any(|c| !c.is_finite()) {
            // Beyond `f64::MAX` in grid space (extent ≥ 1): the world gradient is below
            // `1e-616 / extent`, i.e. it underflows.
            return [0.0; 3];
        }
        let qf = self.ray.to_frame(qg);
        // ∇w is homogeneous of degree −1 in lengths: evaluate on offsets scaled by an exact power
        // of two that brings them to ~1 and scale back, so queries at 1e300 neither overflow
        // |r|² nor turn into NaN (the true gradient there underflows to 0).
        let half_width = self.grid.limit() as f64 * self.cell;
        let span = (0..3).fold(half_width, |m, k| {
            m.max((0.5 * qf[k] - 0.5 * self.origin[k]).abs())
        });
        let exponent = (span.to_bits() >> 52) & 0x7ff;
        let scale = f64::from_bits((2046 - exponent) << 52);
        let mut g = [NeumaierSum::new(); 3];
        for i in 0..self.boundary.len() {
            let (a, b, weight) = self.boundary.edge(i);
            let ra = self.rel_f64(a, qf).map(|v| v * scale);
            let rb = self.rel_f64(b, qf).map(|v| v * scale);
            let e = segment_gradient(ra, rb);
            for k in 0..3 {
                g[k].add(weight * e[k]);
            }
        }
        let g = self.ray.to_world(g.map(|s| s.value() * scale * INV_4PI));
        self.grid.gradient_to_world(g)
    }
}
/// `tri_input` of a triangle whose corners are all on the lattice.
const ON_LATTICE: u32 = u32::MAX;

/// What snapping the mesh's vertices to the lattice lost ([`WindingNumber::snapping`]). The
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
    fn of(inputs: &[InputPoint], cell: f64) -> Snapping {
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

    /// The snapping of `mesh`'s vertices to the default (60-bit) lattice, without building an
    /// evaluator (what `gwn info` prints). `None` for an empty mesh or coordinates the grid
    /// cannot hold.
    pub fn of_mesh(mesh: &Mesh) -> Option<Snapping> {
        let grid = Grid::new(&mesh.bounding_box()?, Precision::Bits60).ok()?;
        let map = RayAxis::PosZ.map();
        let inputs: Vec<InputPoint> = mesh
            .positions()
            .iter()
            .map(|&p| grid.input_vertex(p, map))
            .collect();
        Some(Snapping::of(&inputs, grid.cell_in_world()))
    }

    /// Whether every vertex lies on the lattice (the mesh snapped without loss).
    pub fn lossless(&self) -> bool {
        self.off_lattice == 0
    }
}

/// The longest run [`WindingNumber::eval_batch`] evaluates as one column.
const MAX_RUN: usize = 256;

/// The most points per parallel task of [`WindingNumber::eval_batch`].
const BATCH_CHUNK: usize = 1024;
