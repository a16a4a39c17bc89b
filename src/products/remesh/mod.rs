//! Remeshing at `w = ½`: a closed, edge- and vertex-manifold, consistently oriented triangle
//! surface of the solid `{q : w(q) > ½}` of any [`Evaluator`] (the exact [`WindingNumber`] for
//! triangle meshes and soups, the fast evaluator for oriented point clouds).
//!
//! The pipeline (each step in its own file; the why is in `docs/remesh.md`):
//! 1. [`lattice`]: a lattice of cubes of edge `h = longest extent / res` around the input (finer
//!    along an axis on which the box is thin, so that a plate holds lattice points), with one
//!    coarse cell of margin whose outermost corners are *declared* outside (so the output is
//!    closed even when `w > ½` reaches the box).
//! 2. [`octree`]: corners of a coarse level are classified with [`crate::grid::evaluate`] (ray
//!    reuse along columns); cells whose corner classes differ, or that an input triangle meets
//!    (with [`remesh_guided`]), are split down to the finest level,
//!    and the refinement is closed under neighbours (a cell is split whenever any classified
//!    lattice point on its closed box disagrees with it), which makes the labelling of the whole
//!    finest lattice well defined. Memory grows with the surface, not with `res³`.
//! 3. [`extract`]: marching tetrahedra on the Freudenthal (Kuhn) split of every finest cell whose
//!    corners differ: translation-invariant, hence conforming across cells, and a binary
//!    labelling of the vertices of a triangulation of space has a separating surface that is a
//!    closed 2-manifold, with no ambiguous case.
//! 4. [`place`]: each output vertex moves along its lattice edge to where `w` crosses `½`:
//!    at the edge's crossing with the input triangles ([`crossings`], with [`remesh_guided`])
//!    once two evaluations confirm it (several crossings are told apart by evaluations between
//!    them), else by a bracketed search on the field (ITP: regula falsi where `w` is smooth,
//!    bisection's count at worst); `w` jumps across a sheet, so linear interpolation of `w`
//!    alone would misplace it. Vertices stay strictly inside their edges, which is all the
//!    no-self-intersection argument needs.
//! 5. [`simplify`] (on by default, [`RemeshOptions::simplify`]): half-edge collapses on the
//!    exact fixed-point vertices that refuse any collapse that would break the manifold (link
//!    condition), flip a face, move a removed vertex farther than a tolerance, or make two faces
//!    meet (exact test), down to a fraction of a dense marching cubes' face count; then each kept
//!    vertex moves towards its quadric minimum (on the fixed-point grid) where the same checks
//!    pass. Both run in rounds planned in parallel, with a result independent of the threads.
//! 6. [`report`], [`intersect`]: closed, edge- and vertex-manifold, oriented, Euler
//!    characteristic, components, the exact self-intersection count (on the fixed-point
//!    vertices), the sampled Hausdorff distance, printed and as JSON.
//!
//! ```
//! use gwn::eval::antipodal::WindingNumber;
//! use gwn::products::remesh::{RemeshOptions, remesh};
//! let tet = gwn::Mesh::from_slices(
//!     &[[0., 0., 0.], [1., 0., 0.], [0., 1., 0.], [0., 0., 1.]],
//!     &[[0, 2, 1], [0, 1, 3], [1, 2, 3], [2, 0, 3]],
//! )?;
//! let wn = WindingNumber::new(&tet)?;
//! let out = remesh(&wn, tet.bounding_box().unwrap(), &RemeshOptions::with_resolution(16))?;
//! let report = gwn::products::remesh::report::TopologyReport::of(&out.positions, &out.triangles);
//! assert!(report.closed && report.edge_manifold && report.vertex_manifold && report.oriented);
//! assert_eq!((report.euler_characteristic, report.components), (2, 1));
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```

pub mod coplanar_overlaps;
pub mod crossings;
pub mod cut_intersections;
pub mod dataset;
mod deadline;
pub mod exact_repair;
pub mod extract;
pub mod flatness;
pub mod intersect;
pub mod keep_input;
pub mod keep_parts;
pub mod lattice;
pub mod levels;
pub mod octree;
pub mod place;
pub mod plates;
pub mod reorient;
pub mod report;
pub mod separate_pinches;
pub mod simplify;
pub mod thicken;
pub mod transition;
pub mod write;

use crate::base::bounding_box::BoundingBox;
use crate::eval::Evaluator;
#[cfg(doc)]
use crate::eval::antipodal::WindingNumber;

/// How far above `½` the remesher's inside test sits: a point is inside when
/// `w > ½ + INSIDE_MARGIN` ([`inside`]).
///
/// Why not `½` itself: on a lone sheet (a single triangle, coplanar copies of one, a plate open
/// on both sides) `w` tends to exactly `½` on the sheet's front, and lattice points that lie on
/// the sheet (dyadic coordinates on a plane such as `x + y + z = 6`) evaluate to `½` plus or
/// minus the last bits of the boundary sum, so a test at `½` made a scatter of point-sized
/// solids decided by rounding (assimp-multiple_spaces.obj, one triangle: 3,255 components at
/// res 256, and a different scatter whenever the kernel's rounding changed). `1e-9` is ten times
/// the exact evaluator's documented error (`1e-10`), so the class is that of the exact `w`
/// wherever `|w − ½ − 1e-9| > 1e-10`, and such limit points fall outside; closed inputs (integral
/// `w`) are unaffected, and on open ones the level set moves by `1e-9 / |∇w|`.
pub const INSIDE_MARGIN: f64 = 1e-9;

/// The level the remesher's surface separates: `½ +` [`INSIDE_MARGIN`].
pub const INSIDE_LEVEL: f64 = 0.5 + INSIDE_MARGIN;

/// The remesher's inside test, `w > ½ +` [`INSIDE_MARGIN`] (false for NaN): every class the
/// classification, placement, thickening and report decide goes through it.
///
/// ```
/// use gwn::products::remesh::inside;
/// assert!(inside(1.0) && !inside(0.0) && !inside(0.5) && !inside(f64::NAN));
/// assert!(!inside(0.5 + 1e-12) && inside(0.5 + 1e-6));
/// ```
#[inline]
pub fn inside(w: f64) -> bool {
    w > INSIDE_LEVEL
}

/// Largest accepted `--res`: lattice coordinates are packed in 20 bits per axis.
pub const MAX_RESOLUTION: usize = 1 << 16;

/// Default vertex precision, in bisection steps: each vertex is within
/// `edge length / 2^(steps+1)` of a point where the class changes (the placement spends about
/// half as many evaluations where `w` is smooth, 1–2 at a verified crossing).
pub const DEFAULT_BISECTION_STEPS: u32 = 8;

/// Default [`RemeshOptions::sub_cell_levels`] (of [`RemeshOptions::with_resolution`], the CLI
/// and Python): one level, where parts thinner than a cell come back for a median 1.13× the
/// time (corpus at res 256: Hausdorff distance to the solid's boundary within a cell on 49 of
/// 60 closed inputs, against 38 without; two levels: 51, at 1.26×, with walls thinner than the
/// finest cell dotted into hundreds of components; docs/benchmarks.md, "One sub-cell level by
/// default").
pub const DEFAULT_SUB_CELL_LEVELS: u32 = 1;

/// Default [`RemeshOptions::planar_levels`] (of [`RemeshOptions::with_resolution`], the CLI and
/// Python).
pub const DEFAULT_PLANAR_LEVELS: u32 = 3;

/// [`RemeshOptions::planar_levels`] stop where the lattice of the largest cells would have fewer
/// than this many cells along the longest axis (a cell holding an eighth of the model is split
/// anyway unless the model is a box).
pub const MIN_PLANAR_RESOLUTION: usize = 8;

/// Largest accepted number of bisection steps (beyond it the interval is below `f64` spacing
/// for any reasonable box).
pub const MAX_BISECTION_STEPS: u32 = 40;

/// Peak bytes per classified lattice point, everything after it included (maps, band, edges,
/// triangles, positions): measured ~450 on the bunny at res 256 (0.94 M points classified), with
/// margin. Classification stops with [`RemeshError::OutOfMemory`] before exceeding the budget.
pub const BYTES_PER_CLASSIFIED_POINT: u64 = 512;

/// Options of [`remesh`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RemeshOptions {
    /// Finest equivalent resolution: cells of edge `h = longest extent / res`, and at least
    /// `res / 4` cells across every axis of the box ([`lattice::THIN_AXIS_DIVISOR`]).
    pub resolution: usize,
    /// Vertex precision in bisection steps: within `edge / 2^(steps+1)` of a class change (0:
    /// the midpoint of the lattice edge). What bisection alone would need per vertex; the
    /// placement ([`place`]) usually needs fewer.
    pub bisection_steps: u32,
    /// Most lattice points to classify before giving up with [`RemeshError::OutOfMemory`];
    /// `None`: the memory available ([`crate::grid::available_memory`]) over
    /// [`BYTES_PER_CLASSIFIED_POINT`] (2³¹ points where unknown).
    pub max_classified_points: Option<usize>,
    /// Simplify the marching-tetrahedra surface by edge collapses ([`simplify`]) that keep every
    /// guarantee; `None`: the raw marching-tetrahedra surface.
    pub simplify: Option<simplify::SimplifyOptions>,
    /// With the input triangles ([`remesh_guided`]): make the cells finer across widespread
    /// plates thinner than two cells ([`plates`]; at most 4 times, all axes together). Only the
    /// lattice changes; `false` keeps the lattice of `resolution` alone.
    pub refine_plates: bool,
    /// With the input triangles ([`remesh_guided`]): levels of cells below the resolution's
    /// (at most [`octree::MAX_SUB_LEVELS`]). A cell that a triangle crosses while its corners
    /// agree holds a part thinner than a cell (a horn's tip, a leg, a rib) that no corner sees;
    /// it is cut into eight, and so are its children while the same holds, down to this many
    /// levels, with a conforming transition to the neighbours ([`transition`]). 0: one
    /// uniform finest level.
    pub sub_cell_levels: u32,
    /// With the input triangles ([`remesh_guided`]): levels of cells above the resolution's
    /// (at most [`octree::MAX_PLANAR_LEVELS`]) kept whole where the input in them is flat
    /// (within [`octree::PLANAR_TOLERANCE`] of a plane, with an integer `w` at the corners):
    /// the lattice is built that many times coarser (down to [`MIN_PLANAR_RESOLUTION`] cells)
    /// and cut down to the resolution's cell everywhere else, with a conforming transition
    /// ([`transition`]). A flat face costs cells in proportion to its area in large cells, not
    /// in resolution cells. 0: every cell is at least as fine as the resolution's.
    pub planar_levels: u32,
    /// Use only as many of [`RemeshOptions::planar_levels`] as the [`flatness`] probe finds
    /// pay (none on an input curved everywhere, where they only cost time); `false`: all.
    pub probe_flatness: bool,
    /// Without input triangles: let the evaluator propose where each lattice edge crosses the
    /// surface ([`crate::eval::Evaluator::segment_crossings`]; STEP models, Bézier patch sets), verified
    /// like the triangles' crossings, instead of searching the field alone. Same guarantees,
    /// fewer evaluations; `false` for comparison.
    pub evaluator_crossings: bool,
    /// Give up with [`RemeshError::TimeLimit`] once this instant has passed: checked between
    /// the phases, between the octree's split rounds and between the simplifier's rounds, so
    /// a run overshoots by one round at most. Never changes an output: a run either ends in
    /// time with the surface it would have had, or returns no surface. `None`: no limit.
    pub deadline: Option<std::time::Instant>,
}

impl RemeshOptions {
    /// Checks every option's range (what [`remesh_guided`] refuses).
    pub fn check(&self) -> Result<(), RemeshError> {
        let options = self;
        if options.resolution == 0 || options.resolution > MAX_RESOLUTION {
            return Err(RemeshError::BadResolution {
                resolution: options.resolution,
            });
        }
        if options.sub_cell_levels > octree::MAX_SUB_LEVELS {
            return Err(RemeshError::BadSubCellLevels {
                levels: options.sub_cell_levels,
            });
        }
        if options.planar_levels > octree::MAX_PLANAR_LEVELS {
            return Err(RemeshError::BadPlanarLevels {
                levels: options.planar_levels,
            });
        }
        if options.bisection_steps > MAX_BISECTION_STEPS {
            return Err(RemeshError::BadBisectionSteps {
                steps: options.bisection_steps,
            });
        }
        if let Some(s) = options.simplify {
            let bad = |x: f64| !(x.is_finite() && x >= 0.0);
            for (option, value, wrong) in [
                ("max_distance", s.max_distance, bad(s.max_distance)),
                ("flat_tolerance", s.flat_tolerance, bad(s.flat_tolerance)),
                (
                    "target_fraction_of_marching_cubes",
                    s.target_fraction_of_marching_cubes,
                    bad(s.target_fraction_of_marching_cubes),
                ),
                (
                    "max_face_extent",
                    f64::from(s.max_face_extent),
                    s.max_face_extent == 0,
                ),
            ] {
                if wrong {
                    return Err(RemeshError::BadSimplification { option, value });
                }
            }
        }
        Ok(())
    }

    /// `resolution` with the default bisection steps and the default simplification.
    pub fn with_resolution(resolution: usize) -> Self {
        RemeshOptions {
            resolution,
            bisection_steps: DEFAULT_BISECTION_STEPS,
            max_classified_points: None,
            simplify: Some(simplify::SimplifyOptions::default()),
            refine_plates: true,
            sub_cell_levels: DEFAULT_SUB_CELL_LEVELS,
            planar_levels: DEFAULT_PLANAR_LEVELS,
            probe_flatness: true,
            evaluator_crossings: true,
            deadline: None,
        }
    }
}

/// Why [`remesh`] refused.
#[derive(Clone, Debug, PartialEq)]
pub enum RemeshError {
    /// `resolution` is 0 or above [`MAX_RESOLUTION`].
    BadResolution {
        /// The resolution asked for.
        resolution: usize,
    },
    /// More than [`MAX_BISECTION_STEPS`] bisection steps.
    BadBisectionSteps {
        /// The steps asked for.
        steps: u32,
    },
    /// The bounds are not finite, or `min > max` on some axis.
    BadBounds,
    /// More sub-cell levels than [`octree::MAX_SUB_LEVELS`], or more than the lattice's
    /// coordinates hold at this resolution.
    BadSubCellLevels {
        /// The levels asked for.
        levels: u32,
    },
    /// More planar levels than [`octree::MAX_PLANAR_LEVELS`].
    BadPlanarLevels {
        /// The levels asked for.
        levels: u32,
    },
    /// A simplification option is out of range: a tolerance or target that is negative or not
    /// finite, or a face extent of 0.
    BadSimplification {
        /// The option's name.
        option: &'static str,
        /// Its value.
        value: f64,
    },
    /// The output would have more than `u32::MAX` vertices.
    TooManyVertices,
    /// Classification reached its point budget ([`RemeshOptions::max_classified_points`]):
    /// the surface at this resolution would not fit in memory.
    OutOfMemory {
        /// The budget, in classified lattice points.
        max_points: usize,
    },
    /// [`RemeshOptions::deadline`] passed during this phase.
    TimeLimit {
        /// The phase that was running.
        phase: RemeshPhase,
    },
}

impl std::fmt::Display for RemeshError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            RemeshError::BadResolution { resolution } => {
                write!(f, "resolution {resolution} is outside 1..={MAX_RESOLUTION}")
            }
            RemeshError::BadBisectionSteps { steps } => write!(
                f,
                "{steps} bisection steps is above the limit {MAX_BISECTION_STEPS}"
            ),
            RemeshError::BadSubCellLevels { levels } => write!(
                f,
                "{levels} sub-cell levels is above the limit {} (or too many at this resolution)",
                octree::MAX_SUB_LEVELS
            ),
            RemeshError::BadPlanarLevels { levels } => write!(
                f,
                "{levels} planar levels is above the limit {}",
                octree::MAX_PLANAR_LEVELS
            ),
            RemeshError::BadBounds => {
                f.write_str("bounds must be finite with min <= max on every axis")
            }
            RemeshError::BadSimplification { option, value } => write!(
                f,
                "simplification option {option} = {value} is out of range (finite, >= 0; the \
                 face extent >= 1)"
            ),
            RemeshError::TooManyVertices => f.write_str("the output has more than 2^32 vertices"),
            RemeshError::OutOfMemory { max_points } => write!(
                f,
                "the surface needs more than {max_points} classified lattice points (about \
                 {BYTES_PER_CLASSIFIED_POINT} bytes each), more than the memory available: \
                 lower the resolution"
            ),
            RemeshError::TimeLimit { phase } => {
                write!(f, "the time limit ran out while {}", phase.name())
            }
        }
    }
}

impl std::error::Error for RemeshError {}

/// Work counters of one [`remesh`] run (for reports and benchmarks).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct RemeshStats {
    /// Cells per axis of the finest lattice (margin included).
    pub lattice_cells: [usize; 3],
    /// Cells per axis of the coarse level classified with ray reuse.
    pub coarse_cells: [usize; 3],
    /// Octree levels below the coarse level.
    pub levels: u32,
    /// Lattice points classified (coarse grid included).
    pub classified_points: usize,
    /// Octree cells split.
    pub split_cells: usize,
    /// Finest cells with differing corner classes (the band that is extracted).
    pub band_cells: usize,
    /// Regular cells cut into eight for a part thinner than a cell
    /// ([`RemeshOptions::refine_thin_parts`]).
    pub refined_cells: usize,
    /// Levels above the resolution's cell kept where the input is flat
    /// ([`RemeshOptions::planar_levels`], fewer on a small lattice, 0 without the triangles).
    pub planar_levels: u32,
    /// What the [`flatness`] probe found (all 0 when it did not run).
    pub flatness: flatness::FlatnessProbe,
    /// Evaluations spent on vertex placement (verifications and the field search).
    pub placement_evaluations: usize,
    /// Vertices placed at a verified crossing with the input triangles (no field search).
    pub guided_vertices: usize,
    /// Triangles of the marching-tetrahedra surface (before simplification).
    pub extracted_faces: usize,
    /// Vertices of the marching-tetrahedra surface (before simplification).
    pub extracted_vertices: usize,
    /// Triangles a dense marching cubes would give on the same corner classes (counted per band
    /// cell from its case, [`extract::marching_cubes_triangles`]; not built).
    pub marching_cubes_faces: usize,
    /// Simplification counters (all 0 without simplification).
    pub simplify: simplify::SimplifyStats,
    /// What the plate probe found and how much finer it made the cells along each axis
    /// ([`RemeshOptions::refine_plates`]).
    pub plates: plates::PlateProbe,
    /// Whether the input was kept as the output ([`keep_input::keep_input`]) or why not;
    /// `None` when that was not tried (point clouds, curved inputs, `--always-remesh`).
    pub input: Option<keep_input::InputCheck>,
}

/// The surface [`remesh`] returns.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Remeshed {
    /// Vertex positions.
    pub positions: Vec<[f64; 3]>,
    /// Triangles, counter-clockwise seen from outside (`w ≤ ½`).
    pub triangles: Vec<[u32; 3]>,
    /// The vertices exactly, in fixed point: lattice units times `ticks_per_cell` (the exact
    /// self-intersection check, [`intersect::self_intersections`], runs on these; `positions`
    /// are their images in world coordinates, rounded to `f64`). Empty when the input was kept
    /// ([`keep_input`]): `positions` are then exact.
    pub fixed: Vec<[i64; 3]>,
    /// Fixed-point units per lattice cell edge (`2^(bisection_steps + 1)`; 0 when the input was
    /// kept).
    pub ticks_per_cell: i64,
    /// The resolution's cell edge, `longest extent / resolution` (cells are cubes of this edge,
    /// finer along an axis on which the box is thin or across plates thinner than a cell:
    /// [`Remeshed::cell_sizes`]); the unit of distances "in cells".
    pub cell_size: f64,
    /// The lattice spacing along each axis.
    pub cell_sizes: [f64; 3],
    /// Work counters.
    pub stats: RemeshStats,
}

/// The surface of `{w > ½}` inside `bounds` (grown by a margin), at finest cell size
/// `longest extent of bounds / options.resolution` (finer along a thin axis of the box: at least
/// `resolution / 4` cells across it, see [`lattice`]).
///
/// Output guarantees, whatever the evaluator returns: closed, edge- and vertex-manifold,
/// consistently oriented (outward from `w > ½`). Without the input triangles (this function;
/// see [`remesh_guided`]), a part of the solid thinner than a coarse cell whose coarse corners all
/// miss it is not found (see `docs/remesh.md`).
pub fn remesh<E: Evaluator + ?Sized>(
    evaluator: &E,
    bounds: BoundingBox,
    options: &RemeshOptions,
) -> Result<Remeshed, RemeshError> {
    remesh_guided(evaluator, None, bounds, options, &|_| {})
}

/// Which solid of its own mesh the field given to [`remesh_mesh`] is, so that the mesh may be
/// kept as its own remesh.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Keep {
    /// Not the mesh's own solid, or not to be kept: a thickened field, the fast method's, a
    /// boundary by index (no weld), or a remesh asked for whatever the input.
    No,
    /// The exact method's `{w > ½}` ([`keep_input::keep_input`]).
    Winding,
    /// The parity method's solid ([`reorient::keep_reoriented`]).
    Parity,
}

/// [`remesh_guided`] of a mesh's own field, unless the mesh already is the surface it would aim
/// for: with [`Keep::Winding`] (the exact method's field of `mesh`, nothing thickened), a mesh
/// that [`keep_input::keep_input`] proves to be the boundary of its `w > ½` solid is returned
/// as it is, and with [`Keep::Parity`] (the parity method's) a closed mesh that
/// [`reorient::keep_reoriented`] proves to bound the parity's solid once its faces are turned
/// is returned turned (neither is tried without [`RemeshOptions::simplify`]: the raw lattice
/// surface was asked for); otherwise the remesh, with [`RemeshStats::input`] saying why the
/// input was not kept. Options are checked either way. What `gwn remesh`,
/// `gwn remesh-dataset` and `gwn.remesh` run.
pub fn remesh_mesh<E: Evaluator + ?Sized>(
    mesh: &crate::Mesh,
    keep: Keep,
    evaluator: &E,
    guide: Option<&crossings::SegmentBvh>,
    bounds: BoundingBox,
    options: &RemeshOptions,
    progress: &dyn Fn(RemeshPhase),
) -> Result<Remeshed, RemeshError> {
    remesh_mesh_field(mesh, keep, &evaluator, guide, bounds, options, progress)
}

/// [`remesh_mesh`] on a trait object (compiled once, as [`remesh_field`]).
fn remesh_mesh_field(
    mesh: &crate::Mesh,
    keep: Keep,
    evaluator: &dyn Evaluator,
    guide: Option<&crossings::SegmentBvh>,
    bounds: BoundingBox,
    options: &RemeshOptions,
    progress: &dyn Fn(RemeshPhase),
) -> Result<Remeshed, RemeshError> {
    options.check()?;
    // Without simplification the raw lattice surface was asked for.
    let keep = if options.simplify.is_some() {
        keep
    } else {
        Keep::No
    };
    let kept = match keep {
        Keep::No => None,
        Keep::Winding => {
            progress(RemeshPhase::KeepInput);
            Some(keep_input::keep_input(mesh, bounds, options))
        }
        Keep::Parity => {
            progress(RemeshPhase::KeepInput);
            Some(reorient::keep_reoriented(mesh, bounds, options))
        }
    };
    // Linear in the input and not interrupted; the time limit holds after it.
    if kept.is_some()
        && options
            .deadline
            .is_some_and(|at| std::time::Instant::now() > at)
    {
        return Err(RemeshError::TimeLimit {
            phase: RemeshPhase::KeepInput,
        });
    }
    let not_kept = match kept {
        None => None,
        Some(Ok(out)) => return Ok(out),
        Some(Err(why)) => {
            // Its clean components kept, under the exact method's `w` only: the parity of a
            // part is not the whole's.
            if keep == Keep::Winding
                && let Some(out) =
                    remesh_rest(mesh, guide.is_some(), bounds, options, why, progress)?
            {
                return Ok(out);
            }
            Some(keep_input::InputCheck::Remeshed(why))
        }
    };
    let mut out = remesh_field(evaluator, guide, bounds, options, progress)?;
    out.stats.input = not_kept;
    Ok(out)
}

/// The input's clean components kept and only the rest remeshed ([`keep_parts`]), when the
/// whole was not kept for `why` and the union is proved; `None` to remesh the whole. The rest is
/// remeshed with its own exact evaluator (default options) and, when `guided`, itself as the
/// guide.
fn remesh_rest(
    mesh: &crate::Mesh,
    guided: bool,
    bounds: BoundingBox,
    options: &RemeshOptions,
    why: keep_input::NotKept,
    progress: &dyn Fn(RemeshPhase),
) -> Result<Option<Remeshed>, RemeshError> {
    use keep_input::NotKept;
    // Too fine, or beyond the exact tests: so are the parts.
    if matches!(
        why,
        NotKept::Empty
            | NotKept::TooManyFaces { .. }
            | NotKept::CoordinateRange
            | NotKept::UnevenFaces
    ) {
        return Ok(None);
    }
    let Some(parts) = keep_parts::kept_parts(mesh, bounds, options) else {
        return Ok(None);
    };
    let guide = guided.then(|| crossings::SegmentBvh::of_field_mesh(&parts.rest));
    let rest = remesh_field(&parts.rest_field, guide.as_ref(), bounds, options, progress)?;
    let Some(mut out) = keep_parts::merge(&parts, rest) else {
        return Ok(None);
    };
    out.stats.input = Some(keep_input::InputCheck::PartlyKept {
        kept_components: parts.kept_components,
        components: parts.components,
        kept_faces: parts.kept_triangles.len(),
        why,
    });
    Ok(Some(out))
}

/// The steps of a [`remesh`] run, announced to the progress callback of [`remesh_guided`] as
/// each begins.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum RemeshPhase {
    /// Whether the input already is the surface ([`remesh_mesh`], [`keep_input`]).
    KeepInput,
    /// Corner classification (coarse grid, then the octree band).
    Classify,
    /// Marching tetrahedra over the band.
    Extract,
    /// Vertex placement (guided crossings, bisection).
    Place,
    /// Edge collapses ([`RemeshOptions::simplify`]).
    Simplify,
}

impl RemeshPhase {
    /// A short name for progress messages.
    pub fn name(self) -> &'static str {
        match self {
            RemeshPhase::KeepInput => "checking whether the input is kept as it is",
            RemeshPhase::Classify => "classifying lattice corners",
            RemeshPhase::Extract => "extracting the surface",
            RemeshPhase::Place => "placing vertices",
            RemeshPhase::Simplify => "simplifying",
        }
    }
}

/// [`remesh`], with the input triangles (`guide`) proposing where each vertex goes: a lattice
/// edge that crosses them once gets its vertex at the crossing after two evaluations of `w`
/// confirm the class change there, instead of a search on the field (up to `bisection_steps`
/// evaluations; see [`place`]). Every octree cell that a triangle of `guide` meets is also refined to the finest
/// level: when `w` jumps only across the guide's triangles (a closed input as its own guide),
/// every finest lattice point is labelled by its true class, so no part of the solid holding a
/// finest lattice point is lost. The output's guarantees and the vertex precision are those of
/// [`remesh`] whatever `guide` holds; a guide that is not the evaluator's surface only costs
/// time.
/// `progress` hears of each [`RemeshPhase`] as it begins.
pub fn remesh_guided<E: Evaluator + ?Sized>(
    evaluator: &E,
    guide: Option<&crossings::SegmentBvh>,
    bounds: BoundingBox,
    options: &RemeshOptions,
    progress: &dyn Fn(RemeshPhase),
) -> Result<Remeshed, RemeshError> {
    remesh_field(&evaluator, guide, bounds, options, progress)
}

/// [`remesh_guided`] on a trait object: the pipeline is compiled once, in this crate. Generic over
/// the evaluator, it was compiled again (optimised) in every crate that called it with any
/// evaluator type — the tool, the Python module, each test binary — for one virtual call per
/// evaluation of `w`, which costs microseconds (docs/benchmarks.md, "CI time").
fn remesh_field(
    evaluator: &dyn Evaluator,
    guide: Option<&crossings::SegmentBvh>,
    bounds: BoundingBox,
    options: &RemeshOptions,
    progress: &dyn Fn(RemeshPhase),
) -> Result<Remeshed, RemeshError> {
    options.check()?;
    // Every evaluation below stops at the deadline (NaN after it). All of them are made before
    // placement ends, which checks the clock, so those values never reach a surface.
    let evaluator = &deadline::Deadlined::new(evaluator, options.deadline);
    let mut lattice =
        lattice::Lattice::new(bounds, options.resolution).ok_or(RemeshError::BadBounds)?;
    // The unit of distances in cells stays the resolution's cell whatever the plates refine.
    let cell_size = lattice.largest_cell();
    let plates = match guide {
        Some(guide) if options.refine_plates => plates::probe(evaluator, guide, bounds, lattice.h),
        _ => plates::PlateProbe::none(),
    };
    // Planar levels need the triangles (only they say where the input is flat), are used as
    // far as the flatness probe finds they pay, and stop where the lattice of the largest
    // cells would get too coarse.
    let flatness = match guide {
        Some(guide) if options.planar_levels > 0 && options.probe_flatness => {
            flatness::probe(evaluator, guide, &lattice, options.planar_levels)
        }
        Some(_) => flatness::FlatnessProbe {
            levels: options.planar_levels,
            ..flatness::FlatnessProbe::default()
        },
        None => flatness::FlatnessProbe::default(),
    };
    let planar = if guide.is_some() {
        (0..=flatness.levels)
            .rev()
            .find(|&l| options.resolution.div_ceil(1 << l) >= MIN_PLANAR_RESOLUTION)
            .unwrap_or(0)
    } else {
        0
    };
    if plates.refines() || planar > 0 {
        // Rounded up: the resolution's cell is never coarser than asked for.
        let coarse = options.resolution.div_ceil(1 << planar);
        lattice = lattice::Lattice::refined(bounds, coarse, plates.refinement)
            .and_then(|l| l.with_planar_levels(planar))
            .ok_or(RemeshError::BadBounds)?;
    }
    if options.sub_cell_levels > 0 && guide.is_some() {
        lattice = lattice.with_sub_levels(options.sub_cell_levels).ok_or(
            RemeshError::BadSubCellLevels {
                levels: options.sub_cell_levels,
            },
        )?;
    }
    // Distances and fixed-point units per resolution cell: the simplification's tolerances and
    // the report's cells do not change with the sub-levels or the planar levels.
    let resolution = lattice.resolution();
    let max_points = options.max_classified_points.unwrap_or_else(|| {
        crate::grid::available_memory().map_or(1 << 31, |bytes| {
            usize::try_from(bytes / BYTES_PER_CLASSIFIED_POINT).unwrap_or(usize::MAX)
        })
    });
    // Each phase checks the deadline as it ends (and the long ones between their rounds).
    let in_time = |phase: RemeshPhase| match options.deadline {
        Some(at) if std::time::Instant::now() > at => Err(RemeshError::TimeLimit { phase }),
        _ => Ok(()),
    };
    in_time(RemeshPhase::Classify)?;
    progress(RemeshPhase::Classify);
    let classified = octree::classify(evaluator, &lattice, guide, max_points, options.deadline)
        .map_err(|stop| match stop {
            octree::Stop::TooManyPoints => RemeshError::OutOfMemory { max_points },
            octree::Stop::TimeLimit => RemeshError::TimeLimit {
                phase: RemeshPhase::Classify,
            },
        })?;
    progress(RemeshPhase::Extract);
    let band = extract::extract(&lattice, &classified, options.deadline).ok_or(
        RemeshError::TimeLimit {
            phase: RemeshPhase::Extract,
        },
    )?;
    if band.edges.len() > u32::MAX as usize {
        return Err(RemeshError::TooManyVertices);
    }
    in_time(RemeshPhase::Extract)?;
    progress(RemeshPhase::Place);
    let mut placed = place::place_vertices(
        evaluator,
        &lattice,
        &band.edges,
        &classified.edge_values(&band.edges),
        // The precision is per lattice edge: a cell `2^planar` times larger takes as many
        // more steps, so vertices stay as close to the class change in resolution cells.
        options.bisection_steps + planar,
        match guide {
            Some(bvh) => place::CrossingSource::Triangles(bvh),
            None if options.evaluator_crossings => place::CrossingSource::Evaluator,
            None => place::CrossingSource::None,
        },
        options.deadline,
    )
    .ok_or(RemeshError::TimeLimit {
        phase: RemeshPhase::Place,
    })?;
    let mut stats = RemeshStats {
        lattice_cells: lattice.cells,
        coarse_cells: lattice.coarse_cells(),
        levels: lattice.levels,
        classified_points: classified.labels.len(),
        split_cells: classified.split.len(),
        band_cells: band.band_cells,
        refined_cells: classified.refined.len(),
        planar_levels: lattice.planar_levels,
        flatness,
        placement_evaluations: placed.evaluations,
        guided_vertices: placed.guided,
        extracted_faces: band.triangles.len(),
        extracted_vertices: band.edges.len(),
        marching_cubes_faces: band.marching_cubes_triangles,
        simplify: simplify::SimplifyStats::default(),
        plates,
        input: None,
    };
    drop(classified);
    in_time(RemeshPhase::Place)?;
    let (positions, fixed, triangles) = match &options.simplify {
        None => (placed.positions, placed.fixed, band.triangles),
        Some(simplify_options) => {
            progress(RemeshPhase::Simplify);
            // The input's planes at the vertices placed on them, for the relocation; the world
            // planes and positions and the lattice edges are not needed any more, and the
            // simplifier takes the surface and the planes by value (at res 256 a cube's
            // surface is 1.6M vertices and 3.1M faces: ~300 MB less at the peak, measured).
            let planes = simplify_options
                .input_planes
                .then(|| placed.planes_in_lattice_units(&resolution));
            placed.planes = Vec::new();
            placed.positions = Vec::new();
            drop(band.edges);
            let simplify_options = &simplify::SimplifyOptions {
                lattice_cube_cells: 1 << planar,
                deadline: options.deadline,
                ..*simplify_options
            };
            let s = simplify::simplify_with_planes(
                std::mem::take(&mut placed.fixed),
                band.triangles,
                placed.ticks_per_cell * i64::from(lattice.resolution_cell()),
                simplify_options,
                (simplify_options.target_fraction_of_marching_cubes
                    * band.marching_cubes_triangles as f64) as usize,
                planes,
            );
            // Past the deadline the simplifier stops between rounds: that surface is valid but
            // not the one the options ask for, so it is not returned.
            in_time(RemeshPhase::Simplify)?;
            stats.simplify = s.stats;
            // From the fixed point, as `place` does (exact dyadic steps: the same `f64` for a
            // vertex that was not relocated).
            let ticks = placed.ticks_per_cell as f64;
            (
                s.points
                    .iter()
                    .map(|p| lattice.position(p.map(|c| c as f64 / ticks)))
                    .collect(),
                s.points,
                s.triangles,
            )
        }
    };
    Ok(Remeshed {
        positions,
        triangles,
        fixed,
        ticks_per_cell: placed.ticks_per_cell * i64::from(lattice.resolution_cell()),
        cell_size,
        cell_sizes: resolution.h,
        stats,
    })
}
