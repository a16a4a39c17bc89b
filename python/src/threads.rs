//! `threads=`: batch calls run with the GIL released, in a rayon pool of the requested size, and
//! stay interruptible (Ctrl-C).
//!
//! `None` uses rayon's global pool (all cores). An explicit count uses a pool cached per calling
//! thread and per count: two Python threads asking for one thread each get two different pools
//! (they must not queue behind each other), and repeated calls do not spawn threads again.
//!
//! Ctrl-C: Python runs signal handlers only between bytecodes of the main thread, so a long call
//! with the GIL released would ignore it until it returned (64 s on a large direct sum). The
//! work therefore runs as a job of the pool while the calling thread waits for it, checking for
//! signals every [`POLL`]; on a signal it tells the work to stop, waits for the work to finish
//! its current piece, and raises the handler's exception (`KeyboardInterrupt`). The work stops
//! between pieces: [`in_slices`] (about 0.1 s each) for point batches, the library's `*_until`
//! grid functions (batches of columns) for grids.

use std::cell::RefCell;
use std::collections::HashMap;
use std::sync::Arc;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::mpsc;
use std::time::{Duration, Instant};

use pyo3::exceptions::{PyRuntimeError, PyValueError};
use pyo3::marker::Ungil;
use pyo3::prelude::*;
use rayon::ThreadPool;

/// Pools larger than this are a mistake, not a request (and would exhaust the process).
const MAX_THREADS: usize = 1024;

/// How often a waiting call checks for signals.
const POLL: Duration = Duration::from_millis(50);

/// Time an interruptible batch aims at per piece: the Ctrl-C latency, and long enough that the
/// pieces' parallel loops stay efficient.
const PIECE_TIME: Duration = Duration::from_millis(100);

/// A validated `threads=` value: `None` (all cores) or a count in `1..=MAX_THREADS`. Parsed from
/// any Python int, so that `threads=-1` is a `ValueError` naming the argument instead of the
/// `OverflowError` of an unsigned conversion.
#[derive(Clone, Copy, Debug)]
pub struct Threads(pub usize);

impl<'py> FromPyObject<'py> for Threads {
    fn extract_bound(ob: &Bound<'py, PyAny>) -> PyResult<Self> {
        let n: i128 = ob.extract()?;
        if n < 1 || n > MAX_THREADS as i128 {
            return Err(PyValueError::new_err(format!(
                "threads must be between 1 and {MAX_THREADS} (or None: all cores), got {n}"
            )));
        }
        Ok(Threads(n as usize))
    }
}

thread_local! {
    static POOLS: RefCell<HashMap<usize, Arc<ThreadPool>>> = RefCell::new(HashMap::new());
}

fn pool(threads: usize) -> PyResult<Arc<ThreadPool>> {
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
pub fn pool_for(threads: Option<Threads>) -> PyResult<Option<Arc<ThreadPool>>> {
    threads.map(|Threads(n)| pool(n)).transpose()
}

/// Runs `work` without the GIL, on `threads` worker threads (all cores when `None`). For short
/// work (building an index); long work uses [`run_interruptible`].
pub fn run<T: Ungil + Send>(
    py: Python<'_>,
    threads: Option<Threads>,
    work: impl Ungil + Send + FnOnce() -> T,
) -> PyResult<T> {
    match threads {
        None => Ok(py.allow_threads(work)),
        Some(Threads(n)) => {
            let pool = pool(n)?;
            Ok(py.allow_threads(move || pool.install(work)))
        }
    }
}

/// Runs `work(stop)` without the GIL on `threads` worker threads, raising the signal handler's
/// exception (`KeyboardInterrupt` on Ctrl-C) if a signal arrives meanwhile. `work` must return
/// soon after `stop` becomes true (with `None`); what it returns then is discarded.
pub fn run_interruptible<T: Send>(
    py: Python<'_>,
    threads: Option<Threads>,
    work: impl Send + FnOnce(&AtomicBool) -> Option<T>,
) -> PyResult<T> {
    let pool = threads.map(|Threads(n)| pool(n)).transpose()?;
    let stop = AtomicBool::new(false);
    let waited: PyResult<Option<T>> = py.allow_threads(|| match &pool {
        Some(p) => p.in_place_scope(|scope| wait_for(scope, &stop, work)),
        None => rayon::in_place_scope(|scope| wait_for(scope, &stop, work)),
    });
    waited?.ok_or_else(|| PyRuntimeError::new_err("the evaluation stopped without a result"))
}

/// Spawns `work` in `scope` and waits for it on this thread, checking for signals every
/// [`POLL`]; on a signal sets `stop` and returns the handler's exception (the scope then waits
/// for `work` to wind down before the caller continues).
fn wait_for<'s, T: Send + 's>(
    scope: &rayon::Scope<'s>,
    stop: &'s AtomicBool,
    work: impl Send + FnOnce(&AtomicBool) -> Option<T> + 's,
) -> PyResult<Option<T>> {
    let (tx, rx) = mpsc::channel();
    scope.spawn(move |_| {
        // A send fails only when this function has returned already (on a signal): the result
        // is not wanted then.
        let _ = tx.send(work(stop));
    });
    loop {
        match rx.recv_timeout(POLL) {
            Ok(result) => return Ok(result),
            Err(mpsc::RecvTimeoutError::Timeout) => {
                if let Err(e) = Python::with_gil(|py| py.check_signals()) {
                    stop.store(true, Ordering::Relaxed);
                    return Err(e);
                }
            }
            // The work panicked: the scope re-raises the panic when it ends.
            Err(mpsc::RecvTimeoutError::Disconnected) => return Ok(None),
        }
    }
}

/// `f` over `points` in pieces of about [`PIECE_TIME`] each, giving up (`None`) between pieces
/// once `stop` is set. A point costs anything from nanoseconds (a far query) to seconds (the
/// direct sum over a large mesh), so the piece size adapts: it starts at a few points per
/// worker thread and doubles or halves after each piece. Values are those of one call on all
/// points (every evaluator's batch is pointwise).
pub fn in_slices<P, R>(
    points: &[P],
    stop: &AtomicBool,
    f: impl Fn(&[P]) -> Vec<R>,
) -> Option<Vec<R>> {
    let smallest = 4 * rayon::current_num_threads();
    let mut size = smallest;
    let mut out = Vec::with_capacity(points.len());
    let mut rest = points;
    while !rest.is_empty() {
        if stop.load(Ordering::Relaxed) {
            return None;
        }
        let (piece, tail) = rest.split_at(size.min(rest.len()));
        let start = Instant::now();
        out.extend(f(piece));
        let took = start.elapsed();
        if took < PIECE_TIME / 4 {
            size = size.saturating_mul(2);
        } else if took > PIECE_TIME * 2 {
            size = (size / 2).max(smallest);
        }
        rest = tail;
    }
    Some(out)
}

/// A point batch: [`in_slices`] under [`run_interruptible`].
pub fn run_batch<P: Sync, R: Send>(
    py: Python<'_>,
    threads: Option<Threads>,
    points: &[P],
    f: impl Sync + Fn(&[P]) -> Vec<R>,
) -> PyResult<Vec<R>> {
    run_interruptible(py, threads, |stop| in_slices(points, stop, &f))
}
