//! Dataset jobs: one output file per input mesh, in a folder that mirrors the inputs' layout,
//! and a manifest of what succeeded and what failed and why. [`super::label`] (points labelled
//! for learning) and [`super::remesh::dataset`] (closed surfaces) are the two [`MeshJob`]s.
//!
//! What every job gets from here: outputs keyed by the path below the dataset root (so two
//! inputs never share an output, checked before anything is written); outputs written to a
//! temporary name and renamed (a reader or a resumed run sees the whole file or none, and the
//! temporary files of a killed run are removed); a record beside each output (`*.meta.json`:
//! the options that made it, the input's size and modification time, the row's statistics), so
//! that a rerun reuses an output only when the record matches, else redoes it and says why; and
//! failure isolation: a broken file, a FIFO, a panic or a time-limit overrun is a manifest row,
//! never the end (nor a hang) of the run.

use std::fmt;
use std::io::Write;
use std::path::{Component, Path, PathBuf};
use std::time::{Duration, Instant};

use rayon::prelude::*;

use super::json::json_string;
use crate::io::regular_file_metadata;

/// What happened to one mesh.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Status {
    /// Processed and written in this run.
    Ok,
    /// The output existed already (an earlier run finished it).
    Done,
    /// Could not be processed.
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

/// One kind of per-mesh work that [`run_file`] and [`run_dataset`] run over a dataset.
pub trait MeshJob: Sync {
    /// Why one mesh failed.
    type Error: fmt::Display;
    /// The record's first member (`{"gwn_label":1,...`): which job made an output.
    const RECORD: &'static str;
    /// The manifest's statistics of a mesh, in order, each with its JSON value when the job
    /// never got to it (`null`, `0`).
    const STATS: &'static [(&'static str, &'static str)];
    /// The statistics that describe the input (its size): a row keeps them when the mesh fails
    /// later; the others go back to their unset value.
    const INPUT_STATS: &'static [&'static str];
    /// Whether meshes run side by side, one per thread (else one after the other, each with
    /// every thread: a job that is parallel inside and needs the memory).
    const MESHES_IN_PARALLEL: bool;
    /// The outputs' extension, appended to the input's file name (`m.obj` → `m.obj.npz`, so
    /// `m.obj` and `m.glb` do not collide).
    fn extension(&self) -> &'static str;
    /// The options that decide an output's bytes, as `(name, JSON value)` in record order.
    fn option_fields(&self) -> Vec<(&'static str, String)>;
    /// Unusable options, refused before the run starts (one line).
    fn validate(&self) -> Result<(), String>;
    /// The time limit per mesh, if any.
    fn time_limit(&self) -> Option<Duration>;
    /// Whether a folder walk takes the file `path` as an input (by its extension; files named
    /// one by one are always taken). Default: the mesh formats of [`crate::io`].
    fn walks(&self, path: &Path) -> bool {
        crate::io::format_from_extension(path).is_some()
    }
    /// The manifest status of a failure (default: failed).
    fn status(_error: &Self::Error) -> Status {
        Status::Failed
    }
    /// Processes one mesh: the output's bytes. `key` is its path below the root (a seed may
    /// depend on it); `stats` is filled as values become known (a mesh that fails after loading
    /// still reports its size); `deadline` is when the time limit runs out.
    fn run(
        &self,
        mesh: &Path,
        key: &str,
        deadline: Option<(Instant, Duration)>,
        stats: &mut Stats,
    ) -> Result<Vec<u8>, Self::Error>;
}

/// A row's statistics: `(name, JSON value)` in the job's order ([`MeshJob::STATS`]).
#[derive(Clone, Debug, PartialEq)]
pub struct Stats(pub Vec<(&'static str, String)>);

impl Stats {
    /// Every statistic at its value for a mesh the job never got to.
    pub fn unset(names: &[(&'static str, &'static str)]) -> Stats {
        Stats(names.iter().map(|&(n, v)| (n, v.to_string())).collect())
    }

    /// Sets `name` (one of the job's) to the JSON value `value`.
    pub fn set(&mut self, name: &str, value: impl fmt::Display) {
        if let Some(entry) = self.0.iter_mut().find(|(n, _)| *n == name) {
            entry.1 = value.to_string();
        } else {
            debug_assert!(false, "{name} is not a statistic of this job");
        }
    }

    /// The JSON value of `name`.
    pub fn get(&self, name: &str) -> Option<&str> {
        self.0
            .iter()
            .find(|(n, _)| *n == name)
            .map(|(_, v)| v.as_str())
    }

    /// `name` as a count (`None` when unknown, `null` or not a count).
    pub fn count(&self, name: &str) -> Option<usize> {
        self.get(name)?.parse().ok()
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
    /// The job's statistics ([`MeshJob::STATS`]).
    pub stats: Stats,
    /// Wall time of this mesh in this run.
    pub seconds: f64,
    /// Why an existing output was computed again (its options or input changed), when it was.
    pub redone: Option<String>,
}

impl ManifestRow {
    /// The row as one JSON object (a line of `manifest.jsonl`): `mesh`, `output`, `status`,
    /// `error`, the statistics, `seconds`, `redone`.
    pub fn to_json(&self) -> String {
        let stats: String = self
            .stats
            .0
            .iter()
            .map(|(n, v)| format!("\"{n}\":{v},"))
            .collect();
        format!(
            "{{\"mesh\":{},\"output\":{},\"status\":\"{}\",\"error\":{},{stats}\"seconds\":{:.6},\"redone\":{}}}",
            json_string(&self.mesh.to_string_lossy()),
            json_string(&self.output.to_string_lossy()),
            self.status.as_str(),
            self.error
                .as_deref()
                .map_or("null".to_string(), json_string),
            self.seconds,
            self.redone
                .as_deref()
                .map_or("null".to_string(), json_string),
        )
    }
}

/// Why a dataset run could not start or finish (one mesh's failure is a row, not this).
#[derive(Debug)]
pub enum DatasetError {
    /// The options are unusable.
    Options(String),
    /// Two inputs would be written to one output.
    Collision {
        /// The input listed first.
        first: PathBuf,
        /// The input listed later.
        second: PathBuf,
        /// Their output, relative to the output folder.
        output: PathBuf,
    },
    /// Writing failed.
    Write {
        /// The file or folder.
        path: PathBuf,
        /// The cause.
        source: std::io::Error,
    },
}

impl fmt::Display for DatasetError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            DatasetError::Options(m) => write!(f, "{m}"),
            DatasetError::Collision {
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
            DatasetError::Write { path, source } => {
                write!(f, "cannot write {}: {source}", path.display())
            }
        }
    }
}

impl std::error::Error for DatasetError {}

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
/// relative to the output directory (`key` + `.` + `extension`). A mesh outside `root` is
/// keyed by its whole absolute path.
pub fn output_key(root: &Path, mesh: &Path, extension: &str) -> (String, PathBuf) {
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
            out.push(format!("{p}.{extension}"));
        } else {
            out.push(p);
        }
    }
    (key, out)
}

/// The output of every mesh, or a [`DatasetError::Collision`] naming the first two inputs that
/// would share one (the same file listed twice, or names that differ only in ways the key
/// drops). Checked before anything is written: a second mesh must never be marked `done` with
/// the first one's output.
pub fn plan_outputs(
    meshes: &[PathBuf],
    root: &Path,
    extension: &str,
) -> Result<Vec<PathBuf>, DatasetError> {
    let mut seen: std::collections::HashMap<PathBuf, usize> = std::collections::HashMap::new();
    let mut outputs = Vec::with_capacity(meshes.len());
    for (i, m) in meshes.iter().enumerate() {
        let (_, output) = output_key(root, m, extension);
        if let Some(&j) = seen.get(&output) {
            return Err(DatasetError::Collision {
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
/// end in `.extension`, so a record never shadows an output).
pub fn record_path(target: &Path, extension: &str) -> PathBuf {
    let name = target
        .file_name()
        .map(|n| n.to_string_lossy().into_owned())
        .unwrap_or_default();
    let stem = name.strip_suffix(&format!(".{extension}")).unwrap_or(&name);
    target.with_file_name(format!("{stem}.meta.json"))
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
fn record_head<J: MeshJob>(job: &J, stamp: &str) -> String {
    let fields: Vec<String> = job
        .option_fields()
        .iter()
        .map(|(k, v)| format!("\"{k}\":{v}"))
        .collect();
    format!(
        "{{\"{}\":1,\"options\":{{{}}},\"input\":{stamp},",
        J::RECORD,
        fields.join(",")
    )
}

/// What a rerun does with an output.
enum Resume {
    /// No output: process the mesh.
    Fresh,
    /// The output matches the options and the input: reuse it, with these statistics.
    Done(Stats),
    /// An output exists but cannot be reused, for this reason.
    Redo(String),
}

/// Compares an existing output's record with this run.
fn resume_state<J: MeshJob>(job: &J, target: &Path, stamp: &str) -> Resume {
    if !target.is_file() {
        return Resume::Fresh;
    }
    let record = crate::io::open_regular(&record_path(target, job.extension())).and_then(|f| {
        use std::io::Read;
        let mut text = String::new();
        // A record is one short line; the cap keeps a planted huge file from being read.
        f.take(1 << 16).read_to_string(&mut text)?;
        Ok(text)
    });
    let Ok(text) = record else {
        return Resume::Redo("no record of the options that made the existing output".into());
    };
    let head = record_head(job, stamp);
    if let Some(rest) = text.strip_prefix(&head) {
        let mut stats = Stats::unset(J::STATS);
        for (name, value) in &mut stats.0 {
            let key = format!("\"{name}\":");
            let found = rest.find(&key).and_then(|at| {
                let at = at + key.len();
                let end = rest[at..].find([',', '}'])? + at;
                Some(&rest[at..end])
            });
            if let Some(v) = found {
                *value = v.to_string();
            }
        }
        return Resume::Done(stats);
    }
    let options_then = text
        .strip_prefix(&format!("{{\"{}\":1,\"options\":{{", J::RECORD))
        .and_then(|r| r.split_once("},\"input\":"));
    let Some((then, input_then)) = options_then else {
        return Resume::Redo("its record is unreadable".into());
    };
    let changed: Vec<String> = job
        .option_fields()
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

/// Runs `job` on one mesh file into `out_dir` (the unit of work of [`run_dataset`] and of a
/// Dask task). An existing output is reused (status `done`, with the statistics of the run that
/// made it) only when its record (`*.meta.json`) shows the same options and the same input size
/// and modification time; otherwise the mesh is processed again and `redone` says why. Only
/// regular files are opened (a FIFO is a failed row, never a hang); outputs are written
/// atomically. Never panics and never fails: the result is the manifest row.
pub fn run_file<J: MeshJob>(job: &J, mesh: &Path, root: &Path, out_dir: &Path) -> ManifestRow {
    let start = Instant::now();
    let (key, output) = output_key(root, mesh, job.extension());
    let mut row = ManifestRow {
        mesh: mesh.to_path_buf(),
        output: output.clone(),
        status: Status::Ok,
        error: None,
        stats: Stats::unset(J::STATS),
        seconds: 0.0,
        redone: None,
    };
    let target = out_dir.join(&output);
    // The error as (status, one line).
    let result = std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| {
        let meta = regular_file_metadata(mesh).map_err(|e| {
            let e = crate::error::LoadError::new(
                mesh,
                crate::error::Location::File,
                crate::error::LoadErrorKind::Io(e),
            );
            (Status::Failed, e.to_string())
        })?;
        let stamp = input_stamp(&meta);
        match resume_state(job, &target, &stamp) {
            Resume::Done(stats) => {
                row.status = Status::Done;
                row.stats = stats;
                return Ok(());
            }
            Resume::Redo(why) => row.redone = Some(why),
            Resume::Fresh => {}
        }
        let deadline = job.time_limit().map(|l| (start + l, l));
        let bytes = job
            .run(mesh, &key, deadline, &mut row.stats)
            .map_err(|e| (J::status(&e), e.to_string()))?;
        write_output(job, &target, &bytes, &stamp, &row.stats)
            .map_err(|e| (Status::Failed, e.to_string()))
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
            Some((Status::Failed, format!("internal error (panic): {msg}")))
        }
    };
    if let Some((status, message)) = err {
        row.status = status;
        row.error = Some(message.replace('\n', " "));
        // What the job had learnt about the input stays; what it would have written does not.
        let unset = Stats::unset(J::STATS);
        for ((name, value), (_, unset)) in row.stats.0.iter_mut().zip(&unset.0) {
            if !J::INPUT_STATS.contains(name) {
                *value = unset.clone();
            }
        }
    }
    row.seconds = start.elapsed().as_secs_f64();
    row
}

/// Writes one output and its record: the old record first (were we killed between the two
/// writes, a stale record must not vouch for the new file), the output, then the record.
fn write_output<J: MeshJob>(
    job: &J,
    target: &Path,
    bytes: &[u8],
    stamp: &str,
    stats: &Stats,
) -> Result<(), DatasetError> {
    let record = record_path(target, job.extension());
    match std::fs::remove_file(&record) {
        Err(e) if e.kind() != std::io::ErrorKind::NotFound => {
            return Err(DatasetError::Write {
                path: record,
                source: e,
            });
        }
        _ => {}
    }
    write_atomically(target, bytes)?;
    let fields: Vec<String> = stats
        .0
        .iter()
        .map(|(n, v)| format!("\"{n}\":{v}"))
        .collect();
    let text = format!("{}{}}}\n", record_head(job, stamp), fields.join(","));
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
pub fn write_atomically(target: &Path, bytes: &[u8]) -> Result<(), DatasetError> {
    use std::sync::atomic::{AtomicU64, Ordering};
    static COUNTER: AtomicU64 = AtomicU64::new(0);
    let fail = |source| DatasetError::Write {
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

/// The whole job: checks the options and that no two meshes share an output, removes the
/// temporary files of an interrupted run, runs `job` on every mesh (side by side on the current
/// rayon pool, or one after the other: [`MeshJob::MESHES_IN_PARALLEL`]), calls `progress` after
/// each, and writes `manifest.jsonl` (rows in input order) into `out_dir`. `root` defaults to
/// [`common_root`] of the inputs. Returns the rows.
pub fn run_dataset<J: MeshJob>(
    job: &J,
    meshes: &[PathBuf],
    out_dir: &Path,
    root: Option<&Path>,
    progress: impl Fn(&ManifestRow) + Sync,
) -> Result<Vec<ManifestRow>, DatasetError> {
    job.validate().map_err(DatasetError::Options)?;
    let root = root.map_or_else(|| common_root(meshes), normalize_path);
    plan_outputs(meshes, &root, job.extension())?;
    let write_err = |source| DatasetError::Write {
        path: out_dir.to_path_buf(),
        source,
    };
    std::fs::create_dir_all(out_dir).map_err(write_err)?;
    remove_partial_files(out_dir).map_err(write_err)?;
    let one = |m: &PathBuf| {
        let row = run_file(job, m, &root, out_dir);
        progress(&row);
        row
    };
    let rows: Vec<ManifestRow> = if J::MESHES_IN_PARALLEL {
        meshes.par_iter().with_max_len(1).map(one).collect()
    } else {
        meshes.iter().map(one).collect()
    };
    write_manifest(out_dir, &rows)?;
    Ok(rows)
}

/// Writes `manifest.jsonl` (one [`ManifestRow::to_json`] per line) atomically into `out_dir`.
pub fn write_manifest(out_dir: &Path, rows: &[ManifestRow]) -> Result<PathBuf, DatasetError> {
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
    fn keys_and_roots() {
        let root = common_root(&[PathBuf::from("/d/a/x.obj"), PathBuf::from("/d/b/c/y.glb")]);
        assert_eq!(root, PathBuf::from("/d"));
        let (key, out) = output_key(&root, Path::new("/d/b/c/y.glb"), "npz");
        assert_eq!(key, "b/c/y.glb");
        assert_eq!(out, PathBuf::from("b/c/y.glb.npz"));
        assert_eq!(
            record_path(Path::new("o/b/c/y.glb.ply"), "ply"),
            PathBuf::from("o/b/c/y.glb.meta.json")
        );
        assert_eq!(
            common_root(&[PathBuf::from("/d/a/x.obj")]),
            PathBuf::from("/d/a")
        );
    }
}
