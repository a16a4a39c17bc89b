//! `gwn remesh`: a closed, manifold, oriented surface of `{w > ½}` (`gwn::products::remesh`).

use std::path::PathBuf;

use clap::Args as ClapArgs;
use gwn::products::remesh::crossings::SegmentBvh;
use gwn::products::remesh::keep_input::{InputCheck, WhyEmpty};
use gwn::products::remesh::reorient;
use gwn::products::remesh::report::{
    DistanceReference, PhaseClock, RemeshReport, ReportPhase, curved_surface_for_distance,
};
use gwn::products::remesh::simplify::SimplifyOptions;
use gwn::products::remesh::thicken::{self, ThickenedSheets};
use gwn::products::remesh::write::{SurfaceFormat, write_surface};
use gwn::products::remesh::{
    DEFAULT_BISECTION_STEPS, Keep, RemeshOptions, remesh_guided, remesh_mesh,
};

use crate::common::{CliError, outln};
use crate::method::{MethodArgs, ToleranceArgs};
use gwn::spec::Method;

/// Remesh at w = 1/2: a closed, edge- and vertex-manifold, consistently oriented surface of the
/// solid where the winding number (exact by default) is above 1/2.
///
/// Every solid is kept (nested and disjoint parts), double walls and inner faces vanish where w
/// says so, holes close where w decides. Corners of a lattice of cell edge `extent / res` (finer
/// across a thin axis) are classified (ray reuse on a coarse level, an octree only where classes
/// differ), the surface is extracted by marching tetrahedra and each vertex placed on its lattice
/// edge where w crosses 1/2 (at the edge's crossing with the input triangles once two evaluations
/// confirm it, else by bisection). The report counts self-intersections with exact predicates and gives a sampled
/// Hausdorff distance to the input. See docs/remesh.md.
#[derive(ClapArgs, Debug)]
pub struct Args {
    /// Mesh file (OBJ, STL, OFF, PLY, glTF/GLB) or oriented point cloud (.xyz, .csv, .pts, .ply).
    pub mesh: PathBuf,
    /// Finest equivalent resolution: cells of edge (longest extent of the box) / res, and at
    /// least res/4 cells across every axis (finer cells across a thin plate).
    #[arg(long, default_value_t = 128)]
    pub res: usize,
    /// Output surface: `.obj`, `.ply` (binary), `.stl` (binary) or `.glb` (binary glTF).
    #[arg(long, short)]
    pub out: PathBuf,
    /// Write the report as JSON here.
    #[arg(long)]
    pub report: Option<PathBuf>,
    /// Uniform samples in the box for the occupancy agreement of output and input, and samples
    /// per surface for the Hausdorff distance (0: skip both; at most 10,000,000).
    #[arg(long, default_value_t = 10_000)]
    pub samples: usize,
    /// Place every vertex by searching the field, without the input triangles' crossings (or a
    /// STEP model's or patch set's surface hits) as a guide (same guarantees, more evaluations;
    /// for comparison).
    #[arg(long)]
    pub no_guide: bool,
    /// Close open sheets (cloth, leaves, single walls: w near 1/2 on both sides, no volume) into
    /// slabs of half-thickness EPS (world units, at least one finest cell) where w says the
    /// surface is open; solids are left as they are. Meshes and soups only. Off by default.
    #[arg(long, value_name = "EPS")]
    pub thicken: Option<f64>,
    /// Give up (exit 1) once the remesh has run this many seconds (checked between its phases
    /// and rounds; the report after it is not limited).
    #[arg(long)]
    pub time_limit: Option<f64>,
    #[command(flatten)]
    pub knobs: RemeshKnobs,
    #[command(flatten)]
    pub method: MethodArgs,
    #[command(flatten)]
    pub weld: crate::common::WeldArgs,
    #[command(flatten)]
    pub tolerance: ToleranceArgs,
}

/// Runs `gwn remesh`.
pub fn run(args: Args) -> Result<(), CliError> {
    let format = SurfaceFormat::of_path(&args.out).ok_or_else(|| {
        CliError::msg(format!(
            "{}: unknown output extension (use .obj, .ply, .stl or .glb)",
            args.out.display()
        ))
    })?;
    RemeshReport::check_samples(args.samples)
        .map_err(|e| CliError::msg(format!("--samples: {e}")))?;
    let time_limit = crate::dataset::time_limit(args.time_limit)?;
    let method = args.method.spec(args.tolerance, args.weld);
    method.validate()?;
    let input = crate::method::load_input(&args.mesh, args.weld)?;
    let bounds = input
        .bounding_box()
        .ok_or_else(|| CliError::msg(format!("{}: has no geometry", args.mesh.display())))?;
    let built = crate::method::build(&method, &input, &args.mesh)?;
    let thickened = match (args.thicken, input.mesh()) {
        (None, _) => None,
        (Some(_), None) => {
            return Err(CliError::msg(format!(
                "{}: --thicken needs triangles (a mesh or soup), not a point cloud or patches",
                args.mesh.display()
            )));
        }
        (Some(eps), Some(mesh)) => {
            let extent = (0..3)
                .map(|k| bounds.max[k] - bounds.min[k])
                .fold(0.0, f64::max);
            let cell = extent / args.res.max(1) as f64;
            // Thinner slabs can fall between the lattice points and vanish.
            if eps.is_nan() || eps < cell {
                return Err(CliError::msg(format!(
                    "{}: --thicken {eps} is below one finest cell ({cell:.4e} at --res {}): \
                     use at least that",
                    args.mesh.display(),
                    args.res
                )));
            }
            Some(
                ThickenedSheets::new(mesh, &*built, eps)
                    .map_err(|e| CliError(format!("{}: --thicken: {e}", args.mesh.display())))?,
            )
        }
    };
    let mut options = args.knobs.options(args.res, !args.no_guide);
    // Phases: classify, extract, place, [simplify,] write, self-intersections, Hausdorff,
    // agreement.
    let bar = crate::common::progress(if args.knobs.no_simplify { 7 } else { 8 }, "remesh");
    let start = std::time::Instant::now();
    options.deadline = time_limit.map(|limit| start + limit);
    // A mesh's field, guide, box and distance reference as every remesh of a mesh sets them up
    // (thickened or not: the slabs reach EPS past the box, which grows to hold them); the other
    // inputs have their own evaluator and no triangles.
    let mesh_field = input
        .mesh()
        .map(|m| thicken::of_mesh(m, &*built, thickened.as_ref(), bounds));
    let (wn, guide, bounds): (&dyn gwn::eval::Evaluator, Option<&SegmentBvh>, _) = match &mesh_field
    {
        Some(f) => (f.field, (!args.no_guide).then_some(&f.guide), f.bounds),
        None => (&*built, None, bounds),
    };
    let clock = PhaseClock::start();
    let announce = |phase: gwn::products::remesh::RemeshPhase| {
        clock.mark(phase);
        bar.set_message(phase.name());
        use gwn::products::remesh::RemeshPhase;
        if !matches!(phase, RemeshPhase::Classify | RemeshPhase::KeepInput) {
            bar.inc(1);
        }
    };
    // A mesh that already is the boundary of its `w > ½` solid is the answer as it is (exact
    // checks, linear in the input), and under the parity method a closed mesh that is the
    // boundary of its parity's solid once its faces are turned: the field of the mesh itself
    // only. (Its vertices merged by position, as the exact method's boundary is by default: not
    // with --no-weld, whose boundary is by index.)
    let own_field = thickened.is_none() && !args.weld.no_weld && !args.knobs.always_remesh;
    let keep = match method.method_for(input.kind()) {
        Method::Exact if own_field => Keep::Winding,
        Method::Parity if own_field => Keep::Parity,
        _ => Keep::No,
    };
    let out = match input.mesh() {
        Some(mesh) => remesh_mesh(mesh, keep, wn, guide, bounds, &options, &announce),
        None => remesh_guided(wn, guide, bounds, &options, &announce),
    };
    let mut out = out.map_err(|e| CliError(format!("{}: {e}", args.mesh.display())))?;
    let secs = start.elapsed().as_secs_f64();
    let phase_seconds = clock.seconds();
    bar.inc(1);
    bar.set_message("writing");
    let file = std::fs::File::create(&args.out)
        .map_err(|e| CliError(format!("{}: {e}", args.out.display())))?;
    let positions = std::mem::take(&mut out.positions);
    let triangles = std::mem::take(&mut out.triangles);
    let mesh = gwn::Mesh::new(positions, triangles)?;
    write_surface(std::io::BufWriter::new(file), format, &mesh)
        .map_err(|e| CliError(format!("{}: {e}", args.out.display())))?;
    // Curved inputs are measured against a tessellation within a small fraction of a cell
    // (`patch_surface_for_distance`, `step_surface_for_distance`).
    let curved_surface = (args.samples > 0)
        .then(|| curved_surface_for_distance(&input, out.cell_size))
        .flatten();
    // Thickened sheets bound nothing of the slabs' solid: their distance counts every sample.
    let reference = match (&mesh_field, &curved_surface) {
        (Some(f), _) => f.reference,
        (None, Some(curved)) => DistanceReference::Curved(curved),
        (None, None) => DistanceReference::None,
    };
    let measure_phase = |phase: ReportPhase| {
        bar.inc(1);
        bar.set_message(phase.name());
    };
    let mut report = RemeshReport::measure(
        &out,
        &mesh,
        &options,
        wn,
        reference,
        bounds,
        args.samples,
        &measure_phase,
    )
    .map_err(|e| CliError::msg(format!("--samples: {e}")))?;
    report.seconds = secs;
    let kept = out.stats.input.is_some_and(|i| i.skipped_the_lattice());
    report.phase_seconds = (!kept).then_some(phase_seconds);
    report.thicken = thickened.as_ref().map(|t| t.eps());
    drop(curved_surface);
    let topology = report.topology;
    bar.finish_and_clear();
    let s = out.stats;
    let cell_size = out.cell_size;
    // Cells are cubes unless the box is thin along an axis (finer cells across it).
    let cells = if out.cell_sizes.iter().all(|&h| h == cell_size) {
        format!("cell {cell_size:.4e}")
    } else {
        let [x, y, z] = out.cell_sizes;
        format!("cells {x:.4e} x {y:.4e} x {z:.4e}")
    };
    match s.input {
        Some(InputCheck::Kept { repairs, separated })
        | Some(InputCheck::Cut {
            repairs, separated, ..
        }) => {
            // What the kept input lost or gained (faces; positions only where solids touching
            // were pulled apart), and what the cut changed.
            // Faces of one plane replaced, or vertices moved: no longer the input as it is.
            let changed = !separated.is_empty() || !repairs.coplanar.is_empty();
            let mut repairs = if repairs.is_empty() {
                String::new()
            } else {
                format!(", {repairs}")
            };
            if !separated.is_empty() {
                repairs += &format!(", {separated}");
            }
            let what = match s.input {
                Some(InputCheck::Cut {
                    cut, uncut_faces, ..
                }) => format!(
                    "the input cut at its self-intersections ({cut}{repairs}; {} faces, \
                     {uncut_faces} of them the input's",
                    topology.faces
                ),
                _ if changed => {
                    format!("the input ({} faces{repairs}", topology.faces)
                }
                _ => format!("the input as it is ({} faces{repairs}", topology.faces),
            };
            outln!(
                "{}: {what}, {secs:.2} s): closed, manifold, oriented, no self-intersection \
                 (exact) and the boundary of w > 1/2 (--always-remesh remeshes it at res {})",
                args.out.display(),
                args.res
            )?;
            outln!("{topology}")?;
        }
        Some(InputCheck::Reoriented {
            repairs,
            turned_faces,
        }) => {
            let repairs = if repairs.is_empty() {
                String::new()
            } else {
                format!(", {repairs}")
            };
            outln!(
                "{}: the input with {turned_faces} of its faces turned ({} faces{repairs}, \
                 {secs:.2} s): closed, manifold, oriented, no self-intersection (exact) and the \
                 boundary of the parity method's solid (--always-remesh remeshes it at res {})",
                args.out.display(),
                topology.faces,
                args.res
            )?;
            outln!("{topology}")?;
        }
        Some(InputCheck::PartlyKept {
            kept_components,
            components,
            kept_faces,
            why,
        }) => outln!(
            "partly kept: the input is not kept as it is ({why}); {kept_components} of its \
             {components} components ({kept_faces} faces) are, exactly, and the rest is remeshed"
        )?,
        Some(InputCheck::Remeshed(why)) => {
            outln!("remeshed: the input is not kept as it is: {why}")?
        }
        Some(InputCheck::Planar { repairs }) => {
            let repairs = if repairs.is_empty() {
                String::new()
            } else {
                format!(" ({repairs})")
            };
            outln!(
                "{}: no lattice needed ({secs:.2} s): the input{repairs} lies in one plane and its \
                 faces meet only at the corners and edges they share (exact), so |w| < 1/2 off \
                 it and w > 1/2 nowhere",
                args.out.display()
            )?;
            outln!("{topology}")?;
        }
        Some(InputCheck::BoundsNothing { repairs, why }) => {
            let repairs = if repairs.is_empty() {
                String::new()
            } else {
                format!(" ({repairs})")
            };
            outln!(
                "{}: no lattice needed ({secs:.2} s): the input{repairs} is closed, manifold, \
                 oriented and without self-intersection (exact), and w <= 0 on both sides of \
                 each of its components ({why}), so w > 1/2 nowhere",
                args.out.display()
            )?;
            outln!("{topology}")?;
        }
        None => {}
    }
    if !kept {
        outln!(
            "{}: res {} ({cells}, lattice {}x{}x{}), {:.2} s, {} points classified, {} band cells",
            args.out.display(),
            args.res,
            s.lattice_cells[0],
            s.lattice_cells[1],
            s.lattice_cells[2],
            secs,
            s.classified_points,
            s.band_cells
        )?;
        let phases: Vec<String> = phase_seconds
            .named()
            .iter()
            .map(|(name, s)| format!("{name} {s:.2}"))
            .collect();
        outln!("seconds by phase: {}", phases.join(", "))?;
        if options.sub_cell_levels > 0 {
            outln!(
                "sub-cell levels: {} ({} cells crossed by the input with agreeing corners refined)",
                options.sub_cell_levels,
                s.refined_cells
            )?;
        }
        if options.planar_levels > 0 {
            let f = s.flatness.flat_fraction;
            let kept = if s.planar_levels > 0 {
                format!(
                    "cells up to {}x the resolution's kept whole where the input is flat",
                    1u32 << s.planar_levels
                )
            } else {
                "too little of the input is flat for them to pay".to_string()
            };
            outln!(
                "planar levels: {} of {} ({kept}; input area flat at 2x, 4x, 8x: {:.0} %, {:.0} %, \
                 {:.0} %)",
                s.planar_levels,
                options.planar_levels,
                100.0 * f[1],
                100.0 * f[2],
                100.0 * f[3]
            )?;
        }
        if s.plates.refines() {
            let axes: Vec<String> = (0..3)
                .filter(|&a| s.plates.refinement[a] > 1.0)
                .map(|a| {
                    let thickness = s.plates.thickness[a].unwrap_or(f64::NAN);
                    format!(
                        "{:.2}x along {} (plates {thickness:.4e} thick)",
                        s.plates.refinement[a],
                        ["x", "y", "z"][a]
                    )
                })
                .collect();
            outln!(
                "cells made finer for plates of the input thinner than a cell: {}",
                axes.join(", ")
            )?;
        }
        outln!("{topology}")?;
        if options.simplify.is_some() {
            outln!(
                "faces: {} marching tetrahedra, {} after {} edge collapses ({:.1} %); a dense marching \
                 cubes would have {} ({:.1} % of it)",
                s.extracted_faces,
                topology.faces,
                s.simplify.collapses,
                100.0 * topology.faces as f64 / s.extracted_faces.max(1) as f64,
                s.marching_cubes_faces,
                100.0 * topology.faces as f64 / s.marching_cubes_faces.max(1) as f64
            )?;
            outln!(
                "vertices on cube face and body diagonals collapsed cube by cube first: {} ({} kept)",
                s.simplify.diagonal_collapses,
                s.simplify.diagonals_left
            )?;
            outln!(
                "vertices moved towards their quadric minimum: {} ({} moves refused by the checks)",
                s.simplify.relocated,
                s.simplify.relocations_refused
            )?;
        } else {
            outln!(
                "faces: {} marching tetrahedra (not simplified); a dense marching cubes would have {}",
                s.extracted_faces,
                s.marching_cubes_faces
            )?;
        }
        outln!(
            "marching-tetrahedra vertices placed at a verified crossing with the input: {} of {} ({} \
             evaluations)",
            s.guided_vertices,
            s.extracted_vertices,
            s.placement_evaluations
        )?;
    }
    match &report.self_intersections {
        Ok(r) => outln!(
            "self-intersections (exact): {} face pairs ({} pairs tested, {} degenerate faces, \
             {:.2} s)",
            r.pairs,
            r.tested_pairs,
            r.degenerate_faces,
            report.self_intersection_seconds
        )?,
        Err(e) => outln!("self-intersections: not counted: {e}")?,
    }
    if let Some(d) = report.hausdorff {
        // A curved input's distance is to its tessellation (`patch_surface_for_distance`).
        let to = match report.reference_segment {
            Some(segment) => format!(
                "the input's surfaces tessellated to segments of at most {:.2} cells",
                segment / cell_size
            ),
            None => "the input".to_string(),
        };
        outln!(
            "Hausdorff distance to {to} (sampled, {} points per surface): {:.4e} = {:.3} cells",
            args.samples,
            d,
            d / cell_size
        )?;
    }
    if let Some(b) = report.boundary_hausdorff {
        outln!(
            "  to the input where it bounds the solid (w > 1/2 on one side only: {:.1} % of its \
             samples): {:.4e} = {:.3} cells",
            100.0 * b.boundary_fraction,
            b.distance,
            b.distance / cell_size
        )?;
    }
    if let Some(t) = &thickened {
        outln!(
            "thickened open sheets: half-thickness {:.4e} = {:.3} cells (agreement is against \
             the thickened solid)",
            t.eps(),
            t.eps() / cell_size
        )?;
    }
    if let Some(a) = report.occupancy_agreement {
        outln!(
            "occupancy agreement {:.3} % of {} samples in the box",
            100.0 * a,
            args.samples
        )?;
    }
    if let (Some(mesh), Method::Exact, None) =
        (input.mesh(), method.method_for(input.kind()), args.thicken)
    {
        if let Some(flipped) = reorient::flipped_input(mesh, method.boundary, bounds, &options) {
            outln!("{flipped}; {}", flipped.way_out("--method parity"))?;
        }
    }
    // An empty output is right where `w > ½` is empty, but rarely what was meant: say why.
    if let Some(mesh) = input
        .mesh()
        .filter(|m| topology.faces == 0 && thickened.is_none() && !m.is_empty())
    {
        let why = WhyEmpty::of_mesh(mesh, bounds, &options, s.input);
        let way_out = match why {
            WhyEmpty::WindsInward => "--method parity remeshes the solid it encloses",
            WhyEmpty::NoVolume => {
                "--thicken EPS closes open sheets into thin solids; a finer --res"
            }
        };
        let nowhere = if kept {
            "w > 1/2 nowhere"
        } else {
            "w > 1/2 at no point of the lattice"
        };
        outln!("the output is empty: {nowhere}; {why}: {way_out}")?;
    }
    if let Some(path) = &args.report {
        std::fs::write(path, report.to_json() + "\n")
            .map_err(|e| CliError(format!("{}: {e}", path.display())))?;
    }
    Ok(())
}

/// The remesher's knobs, shared by `gwn remesh` and `gwn remesh-dataset`.
#[derive(ClapArgs, Debug)]
pub struct RemeshKnobs {
    /// Bisection steps per vertex along its lattice edge.
    #[arg(long, default_value_t = DEFAULT_BISECTION_STEPS)]
    pub bisect: u32,
    /// Keep the raw marching-tetrahedra surface: no edge collapses (about 12x the faces of the
    /// simplified surface, vertices within one tick of the class change).
    #[arg(long)]
    pub no_simplify: bool,
    /// Simplification tolerance: every removed vertex stays within this many finest cells of
    /// the simplified surface.
    #[arg(long, default_value_t = gwn::products::remesh::simplify::DEFAULT_MAX_DISTANCE)]
    pub simplify_distance: f64,
    /// Stop simplifying at this fraction of a dense marching cubes' face count (0: as far as
    /// the tolerance allows).
    #[arg(long, default_value_t = gwn::products::remesh::simplify::DEFAULT_TARGET_FRACTION)]
    pub simplify_target: f64,
    /// After the target, keep collapsing where the quadric error is at most this many finest
    /// cells (flat regions end with few faces; 0: stop at the target).
    #[arg(long, default_value_t = gwn::products::remesh::simplify::DEFAULT_FLAT_TOLERANCE)]
    pub simplify_flat: f64,
    /// Largest face, in finest cells along an axis, that a collapse of a flat vertex star (all
    /// its faces in one plane) may make, in a last flat stage; other collapses keep faces within
    /// 6 cells. 6: no large flat faces (box-like inputs keep several times more faces, in less
    /// time on large flat regions).
    #[arg(long, default_value_t = gwn::products::remesh::simplify::DEFAULT_MAX_FLAT_FACE_EXTENT)]
    pub simplify_flat_extent: u32,
    /// Keep every simplified vertex on its marching-tetrahedra position (no move towards the
    /// quadric minimum after the collapses).
    #[arg(long)]
    pub no_relocate: bool,
    /// Relocate vertices by the planes of the marching-tetrahedra faces, not by the input
    /// triangles' planes at the vertices placed on them.
    #[arg(long)]
    pub no_input_planes: bool,
    /// Keep the lattice of --res alone: do not make the cells finer across widespread plates of
    /// the input thinner than two cells (at most 4 times finer, all axes together; meshes and
    /// soups only).
    #[arg(long)]
    pub no_plate_refinement: bool,
    /// Levels of cells below --res (0 to 3; 0: none): a cell that an input triangle crosses
    /// while its corners agree, with a solid of the other class just off the triangle (a part
    /// thinner than a cell: a tip, a leg, a rib), is cut into eight, down to this many levels,
    /// with conforming transitions (meshes and soups only).
    #[arg(long, default_value_t = gwn::products::remesh::DEFAULT_SUB_CELL_LEVELS)]
    pub sub_cell_levels: u32,
    /// Levels of cells above --res (0 to 3) kept whole where the input in them is flat (within
    /// a tenth of a cell of one plane, with an integer winding number at their corners): a flat
    /// face costs cells by its area in cells up to 2^N times larger. At most N: a probe of the
    /// input says how many pay (meshes and soups only).
    #[arg(long, default_value_t = gwn::products::remesh::DEFAULT_PLANAR_LEVELS)]
    pub planar_levels: u32,
    /// Use all --planar-levels, whatever the flatness probe finds.
    #[arg(long)]
    pub no_flatness_probe: bool,
    /// Remesh even an input that already is a closed, manifold, oriented surface without
    /// self-intersections bounding w > 1/2 (by default such an input, proved so with exact
    /// tests, is written as it is when it has at most the simplification target's faces, or at
    /// most 10,000; one that only self-intersects is cut along its intersections and kept where
    /// it bounds w > 1/2, and solids touching at a vertex or along an edge are pulled apart
    /// there by at most 1/64 of a cell, and faces overlapping in one plane (a part on a plate)
    /// are replaced by what they add up to there; otherwise its clean components can be, with the rest
    /// remeshed; not tried
    /// with --no-weld, --thicken, --no-simplify or a method other than exact).
    #[arg(long)]
    pub always_remesh: bool,
}

impl RemeshKnobs {
    /// The library's options at resolution `res`; `guided`: vertices placed at the input's
    /// crossings where two evaluations confirm them.
    pub fn options(&self, res: usize, guided: bool) -> RemeshOptions {
        RemeshOptions {
            resolution: res,
            bisection_steps: self.bisect,
            max_classified_points: None,
            simplify: (!self.no_simplify).then_some(SimplifyOptions {
                max_distance: self.simplify_distance,
                target_fraction_of_marching_cubes: self.simplify_target,
                relocate: !self.no_relocate,
                input_planes: !self.no_input_planes,
                flat_tolerance: self.simplify_flat,
                max_flat_face_extent: self.simplify_flat_extent,
                ..SimplifyOptions::default()
            }),
            refine_plates: !self.no_plate_refinement,
            sub_cell_levels: self.sub_cell_levels,
            planar_levels: self.planar_levels,
            probe_flatness: !self.no_flatness_probe,
            evaluator_crossings: guided,
            deadline: None,
        }
    }
}
