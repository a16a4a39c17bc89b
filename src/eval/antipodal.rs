//! The exact Antipodal evaluator: `w(q) = χ(q) + (1/4π) Σ_{(a,b) ∈ ∂M} k·Area(A, B, x1)`
//! (antipodal paper, Eq. 9 / Alg. 1), with
//! - χ the signed number of crossings of one axis-aligned ray from `q_ε` (BVH, `O(log F)`),
//! - the sum over the signed boundary edges (weight `k`) of the spherical-triangle areas, whose
//!   atan2 branch is decided by the same perturbed predicate as the crossings (`O(B)`).
//!
//! Closed (consistently oriented) meshes have no boundary: `w = χ`, an exact integer.
//!
//! The exact query itself (snapping, the clamp rules, crossings, boundary sums, columns) is the
//! kernel's [`ExactIndex`](crate::kernel::exact_index::ExactIndex), whose documentation states the
//! on-surface semantics (the value at the symbolically perturbed point `q + (ε1, ε2, ε3)` along
//! the ray frame's axes) and the query clamp. This module keeps the options, the
//! [`WindingNumber`] type and batch dispatch.

use std::time::{Duration, Instant};

use rayon::prelude::*;

pub use crate::kernel::exact_index::Snapping;
use crate::kernel::exact_index::{ExactIndex, IndexedEdge, QuantizedVertices, w_of_parts};
use crate::kernel::frame::RayAxis;
use crate::kernel::predicates::{W64, W128, Width};
use crate::kernel::quantize::{GridRangeError, Precision};
use crate::kernel::spherical::INV_4PI;
use crate::mesh::Mesh;
use crate::mesh::{boundary_edges, boundary_welded_by};

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
    /// The parity method's mesh is not closed: `odd_edges` edges (by position, or by index with
    /// [`BoundaryBy::Index`]) have an odd number of faces ([`super::parity::CrossingParity`]).
    NotClosed {
        /// How many.
        odd_edges: usize,
    },
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
            BuildError::NotClosed { odd_edges } => write!(
                f,
                "the parity method needs a closed mesh, but {odd_edges} edges have an odd \
                 number of faces (use the exact method: w > 1/2)"
            ),
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
    Narrow(ExactIndex<W64>),
    Wide(ExactIndex<W128>),
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
        Self::build(mesh, options, true)
    }

    /// The index of `mesh`'s triangles without its boundary: [`WindingNumber::eval`] is then the
    /// signed crossing count χ of the ray alone, an exact integer (what
    /// [`super::parity::CrossingParity`] reduces mod 2). Not a winding number unless the mesh is
    /// closed and consistently oriented.
    pub(crate) fn crossings_only(mesh: &Mesh, options: Options) -> Result<Self, BuildError> {
        Self::build(mesh, options, false)
    }

    /// Quantizes and indexes `mesh`, with its signed boundary unless `with_boundary` is false.
    fn build(mesh: &Mesh, options: Options, with_boundary: bool) -> Result<Self, BuildError> {
        let start = Instant::now();
        let core = match options.precision {
            Precision::Bits30 => Dispatch::Narrow(exact_index(mesh, options, with_boundary)?),
            Precision::Bits60 => Dispatch::Wide(exact_index(mesh, options, with_boundary)?),
        };
        let boundary = match &core {
            Dispatch::Narrow(c) => c.boundary_len(),
            Dispatch::Wide(c) => c.boundary_len(),
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
        w_of_parts(chi, area)
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
        (w_of_parts(chi, area), bound)
    }

    /// Winding numbers at many points, in parallel.
    ///
    /// Runs of consecutive points on one line parallel to the ray (a numpy grid whose last axis is
    /// the ray's, e.g. `np.mgrid[...].reshape(3, -1).T` with the default ray `+z`) are evaluated
    /// as columns ([`WindingNumber::eval_column`]: one crossing traversal per run and the boundary
    /// loop shared), which gives the same bits as point by point.
    pub fn eval_batch(&self, points: &[[f64; 3]]) -> Vec<f64> {
        self.batch(points, |q| self.eval(q), |q, ts| self.eval_column(q, ts))
    }

    /// Winding numbers at many points within `tolerance`, each with a certified bound `b` on
    /// its distance from [`WindingNumber::eval`]'s value: `(v, b)`, `|v − eval(q)| ≤ b ≤
    /// tolerance + Options::tolerance`. Far boundary clusters are replaced by their expansions
    /// at `tolerance` (a second hierarchy, built on first use for that tolerance and kept:
    /// docs/boundary.md), which costs a fraction of the exact loop next to long signed
    /// boundaries, where the evaluator's own tolerance leaves the loop to run. The integer part
    /// is exact as always. A `tolerance` that is not above [`Options::tolerance`] (or NaN)
    /// gives the values of [`WindingNumber::eval_batch`] with bound 0.
    ///
    /// ```
    /// use gwn::{Mesh, eval::antipodal::WindingNumber};
    /// let p = [[0.,0.,0.],[1.,0.,0.],[1.,1.,0.],[0.,1.,0.],[0.,0.,1.],[1.,0.,1.],[1.,1.,1.],[0.,1.,1.]];
    /// let t = [[0,2,1],[0,3,2],[0,1,5],[0,5,4],[1,2,6],[1,6,5],[2,3,7],[2,7,6],[3,0,4],[3,4,7]];
    /// let w = WindingNumber::new(&Mesh::from_slices(&p, &t)?)?;
    /// let q = [[0.5, 0.5, 0.5], [0.5, 0.5, 3.0], [4.0, 0.2, 0.3]];
    /// for ((v, b), exact) in w.eval_batch_within(&q, 1e-3).into_iter().zip(w.eval_batch(&q)) {
    ///     assert!(b <= 1e-3 + 1e-10 && (v - exact).abs() <= b);
    /// }
    /// # Ok::<(), Box<dyn std::error::Error>>(())
    /// ```
    pub fn eval_batch_within(&self, points: &[[f64; 3]], tolerance: f64) -> Vec<(f64, f64)> {
        match &self.core {
            Dispatch::Narrow(c) => self.batch_within(c, points, tolerance),
            Dispatch::Wide(c) => self.batch_within(c, points, tolerance),
        }
    }

    /// [`WindingNumber::eval_batch_within`] on one index.
    fn batch_within<W: Width>(
        &self,
        core: &ExactIndex<W>,
        points: &[[f64; 3]],
        tolerance: f64,
    ) -> Vec<(f64, f64)> {
        let own = self.options.tolerance;
        // (False for a NaN tolerance.)
        let hierarchy = (tolerance > own).then(|| core.hierarchy_within(tolerance));
        let Some(tree) = hierarchy.as_ref().and_then(|h| h.tree()) else {
            // Not looser, or no node pays at `tolerance` (so none at the evaluator's own): the
            // values themselves.
            return self
                .eval_batch(points)
                .into_iter()
                .map(|w| (w, 0.0))
                .collect();
        };
        let tree = Some(tree);
        // The looser sum is within its bound of the flat loop, and `eval` within `own` of it.
        let one = |q: [f64; 3]| {
            if q.iter().any(|c| !c.is_finite()) {
                return (f64::NAN, 0.0);
            }
            let (chi, area, bound) = core.parts_with_bound_using(q, tree);
            (w_of_parts(chi, area), bound + own)
        };
        let column = |q: [f64; 3], ts: &[f64]| {
            core.column_with_bounds(q, ts, tree)
                .into_iter()
                .map(|(w, bound)| (w, bound + own))
                .collect()
        };
        self.batch(points, one, column)
    }

    /// The batch loop of [`WindingNumber::eval_batch`] with the per-point (`one`) and per-column
    /// (`column`) evaluations given.
    fn batch<T: Copy + Default + Send>(
        &self,
        points: &[[f64; 3]],
        one: impl Fn([f64; 3]) -> T + Sync,
        column: impl Fn([f64; 3], &[f64]) -> Vec<T> + Sync,
    ) -> Vec<T> {
        let axis = self.options.ray.map()[2].0;
        let same_line = |a: &[f64; 3], b: &[f64; 3]| {
            (0..3).all(|k| k == axis || a[k].to_bits() == b[k].to_bits())
        };
        let mut out = vec![T::default(); points.len()];
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
                        out[start] = one(points[start]);
                    } else {
                        // The column's own coordinate is replaced by each point's (a non-finite
                        // one gives NaN for that point only).
                        let mut q = points[start];
                        q[axis] = 0.0;
                        let ts: Vec<f64> = points[start..end].iter().map(|p| p[axis]).collect();
                        out[start..end].copy_from_slice(&column(q, &ts));
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
    /// paper's Supp. Alg. 3, see there), within a few `1e-9` relative. Next to an edge's
    /// interior each term takes the cross product of the exact inputs' offsets, so the gradient
    /// is finite at any distance from the boundary curve that `f64` can express, but not on
    /// it; `±∞` where the gradient overflows (NaN where two edges' terms overflow with
    /// opposite signs); NaN for a non-finite query.
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
            Dispatch::Narrow(c) => c.snapping(),
            Dispatch::Wide(c) => c.snapping(),
        }
    }
}

/// Quantizes `mesh` on the `W` grid, finds its signed boundary (unless `with_boundary` is
/// false), and indexes it in the ray frame.
fn exact_index<W: Width>(
    mesh: &Mesh,
    options: Options,
    with_boundary: bool,
) -> Result<ExactIndex<W>, BuildError> {
    let Some(bbox) = mesh.bounding_box() else {
        return Ok(ExactIndex::empty(options.ray)?);
    };
    let vertices = QuantizedVertices::new(&bbox, mesh.positions(), W::PRECISION, options.ray)?;
    let tris = mesh.triangles();
    let boundary = match options.boundary {
        _ if !with_boundary => Vec::new(),
        // The 60-bit evaluator computes on the input values, so it welds equal input positions
        // (`+ 0.0` identifies −0 with 0); the 30-bit one on the snapped mesh.
        BoundaryBy::Position if W::PRECISION == Precision::Bits60 => {
            let keys: Vec<[u64; 3]> = mesh
                .positions()
                .iter()
                .map(|p| p.map(|c| (c + 0.0).to_bits()))
                .collect();
            boundary_welded_by(tris, &keys)
        }
        BoundaryBy::Position => boundary_welded_by(tris, &vertices.lattice_points()),
        BoundaryBy::Index => boundary_edges(mesh),
    };
    let boundary: Vec<IndexedEdge> = boundary
        .iter()
        .map(|e| IndexedEdge {
            from: e.from,
            to: e.to,
            weight: e.weight,
        })
        .collect();
    Ok(ExactIndex::build(
        vertices,
        tris,
        &boundary,
        options.tolerance,
    ))
}

impl Snapping {
    /// The snapping of `mesh`'s vertices to the default (60-bit) lattice, without building an
    /// evaluator (what `gwn info` prints). `None` for an empty mesh or coordinates the grid
    /// cannot hold.
    pub fn of_mesh(mesh: &Mesh) -> Option<Snapping> {
        Snapping::of_vertices(&mesh.bounding_box()?, mesh.positions())
    }
}

/// The longest run [`WindingNumber::eval_batch`] evaluates as one column.
const MAX_RUN: usize = 256;

/// The most points per parallel task of [`WindingNumber::eval_batch`].
const BATCH_CHUNK: usize = 1024;
