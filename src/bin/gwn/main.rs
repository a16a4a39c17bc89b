//! The `gwn` command-line tool: a thin shell over the library. One file per subcommand; each
//! exposes `Args` (clap) and `run(args) -> Result<(), CliError>`.

use clap::{Parser, Subcommand};

mod common;

/// Robust generalized winding numbers for open, dirty triangle meshes.
///
/// The winding number w(q) tells how many times a surface wraps around the point q: 1 inside a
/// closed outward-oriented mesh, 0 outside, a fraction near holes. `gwn` computes it exactly
/// (Antipodal method with exact integer predicates), directly (solid-angle sum), or fast
/// (Barnes-Hut approximation).
#[derive(Parser)]
#[command(name = "gwn", version, about, long_about)]
struct Cli {
    /// Worker threads for batch evaluation (default: all cores).
    #[arg(long, global = true)]
    threads: Option<usize>,
    #[command(subcommand)]
    command: Option<Command>,
}

#[derive(Subcommand)]
enum Command {
    // SUBCOMMANDS: one variant per file in src/bin/gwn/ (keep alphabetical).
}

fn main() {
    let cli = Cli::parse();
    if let Some(n) = cli.threads {
        if let Err(e) = rayon::ThreadPoolBuilder::new()
            .num_threads(n)
            .build_global()
        {
            eprintln!("gwn: cannot set --threads {n}: {e}");
            std::process::exit(2);
        }
    }
    let result = match cli.command {
        // DISPATCH: one arm per variant.
        None => Err(common::CliError::msg(
            "no subcommand given; see `gwn --help`",
        )),
    };
    if let Err(e) = result {
        eprintln!("gwn: {e}");
        std::process::exit(1);
    }
}
