//! What the dataset jobs (`gwn label`, `gwn remesh-dataset`) share on the command line: the
//! inputs (files, folders walked, a list file) and the report of failed and redone meshes.

use std::collections::{HashSet, VecDeque};
use std::path::{Path, PathBuf};
use std::time::Duration;

use clap::Args as ClapArgs;
use gwn::products::dataset::{ManifestRow, MeshJob, run_dataset};

use crate::common::CliError;

/// The meshes of a dataset job.
#[derive(ClapArgs, Debug)]
pub struct DatasetInputs {
    /// Input files or folders: every file below that the command reads, recursively, sorted
    /// (meshes: .obj/.stl/.off/.ply/.gltf/.glb; gwn remesh-dataset also takes STEP models
    /// .step/.stp and patch sets .bpt/.rbpt, and point clouds named one by one or in --list).
    pub inputs: Vec<PathBuf>,
    /// A text file with one mesh path per line (added to INPUTS; blank lines and # comments skipped).
    #[arg(long)]
    pub list: Option<PathBuf>,
    /// Outputs mirror the inputs' paths below this folder (default: the deepest folder holding
    /// every input).
    #[arg(long)]
    pub root: Option<PathBuf>,
}

impl DatasetInputs {
    /// The input files, folders walked in sorted order (the files `walks` takes), then the
    /// list's; an error when none.
    pub fn meshes(&self, walks: &dyn Fn(&Path) -> bool) -> Result<Vec<PathBuf>, CliError> {
        let mut meshes = Vec::new();
        let mut walked = HashSet::new();
        for p in &self.inputs {
            if p.is_dir() {
                let mut linked = VecDeque::from([p.clone()]);
                while let Some(dir) = linked.pop_front() {
                    collect_meshes(&dir, walks, &mut meshes, &mut walked, &mut linked)?;
                }
            } else {
                meshes.push(p.clone());
            }
        }
        if let Some(list) = &self.list {
            let text = std::fs::read_to_string(list)
                .map_err(|e| CliError(format!("{}: {e}", list.display())))?;
            meshes.extend(
                text.lines()
                    .map(str::trim)
                    .filter(|l| !l.is_empty() && !l.starts_with('#'))
                    .map(PathBuf::from),
            );
        }
        if meshes.is_empty() {
            return Err(CliError::msg("no meshes given (INPUTS or --list)"));
        }
        Ok(meshes)
    }
}

impl DatasetInputs {
    /// Runs `job` over the inputs into `out` with a progress bar named `name`: the rows and the
    /// wall time in seconds.
    pub fn run<J: MeshJob>(
        &self,
        job: &J,
        out: &Path,
        name: &str,
    ) -> Result<(Vec<ManifestRow>, f64), CliError> {
        let meshes = self.meshes(&|p| job.walks(p))?;
        let pb = crate::common::progress(meshes.len() as u64, name);
        let start = std::time::Instant::now();
        let rows = run_dataset(job, &meshes, out, self.root.as_deref(), |row| {
            pb.set_message(row.mesh.display().to_string());
            pb.inc(1);
        })?;
        pb.finish_and_clear();
        Ok((rows, start.elapsed().as_secs_f64()))
    }
}

/// `--time-limit SECONDS` as a duration: positive and finite (below 10⁹ s).
pub fn time_limit(seconds: Option<f64>) -> Result<Option<Duration>, CliError> {
    match seconds {
        Some(s) if s.is_finite() && s > 0.0 && s < 1e9 => Ok(Some(Duration::from_secs_f64(s))),
        Some(s) => Err(CliError(format!(
            "--time-limit {s}: expected a positive number of seconds"
        ))),
        None => Ok(None),
    }
}

/// One stderr line per mesh redone (and why) and per mesh that failed or timed out.
pub fn print_problems(command: &str, rows: &[ManifestRow]) {
    for r in rows.iter().filter(|r| r.redone.is_some()) {
        eprintln!(
            "gwn {command}: redone {}: {}",
            r.mesh.display(),
            r.redone.as_deref().unwrap_or_default()
        );
    }
    for r in rows.iter().filter(|r| r.error.is_some()) {
        eprintln!(
            "gwn {command}: {} {}: {}",
            r.status.as_str(),
            r.mesh.display(),
            r.error.as_deref().unwrap_or_default()
        );
    }
}

/// Every file below `dir` that `walks` takes (by extension), recursively, sorted; folders reached through a
/// symlink are put on `linked` for later, so a file is named by its real path when the walk
/// reaches it both ways. Each real folder is walked once (`walked` holds canonical paths): a link
/// to an ancestor cannot loop, and two links to one folder do not list its files twice. Files
/// that are not regular (FIFOs, devices) are listed too: the job makes each a failed row without
/// opening it.
fn collect_meshes(
    dir: &Path,
    walks: &dyn Fn(&Path) -> bool,
    out: &mut Vec<PathBuf>,
    walked: &mut HashSet<PathBuf>,
    linked: &mut VecDeque<PathBuf>,
) -> Result<(), CliError> {
    let real =
        std::fs::canonicalize(dir).map_err(|e| CliError(format!("{}: {e}", dir.display())))?;
    if !walked.insert(real) {
        return Ok(());
    }
    let mut entries: Vec<PathBuf> = std::fs::read_dir(dir)
        .map_err(|e| CliError(format!("{}: {e}", dir.display())))?
        .filter_map(|e| e.ok().map(|e| e.path()))
        .collect();
    entries.sort();
    for p in entries {
        if p.is_dir() {
            if p.symlink_metadata()
                .is_ok_and(|m| m.file_type().is_symlink())
            {
                linked.push_back(p);
            } else {
                collect_meshes(&p, walks, out, walked, linked)?;
            }
        } else if walks(&p) {
            out.push(p);
        }
    }
    Ok(())
}
