//! `gwn gen`: writes a corpus of degenerate meshes (OBJ/OFF/STL) with query files carrying
//! certified winding numbers, reproducible bit for bit from the seed.

use std::fs::File;
use std::io::{BufWriter, Write};
use std::path::{Path, PathBuf};

use gwn::RayAxis;
use gwn::testing::{Kind, Oracle, export};

use crate::common::CliError;
use crate::method::parse_option;

/// Arguments of `gwn gen`.
///
/// Case `i` of a run is generated from seed `S + i`, and every file is named after its own seed
/// (`KIND-SEED.obj`, `.off`, `.stl`, `KIND-SEED.queries.csv`), so runs are reproducible and
/// overlapping runs write identical files. The CSV has the columns `x,y,z,lo,hi,inside`: the
/// certified enclosure [lo, hi] of the winding number at the query perturbed along the ray frame
/// (`--ray`), and `inside` = 1 (certainly > 1/2), 0 (certainly < 1/2) or `?`.
///
/// Kinds: soup, boxes, polycube, t-junction, open, inconsistent, fan, tets, or `all`.
///
/// Example:
///   gwn gen --kind polycube --seed 1 --count 100 --out corpus/
#[derive(clap::Args, Debug)]
#[command(verbatim_doc_comment)]
pub struct Args {
    /// Generator kind (see `docs/testing-kit.md`), or `all`.
    #[arg(long)]
    pub kind: String,
    /// Seed of the first case; case i uses seed + i.
    #[arg(long, default_value_t = 0)]
    pub seed: u64,
    /// Number of cases per kind (at most 1000000: four files each).
    #[arg(long, default_value_t = 10)]
    pub count: u64,
    /// Output directory (created if missing).
    #[arg(long)]
    pub out: PathBuf,
    /// Ray direction (+x, -x, +y, -y, +z or -z) whose perturbation defines the values of
    /// on-surface queries.
    #[arg(long, default_value = "+z", allow_hyphen_values = true,
          value_parser = parse_option::<RayAxis>)]
    pub ray: RayAxis,
}

/// Most cases per kind: four files each, so a million is four million files of a few
/// kilobytes; more is a typo (a count in the hundreds of billions filled the disk).
pub const MAX_COUNT: u64 = 1_000_000;

/// Runs `gwn gen`.
pub fn run(args: Args) -> Result<(), CliError> {
    if args.count > MAX_COUNT {
        return Err(CliError(format!(
            "--count: {} cases per kind is above the limit {MAX_COUNT}",
            args.count
        )));
    }
    let kinds: Vec<Kind> = if args.kind == "all" {
        Kind::ALL.to_vec()
    } else {
        let k = Kind::from_name(&args.kind).ok_or_else(|| {
            let names: Vec<&str> = Kind::ALL.iter().map(|k| k.name()).collect();
            CliError(format!(
                "unknown kind {:?}; expected one of {} or all",
                args.kind,
                names.join(", ")
            ))
        })?;
        vec![k]
    };
    std::fs::create_dir_all(&args.out).map_err(|e| {
        CliError(format!(
            "{}: cannot create directory: {e}",
            args.out.display()
        ))
    })?;
    let ray = args.ray;
    // Written as the cases are, so that its size does not grow in memory with `--count`.
    let manifest_path = args.out.join("manifest.csv");
    let manifest_err =
        |e: std::io::Error| CliError(format!("{}: cannot write: {e}", manifest_path.display()));
    let mut manifest = BufWriter::new(File::create(&manifest_path).map_err(manifest_err)?);
    manifest
        .write_all(b"name,kind,seed,vertices,triangles,queries,undecided\n")
        .map_err(manifest_err)?;
    for kind in kinds {
        for i in 0..args.count {
            let seed = args.seed.wrapping_add(i);
            let case = kind.generate(seed);
            let name = format!("{}-{seed}", kind.name());
            let oracle = Oracle::new(&case.mesh, ray);
            let values: Vec<_> = case.queries.iter().map(|&q| oracle.eval(q)).collect();
            let undecided = values
                .iter()
                .filter(|c| c.decide(0.5) == gwn::testing::Decision::Undecided)
                .count();
            write(&args.out, &format!("{name}.obj"), |w| {
                gwn::mesh::write_obj(w, &case.mesh)
            })?;
            write(&args.out, &format!("{name}.off"), |w| {
                export::write_off(w, &case.mesh)
            })?;
            write(&args.out, &format!("{name}.stl"), |w| {
                export::write_stl(w, &case.mesh)
            })?;
            write(&args.out, &format!("{name}.queries.csv"), |w| {
                export::write_queries_csv(w, &case.queries, &values)
            })?;
            writeln!(
                manifest,
                "{name},{},{seed},{},{},{},{undecided}",
                kind.name(),
                case.mesh.positions().len(),
                case.mesh.triangles().len(),
                case.queries.len()
            )
            .map_err(manifest_err)?;
        }
    }
    manifest.flush().map_err(manifest_err)
}

fn write(
    dir: &Path,
    name: &str,
    body: impl FnOnce(&mut BufWriter<File>) -> std::io::Result<()>,
) -> Result<(), CliError> {
    let path = dir.join(name);
    let err = |e: std::io::Error| CliError(format!("{}: cannot write: {e}", path.display()));
    let mut w = BufWriter::new(File::create(&path).map_err(err)?);
    body(&mut w).map_err(err)?;
    w.flush().map_err(err)
}
