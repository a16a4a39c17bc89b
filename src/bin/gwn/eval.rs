//! `gwn eval`: winding numbers (and gradients) at query points.

use std::path::PathBuf;

use clap::{Args as ClapArgs, ValueEnum};
use gwn::eval::antipodal::{Options, WindingNumber};
use gwn::eval::direct::{winding_number_direct, winding_number_gradient_direct};
use gwn::eval::fast::{FastParams, FastWindingNumber, PointCloudWindingNumber};
use gwn::kernel::frame::RayAxis;
use gwn::kernel::quantize::Precision;
use rayon::prelude::*;

use crate::common::{CliError, load_mesh_for_cli, progress};

/// Evaluation method.
#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
pub enum Method {
    /// Exact Antipodal method (integer predicates; O(boundary + log faces) per query).
    Exact,
    /// Direct solid-angle sum over all faces (O(faces) per query; the reference).
    Direct,
    /// Barnes-Hut approximation (orders 0-2, accuracy --beta); the method for point clouds.
    Fast,
}

/// Ray direction of the exact method.
#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
pub enum Ray {
    /// +z (default)
    #[value(name = "+z")]
    PosZ,
    /// -z
    #[value(name = "-z")]
    NegZ,
    /// +x
    #[value(name = "+x")]
    PosX,
    /// -x
    #[value(name = "-x")]
    NegX,
    /// +y
    #[value(name = "+y")]
    PosY,
    /// -y
    #[value(name = "-y")]
    NegY,
}

impl From<Ray> for RayAxis {
    fn from(r: Ray) -> RayAxis {
        match r {
            Ray::PosZ => RayAxis::PosZ,
            Ray::NegZ => RayAxis::NegZ,
            Ray::PosX => RayAxis::PosX,
            Ray::NegX => RayAxis::NegX,
            Ray::PosY => RayAxis::PosY,
            Ray::NegY => RayAxis::NegY,
        }
    }
}

/// Evaluate the winding number of MESH (or of an oriented point cloud) at query points.
///
/// A point cloud (.xyz/.csv/.txt/.pts with `x y z nx ny nz [area]`, or a PLY with normals and no
/// faces) is evaluated with the fast dipole sum; areas are estimated when absent.
///
/// Points come from a text file (one `x y z` or `x,y,z` per line; `#` comments and a header line
/// are skipped) or a `.npy` float64/float32 array of shape (N, 3). Values go to stdout (one per
/// line) or to `--out` (`.csv` or `.npy`, shape (N,)).
///
/// Examples:
///   gwn eval mesh.obj --points queries.csv
///   gwn eval mesh.stl --points q.npy --out w.npy --method direct
///   gwn eval mesh.off --points q.txt --gradient --gradient-out g.npy
///   gwn eval soup.stl --points q.csv --method fast --beta 2 --order 2
///   gwn eval cloud.xyz --points q.csv
///   gwn eval teapot.bpt --points q.npy --ray -x       # Bézier patches (.bpt / rational .rbpt)
#[derive(ClapArgs, Debug)]
#[command(verbatim_doc_comment)]
pub struct Args {
    /// Mesh file (.obj, .stl, .off, .ply), oriented point cloud (.xyz, .csv, .pts, .ply), or
    /// Bézier patch set (.bpt, rational .rbpt).
    pub mesh: PathBuf,
    /// Query points file (.csv/.txt/.xyz text or .npy).
    #[arg(long)]
    pub points: PathBuf,
    /// Evaluation method.
    #[arg(long, value_enum, default_value_t = Method::Exact)]
    pub method: Method,
    /// Grid bits of the exact method (30: i64 predicates; 60: i128 predicates).
    #[arg(long, default_value_t = 60, value_parser = parse_precision)]
    pub precision: u32,
    /// Ray direction of the exact method (any gives the same value off the surface; on the
    /// surface the value is taken at the point perturbed along this ray's frame).
    #[arg(long, value_enum, default_value_t = Ray::PosZ, allow_hyphen_values = true)]
    pub ray: Ray,
    /// Accuracy of the fast method: a tree node is approximated when its distance exceeds
    /// beta times its radius (Barill et al. 2018); larger is more accurate.
    #[arg(long, default_value_t = 2.0)]
    pub beta: f64,
    /// Expansion order of the fast method (0, 1 or 2).
    #[arg(long, default_value_t = 2, value_parser = clap::value_parser!(u8).range(0..=2))]
    pub order: u8,
    /// Also compute the gradient ∇w (exact and direct methods).
    #[arg(long)]
    pub gradient: bool,
    /// Output file for values (.csv or .npy); stdout when absent.
    #[arg(long)]
    pub out: Option<PathBuf>,
    /// Output file for gradients (.csv or .npy, shape (N, 3)); with --gradient and no file, the
    /// gradient is printed after the value on each stdout line.
    #[arg(long)]
    pub gradient_out: Option<PathBuf>,
    /// Do not weld bit-identical vertices of STL files.
    #[arg(long)]
    pub no_weld: bool,
    /// Patch sets: target absolute error of w (boundary quadrature of the exact method, surface
    /// quadrature of the direct method).
    #[arg(long, default_value_t = 1e-10)]
    pub tolerance: f64,
}

fn parse_precision(s: &str) -> Result<u32, String> {
    match s {
        "30" => Ok(30),
        "60" => Ok(60),
        _ => Err(format!("precision must be 30 or 60, not {s:?}")),
    }
}

/// Runs `gwn eval`.
pub fn run(args: Args) -> Result<(), CliError> {
    if gwn::patch::is_patch_path(&args.mesh) {
        return run_patches(&args);
    }
    if is_point_cloud(&args.mesh) {
        return run_cloud(&args);
    }
    let mesh = load_mesh_for_cli(&args.mesh, args.no_weld)?;
    let points = gwn::io::points::load_points(&args.points)?;
    if args.gradient && args.method == Method::Fast {
        return Err(CliError::msg(
            "--gradient is available with --method exact or direct, not fast",
        ));
    }
    let pb = progress(points.len() as u64, "evaluating");
    let chunk = 4096;
    let (values, grads): (Vec<f64>, Option<Vec<[f64; 3]>>) = match args.method {
        Method::Exact => {
            let precision = if args.precision == 30 {
                Precision::Bits30
            } else {
                Precision::Bits60
            };
            let wn = WindingNumber::with_options(
                &mesh,
                Options {
                    precision,
                    ray: args.ray.into(),
                },
            )
            .map_err(|e| CliError(format!("{}: {e}", args.mesh.display())))?;
            let mut values = Vec::with_capacity(points.len());
            for c in points.chunks(chunk) {
                values.extend(wn.eval_batch(c));
                pb.inc(c.len() as u64);
            }
            let grads = args.gradient.then(|| wn.gradient_batch(&points));
            (values, grads)
        }
        Method::Direct => {
            let mut values = Vec::with_capacity(points.len());
            for c in points.chunks(chunk) {
                values.par_extend(c.par_iter().map(|&q| winding_number_direct(&mesh, q)));
                pb.inc(c.len() as u64);
            }
            let grads = args.gradient.then(|| {
                points
                    .par_iter()
                    .map(|&q| winding_number_gradient_direct(&mesh, q))
                    .collect()
            });
            (values, grads)
        }
        Method::Fast => {
            let params = FastParams::barill(args.beta, args.order);
            let f = FastWindingNumber::with_params(&mesh, params);
            let mut values = Vec::with_capacity(points.len());
            for c in points.chunks(chunk) {
                values.extend(f.eval_batch(c));
                pb.inc(c.len() as u64);
            }
            (values, None)
        }
    };
    pb.finish_and_clear();
    write_outputs(&args, &values, grads.as_deref())
}

/// Text point formats are clouds; a PLY is a cloud when it has no faces.
fn is_point_cloud(path: &std::path::Path) -> bool {
    let ext = path
        .extension()
        .and_then(|e| e.to_str())
        .map(|e| e.to_ascii_lowercase())
        .unwrap_or_default();
    match ext.as_str() {
        "xyz" | "csv" | "txt" | "pts" => true,
        "ply" => matches!(
            gwn::io::load_mesh(path),
            Err(gwn::error::LoadError {
                kind: gwn::error::LoadErrorKind::Empty,
                ..
            })
        ),
        _ => false,
    }
}

fn run_cloud(args: &Args) -> Result<(), CliError> {
    if args.method == Method::Exact && args.gradient {
        return Err(CliError::msg(
            "--gradient is not available for point clouds",
        ));
    }
    let cloud = gwn::io::cloud::load_point_cloud(&args.mesh)?;
    let points = gwn::io::points::load_points(&args.points)?;
    let params = FastParams::barill(args.beta, args.order);
    let wn = PointCloudWindingNumber::with_params(&cloud, params);
    let values = wn.eval_batch(&points);
    write_outputs(args, &values, None)
}

/// Bézier patch sets: the boundary method (`exact`) or the surface quadrature (`direct`).
fn run_patches(args: &Args) -> Result<(), CliError> {
    if args.gradient {
        return Err(CliError::msg("--gradient is not available for patch sets"));
    }
    if !(args.tolerance.is_finite() && args.tolerance > 0.0) {
        return Err(CliError(format!(
            "--tolerance must be a positive number, not {}",
            args.tolerance
        )));
    }
    let set = gwn::patch::load_patches(&args.mesh)?;
    let points = gwn::io::points::load_points(&args.points)?;
    let values = match args.method {
        Method::Exact => gwn::patch::PatchWindingNumber::with_options(
            &set,
            gwn::patch::Options {
                ray: args.ray.into(),
                tolerance: args.tolerance,
            },
        )
        .eval_batch(&points),
        Method::Direct => gwn::patch::surface_quadrature::winding_number_surface_quadrature_batch(
            &set,
            &points,
            args.tolerance,
        ),
        Method::Fast => {
            return Err(CliError::msg(
                "--method fast is not available for patch sets (use exact or direct)",
            ));
        }
    };
    write_outputs(args, &values, None)
}

fn write_outputs(args: &Args, values: &[f64], grads: Option<&[[f64; 3]]>) -> Result<(), CliError> {
    use std::io::Write;
    let save_err =
        |p: &PathBuf, e: std::io::Error| CliError(format!("{}: cannot write: {e}", p.display()));
    if let Some(p) = &args.out {
        gwn::io::points::save_values(p, values).map_err(|e| save_err(p, e))?;
    }
    if let (Some(p), Some(g)) = (&args.gradient_out, grads) {
        gwn::io::points::save_points(p, g).map_err(|e| save_err(p, e))?;
    }
    if args.out.is_none() {
        let stdout = std::io::stdout();
        let mut w = std::io::BufWriter::new(stdout.lock());
        for (i, v) in values.iter().enumerate() {
            let r = match (grads, &args.gradient_out) {
                (Some(g), None) => writeln!(w, "{v:?},{:?},{:?},{:?}", g[i][0], g[i][1], g[i][2]),
                _ => writeln!(w, "{v:?}"),
            };
            if r.is_err() {
                // Broken pipe (e.g. `| head`): stop quietly.
                return Ok(());
            }
        }
    }
    Ok(())
}
