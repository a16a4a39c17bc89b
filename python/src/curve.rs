//! 2D: GauWN, the Gaussian-smoothed winding number of polygons (Sun et al. 2024), and its
//! spatial gradient, with the library's closed forms.

use gwn::curve2d::polygon::{MAX_COORD, query_in_range};
use gwn::curve2d::{GauWn, Point, Polygon};
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;
use pyo3::types::{PyList, PyTuple};
use rayon::prelude::*;

use crate::arrays::{array1, array2, points_vec, with_points};
use crate::errors::value_error;
use crate::threads::{self, Threads};

/// The loops of `polygon`: one `(n, 2)` array, or a list/tuple of them.
fn loops_of(polygon: &Bound<'_, PyAny>) -> PyResult<Vec<Vec<Point>>> {
    let is_sequence = polygon.downcast::<PyList>().is_ok() || polygon.downcast::<PyTuple>().is_ok();
    if is_sequence {
        let numpy = polygon.py().import("numpy")?;
        let first_is_loop = polygon
            .try_iter()?
            .next()
            .transpose()?
            .map(|first| numpy.call_method1("ndim", (first,))?.extract::<usize>())
            .transpose()?
            == Some(2);
        if first_is_loop {
            return polygon
                .try_iter()?
                .enumerate()
                .map(|(k, l)| points_vec::<2>(&l?, &format!("polygon[{k}]")))
                .collect();
        }
    }
    Ok(vec![points_vec::<2>(polygon, "polygon")?])
}

/// Gaussian-smoothed winding number ``W_sigma`` of a polygon at the rows of ``Q`` (k, 2).
///
/// ``polygon``: one closed loop as a float (n, 2) array (the last vertex connects to the first),
/// or a list of such loops. ``sigma`` > 0 is the standard deviation of the Gaussian. Returns
/// float64 (k,), or ``(values, gradients)`` with the spatial gradient float64 (k, 2) when
/// ``gradient=True``. Closed forms of Sun et al. 2024 (no quadrature, no hierarchy).
/// Coordinates of the polygon and of ``Q`` must be at most 1e100 in magnitude (``ValueError``
/// beyond). Ctrl-C interrupts a long call (``KeyboardInterrupt``).
#[pyfunction]
#[pyo3(signature = (polygon, sigma, Q, *, gradient = false, threads = None))]
#[allow(non_snake_case)]
pub fn gauwn<'py>(
    py: Python<'py>,
    polygon: &Bound<'py, PyAny>,
    sigma: f64,
    Q: &Bound<'py, PyAny>,
    gradient: bool,
    threads: Option<Threads>,
) -> PyResult<Bound<'py, PyAny>> {
    if !(sigma.is_finite() && sigma > 0.0) {
        return Err(PyValueError::new_err(format!(
            "sigma must be a positive finite number, got {sigma}"
        )));
    }
    let poly = Polygon::new(loops_of(polygon)?).map_err(value_error)?;
    let g = GauWn::new(sigma);
    let (values, grads) = with_points::<2, _>(Q, "Q", |q| {
        if let Some(i) = q.iter().position(|&p| !query_in_range(p)) {
            return Err(PyValueError::new_err(format!(
                "Q[{i}] = {:?} exceeds {MAX_COORD:e} in magnitude (the 2D limit)",
                q[i]
            )));
        }
        let values = threads::run_batch(py, threads, q, |piece| {
            piece.par_iter().map(|&p| g.value(&poly, p)).collect()
        })?;
        let grads = gradient
            .then(|| {
                threads::run_batch(py, threads, q, |piece| {
                    piece.par_iter().map(|&p| g.gradient(&poly, p)).collect()
                })
            })
            .transpose()?;
        Ok((values, grads))
    })?;
    let values = array1(py, values).into_any();
    match grads {
        Some(g) => Ok((values, array2(py, g)?).into_pyobject(py)?.into_any()),
        None => Ok(values),
    }
}
