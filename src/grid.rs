//! Regular voxel grids of winding numbers, evaluated with **ray reuse**.
//!
//! # Layout
//! A [`GridSpec`] `{ bounds, dims: [W, H, D] }` splits `bounds` into `W × H × D` equal cells
//! (`W` along x, `H` along y, `D` along z) and samples `w` at the **cell centres**:
//!
//! ```text
//! point(i, j, k) = bounds.min + ((i + ½)·hx, (j + ½)·hy, (k + ½)·hz),   h = (max − min) / dims
//! ```
//!
//! Values are stored flat in **C order with shape `(D, H, W)`** — x varies fastest:
//! `values[(k·H + j)·W + i]`. `numpy.load` therefore gives an array indexed `a[z, y, x]`, and the
//! order is also VTK ImageData's point order (see [`crate::products::vti`]).
//!
//! # Columns and ray reuse
//! Any [`Evaluator`] fills a grid. All samples with the same two coordinates transverse to the
//! evaluator's [`Evaluator::column_axis`] (z when it has none) form one *column*, evaluated by one
//! [`Evaluator::eval_column`] call; columns are evaluated in parallel (rayon).
//!
//! For the exact evaluator ([`WindingNumber`]) the column axis is its ray
//! ([`Options::ray`](crate::eval::antipodal::Options), default `+z`), and a column costs one
//! BVH traversal ([`WindingNumber::eval_column`]): the column's crossings, in their exact
//! (perturbed) order along the ray, give χ for every sample, and the boundary term is added per
//! sample. The result is identical to [`WindingNumber::eval`] at every sample (same perturbation
//! rule for samples exactly on the surface).

use std::sync::atomic::{AtomicBool, Ordering};

use rayon::prelude::*;

use crate::base::bounding_box::BoundingBox;
use crate::eval::Evaluator;
#[cfg(doc)]
use crate::eval::antipodal::WindingNumber;

/// A regular grid of cell-centre samples (see the [module documentation](self) for the layout).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct GridSpec {
    /// The box split into cells.
    pub bounds: BoundingBox,
    /// Number of cells `[W, H, D]` along x, y, z.
    pub dims: [usize; 3],
}

/// Why a grid specification is unusable.
#[derive(Clone, Debug, PartialEq)]
pub enum GridError {
    /// A dimension is zero.
    ZeroDimension,
    /// `W·H·D` overflows `usize`.
    TooLarge,
    /// A bound is not finite or `min > max` on some axis.
    BadBounds,
    /// More than [`MAX_GRID_CELLS`] cells ([`GridSpec::check_memory`]).
    TooManyCells {
        /// `W·H·D`.
        cells: usize,
    },
    /// The arrays of the grid would not fit in the memory available
    /// ([`GridSpec::check_memory`]).
    OutOfMemory {
        /// `W·H·D`.
        cells: usize,
        /// Bytes needed.
        need: u64,
        /// Bytes available.
        available: u64,
    },
}

impl std::fmt::Display for GridError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let gib = |b: u64| b as f64 / f64::from(1u32 << 30);
        match self {
            GridError::ZeroDimension => f.write_str("grid dimensions must be at least 1"),
            GridError::TooLarge => f.write_str("grid has too many cells"),
            GridError::BadBounds => {
                f.write_str("grid bounds must be finite with min <= max on every axis")
            }
            GridError::TooManyCells { cells } => {
                write!(f, "a grid of {cells} cells is too large (limit 2^31)")
            }
            GridError::OutOfMemory {
                cells,
                need,
                available,
            } => write!(
                f,
                "a grid of {cells} cells needs about {:.1} GiB of memory, more than the {:.1} GiB \
                 available",
                gib(*need),
                gib(*available)
            ),
        }
    }
}

/// Most cells a grid product ([`evaluate`], the signed-distance grid, `gwn voxelize`/`sdf`, the
/// Python `voxelize`/`sdf`) may have: 2³¹ (16 GiB of `f64`).
pub const MAX_GRID_CELLS: usize = 1 << 31;

/// Peak bytes per cell of [`evaluate`]: the per-column results and the grid they are copied
/// into. Products add what they hold besides (see [`GridSpec::check_memory`]).
pub const EVALUATE_BYTES_PER_CELL: usize = 8 + 8;

/// The memory the system can still give (Linux `MemAvailable`), `None` where unknown.
pub fn available_memory() -> Option<u64> {
    let info = std::fs::read_to_string("/proc/meminfo").ok()?;
    let line = info.lines().find(|l| l.starts_with("MemAvailable:"))?;
    let kib: u64 = line.split_whitespace().nth(1)?.parse().ok()?;
    Some(kib.saturating_mul(1024))
}

impl std::error::Error for GridError {}

impl GridSpec {
    /// A checked grid.
    pub fn new(bounds: BoundingBox, dims: [usize; 3]) -> Result<Self, GridError> {
        if dims.contains(&0) {
            return Err(GridError::ZeroDimension);
        }
        dims.iter()
            .try_fold(1usize, |a, &d| a.checked_mul(d))
            .ok_or(GridError::TooLarge)?;
        // The extent, not only the corners, must be finite: [-1e308, 1e308] overflows.
        let finite = (0..3).all(|k| (bounds.max[k] - bounds.min[k]).is_finite());
        if !finite || (0..3).any(|k| bounds.min[k] > bounds.max[k]) {
            return Err(GridError::BadBounds);
        }
        Ok(GridSpec { bounds, dims })
    }

    /// A grid over `bounds` whose longest side has `res` cells; the other sides get as many
    /// cells as keep the cells as close to cubes as possible (at least 1).
    pub fn with_resolution(bounds: BoundingBox, res: usize) -> Result<Self, GridError> {
        let ext: [f64; 3] = std::array::from_fn(|k| bounds.max[k] - bounds.min[k]);
        let longest = ext.iter().copied().fold(0.0_f64, f64::max);
        let dims = ext.map(|e| {
            if longest > 0.0 {
                ((e / longest * res as f64).round() as usize).max(1)
            } else {
                res.max(1)
            }
        });
        let dims = if res == 0 { [0; 3] } else { dims };
        Self::new(bounds, dims)
    }

    /// Number of samples `W·H·D`.
    pub fn len(&self) -> usize {
        self.dims.iter().product()
    }

    /// True when the grid has no samples.
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// Cell size along each axis.
    pub fn spacing(&self) -> [f64; 3] {
        std::array::from_fn(|k| (self.bounds.max[k] - self.bounds.min[k]) / self.dims[k] as f64)
    }

    /// The coordinate of sample `i` along `axis` (a cell centre).
    #[inline]
    pub fn coord(&self, axis: usize, i: usize) -> f64 {
        let h = (self.bounds.max[axis] - self.bounds.min[axis]) / self.dims[axis] as f64;
        self.bounds.min[axis] + (i as f64 + 0.5) * h
    }

    /// The sample point of cell `(i, j, k)`.
    #[inline]
    pub fn point(&self, i: usize, j: usize, k: usize) -> [f64; 3] {
        [self.coord(0, i), self.coord(1, j), self.coord(2, k)]
    }

    /// Flat index of cell `(i, j, k)` in the C-order `(D, H, W)` layout.
    #[inline]
    pub fn index(&self, i: usize, j: usize, k: usize) -> usize {
        (k * self.dims[1] + j) * self.dims[0] + i
    }

    /// All sample points in storage order.
    pub fn points(&self) -> Vec<[f64; 3]> {
        let mut out = Vec::with_capacity(self.len());
        for k in 0..self.dims[2] {
            for j in 0..self.dims[1] {
                for i in 0..self.dims[0] {
                    out.push(self.point(i, j, k));
                }
            }
        }
        out
    }

    /// The C-order shape `(D, H, W)`.
    pub fn shape(&self) -> [usize; 3] {
        [self.dims[2], self.dims[1], self.dims[0]]
    }

    /// The one size check of grid products, shared by the CLI and the Python package: refuses
    /// more than [`MAX_GRID_CELLS`] cells, and grids whose arrays (`bytes_per_cell` at the
    /// product's peak) exceed `available` bytes (pass [`available_memory`]; `None`: unknown,
    /// not checked). Allocating them would abort the process, or wake the OOM killer, with no
    /// useful message.
    pub fn check_memory(
        &self,
        bytes_per_cell: usize,
        available: Option<u64>,
    ) -> Result<(), GridError> {
        let cells = self.len();
        if cells > MAX_GRID_CELLS {
            return Err(GridError::TooManyCells { cells });
        }
        let need = (cells as u64).saturating_mul(bytes_per_cell as u64);
        match available {
            Some(available) if need > available => Err(GridError::OutOfMemory {
                cells,
                need,
                available,
            }),
            _ => Ok(()),
        }
    }

    /// Number of columns along world axis `axis`.
    pub fn column_count(&self, axis: usize) -> usize {
        self.len() / self.dims[axis]
    }
}

/// The world axis grid columns run along for `evaluator`: its [`Evaluator::column_axis`], or z.
pub fn column_axis<E: Evaluator + ?Sized>(evaluator: &E) -> usize {
    evaluator.column_axis().unwrap_or(2)
}

/// Winding numbers at every sample of `spec`, column by column (see the
/// [module documentation](self)). Storage order as [`GridSpec::index`].
pub fn evaluate<E: Evaluator + ?Sized>(evaluator: &E, spec: &GridSpec) -> Vec<f64> {
    evaluate_with_progress(evaluator, spec, |_| {})
}

/// [`evaluate`], calling `progress(n)` after every finished batch of `n` columns (from worker
/// threads).
pub fn evaluate_with_progress<E: Evaluator + ?Sized>(
    evaluator: &E,
    spec: &GridSpec,
    progress: impl Fn(usize) + Sync,
) -> Vec<f64> {
    let never = AtomicBool::new(false);
    evaluate_until(evaluator, spec, progress, &never).unwrap_or_default()
}

/// [`evaluate_with_progress`] that gives up when `stop` becomes true: batches of columns not yet
/// started are skipped and the result is `None`. How a caller interrupts a long grid from
/// another thread (the Python package on Ctrl-C); values are those of [`evaluate`] otherwise.
pub fn evaluate_until<E: Evaluator + ?Sized>(
    evaluator: &E,
    spec: &GridSpec,
    progress: impl Fn(usize) + Sync,
    stop: &AtomicBool,
) -> Option<Vec<f64>> {
    let n = spec.len();
    if n == 0 {
        return Some(Vec::new());
    }
    let axis = column_axis(evaluator);
    // The two transverse axes, in increasing order; a column is addressed by (a, b).
    let (ta, tb) = match axis {
        0 => (1, 2),
        1 => (0, 2),
        _ => (0, 1),
    };
    let ts: Vec<f64> = (0..spec.dims[axis]).map(|i| spec.coord(axis, i)).collect();
    let na = spec.dims[ta];
    let columns = spec.column_count(axis);
    // Groups of columns per task keep the scheduling overhead small on thin columns.
    let chunk = (4096 / ts.len()).clamp(1, 64);
    let results: Vec<Vec<f64>> = (0..columns)
        .into_par_iter()
        .chunks(chunk)
        .map(|cols| {
            if stop.load(Ordering::Relaxed) {
                return Vec::new();
            }
            let mut out = Vec::with_capacity(cols.len() * ts.len());
            for c in &cols {
                let (a, b) = (c % na, c / na);
                let mut q = [0.0; 3];
                q[ta] = spec.coord(ta, a);
                q[tb] = spec.coord(tb, b);
                q[axis] = ts[0];
                out.extend(evaluator.eval_column(q, axis, &ts));
            }
            progress(cols.len());
            out
        })
        .collect();
    if stop.load(Ordering::Relaxed) {
        return None;
    }
    let mut values = vec![0.0; n];
    let mut c = 0usize;
    for block in results {
        for col in block.chunks_exact(ts.len()) {
            let (a, b) = (c % na, c / na);
            for (t, &v) in col.iter().enumerate() {
                let mut idx = [0usize; 3];
                idx[ta] = a;
                idx[tb] = b;
                idx[axis] = t;
                values[spec.index(idx[0], idx[1], idx[2])] = v;
            }
            c += 1;
        }
    }
    Some(values)
}

/// The same grid evaluated point by point ([`Evaluator::eval_batch`]; for the exact evaluator one
/// ray per sample): the reference for [`evaluate`] and the baseline of its speed-up.
pub fn evaluate_per_point<E: Evaluator + ?Sized>(evaluator: &E, spec: &GridSpec) -> Vec<f64> {
    evaluator.eval_batch(&spec.points())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn layout_and_resolution() {
        let b = BoundingBox {
            min: [0.0, 0.0, 0.0],
            max: [2.0, 1.0, 0.5],
        };
        let g = GridSpec::with_resolution(b, 8).unwrap();
        assert_eq!(g.dims, [8, 4, 2]);
        assert_eq!(g.shape(), [2, 4, 8]);
        assert_eq!(g.point(0, 0, 0), [0.125, 0.125, 0.125]);
        assert_eq!(g.index(1, 2, 1), 8 * 4 + 2 * 8 + 1);
        assert_eq!(g.points()[g.index(3, 1, 1)], g.point(3, 1, 1));
        assert_eq!(
            GridSpec::new(b, [0, 1, 1]).unwrap_err(),
            GridError::ZeroDimension
        );
        assert!(GridSpec::new(b, [usize::MAX, 2, 1]).is_err());
    }
}
