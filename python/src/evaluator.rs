//! The evaluators behind `gwn.WindingNumber`, behind one small enum so that moving to the
//! library's `Evaluator` trait (issue 13) changes this file only.

use std::sync::Arc;

use gwn::Mesh;
use gwn::eval::antipodal::{DEFAULT_TOLERANCE, Options, WindingNumber};
use gwn::eval::direct::{winding_number_direct_batch, winding_number_gradient_direct};
use gwn::eval::fast::{FastParams, FastWindingNumber, PointCloudWindingNumber};
use gwn::kernel::frame::RayAxis;
use gwn::kernel::quantize::Precision;
use gwn::patch::step::{StepEvaluation, StepWindingNumber};
use rayon::prelude::*;

/// `1/4π` exactly as `WindingNumber::eval` multiplies the boundary sum with, so that
/// `chi + fraction` is bit-identical to the value.
use gwn::kernel::spherical::INV_4PI;

/// The evaluation method a user asked for.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Method {
    /// The exact Antipodal method.
    Exact,
    /// The compensated solid-angle sum over all triangles.
    Direct,
    /// Barnes–Hut (Barill et al. 2018).
    Fast,
}

impl Method {
    /// Parses `"exact"`, `"direct"` or `"fast"`.
    pub fn parse(s: &str) -> Result<Self, String> {
        match s {
            "exact" => Ok(Method::Exact),
            "direct" => Ok(Method::Direct),
            "fast" => Ok(Method::Fast),
            _ => Err(format!(
                "method must be \"exact\", \"direct\" or \"fast\", got {s:?}"
            )),
        }
    }

    /// The name `parse` accepts.
    pub fn name(self) -> &'static str {
        match self {
            Method::Exact => "exact",
            Method::Direct => "direct",
            Method::Fast => "fast",
        }
    }
}

/// Parses a ray direction `"+z"`, `"-x"`, ... (the CLI's `--ray` values).
pub fn parse_ray(s: &str) -> Result<RayAxis, String> {
    Ok(match s {
        "+z" | "z" => RayAxis::PosZ,
        "-z" => RayAxis::NegZ,
        "+x" | "x" => RayAxis::PosX,
        "-x" => RayAxis::NegX,
        "+y" | "y" => RayAxis::PosY,
        "-y" => RayAxis::NegY,
        _ => return Err(format!("ray must be one of +x -x +y -y +z -z, got {s:?}")),
    })
}

/// Parses the grid precision in bits (30 or 60).
pub fn parse_precision(bits: u32) -> Result<Precision, String> {
    match bits {
        30 => Ok(Precision::Bits30),
        60 => Ok(Precision::Bits60),
        _ => Err(format!("precision must be 30 or 60, got {bits}")),
    }
}

/// Barill's parameters, validated: the library accepts any `β` (NaN means "exact"), but a
/// Python user passing NaN or a negative `β` has made a mistake.
pub fn fast_params(beta: f64, order: u8) -> Result<FastParams, String> {
    if !(beta.is_finite() && beta > 0.0) {
        return Err(format!("beta must be a positive finite number, got {beta}"));
    }
    if order > 2 {
        return Err(format!("order must be 0, 1 or 2, got {order}"));
    }
    Ok(FastParams::barill(beta, order))
}

/// The Python default of `tolerance=`, written as a literal in the `#[pyo3(signature)]`s so that
/// `help()` shows it; this pins it to the library's default.
pub const PY_DEFAULT_TOLERANCE: f64 = 1e-10;
const _: () = assert!(PY_DEFAULT_TOLERANCE == DEFAULT_TOLERANCE);

/// The exact method's boundary tolerance, validated: a finite number `>= 0` (the CLI's rule).
pub fn check_tolerance(tolerance: f64) -> Result<f64, String> {
    if tolerance.is_finite() && tolerance >= 0.0 {
        Ok(tolerance)
    } else {
        Err(format!(
            "tolerance must be a finite number >= 0, got {tolerance}"
        ))
    }
}

/// Why an evaluator cannot answer a query kind.
#[derive(Clone, Copy, Debug)]
pub struct Unsupported {
    /// What was asked (`"gradient"`, `"parts"`, `"eval_with_bound"`).
    pub what: &'static str,
    /// The evaluator's description.
    pub method: &'static str,
}

impl std::fmt::Display for Unsupported {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(
            f,
            "{} is not available with the {} method",
            self.what, self.method
        )
    }
}

/// One built evaluator.
#[derive(Debug)]
pub enum Evaluator {
    /// Exact Antipodal method (boxed: it is several times larger than the other variants).
    Exact(Box<WindingNumber>),
    /// Direct sum over the triangles of the mesh.
    Direct(Arc<Mesh>),
    /// Barnes–Hut over a triangle soup.
    FastSoup(FastWindingNumber),
    /// Barnes–Hut over an oriented point cloud.
    FastCloud(PointCloudWindingNumber),
    /// A trimmed B-rep (STEP) model: crossings of the trimmed faces plus the surface-boundary
    /// integral (boxed: the model is large).
    Step(Box<StepWindingNumber>),
}

impl Evaluator {
    /// Builds the evaluator of `method` for a mesh.
    pub fn for_mesh(
        mesh: &Arc<Mesh>,
        method: Method,
        options: Options,
        params: FastParams,
    ) -> Result<Self, String> {
        Ok(match method {
            Method::Exact => Evaluator::Exact(Box::new(
                WindingNumber::with_options(mesh, options).map_err(|e| e.to_string())?,
            )),
            Method::Direct => Evaluator::Direct(mesh.clone()),
            Method::Fast => Evaluator::FastSoup(FastWindingNumber::with_params(mesh, params)),
        })
    }

    /// What `Unsupported` calls this evaluator.
    fn description(&self) -> &'static str {
        match self {
            Evaluator::Exact(_) => "exact",
            Evaluator::Direct(_) => "direct",
            Evaluator::FastSoup(_) => "fast",
            Evaluator::FastCloud(_) => "fast point-cloud",
            Evaluator::Step(_) => "trimmed B-rep (STEP)",
        }
    }

    /// Winding numbers at `points` (parallel on the current rayon pool).
    pub fn eval_batch(&self, points: &[[f64; 3]]) -> Vec<f64> {
        match self {
            Evaluator::Exact(wn) => wn.eval_batch(points),
            Evaluator::Direct(mesh) => winding_number_direct_batch(mesh, points),
            Evaluator::FastSoup(f) => f.eval_batch(points),
            Evaluator::FastCloud(f) => f.eval_batch(points),
            Evaluator::Step(s) => s.eval_batch(points),
        }
    }

    /// Evaluations with diagnostics (STEP models only), in parallel on the current rayon pool.
    pub fn step_batch(&self, points: &[[f64; 3]]) -> Option<Vec<StepEvaluation>> {
        match self {
            Evaluator::Step(s) => Some(points.par_iter().map(|&q| s.evaluate(q)).collect()),
            _ => None,
        }
    }

    /// Gradients `∇w` at `points` (exact and direct methods).
    pub fn gradient_batch(&self, points: &[[f64; 3]]) -> Result<Vec<[f64; 3]>, Unsupported> {
        match self {
            Evaluator::Exact(wn) => Ok(wn.gradient_batch(points)),
            Evaluator::Direct(mesh) => Ok(points
                .par_iter()
                .map(|&q| winding_number_gradient_direct(mesh, q))
                .collect()),
            _ => Err(Unsupported {
                what: "gradient",
                method: self.description(),
            }),
        }
    }

    /// The integer crossing count χ and the fractional boundary part `w − χ` (exact method).
    pub fn parts_batch(&self, points: &[[f64; 3]]) -> Result<(Vec<i64>, Vec<f64>), Unsupported> {
        match self {
            Evaluator::Exact(wn) => Ok(points
                .par_iter()
                .map(|&q| {
                    let (chi, boundary_sum) = wn.parts(q);
                    (chi, boundary_sum * INV_4PI)
                })
                .unzip()),
            _ => Err(Unsupported {
                what: "parts",
                method: self.description(),
            }),
        }
    }

    /// Winding numbers and their certified bounds on `|w − w_flat|` (exact method;
    /// [`WindingNumber::eval_with_bound`]), parallel on the current rayon pool.
    pub fn bound_batch(&self, points: &[[f64; 3]]) -> Result<(Vec<f64>, Vec<f64>), Unsupported> {
        match self {
            Evaluator::Exact(wn) => Ok(points.par_iter().map(|&q| wn.eval_with_bound(q)).unzip()),
            _ => Err(Unsupported {
                what: "eval_with_bound",
                method: self.description(),
            }),
        }
    }

    /// The exact evaluator, when this is one (grids with ray reuse need it).
    pub fn exact(&self) -> Option<&WindingNumber> {
        match self {
            Evaluator::Exact(wn) => Some(wn.as_ref()),
            _ => None,
        }
    }

    /// Number of boundary edges (exact method; STEP models: edge uses left as the surface
    /// boundary).
    pub fn boundary_edge_count(&self) -> Option<usize> {
        match self {
            Evaluator::Step(s) => Some(s.model().info().boundary_edges),
            _ => self.exact().map(WindingNumber::boundary_edge_count),
        }
    }
}
