//! The evaluation options shared by every subcommand that evaluates `w` (`eval`, `slice`,
//! `voxelize`, `sdf`, `classify`, `filter-tets`), translated into the library's
//! [`EvaluatorSpec`]: the rules (what applies to which method and input, which values are valid)
//! and their messages are the library's, shared with the Python package.

use std::path::Path;

use clap::Args as ClapArgs;
use gwn::eval::Evaluator;
use gwn::eval::fast::Admissibility;
use gwn::input::{Input, InputKind};
use gwn::mesh::Mesh;
use gwn::spec::{EvaluatorSpec, Method, SpecError};

use crate::common::{CliError, WeldArgs};

/// Parses an option with the library's `FromStr`, so that a bad value reads as it does in
/// Python (`ray must be one of +x -x +y -y +z -z, got "+w"`).
pub fn parse_option<T>(s: &str) -> Result<T, String>
where
    T: std::str::FromStr<Err = gwn::spec::ParseError>,
{
    s.parse::<T>().map_err(|e| e.to_string())
}

/// `--method`, `--beta`, `--order`.
#[derive(ClapArgs, Debug, Clone, Default)]
pub struct MethodArgs {
    /// Evaluation method: exact (Antipodal method, integer predicates; O(boundary + log faces)
    /// per query), direct (solid-angle sum over all faces, O(faces); the reference), fast
    /// (Barnes-Hut; the method for point clouds) or parity (closed meshes of any orientation:
    /// 1 where a ray crosses the surface an odd number of times, else 0; exact, O(log faces))
    /// [default: exact for meshes, fast for point clouds].
    #[arg(long, value_parser = parse_option::<Method>)]
    pub method: Option<Method>,
    /// Accuracy of the fast method: a tree node is approximated when its distance exceeds
    /// beta times its radius (Barill et al. 2018); larger is more accurate. Positive, finite
    /// [default: 2].
    #[arg(long, allow_negative_numbers = true)]
    pub beta: Option<f64>,
    /// Expansion order of the fast method (0, 1 or 2) [default: 2].
    #[arg(long)]
    pub order: Option<u8>,
    /// Which node size beta multiplies in the fast method: radius (Barill et al.), box-corner
    /// (libigl), box-diagonal (FOSSIL) or radius-or-box-corner (admit by whichever of radius
    /// at beta and box-corner at 6/7 beta admits first; at beta 2.8 as accurate as libigl's
    /// default on the shared corpus, and faster: docs/fast.md) [default: radius].
    #[arg(long, value_parser = parse_option::<Admissibility>)]
    pub rule: Option<Admissibility>,
}

/// `--tolerance`, shared by every subcommand that evaluates `w`.
#[derive(ClapArgs, Debug, Clone, Copy, Default)]
pub struct ToleranceArgs {
    /// Target absolute error of w. Meshes, exact method: far boundary clusters are replaced by
    /// a multipole expansion with a certified bound (docs/boundary.md; 0 = the flat exact loop,
    /// the integer part is always exact). Patch sets and STEP models: the boundary quadrature
    /// (exact method) or the surface quadrature (direct method; patch sets) [default: 1e-10].
    #[arg(long, allow_negative_numbers = true)]
    pub tolerance: Option<f64>,
}

impl MethodArgs {
    /// The library's spec of these flags, `tolerance` and `weld` (exact options unset).
    pub fn spec(&self, tolerance: ToleranceArgs, weld: WeldArgs) -> EvaluatorSpec {
        EvaluatorSpec {
            method: self.method,
            beta: self.beta,
            order: self.order,
            rule: self.rule,
            tolerance: tolerance.tolerance,
            boundary: weld.boundary(),
            ..Default::default()
        }
    }
}

/// Loads whatever `path` holds ([`gwn::input::load_input_with`]), welded as `weld` says; prints
/// the loader's warnings.
pub fn load_input(path: &Path, weld: WeldArgs) -> Result<Input, CliError> {
    let loaded = gwn::input::load_input_with(path, &weld.load_options())?;
    crate::common::print_load_warnings(path, &loaded.warnings);
    Ok(loaded.input)
}

/// The mesh of `input`, or a one-line error naming `path` and what needed a mesh.
pub fn need_mesh<'a>(input: &'a Input, path: &Path, what: &str) -> Result<&'a Mesh, CliError> {
    input.mesh().ok_or_else(|| {
        CliError::msg(format!(
            "{}: is {}, but {what} needs a triangle mesh",
            path.display(),
            input.kind()
        ))
    })
}

/// A spec error for `input` read from `path`: the library's message, after the file name when
/// the input is what it is about.
pub fn spec_error(e: SpecError, path: &Path) -> CliError {
    match e {
        SpecError::MethodForInput { .. }
        | SpecError::OptionForInput { .. }
        | SpecError::ZeroTolerance(_)
        | SpecError::Build(_) => CliError(format!("{}: {e}", path.display())),
        e => CliError(e.to_string()),
    }
}

/// Checks `spec` for `input` (read from `path`) and builds its evaluator.
pub fn build<'a>(
    spec: &EvaluatorSpec,
    input: &'a Input,
    path: &Path,
) -> Result<Box<dyn Evaluator + 'a>, CliError> {
    spec.build(input).map_err(|e| spec_error(e, path))
}

/// [`EvaluatorSpec::check`] for `input` read from `path`.
pub fn check(spec: &EvaluatorSpec, input: InputKind, path: &Path) -> Result<Method, CliError> {
    spec.check(input).map_err(|e| spec_error(e, path))
}
