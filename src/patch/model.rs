//! Tensor-product (rational) Bézier patches and patch sets.
//!
//! A patch of degrees `(m, n)` has `(m+1)(n+1)` control points `P_ij` (row `i` ↔ parameter `s`,
//! column `j` ↔ parameter `t`) and positive weights `w_ij`:
//! `S(s,t) = Σ B_i^m(s) B_j^n(t) w_ij P_ij / Σ B_i^m(s) B_j^n(t) w_ij`.
//! Orientation: `∂S/∂t × ∂S/∂s` is the normal whose side has `w = 1` for a closed set (the
//! convention of the Utah teapot file, see `docs/patches.md`).

use std::fmt;

/// Largest degree accepted in either direction. Bounds the work per patch (de Casteljau is
/// quadratic in the degree) and keeps a hostile header from asking for a huge allocation.
pub const MAX_DEGREE: usize = 32;

/// A patch set that cannot be built or read.
#[derive(Clone, Debug, PartialEq)]
pub enum PatchError {
    /// A degree is larger than [`MAX_DEGREE`].
    DegreeTooHigh {
        /// Patch (0-based).
        patch: usize,
        /// The degrees given.
        degrees: (usize, usize),
    },
    /// The number of control points does not match the degrees.
    ControlPointCount {
        /// Patch (0-based).
        patch: usize,
        /// `(m+1)(n+1)`.
        expected: usize,
        /// What was given.
        found: usize,
    },
    /// A coordinate is NaN or infinite.
    NonFiniteCoordinate {
        /// Patch (0-based).
        patch: usize,
        /// Control point (row-major, 0-based).
        point: usize,
    },
    /// A weight is not a finite positive number (the convex-hull property, on which the
    /// evaluator's certificates rest, needs positive weights).
    BadWeight {
        /// Patch (0-based).
        patch: usize,
        /// Control point (row-major, 0-based).
        point: usize,
        /// The value found.
        weight: f64,
    },
    /// A text file does not follow the format.
    Parse {
        /// 1-based line number.
        line: usize,
        /// What was expected.
        message: String,
    },
    /// The file could not be read.
    Io {
        /// The file.
        path: std::path::PathBuf,
        /// The operating system's error kind (`NotFound`, `PermissionDenied`, …): Python raises
        /// the matching `OSError` subclass.
        kind: std::io::ErrorKind,
        /// Its message.
        message: String,
    },
    /// The path does not name a patch file (`.bpt` or `.rbpt`).
    NotPatchFile(std::path::PathBuf),
    /// The file was read, and its content is not a valid patch set.
    InFile {
        /// The file.
        path: std::path::PathBuf,
        /// What is wrong in it.
        error: Box<PatchError>,
    },
    /// The set has no patch.
    Empty,
}

impl fmt::Display for PatchError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            PatchError::DegreeTooHigh { patch, degrees } => write!(
                f,
                "patch {patch} has degrees {} x {}, more than the supported {MAX_DEGREE}",
                degrees.0, degrees.1
            ),
            PatchError::ControlPointCount {
                patch,
                expected,
                found,
            } => write!(
                f,
                "patch {patch} needs {expected} control points, {found} were given"
            ),
            PatchError::NonFiniteCoordinate { patch, point } => write!(
                f,
                "patch {patch}, control point {point}: non-finite coordinate"
            ),
            PatchError::BadWeight {
                patch,
                point,
                weight,
            } => write!(
                f,
                "patch {patch}, control point {point}: weight {weight} is not a finite positive number"
            ),
            PatchError::Parse { line, message } => write!(f, "line {line}: {message}"),
            PatchError::Io { path, message, .. } => write!(f, "{}: {message}", path.display()),
            PatchError::NotPatchFile(path) => write!(
                f,
                "{}: not a patch file (expected .bpt or .rbpt)",
                path.display()
            ),
            PatchError::InFile { path, error } => write!(f, "{}: {error}", path.display()),
            PatchError::Empty => write!(f, "the patch set has no patch"),
        }
    }
}

impl std::error::Error for PatchError {}

/// One tensor-product rational Bézier patch.
#[derive(Clone, Debug, PartialEq)]
pub struct Patch {
    degree: (usize, usize),
    points: Vec<[f64; 3]>,
    weights: Vec<f64>,
}

impl Patch {
    /// A polynomial patch (all weights 1). `points` is row-major: `m+1` rows of `n+1` points.
    pub fn polynomial(m: usize, n: usize, points: Vec<[f64; 3]>) -> Result<Patch, PatchError> {
        let weights = vec![1.0; points.len()];
        Patch::rational(m, n, points, weights)
    }

    /// A rational patch; `weights[k]` belongs to `points[k]`.
    pub fn rational(
        m: usize,
        n: usize,
        points: Vec<[f64; 3]>,
        weights: Vec<f64>,
    ) -> Result<Patch, PatchError> {
        Patch::checked(0, m, n, points, weights)
    }

    pub(crate) fn checked(
        index: usize,
        m: usize,
        n: usize,
        points: Vec<[f64; 3]>,
        weights: Vec<f64>,
    ) -> Result<Patch, PatchError> {
        if m > MAX_DEGREE || n > MAX_DEGREE {
            return Err(PatchError::DegreeTooHigh {
                patch: index,
                degrees: (m, n),
            });
        }
        let expected = (m + 1) * (n + 1);
        for found in [points.len(), weights.len()] {
            if found != expected {
                return Err(PatchError::ControlPointCount {
                    patch: index,
                    expected,
                    found,
                });
            }
        }
        for (k, (p, &w)) in points.iter().zip(&weights).enumerate() {
            if p.iter().any(|c| !c.is_finite()) {
                return Err(PatchError::NonFiniteCoordinate {
                    patch: index,
                    point: k,
                });
            }
            if !(w.is_finite() && w > 0.0) {
                return Err(PatchError::BadWeight {
                    patch: index,
                    point: k,
                    weight: w,
                });
            }
        }
        Ok(Patch {
            degree: (m, n),
            points,
            weights,
        })
    }

    /// `(m, n)`: degree in `s` (rows) and in `t` (columns).
    pub fn degree(&self) -> (usize, usize) {
        self.degree
    }

    /// Control points, row-major.
    pub fn points(&self) -> &[[f64; 3]] {
        &self.points
    }

    /// Weights, row-major (all 1 for a polynomial patch).
    pub fn weights(&self) -> &[f64] {
        &self.weights
    }

    /// Whether some weight differs from the others (a rational patch with equal weights is
    /// polynomial).
    pub fn is_rational(&self) -> bool {
        self.weights.iter().any(|&w| w != self.weights[0])
    }

    /// Row-major index of control point `(i, j)`.
    #[inline]
    pub fn index(&self, i: usize, j: usize) -> usize {
        i * (self.degree.1 + 1) + j
    }

    /// The point `S(s, t)` and the partial derivatives `∂S/∂s`, `∂S/∂t`.
    pub fn eval_with_partials(&self, s: f64, t: f64) -> ([f64; 3], [f64; 3], [f64; 3]) {
        let (m, n) = self.degree;
        let [mut bs, mut dbs, mut bt, mut dbt] = [[0.0; MAX_DEGREE + 1]; 4];
        bernstein_with_derivative_into(m, s, &mut bs, &mut dbs);
        bernstein_with_derivative_into(n, t, &mut bt, &mut dbt);
        // Homogeneous sums H = Σ B B w P (xyz) and W = Σ B B w, with their partials.
        let mut h = [[0.0f64; 4]; 3]; // value, d/ds, d/dt
        for i in 0..=m {
            for j in 0..=n {
                let k = self.index(i, j);
                let w = self.weights[k];
                let p = self.points[k];
                let hp = [w * p[0], w * p[1], w * p[2], w];
                let f = [bs[i] * bt[j], dbs[i] * bt[j], bs[i] * dbt[j]];
                for (acc, fk) in h.iter_mut().zip(f) {
                    for c in 0..4 {
                        acc[c] += fk * hp[c];
                    }
                }
            }
        }
        let w = h[0][3];
        let p = [h[0][0] / w, h[0][1] / w, h[0][2] / w];
        let partial = |d: [f64; 4]| {
            [
                (d[0] - p[0] * d[3]) / w,
                (d[1] - p[1] * d[3]) / w,
                (d[2] - p[2] * d[3]) / w,
            ]
        };
        (p, partial(h[1]), partial(h[2]))
    }

    /// The point `S(s, t)`.
    pub fn eval(&self, s: f64, t: f64) -> [f64; 3] {
        self.eval_with_partials(s, t).0
    }

    /// The two halves of the patch split at parameter `tau ∈ (0, 1)` of `s` (`along_s`) or `t`
    /// (de Casteljau on the homogeneous net). The halves share the split curve's control points
    /// bit for bit, so their common edge cancels exactly in the boundary.
    pub fn split(&self, along_s: bool, tau: f64) -> (Patch, Patch) {
        let (m, n) = self.degree;
        let h: Vec<[f64; 4]> = self
            .points
            .iter()
            .zip(&self.weights)
            .map(|(p, &w)| [w * p[0], w * p[1], w * p[2], w])
            .collect();
        // Lines along the split direction: columns for s, rows for t.
        let (lines, len) = if along_s {
            (n + 1, m + 1)
        } else {
            (m + 1, n + 1)
        };
        let at = |line: usize, k: usize| {
            if along_s {
                k * (n + 1) + line
            } else {
                line * (n + 1) + k
            }
        };
        let mut a = h.clone();
        let mut b = h.clone();
        for line in 0..lines {
            let mut work: Vec<[f64; 4]> = (0..len).map(|k| h[at(line, k)]).collect();
            let d = len - 1;
            a[at(line, 0)] = work[0];
            b[at(line, d)] = work[d];
            for level in 1..=d {
                for i in 0..=(d - level) {
                    for c in 0..4 {
                        work[i][c] = (1.0 - tau) * work[i][c] + tau * work[i + 1][c];
                    }
                }
                a[at(line, level)] = work[0];
                b[at(line, d - level)] = work[d - level];
            }
        }
        let back = |h: Vec<[f64; 4]>| {
            let points = h
                .iter()
                .map(|q| [q[0] / q[3], q[1] / q[3], q[2] / q[3]])
                .collect();
            let weights = h.iter().map(|q| q[3]).collect();
            Patch {
                degree: (m, n),
                points,
                weights,
            }
        };
        (back(a), back(b))
    }
}

/// The Bernstein basis `B_i^d(x)`, `i = 0..=d`, and its derivative, into `b[..=d]` and
/// `db[..=d]` (`d ≤ MAX_DEGREE`). No allocation: a surface point with its partials
/// ([`Patch::eval_with_partials`]) runs at every Newton step of a ray hit, where six `Vec`s per
/// call (with the net halvings' own) made the allocator a third of a STEP model's remeshing
/// time.
pub(crate) fn bernstein_with_derivative_into(d: usize, x: f64, b: &mut [f64], db: &mut [f64]) {
    bernstein_into(d, x, b);
    db[..=d].fill(0.0);
    if d > 0 {
        let mut lower = [0.0; MAX_DEGREE + 1];
        bernstein_into(d - 1, x, &mut lower);
        let df = d as f64;
        for i in 0..=d {
            let left = if i > 0 { lower[i - 1] } else { 0.0 };
            let right = if i < d { lower[i] } else { 0.0 };
            db[i] = df * (left - right);
        }
    }
}

/// The Bernstein basis into `b[..=d]`, by the triangular recurrence (stable on `[0, 1]`, exact
/// 0/1 at the ends).
fn bernstein_into(d: usize, x: f64, b: &mut [f64]) {
    let b = &mut b[..=d];
    b.fill(0.0);
    b[0] = 1.0;
    let y = 1.0 - x;
    for k in 1..=d {
        let mut prev = 0.0;
        for bi in b.iter_mut().take(k + 1) {
            let cur = *bi;
            *bi = y * cur + x * prev;
            prev = cur;
        }
    }
}

/// A set of patches with the surface they form.
#[derive(Clone, Debug, PartialEq)]
pub struct PatchSet {
    patches: Vec<Patch>,
}

impl PatchSet {
    /// A set from patches (at least one).
    pub fn new(patches: Vec<Patch>) -> Result<PatchSet, PatchError> {
        if patches.is_empty() {
            return Err(PatchError::Empty);
        }
        Ok(PatchSet { patches })
    }

    /// The patches.
    pub fn patches(&self) -> &[Patch] {
        &self.patches
    }

    /// Whether any patch is rational.
    pub fn is_rational(&self) -> bool {
        self.patches.iter().any(Patch::is_rational)
    }

    /// Bounding box of all control points (it contains the surface).
    pub fn bounding_box(&self) -> ([f64; 3], [f64; 3]) {
        let mut lo = [f64::INFINITY; 3];
        let mut hi = [f64::NEG_INFINITY; 3];
        for p in self.patches.iter().flat_map(|p| p.points()) {
            for a in 0..3 {
                lo[a] = lo[a].min(p[a]);
                hi[a] = hi[a].max(p[a]);
            }
        }
        (lo, hi)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn bernstein(d: usize, x: f64) -> Vec<f64> {
        let mut b = vec![0.0; d + 1];
        bernstein_into(d, x, &mut b);
        b
    }

    fn bernstein_with_derivative(d: usize, x: f64) -> (Vec<f64>, Vec<f64>) {
        let (mut b, mut db) = (vec![0.0; d + 1], vec![0.0; d + 1]);
        bernstein_with_derivative_into(d, x, &mut b, &mut db);
        (b, db)
    }

    #[test]
    fn bernstein_partition_of_unity_and_ends() {
        for d in 0..6 {
            let b = bernstein(d, 0.3);
            assert!((b.iter().sum::<f64>() - 1.0).abs() < 1e-15);
            assert_eq!(bernstein(d, 0.0)[0], 1.0);
            assert_eq!(bernstein(d, 1.0)[d], 1.0);
        }
        let (_, db) = bernstein_with_derivative(3, 0.25);
        let h = 1e-6;
        let fd: Vec<f64> = bernstein(3, 0.25 + h)
            .iter()
            .zip(bernstein(3, 0.25 - h))
            .map(|(a, b)| (a - b) / (2.0 * h))
            .collect();
        for (a, b) in db.iter().zip(fd) {
            assert!((a - b).abs() < 1e-8);
        }
    }

    #[test]
    fn rejects_bad_patches() {
        let pts = vec![[0.0; 3]; 4];
        assert!(matches!(
            Patch::polynomial(1, 2, pts.clone()),
            Err(PatchError::ControlPointCount { expected: 6, .. })
        ));
        assert!(matches!(
            Patch::rational(1, 1, pts.clone(), vec![1.0, 0.0, 1.0, 1.0]),
            Err(PatchError::BadWeight { point: 1, .. })
        ));
        let mut bad = pts.clone();
        bad[3][1] = f64::NAN;
        assert!(matches!(
            Patch::polynomial(1, 1, bad),
            Err(PatchError::NonFiniteCoordinate { point: 3, .. })
        ));
        assert!(matches!(
            Patch::polynomial(40, 1, vec![]),
            Err(PatchError::DegreeTooHigh { .. })
        ));
        assert_eq!(PatchSet::new(vec![]), Err(PatchError::Empty));
    }
}
