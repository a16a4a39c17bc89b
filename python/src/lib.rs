//! Python bindings of `gwn` (module `gwn._gwn`, re-exported by the `gwn` package).
//!
//! Every function is a thin call of the library: arrays are validated and converted in
//! [`arrays`], evaluation runs with the GIL released in a rayon pool of the requested size
//! ([`threads`]), and library errors become `ValueError`/`OSError` with the library's message
//! ([`errors`]). No formula lives here.

mod arrays;
mod curve;
mod dataset;
mod errors;
mod evaluator;
mod loaders;
mod oneshot;
mod patches;
mod products;
mod step;
mod threads;
mod winding_number;

use pyo3::prelude::*;

#[pymodule]
fn _gwn(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_class::<winding_number::PyWindingNumber>()?;
    m.add_class::<step::PyStepModel>()?;
    m.add_class::<patches::PyPatchSet>()?;
    m.add_function(wrap_pyfunction!(oneshot::winding_number, m)?)?;
    m.add_function(wrap_pyfunction!(oneshot::fast_winding_number, m)?)?;
    m.add_function(wrap_pyfunction!(products::voxelize, m)?)?;
    m.add_function(wrap_pyfunction!(products::sdf, m)?)?;
    m.add_function(wrap_pyfunction!(products::signed_distance, m)?)?;
    m.add_function(wrap_pyfunction!(products::slice, m)?)?;
    m.add_function(wrap_pyfunction!(products::classify, m)?)?;
    m.add_function(wrap_pyfunction!(products::filter_tets, m)?)?;
    m.add_function(wrap_pyfunction!(products::remesh, m)?)?;
    m.add_function(wrap_pyfunction!(curve::gauwn, m)?)?;
    m.add_function(wrap_pyfunction!(dataset::label_dataset, m)?)?;
    m.add_function(wrap_pyfunction!(dataset::label_file, m)?)?;
    m.add_function(wrap_pyfunction!(dataset::remesh_dataset, m)?)?;
    m.add_function(wrap_pyfunction!(dataset::remesh_file, m)?)?;
    m.add_function(wrap_pyfunction!(dataset::common_root, m)?)?;
    m.add_function(wrap_pyfunction!(dataset::plan_outputs, m)?)?;
    m.add_function(wrap_pyfunction!(dataset::remove_partial_files, m)?)?;
    m.add_function(wrap_pyfunction!(loaders::load, m)?)?;
    m.add_function(wrap_pyfunction!(loaders::load_point_cloud, m)?)?;
    m.add_function(wrap_pyfunction!(loaders::load_points, m)?)?;
    m.add_function(wrap_pyfunction!(loaders::load_tets, m)?)?;
    m.add_function(wrap_pyfunction!(loaders::load_polygon, m)?)?;
    m.add("__version__", env!("CARGO_PKG_VERSION"))?;
    Ok(())
}
