//! `gwn label`: the dataset labelling job (sample, label with w / occupancy / SDF, one `.npz` per
//! mesh, a manifest).

use std::path::PathBuf;

use clap::Args as ClapArgs;
use gwn::products::dataset::Status;
use gwn::products::label::{JobOptions, SamplingOptions};

use crate::common::{CliError, outln};
use crate::dataset::{DatasetInputs, print_problems, time_limit};

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
    #[command(flatten)]
    pub inputs: DatasetInputs,
    /// Output folder.
    #[arg(long, short, default_value = "labels")]
    pub out: PathBuf,
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
    let time_limit = time_limit(args.time_limit)?;
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
    let (rows, secs) = args.inputs.run(&opts, &args.out, "label")?;
    let count = |s: Status| rows.iter().filter(|r| r.status == s).count();
    let points: usize = rows.iter().filter_map(|r| r.stats.count("points")).sum();
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
    print_problems("label", &rows);
    Ok(())
}
