//! `gwn remesh-dataset`: `gwn remesh` over a dataset (one closed surface per mesh, a manifest;
//! `gwn::products::remesh::dataset`).

use std::path::PathBuf;

use clap::Args as ClapArgs;
use gwn::products::dataset::Status;
use gwn::products::remesh::dataset::RemeshJob;
use gwn::products::remesh::write::SurfaceFormat;

use crate::common::{CliError, outln};
use crate::dataset::{DatasetInputs, print_problems, time_limit};
use crate::remesh::RemeshKnobs;

/// Remesh a dataset at w = 1/2: per input, the closed, edge- and vertex-manifold, oriented surface
/// of `gwn remesh` (meshes and soups: exact w, the input triangles as the guide; STEP models and
/// patch sets: their own evaluator, vertices at their surface hits; oriented point clouds: the
/// fast evaluator), written to OUT/<path below the root>.FORMAT. OUT/manifest.jsonl gets one
/// JSON line per input: status ok / done / failed / timeout, the error, the input's kind, faces
/// (triangles, patches or B-rep faces) and vertices (mesh vertices or points), the method
/// (exact, parity or fast), how the output was made (kept, reoriented, cut, ...), the output's
/// faces and vertices, whether it is valid (closed, manifold, oriented, no exact
/// self-intersection), its components, the self-intersecting face pairs, the Hausdorff distance
/// in finest cells to where the input bounds the solid (to a fine tessellation of a curved one;
/// none for point clouds) and the occupancy agreement (both sampled; null with --samples 0),
/// seconds.
///
/// Inputs run one after the other, each on every thread. Resumable as `gwn label` is: an
/// existing output is reused only when its record (.meta.json beside it) shows the same options
/// and input size and time; otherwise it is redone and the manifest says why. Broken files,
/// FIFOs and devices are manifest rows; two inputs with one output are refused up front; the exit
/// code is 0 unless the job itself cannot run. --time-limit makes an input that runs past it a
/// timeout row (checked between the remesher's phases and rounds and between chunks of 4096
/// evaluations); memory is bounded anyway (an input that needs more than the machine has is a
/// failed row).
///
/// Example: gwn remesh-dataset ../shared/meshes --out closed --res 128 --samples 0
#[derive(ClapArgs, Debug)]
#[command(verbatim_doc_comment)]
pub struct Args {
    #[command(flatten)]
    pub inputs: DatasetInputs,
    /// Output folder.
    #[arg(long, short, default_value = "remeshed")]
    pub out: PathBuf,
    /// Finest equivalent resolution per mesh (cells of edge: longest extent / res).
    #[arg(long, default_value_t = 128)]
    pub res: usize,
    /// Output format: obj, ply (binary), stl (binary) or glb; the extension appended to each
    /// input's name.
    #[arg(long, default_value = "ply")]
    pub format: String,
    /// Report samples per mesh (occupancy agreement, Hausdorff distance; 0: skip both).
    #[arg(long, default_value_t = 10_000)]
    pub samples: usize,
    /// Close open sheets into slabs of this half-thickness, in finest cells (at least 1): in
    /// cells, since a dataset's meshes come at any scale. Off by default; meshes only (other
    /// inputs are then failed rows).
    #[arg(long, value_name = "CELLS")]
    pub thicken_cells: Option<f64>,
    /// Per-input time limit in seconds (checked between the remesher's phases and rounds, and
    /// between chunks of 4096 evaluations).
    #[arg(long)]
    pub time_limit: Option<f64>,
    /// Do not weld STL and glTF vertices.
    #[arg(long)]
    pub no_weld: bool,
    /// Remesh meshes that are closed but not consistently oriented (flipped faces: w is
    /// fractional near them) by ray parity, the solid they enclose, as `gwn remesh --method
    /// parity` (kept with their faces turned where that is proved); the manifest's method column
    /// says which inputs were. Other inputs as without it.
    #[arg(long)]
    pub parity_where_flipped: bool,
    #[command(flatten)]
    pub knobs: RemeshKnobs,
}

/// Runs `gwn remesh-dataset`.
pub fn run(args: Args) -> Result<(), CliError> {
    let format = SurfaceFormat::of_path(std::path::Path::new(&format!("x.{}", args.format)))
        .ok_or_else(|| {
            CliError::msg(format!(
                "--format {}: expected obj, ply, stl or glb",
                args.format
            ))
        })?;
    let time_limit = time_limit(args.time_limit)?;
    let job = RemeshJob {
        time_limit,
        options: args.knobs.options(args.res, true),
        format,
        samples: args.samples,
        thicken_cells: args.thicken_cells,
        load: gwn::io::LoadOptions {
            weld: if args.no_weld { Some(false) } else { None },
        },
        keep_input: !args.knobs.always_remesh,
        parity_where_flipped: args.parity_where_flipped,
    };
    let (rows, secs) = args.inputs.run(&job, &args.out, "remesh")?;
    let count = |s: Status| rows.iter().filter(|r| r.status == s).count();
    let valid = rows
        .iter()
        .filter(|r| {
            matches!(r.status, Status::Ok | Status::Done) && r.stats.get("valid") == Some("true")
        })
        .count();
    let redone = rows.iter().filter(|r| r.redone.is_some()).count();
    // Empty outputs are right where `w > 1/2` is empty, but a dataset's user wants them
    // counted, by reason (the manifest's `empty` column says which).
    let empty = |why: &str| {
        let value = format!("\"{why}\"");
        rows.iter()
            .filter(|r| r.stats.get("empty") == Some(value.as_str()))
            .count()
    };
    let (inward, no_volume) = (empty("winds inward"), empty("no volume"));
    let parity = rows
        .iter()
        .filter(|r| r.stats.get("method") == Some("\"parity\""))
        .count();
    let parity = if parity > 0 {
        format!("; {parity} by parity (closed, faces flipped: the manifest's method column)")
    } else {
        String::new()
    };
    let empties = if inward + no_volume > 0 {
        format!(
            "; {} outputs empty ({inward} wound inward, {no_volume} without volume: the \
             manifest's empty column)",
            inward + no_volume
        )
    } else {
        String::new()
    };
    outln!(
        "remeshed {} inputs ({} done before, {redone} redone, {} failed, {} timed out) in \
         {secs:.3} s; {valid} outputs valid (closed, manifold, oriented, no self-intersection)\
         {empties}{parity}; manifest: {}",
        count(Status::Ok),
        count(Status::Done),
        count(Status::Failed),
        count(Status::Timeout),
        args.out.join("manifest.jsonl").display()
    )?;
    print_problems("remesh-dataset", &rows);
    Ok(())
}
