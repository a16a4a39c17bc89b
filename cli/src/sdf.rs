//! `gwn sdf`: signed distance on a voxel grid, signed by the winding number.

use std::path::PathBuf;

use clap::Args as ClapArgs;
use gwn::products::sdf::SignedDistance;

use crate::common::{CliError, progress};
use gwn::input::Input;

use crate::method::MethodArgs;
use crate::voxelize::GridArgs;

/// Signed distance to the mesh on a voxel grid, signed by the winding number (`.npy`, `.vti`).
///
/// The `.npy` is C order with shape (D, H, W), indexed [z, y, x]; samples are at cell centres.
/// The distance is to the closest point of the triangles (of a point cloud: to the closest
/// point); the sign is negative where the winding number (exact by default) is above 0.5, which
/// stays correct on open and dirty meshes where pseudo-normal signs fail.
#[derive(ClapArgs, Debug)]
pub struct Args {
    /// Mesh file (OBJ, STL, OFF, PLY, glTF/GLB) or oriented point cloud (.xyz, .csv, .pts, .ply).
    pub mesh: PathBuf,
    #[command(flatten)]
    pub grid: GridArgs,
    #[command(flatten)]
    pub method: MethodArgs,
    /// Output `.npy`.
    #[arg(long, short, default_value = "sdf.npy")]
    pub out: PathBuf,
    #[command(flatten)]
    pub weld: crate::common::WeldArgs,
    #[command(flatten)]
    pub tolerance: crate::method::ToleranceArgs,
}

/// Peak bytes per cell of `gwn sdf`: the library's signed-distance grid and the `f32` copy.
const SDF_BYTES_PER_CELL: usize = gwn::products::sdf::GRID_BYTES_PER_CELL + 4;

/// Runs `gwn sdf`.
pub fn run(args: Args) -> Result<(), CliError> {
    args.grid.check()?;
    let method = args.method.spec(args.tolerance, args.weld);
    method.validate()?;
    let input = crate::method::load_input(&args.mesh, args.weld)?;
    let spec = args.grid.spec(&input, &args.mesh, SDF_BYTES_PER_CELL)?;
    let wn = crate::method::build(&method, &input, &args.mesh)?;
    let sdf = match &input {
        Input::Mesh(mesh) => SignedDistance::with_evaluator(mesh, wn),
        Input::Cloud(cloud) => SignedDistance::with_points(cloud.positions(), wn),
        Input::Patches(_) | Input::Step(_) => {
            return Err(CliError::msg(format!(
                "{}: sdf needs a triangle mesh or a point cloud (tessellate the patches)",
                args.mesh.display()
            )));
        }
    };
    let cols = spec.column_count(gwn::grid::column_axis(sdf.winding_number()));
    let pb = progress((cols + spec.len()) as u64, "sdf");
    let start = std::time::Instant::now();
    let values = sdf.eval_grid_with_progress(&spec, |n| pb.inc(n as u64));
    pb.finish_and_clear();
    let secs = start.elapsed().as_secs_f64();
    let written = args.grid.write(&spec, &values, &args.out, "sdf", true)?;
    let inside = values.iter().filter(|v| v.is_sign_negative()).count();
    crate::voxelize::report_grid(
        &spec,
        secs,
        "points",
        &format!(", {inside} inside,"),
        &written,
    )
}
