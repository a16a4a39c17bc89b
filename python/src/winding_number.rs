//! `gwn.WindingNumber`: build once, query many times from any number of Python threads.

use std::sync::Arc;

use gwn::Mesh;
use gwn::eval::fast::PointCloudWindingNumber;
use gwn::input::InputKind;
use gwn::mesh::PointCloud;
use gwn::spec::{EvaluatorSpec, Method};
use numpy::PyArray1;
use pyo3::prelude::*;
use pyo3::types::PyTuple;

use crate::arrays::{
    array1, array2, indices_vec, one_or_many, points_vec, values_out, values_vec, with_points,
};
use crate::errors::{mesh_error, value_error};
use crate::evaluator::Certified;
use crate::evaluator::{Evaluator, SpecArgs};
use crate::patches::PyPatchSet;
use crate::step::{PyStepModel, warn_uncertified};
use crate::threads::{self, Threads};

/// `WindingNumber.parts`' result: crossing counts and fractional parts.
type Parts<'py> = (Bound<'py, PyArray1<i64>>, Bound<'py, PyArray1<f64>>);

/// `WindingNumber.eval_with_bound`'s result: values and their certified bounds.
type Bounded<'py> = (Bound<'py, PyArray1<f64>>, Bound<'py, PyArray1<f64>>);

/// `WindingNumber.eval_with_status`' result: values, error estimates, uncertified flags.
type WithStatus<'py> = (
    Bound<'py, PyArray1<f64>>,
    Bound<'py, PyArray1<f64>>,
    Bound<'py, PyArray1<bool>>,
);

/// What the evaluator was built from, kept for pickling (rebuilt from these on unpickle).
#[derive(Debug)]
enum Source {
    Mesh(Arc<Mesh>),
    Cloud {
        positions: Vec<[f64; 3]>,
        /// As given (the library normalises them; normalising twice could change the last bit).
        normals: Vec<[f64; 3]>,
        /// As used: given or estimated, so that the rebuilt object skips the estimation and
        /// gives bit-identical values.
        areas: Vec<f64>,
    },
    /// A STEP model (`gwn.load("part.step")`).
    Step(Py<PyStepModel>),
    /// A patch set (`gwn.load("teapot.bpt")`).
    Patches(Py<PyPatchSet>),
}

/// Winding-number evaluator of one mesh, oriented point cloud, STEP model or patch set, built
/// once.
///
/// ``WindingNumber(V, F, method="exact", beta=None, order=None, precision=None, ray=None,
/// tolerance=None)`` (``None``: the default)
///
/// ``method``: ``"exact"`` (Antipodal method, the default), ``"direct"`` (solid-angle sum over
/// all triangles) or ``"fast"`` (Barnes-Hut with accuracy ``beta``, default 2, and expansion
/// ``order``, default 2). ``precision`` (30 or 60 bits, default 60), ``ray`` (``"+z"``,
/// ``"-x"``, ..., default ``"+z"``) and ``tolerance`` (default 1e-10) are options of the exact
/// method; an option the method does not use is a ``ValueError`` (the rules and messages of the
/// ``gwn`` command line). ``tolerance`` (finite, ``>= 0``) is the absolute tolerance on ``w`` for
/// the far boundary: far boundary clusters are replaced by a multipole expansion with a certified
/// error bound (:meth:`WindingNumber.eval_with_bound`); the integer part is always exact, ``0``
/// is the flat exact loop. Oriented point clouds: :meth:`WindingNumber.from_point_cloud`.
///
/// ``WindingNumber(model, tolerance=1e-10)`` with a :class:`StepModel` (``gwn.load("part.step")``)
/// evaluates the trimmed B-rep model as ``gwn eval part.step`` does: ``tolerance`` (``> 0``) is
/// the target error of the surface-boundary integral (closed models are exact integers off the
/// surface); ``method``, ``beta``, ``order``, ``precision`` and ``ray`` do not apply (the
/// evaluator chooses a ray per query) and must be left at their defaults. Values that could not
/// be certified (query on or within the margins of the surface or an edge) raise a
/// ``RuntimeWarning``; :meth:`WindingNumber.eval_with_status` returns the flags.
///
/// ``WindingNumber(patches, method="exact", ray=None, tolerance=1e-10)`` with a :class:`PatchSet`
/// (``gwn.load("teapot.bpt")``) evaluates the Bézier patches as ``gwn eval teapot.bpt`` does:
/// the exact method (``ray`` and ``tolerance`` apply; a closed set gives exact integers off the
/// surface, uncertified values warn as for STEP models) or ``method="direct"`` (the surface
/// quadrature, ``tolerance`` only).
///
/// Calls release the GIL; one object can be queried from several Python threads at once.
/// Objects pickle by their arrays and are rebuilt on unpickling.
#[pyclass(module = "gwn", name = "WindingNumber", frozen)]
pub struct PyWindingNumber {
    evaluator: Evaluator,
    source: Source,
    method: Method,
    /// The options it was built with (rebuilt from these on unpickling).
    spec: EvaluatorSpec,
}

impl PyWindingNumber {
    /// Builds the evaluator of a mesh given as arrays.
    fn from_mesh_arrays(
        py: Python<'_>,
        v: &Bound<'_, PyAny>,
        f: &Bound<'_, PyAny>,
        args: SpecArgs<'_>,
    ) -> PyResult<Self> {
        let spec = args.spec().map_err(value_error)?;
        let mesh =
            Arc::new(Mesh::new(points_vec(v, "V")?, indices_vec(f, "F")?).map_err(mesh_error)?);
        let evaluator = py
            .allow_threads(|| Evaluator::for_mesh(&mesh, &spec))
            .map_err(value_error)?;
        Ok(PyWindingNumber {
            evaluator,
            source: Source::Mesh(mesh),
            method: spec.method_for(InputKind::Mesh),
            spec,
        })
    }

    /// The options to rebuild this evaluator with, as `WindingNumber(V, F, ...)` takes them
    /// after the arrays: the method and, resolved to their values, the options it uses (`None`
    /// for the others).
    #[allow(clippy::type_complexity)]
    fn rebuild_options(
        &self,
    ) -> (
        &'static str,
        Option<f64>,
        Option<u8>,
        Option<u32>,
        Option<String>,
        Option<f64>,
        Option<&'static str>,
    ) {
        let exact = self.spec.exact_options();
        let fast = self.spec.fast_params();
        match self.method {
            Method::Exact => (
                "exact",
                None,
                None,
                Some(exact.precision.bits()),
                Some(exact.ray.to_string()),
                Some(exact.tolerance),
                None,
            ),
            Method::Direct => ("direct", None, None, None, None, None, None),
            Method::Parity => (
                "parity",
                None,
                None,
                Some(exact.precision.bits()),
                Some(exact.ray.to_string()),
                None,
                None,
            ),
            Method::Fast => (
                "fast",
                Some(fast.beta),
                Some(fast.order),
                None,
                None,
                None,
                Some(fast.admissibility.name()),
            ),
        }
    }

    /// Builds the evaluator of a STEP model or patch set `v` (`None` when `v` is neither): the
    /// library's rules and messages for the options (`EvaluatorSpec::check` on its input
    /// kind), plus `F` (given and not `None`), which only Python can pass.
    fn from_curved(
        py: Python<'_>,
        v: &Bound<'_, PyAny>,
        f: Option<&Bound<'_, PyAny>>,
        args: SpecArgs<'_>,
    ) -> PyResult<Option<Self>> {
        let (kind, source) = if let Ok(model) = v.downcast::<PyStepModel>() {
            (InputKind::Step, Source::Step(model.clone().unbind()))
        } else if let Ok(set) = v.downcast::<PyPatchSet>() {
            (InputKind::Patches, Source::Patches(set.clone().unbind()))
        } else {
            return Ok(None);
        };
        if f.is_some() {
            return Err(value_error(format!(
                "F does not apply to {kind} (pass it alone)"
            )));
        }
        let spec = args.spec().map_err(value_error)?;
        let evaluator = match &source {
            Source::Step(model) => {
                let shared = model.get().model.clone();
                py.allow_threads(|| Evaluator::for_step(&shared, &spec))
            }
            Source::Patches(set) => {
                let shared = set.get().set.clone();
                py.allow_threads(|| Evaluator::for_patches(&shared, &spec))
            }
            Source::Mesh(_) | Source::Cloud { .. } => unreachable!("matched above"),
        }
        .map_err(value_error)?;
        Ok(Some(PyWindingNumber {
            evaluator,
            source,
            method: spec.method_for(kind),
            spec,
        }))
    }

    /// The certified evaluations at the rows of `q` (n, 3), interruptible (`None`: this
    /// evaluator has no certificates).
    fn certified_evaluations(
        &self,
        py: Python<'_>,
        q: &Bound<'_, PyAny>,
        threads: Option<Threads>,
    ) -> PyResult<Option<Vec<Certified>>> {
        if !self.evaluator.certifies() {
            return Ok(None);
        }
        with_points(q, "Q", |q| {
            threads::run_batch(py, threads, q, |piece| {
                self.evaluator.certified_batch(piece).unwrap_or_default()
            })
        })
        .map(Some)
    }

    /// The exact evaluator and mesh, for products that need both.
    pub fn evaluator(&self) -> &Evaluator {
        &self.evaluator
    }
}

#[pymethods]
impl PyWindingNumber {
    #[new]
    #[pyo3(signature = (V, F = None, method = "exact", beta = None, order = None, precision = None, ray = None, tolerance = None, rule = None))]
    #[allow(non_snake_case, clippy::too_many_arguments)]
    fn new(
        py: Python<'_>,
        V: &Bound<'_, PyAny>,
        F: Option<&Bound<'_, PyAny>>,
        method: &str,
        beta: Option<f64>,
        order: Option<u8>,
        precision: Option<u32>,
        ray: Option<&str>,
        tolerance: Option<f64>,
        rule: Option<&str>,
    ) -> PyResult<Self> {
        let args = SpecArgs {
            method: Some(method),
            beta,
            order,
            rule,
            precision,
            ray,
            tolerance,
        };
        let F = F.filter(|f| !f.is_none());
        if let Some(curved) = Self::from_curved(py, V, F, args)? {
            return Ok(curved);
        }
        let Some(F) = F else {
            return Err(value_error(
                "F (the triangles) is required unless V is a gwn.StepModel or gwn.PatchSet",
            ));
        };
        Self::from_mesh_arrays(py, V, F, args)
    }

    /// Barnes-Hut evaluator of an oriented point cloud: positions ``P`` (n, 3), normals ``N``
    /// (n, 3; their length is ignored) and areas ``A`` (n,), estimated from the 20 nearest
    /// neighbours when ``None``. ``beta`` defaults to 2.3 (Barill et al. for points); ``rule``
    /// is the admissibility rule (``"radius"``, the default, ``"box-corner"``, ``"box-diagonal"``
    /// or ``"radius-or-box-corner"``).
    #[staticmethod]
    #[pyo3(signature = (P, N, A = None, beta = 2.3, order = 2, rule = None))]
    #[allow(non_snake_case)]
    fn from_point_cloud(
        py: Python<'_>,
        P: &Bound<'_, PyAny>,
        N: &Bound<'_, PyAny>,
        A: Option<&Bound<'_, PyAny>>,
        beta: f64,
        order: u8,
        rule: Option<&str>,
    ) -> PyResult<Self> {
        let spec = EvaluatorSpec {
            beta: Some(beta),
            order: Some(order),
            rule: rule
                .map(str::parse::<gwn::eval::fast::Admissibility>)
                .transpose()
                .map_err(value_error)?,
            ..Default::default()
        };
        spec.check(InputKind::Cloud).map_err(value_error)?;
        let params = spec.fast_params();
        let positions = points_vec::<3>(P, "P")?;
        let normals = points_vec::<3>(N, "N")?;
        let areas = A.map(|a| values_vec(a, "A", positions.len())).transpose()?;
        let cloud =
            PointCloud::new(positions.clone(), normals.clone(), areas).map_err(value_error)?;
        let fast = py.allow_threads(|| PointCloudWindingNumber::with_params(&cloud, params));
        let areas = fast.areas().to_vec();
        let evaluator = Evaluator::FastCloud(fast);
        Ok(PyWindingNumber {
            evaluator,
            source: Source::Cloud {
                positions,
                normals,
                areas,
            },
            method: Method::Fast,
            spec,
        })
    }

    /// Winding numbers at the rows of ``Q`` (n, 3): float64 array (n,); a single point of shape
    /// (3,) gives a float (as libigl). Ctrl-C interrupts a long call (``KeyboardInterrupt``).
    #[pyo3(signature = (Q, threads = None))]
    #[allow(non_snake_case)]
    fn __call__<'py>(
        &self,
        py: Python<'py>,
        Q: &Bound<'py, PyAny>,
        threads: Option<Threads>,
    ) -> PyResult<Bound<'py, PyAny>> {
        self.eval(py, Q, threads)
    }

    /// Winding numbers at the rows of ``Q`` (n, 3): float64 array (n,); a single point of shape
    /// (3,) gives a float (as libigl). The same as calling the object (``wn(Q)``), under a name
    /// that carries this docstring at run time. Ctrl-C interrupts a long call
    /// (``KeyboardInterrupt``).
    #[pyo3(signature = (Q, threads = None))]
    #[allow(non_snake_case)]
    fn eval<'py>(
        &self,
        py: Python<'py>,
        Q: &Bound<'py, PyAny>,
        threads: Option<Threads>,
    ) -> PyResult<Bound<'py, PyAny>> {
        let (q, single) = one_or_many::<3>(Q, "Q")?;
        if let Some(evaluations) = self.certified_evaluations(py, &q, threads)? {
            warn_uncertified(py, &evaluations, self.evaluator.uncertified_near())?;
            let values = evaluations.iter().map(|e| e.value).collect();
            return values_out(py, values, single);
        }
        let values = with_points(&q, "Q", |q| {
            threads::run_batch(py, threads, q, |piece| self.evaluator.eval_batch(piece))
        })?;
        values_out(py, values, single)
    }

    /// STEP models and patch sets (exact method): ``(w, error, uncertified)`` at the rows of
    /// ``Q`` (n, 3): float64 (n,) values (as ``self(Q)``, without the warning), float64 (n,)
    /// error estimates of the boundary integral, bool (n,) flags of the values that could not
    /// be certified (query on or within the margins of the surface or an edge, or the work cap
    /// reached; see docs/patches.md). ``ValueError`` for the mesh, point-cloud and direct
    /// evaluators.
    #[pyo3(signature = (Q, threads = None))]
    #[allow(non_snake_case)]
    fn eval_with_status<'py>(
        &self,
        py: Python<'py>,
        Q: &Bound<'py, PyAny>,
        threads: Option<Threads>,
    ) -> PyResult<WithStatus<'py>> {
        let Some(evaluations) = self.certified_evaluations(py, Q, threads)? else {
            return Err(value_error(crate::evaluator::Unsupported {
                what: "eval_with_status",
                method: "mesh, point-cloud or direct",
            }));
        };
        Ok((
            array1(py, evaluations.iter().map(|e| e.value).collect()),
            array1(py, evaluations.iter().map(|e| e.error_estimate).collect()),
            PyArray1::from_vec(py, evaluations.iter().map(|e| e.uncertified).collect()),
        ))
    }

    /// Gradients of the winding number at the rows of ``Q`` (n, 3): float64 array (n, 3).
    /// Exact and direct methods only (``ValueError`` for ``"fast"``).
    #[pyo3(signature = (Q, threads = None))]
    #[allow(non_snake_case)]
    fn gradient<'py>(
        &self,
        py: Python<'py>,
        Q: &Bound<'py, PyAny>,
        threads: Option<Threads>,
    ) -> PyResult<Bound<'py, PyAny>> {
        self.evaluator.gradient_batch(&[]).map_err(value_error)?;
        let grads = with_points(Q, "Q", |q| {
            threads::run_batch(py, threads, q, |piece| {
                // Supported (checked above): the error cannot occur here.
                self.evaluator.gradient_batch(piece).unwrap_or_default()
            })
        })?;
        array2(py, grads)
    }

    /// Integer and fractional parts of the winding number at the rows of ``Q`` (exact method):
    /// ``(chi, fraction)`` with ``chi`` int64 (n,) the signed crossing count of the ray and
    /// ``fraction`` float64 (n,) the boundary term, so that ``chi + fraction == wn(Q)`` bit for
    /// bit. For a closed mesh ``fraction`` is 0 and ``chi`` is the exact winding number.
    #[pyo3(signature = (Q, threads = None))]
    #[allow(non_snake_case)]
    fn parts<'py>(
        &self,
        py: Python<'py>,
        Q: &Bound<'py, PyAny>,
        threads: Option<Threads>,
    ) -> PyResult<Parts<'py>> {
        self.evaluator.parts_batch(&[]).map_err(value_error)?;
        let (chi, fraction): (Vec<i64>, Vec<f64>) = with_points(Q, "Q", |q| {
            threads::run_batch(py, threads, q, |piece| {
                let (chi, fraction) = self.evaluator.parts_batch(piece).unwrap_or_default();
                chi.into_iter().zip(fraction).collect()
            })
        })?
        .into_iter()
        .unzip();
        Ok((PyArray1::from_vec(py, chi), array1(py, fraction)))
    }

    /// Winding numbers and certified error bounds at the rows of ``Q`` (n, 3) (exact method):
    /// ``(w, bound)``, both float64 (n,), with ``|w - w_flat| <= bound <= tolerance`` where
    /// ``w_flat`` is the flat exact loop (``tolerance=0``). ``bound`` is 0 where no far boundary
    /// cluster was expanded; ``w`` equals ``self(Q)`` bit for bit.
    #[pyo3(signature = (Q, threads = None))]
    #[allow(non_snake_case)]
    fn eval_with_bound<'py>(
        &self,
        py: Python<'py>,
        Q: &Bound<'py, PyAny>,
        threads: Option<Threads>,
    ) -> PyResult<Bounded<'py>> {
        self.evaluator.bound_batch(&[]).map_err(value_error)?;
        let (values, bounds): (Vec<f64>, Vec<f64>) = with_points(Q, "Q", |q| {
            threads::run_batch(py, threads, q, |piece| {
                let (values, bounds) = self.evaluator.bound_batch(piece).unwrap_or_default();
                values.into_iter().zip(bounds).collect()
            })
        })?
        .into_iter()
        .unzip();
        Ok((array1(py, values), array1(py, bounds)))
    }

    /// ``"exact"``, ``"direct"`` or ``"fast"``.
    #[getter]
    fn method(&self) -> &'static str {
        self.method.name()
    }

    /// Number of triangles (0 for a point cloud; B-rep faces for a STEP model).
    #[getter]
    fn face_count(&self) -> usize {
        match &self.source {
            Source::Mesh(m) => m.triangles().len(),
            Source::Cloud { .. } => 0,
            Source::Step(m) => m.get().model.info().faces,
            Source::Patches(p) => p.get().set.patches().len(),
        }
    }

    /// The exact method's boundary tolerance (``None`` for the other methods).
    #[getter]
    fn tolerance(&self) -> Option<f64> {
        (self.method == Method::Exact).then_some(self.spec.exact_options().tolerance)
    }

    /// Number of boundary edges of the exact method's signed boundary (``None`` for the other
    /// methods).
    #[getter]
    fn boundary_edge_count(&self) -> Option<usize> {
        self.evaluator.boundary_edge_count()
    }

    fn __repr__(&self) -> String {
        match &self.source {
            Source::Mesh(m) => format!(
                "gwn.WindingNumber(method={:?}, vertices={}, faces={})",
                self.method.name(),
                m.positions().len(),
                m.triangles().len()
            ),
            Source::Cloud { positions, .. } => format!(
                "gwn.WindingNumber(method=\"fast\", points={})",
                positions.len()
            ),
            Source::Step(m) => format!(
                "gwn.WindingNumber(step={:?}, faces={}, tolerance={:e})",
                m.get().path().display().to_string(),
                m.get().model.info().faces,
                self.spec.step_options().tolerance
            ),
            Source::Patches(p) => format!(
                "gwn.WindingNumber(patch_set={:?}, method={:?}, patches={}, tolerance={:e})",
                p.get().path().display().to_string(),
                self.method.name(),
                p.get().set.patches().len(),
                self.spec.patch_options().tolerance
            ),
        }
    }

    /// Pickles by the source arrays and the options; unpickling rebuilds the evaluator
    /// (see docs/python.md for why rebuilding was chosen over serializing the built index).
    fn __reduce__<'py>(
        &self,
        py: Python<'py>,
    ) -> PyResult<(Bound<'py, PyAny>, Bound<'py, PyTuple>)> {
        match &self.source {
            Source::Mesh(m) => {
                let cls = py.get_type::<PyWindingNumber>().into_any();
                let (method, beta, order, precision, ray, tolerance, rule) = self.rebuild_options();
                let args = (
                    array2(py, m.positions().to_vec())?,
                    array2(py, m.triangles().to_vec())?,
                    method,
                    beta,
                    order,
                    precision,
                    ray,
                    tolerance,
                    rule,
                )
                    .into_pyobject(py)?;
                Ok((cls, args))
            }
            Source::Cloud {
                positions,
                normals,
                areas,
            } => {
                let rebuild = py
                    .get_type::<PyWindingNumber>()
                    .getattr("from_point_cloud")?;
                let args = (
                    array2(py, positions.clone())?,
                    array2(py, normals.clone())?,
                    array1(py, areas.clone()),
                    self.spec.fast_params().beta,
                    self.spec.fast_params().order,
                    self.spec.fast_params().admissibility.name(),
                )
                    .into_pyobject(py)?;
                Ok((rebuild, args))
            }
            Source::Step(m) => {
                let cls = py.get_type::<PyWindingNumber>().into_any();
                // Only the tolerance applies to STEP models (the spec refuses the others).
                let args = (
                    m.clone_ref(py),
                    py.None(),
                    self.method.name(),
                    None::<f64>,
                    None::<u8>,
                    None::<u32>,
                    None::<String>,
                    self.spec.step_options().tolerance,
                    None::<String>,
                )
                    .into_pyobject(py)?;
                Ok((cls, args))
            }
            Source::Patches(p) => {
                let cls = py.get_type::<PyWindingNumber>().into_any();
                // The ray applies to the exact method only, the tolerance to both.
                let options = self.spec.patch_options();
                let ray = (self.method == Method::Exact).then(|| options.ray.to_string());
                let args = (
                    p.clone_ref(py),
                    py.None(),
                    self.method.name(),
                    None::<f64>,
                    None::<u8>,
                    None::<u32>,
                    ray,
                    options.tolerance,
                    None::<String>,
                )
                    .into_pyobject(py)?;
                Ok((cls, args))
            }
        }
    }
}
