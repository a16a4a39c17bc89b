//! `gwn.PatchSet`: (rational) Bézier patches read from a `.bpt`/`.rbpt` file
//! (`gwn.load("teapot.bpt")`), evaluated by `gwn.WindingNumber(patches)` and remeshed by
//! `gwn.remesh(patches, res=...)` with the CLI's options and errors.

use std::path::PathBuf;
use std::sync::Arc;

use gwn::patch::{PatchError, PatchSet};
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyTuple};

use crate::arrays::box_corners;
use crate::errors::os_error;
use crate::evaluator::Curved;
use crate::step::{PyStepModel, reduce_by_path};

/// A patch file that cannot be read is an `OSError` (`FileNotFoundError` when missing,
/// `PermissionError` when not readable); one that is read but is not a valid patch set (or is
/// not text) is a `ValueError`. Both carry the CLI's one-line message, which names the file.
pub fn patch_error(e: PatchError) -> PyErr {
    match &e {
        PatchError::Io { kind, .. } if *kind != std::io::ErrorKind::InvalidData => {
            os_error(*kind, e.to_string())
        }
        _ => pyo3::exceptions::PyValueError::new_err(e.to_string()),
    }
}

/// The curved input `v` is, if it is a `gwn.StepModel` or `gwn.PatchSet`.
pub fn curved_of(v: &Bound<'_, PyAny>) -> Option<Curved> {
    if let Ok(model) = v.downcast::<PyStepModel>() {
        Some(Curved::Step(model.get().model.clone()))
    } else {
        v.downcast::<PyPatchSet>()
            .ok()
            .map(|set| Curved::Patches(set.get().set.clone()))
    }
}

/// Reads a patch set (the body of `gwn.load` for `.bpt`/`.rbpt`).
pub fn load_patch_set(py: Python<'_>, path: PathBuf) -> PyResult<PyPatchSet> {
    let set = py
        .allow_threads(|| gwn::patch::load_patches(&path))
        .map_err(patch_error)?;
    Ok(PyPatchSet {
        set: Arc::new(set),
        path,
    })
}

/// A set of (rational) Bézier patches read by :func:`gwn.load` from a ``.bpt`` (polynomial) or
/// ``.rbpt`` (rational) file: the curved surfaces of the Antipodal method (docs/patches.md).
/// Evaluate it with ``gwn.WindingNumber(patches, tolerance=1e-10)`` (``method="direct"``: the
/// surface quadrature) and remesh it with ``gwn.remesh(patches, res=...)``. Pickles by its path
/// (the file is read again on unpickling).
#[pyclass(module = "gwn", name = "PatchSet", frozen)]
pub struct PyPatchSet {
    pub(crate) set: Arc<PatchSet>,
    path: PathBuf,
}

#[pymethods]
impl PyPatchSet {
    /// The path the set was read from.
    #[getter]
    pub fn path(&self) -> PathBuf {
        self.path.clone()
    }

    /// ``{"patches": n, "rational": bool, "max_degree": (m, n)}``: the number of patches,
    /// whether any has weights other than 1, and the largest degree in each direction.
    #[getter]
    fn info<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        let patches = self.set.patches();
        let max_degree = patches.iter().fold((0, 0), |(m, n), p| {
            let (pm, pn) = p.degree();
            (m.max(pm), n.max(pn))
        });
        let d = PyDict::new(py);
        d.set_item("patches", patches.len())?;
        d.set_item("rational", self.set.is_rational())?;
        d.set_item("max_degree", max_degree)?;
        Ok(d)
    }

    /// ``(lo, hi)``: float64 (3,) corners of a box containing the patches (their control
    /// points' box).
    #[getter]
    fn bounding_box<'py>(&self, py: Python<'py>) -> (Bound<'py, PyAny>, Bound<'py, PyAny>) {
        box_corners(py, self.set.bounding_box())
    }

    fn __len__(&self) -> usize {
        self.set.patches().len()
    }

    fn __repr__(&self) -> String {
        format!(
            "gwn.PatchSet({:?}, patches={}, rational={})",
            self.path.display().to_string(),
            self.set.patches().len(),
            if self.set.is_rational() {
                "True"
            } else {
                "False"
            }
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
