//! The evaluation method options shared by every subcommand that evaluates `w` (`eval`, `slice`,
//! `voxelize`, `sdf`, `classify`, `filter-tets`), and the input they evaluate: a triangle mesh
//! or an oriented point cloud.

use std::path::Path;

use clap::{Args as ClapArgs, ValueEnum};
use gwn::eval::Evaluator;
use gwn::eval::antipodal::{Options, WindingNumber};
use gwn::eval::direct::DirectWindingNumber;
use gwn::eval::fast::{FastParams, FastWindingNumber, PointCloud, PointCloudWindingNumber};
use gwn::{BoundingBox, Mesh};

use crate::common::{CliError, WeldArgs, load_mesh_for_cli};

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

impl Method {
    fn flag(self) -> &'static str {
        match self {
            Method::Exact => "--method exact",
            Method::Direct => "--method direct",
            Method::Fast => "--method fast",
        }
    }
}

/// `--method`, `--beta`, `--order`.
#[derive(ClapArgs, Debug, Clone, Default)]
pub struct MethodArgs {
    /// Evaluation method [default: exact for meshes, fast for point clouds].
    #[arg(long, value_enum)]
    pub method: Option<Method>,
    /// Accuracy of the fast method: a tree node is approximated when its distance exceeds
    /// beta times its radius (Barill et al. 2018); larger is more accurate. Positive, finite
    /// [default: 2].
    #[arg(long, allow_negative_numbers = true)]
    pub beta: Option<f64>,
    /// Expansion order of the fast method (0, 1 or 2) [default: 2].
    #[arg(long, value_parser = clap::value_parser!(u8).range(0..=2))]
    pub order: Option<u8>,
}

/// What a subcommand evaluates.
#[derive(Debug)]
pub enum Input {
    /// A triangle mesh (or soup).
    Mesh(Mesh),
    /// An oriented point cloud.
    Cloud(PointCloud),
    /// A set of (rational) Bézier patches (`.bpt`, `.rbpt`).
    Patches(gwn::patch::PatchSet),
    /// A trimmed B-rep model (`.step`, `.stp`).
    Step(Box<gwn::patch::step::StepModel>),
}

impl Input {
    /// Loads `path` as a point cloud when it is one ([`is_point_cloud`]), as a mesh otherwise.
    pub fn load(path: &Path, weld: WeldArgs) -> Result<Input, CliError> {
        if gwn::patch::is_patch_path(path) {
            return Ok(Input::Patches(gwn::patch::load_patches(path)?));
        }
        if gwn::patch::step::is_step_path(path) {
            return Ok(Input::Step(Box::new(gwn::patch::step::load_step(path)?)));
        }
        if is_point_cloud(path) {
            let (cloud, warnings) = gwn::io::cloud::load_point_cloud_with_warnings(path)?;
            crate::common::print_load_warnings(path, &warnings);
            Ok(Input::Cloud(cloud))
        } else {
            Ok(Input::Mesh(load_mesh_for_cli(path, weld)?))
        }
    }

    /// The bounding box of the triangles or points, `None` when there are none.
    pub fn bounding_box(&self) -> Option<BoundingBox> {
        match self {
            Input::Mesh(m) => m.bounding_box(),
            Input::Cloud(c) => BoundingBox::of_points(c.positions()),
            Input::Patches(p) => {
                let (min, max) = p.bounding_box();
                Some(BoundingBox { min, max })
            }
            Input::Step(m) => {
                let (min, max) = m.bounding_box();
                Some(BoundingBox { min, max })
            }
        }
    }

    /// The mesh, or a one-line error naming `path` and what needed a mesh.
    pub fn mesh(&self, path: &Path, what: &str) -> Result<&Mesh, CliError> {
        match self {
            Input::Mesh(m) => Ok(m),
            Input::Cloud(_) => Err(CliError::msg(format!(
                "{}: is a point cloud, but {what} needs a triangle mesh",
                path.display()
            ))),
            Input::Patches(_) => Err(CliError::msg(format!(
                "{}: is a patch set, but {what} needs a triangle mesh",
                path.display()
            ))),
            Input::Step(_) => Err(CliError::msg(format!(
                "{}: is a STEP B-rep model, but {what} needs a triangle mesh",
                path.display()
            ))),
        }
    }
}

/// Text point formats are clouds; a PLY is a cloud when it has no faces.
pub fn is_point_cloud(path: &Path) -> bool {
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

impl MethodArgs {
    /// The method for `input`: the one asked for, else exact for meshes and fast for clouds.
    pub fn method(&self, input: &Input) -> Method {
        self.method.unwrap_or(match input {
            Input::Mesh(_) | Input::Patches(_) | Input::Step(_) => Method::Exact,
            Input::Cloud(_) => Method::Fast,
        })
    }

    /// Builds the evaluator for `input` (read from `path`, for messages); `exact` are the exact
    /// method's options. A method or option that does not apply is an error, never ignored.
    pub fn build<'a>(
        &self,
        input: &'a Input,
        path: &Path,
        exact: Options,
    ) -> Result<Box<dyn Evaluator + 'a>, CliError> {
        if let Some(beta) = self.beta {
            crate::common::check_beta(beta)?;
        }
        let method = self.method(input);
        if method != Method::Fast {
            for (given, flag) in [
                (self.beta.is_some(), "--beta"),
                (self.order.is_some(), "--order"),
            ] {
                if given {
                    return Err(CliError::msg(format!(
                        "{flag} applies to --method fast, not {}",
                        method.flag()
                    )));
                }
            }
        }
        let params = FastParams::barill(self.beta.unwrap_or(2.0), self.order.unwrap_or(2));
        Ok(match (input, method) {
            (Input::Mesh(mesh), Method::Exact) => Box::new(
                WindingNumber::with_options(mesh, exact)
                    .map_err(|e| CliError(format!("{}: {e}", path.display())))?,
            ),
            (Input::Mesh(mesh), Method::Direct) => Box::new(DirectWindingNumber::new(mesh)),
            (Input::Mesh(mesh), Method::Fast) => {
                Box::new(FastWindingNumber::with_params(mesh, params))
            }
            (Input::Cloud(cloud), Method::Fast) => {
                Box::new(PointCloudWindingNumber::with_params(cloud, params))
            }
            (Input::Patches(set), Method::Exact) => {
                Box::new(gwn::patch::PatchWindingNumber::with_options(
                    set,
                    gwn::patch::Options {
                        ray: exact.ray,
                        ..Default::default()
                    },
                ))
            }
            // The trimmed-model evaluator picks its own ray per query (a product's ray choice,
            // e.g. a slice's in-plane ray, only serves ray reuse, which it does not do).
            (Input::Step(model), Method::Exact) => {
                Box::new(gwn::patch::step::StepWindingNumber::new(model))
            }
            (Input::Step(_), m) => {
                return Err(CliError::msg(format!(
                    "{}: {} does not apply to a STEP model (use --method exact)",
                    path.display(),
                    m.flag()
                )));
            }
            (Input::Patches(_), m) => {
                return Err(CliError::msg(format!(
                    "{}: {} does not apply to a patch set here (use --method exact; `gwn eval` \
                     also has --method direct)",
                    path.display(),
                    m.flag()
                )));
            }
            (Input::Cloud(_), m) => {
                return Err(CliError::msg(format!(
                    "{}: {} does not apply to a point cloud (use --method fast)",
                    path.display(),
                    m.flag()
                )));
            }
        })
    }
}
