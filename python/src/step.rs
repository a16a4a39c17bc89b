//! `gwn.StepModel`: a trimmed B-rep model read from a STEP file (`gwn.load("part.step")`),
//! evaluated by `gwn.WindingNumber(model)` with the CLI's options and errors.

use std::path::PathBuf;
use std::sync::Arc;

use gwn::input::{Input, InputError};
use gwn::patch::step::{StepError, StepModel};
use pyo3::exceptions::PyRuntimeWarning;
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyTuple};

use crate::arrays::box_corners;
use crate::errors::os_error;
use crate::evaluator::Certified;

/// A STEP file that cannot be read is an `OSError` (`FileNotFoundError` when missing,
/// `PermissionError` when not readable); one that is read but is not a supported B-rep model is
/// a `ValueError`. Both carry the CLI's one-line message, which names the file.
pub fn step_error(e: StepError) -> PyErr {
    match &e {
        StepError::Io { kind, .. } => os_error(*kind, e.to_string()),
        _ => pyo3::exceptions::PyValueError::new_err(e.to_string()),
    }
}

/// Reads a STEP model (the body of `gwn.load` for `.step`/`.stp`) through the library's front
/// door, `gwn::input::load_input`, as the CLI does.
pub fn load_step_model(py: Python<'_>, path: PathBuf) -> PyResult<PyStepModel> {
    let loaded = py
        .allow_threads(|| gwn::input::load_input(&path))
        .map_err(|e| match e {
            InputError::Step(e) => step_error(e),
            other => pyo3::exceptions::PyValueError::new_err(other.to_string()),
        })?;
    match loaded.input {
        Input::Step(model) => Ok(PyStepModel {
            model: Arc::new(*model),
            path,
        }),
        other => Err(pyo3::exceptions::PyValueError::new_err(format!(
            "{}: read as {}, not a STEP model",
            path.display(),
            other.kind()
        ))),
    }
}

/// A trimmed B-rep model read from an ISO 10303-21 (STEP) file by :func:`gwn.load`: its faces
/// as trimmed rational Bézier patches and its surface boundary (edges no other face shares).
/// Evaluate it with ``gwn.WindingNumber(model, tolerance=1e-10)``. Coordinates are in the
/// file's own length unit (:attr:`info` ``["unit"]``). Pickles by its path (the file is read
/// again on unpickling).
#[pyclass(module = "gwn", name = "StepModel", frozen)]
pub struct PyStepModel {
    pub(crate) model: Arc<StepModel>,
    path: PathBuf,
}

#[pymethods]
impl PyStepModel {
    /// The path the model was read from.
    #[getter]
    pub fn path(&self) -> PathBuf {
        self.path.clone()
    }

    /// Counts as ``gwn info`` prints them: ``faces``, ``patches``, ``surfaces`` (faces per
    /// surface kind), ``edges``, ``boundary_edges`` (edge uses left as the surface boundary),
    /// ``cancelled_exact``/``cancelled_matched`` (shared-edge pairs), ``trim_segments``,
    /// ``pcurve_uses`` (edge uses trimmed by the file's pcurve), ``pcurves_rejected`` (pcurves
    /// straying from their 3D edge, mapped from 3D instead), ``pcurves_unreadable``,
    /// ``solids``, ``shells``, ``unit``.
    #[getter]
    fn info<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        let i = self.model.info();
        let d = PyDict::new(py);
        d.set_item("faces", i.faces)?;
        d.set_item("patches", i.patches)?;
        let s = PyDict::new(py);
        for (k, v) in &i.surfaces {
            s.set_item(*k, *v)?;
        }
        d.set_item("surfaces", s)?;
        d.set_item("edges", i.edges)?;
        d.set_item("boundary_edges", i.boundary_edges)?;
        d.set_item("cancelled_exact", i.cancelled_exact)?;
        d.set_item("cancelled_matched", i.cancelled_matched)?;
        d.set_item("trim_segments", i.trim_segments)?;
        d.set_item("pcurve_uses", i.pcurve_uses)?;
        d.set_item("pcurves_rejected", i.pcurves_rejected)?;
        d.set_item("pcurves_unreadable", i.pcurves_unreadable)?;
        d.set_item("solids", i.topology.solids)?;
        d.set_item("shells", i.topology.shells)?;
        d.set_item("unit", i.topology.length_unit.clone())?;
        Ok(d)
    }

    /// ``True`` when every edge use cancels against another (no surface boundary): the winding
    /// number is then an exact integer off the surface.
    #[getter]
    fn closed(&self) -> bool {
        self.model.boundary().is_empty()
    }

    /// ``(lo, hi)``: float64 (3,) corners of a box containing the model.
    #[getter]
    fn bounding_box<'py>(&self, py: Python<'py>) -> (Bound<'py, PyAny>, Bound<'py, PyAny>) {
        box_corners(py, self.model.bounding_box())
    }

    fn __repr__(&self) -> String {
        let i = self.model.info();
        format!(
            "gwn.StepModel({:?}, faces={}, patches={}, boundary_edges={})",
            self.path.display().to_string(),
            i.faces,
            i.patches,
            i.boundary_edges
        )
    }

    /// Pickles by the path: unpickling reads the file again.
    fn __reduce__<'py>(
        &self,
        py: Python<'py>,
    ) -> PyResult<(Bound<'py, PyAny>, Bound<'py, PyTuple>)> {
        reduce_by_path(py, &self.path)
    }
}

/// `__reduce__` of a model read from a file: `gwn.load(path)` reads it again on unpickling.
pub fn reduce_by_path<'py>(
    py: Python<'py>,
    path: &std::path::Path,
) -> PyResult<(Bound<'py, PyAny>, Bound<'py, PyTuple>)> {
    let load = py.import("gwn")?.getattr("load")?;
    let args = (path.to_path_buf(),).into_pyobject(py)?;
    Ok((load, args))
}

/// Warns (``RuntimeWarning``) when some values are uncertified, with the CLI's text (`near`:
/// what such a value is near, [`crate::evaluator::Evaluator::uncertified_near`]).
pub fn warn_uncertified(py: Python<'_>, evaluations: &[Certified], near: &str) -> PyResult<()> {
    let uncertified = evaluations.iter().filter(|e| e.uncertified).count();
    if uncertified == 0 {
        return Ok(());
    }
    let worst = evaluations
        .iter()
        .filter(|e| e.uncertified)
        .fold(0.0f64, |a, e| a.max(e.error_estimate));
    let message = std::ffi::CString::new(format!(
        "{uncertified} of {} values uncertified ({near}, or work cap reached; largest error \
         estimate {worst:.1e}); see docs/patches.md",
        evaluations.len()
    ))
    .unwrap_or_default();
    PyErr::warn(
        py,
        &py.get_type::<PyRuntimeWarning>(),
        message.as_c_str(),
        1,
    )
}
