//! numpy arrays in and out.
//!
//! In: float32/float64 coordinates and int32/int64/uint32/uint64 indices, any strides, any
//! object `numpy.asarray` accepts. A C-contiguous float64 query array is borrowed without a copy;
//! everything else is converted once. Wrong shapes and non-finite values are `ValueError`s, wrong
//! dtypes `TypeError`s, each naming the argument.
//!
//! Out: float64 arrays that take ownership of the Rust `Vec` (no copy).

use numpy::ndarray::ArrayView2;
use numpy::{Element, PyArray1, PyArray2, PyArrayMethods, PyUntypedArray, PyUntypedArrayMethods};
use pyo3::exceptions::{PyTypeError, PyValueError};
use pyo3::prelude::*;

/// `obj` as a numpy array (itself when it already is one), in native byte order: a big-endian
/// array (`'>f8'`, as read from some files) is converted once, as numpy would, instead of being
/// refused as an unknown dtype.
fn as_ndarray<'py>(obj: &Bound<'py, PyAny>, name: &str) -> PyResult<Bound<'py, PyUntypedArray>> {
    if let Ok(a) = obj.downcast::<PyUntypedArray>() {
        let dtype = a.dtype();
        if dtype.getattr("isnative")?.extract::<bool>()? {
            return Ok(a.clone());
        }
        let native = dtype.call_method1("newbyteorder", ("=",))?;
        return a
            .call_method1("astype", (native,))?
            .downcast_into::<PyUntypedArray>()
            .map_err(|_| PyTypeError::new_err(format!("{name}: not convertible to an array")));
    }
    let converted = obj
        .py()
        .import("numpy")?
        .call_method1("asarray", (obj,))
        .map_err(|e| PyTypeError::new_err(format!("{name}: not convertible to an array: {e}")))?;
    converted
        .downcast_into::<PyUntypedArray>()
        .map_err(|_| PyTypeError::new_err(format!("{name}: not convertible to an array")))
}

/// The number of rows of a 2-D array with `cols` columns.
fn rows_of(a: &Bound<'_, PyUntypedArray>, name: &str, cols: usize) -> PyResult<usize> {
    let shape = a.shape();
    if shape.len() != 2 || shape[1] != cols {
        return Err(PyValueError::new_err(format!(
            "{name} must have shape (n, {cols}), got {}",
            shape_text(shape)
        )));
    }
    Ok(shape[0])
}

/// A shape as Python prints it: `(2, 2)`, `(3,)`.
fn shape_text(shape: &[usize]) -> String {
    match shape {
        [n] => format!("({n},)"),
        _ => format!(
            "({})",
            shape
                .iter()
                .map(usize::to_string)
                .collect::<Vec<_>>()
                .join(", ")
        ),
    }
}

fn dtype_name(a: &Bound<'_, PyUntypedArray>) -> String {
    a.dtype().to_string()
}

fn rows_to_vec<T: Copy, const N: usize>(
    view: ArrayView2<'_, T>,
    convert: impl Fn(T) -> f64,
) -> Vec<[f64; N]> {
    view.rows()
        .into_iter()
        .map(|r| std::array::from_fn(|j| convert(r[j])))
        .collect()
}

fn check_finite<const N: usize>(points: &[[f64; N]], name: &str) -> PyResult<()> {
    match points.iter().position(|p| p.iter().any(|c| !c.is_finite())) {
        Some(i) => Err(PyValueError::new_err(format!(
            "{name}[{i}] = {:?} is not finite",
            points[i]
        ))),
        None => Ok(()),
    }
}

/// Runs `f` on the rows of an `(n, N)` float array. A C-contiguous float64 array is borrowed in
/// place; other layouts and float32 are converted. Non-finite entries are a `ValueError`.
pub fn with_points<const N: usize, R>(
    obj: &Bound<'_, PyAny>,
    name: &str,
    f: impl FnOnce(&[[f64; N]]) -> PyResult<R>,
) -> PyResult<R> {
    let a = as_ndarray(obj, name)?;
    rows_of(&a, name, N)?;
    if let Ok(arr) = a.downcast::<PyArray2<f64>>() {
        let ro = arr.readonly();
        // `as_slice` also accepts Fortran order, whose flat memory is not row after row.
        if let (true, Ok(flat)) = (ro.is_c_contiguous(), ro.as_slice()) {
            let points: &[[f64; N]] = bytemuck::cast_slice(flat);
            check_finite(points, name)?;
            return f(points);
        }
        let points = rows_to_vec::<f64, N>(ro.as_array(), |v| v);
        check_finite(&points, name)?;
        return f(&points);
    }
    if let Ok(arr) = a.downcast::<PyArray2<f32>>() {
        let points = rows_to_vec::<f32, N>(arr.readonly().as_array(), f64::from);
        check_finite(&points, name)?;
        return f(&points);
    }
    Err(PyTypeError::new_err(format!(
        "{name} must be float32 or float64, got {}",
        dtype_name(&a)
    )))
}

/// The rows of an `(n, N)` float array, copied (for data the library takes by value).
/// Non-finite values are left to the library's own validation, which names the vertex.
pub fn points_vec<const N: usize>(obj: &Bound<'_, PyAny>, name: &str) -> PyResult<Vec<[f64; N]>> {
    let a = as_ndarray(obj, name)?;
    rows_of(&a, name, N)?;
    if let Ok(arr) = a.downcast::<PyArray2<f64>>() {
        return Ok(rows_to_vec::<f64, N>(arr.readonly().as_array(), |v| v));
    }
    if let Ok(arr) = a.downcast::<PyArray2<f32>>() {
        return Ok(rows_to_vec::<f32, N>(arr.readonly().as_array(), f64::from));
    }
    Err(PyTypeError::new_err(format!(
        "{name} must be float32 or float64, got {}",
        dtype_name(&a)
    )))
}

/// A 1-D float array of length `len`, copied; non-finite values are left to the library.
pub fn values_vec(obj: &Bound<'_, PyAny>, name: &str, len: usize) -> PyResult<Vec<f64>> {
    let a = as_ndarray(obj, name)?;
    if a.shape() != [len] {
        return Err(PyValueError::new_err(format!(
            "{name} must have shape ({len},), got {}",
            shape_text(a.shape())
        )));
    }
    if let Ok(arr) = a.downcast::<numpy::PyArray1<f64>>() {
        return Ok(arr.readonly().as_array().to_vec());
    }
    if let Ok(arr) = a.downcast::<numpy::PyArray1<f32>>() {
        return Ok(arr
            .readonly()
            .as_array()
            .iter()
            .map(|&v| f64::from(v))
            .collect());
    }
    Err(PyTypeError::new_err(format!(
        "{name} must be float32 or float64, got {}",
        dtype_name(&a)
    )))
}

fn index_rows<T, const N: usize>(view: ArrayView2<'_, T>, name: &str) -> PyResult<Vec<[u32; N]>>
where
    T: Copy + std::fmt::Display + TryInto<u32>,
{
    let mut out = Vec::with_capacity(view.nrows());
    for (i, r) in view.rows().into_iter().enumerate() {
        let mut row = [0u32; N];
        for (j, slot) in row.iter_mut().enumerate() {
            let v = r[j];
            *slot = v.try_into().map_err(|_| {
                PyValueError::new_err(format!(
                    "{name}[{i}, {j}] = {v} is not a valid vertex index (negative or >= 2^32)"
                ))
            })?;
        }
        out.push(row);
    }
    Ok(out)
}

fn try_indices<T, const N: usize>(
    a: &Bound<'_, PyUntypedArray>,
    name: &str,
) -> Option<PyResult<Vec<[u32; N]>>>
where
    T: Element + Copy + std::fmt::Display + TryInto<u32>,
{
    a.downcast::<PyArray2<T>>()
        .ok()
        .map(|arr| index_rows::<T, N>(arr.readonly().as_array(), name))
}

/// An `(m, N)` integer index array (int32, int64, uint32 or uint64) as `u32` rows. Negative
/// indices and indices beyond `u32` are a `ValueError` here; indices beyond the vertex count are
/// caught by the library's mesh validation.
pub fn indices_vec<const N: usize>(obj: &Bound<'_, PyAny>, name: &str) -> PyResult<Vec<[u32; N]>> {
    let a = as_ndarray(obj, name)?;
    rows_of(&a, name, N)?;
    try_indices::<i64, N>(&a, name)
        .or_else(|| try_indices::<i32, N>(&a, name))
        .or_else(|| try_indices::<u32, N>(&a, name))
        .or_else(|| try_indices::<u64, N>(&a, name))
        .unwrap_or_else(|| {
            Err(PyTypeError::new_err(format!(
                "{name} must be an integer array (int32, int64, uint32 or uint64), got {}",
                dtype_name(&a)
            )))
        })
}

/// True when `obj` is (or converts to) an array of an integer dtype.
pub fn is_integer_array(obj: &Bound<'_, PyAny>) -> bool {
    as_ndarray(obj, "array").is_ok_and(|a| {
        a.dtype()
            .getattr("kind")
            .and_then(|k| k.extract::<String>())
            .is_ok_and(|k| k == "i" || k == "u")
    })
}

/// `obj` as an `(n, N)` query array, and whether it was a single point of shape `(N,)` (made a
/// `(1, N)` array here): libigl accepts one point and returns a float, so do the callers.
pub fn one_or_many<'py, const N: usize>(
    obj: &Bound<'py, PyAny>,
    name: &str,
) -> PyResult<(Bound<'py, PyAny>, bool)> {
    let a = as_ndarray(obj, name)?;
    if a.shape() == [N] {
        return Ok((a.call_method1("reshape", ((1, N),))?, true));
    }
    Ok((a.into_any(), false))
}

/// `values` as a float64 array, or as a float when the query was a single point
/// ([`one_or_many`]).
pub fn values_out<'py>(
    py: Python<'py>,
    values: Vec<f64>,
    single: bool,
) -> PyResult<Bound<'py, PyAny>> {
    if single {
        return Ok(pyo3::types::PyFloat::new(py, values[0]).into_any());
    }
    Ok(array1(py, values).into_any())
}

/// A float64 `(n,)` array owning `values`.
pub fn array1<'py>(py: Python<'py>, values: Vec<f64>) -> Bound<'py, PyArray1<f64>> {
    PyArray1::from_vec(py, values)
}

/// A float64 `(n, N)` array owning `rows` (a view of one allocation, no copy).
pub fn array2<'py, T: Element, const N: usize>(
    py: Python<'py>,
    rows: Vec<[T; N]>,
) -> PyResult<Bound<'py, PyAny>> {
    let n = rows.len();
    let flat = PyArray1::from_vec(py, rows.into_flattened());
    Ok(flat.reshape([n, N])?.into_any())
}

/// A float64 array of the given shape owning `values` (`values.len()` must match).
pub fn array_nd<'py>(
    py: Python<'py>,
    values: Vec<f64>,
    shape: &[usize],
) -> PyResult<Bound<'py, PyAny>> {
    let flat = PyArray1::from_vec(py, values);
    Ok(flat.reshape(shape.to_vec())?.into_any())
}

/// A box's corners as Python's ``(lo, hi)``: float64 (3,) each.
pub fn box_corners<'py>(
    py: Python<'py>,
    (lo, hi): ([f64; 3], [f64; 3]),
) -> (Bound<'py, PyAny>, Bound<'py, PyAny>) {
    (
        array1(py, lo.to_vec()).into_any(),
        array1(py, hi.to_vec()).into_any(),
    )
}
