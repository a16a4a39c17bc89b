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
use std::io::Write;
use std::path::{Component, Path, PathBuf};
use std::time::{Duration, Instant};

use rayon::prelude::*;

use super::json::json_string;
use super::npz::NpzWriter;
use super::sdf::SignedDistance;
use crate::base::splitmix::SplitMix64;
use crate::error::{LoadError, LoadErrorKind, Location};
use crate::eval::antipodal::BuildError;
use crate::io::{LoadOptions, load_mesh_with, regular_file_metadata};
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
    /// Two inputs would be written to one output.
    Collision {
        /// The input listed first.
        first: PathBuf,
        /// The input listed later.
        second: PathBuf,
        /// Their output, relative to the output folder.
        output: PathBuf,
    },
    /// The time limit ran out during `stage`.
    TimeLimit {
        /// What was running.
        stage: &'static str,
        /// The limit.
        limit: Duration,
    },
    /// Writing the output failed.
    Write {
        /// The file.
        path: PathBuf,
        /// The cause.
        source: std::io::Error,
    },
    /// A bug: the labelling panicked (caught, so the run goes on).
    Panic(String),
}

impl LabelError {
    /// The manifest's `status` for this error.
    pub fn status(&self) -> Status {
        match self {
            LabelError::TimeLimit { .. } => Status::Timeout,
            _ => Status::Failed,
        }
    }
}

impl fmt::Display for LabelError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            LabelError::Options(m) => write!(f, "{m}"),
            LabelError::Load(e) => write!(f, "{e}"),
            LabelError::Build(e) => write!(f, "{e}"),
            LabelError::Extent => write!(f, "the bounding box of the mesh is not finite"),
            LabelError::SampleBox(m) => write!(f, "{m}"),
            LabelError::Collision {
                first,
                second,
                output,
            } => write!(
                f,
                "{} and {} would both be written to {}: give each mesh once",
                first.display(),
                second.display(),
                output.display()
            ),
            LabelError::TimeLimit { stage, limit } => write!(
                f,
                "time limit of {:.3} s exceeded while {stage}",
                limit.as_secs_f64()
            ),
            LabelError::Write { path, source } => {
                write!(f, "cannot write {}: {source}", path.display())
            }
            LabelError::Panic(m) => write!(f, "internal error (panic): {m}"),
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

/// Options of the dataset job.
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

/// What happened to one mesh.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Status {
    /// Labelled and written in this run.
    Ok,
    /// The output existed already (an earlier run finished it).
    Done,
    /// Could not be labelled.
    Failed,
    /// Ran out of time.
    Timeout,
}

impl Status {
    /// The manifest spelling.
    pub fn as_str(self) -> &'static str {
        match self {
            Status::Ok => "ok",
            Status::Done => "done",
            Status::Failed => "failed",
            Status::Timeout => "timeout",
        }
    }
}

/// One manifest row.
#[derive(Clone, Debug)]
pub struct ManifestRow {
    /// The input path as given.
    pub mesh: PathBuf,
    /// The output, relative to the output directory.
    pub output: PathBuf,
    /// What happened.
    pub status: Status,
    /// Why it failed (one line).
    pub error: Option<String>,
    /// Triangles and vertices of the mesh as labelled (after welding), when it loaded.
    pub faces: Option<usize>,
    /// Vertices.
    pub vertices: Option<usize>,
    /// Points written.
    pub points: usize,
    /// Points with `w > 1/2`.
    pub inside: usize,
    /// Wall time of this mesh in this run.
    pub seconds: f64,
    /// Why an existing output was computed again (its options or input changed), when it was.
    pub redone: Option<String>,
}

impl ManifestRow {
    /// The row as one JSON object (a line of `manifest.jsonl`).
    pub fn to_json(&self) -> String {
        let opt = |v: Option<usize>| v.map_or("null".to_string(), |v| v.to_string());
        format!(
            "{{\"mesh\":{},\"output\":{},\"status\":\"{}\",\"error\":{},\"faces\":{},\"vertices\":{},\"points\":{},\"inside\":{},\"seconds\":{:.6},\"redone\":{}}}",
            json_string(&self.mesh.to_string_lossy()),
            json_string(&self.output.to_string_lossy()),
            self.status.as_str(),
            self.error
                .as_deref()
                .map_or("null".to_string(), json_string),
            opt(self.faces),
            opt(self.vertices),
            self.points,
            self.inside,
            self.seconds,
            self.redone
                .as_deref()
                .map_or("null".to_string(), json_string),
        )
    }
}

/// `path` made absolute, with `.` and `..` applied to the text: `a/../d/m.obj` is `d/m.obj`, so
/// it is named (and seeded) as `d/m.obj` is, and cannot take the output of `a/d/m.obj`.
pub fn normalize_path(path: &Path) -> PathBuf {
    let abs = std::path::absolute(path).unwrap_or_else(|_| path.to_path_buf());
    let mut out = PathBuf::new();
    for c in abs.components() {
        match c {
            Component::CurDir => {}
            Component::ParentDir => {
                // `..` at the root stays at the root, as the file system does.
                out.pop();
            }
            c => out.push(c),
        }
    }
    out
}

/// The deepest directory containing every path (lexically, after [`normalize_path`]); the
/// outputs mirror the inputs' layout below it. Empty input: the current directory.
pub fn common_root(paths: &[PathBuf]) -> PathBuf {
    let abs: Vec<PathBuf> = paths.iter().map(|p| normalize_path(p)).collect();
    let Some(first) = abs.first() else {
        return PathBuf::from(".");
    };
    let mut root: Vec<Component<'_>> = first
        .parent()
        .map(|p| p.components().collect())
        .unwrap_or_default();
    for p in &abs[1..] {
        let dir: Vec<Component<'_>> = p
            .parent()
            .map(|d| d.components().collect())
            .unwrap_or_default();
        let same = root.iter().zip(&dir).take_while(|(a, b)| a == b).count();
        root.truncate(same);
    }
    root.iter().collect()
}

/// The key of a mesh (its normalized path below `root`, `/`-separated) and its output path
/// relative to the output directory (`key` + `.npz`, so `a/model.obj` and `a/model.glb` do not
/// collide). A mesh outside `root` is keyed by its whole absolute path.
pub fn output_key(root: &Path, mesh: &Path) -> (String, PathBuf) {
    let abs = normalize_path(mesh);
    let root = normalize_path(root);
    let rel = abs.strip_prefix(&root).unwrap_or(&abs);
    let parts: Vec<String> = rel
        .components()
        .filter_map(|c| match c {
            Component::Normal(s) => Some(s.to_string_lossy().into_owned()),
            _ => None,
        })
        .collect();
    let key = parts.join("/");
    let mut out = PathBuf::new();
    for (i, p) in parts.iter().enumerate() {
        if i + 1 == parts.len() {
            out.push(format!("{p}.npz"));
        } else {
            out.push(p);
        }
    }
    (key, out)
}

/// The output of every mesh, or a [`LabelError::Collision`] naming the first two inputs that
/// would share one (the same file listed twice, or names that differ only in ways the key
/// drops). Checked before anything is written: a second mesh must never be marked `done` with
/// the first one's labels.
pub fn plan_outputs(meshes: &[PathBuf], root: &Path) -> Result<Vec<PathBuf>, LabelError> {
    let mut seen: std::collections::HashMap<PathBuf, usize> = std::collections::HashMap::new();
    let mut outputs = Vec::with_capacity(meshes.len());
    for (i, m) in meshes.iter().enumerate() {
        let (_, output) = output_key(root, m);
        if let Some(&j) = seen.get(&output) {
            return Err(LabelError::Collision {
                first: meshes[j].clone(),
                second: m.clone(),
                output,
            });
        }
        seen.insert(output.clone(), i);
        outputs.push(output);
    }
    Ok(outputs)
}

/// Where the record of an output lives: `m.obj.npz` → `m.obj.meta.json`, beside it (outputs all
/// end in `.npz`, so a record never shadows an output).
pub fn record_path(target: &Path) -> PathBuf {
    let name = target
        .file_name()
        .map(|n| n.to_string_lossy().into_owned())
        .unwrap_or_default();
    let stem = name.strip_suffix(".npz").unwrap_or(&name);
    target.with_file_name(format!("{stem}.meta.json"))
}

/// The options that decide an output's bytes, as `(name, JSON value)` in record order.
fn option_fields(opts: &JobOptions) -> Vec<(&'static str, String)> {
    let s = &opts.sampling;
    let sigmas: Vec<String> = s.sigmas.iter().map(|v| format!("{v:?}")).collect();
    vec![
        ("uniform", s.uniform.to_string()),
        ("near", s.near.to_string()),
        ("sigmas", format!("[{}]", sigmas.join(","))),
        ("padding", format!("{:?}", s.padding)),
        ("seed", s.seed.to_string()),
        (
            "weld",
            opts.load.weld.map_or("null".into(), |w| w.to_string()),
        ),
    ]
}

/// The input as the record sees it: size and modification time (nanoseconds since 1970).
fn input_stamp(meta: &std::fs::Metadata) -> String {
    let mtime = meta
        .modified()
        .ok()
        .and_then(|t| t.duration_since(std::time::UNIX_EPOCH).ok())
        .map_or("null".into(), |d| d.as_nanos().to_string());
    format!("{{\"bytes\":{},\"mtime_ns\":{mtime}}}", meta.len())
}

/// The record's text up to the statistics: what must match for an output to be reused.
fn record_head(opts: &JobOptions, stamp: &str) -> String {
    let fields: Vec<String> = option_fields(opts)
        .iter()
        .map(|(k, v)| format!("\"{k}\":{v}"))
        .collect();
    format!(
        "{{\"gwn_label\":1,\"options\":{{{}}},\"input\":{stamp},",
        fields.join(",")
    )
}

/// What a rerun does with an output.
enum Resume {
    /// No output: label it.
    Fresh,
    /// The output matches the options and the input: reuse it, with these statistics
    /// (faces, vertices, points, inside).
    Done([Option<usize>; 4]),
    /// An output exists but cannot be reused, for this reason.
    Redo(String),
}

/// Compares an existing output's record with this run.
fn resume_state(target: &Path, opts: &JobOptions, stamp: &str) -> Resume {
    if !target.is_file() {
        return Resume::Fresh;
    }
    let record = crate::io::open_regular(&record_path(target)).and_then(|f| {
        use std::io::Read;
        let mut text = String::new();
        // A record is one short line; the cap keeps a planted huge file from being read.
        f.take(1 << 16).read_to_string(&mut text)?;
        Ok(text)
    });
    let Ok(text) = record else {
        return Resume::Redo("no record of the options that made the existing output".into());
    };
    let head = record_head(opts, stamp);
    if let Some(rest) = text.strip_prefix(&head) {
        let stat = |name: &str| -> Option<usize> {
            let at = rest.find(&format!("\"{name}\":"))? + name.len() + 3;
            let end = rest[at..].find([',', '}'])? + at;
            rest[at..end].parse().ok()
        };
        return Resume::Done([
            stat("faces"),
            stat("vertices"),
            stat("points"),
            stat("inside"),
        ]);
    }
    let options_then = text
        .strip_prefix("{\"gwn_label\":1,\"options\":{")
        .and_then(|r| r.split_once("},\"input\":"));
    let Some((then, input_then)) = options_then else {
        return Resume::Redo("its record is unreadable".into());
    };
    let changed: Vec<String> = option_fields(opts)
        .into_iter()
        .filter_map(|(k, now)| {
            let before = then
                .split(",\"")
                .map(|f| f.trim_start_matches('"'))
                .find_map(|f| f.strip_prefix(k)?.strip_prefix("\":"))
                .unwrap_or("?");
            (before != now).then(|| format!("{k} {before} -> {now}"))
        })
        .collect();
    if !changed.is_empty() {
        return Resume::Redo(format!("options changed: {}", changed.join(", ")));
    }
    if !input_then.starts_with(stamp) {
        return Resume::Redo("its input changed (size or modification time)".into());
    }
    Resume::Redo("its record is unreadable".into())
}

/// Labels one mesh file into `out_dir` (the unit of work of the CLI's thread pool and of a Dask
/// task). An existing output is reused (status `done`, with the statistics of the run that made
/// it) only when its record (`*.meta.json`) shows the same options and the same input size and
/// modification time; otherwise the mesh is labelled again and `redone` says why. Only regular
/// files are opened (a FIFO is a failed row, never a hang); outputs are written atomically.
/// Never panics and never fails: the result is the manifest row.
pub fn label_file(mesh: &Path, root: &Path, out_dir: &Path, opts: &JobOptions) -> ManifestRow {
    let start = Instant::now();
    let (key, output) = output_key(root, mesh);
    let mut row = ManifestRow {
        mesh: mesh.to_path_buf(),
        output: output.clone(),
        status: Status::Ok,
        error: None,
        faces: None,
        vertices: None,
        points: 0,
        inside: 0,
        seconds: 0.0,
        redone: None,
    };
    let target = out_dir.join(&output);
    let result = std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| {
        let meta = regular_file_metadata(mesh).map_err(|e| {
            LabelError::Load(LoadError::new(mesh, Location::File, LoadErrorKind::Io(e)))
        })?;
        let stamp = input_stamp(&meta);
        match resume_state(&target, opts, &stamp) {
            Resume::Done([faces, vertices, points, inside]) => {
                row.status = Status::Done;
                row.faces = faces;
                row.vertices = vertices;
                row.points = points.unwrap_or(0);
                row.inside = inside.unwrap_or(0);
                return Ok(());
            }
            Resume::Redo(why) => row.redone = Some(why),
            Resume::Fresh => {}
        }
        label_file_inner(mesh, &key, &target, opts, &stamp, start, &mut row)
    }));
    let err = match result {
        Ok(Ok(())) => None,
        Ok(Err(e)) => Some(e),
        Err(payload) => {
            let msg = payload
                .downcast_ref::<&str>()
                .map(|s| s.to_string())
                .or_else(|| payload.downcast_ref::<String>().cloned())
                .unwrap_or_else(|| "unknown".into());
            Some(LabelError::Panic(msg))
        }
    };
    if let Some(e) = err {
        row.status = e.status();
        row.error = Some(e.to_string().replace('\n', " "));
        row.points = 0;
        row.inside = 0;
    }
    row.seconds = start.elapsed().as_secs_f64();
    row
}

fn label_file_inner(
    mesh_path: &Path,
    key: &str,
    target: &Path,
    opts: &JobOptions,
    stamp: &str,
    start: Instant,
    row: &mut ManifestRow,
) -> Result<(), LabelError> {
    let deadline = opts.time_limit.map(|l| (start + l, l));
    let mesh = load_mesh_with(mesh_path, &opts.load)
        .map_err(LabelError::Load)?
        .mesh;
    row.faces = Some(mesh.triangles().len());
    row.vertices = Some(mesh.positions().len());
    if let Some((at, limit)) = deadline {
        if Instant::now() > at {
            return Err(LabelError::TimeLimit {
                stage: "loading",
                limit,
            });
        }
    }
    let labels = label_mesh(&mesh, key, &opts.sampling, deadline)?;
    let bytes = labels.to_npz().map_err(|source| LabelError::Write {
        path: target.to_path_buf(),
        source,
    })?;
    // The old record goes first: were we killed between the two writes below, a stale record
    // must not vouch for the new file.
    let record = record_path(target);
    match std::fs::remove_file(&record) {
        Err(e) if e.kind() != std::io::ErrorKind::NotFound => {
            return Err(LabelError::Write {
                path: record,
                source: e,
            });
        }
        _ => {}
    }
    write_atomically(target, &bytes)?;
    row.points = labels.points.len();
    row.inside = labels.occupancy.iter().filter(|&&o| o).count();
    let opt = |v: Option<usize>| v.map_or("null".to_string(), |v| v.to_string());
    let text = format!(
        "{}\"faces\":{},\"vertices\":{},\"points\":{},\"inside\":{}}}\n",
        record_head(opts, stamp),
        opt(row.faces),
        opt(row.vertices),
        row.points,
        row.inside
    );
    write_atomically(&record, text.as_bytes())
}

/// The name of a temporary file [`write_atomically`] writes for `name`.
fn partial_name(name: &str, pid: u32, n: u64) -> String {
    format!(".{name}.partial-{pid}-{n}")
}

/// True for a name [`partial_name`] makes: `.NAME.partial-PID-N`.
fn is_partial_name(name: &str) -> bool {
    let Some(rest) = name.strip_prefix('.') else {
        return false;
    };
    let Some((_, tail)) = rest.rsplit_once(".partial-") else {
        return false;
    };
    let digits = |s: &str| !s.is_empty() && s.bytes().all(|b| b.is_ascii_digit());
    tail.split_once('-')
        .is_some_and(|(pid, n)| digits(pid) && digits(n))
}

/// Removes the temporary files a killed run (`kill -9`, a lost Dask worker) left below
/// `out_dir` (names `.NAME.partial-PID-N`; symlinks are not followed). Two jobs must not write
/// one folder at the same time: this would delete the other job's files in progress. Returns how
/// many were removed.
pub fn remove_partial_files(out_dir: &Path) -> std::io::Result<usize> {
    let mut removed = 0;
    let mut stack = vec![out_dir.to_path_buf()];
    while let Some(dir) = stack.pop() {
        for entry in std::fs::read_dir(&dir)? {
            let entry = entry?;
            let kind = entry.file_type()?;
            if kind.is_dir() {
                stack.push(entry.path());
            } else if kind.is_file() && is_partial_name(&entry.file_name().to_string_lossy()) {
                std::fs::remove_file(entry.path())?;
                removed += 1;
            }
        }
    }
    Ok(removed)
}

/// Writes `bytes` to a unique temporary name next to `target`, then renames it: readers (and a
/// resumed run) see either no file or the whole file.
pub fn write_atomically(target: &Path, bytes: &[u8]) -> Result<(), LabelError> {
    use std::sync::atomic::{AtomicU64, Ordering};
    static COUNTER: AtomicU64 = AtomicU64::new(0);
    let fail = |source| LabelError::Write {
        path: target.to_path_buf(),
        source,
    };
    if let Some(dir) = target.parent() {
        std::fs::create_dir_all(dir).map_err(fail)?;
    }
    let name = target
        .file_name()
        .map(|n| n.to_string_lossy().into_owned())
        .unwrap_or_default();
    let tmp = target.with_file_name(partial_name(
        &name,
        std::process::id(),
        COUNTER.fetch_add(1, Ordering::Relaxed),
    ));
    let written = std::fs::File::create(&tmp).and_then(|mut f| {
        f.write_all(bytes)?;
        f.sync_all()
    });
    if let Err(e) = written.and_then(|_| std::fs::rename(&tmp, target)) {
        let _ = std::fs::remove_file(&tmp);
        return Err(fail(e));
    }
    Ok(())
}

/// The whole job: checks that no two meshes share an output, removes the temporary files of an
/// interrupted run, labels every mesh (in parallel on the current rayon pool), calls `progress`
/// after each, and writes `manifest.jsonl` (rows in input order) into `out_dir`. `root` defaults
/// to [`common_root`] of the inputs. Returns the rows.
pub fn label_dataset(
    meshes: &[PathBuf],
    out_dir: &Path,
    root: Option<&Path>,
    opts: &JobOptions,
    progress: impl Fn(&ManifestRow) + Sync,
) -> Result<Vec<ManifestRow>, LabelError> {
    opts.sampling.validate()?;
    let root = root.map_or_else(|| common_root(meshes), normalize_path);
    plan_outputs(meshes, &root)?;
    let write_err = |source| LabelError::Write {
        path: out_dir.to_path_buf(),
        source,
    };
    std::fs::create_dir_all(out_dir).map_err(write_err)?;
    remove_partial_files(out_dir).map_err(write_err)?;
    let rows: Vec<ManifestRow> = meshes
        .par_iter()
        .with_max_len(1)
        .map(|m| {
            let row = label_file(m, &root, out_dir, opts);
            progress(&row);
            row
        })
        .collect();
    write_manifest(out_dir, &rows)?;
    Ok(rows)
}

/// Writes `manifest.jsonl` (one [`ManifestRow::to_json`] per line) atomically into `out_dir`.
pub fn write_manifest(out_dir: &Path, rows: &[ManifestRow]) -> Result<PathBuf, LabelError> {
    let mut text = String::new();
    for r in rows {
        text.push_str(&r.to_json());
        text.push('\n');
    }
    let path = out_dir.join("manifest.jsonl");
    write_atomically(&path, text.as_bytes())?;
    Ok(path)
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

    #[test]
    fn keys_and_roots() {
        let root = common_root(&[PathBuf::from("/d/a/x.obj"), PathBuf::from("/d/b/c/y.glb")]);
        assert_eq!(root, PathBuf::from("/d"));
        let (key, out) = output_key(&root, Path::new("/d/b/c/y.glb"));
        assert_eq!(key, "b/c/y.glb");
        assert_eq!(out, PathBuf::from("b/c/y.glb.npz"));
        assert_eq!(
            common_root(&[PathBuf::from("/d/a/x.obj")]),
            PathBuf::from("/d/a")
        );
    }
}
