//! `gwn eval`: winding numbers (and gradients) at query points.

use std::path::PathBuf;

use clap::{Args as ClapArgs, ValueEnum};
use gwn::eval::antipodal::Options;
use gwn::kernel::frame::RayAxis;
use gwn::kernel::quantize::Precision;

use crate::common::{CliError, check_beta, progress, stdout_error};
use crate::method::{Input, Method, MethodArgs};

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
/// faces) is evaluated with the fast dipole sum (--method fast; areas are estimated when absent).
/// An option that does not apply to the method or input (--beta with exact, --precision with
/// fast, --method exact on a cloud) is an error.
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
///   gwn eval part.step --points q.npy --out w.npy     # trimmed B-rep (STEP AP203/AP214/AP242)
#[derive(ClapArgs, Debug)]
#[command(verbatim_doc_comment)]
pub struct Args {
    /// Mesh file (.obj, .stl, .off, .ply), oriented point cloud (.xyz, .csv, .pts, .ply),
    /// Bézier patch set (.bpt, rational .rbpt), or trimmed B-rep model (.step, .stp).
    pub mesh: PathBuf,
    /// Query points file (.csv/.txt/.xyz text or .npy).
    #[arg(long)]
    pub points: PathBuf,
    #[command(flatten)]
    pub method: MethodArgs,
    /// Grid bits of the exact method (30: i64 predicates; 60: i128 predicates) [default: 60].
    #[arg(long, value_parser = parse_precision)]
    pub precision: Option<u32>,
    /// Ray direction of the exact method (any gives the same value off the surface; on the
    /// surface the value is taken at the point perturbed along this ray's frame) [default: +z].
    #[arg(long, value_enum, allow_hyphen_values = true)]
    pub ray: Option<Ray>,
    /// Also compute the gradient ∇w (every method; for fast, the derivative of its expansion).
    #[arg(long)]
    pub gradient: bool,
    /// Output file for values (.csv or .npy); stdout when absent.
    #[arg(long)]
    pub out: Option<PathBuf>,
    /// Output file for gradients (.csv or .npy, shape (N, 3)); with --gradient and no file, the
    /// gradient is printed after the value on each stdout line.
    #[arg(long)]
    pub gradient_out: Option<PathBuf>,
    #[command(flatten)]
    pub weld: crate::common::WeldArgs,
    /// Target absolute error of w. Meshes, exact method: far boundary clusters are replaced by a
    /// multipole expansion with a certified bound (docs/boundary.md; 0 = the flat exact loop, the
    /// integer part is always exact). Patch sets: boundary quadrature of the exact method, surface
    /// quadrature of the direct method.
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
    if gwn::patch::step::is_step_path(&args.mesh) {
        return run_step(&args);
    }
    if let Some(beta) = args.method.beta {
        check_beta(beta)?;
    }
    if args.gradient_out.is_some() && !args.gradient {
        return Err(CliError::msg(
            "--gradient-out needs --gradient (no gradient is computed without it)",
        ));
    }
    crate::common::check_boundary_tolerance(args.tolerance)?;
    let input = Input::load(&args.mesh, args.weld)?;
    let method = args.method.method(&input);
    if method != Method::Exact {
        for (given, flag) in [
            (args.precision.is_some(), "--precision"),
            (args.ray.is_some(), "--ray"),
        ] {
            if given {
                return Err(CliError::msg(format!(
                    "{flag} applies to --method exact only"
                )));
            }
        }
    }
    let options = Options {
        precision: if args.precision == Some(30) {
            Precision::Bits30
        } else {
            Precision::Bits60
        },
        ray: args.ray.unwrap_or(Ray::PosZ).into(),
        tolerance: args.tolerance,
        ..args.weld.exact_options()
    };
    let wn = args.method.build(&input, &args.mesh, options)?;
    let points = gwn::io::points::load_points(&args.points)?;
    let pb = progress(points.len() as u64, "evaluating");
    let mut values = Vec::with_capacity(points.len());
    for c in points.chunks(4096) {
        values.extend(wn.eval_batch(c));
        pb.inc(c.len() as u64);
    }
    pb.finish_and_clear();
    let grads = if args.gradient {
        Some(wn.try_gradient_batch(&points)?)
    } else {
        None
    };
    write_outputs(&args, &values, grads.as_deref())
}

/// The options every curved-surface input (patch sets, STEP models) refuses or needs: no
/// gradient, a positive tolerance, no mesh-only options (`what` names the input in the errors).
fn check_curved_surface_options(args: &Args, what: &str) -> Result<(), CliError> {
    if args.gradient {
        return Err(CliError(format!("--gradient is not available for {what}")));
    }
    if !(args.tolerance.is_finite() && args.tolerance > 0.0) {
        return Err(CliError(format!(
            "--tolerance must be a positive number, not {}",
            args.tolerance
        )));
    }
    if args.method.beta.is_some() || args.method.order.is_some() || args.precision.is_some() {
        return Err(CliError(format!(
            "--beta, --order and --precision do not apply to {what}"
        )));
    }
    Ok(())
}

/// Bézier patch sets: the boundary method (`exact`) or the surface quadrature (`direct`).
fn run_patches(args: &Args) -> Result<(), CliError> {
    check_curved_surface_options(args, "patch sets")?;
    let set = gwn::patch::load_patches(&args.mesh)?;
    let points = gwn::io::points::load_points(&args.points)?;
    let values = match args.method.method.unwrap_or(Method::Exact) {
        Method::Exact => {
            let evaluations = gwn::patch::PatchWindingNumber::with_options(
                &set,
                gwn::patch::Options {
                    ray: args.ray.unwrap_or(Ray::PosZ).into(),
                    tolerance: args.tolerance,
                },
            )
            .evaluate_batch(&points);
            // The flag of docs/patches.md ("Error model"): queries on the surface (principal
            // value), at rounding level from it, or past the work cap.
            let uncertified = evaluations.iter().filter(|e| !e.certified).count();
            let worst = evaluations
                .iter()
                .filter(|e| !e.certified)
                .fold(0.0f64, |a, e| a.max(e.error_estimate));
            if uncertified > 0 {
                eprintln!(
                    "gwn eval: warning: {uncertified} of {} values uncertified (on or within \
                     rounding of the surface, or work cap reached; largest error estimate \
                     {worst:.1e}); see docs/patches.md",
                    points.len()
                );
            }
            evaluations.iter().map(|e| e.value).collect()
        }
        Method::Direct => {
            if args.ray.is_some() {
                return Err(CliError::msg("--ray applies to --method exact only"));
            }
            gwn::patch::surface_quadrature::winding_number_surface_quadrature_batch(
                &set,
                &points,
                args.tolerance,
            )
        }
        Method::Fast => {
            return Err(CliError::msg(
                "--method fast is not available for patch sets (use exact or direct)",
            ));
        }
    };
    write_outputs(args, &values, None)
}

/// Trimmed B-rep STEP models: the crossing count plus the surface-boundary integral.
fn run_step(args: &Args) -> Result<(), CliError> {
    check_curved_surface_options(args, "STEP models")?;
    if args.ray.is_some() {
        return Err(CliError::msg(
            "--ray does not apply to STEP models (the evaluator chooses a ray per query)",
        ));
    }
    if !matches!(args.method.method, None | Some(Method::Exact)) {
        return Err(CliError::msg(
            "only --method exact is available for STEP models",
        ));
    }
    let model = gwn::patch::step::load_step(&args.mesh)?;
    let points = gwn::io::points::load_points(&args.points)?;
    let wn = gwn::patch::step::StepWindingNumber::with_options(
        &model,
        gwn::patch::step::StepOptions {
            tolerance: args.tolerance,
        },
    );
    let evaluations: Vec<gwn::patch::step::StepEvaluation> = {
        use rayon::prelude::*;
        points.par_iter().map(|&q| wn.evaluate(q)).collect()
    };
    // The flag of docs/patches.md ("Trimmed B-rep models"): no ray direction passed the
    // certificates (query on or within the margins of the surface or an edge), or the work cap.
    let uncertified = evaluations.iter().filter(|e| e.uncertified).count();
    if uncertified > 0 {
        let worst = evaluations
            .iter()
            .filter(|e| e.uncertified)
            .fold(0.0f64, |a, e| a.max(e.error_estimate));
        eprintln!(
            "gwn eval: warning: {uncertified} of {} values uncertified (on or within the margins \
             of the surface or an edge, or work cap reached; largest error estimate {worst:.1e}); \
             see docs/patches.md",
            points.len()
        );
    }
    let values: Vec<f64> = evaluations.iter().map(|e| e.value).collect();
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
        let mut w = std::io::BufWriter::new(std::io::stdout().lock());
        for (i, v) in values.iter().enumerate() {
            match (grads, &args.gradient_out) {
                (Some(g), None) => writeln!(w, "{v:?},{:?},{:?},{:?}", g[i][0], g[i][1], g[i][2]),
                _ => writeln!(w, "{v:?}"),
            }
            .map_err(stdout_error)?;
        }
        // An explicit flush: dropping the BufWriter would discard the error of the last write.
        w.flush().map_err(stdout_error)?;
    }
    Ok(())
}
