//! Readers for every file kind the CLI reads, returning numpy arrays.

use std::path::PathBuf;

use gwn::io::LoadOptions;
use numpy::PyArray1;
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;
use pyo3::types::{PyList, PyTuple};

use crate::arrays::{array1, array2};
use crate::errors::{load_error, os_error, value_error};
use crate::patches::load_patch_set;
use crate::step::load_step_model;

fn widen<const N: usize>(rows: Vec<[u32; N]>) -> Vec<[i64; N]> {
    rows.into_iter().map(|r| r.map(i64::from)).collect()
}

/// Reads a triangle mesh (OBJ, STL ascii/binary, OFF, PLY ascii/binary, glTF/GLB; format by
/// extension, else by content) as ``(V, F)``: float64 (n, 3) and int64 (m, 3). Polygons are
/// fan-triangulated. ``weld``: merge bit-identical vertices (default: on for STL and glTF/GLB only).
/// A STEP file (``.step``/``.stp``: trimmed B-rep, AP203/AP214/AP242) gives a
/// :class:`StepModel` instead, and a patch file (``.bpt``/``.rbpt``: Bézier patches) a
/// :class:`PatchSet`, for ``WindingNumber(model)`` and ``remesh(model, res=...)``.
/// ``OSError`` when the file (or a glTF buffer file it refers to) cannot be read:
/// ``FileNotFoundError`` when missing, ``PermissionError`` when not readable; ``ValueError`` when
/// it is not a valid mesh (or STEP model: the message names the entity and its ``#id``; or
/// patch set: the line).
#[pyfunction]
#[pyo3(signature = (path, weld = None))]
pub fn load<'py>(
    py: Python<'py>,
    path: PathBuf,
    weld: Option<bool>,
) -> PyResult<Bound<'py, PyAny>> {
    if gwn::patch::step::is_step_path(&path) {
        if weld.is_some() {
            return Err(PyValueError::new_err(
                "weld does not apply to STEP models (their faces are trimmed surfaces)",
            ));
        }
        return Ok(Bound::new(py, load_step_model(py, path)?)?.into_any());
    }
    if gwn::patch::is_patch_path(&path) {
        if weld.is_some() {
            return Err(PyValueError::new_err(
                "weld does not apply to patch sets (their patches are curved surfaces)",
            ));
        }
        return Ok(Bound::new(py, load_patch_set(py, path)?)?.into_any());
    }
    let loaded = py
        .allow_threads(|| gwn::io::load_mesh_with(&path, &LoadOptions { weld }))
        .map_err(load_error)?;
    let positions = loaded.mesh.positions().to_vec();
    let triangles = widen(loaded.mesh.triangles().to_vec());
    Ok(PyTuple::new(py, [array2(py, positions)?, array2(py, triangles)?])?.into_any())
}

/// Reads an oriented point cloud (text ``x y z nx ny nz [area]`` as .xyz/.csv/.txt/.pts, or a
/// PLY with normals) as ``(P, N, A)``: float64 (n, 3), (n, 3) unit normals, and (n,) areas or
/// ``None`` when the file has none.
#[pyfunction]
#[allow(clippy::type_complexity)]
pub fn load_point_cloud<'py>(
    py: Python<'py>,
    path: PathBuf,
) -> PyResult<(
    Bound<'py, PyAny>,
    Bound<'py, PyAny>,
    Option<Bound<'py, PyArray1<f64>>>,
)> {
    let cloud = py
        .allow_threads(|| gwn::io::cloud::load_point_cloud(&path))
        .map_err(load_error)?;
    Ok((
        array2(py, cloud.positions().to_vec())?,
        array2(py, cloud.normals().to_vec())?,
        cloud.areas().map(|a| array1(py, a.to_vec())),
    ))
}

/// Reads query points (text ``x y z`` / ``x,y,z`` per line, or ``.npy`` float (n, 3)) as
/// float64 (n, 3).
#[pyfunction]
pub fn load_points<'py>(py: Python<'py>, path: PathBuf) -> PyResult<Bound<'py, PyAny>> {
    let points = py
        .allow_threads(|| gwn::io::points::load_points(&path))
        .map_err(load_error)?;
    array2(py, points)
}

/// Reads a tetrahedral mesh (MEDIT ``.mesh`` or TetGen ``.node``/``.ele``) as
/// ``(points, tets, refs)``: float64 (p, 3), int64 (t, 4) 0-based corners, int64 (t,) region
/// references (0 for TetGen).
#[pyfunction]
#[allow(clippy::type_complexity)]
pub fn load_tets<'py>(
    py: Python<'py>,
    path: PathBuf,
) -> PyResult<(
    Bound<'py, PyAny>,
    Bound<'py, PyAny>,
    Bound<'py, PyArray1<i64>>,
)> {
    let tets = py
        .allow_threads(|| gwn::io::tets::load_tets(&path))
        .map_err(|e| {
            if path.exists() {
                value_error(e)
            } else {
                os_error(std::io::ErrorKind::NotFound, e.to_string())
            }
        })?;
    Ok((
        array2(py, tets.points)?,
        array2(py, widen(tets.tets))?,
        PyArray1::from_vec(py, tets.refs),
    ))
}

/// Reads a 2D polygon (text loops separated by blank lines, or the paths of an SVG) as a list of
/// float64 (n_i, 2) arrays, one per closed loop: the input :func:`gauwn` takes.
#[pyfunction]
pub fn load_polygon<'py>(py: Python<'py>, path: PathBuf) -> PyResult<Bound<'py, PyList>> {
    if !path.exists() {
        return Err(os_error(
            std::io::ErrorKind::NotFound,
            format!("{}: no such file", path.display()),
        ));
    }
    let poly = py
        .allow_threads(|| gwn::curve2d::io::read_polygon(&path))
        .map_err(|e| PyValueError::new_err(e.to_string()))?;
    let loops = (0..poly.num_loops())
        .map(|k| array2(py, poly.loop_points(k).to_vec()))
        .collect::<PyResult<Vec<_>>>()?;
    PyList::new(py, loops)
}
