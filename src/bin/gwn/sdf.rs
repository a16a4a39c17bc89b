//! `gwn sdf`: signed distance on a voxel grid, signed by the winding number.

use std::path::PathBuf;

use clap::Args as ClapArgs;
use gwn::products::sdf::SignedDistance;

use crate::common::{CliError, load_mesh_for_cli, progress};
use crate::voxelize::GridArgs;

/// Signed distance to the mesh on a voxel grid, signed by the winding number (`.npy`, `.vti`).
///
/// The `.npy` is C order with shape (D, H, W), indexed [z, y, x]; samples are at cell centres.
/// The distance is to the closest point of the triangles; the sign is negative where the exact
/// winding number is above 0.5, which stays correct on open and dirty meshes where
/// pseudo-normal signs fail.
#[derive(ClapArgs, Debug)]
pub struct Args {
    /// Mesh file (OBJ, STL, OFF, PLY, glTF/GLB).
    pub mesh: PathBuf,
    #[command(flatten)]
    pub grid: GridArgs,
    /// Output `.npy`.
    #[arg(long, short, default_value = "sdf.npy")]
    pub out: PathBuf,
    /// Do not weld STL vertices.
    #[arg(long)]
    pub no_weld: bool,
}

/// Runs `gwn sdf`.
pub fn run(args: Args) -> Result<(), CliError> {
    let mesh = load_mesh_for_cli(&args.mesh, args.no_weld)?;
    let spec = args.grid.spec(&mesh, &args.mesh)?;
    let sdf = SignedDistance::new(&mesh)?;
    let cols = spec.column_count(gwn::grid::ray_world_axis(sdf.winding_number()));
    let pb = progress((cols + spec.len()) as u64, "sdf");
    let start = std::time::Instant::now();
    let values = sdf.eval_grid_with_progress(&spec, |n| pb.inc(n as u64));
    pb.finish_and_clear();
    let secs = start.elapsed().as_secs_f64();
    let written = args.grid.write(&spec, &values, &args.out, "sdf")?;
    let inside = values.iter().filter(|v| v.is_sign_negative()).count();
    crate::voxelize::report_grid(
        &spec,
        secs,
        "points",
        &format!(", {inside} inside,"),
        &written,
    );
    Ok(())
}
