//! `gwn label`: the dataset labelling job (sample, label with w / occupancy / SDF, one `.npz` per
//! mesh, a manifest).

use std::collections::{HashSet, VecDeque};
use std::path::{Path, PathBuf};
use std::time::{Duration, Instant};

use clap::Args as ClapArgs;
use gwn::products::label::{JobOptions, SamplingOptions, Status, label_dataset};

use crate::common::{CliError, outln, progress};

/// Label a dataset of meshes for learning: per mesh, sample points uniform in the padded bounding
/// box and near the surface (Gaussian offsets), label them with the exact winding number w,
/// occupancy (w > 1/2) and signed distance (signed by w), and write OUT/<path below the root>.npz
/// with arrays points (N,3) float64, source (N,) uint8 (0 uniform, k near-surface with the k-th
/// sigma), w, occupancy (bool) and sdf. OUT/manifest.jsonl gets one JSON line per mesh: status
/// ok / done / failed / timeout, the error, faces, points, seconds.
///
/// Reproducible byte for byte (per-mesh seeds from --seed and the path below the root; any thread
/// count). Resumable: an existing .npz is reused only when its record (.meta.json beside it) shows
/// the same options and input size and time; otherwise it is redone and the manifest says why
/// (outputs are renamed into place when complete; temporary files of a killed run are removed).
/// Broken files, FIFOs and devices are manifest rows; two inputs with one output are refused up
/// front; the exit code is 0 unless the job itself cannot run.
///
/// Example: gwn label ../shared/meshes --out labels --uniform 20000 --near 20000 --time-limit 60
#[derive(ClapArgs, Debug)]
#[command(verbatim_doc_comment)]
pub struct Args {
    /// Mesh files or folders (every .obj/.stl/.off/.ply/.gltf/.glb below, recursively, sorted).
    pub inputs: Vec<PathBuf>,
    /// A text file with one mesh path per line (added to INPUTS; blank lines and # comments skipped).
    #[arg(long)]
    pub list: Option<PathBuf>,
    /// Output folder.
    #[arg(long, short, default_value = "labels")]
    pub out: PathBuf,
    /// Outputs mirror the inputs' paths below this folder (default: the deepest folder holding
    /// every input).
    #[arg(long)]
    pub root: Option<PathBuf>,
    /// Points uniform in the padded bounding box, per mesh.
    #[arg(long, default_value_t = 50_000)]
    pub uniform: usize,
    /// Points near the surface, per mesh (split evenly between the sigmas).
    #[arg(long, default_value_t = 50_000)]
    pub near: usize,
    /// Standard deviations of the near-surface offsets, as fractions of the bounding-box diagonal.
    #[arg(long, value_delimiter = ',', default_value = "0.005,0.05")]
    pub sigma: Vec<f64>,
    /// Padding of the uniform box on every side, as a fraction of the bounding-box diagonal.
    #[arg(long, default_value_t = 0.05)]
    pub padding: f64,
    /// Seed of the run.
    #[arg(long, default_value_t = 0)]
    pub seed: u64,
    /// Per-mesh time limit in seconds (checked between stages and every 1024 points).
    #[arg(long)]
    pub time_limit: Option<f64>,
    /// Do not weld STL and glTF vertices.
    #[arg(long)]
    pub no_weld: bool,
}

/// Runs `gwn label`.
pub fn run(args: Args) -> Result<(), CliError> {
    let mut meshes = Vec::new();
    let mut walked = HashSet::new();
    for p in &args.inputs {
        if p.is_dir() {
            let mut linked = VecDeque::from([p.clone()]);
            while let Some(dir) = linked.pop_front() {
                collect_meshes(&dir, &mut meshes, &mut walked, &mut linked)?;
            }
        } else {
            meshes.push(p.clone());
        }
    }
    if let Some(list) = &args.list {
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
    let time_limit = match args.time_limit {
        Some(s) if s.is_finite() && s > 0.0 && s < 1e9 => Some(Duration::from_secs_f64(s)),
        Some(s) => {
            return Err(CliError(format!(
                "--time-limit {s}: expected a positive number of seconds"
            )));
        }
        None => None,
    };
    let opts = JobOptions {
        sampling: SamplingOptions {
            uniform: args.uniform,
            near: args.near,
            sigmas: args.sigma.clone(),
            padding: args.padding,
            seed: args.seed,
        },
        time_limit,
        load: gwn::io::LoadOptions {
            weld: if args.no_weld { Some(false) } else { None },
        },
    };
    let pb = progress(meshes.len() as u64, "label");
    let start = Instant::now();
    let rows = label_dataset(&meshes, &args.out, args.root.as_deref(), &opts, |row| {
        pb.set_message(row.mesh.display().to_string());
        pb.inc(1);
    })?;
    pb.finish_and_clear();
    let secs = start.elapsed().as_secs_f64();
    let count = |s: Status| rows.iter().filter(|r| r.status == s).count();
    let points: usize = rows.iter().map(|r| r.points).sum();
    let ok = count(Status::Ok);
    let redone = rows.iter().filter(|r| r.redone.is_some()).count();
    outln!(
        "labelled {ok} meshes ({} done before, {redone} redone, {} failed, {} timed out), {points} points in {secs:.3} s: {:.2} meshes/s, {:.0} points/s; manifest: {}",
        count(Status::Done),
        count(Status::Failed),
        count(Status::Timeout),
        ok as f64 / secs.max(1e-9),
        points as f64 / secs.max(1e-9),
        args.out.join("manifest.jsonl").display()
    )?;
    for r in rows.iter().filter(|r| r.redone.is_some()) {
        eprintln!(
            "gwn label: redone {}: {}",
            r.mesh.display(),
            r.redone.as_deref().unwrap_or_default()
        );
    }
    for r in rows.iter().filter(|r| r.error.is_some()) {
        eprintln!(
            "gwn label: {} {}: {}",
            r.status.as_str(),
            r.mesh.display(),
            r.error.as_deref().unwrap_or_default()
        );
    }
    Ok(())
}

/// Every mesh file below `dir` (known extensions), recursively, sorted; folders reached through a
/// symlink are put on `linked` for later, so a file is named by its real path when the walk
/// reaches it both ways. Each real folder is walked once (`walked` holds canonical paths): a link
/// to an ancestor cannot loop, and two links to one folder do not list its files twice. Files
/// that are not regular (FIFOs, devices) are listed too: the job makes each a failed row without
/// opening it.
fn collect_meshes(
    dir: &Path,
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
                collect_meshes(&p, out, walked, linked)?;
            }
        } else if gwn::io::format_from_extension(&p).is_some() {
            out.push(p);
        }
    }
    Ok(())
}
