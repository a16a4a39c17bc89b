//! `gwn eval`: winding numbers (and gradients) at query points.

use std::path::PathBuf;

use clap::Args as ClapArgs;
use gwn::input::Input;
use gwn::spec::{EvaluatorSpec, Method};
use gwn::{Precision, RayAxis};

use crate::common::{CliError, progress, stdout_error};
use crate::method::{MethodArgs, ToleranceArgs, parse_option};

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
    #[arg(long, value_parser = parse_option::<Precision>)]
    pub precision: Option<Precision>,
    /// Ray direction of the exact method: +x, -x, +y, -y, +z or -z (any gives the same value
    /// off the surface; on the surface the value is taken at the point perturbed along this
    /// ray's frame) [default: +z].
    #[arg(long, allow_hyphen_values = true, value_parser = parse_option::<RayAxis>)]
    pub ray: Option<RayAxis>,
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
    #[command(flatten)]
    pub tolerance: ToleranceArgs,
}

impl Args {
    /// The library's spec of the flags.
    fn spec(&self) -> EvaluatorSpec {
        EvaluatorSpec {
            precision: self.precision,
            ray: self.ray,
            ..self.method.spec(self.tolerance, self.weld)
        }
    }
}

/// Runs `gwn eval`.
pub fn run(args: Args) -> Result<(), CliError> {
    let spec = args.spec();
    spec.validate()?;
    if args.gradient_out.is_some() && !args.gradient {
        return Err(CliError::msg(
            "--gradient-out needs --gradient (no gradient is computed without it)",
        ));
    }
    let input = crate::method::load_input(&args.mesh, args.weld)?;
    let method = crate::method::check(&spec, input.kind(), &args.mesh)?;
    if let (Input::Patches(set), Method::Exact) = (&input, method) {
        // The patch evaluator's own loop, for its certification flags.
        refuse_gradient(&args, &input.kind().to_string())?;
        let points = gwn::io::points::load_points(&args.points)?;
        let values = eval_patches(set, &spec, &points)?;
        return write_outputs(&args, &values, None);
    }
    if let Input::Step(model) = &input {
        // The STEP evaluator's own loop, for its certification flags.
        refuse_gradient(&args, &input.kind().to_string())?;
        let points = gwn::io::points::load_points(&args.points)?;
        let values = eval_step(model, &spec, &points)?;
        return write_outputs(&args, &values, None);
    }
    let wn = crate::method::build(&spec, &input, &args.mesh)?;
    if args.gradient && wn.try_gradient([0.0; 3]).is_err() {
        // Whether an evaluator has a gradient does not depend on the query: refuse up front.
        refuse_gradient(&args, &input.kind().to_string())?;
    }
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

/// `--gradient` for an input whose evaluator has none.
fn refuse_gradient(args: &Args, what: &str) -> Result<(), CliError> {
    if args.gradient {
        return Err(CliError(format!("--gradient is not available for {what}")));
    }
    Ok(())
}

/// Bézier patch sets, exact method: values, and a warning for the uncertified ones.
fn eval_patches(
    set: &gwn::patch::PatchSet,
    spec: &EvaluatorSpec,
    points: &[[f64; 3]],
) -> Result<Vec<f64>, CliError> {
    let evaluations = gwn::patch::PatchWindingNumber::with_options(set, spec.patch_options())
        .map_err(|e| CliError(e.to_string()))?
        .evaluate_batch(points);
    // The flag of docs/patches.md ("Error model"): queries on the surface (principal value), at
    // rounding level from it, or past the work cap.
    let uncertified = evaluations.iter().filter(|e| !e.certified).count();
    let worst = evaluations
        .iter()
        .filter(|e| !e.certified)
        .fold(0.0f64, |a, e| a.max(e.error_estimate));
    if uncertified > 0 {
        eprintln!(
            "gwn eval: warning: {uncertified} of {} values uncertified (on or within rounding of \
             the surface, or work cap reached; largest error estimate {worst:.1e}); see \
             docs/patches.md",
            points.len()
        );
    }
    Ok(evaluations.iter().map(|e| e.value).collect())
}

/// STEP models: values, and a warning for the uncertified ones.
fn eval_step(
    model: &gwn::patch::step::StepModel,
    spec: &EvaluatorSpec,
    points: &[[f64; 3]],
) -> Result<Vec<f64>, CliError> {
    use rayon::prelude::*;
    let wn = gwn::patch::step::StepWindingNumber::with_options(model, spec.step_options())
        .map_err(|e| CliError(e.to_string()))?;
    let evaluations: Vec<gwn::patch::step::StepEvaluation> =
        points.par_iter().map(|&q| wn.evaluate(q)).collect();
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
    Ok(evaluations.iter().map(|e| e.value).collect())
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
