//! `gwn voxelize`: the winding number on a voxel grid (ray reuse) as `.npy` / `.vti`.

use std::path::{Path, PathBuf};

use clap::{Args as ClapArgs, ValueEnum};
use gwn::eval::antipodal::WindingNumber;
use gwn::grid::GridSpec;
use gwn::products::{npy, vti};
use gwn::{BoundingBox, Mesh};

use crate::common::{CliError, load_mesh_for_cli, progress};

/// Element type of the `.npy` output.
#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
pub enum Dtype {
    /// float32
    F32,
    /// float64
    F64,
}

/// The grid options shared by `voxelize` and `sdf`.
#[derive(ClapArgs, Debug)]
pub struct GridArgs {
    /// Cells along the longest side of the bounds (others proportional).
    #[arg(long, default_value_t = 64, conflicts_with = "dims")]
    pub res: usize,
    /// Explicit cell counts along x, y, z (W H D).
    #[arg(long, num_args = 3, value_names = ["W", "H", "D"])]
    pub dims: Option<Vec<usize>>,
    /// Grid bounds x0 y0 z0 x1 y1 z1 (default: the mesh's box grown by --margin).
    #[arg(long, num_args = 6, allow_negative_numbers = true,
          value_names = ["X0", "Y0", "Z0", "X1", "Y1", "Z1"])]
    pub bounds: Option<Vec<f64>>,
    /// Margin around the mesh's bounding box as a fraction of its largest extent (default bounds).
    #[arg(long, default_value_t = 0.05)]
    pub margin: f64,
    /// Element type of the `.npy` output.
    #[arg(long, value_enum, default_value_t = Dtype::F32)]
    pub dtype: Dtype,
    /// Also write VTK ImageData (ascii XML) for ParaView.
    #[arg(long)]
    pub vti: Option<PathBuf>,
}

impl GridArgs {
    /// The grid for `mesh`.
    pub fn spec(&self, mesh: &Mesh, name: &Path) -> Result<GridSpec, CliError> {
        let bounds = match &self.bounds {
            Some(b) => BoundingBox {
                min: [b[0], b[1], b[2]],
                max: [b[3], b[4], b[5]],
            },
            None => {
                if !(self.margin.is_finite() && self.margin >= 0.0) {
                    return Err(CliError::msg("--margin must be a non-negative number"));
                }
                mesh.bounding_box()
                    .ok_or_else(|| {
                        CliError::msg(format!("{}: mesh has no triangles", name.display()))
                    })?
                    .enlarged(self.margin)
            }
        };
        let spec = match &self.dims {
            Some(d) => GridSpec::new(bounds, [d[0], d[1], d[2]]),
            None => GridSpec::with_resolution(bounds, self.res),
        }
        .map_err(|e| CliError::msg(format!("bad grid: {e}")))?;
        const MAX: usize = 1 << 31;
        if spec.len() > MAX {
            return Err(CliError::msg(format!(
                "grid of {:?} cells is too large (limit 2^31)",
                spec.dims
            )));
        }
        Ok(spec)
    }

    /// Writes `values` as `.npy` (and `.vti` if asked); returns the paths written.
    pub fn write(
        &self,
        spec: &GridSpec,
        values: &[f64],
        out: &Path,
        name: &str,
    ) -> Result<Vec<PathBuf>, CliError> {
        let shape = spec.shape();
        match self.dtype {
            Dtype::F64 => npy::save(out, &shape, values).map_err(|e| io_err(out, e))?,
            Dtype::F32 => {
                let v: Vec<f32> = values.iter().map(|&x| x as f32).collect();
                npy::save(out, &shape, &v).map_err(|e| io_err(out, e))?
            }
        }
        let mut written = vec![out.to_path_buf()];
        if let Some(p) = &self.vti {
            vti::save(p, spec, name, values, self.dtype == Dtype::F32).map_err(|e| io_err(p, e))?;
            written.push(p.clone());
        }
        Ok(written)
    }
}

fn io_err(p: &Path, e: std::io::Error) -> CliError {
    CliError::msg(format!("{}: {e}", p.display()))
}

/// Winding numbers on a voxel grid, written as `.npy` (and optionally `.vti`).
///
/// The `.npy` is C order with shape (D, H, W), indexed [z, y, x]; samples are at cell centres.
/// One ray per grid column along z is shared by all voxels of the column (ray reuse); values
/// equal per-point evaluation exactly.
#[derive(ClapArgs, Debug)]
pub struct Args {
    /// Mesh file (OBJ, STL, OFF, PLY, glTF/GLB).
    pub mesh: PathBuf,
    #[command(flatten)]
    pub grid: GridArgs,
    /// Output `.npy` with the winding numbers.
    #[arg(long, short, default_value = "winding.npy")]
    pub out: PathBuf,
    /// Also write a uint8 occupancy `.npy` (1 where w > T) at this threshold.
    #[arg(long, value_name = "T", allow_negative_numbers = true)]
    pub occupancy: Option<f64>,
    /// Path of the occupancy `.npy` (default: OUT with `-occupancy` appended to its stem).
    #[arg(long)]
    pub occupancy_out: Option<PathBuf>,
    /// Do not weld STL vertices.
    #[arg(long)]
    pub no_weld: bool,
}

/// Runs `gwn voxelize`.
pub fn run(args: Args) -> Result<(), CliError> {
    let mesh = load_mesh_for_cli(&args.mesh, args.no_weld)?;
    let spec = args.grid.spec(&mesh, &args.mesh)?;
    let wn = WindingNumber::new(&mesh)?;
    let pb = progress(
        spec.column_count(gwn::grid::ray_world_axis(&wn)) as u64,
        "voxelize",
    );
    let start = std::time::Instant::now();
    let values = gwn::grid::evaluate_with_progress(&wn, &spec, |n| pb.inc(n as u64));
    pb.finish_and_clear();
    let secs = start.elapsed().as_secs_f64();
    let mut written = args.grid.write(&spec, &values, &args.out, "w")?;
    if let Some(t) = args.occupancy {
        let path = args.occupancy_out.clone().unwrap_or_else(|| {
            let stem = args
                .out
                .file_stem()
                .and_then(|s| s.to_str())
                .unwrap_or("grid");
            args.out.with_file_name(format!("{stem}-occupancy.npy"))
        });
        let occ: Vec<u8> = values.iter().map(|&w| u8::from(w > t)).collect();
        npy::save(&path, &spec.shape(), &occ)
            .map_err(|e| CliError::msg(format!("{}: {e}", path.display())))?;
        let inside = occ.iter().filter(|&&o| o == 1).count();
        println!("occupancy (w > {t}): {inside} of {} voxels", occ.len());
        written.push(path);
    }
    report_grid(&spec, secs, "voxels", "", &written);
    Ok(())
}

/// The summary `gwn voxelize` and `gwn sdf` print: size, layout, throughput, files written.
pub fn report_grid(spec: &GridSpec, secs: f64, noun: &str, extra: &str, written: &[PathBuf]) {
    let [w, h, d] = spec.dims;
    println!(
        "{} {noun} (W×H×D = {w}×{h}×{d}, npy shape ({d}, {h}, {w})){extra} in {secs:.3} s ({:.3e} {noun}/s)",
        spec.len(),
        spec.len() as f64 / secs.max(1e-9),
    );
    for p in written {
        println!("wrote {}", p.display());
    }
}
