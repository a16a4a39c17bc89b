//! `gwn voxelize`: the winding number on a voxel grid (ray reuse) as `.npy` / `.vti`.

use std::path::{Path, PathBuf};

use clap::{Args as ClapArgs, ValueEnum};
use gwn::BoundingBox;
use gwn::grid::{GridError, GridSpec};
use gwn::products::{npy, vti};

use crate::common::{CliError, outln, progress};
use gwn::input::Input;

use crate::method::{MethodArgs, ToleranceArgs};

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
    /// Checks the options that do not depend on the mesh, so that bad values fail before the
    /// mesh is loaded.
    pub fn check(&self) -> Result<(), CliError> {
        if !(self.margin.is_finite() && self.margin >= 0.0) {
            return Err(CliError(format!(
                "--margin {}: expected a non-negative number",
                self.margin
            )));
        }
        if let Some(b) = &self.bounds {
            if let Some(bad) = b.iter().find(|c| !c.is_finite()) {
                return Err(CliError(format!("--bounds: {bad} is not a finite number")));
            }
            for k in 0..3 {
                let extent = b[k + 3] - b[k];
                if extent < 0.0 {
                    return Err(CliError(format!(
                        "--bounds: {} max {:?} is below min {:?}",
                        ["x", "y", "z"][k],
                        b[k + 3],
                        b[k]
                    )));
                }
                if !extent.is_finite() {
                    return Err(CliError(format!(
                        "--bounds: the {} extent {:?} - ({:?}) overflows",
                        ["x", "y", "z"][k],
                        b[k + 3],
                        b[k]
                    )));
                }
            }
        }
        Ok(())
    }

    /// The grid for `input`; refused when its `bytes_per_cell` (what the subcommand holds per
    /// cell at its peak) exceed the memory available.
    pub fn spec(
        &self,
        input: &Input,
        name: &Path,
        bytes_per_cell: usize,
    ) -> Result<GridSpec, CliError> {
        let bounds = match &self.bounds {
            Some(b) => BoundingBox {
                min: [b[0], b[1], b[2]],
                max: [b[3], b[4], b[5]],
            },
            None => {
                self.check()?;
                input
                    .bounding_box()
                    .ok_or_else(|| {
                        CliError::msg(format!("{}: has no triangles or points", name.display()))
                    })?
                    .enlarged(self.margin)
            }
        };
        let spec = match &self.dims {
            Some(d) => GridSpec::new(bounds, [d[0], d[1], d[2]]),
            None => GridSpec::with_resolution(bounds, self.res),
        }
        .map_err(|e| CliError::msg(format!("bad grid: {e}")))?;
        // The library's check, shared with the Python package.
        spec.check_memory(bytes_per_cell, gwn::grid::available_memory())
            .map_err(|e| match e {
                GridError::OutOfMemory { .. } => CliError(format!("{e}; lower --res or --dims")),
                e => CliError(e.to_string()),
            })?;
        Ok(spec)
    }

    /// Writes `values` as `.npy` (and `.vti` if asked); returns the paths written. With
    /// `check_f32`, a `float32` output that cannot hold the values ([`npy::check_f32`]) is
    /// refused before anything is written (signed distances; winding numbers only lose
    /// negligible far-field digits).
    pub fn write(
        &self,
        spec: &GridSpec,
        values: &[f64],
        out: &Path,
        name: &str,
        check_f32: bool,
    ) -> Result<Vec<PathBuf>, CliError> {
        if check_f32 && self.dtype == Dtype::F32 {
            npy::check_f32(values)
                .map_err(|e| CliError(format!("{}: {e}; use --dtype f64", out.display())))?;
        }
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
    CliError::msg(format!("{}: cannot write: {e}", p.display()))
}

/// Peak bytes per cell of `gwn voxelize`: the library's grid evaluation, the `f32` copy for
/// `.npy` and the occupancy.
pub const VOXELIZE_BYTES_PER_CELL: usize = gwn::grid::EVALUATE_BYTES_PER_CELL + 4 + 1;

/// Winding numbers on a voxel grid, written as `.npy` (and optionally `.vti`).
///
/// The `.npy` is C order with shape (D, H, W), indexed [z, y, x]; samples are at cell centres.
/// With the exact method one ray per grid column along z is shared by all voxels of the column
/// (ray reuse); values equal per-point evaluation exactly. Point clouds use the fast method.
#[derive(ClapArgs, Debug)]
pub struct Args {
    /// Mesh file (OBJ, STL, OFF, PLY, glTF/GLB), patch set (.bpt, .rbpt) or oriented point cloud
    /// (.xyz, .csv, .pts, .ply).
    pub mesh: PathBuf,
    #[command(flatten)]
    pub grid: GridArgs,
    #[command(flatten)]
    pub method: MethodArgs,
    /// Output `.npy` with the winding numbers.
    #[arg(long, short, default_value = "winding.npy")]
    pub out: PathBuf,
    /// Also write a uint8 occupancy `.npy` (1 where w > T) at this threshold.
    #[arg(long, value_name = "T", allow_negative_numbers = true)]
    pub occupancy: Option<f64>,
    /// Path of the occupancy `.npy` (default: OUT with `-occupancy` appended to its stem).
    #[arg(long)]
    pub occupancy_out: Option<PathBuf>,
    #[command(flatten)]
    pub weld: crate::common::WeldArgs,
    #[command(flatten)]
    pub tolerance: ToleranceArgs,
}

/// Runs `gwn voxelize`.
pub fn run(args: Args) -> Result<(), CliError> {
    if let Some(t) = args.occupancy {
        crate::common::check_threshold(t, "--occupancy")?;
    }
    if args.occupancy_out.is_some() && args.occupancy.is_none() {
        return Err(CliError::msg(
            "--occupancy-out needs --occupancy T (the threshold)",
        ));
    }
    args.grid.check()?;
    let method = args.method.spec(args.tolerance, args.weld);
    method.validate()?;
    let input = crate::method::load_input(&args.mesh, args.weld)?;
    let spec = args
        .grid
        .spec(&input, &args.mesh, VOXELIZE_BYTES_PER_CELL)?;
    let wn = crate::method::build(&method, &input, &args.mesh)?;
    let pb = progress(
        spec.column_count(gwn::grid::column_axis(&wn)) as u64,
        "voxelize",
    );
    let start = std::time::Instant::now();
    let values = gwn::grid::evaluate_with_progress(&wn, &spec, |n| pb.inc(n as u64));
    pb.finish_and_clear();
    let secs = start.elapsed().as_secs_f64();
    let mut written = args.grid.write(&spec, &values, &args.out, "w", false)?;
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
        npy::save(&path, &spec.shape(), &occ).map_err(|e| io_err(&path, e))?;
        let inside = occ.iter().filter(|&&o| o == 1).count();
        outln!("occupancy (w > {t}): {inside} of {} voxels", occ.len())?;
        written.push(path);
    }
    report_grid(&spec, secs, "voxels", "", &written)
}

/// The summary `gwn voxelize` and `gwn sdf` print: size, layout, throughput, files written.
pub fn report_grid(
    spec: &GridSpec,
    secs: f64,
    noun: &str,
    extra: &str,
    written: &[PathBuf],
) -> Result<(), CliError> {
    let [w, h, d] = spec.dims;
    outln!(
        "{} {noun} (W×H×D = {w}×{h}×{d}, npy shape ({d}, {h}, {w})){extra} in {secs:.3} s ({:.3e} {noun}/s)",
        spec.len(),
        spec.len() as f64 / secs.max(1e-9),
    )?;
    for p in written {
        outln!("wrote {}", p.display())?;
    }
    Ok(())
}
