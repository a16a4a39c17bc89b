//! Remeshing a dataset: [`RemeshJob`], the [`MeshJob`] that writes one closed, manifold,
//! oriented surface per input and a manifest row with its report's main numbers — the job ML
//! pipelines run over ShapeNet or Objaverse before computing occupancy or SDF labels, and over
//! CAD collections (ABC's STEP files) to get watertight meshes of them. Each input is set up as
//! `gwn remesh` sets it up: a mesh or soup remeshes its exact `w` with its triangles as the guide
//! ([`super::thicken::of_mesh`]); a STEP model or a patch set its own evaluator, vertices placed
//! at its surface hits, the distance measured to a fine tessellation
//! ([`super::report::curved_surface_for_distance`]); an oriented point cloud the fast
//! evaluator, with no distance.
//!
//! Inputs run one after the other, each on every thread (a remesh is parallel inside and takes
//! the memory it finds: two side by side could each count on all of it). Everything else —
//! outputs mirroring the inputs' layout, atomic writes, resuming, broken files as rows — is
//! [`crate::products::dataset`]'s.
//!
//! ```
//! use gwn::products::dataset::{run_dataset, Status};
//! use gwn::products::remesh::dataset::RemeshJob;
//! let dir = std::env::temp_dir().join(format!("gwn-remesh-dataset-doc-{}", std::process::id()));
//! std::fs::create_dir_all(&dir)?;
//! let tet = dir.join("tet.obj");
//! std::fs::write(&tet, "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\nf 1 3 2\nf 1 2 4\nf 2 3 4\nf 3 1 4\n")?;
//! let job = RemeshJob { samples: 1000, ..RemeshJob::new(32) };
//! let rows = run_dataset(&job, &[tet], &dir.join("out"), None, |_| {})?;
//! assert_eq!(rows[0].status, Status::Ok);
//! assert_eq!(rows[0].stats.get("valid"), Some("true"));
//! assert!(dir.join("out/tet.obj.ply").is_file());
//! # std::fs::remove_dir_all(&dir)?;
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```

use std::path::Path;
use std::time::{Duration, Instant};

use super::crossings::SegmentBvh;
use super::keep_input::{InputCheck, WhyEmpty};
use super::report::{DistanceReference, RemeshReport};
use super::thicken::{self, MeshField, ThickenedSheets};
use super::write::{SurfaceFormat, write_surface};
use super::{Keep, RemeshOptions, Remeshed, remesh_guided, remesh_mesh};
use crate::eval::Evaluator;
use crate::eval::antipodal::BoundaryBy;
use crate::eval::parity::{CrossingParity, EdgeCensus};
use crate::input::{Input, InputKind, load_input_with};
use crate::io::LoadOptions;
use crate::mesh::Mesh;
use crate::products::dataset::{MeshJob, Stats};
use crate::products::json::{json_number, json_string};
use crate::spec::EvaluatorSpec;

/// Options of the remeshing job.
#[derive(Clone, Debug)]
pub struct RemeshJob {
    /// The remesher's options (resolution, simplification, levels).
    pub options: RemeshOptions,
    /// The outputs' format (and extension: `m.obj` → `m.obj.ply`).
    pub format: SurfaceFormat,
    /// Report samples per mesh ([`RemeshReport::measure`]: the occupancy agreement and the
    /// Hausdorff distance; 0 measures neither). At most [`super::report::MAX_SAMPLES`].
    pub samples: usize,
    /// Close open sheets into slabs of this half-thickness in finest cells (at least 1): in
    /// cells, not world units, since a dataset's meshes come at any scale. Meshes only: other
    /// inputs fail.
    pub thicken_cells: Option<f64>,
    /// Loader options (welding).
    pub load: LoadOptions,
    /// Per-input time limit (loading, remeshing, measuring; the remesher checks it between its
    /// phases and rounds and every 4096 evaluations, [`RemeshOptions::deadline`]). An input
    /// past it is a `timeout` row without an output.
    pub time_limit: Option<Duration>,
    /// Write a mesh that already is the boundary of its `w > ½` solid as it is
    /// ([`super::keep_input`]; the row's `kept`); `false` remeshes every input.
    pub keep_input: bool,
    /// Remesh a mesh that is closed but not consistently oriented (flipped faces, where `w` is
    /// fractional: [`crate::eval::parity::EdgeCensus::closed_but_not_oriented`]) by the parity
    /// method, the solid it encloses, as `gwn remesh --method parity` does (with
    /// [`RemeshJob::keep_input`], kept with its faces turned where
    /// [`super::reorient::keep_reoriented`] proves it); every other input as without it. The
    /// row's `method` says which. Off by default: `w > ½` is the remesh's definition.
    pub parity_where_flipped: bool,
}

impl RemeshJob {
    /// The defaults of `gwn remesh` at `resolution`, written as binary PLY, with 10,000 report
    /// samples.
    pub fn new(resolution: usize) -> RemeshJob {
        RemeshJob {
            options: RemeshOptions::with_resolution(resolution),
            format: SurfaceFormat::Ply,
            samples: 10_000,
            thicken_cells: None,
            load: LoadOptions::default(),
            time_limit: None,
            keep_input: true,
            parity_where_flipped: false,
        }
    }
}

/// Why one mesh could not be remeshed (one line; the manifest row names the mesh).
pub type RemeshJobError = Box<dyn std::error::Error + Send + Sync>;

/// A mesh ran out of [`RemeshJob::time_limit`].
#[derive(Debug)]
pub struct TimeLimitExceeded {
    /// What was running.
    pub stage: &'static str,
    /// The limit.
    pub limit: Duration,
}

impl std::fmt::Display for TimeLimitExceeded {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(
            f,
            "time limit of {:.3} s exceeded while {}",
            self.limit.as_secs_f64(),
            self.stage
        )
    }
}

impl std::error::Error for TimeLimitExceeded {}

impl MeshJob for RemeshJob {
    type Error = RemeshJobError;
    const RECORD: &'static str = "gwn_remesh";
    const STATS: &'static [(&'static str, &'static str)] = &[
        ("input", "null"),
        ("faces", "null"),
        ("vertices", "null"),
        ("method", "null"),
        ("kept", "null"),
        ("outcome", "null"),
        ("kept_faces", "null"),
        ("output_faces", "null"),
        ("empty", "null"),
        ("output_vertices", "null"),
        ("valid", "null"),
        ("components", "null"),
        ("self_intersections", "null"),
        ("hausdorff_cells", "null"),
        ("occupancy_agreement", "null"),
    ];
    const INPUT_STATS: &'static [&'static str] = &["input", "faces", "vertices"];
    const MESHES_IN_PARALLEL: bool = false;

    fn extension(&self) -> &'static str {
        match self.format {
            SurfaceFormat::Obj => "obj",
            SurfaceFormat::Ply => "ply",
            SurfaceFormat::Stl => "stl",
            SurfaceFormat::Glb => "glb",
        }
    }

    fn option_fields(&self) -> Vec<(&'static str, String)> {
        let o = &self.options;
        let or_null = |v: Option<String>| v.unwrap_or_else(|| "null".into());
        let mut fields = vec![
            ("res", o.resolution.to_string()),
            ("samples", self.samples.to_string()),
            (
                "thicken_cells",
                or_null(self.thicken_cells.map(json_number)),
            ),
            ("weld", or_null(self.load.weld.map(|w| w.to_string()))),
            ("keep_input", self.keep_input.to_string()),
            ("bisection_steps", o.bisection_steps.to_string()),
            (
                "max_classified_points",
                or_null(o.max_classified_points.map(|n| n.to_string())),
            ),
            ("refine_plates", o.refine_plates.to_string()),
            ("sub_cell_levels", o.sub_cell_levels.to_string()),
            ("planar_levels", o.planar_levels.to_string()),
            ("probe_flatness", o.probe_flatness.to_string()),
            ("evaluator_crossings", o.evaluator_crossings.to_string()),
            ("simplify", o.simplify.is_some().to_string()),
        ];
        // Only when on: outputs made before the option existed stay reusable.
        if self.parity_where_flipped {
            fields.push(("parity_where_flipped", "true".into()));
        }
        // Every simplification knob, so that a change to any of them redoes the output and
        // the manifest names it.
        if let Some(s) = &o.simplify {
            fields.extend([
                ("simplify_max_distance", json_number(s.max_distance)),
                ("simplify_max_face_extent", s.max_face_extent.to_string()),
                (
                    "simplify_max_flat_face_extent",
                    s.max_flat_face_extent.to_string(),
                ),
                (
                    "simplify_target",
                    json_number(s.target_fraction_of_marching_cubes),
                ),
                ("simplify_relocate", s.relocate.to_string()),
                ("simplify_input_planes", s.input_planes.to_string()),
                ("simplify_flat_tolerance", json_number(s.flat_tolerance)),
                (
                    "simplify_lattice_diagonals",
                    s.lattice_diagonals.to_string(),
                ),
                (
                    "simplify_lattice_diagonal_error",
                    json_number(s.lattice_diagonal_error),
                ),
                (
                    "simplify_lattice_cube_cells",
                    s.lattice_cube_cells.to_string(),
                ),
                ("simplify_slab_cells", s.slab_cells.to_string()),
            ]);
        }
        fields
    }

    fn validate(&self) -> Result<(), String> {
        let res = self.options.resolution;
        if res == 0 || res > super::MAX_RESOLUTION {
            return Err(format!(
                "resolution {res} is outside 1..={}",
                super::MAX_RESOLUTION
            ));
        }
        RemeshReport::check_samples(self.samples).map_err(|e| format!("samples: {e}"))?;
        match self.thicken_cells {
            Some(k) if !(k.is_finite() && k >= 1.0) => {
                Err(format!("thicken: {k} cells: use at least one finest cell"))
            }
            _ => Ok(()),
        }
    }

    fn time_limit(&self) -> Option<Duration> {
        self.time_limit
    }

    fn status(error: &RemeshJobError) -> crate::products::dataset::Status {
        if error.downcast_ref::<TimeLimitExceeded>().is_some() {
            crate::products::dataset::Status::Timeout
        } else {
            crate::products::dataset::Status::Failed
        }
    }

    fn walks(&self, path: &Path) -> bool {
        let curved = cfg!(feature = "patch") && is_curved_path(path);
        curved || crate::io::format_from_extension(path).is_some()
    }

    fn run(
        &self,
        path: &Path,
        _key: &str,
        deadline: Option<(Instant, Duration)>,
        stats: &mut Stats,
    ) -> Result<Vec<u8>, RemeshJobError> {
        let in_time = |stage| in_time(deadline, stage);
        let input = load_input_with(path, &self.load)?.input;
        stats.set("input", json_string(input_name(input.kind())));
        match &input {
            Input::Mesh(mesh) => {
                stats.set("faces", mesh.triangles().len());
                stats.set("vertices", mesh.positions().len());
            }
            Input::Cloud(cloud) => stats.set("vertices", cloud.len()),
            #[cfg(feature = "patch")]
            Input::Patches(set) => stats.set("faces", set.patches().len()),
            #[cfg(feature = "patch")]
            Input::Step(model) => stats.set("faces", model.faces().len()),
        }
        in_time("loading")?;
        let bounds = input.bounding_box().ok_or("the input has no geometry")?;
        // A closed mesh with flipped faces by its parity, on request.
        let parity = input.mesh().filter(|mesh| {
            self.parity_where_flipped
                && EdgeCensus::of(mesh, BoundaryBy::default()).closed_but_not_oriented()
        });
        let wn: Box<dyn Evaluator> = match parity {
            Some(mesh) => Box::new(CrossingParity::new(mesh)?),
            None => EvaluatorSpec::default().build(&input)?,
        };
        stats.set(
            "method",
            json_string(match (&input, parity) {
                (_, Some(_)) => "parity",
                (Input::Cloud(_), None) => "fast",
                _ => "exact",
            }),
        );
        let Some(mesh) = input.mesh() else {
            // A point cloud (the fast evaluator) or a curved input (its own surface hits place
            // the vertices): no triangles to guide the remesh or to thicken, as `gwn remesh`.
            if self.thicken_cells.is_some() {
                return Err(format!(
                    "thicken: needs triangles (a mesh or soup), not {}",
                    input.kind()
                )
                .into());
            }
            in_time("building the evaluator")?;
            let out = self.remesh(&*wn, None, None, bounds, deadline)?;
            #[cfg(feature = "patch")]
            let curved = (self.samples > 0)
                .then(|| super::report::curved_surface_for_distance(&input, out.cell_size))
                .flatten();
            #[cfg(feature = "patch")]
            let reference = curved
                .as_ref()
                .map_or(DistanceReference::None, DistanceReference::Curved);
            #[cfg(not(feature = "patch"))]
            let reference = DistanceReference::None;
            return self.finish(out, &*wn, reference, bounds, deadline, stats);
        };
        let extent = (0..3)
            .map(|k| bounds.max[k] - bounds.min[k])
            .fold(0.0, f64::max);
        let cell = extent / self.options.resolution as f64;
        // A closed mesh has no open sheet to thicken.
        let thick = self
            .thicken_cells
            .filter(|_| parity.is_none())
            .map(|k| ThickenedSheets::new(mesh, &*wn, k * cell))
            .transpose()?;
        let MeshField {
            field,
            guide,
            bounds,
            reference,
        } = thicken::of_mesh(mesh, &*wn, thick.as_ref(), bounds);
        in_time("building the evaluator")?;
        // Kept with its vertices merged by position, as the field's boundary is: not when
        // welding is off (a boundary by index).
        let keep = match parity {
            _ if !(self.keep_input && thick.is_none() && self.load.weld != Some(false)) => Keep::No,
            Some(_) => Keep::Parity,
            None => Keep::Winding,
        };
        let out = self.remesh(field, Some(&guide), Some((mesh, keep)), bounds, deadline)?;
        self.finish(out, field, reference, bounds, deadline, stats)
    }
}

/// [`TimeLimitExceeded`] while `stage` runs once `deadline` has passed.
fn in_time(
    deadline: Option<(Instant, Duration)>,
    stage: &'static str,
) -> Result<(), TimeLimitExceeded> {
    match deadline {
        Some((at, limit)) if Instant::now() > at => Err(TimeLimitExceeded { stage, limit }),
        _ => Ok(()),
    }
}

/// Whether `path` names a patch set or a STEP model (by its extension).
fn is_curved_path(path: &Path) -> bool {
    #[cfg(feature = "patch")]
    {
        crate::patch::is_patch_path(path) || crate::patch::step::is_step_path(path)
    }
    #[cfg(not(feature = "patch"))]
    {
        let _ = path;
        false
    }
}

/// The manifest's name of an input kind.
fn input_name(kind: InputKind) -> &'static str {
    match kind {
        InputKind::Mesh => "mesh",
        InputKind::Cloud => "point cloud",
        InputKind::Patches => "patch set",
        InputKind::Step => "STEP model",
    }
}

impl RemeshJob {
    /// [`remesh_guided`] under the job's options and `deadline`, its time limit named as the
    /// job's; [`super::remesh_mesh`] with `mesh` (the mesh, and whether it may be kept).
    fn remesh(
        &self,
        field: &dyn Evaluator,
        guide: Option<&SegmentBvh>,
        mesh: Option<(&Mesh, Keep)>,
        bounds: crate::BoundingBox,
        deadline: Option<(Instant, Duration)>,
    ) -> Result<Remeshed, RemeshJobError> {
        let options = RemeshOptions {
            deadline: deadline.map(|(at, _)| at),
            ..self.options
        };
        let out = match mesh {
            Some((mesh, keep)) => remesh_mesh(mesh, keep, field, guide, bounds, &options, &|_| {}),
            None => remesh_guided(field, guide, bounds, &options, &|_| {}),
        };
        out.map_err(|e| -> RemeshJobError {
            match (e, deadline) {
                (super::RemeshError::TimeLimit { phase }, Some((_, limit))) => {
                    Box::new(TimeLimitExceeded {
                        stage: phase.name(),
                        limit,
                    })
                }
                (e, _) => Box::new(e),
            }
        })
    }

    /// Measures `out` against `reference`, fills the row's statistics and gives the output's
    /// bytes.
    fn finish(
        &self,
        mut out: Remeshed,
        field: &dyn Evaluator,
        reference: DistanceReference<'_>,
        bounds: crate::BoundingBox,
        deadline: Option<(Instant, Duration)>,
        stats: &mut Stats,
    ) -> Result<Vec<u8>, RemeshJobError> {
        let in_time = |stage| in_time(deadline, stage);
        let positions = std::mem::take(&mut out.positions);
        let triangles = std::mem::take(&mut out.triangles);
        let surface = Mesh::new(positions, triangles)?;
        // The agreement's and the distance's side tests evaluate `w` too: stopped at the
        // deadline like the remesh, the report then discarded by the check below.
        let report = RemeshReport::measure(
            &out,
            &surface,
            &self.options,
            &super::deadline::Deadlined::new(field, deadline.map(|(at, _)| at)),
            reference,
            bounds,
            self.samples,
            &|_| {},
        )?;
        in_time("measuring the report")?;
        let mut bytes = Vec::new();
        write_surface(&mut bytes, self.format, &surface)?;
        let t = report.topology;
        stats.set("kept", out.stats.input.is_some_and(|i| i.is_kept()));
        // The input's faces in the output as they are: all of a kept input, the components
        // kept of one kept in part.
        let kept_faces = match out.stats.input {
            Some(InputCheck::Kept { .. }) => t.faces,
            Some(InputCheck::PartlyKept { kept_faces, .. }) => kept_faces,
            Some(InputCheck::Cut { uncut_faces, .. }) => uncut_faces,
            Some(InputCheck::Reoriented { turned_faces, .. }) => {
                t.faces.saturating_sub(turned_faces)
            }
            _ => 0,
        };
        stats.set("kept_faces", kept_faces);
        let or_null = |v: Option<String>| v.unwrap_or_else(|| "null".into());
        // How the output was made (the remesh report's `input`; `remeshed` where nothing was
        // tried), and why an empty one is empty.
        let outcome = out.stats.input.map_or("remeshed", |i| i.name());
        stats.set("outcome", json_string(outcome));
        let empty = (t.faces == 0).then(|| json_string(WhyEmpty::of(out.stats.input).name()));
        stats.set("output_faces", t.faces);
        stats.set("empty", or_null(empty));
        stats.set("output_vertices", t.vertices);
        let intersections = report.self_intersections.as_ref().ok().map(|r| r.pairs);
        let valid = t.closed && t.edge_manifold && t.vertex_manifold && t.oriented;
        stats.set("valid", valid && intersections == Some(0));
        stats.set("components", t.components);
        stats.set(
            "self_intersections",
            or_null(intersections.map(|n| n.to_string())),
        );
        // The distance to where the input bounds the solid (the plain one for thickened
        // sheets), in finest cells, and the agreement: JSON numbers or null.
        let hausdorff = report
            .boundary_hausdorff
            .map(|b| b.distance)
            .or(report.hausdorff)
            .map(|d| json_number(d / out.cell_size));
        stats.set("hausdorff_cells", or_null(hausdorff));
        stats.set(
            "occupancy_agreement",
            or_null(report.occupancy_agreement.map(json_number)),
        );
        Ok(bytes)
    }
}
