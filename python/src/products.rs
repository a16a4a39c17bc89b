//! Grids and products: `voxelize`, `sdf`, `signed_distance`, `slice`, `classify`, `filter_tets`.
//! Each is a thin call of the library function the CLI uses, so values are the CLI's, bit for bit.

use gwn::BoundingBox;
use gwn::Mesh;
use gwn::eval::Evaluator;
use gwn::eval::antipodal::Options;
use gwn::grid::GridSpec;
use gwn::input::InputKind;
use gwn::products::classify::classify_faces;
use gwn::products::png::Slice;
use gwn::products::sdf::SignedDistance;
use gwn::spec::{EvaluatorSpec, Method};
use numpy::PyArray1;
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;
use pyo3::types::{PyBytes, PyTuple};

use crate::arrays::{array_nd, array1, array2, indices_vec, with_points};
use crate::errors::value_error;
use crate::evaluator::SpecArgs;
use crate::oneshot::mesh_from;
use crate::threads::{self, Threads};

/// The evaluator a product uses: any of the library's, through its `Evaluator` trait (the CLI's
/// `--method/--beta/--order/--tolerance`).
type AnyEvaluator<'m> = Box<dyn Evaluator + 'm>;

/// The spec of a product's `method`/`beta`/`order`/`tolerance`, checked up front for a mesh (so
/// that errors come before any work) by the library's rules.
fn spec_of(
    method: &str,
    beta: Option<f64>,
    order: Option<u8>,
    tolerance: Option<f64>,
) -> PyResult<EvaluatorSpec> {
    let spec = SpecArgs {
        method: Some(method),
        beta,
        order,
        rule: None,
        precision: None,
        ray: None,
        tolerance,
    }
    .spec()
    .map_err(value_error)?;
    spec.check(InputKind::Mesh).map_err(value_error)?;
    Ok(spec)
}

/// The exact method's options for `tolerance=` (the CLI's `--tolerance`), checked up front.
pub fn exact_options(tolerance: f64) -> PyResult<Options> {
    let spec = EvaluatorSpec {
        tolerance: Some(tolerance),
        ..Default::default()
    };
    spec.validate().map_err(value_error)?;
    Ok(spec.exact_options())
}

/// Builds the evaluator `spec` describes for `mesh`.
fn evaluator_for<'m>(
    mesh: &'m Mesh,
    spec: &EvaluatorSpec,
) -> Result<AnyEvaluator<'m>, Box<dyn std::error::Error + Send + Sync>> {
    Ok(spec.build_mesh(mesh)?)
}

/// Largest slice side in pixels (the CLI's limit).
const MAX_SLICE_RES: usize = 1 << 15;

/// The grid of `voxelize` and `sdf`: explicit `bounds` or the mesh's box grown by `margin`,
/// explicit `dims` (W, H, D) or `res` cells along the longest side; refused (before any
/// allocation) by the library's size check, the CLI's, when its `bytes_per_cell` exceed the
/// available memory.
fn grid_spec(
    input_box: Option<BoundingBox>,
    res: usize,
    dims: Option<[usize; 3]>,
    bounds: Option<[f64; 6]>,
    margin: f64,
    bytes_per_cell: usize,
) -> PyResult<GridSpec> {
    let bounds = match bounds {
        Some(b) => BoundingBox {
            min: [b[0], b[1], b[2]],
            max: [b[3], b[4], b[5]],
        },
        None => {
            if !(margin.is_finite() && margin >= 0.0) {
                return Err(PyValueError::new_err(format!(
                    "margin must be a non-negative number, got {margin}"
                )));
            }
            input_box
                .ok_or_else(|| PyValueError::new_err("the mesh has no triangles"))?
                .enlarged(margin)
        }
    };
    let spec = match dims {
        Some(d) => GridSpec::new(bounds, d),
        None => GridSpec::with_resolution(bounds, res),
    }
    .map_err(|e| PyValueError::new_err(format!("bad grid: {e}")))?;
    spec.check_memory(bytes_per_cell, gwn::grid::available_memory())
        .map_err(|e| PyValueError::new_err(format!("{e}; lower res or dims")))?;
    Ok(spec)
}

/// A grid's values (D, H, W), origin (3,) and spacing (3,).
type GridArrays<'py> = (
    Bound<'py, PyAny>,
    Bound<'py, PyArray1<f64>>,
    Bound<'py, PyArray1<f64>>,
);

/// `(values (D, H, W), origin (3,), spacing (3,))` of a grid.
fn grid_result<'py>(
    py: Python<'py>,
    spec: &GridSpec,
    values: Vec<f64>,
) -> PyResult<GridArrays<'py>> {
    let origin = spec.point(0, 0, 0).to_vec();
    let spacing = spec.spacing().to_vec();
    Ok((
        array_nd(py, values, &spec.shape())?,
        array1(py, origin),
        array1(py, spacing),
    ))
}

/// Winding numbers on a voxel grid (``method`` exact by default, with ray reuse: one ray per
/// grid column; ``"direct"`` or ``"fast"`` with ``beta``/``order`` as in ``gwn voxelize``).
///
/// Returns ``(W, origin, spacing)``: ``W`` float64 of shape (D, H, W) indexed ``[z, y, x]``
/// (x fastest, as ``gwn voxelize`` writes it), samples at cell centres
/// ``origin + (i, j, k) * spacing`` for ``W[k, j, i]``. The grid covers ``bounds``
/// ``(x0, y0, z0, x1, y1, z1)`` or the mesh's bounding box grown by ``margin`` times its largest
/// extent, with ``dims`` (W, H, D) cells or ``res`` cells along the longest side. ``tolerance``
/// is the exact method's boundary tolerance (``gwn voxelize --tolerance``; see
/// :class:`WindingNumber`). ``voxelize(model, res=...)`` of a :class:`StepModel` or
/// :class:`PatchSet` takes no ``F`` and evaluates the model with its own evaluator (the options
/// :class:`WindingNumber` takes for it), as ``gwn voxelize part.step`` does.
#[pyfunction]
#[pyo3(signature = (V, F = None, res = 64, *, dims = None, bounds = None, margin = 0.05, method = "exact", beta = None, order = None, tolerance = None, threads = None))]
#[allow(non_snake_case, clippy::too_many_arguments)]
pub fn voxelize<'py>(
    py: Python<'py>,
    V: &Bound<'py, PyAny>,
    F: Option<&Bound<'py, PyAny>>,
    res: usize,
    dims: Option<[usize; 3]>,
    bounds: Option<[f64; 6]>,
    margin: f64,
    method: &str,
    beta: Option<f64>,
    order: Option<u8>,
    tolerance: Option<f64>,
    threads: Option<Threads>,
) -> PyResult<GridArrays<'py>> {
    let method = spec_of(method, beta, order, tolerance)?;
    let source = Source::of(V, F, "voxelize")?;
    let grid = grid_spec(
        source.bounding_box(),
        res,
        dims,
        bounds,
        margin,
        gwn::grid::EVALUATE_BYTES_PER_CELL,
    )?;
    let values = threads::run_interruptible(py, threads, |stop| {
        // `None` (interrupted) out, a refused option in.
        source
            .with_evaluator(&method, |wn| {
                gwn::grid::evaluate_until(wn, &grid, |_| {}, stop)
            })
            .transpose()
    })?;
    let values = values.map_err(value_error)?;
    grid_result(py, &grid, values)
}

/// Signed distance on a voxel grid: distance to the closest point of the triangles, negative
/// where the exact winding number is above 1/2 (correct on open and dirty meshes).
///
/// Same grid arguments and return value as :func:`voxelize` (``gwn sdf``'s values);
/// ``tolerance`` is the exact sign's boundary tolerance (``gwn sdf --tolerance``).
#[pyfunction]
#[pyo3(signature = (V, F, res = 64, *, dims = None, bounds = None, margin = 0.05, tolerance = 1e-10, threads = None))]
#[allow(non_snake_case, clippy::too_many_arguments)]
pub fn sdf<'py>(
    py: Python<'py>,
    V: &Bound<'py, PyAny>,
    F: &Bound<'py, PyAny>,
    res: usize,
    dims: Option<[usize; 3]>,
    bounds: Option<[f64; 6]>,
    margin: f64,
    tolerance: f64,
    threads: Option<Threads>,
) -> PyResult<GridArrays<'py>> {
    let exact = exact_options(tolerance)?;
    let mesh = mesh_from(V, F, "V", "F")?;
    let spec = grid_spec(
        mesh.bounding_box(),
        res,
        dims,
        bounds,
        margin,
        gwn::products::sdf::GRID_BYTES_PER_CELL,
    )?;
    let sdf = threads::run(py, threads, || SignedDistance::with_options(&mesh, exact))?
        .map_err(value_error)?;
    let values =
        threads::run_interruptible(py, threads, |stop| sdf.eval_grid_until(&spec, |_| {}, stop))?;
    grid_result(py, &spec, values)
}

/// Signed distance at the rows of ``Q`` (k, 3): float64 (k,), negative where the exact winding
/// number is above 1/2; ``inf`` for a mesh without triangles. ``tolerance`` is the exact sign's
/// boundary tolerance (see :class:`WindingNumber`).
#[pyfunction]
#[pyo3(signature = (V, F, Q, threads = None, *, tolerance = 1e-10))]
#[allow(non_snake_case)]
pub fn signed_distance<'py>(
    py: Python<'py>,
    V: &Bound<'py, PyAny>,
    F: &Bound<'py, PyAny>,
    Q: &Bound<'py, PyAny>,
    threads: Option<Threads>,
    tolerance: f64,
) -> PyResult<Bound<'py, PyArray1<f64>>> {
    let exact = exact_options(tolerance)?;
    let mesh = mesh_from(V, F, "V", "F")?;
    let values = with_points(Q, "Q", |q| {
        let sdf = threads::run(py, threads, || SignedDistance::with_options(&mesh, exact))?
            .map_err(value_error)?;
        threads::run_batch(py, threads, q, |piece| sdf.eval_batch(piece))
    })?;
    Ok(array1(py, values))
}

fn axis_index(axis: &str) -> PyResult<usize> {
    match axis {
        "x" => Ok(0),
        "y" => Ok(1),
        "z" => Ok(2),
        _ => Err(PyValueError::new_err(format!(
            "axis must be \"x\", \"y\" or \"z\", got {axis:?}"
        ))),
    }
}

/// A slice of the exact winding number on an axis-aligned plane, as ``gwn slice`` renders it.
///
/// The plane is normal to ``axis`` at ``at`` (fraction of the input's bounding box along the axis,
/// 0 = min, 1 = max) or at the absolute coordinate ``at_coord``; it covers the box grown by
/// ``margin``, with ``res`` pixels along its longer side. Returns ``(image, png)``: ``image``
/// float64 (height, width), row 0 at the top (x-slice: y right, z up; y-slice: x right, z up;
/// z-slice: x right, y up), and ``png`` the bytes of the coloured picture with its colour bar
/// (and the mesh's cross-section in black when ``outline``). ``tolerance`` is the exact method's
/// boundary tolerance (``gwn slice --tolerance``). ``slice(model, axis=...)`` of a
/// :class:`StepModel` or :class:`PatchSet` takes no ``F`` and evaluates the model with its own
/// evaluator, as ``gwn slice part.step`` does (``outline`` needs a triangle mesh).
#[pyfunction]
#[pyo3(signature = (V, F = None, axis = "z", at = 0.5, *, at_coord = None, res = 1024, margin = 0.1, outline = false, method = "exact", beta = None, order = None, tolerance = None, threads = None))]
#[allow(non_snake_case, clippy::too_many_arguments)]
pub fn slice<'py>(
    py: Python<'py>,
    V: &Bound<'py, PyAny>,
    F: Option<&Bound<'py, PyAny>>,
    axis: &str,
    at: f64,
    at_coord: Option<f64>,
    res: usize,
    margin: f64,
    outline: bool,
    method: &str,
    beta: Option<f64>,
    order: Option<u8>,
    tolerance: Option<f64>,
    threads: Option<Threads>,
) -> PyResult<(Bound<'py, PyAny>, Bound<'py, PyBytes>)> {
    let spec = spec_of(method, beta, order, tolerance)?;
    let axis = axis_index(axis)?;
    if res == 0 || res > MAX_SLICE_RES {
        return Err(PyValueError::new_err(format!(
            "res must be between 1 and {MAX_SLICE_RES}, got {res}"
        )));
    }
    if !(margin.is_finite() && margin >= 0.0) {
        return Err(PyValueError::new_err(format!(
            "margin must be a non-negative number, got {margin}"
        )));
    }
    let source = Source::of(V, F, "slice")?;
    if outline && let Source::Curved(curved) = &source {
        return Err(PyValueError::new_err(format!(
            "slice(model, outline=True): the outline needs a triangle mesh, not {}",
            curved.kind()
        )));
    }
    let bbox = source
        .bounding_box()
        .ok_or_else(|| PyValueError::new_err("the mesh has no triangles"))?;
    let coord = match at_coord {
        Some(c) if c.is_finite() => c,
        Some(c) => {
            return Err(PyValueError::new_err(format!(
                "at_coord must be finite, got {c}"
            )));
        }
        None if at.is_finite() => bbox.min[axis] + at * (bbox.max[axis] - bbox.min[axis]),
        None => {
            return Err(PyValueError::new_err(format!(
                "at must be finite, got {at}"
            )));
        }
    };
    let slice = Slice::new(&bbox.enlarged(margin), axis, coord, res);
    let (values, png) = threads::run(py, threads, || {
        // A ray in the plane: one ray serves a whole image column or row (the exact method on
        // meshes and patch sets; the STEP evaluator picks its own rays), as `gwn slice`.
        let mut spec = spec;
        let kind = source.kind();
        if spec.method_for(kind) == Method::Exact && kind != InputKind::Step {
            spec.ray = Some(slice.ray());
        }
        let values = source.with_evaluator(&spec, |wn| slice.evaluate(wn))?;
        let mut png = Vec::new();
        // Writing into a Vec cannot fail for I/O reasons; an encoder error is still reported.
        let written = slice
            .render(&values, outline.then(|| source.mesh()).flatten())
            .write_png(&mut png);
        Ok::<_, Box<dyn std::error::Error + Send + Sync>>((values, written.map(|()| png)))
    })?
    .map_err(value_error)?;
    let png = png.map_err(value_error)?;
    Ok((
        array_nd(py, values, &[slice.height, slice.width])?,
        PyBytes::new(py, &png),
    ))
}

/// What a product evaluates: a mesh `(V, F)`, or a STEP model or patch set that comes alone.
enum Source {
    Mesh(Mesh),
    Curved(crate::evaluator::Curved),
}

impl Source {
    /// `(V, F)` as a mesh, or `V` a `StepModel`/`PatchSet` with no `F`; `what` names the call in
    /// the messages.
    fn of(v: &Bound<'_, PyAny>, f: Option<&Bound<'_, PyAny>>, what: &str) -> PyResult<Source> {
        Self::named(v, f, what, ["V", "F"])
    }

    /// [`Source::of`] with the arguments' names (`classify`'s `VB`, `FB`).
    fn named(
        v: &Bound<'_, PyAny>,
        f: Option<&Bound<'_, PyAny>>,
        what: &str,
        [v_name, f_name]: [&str; 2],
    ) -> PyResult<Source> {
        match (crate::patches::curved_of(v), f.filter(|f| !f.is_none())) {
            (Some(curved), None) => Ok(Source::Curved(curved)),
            (Some(curved), Some(_)) => Err(PyValueError::new_err(format!(
                "{what}: {} takes no {f_name} (pass the other arguments by name)",
                curved.kind()
            ))),
            (None, Some(f)) => Ok(Source::Mesh(mesh_from(v, f, v_name, f_name)?)),
            (None, None) => Err(PyValueError::new_err(format!(
                "{what}: {f_name} is required for a mesh (only a gwn.StepModel or gwn.PatchSet comes alone)"
            ))),
        }
    }

    fn kind(&self) -> InputKind {
        match self {
            Source::Mesh(_) => InputKind::Mesh,
            Source::Curved(curved) => curved.kind(),
        }
    }

    fn mesh(&self) -> Option<&Mesh> {
        match self {
            Source::Mesh(mesh) => Some(mesh),
            Source::Curved(_) => None,
        }
    }

    /// A box containing the input (none for a mesh without triangles).
    fn bounding_box(&self) -> Option<BoundingBox> {
        match self {
            Source::Mesh(mesh) => mesh.bounding_box(),
            Source::Curved(curved) => Some(curved.bounding_box()),
        }
    }

    /// Runs `f` with the evaluator `spec` describes for this input.
    fn with_evaluator<R>(
        &self,
        spec: &EvaluatorSpec,
        f: impl FnOnce(&dyn Evaluator) -> R,
    ) -> Result<R, Box<dyn std::error::Error + Send + Sync>> {
        match self {
            Source::Mesh(mesh) => Ok(f(evaluator_for(mesh, spec)?.as_ref())),
            Source::Curved(curved) => Ok(curved.with_evaluator(spec, f)?),
        }
    }
}

/// Classifies each face of mesh A by the exact winding number of mesh B at its centroid
/// (the building block of mesh booleans; ``gwn classify``). Returns float64 (faces of A,);
/// ``w > 0.5`` means inside B. ``tolerance`` is the exact method's boundary tolerance
/// (``gwn classify --tolerance``). ``VB`` may be a :class:`StepModel` or :class:`PatchSet`
/// (no ``FB``), evaluated with its own evaluator, as ``gwn classify a.obj part.step``.
#[pyfunction]
#[pyo3(signature = (VA, FA, VB, FB = None, *, method = "exact", beta = None, order = None, tolerance = None, threads = None))]
#[allow(non_snake_case, clippy::too_many_arguments)]
pub fn classify<'py>(
    py: Python<'py>,
    VA: &Bound<'py, PyAny>,
    FA: &Bound<'py, PyAny>,
    VB: &Bound<'py, PyAny>,
    FB: Option<&Bound<'py, PyAny>>,
    method: &str,
    beta: Option<f64>,
    order: Option<u8>,
    tolerance: Option<f64>,
    threads: Option<Threads>,
) -> PyResult<Bound<'py, PyArray1<f64>>> {
    let spec = spec_of(method, beta, order, tolerance)?;
    let a = mesh_from(VA, FA, "VA", "FA")?;
    let b = Source::named(VB, FB, "classify", ["VB", "FB"])?;
    let values = threads::run(py, threads, || {
        b.with_evaluator(&spec, |wn| classify_faces(&a, wn))
    })?
    .map_err(value_error)?;
    Ok(array1(py, values))
}

/// Marks the tets whose centroid has exact winding number above ``threshold`` with respect to
/// the surface ``(V, F)`` (the front end of a tet mesher; ``gwn filter-tets``).
///
/// ``points`` (p, 3) float, ``tets`` (t, 4) int corner indices; returns a bool array (t,)
/// (``tets[mask]`` keeps the inside tets). ``tolerance`` is the exact method's boundary
/// tolerance (``gwn filter-tets --tolerance``).
#[pyfunction]
#[pyo3(signature = (V, F, points, tets, threshold = 0.5, *, method = "exact", beta = None, order = None, tolerance = None, threads = None))]
#[allow(non_snake_case, clippy::too_many_arguments)]
pub fn filter_tets<'py>(
    py: Python<'py>,
    V: &Bound<'py, PyAny>,
    F: &Bound<'py, PyAny>,
    points: &Bound<'py, PyAny>,
    tets: &Bound<'py, PyAny>,
    threshold: f64,
    method: &str,
    beta: Option<f64>,
    order: Option<u8>,
    tolerance: Option<f64>,
    threads: Option<Threads>,
) -> PyResult<Bound<'py, PyArray1<bool>>> {
    let spec = spec_of(method, beta, order, tolerance)?;
    let mesh = mesh_from(V, F, "V", "F")?;
    if !threshold.is_finite() {
        return Err(PyValueError::new_err(format!(
            "threshold must be finite, got {threshold}"
        )));
    }
    let tet_indices = indices_vec::<4>(tets, "tets")?;
    let keep = with_points::<3, _>(points, "points", |tet_points| {
        let n = tet_points.len();
        if let Some((i, t)) = tet_indices
            .iter()
            .enumerate()
            .find(|(_, t)| t.iter().any(|&c| c as usize >= n))
        {
            return Err(PyValueError::new_err(format!(
                "tets[{i}] = {t:?} references a point beyond the {n} points"
            )));
        }
        threads::run(py, threads, || {
            evaluator_for(&mesh, &spec).map(|wn| {
                gwn::products::tets::filter_tets(tet_points, &tet_indices, &wn, threshold)
            })
        })?
        .map_err(value_error)
    })?;
    Ok(PyArray1::from_vec(py, keep))
}

/// Remeshes at w = 1/2: a closed, edge- and vertex-manifold, consistently oriented surface
/// (no self-intersections) of the solid where the winding number (exact by default) is above
/// 1/2, as ``gwn remesh`` writes it.
///
/// ``res`` is the finest resolution (cells of edge longest extent / ``res``, and at least
/// ``res / 4`` cells across every axis of the box, so that a thin plate is kept); ``bisect`` the
/// placement precision (each vertex within ``cell / 2**(bisect+1)`` of where ``w`` crosses 1/2
/// along its lattice edge); ``simplify`` (default on) reduces the marching-tetrahedra surface by
/// edge collapses that keep every guarantee (each removed vertex within half a cell of the
/// result, each kept vertex then moved by at most half a cell towards the planes it replaces;
/// ``False``: the raw surface). Every solid is kept, double walls and inner faces vanish where ``w``
/// says so, holes close where ``w`` decides. Returns ``(V, F)``: float64 (n, 3) and int64
/// (m, 3), triangles counter-clockwise seen from outside. ``method``/``beta``/``order``/
/// ``tolerance`` as in :func:`voxelize`; refused (``ValueError``) when the surface would not fit
/// in memory. ``thicken=EPS`` closes open sheets (``w`` near 1/2 on both sides, no volume) into
/// slabs of half-thickness ``EPS`` where ``w`` says the surface is open, as ``gwn remesh
/// --thicken``; ``EPS`` must be at least one finest cell. ``refine_plates`` (default on) makes
/// the cells finer (at most 4 times, all axes together) across widespread plates of the input
/// thinner than two cells, as ``gwn remesh`` does (``--no-plate-refinement``).
/// ``sub_cell_levels`` (0 to 3, default 1) cuts cells that an input triangle crosses while their
/// corners agree (parts thinner than a cell) into eight, down to that many levels below
/// ``res``, as ``gwn remesh --sub-cell-levels``. ``planar_levels`` (0 to 3, default 3) keeps
/// cells up to ``2**planar_levels`` times larger whole where the input in them is flat, as many levels as a
/// probe of the input finds pay (none on curved inputs), as ``gwn remesh --planar-levels``.
/// With the exact method, a mesh that already is a closed, manifold, oriented surface without
/// self-intersections bounding ``w > 1/2`` (proved with exact tests) comes back as it is, when
/// it has at most the simplification target's faces (zero-area faces and cancelling pairs left
/// out, faces split at T-junctions; the report's ``input`` says ``kept``, or ``remeshed`` and
/// ``input_not_kept`` why); one that only self-intersects comes back cut along its
/// intersections, the pieces inside its solid left out (``cut``: the union of overlapping
/// shells, proved the same way); solids touching at a vertex or along an edge come back pulled
/// apart there by at most a 64th of a cell, twice that where a vertex is split again at an edge
/// pinched flat (``input_separated_vertices``,
/// ``input_largest_move``); faces overlapping in one plane (a part standing on a plate) are
/// replaced by what they add up to there (``input_coplanar_faces``,
/// ``input_crossing_vertices``); otherwise its clean components can come back as they are with
/// the rest remeshed (``partly kept``); an open sheet in one plane whose faces meet only at
/// shared corners and edges comes back empty at once (``planar``: ``|w| < 1/2`` everywhere,
/// proved). With ``method="parity"``, a closed, manifold mesh
/// without self-intersections comes back with its faces turned to face out of the parity's
/// solid (``reoriented``, ``input_turned_faces``; cavities inward), proved the same way.
/// ``always_remesh=True`` remeshes it all anyway, as
/// ``gwn remesh --always-remesh``. An empty output of a mesh with faces (``{w > 1/2}`` empty)
/// comes with a ``UserWarning`` saying why: an inward-wound input (``method="parity"``
/// remeshes what it encloses), or no volume (``thicken=``).
/// ``gwn.remesh(model, res=...)`` remeshes a :class:`StepModel` (``gwn.load("part.step")``)
/// the way ``gwn remesh part.step`` does: no ``F``, exact method only (``tolerance=`` as in
/// :class:`WindingNumber`), vertices placed at the model's own surface hits; ``thicken`` is
/// refused. ``report=True`` returns ``(V, F, report)``, ``report`` a dict of the members
/// ``gwn remesh --report`` writes, measured the same way (topology, exact self-intersection
/// count, sampled Hausdorff distance to the input and to where it bounds the solid, in world
/// units and cells, occupancy agreement, the run's counters and ``seconds``), with ``samples``
/// points per surface and in the box (default 10,000, at most 10,000,000; 0 measures neither
/// the distance nor the agreement). ``time_limit`` (seconds) raises ``TimeoutError`` once the
/// remesh runs past it (checked between its phases and rounds; the report is not limited).
#[pyfunction]
#[pyo3(signature = (V, F = None, res = 128, *, bisect = gwn::products::remesh::DEFAULT_BISECTION_STEPS, simplify = true, method = "exact", beta = None, order = None, tolerance = None, threads = None, thicken = None, refine_plates = true, sub_cell_levels = gwn::products::remesh::DEFAULT_SUB_CELL_LEVELS, planar_levels = gwn::products::remesh::DEFAULT_PLANAR_LEVELS, report = false, samples = 10_000, time_limit = None, always_remesh = false))]
#[allow(non_snake_case, clippy::too_many_arguments)]
pub fn remesh<'py>(
    py: Python<'py>,
    V: &Bound<'py, PyAny>,
    F: Option<&Bound<'py, PyAny>>,
    res: usize,
    bisect: u32,
    simplify: bool,
    method: &str,
    beta: Option<f64>,
    order: Option<u8>,
    tolerance: Option<f64>,
    threads: Option<Threads>,
    thicken: Option<f64>,
    refine_plates: bool,
    sub_cell_levels: u32,
    planar_levels: u32,
    report: bool,
    samples: usize,
    time_limit: Option<f64>,
    always_remesh: bool,
) -> PyResult<Bound<'py, PyTuple>> {
    use gwn::products::remesh::report::{DistanceReference, PhaseClock, RemeshReport};

    use gwn::products::remesh::keep_input::WhyEmpty;
    use gwn::products::remesh::{
        Keep, RemeshOptions, remesh_guided, remesh_mesh, reorient,
        thicken::{self, ThickenedSheets},
    };
    let method = spec_of(method, beta, order, tolerance)?;
    let options = RemeshOptions {
        resolution: res,
        bisection_steps: bisect,
        max_classified_points: None,
        simplify: simplify.then(gwn::products::remesh::simplify::SimplifyOptions::default),
        refine_plates,
        sub_cell_levels,
        planar_levels,
        probe_flatness: true,
        evaluator_crossings: true,
        // From the call: the arguments are checked and the mesh copied by now.
        deadline: crate::dataset::time_limit_of(time_limit)?
            .map(|limit| std::time::Instant::now() + limit),
    };
    let samples = if report { samples } else { 0 };
    RemeshReport::check_samples(samples)
        .map_err(|e| PyValueError::new_err(format!("samples={samples}: {e}")))?;
    if let Some(curved) = crate::patches::curved_of(V) {
        let kind = curved.kind();
        if F.is_some_and(|f| !f.is_none()) {
            return Err(PyValueError::new_err(format!(
                "remesh(model): {kind} takes no F (pass res= by name)"
            )));
        }
        if thicken.is_some() {
            return Err(PyValueError::new_err(format!(
                "thicken= needs triangles (a mesh or soup), not {kind}"
            )));
        }
        let bounds = curved.bounding_box();
        // The input's own evaluator, vertices placed at its own surface hits (as `gwn remesh
        // part.step` / `teapot.bpt`); measured against its tessellation.
        let out = threads::run(py, threads, || {
            curved.with_evaluator(&method, |wn| {
                let start = std::time::Instant::now();
                let clock = PhaseClock::start();
                let out = remesh_guided(wn, None, bounds, &options, &|phase| clock.mark(phase))?;
                let seconds = start.elapsed().as_secs_f64();
                let phase_seconds = clock.seconds();
                let surface = (report && samples > 0)
                    .then(|| curved.surface_for_distance(out.cell_size))
                    .flatten();
                let reference = surface
                    .as_ref()
                    .map_or(DistanceReference::None, DistanceReference::Curved);
                let request = report.then_some(ReportRequest {
                    options: &options,
                    reference,
                    bounds,
                    samples,
                    seconds,
                    phase_seconds,
                    thicken: None,
                });
                measured(out, wn, request)
            })?
        })?
        .map_err(remesh_error)?;
        return surface_tuple(py, out);
    }
    let Some(F) = F else {
        return Err(PyValueError::new_err(
            "remesh(V, F): F is required for a mesh (only a gwn.StepModel or gwn.PatchSet comes alone)",
        ));
    };
    let mesh = mesh_from(V, F, "V", "F")?;
    let Some(bounds) = mesh.bounding_box() else {
        return Err(PyValueError::new_err(
            "remesh needs a mesh with at least one vertex",
        ));
    };
    if let Some(eps) = thicken {
        let extent = (0..3)
            .map(|k| bounds.max[k] - bounds.min[k])
            .fold(0.0, f64::max);
        let cell = extent / res.max(1) as f64;
        // Thinner slabs can fall between the lattice points and vanish.
        if eps.is_nan() || eps < cell {
            return Err(PyValueError::new_err(format!(
                "thicken={eps} is below one finest cell ({cell:.4e} at res={res})"
            )));
        }
    }
    let out = threads::run(py, threads, || {
        let wn = evaluator_for(&mesh, &method)?;
        let thick = thicken
            .map(|eps| ThickenedSheets::new(&mesh, &*wn, eps))
            .transpose()?;
        let start = std::time::Instant::now();
        // As `gwn remesh` sets it up (the box grown by the slabs, the distance's reference).
        let thicken::MeshField {
            field,
            guide,
            bounds,
            reference,
        } = thicken::of_mesh(&mesh, &*wn, thick.as_ref(), bounds);
        let clock = PhaseClock::start();
        // As `gwn remesh`: a mesh that already bounds its `w > ½` solid is kept as it is, and
        // under the parity method a closed one that bounds its parity's solid once its faces
        // are turned is kept turned.
        let own_field = thick.is_none() && !always_remesh;
        let keep = match method.method_for(gwn::input::InputKind::Mesh) {
            gwn::spec::Method::Exact if own_field => Keep::Winding,
            gwn::spec::Method::Parity if own_field => Keep::Parity,
            _ => Keep::No,
        };
        let out = remesh_mesh(
            &mesh,
            keep,
            field,
            Some(&guide),
            bounds,
            &options,
            &|phase| clock.mark(phase),
        )?;
        let seconds = start.elapsed().as_secs_f64();
        let phase_seconds = clock.seconds();
        let request = report.then_some(ReportRequest {
            options: &options,
            reference,
            bounds,
            samples,
            seconds,
            phase_seconds,
            thicken,
        });
        let empty = (out.triangles.is_empty() && thick.is_none() && !mesh.is_empty())
            .then(|| WhyEmpty::of_mesh(&mesh, bounds, &options, out.stats.input));
        let nowhere = out.stats.input.is_some_and(|i| i.skipped_the_lattice());
        // As `gwn remesh` says it: a closed input with flipped faces has a fractional `w`.
        let exact = method.method_for(gwn::input::InputKind::Mesh) == gwn::spec::Method::Exact;
        let flipped = (exact && thick.is_none())
            .then(|| reorient::flipped_input(&mesh, method.boundary, bounds, &options))
            .flatten();
        Ok((measured(out, field, request)?, empty, nowhere, flipped))
    })?
    .map_err(remesh_error)?;
    let (out, empty, nowhere, flipped) = out;
    let warn = |message: String| {
        PyErr::warn(
            py,
            &py.get_type::<pyo3::exceptions::PyUserWarning>(),
            &std::ffi::CString::new(message).expect("no NUL in the message"),
            1,
        )
    };
    if let Some(flipped) = flipped {
        warn(format!(
            "remesh: {flipped}; {}",
            flipped.way_out("method='parity'")
        ))?;
    }
    // As `gwn remesh` prints it: an empty output is right where `w > 1/2` is empty, but rarely
    // what was meant.
    if let Some(why) = empty {
        let way_out = match why {
            WhyEmpty::WindsInward => "method='parity' remeshes the solid it encloses",
            WhyEmpty::NoVolume => "thicken=EPS closes open sheets into thin solids; a finer res",
        };
        let nowhere = if nowhere {
            "w > 1/2 nowhere"
        } else {
            "w > 1/2 at no point of the lattice"
        };
        warn(format!(
            "remesh: the output is empty: {nowhere}; {why}: {way_out}"
        ))?;
    }
    surface_tuple(py, out)
}

/// A remesh's error as a Python exception: `TimeoutError` past ``time_limit``, else
/// `ValueError`, with the library's message.
fn remesh_error(e: Box<dyn std::error::Error + Send + Sync>) -> PyErr {
    match e.downcast_ref::<gwn::products::remesh::RemeshError>() {
        Some(gwn::products::remesh::RemeshError::TimeLimit { .. }) => {
            pyo3::exceptions::PyTimeoutError::new_err(e.to_string())
        }
        _ => value_error(e),
    }
}

/// What [`measured`] measures a remesh against, and the run's facts the report carries.
struct ReportRequest<'a> {
    options: &'a gwn::products::remesh::RemeshOptions,
    reference: gwn::products::remesh::report::DistanceReference<'a>,
    bounds: gwn::BoundingBox,
    samples: usize,
    seconds: f64,
    phase_seconds: gwn::products::remesh::report::PhaseSeconds,
    thicken: Option<f64>,
}

/// A remeshed surface: its vertices, triangles and, when requested, its report
/// ([`gwn::products::remesh::report::RemeshReport::measure`] against `field`, which needs the
/// surface as a mesh too; without a report the arrays are moved out, not copied).
type Measured = (
    Vec<[f64; 3]>,
    Vec<[u32; 3]>,
    Option<gwn::products::remesh::report::RemeshReport>,
);

fn measured<E: gwn::eval::Evaluator + ?Sized>(
    mut out: gwn::products::remesh::Remeshed,
    field: &E,
    request: Option<ReportRequest<'_>>,
) -> Result<Measured, Box<dyn std::error::Error + Send + Sync>> {
    let positions = std::mem::take(&mut out.positions);
    let triangles = std::mem::take(&mut out.triangles);
    let Some(r) = request else {
        return Ok((positions, triangles, None));
    };
    let surface = gwn::Mesh::new(positions, triangles)?;
    let mut report = gwn::products::remesh::report::RemeshReport::measure(
        &out,
        &surface,
        r.options,
        field,
        r.reference,
        r.bounds,
        r.samples,
        &|_| {},
    )?;
    report.seconds = r.seconds;
    report.phase_seconds = Some(r.phase_seconds);
    report.thicken = r.thicken;
    Ok((
        surface.positions().to_vec(),
        surface.triangles().to_vec(),
        Some(report),
    ))
}

/// `(V, F)`: float64 (n, 3) and int64 (m, 3); with a report, `(V, F, report)`, the report a
/// dict of the members `gwn remesh --report` writes.
fn surface_tuple<'py>(
    py: Python<'py>,
    (positions, triangles, report): Measured,
) -> PyResult<Bound<'py, PyTuple>> {
    let triangles: Vec<[i64; 3]> = triangles.iter().map(|t| t.map(i64::from)).collect();
    let v = array2(py, positions)?;
    let f = array2(py, triangles)?;
    match report {
        None => PyTuple::new(py, [v, f]),
        Some(r) => {
            let dict = py.import("json")?.call_method1("loads", (r.to_json(),))?;
            PyTuple::new(py, [v, f, dict])
        }
    }
}
