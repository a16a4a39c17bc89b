//! `threads=`: batch calls run with the GIL released, in a rayon pool of the requested size.
//!
//! `None` uses rayon's global pool (all cores). An explicit count uses a pool cached per calling
//! thread and per count: two Python threads asking for one thread each get two different pools
//! (they must not queue behind each other), and repeated calls do not spawn threads again.

use std::cell::RefCell;
use std::collections::HashMap;
use std::sync::Arc;

use pyo3::exceptions::{PyRuntimeError, PyValueError};
use pyo3::marker::Ungil;
use pyo3::prelude::*;
use rayon::ThreadPool;

/// Pools larger than this are a mistake, not a request (and would exhaust the process).
const MAX_THREADS: usize = 1024;

thread_local! {
    static POOLS: RefCell<HashMap<usize, Arc<ThreadPool>>> = RefCell::new(HashMap::new());
}

fn pool(threads: usize) -> PyResult<Arc<ThreadPool>> {
    if threads == 0 || threads > MAX_THREADS {
        return Err(PyValueError::new_err(format!(
            "threads must be between 1 and {MAX_THREADS}, got {threads}"
        )));
    }
    POOLS.with(|pools| {
        if let Some(p) = pools.borrow().get(&threads) {
            return Ok(p.clone());
        }
        let p = Arc::new(
            rayon::ThreadPoolBuilder::new()
                .num_threads(threads)
                .build()
                .map_err(|e| {
                    PyRuntimeError::new_err(format!("cannot start {threads} threads: {e}"))
                })?,
        );
        pools.borrow_mut().insert(threads, p.clone());
        Ok(p)
    })
}

/// The pool for `threads` (`None`: rayon's global pool), for work started on another thread.
pub fn pool_for(threads: Option<usize>) -> PyResult<Option<Arc<ThreadPool>>> {
    threads.map(pool).transpose()
}

/// Runs `work` without the GIL, on `threads` worker threads (all cores when `None`).
pub fn run<T: Ungil + Send>(
    py: Python<'_>,
    threads: Option<usize>,
    work: impl Ungil + Send + FnOnce() -> T,
) -> PyResult<T> {
    match threads {
        None => Ok(py.allow_threads(work)),
        Some(n) => {
            let pool = pool(n)?;
            Ok(py.allow_threads(move || pool.install(work)))
        }
    }
}
