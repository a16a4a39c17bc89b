//! `gwn filter-tets`: keep the tets of a tet mesh whose centroid is inside a surface.

use std::path::PathBuf;

use clap::Args as ClapArgs;
use gwn::io::tets::{load_tets, save_tets};
use gwn::products::tets::{DEFAULT_THRESHOLD, filter_tets};

use crate::common::{CliError, check_threshold, outln};
use crate::method::MethodArgs;

/// Keep the tets of TETS whose centroid has w(MESH) > threshold, and write them to OUT.
///
/// TETS and OUT are MEDIT `.mesh` or TetGen `.node`/`.ele` (either file of the pair names it).
/// Unreferenced points are dropped from the output.
#[derive(ClapArgs, Debug)]
pub struct Args {
    /// Surface mesh (OBJ, STL, OFF, PLY, glTF/GLB), patch set (.bpt, .rbpt) or oriented point cloud
    /// (.xyz, .csv, .pts, .ply).
    pub mesh: PathBuf,
    #[command(flatten)]
    pub method: MethodArgs,
    /// Tet mesh (.mesh, .node or .ele).
    pub tets: PathBuf,
    /// Output tet mesh (.mesh, .node or .ele).
    #[arg(long, short)]
    pub out: PathBuf,
    /// Keep tets with w at the centroid above this value.
    #[arg(long, default_value_t = DEFAULT_THRESHOLD, allow_negative_numbers = true)]
    pub threshold: f64,
    #[command(flatten)]
    pub weld: crate::common::WeldArgs,
    #[command(flatten)]
    pub tolerance: crate::method::ToleranceArgs,
}

/// Runs `gwn filter-tets`.
pub fn run(args: Args) -> Result<(), CliError> {
    check_threshold(args.threshold, "--threshold")?;
    let method = args.method.spec(args.tolerance, args.weld);
    method.validate()?;
    let input = crate::method::load_input(&args.mesh, args.weld)?;
    let tets = load_tets(&args.tets)?;
    let wn = crate::method::build(&method, &input, &args.mesh)?;
    let keep = filter_tets(&tets.points, &tets.tets, &wn, args.threshold);
    let kept = tets.select(&keep);
    // `save_tets` errors already start with the file they concern.
    let written = save_tets(&args.out, &kept).map_err(|e| CliError::msg(e.to_string()))?;
    outln!(
        "kept {} of {} tets (w > {} at the centroid)",
        kept.tets.len(),
        tets.tets.len(),
        args.threshold
    )?;
    for p in written {
        outln!("wrote {}", p.display())?;
    }
    Ok(())
}
