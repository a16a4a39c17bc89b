//! Dataset jobs: labelling (`label_dataset`, the whole job, and `label_file`, one mesh: the unit
//! of a Dask task) and remeshing (`remesh_dataset`, `remesh_file`). All run the library's
//! `gwn::products::dataset` jobs, so the files are the CLI's, byte for byte, and rows come back
//! as the manifest's JSON lines.

use std::path::PathBuf;
use std::sync::mpsc;
use std::time::Duration;

use gwn::io::LoadOptions;
use gwn::products::dataset::{self, MeshJob};
use gwn::products::label::{JobOptions, SamplingOptions};
use gwn::products::remesh::dataset::RemeshJob;
use gwn::products::remesh::write::SurfaceFormat;
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;

use crate::errors::value_error;
use crate::threads::{self, Threads};

/// ``time_limit`` (seconds) as a duration: positive and finite (below 10⁹ s).
pub(crate) fn time_limit_of(seconds: Option<f64>) -> PyResult<Option<Duration>> {
    match seconds {
        Some(s) if s.is_finite() && s > 0.0 && s < 1e9 => Ok(Some(Duration::from_secs_f64(s))),
        Some(s) => Err(PyValueError::new_err(format!(
            "time_limit must be a positive number of seconds, got {s}"
        ))),
        None => Ok(None),
    }
}

#[allow(clippy::too_many_arguments)]
fn job_options(
    uniform: usize,
    near: usize,
    sigmas: Vec<f64>,
    padding: f64,
    seed: u64,
    time_limit: Option<f64>,
    weld: Option<bool>,
) -> PyResult<JobOptions> {
    let time_limit = time_limit_of(time_limit)?;
    let sampling = SamplingOptions {
        uniform,
        near,
        sigmas,
        padding,
        seed,
    };
    sampling.validate().map_err(value_error)?;
    Ok(JobOptions {
        sampling,
        time_limit,
        load: LoadOptions { weld },
    })
}

/// Labels every mesh of ``paths`` into ``out_dir`` (see ``gwn label --help``): per mesh,
/// ``uniform`` points in the bounding box padded by ``padding`` × diagonal and ``near`` points
/// near the surface (Gaussian offsets of ``sigmas`` × diagonal), labelled with the exact winding
/// number ``w``, ``occupancy`` (w > 1/2) and ``sdf``; one ``.npz`` per mesh at
/// ``out_dir/<path below root>.npz`` and ``out_dir/manifest.jsonl``. An existing output is
/// reused only when made with the same options from the same input (resumable); broken files,
/// FIFOs, panics and ``time_limit`` overruns are rows, not exceptions. Returns the manifest rows as JSON strings, in input order. ``progress``, when
/// given, is called with each finished mesh's row (a JSON string) on the calling thread, in the
/// order the meshes finish; an exception it raises is re-raised after the job ends.
#[pyfunction]
#[pyo3(signature = (paths, out_dir, *, root = None, uniform = 50_000, near = 50_000,
    sigmas = vec![0.005, 0.05], padding = 0.05, seed = 0, time_limit = None, weld = None,
    threads = None, progress = None))]
#[allow(clippy::too_many_arguments)]
pub fn label_dataset(
    py: Python<'_>,
    paths: Vec<PathBuf>,
    out_dir: PathBuf,
    root: Option<PathBuf>,
    uniform: usize,
    near: usize,
    sigmas: Vec<f64>,
    padding: f64,
    seed: u64,
    time_limit: Option<f64>,
    weld: Option<bool>,
    threads: Option<Threads>,
    progress: Option<PyObject>,
) -> PyResult<Vec<String>> {
    let opts = job_options(uniform, near, sigmas, padding, seed, time_limit, weld)?;
    run_job(py, opts, paths, out_dir, root, threads, progress)
}

/// Runs `job` over `paths` ([`dataset::run_dataset`]) on `threads`, the GIL released: the rows
/// as JSON strings in input order. With `progress`, the job runs on its own thread and this one
/// waits without the GIL, taking it only to hand each finished row to `progress`, so the
/// callback runs on the caller's thread; an exception it raises is re-raised after the job.
fn run_job<J: MeshJob + Send>(
    py: Python<'_>,
    job: J,
    paths: Vec<PathBuf>,
    out_dir: PathBuf,
    root: Option<PathBuf>,
    threads: Option<Threads>,
    progress: Option<PyObject>,
) -> PyResult<Vec<String>> {
    let Some(progress) = progress else {
        let rows = threads::run(py, threads, move || {
            dataset::run_dataset(&job, &paths, &out_dir, root.as_deref(), |_| {})
        })?
        .map_err(value_error)?;
        return Ok(rows.iter().map(|r| r.to_json()).collect());
    };
    let pool = threads::pool_for(threads)?;
    let (tx, rx) = mpsc::channel::<String>();
    let (rows, callback_error) = py.allow_threads(move || {
        std::thread::scope(|scope| {
            let job = scope.spawn(move || {
                let run = || {
                    dataset::run_dataset(&job, &paths, &out_dir, root.as_deref(), |row| {
                        // The receiver outlives the job, so a send cannot fail.
                        let _ = tx.send(row.to_json());
                    })
                };
                match pool {
                    Some(p) => p.install(run),
                    None => run(),
                }
            });
            let mut callback_error = None;
            for line in rx.iter() {
                if callback_error.is_none() {
                    callback_error = Python::with_gil(|py| progress.call1(py, (line,)).err());
                }
            }
            (job.join(), callback_error)
        })
    });
    let rows = match rows {
        Ok(r) => r.map_err(value_error)?,
        Err(_) => {
            return Err(pyo3::exceptions::PyRuntimeError::new_err(
                "the dataset job panicked",
            ));
        }
    };
    if let Some(e) = callback_error {
        return Err(e);
    }
    Ok(rows.iter().map(|r| r.to_json()).collect())
}

/// Labels one mesh into ``out_dir`` (its existing output is reused when its record shows the
/// same options and input, else redone) and returns its manifest row as a JSON string. ``root`` must be the same for every mesh of a dataset (see
/// ``common_root``): it fixes the output path and the mesh's seed.
#[pyfunction]
#[pyo3(signature = (path, out_dir, root, *, uniform = 50_000, near = 50_000,
    sigmas = vec![0.005, 0.05], padding = 0.05, seed = 0, time_limit = None, weld = None,
    threads = None))]
#[allow(clippy::too_many_arguments)]
pub fn label_file(
    py: Python<'_>,
    path: PathBuf,
    out_dir: PathBuf,
    root: PathBuf,
    uniform: usize,
    near: usize,
    sigmas: Vec<f64>,
    padding: f64,
    seed: u64,
    time_limit: Option<f64>,
    weld: Option<bool>,
    threads: Option<Threads>,
) -> PyResult<String> {
    let opts = job_options(uniform, near, sigmas, padding, seed, time_limit, weld)?;
    let root = std::path::absolute(&root).unwrap_or(root);
    threads::run(py, threads, move || {
        dataset::run_file(&opts, &path, &root, &out_dir).to_json()
    })
}

#[allow(clippy::too_many_arguments)]
fn remesh_job(
    res: usize,
    format: &str,
    samples: usize,
    thicken_cells: Option<f64>,
    weld: Option<bool>,
    time_limit: Option<f64>,
    bisect: u32,
    simplify: bool,
    refine_plates: bool,
    sub_cell_levels: u32,
    planar_levels: u32,
    always_remesh: bool,
    parity_where_flipped: bool,
) -> PyResult<RemeshJob> {
    let format =
        SurfaceFormat::of_path(std::path::Path::new(&format!("x.{format}"))).ok_or_else(|| {
            PyValueError::new_err(format!("format={format:?}: expected obj, ply, stl or glb"))
        })?;
    let mut job = RemeshJob::new(res);
    job.format = format;
    job.samples = samples;
    job.thicken_cells = thicken_cells;
    job.load = LoadOptions { weld };
    job.time_limit = time_limit_of(time_limit)?;
    job.options.bisection_steps = bisect;
    if !simplify {
        job.options.simplify = None;
    }
    job.options.refine_plates = refine_plates;
    job.options.sub_cell_levels = sub_cell_levels;
    job.options.planar_levels = planar_levels;
    job.keep_input = !always_remesh;
    job.parity_where_flipped = parity_where_flipped;
    job.validate().map_err(PyValueError::new_err)?;
    Ok(job)
}

/// Remeshes every mesh of ``paths`` into ``out_dir`` (see ``gwn remesh-dataset --help``): per
/// mesh, the closed, manifold, oriented surface ``gwn.remesh`` makes at ``res`` (the same bytes
/// ``gwn remesh`` writes), at ``out_dir/<path below root>.<format>``, and
/// ``out_dir/manifest.jsonl``. Meshes run one after the other, each on ``threads``. Resumable
/// and failure-isolated as ``label_dataset``; a mesh past ``time_limit`` seconds is a
/// ``timeout`` row. Returns the manifest rows as JSON strings, in input
/// order; ``progress`` as in ``label_dataset``.
#[pyfunction]
#[pyo3(signature = (paths, out_dir, res = 128, *, root = None, format = "ply", samples = 10_000,
    thicken_cells = None, weld = None, time_limit = None,
    bisect = gwn::products::remesh::DEFAULT_BISECTION_STEPS,
    simplify = true, refine_plates = true,
    sub_cell_levels = gwn::products::remesh::DEFAULT_SUB_CELL_LEVELS,
    planar_levels = gwn::products::remesh::DEFAULT_PLANAR_LEVELS, always_remesh = false,
    parity_where_flipped = false,
    threads = None, progress = None))]
#[allow(clippy::too_many_arguments)]
pub fn remesh_dataset(
    py: Python<'_>,
    paths: Vec<PathBuf>,
    out_dir: PathBuf,
    res: usize,
    root: Option<PathBuf>,
    format: &str,
    samples: usize,
    thicken_cells: Option<f64>,
    weld: Option<bool>,
    time_limit: Option<f64>,
    bisect: u32,
    simplify: bool,
    refine_plates: bool,
    sub_cell_levels: u32,
    planar_levels: u32,
    always_remesh: bool,
    parity_where_flipped: bool,
    threads: Option<Threads>,
    progress: Option<PyObject>,
) -> PyResult<Vec<String>> {
    let job = remesh_job(
        res,
        format,
        samples,
        thicken_cells,
        weld,
        time_limit,
        bisect,
        simplify,
        refine_plates,
        sub_cell_levels,
        planar_levels,
        always_remesh,
        parity_where_flipped,
    )?;
    run_job(py, job, paths, out_dir, root, threads, progress)
}

/// Remeshes one mesh into ``out_dir`` (reused when its record shows the same options and
/// input, else redone) and returns its manifest row as a JSON string: the unit of a Dask task.
/// ``root`` must be the same for every mesh of a dataset (see ``common_root``).
#[pyfunction]
#[pyo3(signature = (path, out_dir, root, res = 128, *, format = "ply", samples = 10_000,
    thicken_cells = None, weld = None, time_limit = None,
    bisect = gwn::products::remesh::DEFAULT_BISECTION_STEPS,
    simplify = true, refine_plates = true,
    sub_cell_levels = gwn::products::remesh::DEFAULT_SUB_CELL_LEVELS,
    planar_levels = gwn::products::remesh::DEFAULT_PLANAR_LEVELS, always_remesh = false,
    parity_where_flipped = false,
    threads = None))]
#[allow(clippy::too_many_arguments)]
pub fn remesh_file(
    py: Python<'_>,
    path: PathBuf,
    out_dir: PathBuf,
    root: PathBuf,
    res: usize,
    format: &str,
    samples: usize,
    thicken_cells: Option<f64>,
    weld: Option<bool>,
    time_limit: Option<f64>,
    bisect: u32,
    simplify: bool,
    refine_plates: bool,
    sub_cell_levels: u32,
    planar_levels: u32,
    always_remesh: bool,
    parity_where_flipped: bool,
    threads: Option<Threads>,
) -> PyResult<String> {
    let job = remesh_job(
        res,
        format,
        samples,
        thicken_cells,
        weld,
        time_limit,
        bisect,
        simplify,
        refine_plates,
        sub_cell_levels,
        planar_levels,
        always_remesh,
        parity_where_flipped,
    )?;
    let root = std::path::absolute(&root).unwrap_or(root);
    threads::run(py, threads, move || {
        dataset::run_file(&job, &path, &root, &out_dir).to_json()
    })
}

/// The output of every mesh below ``root`` (relative paths with ``extension`` appended, input
/// order); ``ValueError`` naming the first two inputs that would share one.
#[pyfunction]
#[pyo3(signature = (paths, root, extension = "npz"))]
pub fn plan_outputs(paths: Vec<PathBuf>, root: PathBuf, extension: &str) -> PyResult<Vec<PathBuf>> {
    dataset::plan_outputs(&paths, &root, extension).map_err(value_error)
}

/// Removes the temporary files a killed run left below ``out_dir``; returns how many.
#[pyfunction]
pub fn remove_partial_files(out_dir: PathBuf) -> PyResult<usize> {
    dataset::remove_partial_files(&out_dir)
        .map_err(|e| pyo3::exceptions::PyOSError::new_err(format!("{}: {e}", out_dir.display())))
}

/// The deepest folder holding every path (absolute): the default ``root`` of a dataset.
#[pyfunction]
pub fn common_root(paths: Vec<PathBuf>) -> PathBuf {
    dataset::common_root(&paths)
}
