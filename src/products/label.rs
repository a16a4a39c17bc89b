//! Dataset labelling: for each mesh, sample points (uniform in the padded bounding box, and near
//! the surface with Gaussian offsets), label them with the exact winding number `w`, occupancy
//! (`w > 1/2`) and signed distance ([`SignedDistance`], signed by the same `w`), and write one
//! `.npz` per mesh plus a manifest of what succeeded and what failed and why.
//!
//! Reproducible byte for byte: each mesh's points come from its own seed, derived from the run's
//! seed and the mesh's path relative to the dataset root (not from its position in the list or
//! the thread that runs it), the random numbers from SplitMix64 and the Gaussian offsets from
//! `libm` (the same bits on every platform); the labels do not depend on the thread count, and the
//! `.npz` has no timestamps. Resumable: an output that exists is finished (outputs are written to
//! a temporary name and renamed), and a rerun reuses it when its record (`*.meta.json`: options,
//! input size and modification time, statistics) matches, else redoes it and says why. A broken
//! file, a FIFO, a panic or a time-limit overrun is a manifest row, never the end (nor a hang) of
//! the run; two inputs with one output stop the job before it starts.
//!
//! ```
//! use gwn::{Mesh, products::label::{label_mesh, SamplingOptions}};
//! let tet = Mesh::from_slices(
//!     &[[0., 0., 0.], [1., 0., 0.], [0., 1., 0.], [0., 0., 1.]],
//!     &[[0, 2, 1], [0, 1, 3], [1, 2, 3], [2, 0, 3]],
//! )?;
//! let opts = SamplingOptions { uniform: 100, near: 100, ..Default::default() };
//! let labels = label_mesh(&tet, "tet.off", &opts, None)?;
//! assert_eq!(labels.points.len(), 200);
//! assert!(labels.occupancy.iter().zip(&labels.sdf).all(|(&o, &d)| o == (d < 0.0) || d == 0.0));
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```

use std::fmt;
use std::path::{Path, PathBuf};
use std::time::{Duration, Instant};

use rayon::prelude::*;

use super::dataset::{DatasetError, ManifestRow, MeshJob, Stats, Status, run_dataset, run_file};
use super::npz::NpzWriter;
use super::sdf::SignedDistance;
use crate::base::splitmix::SplitMix64;
use crate::error::LoadError;
use crate::eval::antipodal::BuildError;
use crate::io::{LoadOptions, load_mesh_with};
use crate::mesh::Mesh;

/// How points are sampled for one mesh. Distances (`padding`, `sigmas`) are fractions of the
/// mesh's bounding-box diagonal, so the same options suit meshes of any scale.
#[derive(Clone, Debug, PartialEq)]
pub struct SamplingOptions {
    /// Points uniform in the padded bounding box.
    pub uniform: usize,
    /// Points near the surface: area-weighted on the triangles, then offset by an isotropic
    /// Gaussian. Split evenly between the `sigmas` (the first ones get the remainder).
    pub near: usize,
    /// Standard deviations of the near-surface offsets.
    pub sigmas: Vec<f64>,
    /// The box is the bounding box grown by this much on every side.
    pub padding: f64,
    /// The run's seed; each mesh's seed is derived from it and the mesh's key.
    pub seed: u64,
}

impl Default for SamplingOptions {
    fn default() -> Self {
        SamplingOptions {
            uniform: 50_000,
            near: 50_000,
            sigmas: vec![0.005, 0.05],
            padding: 0.05,
            seed: 0,
        }
    }
}

impl SamplingOptions {
    /// Checks the options (a one-line error for the CLI and Python).
    pub fn validate(&self) -> Result<(), LabelError> {
        let bad = |m: String| Err(LabelError::Options(m));
        if self.near > 0 && self.sigmas.is_empty() {
            return bad("near-surface points need at least one sigma".into());
        }
        if let Some(s) = self.sigmas.iter().find(|s| !(s.is_finite() && **s >= 0.0)) {
            return bad(format!("sigma {s} must be finite and non-negative"));
        }
        if !(self.padding.is_finite() && self.padding >= 0.0) {
            return bad(format!(
                "padding {} must be finite and non-negative",
                self.padding
            ));
        }
        if self
            .uniform
            .checked_add(self.near)
            .is_none_or(|n| n > MAX_POINTS)
        {
            return bad(format!("at most {MAX_POINTS} points per mesh"));
        }
        Ok(())
    }
}

/// Most points per mesh: 40 bytes of output each, so a typo cannot ask for terabytes.
pub const MAX_POINTS: usize = 100_000_000;

/// Points evaluated between two checks of the time limit.
const CHUNK: usize = 1024;

/// The labels of one mesh. Uniform points come first, then the near-surface points of each sigma
/// in turn.
#[derive(Clone, Debug, PartialEq)]
pub struct Labels {
    /// Sample points.
    pub points: Vec<[f64; 3]>,
    /// `0` for a uniform point, `k` for a near-surface point of `sigmas[k - 1]`.
    pub source: Vec<u8>,
    /// Exact winding number.
    pub w: Vec<f64>,
    /// `w > 1/2`.
    pub occupancy: Vec<bool>,
    /// Signed distance, negative where `w > 1/2`.
    pub sdf: Vec<f64>,
}

impl Labels {
    /// The `.npz` bytes: arrays `points` (N, 3) float64, `source` (N,) uint8, `w` (N,) float64,
    /// `occupancy` (N,) bool, `sdf` (N,) float64.
    pub fn to_npz(&self) -> std::io::Result<Vec<u8>> {
        let n = self.points.len();
        let flat: Vec<f64> = self.points.iter().flatten().copied().collect();
        let mut z = NpzWriter::new();
        z.add("points", &[n, 3], &flat)?;
        z.add("source", &[n], &self.source)?;
        z.add("w", &[n], &self.w)?;
        z.add("occupancy", &[n], &self.occupancy)?;
        z.add("sdf", &[n], &self.sdf)?;
        Ok(z.finish())
    }
}

/// Why one mesh could not be labelled.
#[derive(Debug)]
pub enum LabelError {
    /// The options are unusable.
    Options(String),
    /// The file could not be read as a mesh.
    Load(LoadError),
    /// The evaluator could not be built.
    Build(BuildError),
    /// The mesh's bounding box is not finite (coordinates near `f64::MAX`).
    Extent,
    /// The padding or a sigma is so large that sample points would overflow (the message says
    /// which).
    SampleBox(String),
    /// The time limit ran out during `stage`.
    TimeLimit {
        /// What was running.
        stage: &'static str,
        /// The limit.
        limit: Duration,
    },
    /// The `.npz` could not be encoded.
    Encode(std::io::Error),
}

impl fmt::Display for LabelError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            LabelError::Options(m) => write!(f, "{m}"),
            LabelError::Load(e) => write!(f, "{e}"),
            LabelError::Build(e) => write!(f, "{e}"),
            LabelError::Extent => write!(f, "the bounding box of the mesh is not finite"),
            LabelError::SampleBox(m) => write!(f, "{m}"),
            LabelError::TimeLimit { stage, limit } => write!(
                f,
                "time limit of {:.3} s exceeded while {stage}",
                limit.as_secs_f64()
            ),
            LabelError::Encode(e) => write!(f, "cannot encode the .npz: {e}"),
        }
    }
}

impl std::error::Error for LabelError {}

/// Two independent standard normals (Box–Muller with `libm`, so every platform gets the same
/// bits).
fn normal_pair(rng: &mut SplitMix64) -> (f64, f64) {
    let u1 = 1.0 - rng.unit(); // (0, 1]: the logarithm stays finite
    let u2 = rng.unit();
    let r = libm::sqrt(-2.0 * libm::log(u1));
    let t = 2.0 * std::f64::consts::PI * u2;
    (r * libm::cos(t), r * libm::sin(t))
}

/// The seed of one mesh: the run's seed mixed with an FNV-1a hash of its key.
pub fn mesh_seed(seed: u64, key: &str) -> u64 {
    let mut h: u64 = 0xCBF2_9CE4_8422_2325;
    for &b in key.as_bytes() {
        h ^= u64::from(b);
        h = h.wrapping_mul(0x0000_0100_0000_01B3);
    }
    SplitMix64(seed ^ h).next_u64()
}

/// The sample points of `mesh` (uniform first, then near-surface per sigma) and their `source`
/// codes. `key` names the mesh for its seed.
pub fn sample_points(
    mesh: &Mesh,
    key: &str,
    opts: &SamplingOptions,
) -> Result<(Vec<[f64; 3]>, Vec<u8>), LabelError> {
    opts.validate()?;
    let bb = mesh.bounding_box().ok_or(LabelError::Extent)?;
    let diag = bb.diagonal();
    if !diag.is_finite() {
        return Err(LabelError::Extent);
    }
    check_sample_box(&bb, diag, opts)?;
    let mut rng = SplitMix64(mesh_seed(opts.seed, key));
    let total = opts.uniform + opts.near;
    let mut points = Vec::with_capacity(total);
    let mut source = Vec::with_capacity(total);

    let pad = opts.padding * diag;
    let lo = bb.min.map(|c| c - pad);
    let hi = bb.max.map(|c| c + pad);
    for _ in 0..opts.uniform {
        points.push(std::array::from_fn(|k| {
            lo[k] + rng.unit() * (hi[k] - lo[k])
        }));
        source.push(0);
    }

    if opts.near > 0 {
        let cumulative = cumulative_areas(mesh);
        let area = cumulative.last().copied().unwrap_or(0.0);
        let faces = mesh.triangles().len();
        let per = opts.near / opts.sigmas.len();
        let extra = opts.near % opts.sigmas.len();
        for (k, &sigma) in opts.sigmas.iter().enumerate() {
            let s = sigma * diag;
            for _ in 0..per + usize::from(k < extra) {
                // Area-weighted face; a mesh without area (all faces degenerate) picks uniformly.
                let f = if area > 0.0 && area.is_finite() {
                    let r = rng.unit() * area;
                    cumulative.partition_point(|&c| c <= r).min(faces - 1)
                } else {
                    ((rng.unit() * faces as f64) as usize).min(faces - 1)
                };
                let [a, b, c] = mesh.triangle_positions(f);
                let (mut r1, mut r2) = (rng.unit(), rng.unit());
                if r1 + r2 > 1.0 {
                    (r1, r2) = (1.0 - r1, 1.0 - r2);
                }
                let (n0, n1) = normal_pair(&mut rng);
                let (n2, _) = normal_pair(&mut rng);
                let n = [n0, n1, n2];
                points.push(std::array::from_fn(|j| {
                    a[j] + r1 * (b[j] - a[j]) + r2 * (c[j] - a[j]) + s * n[j]
                }));
                // At most 255 sigmas get distinct codes; `validate` callers use a handful.
                source.push(u8::try_from(k + 1).unwrap_or(u8::MAX));
            }
        }
    }
    Ok((points, source))
}

/// The largest |N(0, 1)| Box–Muller can return here: `u1 ≥ 2⁻⁵³` gives
/// `√(−2 ln 2⁻⁵³) ≈ 8.57`.
const MAX_GAUSSIAN: f64 = 9.0;

/// Refuses options whose points could overflow: the bounding box grown by `padding × diag` (when
/// uniform points are asked for) and by `MAX_GAUSSIAN × sigma × diag` (near points) must have
/// finite corners, extent and diagonal, so every point, distance and label stays finite.
fn check_sample_box(
    bb: &crate::base::bounding_box::BoundingBox,
    diag: f64,
    opts: &SamplingOptions,
) -> Result<(), LabelError> {
    let padding = if opts.uniform > 0 { opts.padding } else { 0.0 };
    let sigma = if opts.near > 0 {
        opts.sigmas.iter().copied().fold(0.0, f64::max)
    } else {
        0.0
    };
    let reach = padding.max(MAX_GAUSSIAN * sigma) * diag;
    let lo = bb.min.map(|c| c - reach);
    let hi = bb.max.map(|c| c + reach);
    let extent: [f64; 3] = std::array::from_fn(|k| hi[k] - lo[k]);
    let diagonal = extent.iter().map(|e| e * e).sum::<f64>().sqrt();
    if lo.iter().chain(&hi).chain(&extent).all(|v| v.is_finite()) && diagonal.is_finite() {
        Ok(())
    } else {
        Err(LabelError::SampleBox(format!(
            "the sample box is not finite: padding {} and sigma {sigma} reach {reach:e} beyond a mesh of diagonal {diag:e}",
            opts.padding
        )))
    }
}

fn cumulative_areas(mesh: &Mesh) -> Vec<f64> {
    let mut sum = 0.0;
    (0..mesh.triangles().len())
        .map(|f| {
            let [a, b, c] = mesh.triangle_positions(f);
            let u = [b[0] - a[0], b[1] - a[1], b[2] - a[2]];
            let v = [c[0] - a[0], c[1] - a[1], c[2] - a[2]];
            let n = [
                u[1] * v[2] - u[2] * v[1],
                u[2] * v[0] - u[0] * v[2],
                u[0] * v[1] - u[1] * v[0],
            ];
            sum += 0.5 * (n[0] * n[0] + n[1] * n[1] + n[2] * n[2]).sqrt();
            sum
        })
        .collect()
}

/// Samples and labels one mesh. `key` names it for its seed (the dataset job uses the path
/// relative to the dataset root); `deadline` is checked between stages and between chunks of
/// 1024 points.
pub fn label_mesh(
    mesh: &Mesh,
    key: &str,
    opts: &SamplingOptions,
    deadline: Option<(Instant, Duration)>,
) -> Result<Labels, LabelError> {
    let check = |stage: &'static str| match deadline {
        Some((at, limit)) if Instant::now() > at => Err(LabelError::TimeLimit { stage, limit }),
        _ => Ok(()),
    };
    let (points, source) = sample_points(mesh, key, opts)?;
    check("sampling")?;
    let sdf = SignedDistance::new(mesh).map_err(LabelError::Build)?;
    check("building the evaluator")?;
    let mut w = Vec::with_capacity(points.len());
    let mut d = Vec::with_capacity(points.len());
    for chunk in points.chunks(CHUNK) {
        check("labelling points")?;
        let labelled: Vec<(f64, f64)> = chunk
            .par_iter()
            .map(|&q| sdf.eval_with_winding(q))
            .collect();
        for (sd, wq) in labelled {
            d.push(sd);
            w.push(wq);
        }
    }
    check("labelling points")?;
    let occupancy = w.iter().map(|&x| x > 0.5).collect();
    Ok(Labels {
        points,
        source,
        w,
        occupancy,
        sdf: d,
    })
}

/// Options of the dataset job (the [`MeshJob`] that [`label_dataset`] runs).
#[derive(Clone, Debug, Default)]
pub struct JobOptions {
    /// Point sampling.
    pub sampling: SamplingOptions,
    /// Per-mesh time limit (loading, sampling, building, labelling; checked between stages and
    /// point chunks, so one overrun can exceed it by a chunk's time).
    pub time_limit: Option<Duration>,
    /// Loader options (welding).
    pub load: LoadOptions,
}

impl MeshJob for JobOptions {
    type Error = LabelError;
    const RECORD: &'static str = "gwn_label";
    const STATS: &'static [(&'static str, &'static str)] = &[
        ("faces", "null"),
        ("vertices", "null"),
        ("points", "0"),
        ("inside", "0"),
    ];
    const INPUT_STATS: &'static [&'static str] = &["faces", "vertices"];
    const MESHES_IN_PARALLEL: bool = true;

    fn extension(&self) -> &'static str {
        "npz"
    }

    fn option_fields(&self) -> Vec<(&'static str, String)> {
        let s = &self.sampling;
        let sigmas: Vec<String> = s.sigmas.iter().map(|v| format!("{v:?}")).collect();
        vec![
            ("uniform", s.uniform.to_string()),
            ("near", s.near.to_string()),
            ("sigmas", format!("[{}]", sigmas.join(","))),
            ("padding", format!("{:?}", s.padding)),
            ("seed", s.seed.to_string()),
            (
                "weld",
                self.load.weld.map_or("null".into(), |w| w.to_string()),
            ),
        ]
    }

    fn validate(&self) -> Result<(), String> {
        self.sampling.validate().map_err(|e| e.to_string())
    }

    fn time_limit(&self) -> Option<Duration> {
        self.time_limit
    }

    fn status(error: &LabelError) -> Status {
        match error {
            LabelError::TimeLimit { .. } => Status::Timeout,
            _ => Status::Failed,
        }
    }

    fn run(
        &self,
        mesh_path: &Path,
        key: &str,
        deadline: Option<(Instant, Duration)>,
        stats: &mut Stats,
    ) -> Result<Vec<u8>, LabelError> {
        let mesh = load_mesh_with(mesh_path, &self.load)
            .map_err(LabelError::Load)?
            .mesh;
        stats.set("faces", mesh.triangles().len());
        stats.set("vertices", mesh.positions().len());
        if let Some((at, limit)) = deadline
            && Instant::now() > at
        {
            return Err(LabelError::TimeLimit {
                stage: "loading",
                limit,
            });
        }
        let labels = label_mesh(&mesh, key, &self.sampling, deadline)?;
        let bytes = labels.to_npz().map_err(LabelError::Encode)?;
        stats.set("points", labels.points.len());
        stats.set("inside", labels.occupancy.iter().filter(|&&o| o).count());
        Ok(bytes)
    }
}

/// Labels one mesh file into `out_dir` ([`run_file`] with the label job): the unit of work of
/// the CLI's thread pool and of a Dask task. Never panics and never fails: the result is the
/// manifest row (`faces`, `vertices`, `points`, `inside`).
pub fn label_file(mesh: &Path, root: &Path, out_dir: &Path, opts: &JobOptions) -> ManifestRow {
    run_file(opts, mesh, root, out_dir)
}

/// The whole labelling job ([`run_dataset`] with the label job): one `.npz` per mesh below
/// `out_dir`, meshes side by side on the current rayon pool, and `manifest.jsonl`.
pub fn label_dataset(
    meshes: &[PathBuf],
    out_dir: &Path,
    root: Option<&Path>,
    opts: &JobOptions,
    progress: impl Fn(&ManifestRow) + Sync,
) -> Result<Vec<ManifestRow>, DatasetError> {
    run_dataset(opts, meshes, out_dir, root, progress)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn splitmix_reference_values() {
        // First outputs for seed 1234567 from the reference C implementation.
        let mut r = SplitMix64(1234567);
        assert_eq!(r.next_u64(), 6457827717110365317);
        assert_eq!(r.next_u64(), 3203168211198807973);
    }

    #[test]
    fn gaussian_moments() {
        let mut r = SplitMix64(7);
        let n = 200_000;
        let (mut s, mut s2) = (0.0, 0.0);
        for _ in 0..n / 2 {
            let (a, b) = normal_pair(&mut r);
            s += a + b;
            s2 += a * a + b * b;
        }
        let mean = s / n as f64;
        let var = s2 / n as f64 - mean * mean;
        assert!(mean.abs() < 0.01, "{mean}");
        assert!((var - 1.0).abs() < 0.01, "{var}");
    }
}
