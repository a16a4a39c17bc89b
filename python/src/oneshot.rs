//! libigl-compatible one-shot calls: same argument order and shapes as `igl.winding_number` and
//! `igl.fast_winding_number`, so that `import gwn as igl`-style swaps work for these two.

use std::sync::Arc;

use gwn::Mesh;
use gwn::eval::antipodal::{Options, WindingNumber};
use gwn::eval::fast::{FastWindingNumber, PointCloud, PointCloudWindingNumber};
use numpy::PyArray1;
use pyo3::exceptions::{PyTypeError, PyValueError};
use pyo3::prelude::*;
use pyo3::types::PyTuple;

use crate::arrays::{array1, indices_vec, is_integer_array, points_vec, values_vec, with_points};
use crate::errors::{mesh_error, value_error};
use crate::evaluator::{check_tolerance, fast_params};
use crate::threads;

/// A validated mesh from `V`, `F` arrays.
pub fn mesh_from(
    v: &Bound<'_, PyAny>,
    f: &Bound<'_, PyAny>,
    vn: &str,
    fnm: &str,
) -> PyResult<Mesh> {
    Mesh::new(points_vec(v, vn)?, indices_vec(f, fnm)?).map_err(mesh_error)
}

/// Exact generalized winding numbers of the mesh ``(V, F)`` at the rows of ``O``.
///
/// Drop-in for ``igl.winding_number(V, F, O)``: ``V`` (n, 3) float, ``F`` (m, 3) int,
/// ``O`` (k, 3) float; returns float64 (k,). Uses the exact Antipodal method (never off by an
/// integer, also on the surface). ``tolerance`` (finite, ``>= 0``, default 1e-10) is the
/// absolute tolerance on ``w`` for far boundary clusters (certified; ``0``: the flat exact loop).
/// The GIL is released; ``threads`` limits the worker threads (default: all cores).
#[pyfunction]
#[pyo3(signature = (V, F, O, threads = None, *, tolerance = 1e-10))]
#[allow(non_snake_case)]
pub fn winding_number<'py>(
    py: Python<'py>,
    V: &Bound<'py, PyAny>,
    F: &Bound<'py, PyAny>,
    O: &Bound<'py, PyAny>,
    threads: Option<usize>,
    tolerance: f64,
) -> PyResult<Bound<'py, PyArray1<f64>>> {
    let options = Options {
        tolerance: check_tolerance(tolerance).map_err(PyValueError::new_err)?,
        ..Options::default()
    };
    let mesh = mesh_from(V, F, "V", "F")?;
    let values = with_points(O, "O", |q| {
        threads::run(py, threads, || {
            WindingNumber::with_options(&mesh, options).map(|wn| wn.eval_batch(q))
        })
    })?
    .map_err(value_error)?;
    Ok(array1(py, values))
}

/// Barnes-Hut winding numbers (Barill et al. 2018), in libigl's two forms:
///
/// - ``fast_winding_number(V, F, Q, beta=2.0, order=2)``: triangle mesh or soup;
/// - ``fast_winding_number(P, N, A, Q, beta=2.0, order=2)``: oriented point cloud with areas
///   ``A`` (n,), or ``A=None`` to estimate them from the 20 nearest neighbours; the three-array
///   form ``(P, N, Q)`` (float ``N``) is the same with estimated areas.
///
/// ``expansion_order`` is accepted as libigl's name for ``order``. Returns float64 (k,).
#[pyfunction]
#[pyo3(signature = (*arrays, beta = 2.0, order = None, expansion_order = None, threads = None))]
pub fn fast_winding_number<'py>(
    py: Python<'py>,
    arrays: &Bound<'py, PyTuple>,
    beta: f64,
    order: Option<u8>,
    expansion_order: Option<u8>,
    threads: Option<usize>,
) -> PyResult<Bound<'py, PyArray1<f64>>> {
    let order = match (order, expansion_order) {
        (Some(_), Some(_)) => {
            return Err(PyTypeError::new_err(
                "give order or expansion_order, not both",
            ));
        }
        (o, e) => o.or(e).unwrap_or(2),
    };
    let params = fast_params(beta, order).map_err(PyValueError::new_err)?;
    let items: Vec<Bound<'py, PyAny>> = arrays.iter().collect();
    let values = match items.as_slice() {
        [v, f, q] if is_integer_array(f) => {
            let mesh = Arc::new(mesh_from(v, f, "V", "F")?);
            with_points(q, "Q", |q| {
                threads::run(py, threads, || {
                    FastWindingNumber::with_params(&mesh, params).eval_batch(q)
                })
            })?
        }
        [p, n, q] => cloud_values(py, p, n, None, q, params, threads)?,
        [p, n, a, q] => {
            let a = (!a.is_none()).then_some(a);
            cloud_values(py, p, n, a, q, params, threads)?
        }
        _ => {
            return Err(PyTypeError::new_err(format!(
                "fast_winding_number takes (V, F, Q) or (P, N, A, Q), got {} arrays",
                items.len()
            )));
        }
    };
    Ok(array1(py, values))
}

fn cloud_values(
    py: Python<'_>,
    p: &Bound<'_, PyAny>,
    n: &Bound<'_, PyAny>,
    a: Option<&Bound<'_, PyAny>>,
    q: &Bound<'_, PyAny>,
    params: gwn::eval::fast::FastParams,
    threads: Option<usize>,
) -> PyResult<Vec<f64>> {
    let positions = points_vec::<3>(p, "P")?;
    let normals = points_vec::<3>(n, "N")?;
    let areas = a.map(|a| values_vec(a, "A", positions.len())).transpose()?;
    let cloud = PointCloud::new(positions, normals, areas).map_err(value_error)?;
    with_points(q, "Q", |q| {
        threads::run(py, threads, || {
            PointCloudWindingNumber::with_params(&cloud, params).eval_batch(q)
        })
    })
}
