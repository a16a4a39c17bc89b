//! libigl-compatible one-shot calls: same argument order and shapes as `igl.winding_number` and
//! `igl.fast_winding_number`, so that `import gwn as igl`-style swaps work for these two.

use std::sync::Arc;

use gwn::Mesh;
use gwn::eval::antipodal::WindingNumber;
use gwn::eval::fast::{FastWindingNumber, PointCloudWindingNumber};
use gwn::mesh::PointCloud;
use numpy::PyArray1;
use pyo3::exceptions::PyTypeError;
use pyo3::prelude::*;
use pyo3::types::{PyFloat, PyInt, PyTuple};

use crate::arrays::{
    array1, indices_vec, is_integer_array, one_or_many, points_vec, values_out, values_vec,
    with_points,
};
use crate::errors::{mesh_error, value_error};
use crate::products::exact_options;
use crate::threads::{self, Threads};

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
/// ``O`` (k, 3) float; returns float64 (k,), or a float for a single point ``O`` of shape (3,).
/// Uses the exact Antipodal method (never off by an integer, also on the surface; on-surface
/// values follow a rule of their own, see docs/python.md). ``tolerance`` (finite, ``>= 0``,
/// default 1e-10) is the absolute tolerance on ``w`` for far boundary clusters (certified;
/// ``0``: the flat exact loop). The GIL is released; ``threads`` limits the worker threads
/// (default: all cores); Ctrl-C interrupts a long call (``KeyboardInterrupt``).
#[pyfunction]
#[pyo3(signature = (V, F, O, threads = None, *, tolerance = 1e-10))]
#[allow(non_snake_case)]
pub fn winding_number<'py>(
    py: Python<'py>,
    V: &Bound<'py, PyAny>,
    F: &Bound<'py, PyAny>,
    O: &Bound<'py, PyAny>,
    threads: Option<Threads>,
    tolerance: f64,
) -> PyResult<Bound<'py, PyAny>> {
    let options = exact_options(tolerance)?;
    let mesh = mesh_from(V, F, "V", "F")?;
    let (o, single) = one_or_many::<3>(O, "O")?;
    let values = with_points(&o, "O", |q| {
        let wn = threads::run(py, threads, || WindingNumber::with_options(&mesh, options))?
            .map_err(value_error)?;
        threads::run_batch(py, threads, q, |piece| wn.eval_batch(piece))
    })?;
    values_out(py, values, single)
}

/// Barnes-Hut winding numbers (Barill et al. 2018), in libigl's two forms:
///
/// - ``fast_winding_number(V, F, Q, expansion_order=2, beta=2.0)``: triangle mesh or soup;
/// - ``fast_winding_number(P, N, A, Q, expansion_order=2, beta=2.0)``: oriented point cloud with
///   areas ``A`` (n,), or ``A=None`` to estimate them from the 20 nearest neighbours; the
///   three-array form ``(P, N, Q)`` (float ``N``) is the same with estimated areas.
///
/// As in libigl, the expansion order and ``beta`` may follow the arrays positionally
/// (``fast_winding_number(P, N, A, Q, 2, 2.0)``); ``order=`` is accepted as a shorter name of
/// ``expansion_order``. Defaults: order 2, ``beta`` 2.0. ``rule`` is the admissibility rule
/// (``"radius"``, Barill's, the default; ``"box-corner"``, libigl's; ``"box-diagonal"``;
/// ``"radius-or-box-corner"``: at ``beta=2.8`` as accurate as libigl's default on the shared
/// corpus, and faster; docs/fast.md). Returns float64 (k,). Ctrl-C interrupts a long call
/// (``KeyboardInterrupt``).
#[pyfunction]
#[pyo3(signature = (*arrays, beta = None, order = None, expansion_order = None, threads = None, rule = None))]
pub fn fast_winding_number<'py>(
    py: Python<'py>,
    arrays: &Bound<'py, PyTuple>,
    beta: Option<f64>,
    order: Option<u8>,
    expansion_order: Option<u8>,
    threads: Option<Threads>,
    rule: Option<&str>,
) -> PyResult<Bound<'py, PyArray1<f64>>> {
    let mut items: Vec<Bound<'py, PyAny>> = arrays.iter().collect();
    // libigl's trailing positional `expansion_order, beta`: at most two numbers after the arrays
    // (the arrays themselves are never plain numbers).
    let mut trailing: Vec<Bound<'py, PyAny>> = Vec::new();
    while items.len() > 3 && trailing.len() < 2 && items.last().is_some_and(is_number) {
        trailing.insert(0, items.pop().expect("checked"));
    }
    let positional_order = trailing.first().map(|o| o.extract::<u8>()).transpose()?;
    let positional_beta = trailing.get(1).map(|b| b.extract::<f64>()).transpose()?;
    let orders_given = [order, expansion_order, positional_order]
        .iter()
        .filter(|o| o.is_some())
        .count();
    if orders_given > 1 {
        return Err(PyTypeError::new_err(
            "give order or expansion_order (or libigl's positional order), not both",
        ));
    }
    if beta.is_some() && positional_beta.is_some() {
        return Err(PyTypeError::new_err(
            "beta given both positionally and as beta=",
        ));
    }
    let order = order.or(expansion_order).or(positional_order).unwrap_or(2);
    let beta = beta.or(positional_beta).unwrap_or(2.0);
    let spec = gwn::spec::EvaluatorSpec {
        method: Some(gwn::spec::Method::Fast),
        beta: Some(beta),
        order: Some(order),
        rule: rule
            .map(str::parse::<gwn::eval::fast::Admissibility>)
            .transpose()
            .map_err(value_error)?,
        ..Default::default()
    };
    spec.validate().map_err(value_error)?;
    let params = spec.fast_params();
    let values = match items.as_slice() {
        [v, f, q] if is_integer_array(f) => {
            let mesh = Arc::new(mesh_from(v, f, "V", "F")?);
            with_points(q, "Q", |q| {
                let fast = threads::run(py, threads, || {
                    FastWindingNumber::with_params(&mesh, params)
                })?;
                threads::run_batch(py, threads, q, |piece| fast.eval_batch(piece))
            })?
        }
        [p, n, q] => cloud_values(py, p, n, None, q, params, threads)?,
        [p, n, a, q] => {
            let a = (!a.is_none()).then_some(a);
            cloud_values(py, p, n, a, q, params, threads)?
        }
        _ => {
            return Err(PyTypeError::new_err(format!(
                "fast_winding_number takes (V, F, Q) or (P, N, A, Q), optionally followed by \
                 expansion_order and beta; got {} arrays",
                items.len()
            )));
        }
    };
    Ok(array1(py, values))
}

/// A Python int or float (or numpy scalar), not an array or a list.
fn is_number(obj: &Bound<'_, PyAny>) -> bool {
    obj.is_instance_of::<PyInt>()
        || obj.is_instance_of::<PyFloat>()
        || obj
            .getattr("ndim")
            .and_then(|d| d.extract::<usize>())
            .is_ok_and(|d| d == 0)
}

fn cloud_values(
    py: Python<'_>,
    p: &Bound<'_, PyAny>,
    n: &Bound<'_, PyAny>,
    a: Option<&Bound<'_, PyAny>>,
    q: &Bound<'_, PyAny>,
    params: gwn::eval::fast::FastParams,
    threads: Option<Threads>,
) -> PyResult<Vec<f64>> {
    let positions = points_vec::<3>(p, "P")?;
    let normals = points_vec::<3>(n, "N")?;
    let areas = a.map(|a| values_vec(a, "A", positions.len())).transpose()?;
    let cloud = PointCloud::new(positions, normals, areas).map_err(value_error)?;
    with_points(q, "Q", |q| {
        let fast = threads::run(py, threads, || {
            PointCloudWindingNumber::with_params(&cloud, params)
        })?;
        threads::run_batch(py, threads, q, |piece| fast.eval_batch(piece))
    })
}
