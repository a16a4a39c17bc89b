//! The `gwn` command-line tool: a thin shell over the library. One file per subcommand; each
//! exposes `Args` (clap) and `run(args) -> Result<(), CliError>`.

use std::io::Write;

use clap::{Parser, Subcommand};

mod bench;
mod classify;
mod common;
mod curve;
mod dataset;
mod eval;
mod filter_tets;
mod r#gen;
mod info;
mod label;
mod method;
mod remesh;
mod remesh_dataset;
mod sdf;
mod slice;
mod voxelize;

/// Robust generalized winding numbers for open, dirty triangle meshes.
///
/// The winding number w(q) tells how many times a surface wraps around the point q: 1 inside a
/// closed outward-oriented mesh, 0 outside, a fraction near holes. `gwn` computes it exactly
/// (Antipodal method with exact integer predicates), directly (solid-angle sum), or fast
/// (Barnes-Hut approximation).
#[derive(Parser)]
#[command(name = "gwn", version, about, long_about)]
struct Cli {
    /// Worker threads for batch evaluation (default: all cores; more than 4 per core are capped).
    #[arg(long, global = true)]
    threads: Option<usize>,
    #[command(subcommand)]
    command: Option<Command>,
}

#[derive(Subcommand)]
enum Command {
    // SUBCOMMANDS: one variant per file in cli/src/ (keep alphabetical).
    /// Benchmark exact vs direct on meshes (queries/s on a 32³ grid, 1 and 2 threads).
    Bench(bench::Args),
    /// Classify the faces of mesh A by the winding number of mesh B (for booleans).
    Classify(classify::Args),
    /// 2D polygons: GauWN field pictures, untangling and offsetting (`gwn curve --help`).
    Curve(curve::Args),
    /// Evaluate w (and optionally ∇w) at query points.
    Eval(eval::Args),
    /// Keep the tetrahedra of a tet mesh whose centroid has w above a threshold.
    FilterTets(filter_tets::Args),
    /// Write a corpus of degenerate test meshes with certified winding numbers (`gwn gen --help`).
    Gen(r#gen::Args),
    /// Print format, size and topology of a mesh (boundary, non-manifold edges, components…).
    Info(info::Args),
    /// Label a dataset: sample points per mesh, write w / occupancy / SDF as .npz and a manifest.
    Label(label::Args),
    /// A closed, manifold, oriented surface of the solid w > 1/2 (marching tetrahedra, octree).
    Remesh(remesh::Args),
    /// Remesh a dataset: one closed surface per mesh and a manifest (gwn remesh over folders).
    RemeshDataset(remesh_dataset::Args),
    /// Signed distance on a voxel grid, signed by the winding number (inside where w > 1/2).
    Sdf(sdf::Args),
    /// Write a PNG slice of the winding-number field (the default job when no subcommand is given).
    Slice(slice::Args),
    /// Evaluate w on a voxel grid (ray reuse) and write .npy / occupancy / .vti.
    Voxelize(voxelize::Args),
}

fn main() {
    let cli = Cli::parse();
    let result = run(cli).and_then(|()| common::flush_stdout());
    if let Err(e) = result {
        // Ignore a failed write to stderr: the exit code still reports the failure.
        let _ = writeln!(std::io::stderr(), "gwn: {e}");
        std::process::exit(1);
    }
}

fn run(cli: Cli) -> Result<(), common::CliError> {
    if let Some(n) = cli.threads {
        let n = common::checked_threads(n, "--threads")?;
        rayon::ThreadPoolBuilder::new()
            .num_threads(n)
            .build_global()
            .map_err(|e| common::CliError(format!("cannot set --threads {n}: {e}")))?;
    }
    match cli.command {
        // DISPATCH: one arm per variant.
        Some(Command::Bench(a)) => bench::run(a),
        Some(Command::Classify(a)) => classify::run(a),
        Some(Command::Curve(a)) => curve::run(a),
        Some(Command::Eval(a)) => eval::run(a),
        Some(Command::FilterTets(a)) => filter_tets::run(a),
        Some(Command::Gen(a)) => r#gen::run(a),
        Some(Command::Info(a)) => info::run(a),
        Some(Command::Label(a)) => label::run(a),
        Some(Command::Remesh(a)) => remesh::run(a),
        Some(Command::RemeshDataset(a)) => remesh_dataset::run(a),
        Some(Command::Sdf(a)) => sdf::run(a),
        Some(Command::Slice(a)) => slice::run(a),
        Some(Command::Voxelize(a)) => voxelize::run(a),
        None => slice::run_default(),
    }
}
