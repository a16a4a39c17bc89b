//! `gwn classify`: w of mesh B at every face centroid of mesh A (boolean building block).

use std::path::PathBuf;

use clap::{Args as ClapArgs, ValueEnum};
use gwn::mesh::write_obj;
use gwn::products::classify::{Select, classify_faces, select, submesh};

use crate::common::{CliError, check_threshold, outln};
use crate::method::{MethodArgs, need_mesh};

/// Which faces to select.
#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
pub enum Which {
    /// Faces with w_B > threshold.
    Inside,
    /// Faces with w_B <= threshold.
    Outside,
}

/// Classify each face of A by the winding number of B at its centroid (exact method by default;
/// B may be an oriented point cloud, evaluated with the fast method).
///
/// Writes one value per face of A (CSV, or `.npy` by extension). With --select, also reports
/// the selected faces and writes them as OBJ with --mesh-out. Faces of A lying on B's surface get
/// w_B on the +x side (then +y, then +z) of the surface.
#[derive(ClapArgs, Debug)]
pub struct Args {
    /// Mesh A: the faces to classify.
    pub a: PathBuf,
    /// Mesh B (or oriented point cloud): the solid they are classified against.
    pub b: PathBuf,
    #[command(flatten)]
    pub method: MethodArgs,
    /// Per-face values of w_B (`.npy` float64 of shape (F,), otherwise CSV one per line).
    #[arg(long, short)]
    pub out: PathBuf,
    /// Select faces inside or outside B (default inside when --mesh-out is given).
    #[arg(long, value_enum)]
    pub select: Option<Which>,
    /// Threshold on w_B for --select.
    #[arg(long, default_value_t = 0.5, allow_negative_numbers = true)]
    pub threshold: f64,
    /// Write the selected faces of A as OBJ.
    #[arg(long)]
    pub mesh_out: Option<PathBuf>,
    #[command(flatten)]
    pub weld: crate::common::WeldArgs,
    #[command(flatten)]
    pub tolerance: crate::method::ToleranceArgs,
}

/// Runs `gwn classify`.
pub fn run(args: Args) -> Result<(), CliError> {
    check_threshold(args.threshold, "--threshold")?;
    let method = args.method.spec(args.tolerance, args.weld);
    method.validate()?;
    let a_input = crate::method::load_input(&args.a, args.weld)?;
    let a = need_mesh(&a_input, &args.a, "classify (its faces are classified)")?;
    let b = crate::method::load_input(&args.b, args.weld)?;
    let wn = crate::method::build(&method, &b, &args.b)?;
    let values = classify_faces(a, &wn);
    gwn::io::points::save_values(&args.out, &values)
        .map_err(|e| CliError::msg(format!("{}: cannot write: {e}", args.out.display())))?;
    outln!("wrote {} ({} faces)", args.out.display(), values.len())?;
    let which = args
        .select
        .or(args.mesh_out.as_ref().map(|_| Which::Inside));
    if let Some(which) = which {
        let sel = match which {
            Which::Inside => Select::Inside,
            Which::Outside => Select::Outside,
        };
        let keep = select(&values, sel, args.threshold);
        let n = keep.iter().filter(|&&k| k).count();
        outln!(
            "{n} of {} faces {} (threshold {})",
            keep.len(),
            match which {
                Which::Inside => "inside",
                Which::Outside => "outside",
            },
            args.threshold
        )?;
        if let Some(p) = &args.mesh_out {
            let is_obj = p
                .extension()
                .and_then(|e| e.to_str())
                .is_some_and(|e| e.eq_ignore_ascii_case("obj"));
            if !is_obj {
                return Err(CliError::msg(format!(
                    "{}: --mesh-out writes OBJ only (use a .obj name)",
                    p.display()
                )));
            }
            let cannot_write = |e| CliError::msg(format!("{}: cannot write: {e}", p.display()));
            let f = std::fs::File::create(p).map_err(cannot_write)?;
            write_obj(std::io::BufWriter::new(f), &submesh(a, &keep)).map_err(cannot_write)?;
            outln!("wrote {}", p.display())?;
        }
    }
    Ok(())
}
