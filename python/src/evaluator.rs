//! The evaluators behind `gwn.WindingNumber`, behind one small enum so that moving to the
//! library's `Evaluator` trait (issue 13) changes this file only.

use std::sync::Arc;

use gwn::Mesh;
use gwn::eval::antipodal::{DEFAULT_TOLERANCE, WindingNumber};
use gwn::eval::direct::{winding_number_direct_batch, winding_number_gradient_direct};
use gwn::eval::fast::{Admissibility, FastWindingNumber, PointCloudWindingNumber};
use gwn::eval::parity::CrossingParity;
use gwn::input::InputKind;
use gwn::patch::step::{StepModel, StepWindingNumber};
use gwn::patch::surface_quadrature::SurfaceQuadrature;
use gwn::patch::{PatchSet, PatchWindingNumber};
use gwn::spec::{EvaluatorSpec, Method, SpecError};
use gwn::{Precision, RayAxis};
use rayon::prelude::*;

/// The Python default of `tolerance=`, written as a literal in the docstrings; this pins it to
/// the library's default.
pub const PY_DEFAULT_TOLERANCE: f64 = 1e-10;
const _: () = assert!(PY_DEFAULT_TOLERANCE == DEFAULT_TOLERANCE);

/// The library's spec of Python's keyword arguments (`None`: not given, the library's default).
/// Values are checked by the library ([`EvaluatorSpec::validate`]), so Python and the CLI
/// refuse the same options with the same message.
#[derive(Clone, Copy)]
pub struct SpecArgs<'a> {
    /// `method=`.
    pub method: Option<&'a str>,
    /// `beta=`.
    pub beta: Option<f64>,
    /// `order=`.
    pub order: Option<u8>,
    /// `rule=` (the fast method's admissibility rule).
    pub rule: Option<&'a str>,
    /// `precision=` (bits).
    pub precision: Option<u32>,
    /// `ray=`.
    pub ray: Option<&'a str>,
    /// `tolerance=`.
    pub tolerance: Option<f64>,
}

impl SpecArgs<'_> {
    /// The spec, parsed and validated (before any work, so errors come first).
    pub fn spec(&self) -> Result<EvaluatorSpec, SpecError> {
        let spec = EvaluatorSpec {
            method: self.method.map(str::parse::<Method>).transpose()?,
            beta: self.beta,
            order: self.order,
            rule: self.rule.map(str::parse::<Admissibility>).transpose()?,
            precision: self.precision.map(Precision::try_from).transpose()?,
            ray: self.ray.map(str::parse::<RayAxis>).transpose()?,
            tolerance: self.tolerance,
            ..Default::default()
        };
        spec.validate()?;
        Ok(spec)
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
    /// The crossing parity of a closed mesh (boxed like the exact evaluator it holds).
    Parity(Box<CrossingParity>),
    /// A trimmed B-rep (STEP) model: crossings of the trimmed faces plus the surface-boundary
    /// integral (boxed: the model is large).
    Step(Box<StepWindingNumber>),
    /// Bézier patches, exact method: ray crossings plus the boundary integral.
    Patches(Box<PatchWindingNumber>),
    /// Bézier patches, direct method: the surface quadrature (it borrows the set, so it is
    /// made per batch, which costs nothing).
    PatchesDirect {
        /// The patches.
        set: Arc<PatchSet>,
        /// The quadrature's tolerance.
        tolerance: f64,
    },
}

/// One value of a curved input with its certificate (the flags of docs/patches.md).
#[derive(Clone, Copy, Debug, Default)]
pub struct Certified {
    /// The winding number.
    pub value: f64,
    /// The estimate of its error (the boundary integrals').
    pub error_estimate: f64,
    /// The value could not be certified (query on or within the margins of the surface, or
    /// the work cap reached).
    pub uncertified: bool,
}

impl Evaluator {
    /// Builds the evaluator `spec` describes for a mesh (checked by the library for meshes).
    pub fn for_mesh(mesh: &Arc<Mesh>, spec: &EvaluatorSpec) -> Result<Self, SpecError> {
        Ok(match spec.check(InputKind::Mesh)? {
            Method::Exact => Evaluator::Exact(Box::new(WindingNumber::with_options(
                mesh,
                spec.exact_options(),
            )?)),
            Method::Direct => Evaluator::Direct(mesh.clone()),
            Method::Fast => {
                Evaluator::FastSoup(FastWindingNumber::with_params(mesh, spec.fast_params()))
            }
            Method::Parity => Evaluator::Parity(Box::new(CrossingParity::with_options(
                mesh,
                spec.exact_options(),
            )?)),
        })
    }

    /// Builds the STEP evaluator `spec` describes (checked by the library for STEP models: only
    /// the exact method, no `ray=`, `precision=` or fast options).
    pub fn for_step(model: &StepModel, spec: &EvaluatorSpec) -> Result<Self, SpecError> {
        Ok(Evaluator::Step(Box::new(step_evaluator(model, spec)?)))
    }

    /// Builds the patch-set evaluator `spec` describes (checked by the library for patch sets:
    /// the exact or the direct method, no `precision=` or fast options).
    pub fn for_patches(set: &Arc<PatchSet>, spec: &EvaluatorSpec) -> Result<Self, SpecError> {
        Ok(match spec.check(InputKind::Patches)? {
            Method::Exact => Evaluator::Patches(Box::new(
                PatchWindingNumber::with_options(set, spec.patch_options())
                    .map_err(|e| SpecError::refused_tolerance(e, InputKind::Patches))?,
            )),
            _ => Evaluator::PatchesDirect {
                set: set.clone(),
                tolerance: spec.tolerance.unwrap_or(DEFAULT_TOLERANCE),
            },
        })
    }

    /// What `Unsupported` calls this evaluator.
    fn description(&self) -> &'static str {
        match self {
            Evaluator::Exact(_) => "exact",
            Evaluator::Direct(_) => "direct",
            Evaluator::FastSoup(_) => "fast",
            Evaluator::FastCloud(_) => "fast point-cloud",
            Evaluator::Parity(_) => "parity",
            Evaluator::Step(_) => "trimmed B-rep (STEP)",
            Evaluator::Patches(_) => "exact (patches)",
            Evaluator::PatchesDirect { .. } => "direct (patches)",
        }
    }

    /// Winding numbers at `points` (parallel on the current rayon pool).
    pub fn eval_batch(&self, points: &[[f64; 3]]) -> Vec<f64> {
        match self {
            Evaluator::Exact(wn) => wn.eval_batch(points),
            Evaluator::Direct(mesh) => winding_number_direct_batch(mesh, points),
            Evaluator::FastSoup(f) => f.eval_batch(points),
            Evaluator::FastCloud(f) => f.eval_batch(points),
            Evaluator::Parity(p) => p.eval_batch(points),
            Evaluator::Step(s) => s.eval_batch(points),
            Evaluator::Patches(p) => p.eval_batch(points),
            Evaluator::PatchesDirect { set, tolerance } => {
                gwn::eval::Evaluator::eval_batch(&SurfaceQuadrature::new(set, *tolerance), points)
            }
        }
    }

    /// Whether [`Evaluator::certified_batch`] answers (STEP models and the exact method on
    /// patches).
    pub fn certifies(&self) -> bool {
        matches!(self, Evaluator::Step(_) | Evaluator::Patches(_))
    }

    /// Evaluations with their certificates (STEP models and the exact method on patches), in
    /// parallel on the current rayon pool.
    pub fn certified_batch(&self, points: &[[f64; 3]]) -> Option<Vec<Certified>> {
        match self {
            Evaluator::Step(s) => Some(
                points
                    .par_iter()
                    .map(|&q| {
                        let e = s.evaluate(q);
                        Certified {
                            value: e.value,
                            error_estimate: e.error_estimate,
                            uncertified: e.uncertified,
                        }
                    })
                    .collect(),
            ),
            Evaluator::Patches(p) => Some(
                p.evaluate_batch(points)
                    .iter()
                    .map(|e| Certified {
                        value: e.value,
                        error_estimate: e.error_estimate,
                        uncertified: !e.certified,
                    })
                    .collect(),
            ),
            _ => None,
        }
    }

    /// The warning's words for what an uncertified value of this evaluator is near (the CLI's).
    pub fn uncertified_near(&self) -> &'static str {
        match self {
            Evaluator::Step(_) => "on or within the margins of the surface or an edge",
            _ => "on or within rounding of the surface",
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
                .map(|&q| wn.integer_and_fraction(q))
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
    /// boundary; patch sets: patch edges no other patch shares).
    pub fn boundary_edge_count(&self) -> Option<usize> {
        match self {
            Evaluator::Step(s) => Some(s.model().info().boundary_edges),
            Evaluator::Patches(p) => Some(p.edge_counts().0),
            _ => self.exact().map(WindingNumber::boundary_edge_count),
        }
    }
}

/// A curved input of `WindingNumber` and `remesh`: a STEP model or a patch set (Python objects
/// that come without `F`).
pub enum Curved {
    /// `gwn.StepModel`.
    Step(Arc<StepModel>),
    /// `gwn.PatchSet`.
    Patches(Arc<PatchSet>),
}

impl Curved {
    /// The input kind, for the library's rules and messages.
    pub fn kind(&self) -> InputKind {
        match self {
            Curved::Step(_) => InputKind::Step,
            Curved::Patches(_) => InputKind::Patches,
        }
    }

    /// A box containing the input.
    pub fn bounding_box(&self) -> gwn::BoundingBox {
        let (min, max) = match self {
            Curved::Step(model) => model.bounding_box(),
            Curved::Patches(set) => set.bounding_box(),
        };
        gwn::BoundingBox { min, max }
    }

    /// Runs `f` with the library evaluator `spec` describes for this input (what the remesher
    /// takes).
    pub fn with_evaluator<R>(
        &self,
        spec: &EvaluatorSpec,
        f: impl FnOnce(&dyn gwn::eval::Evaluator) -> R,
    ) -> Result<R, SpecError> {
        match self {
            Curved::Step(model) => Ok(f(&step_evaluator(model, spec)?)),
            Curved::Patches(set) => Ok(match Evaluator::for_patches(set, spec)? {
                Evaluator::Patches(wn) => f(wn.as_ref()),
                Evaluator::PatchesDirect { set, tolerance } => {
                    f(&SurfaceQuadrature::new(&set, tolerance))
                }
                _ => unreachable!("for_patches builds one of the two"),
            }),
        }
    }

    /// The tessellation the remesh report measures the Hausdorff distance to, at `cell_size`.
    pub fn surface_for_distance(
        &self,
        cell_size: f64,
    ) -> Option<gwn::products::remesh::report::CurvedSurface> {
        use gwn::products::remesh::report::{
            patch_surface_for_distance, step_surface_for_distance,
        };
        match self {
            Curved::Step(model) => step_surface_for_distance(model, cell_size),
            Curved::Patches(set) => patch_surface_for_distance(set, cell_size),
        }
    }
}

/// The STEP evaluator `spec` describes (checked by the library for STEP models: only the exact
/// method, no `ray=`, `precision=` or fast options): `WindingNumber(model)` and `remesh(model)`.
pub fn step_evaluator(
    model: &StepModel,
    spec: &EvaluatorSpec,
) -> Result<StepWindingNumber, SpecError> {
    spec.check(InputKind::Step)?;
    StepWindingNumber::with_options(model, spec.step_options())
        .map_err(|e| SpecError::refused_tolerance(e, InputKind::Step))
}
