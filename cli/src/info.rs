//! `gwn info MESH`: format, size and topology of a mesh file (or what a point cloud, patch set or
//! STEP model holds).

use std::io::Write;
use std::path::PathBuf;

use gwn::io::{MeshOrCloud, load_mesh_or_cloud};
use gwn::mesh::stats::MeshStats;

use crate::common::CliError;

/// Arguments of `gwn info`.
#[derive(clap::Args)]
pub struct Args {
    /// Mesh file (.obj, .stl, .off, .ply, .gltf, .glb; detected by content if the extension is
    /// unknown), oriented point cloud (.xyz, .pts, .txt, .csv, or a PLY with normals and no
    /// faces), Bézier patch set (.bpt, rational .rbpt), or trimmed B-rep model (.step, .stp).
    pub mesh: PathBuf,
    #[command(flatten)]
    pub weld: crate::common::WeldArgs,
}

/// Loads the mesh and prints its statistics.
pub fn run(args: Args) -> Result<(), CliError> {
    if gwn::patch::step::is_step_path(&args.mesh) {
        let model = gwn::patch::step::load_step(&args.mesh)?;
        crate::common::write_stdout(format_args!("{}", step_report(&args.mesh, &model)))?;
        return Ok(());
    }
    if gwn::patch::is_patch_path(&args.mesh) {
        let set = gwn::patch::load_patches(&args.mesh)?;
        crate::common::write_stdout(format_args!("{}", patch_report(&args.mesh, &set)))?;
        return Ok(());
    }
    // Meshes and clouds as every other subcommand reads them (a PLY without faces is a cloud).
    let loaded = match load_mesh_or_cloud(&args.mesh, &args.weld.load_options())? {
        MeshOrCloud::Mesh(loaded) => loaded,
        MeshOrCloud::Cloud(cloud, warnings) => {
            crate::common::print_load_warnings(&args.mesh, &warnings);
            crate::common::write_stdout(format_args!("{}", cloud_report(&args.mesh, &cloud)))?;
            return Ok(());
        }
    };
    crate::common::print_load_warnings(&args.mesh, &loaded.warnings);
    let s = MeshStats::compute(&loaded.mesh);
    std::io::stdout()
        .write_all(report(&args.mesh, &loaded, &s).as_bytes())
        .map_err(crate::common::stdout_error)?;
    Ok(())
}

/// The text block `gwn info` prints for a STEP model.
fn step_report(path: &std::path::Path, model: &gwn::patch::step::StepModel) -> String {
    let i = model.info();
    let (lo, hi) = model.bounding_box();
    let surfaces = i
        .surfaces
        .iter()
        .map(|(k, n)| format!("{n} {k}"))
        .collect::<Vec<_>>()
        .join(", ");
    let rows: Vec<(&str, String)> = vec![
        ("file", path.display().to_string()),
        ("format", "STEP (ISO 10303-21) B-rep, trimmed".into()),
        ("length unit", i.topology.length_unit.clone()),
        ("solids", i.topology.solids.to_string()),
        ("shells", i.topology.shells.to_string()),
        ("faces", i.faces.to_string()),
        ("surfaces", surfaces),
        ("Bézier patches", i.patches.to_string()),
        ("trim polygon segments", i.trim_segments.to_string()),
        (
            "edge uses trimmed by pcurves",
            format!(
                "{} ({} pcurves off their 3D edge, {} unreadable: mapped from 3D)",
                i.pcurve_uses, i.pcurves_rejected, i.pcurves_unreadable
            ),
        ),
        ("edges", i.edges.to_string()),
        ("edge pairs cancelled", i.cancelled_exact.to_string()),
        ("edge pairs matched", i.cancelled_matched.to_string()),
        ("boundary edges", i.boundary_edges.to_string()),
        ("closed", yes(i.boundary_edges == 0).to_string()),
        ("bbox min", format!("{lo:?}")),
        ("bbox max", format!("{hi:?}")),
    ];
    aligned(&rows)
}

/// The text block `gwn info` prints for a Bézier patch set.
fn patch_report(path: &std::path::Path, set: &gwn::patch::PatchSet) -> String {
    let wn = gwn::patch::PatchWindingNumber::new(set);
    let (boundary, shared, degenerate) = wn.edge_counts();
    let mut degrees: Vec<(usize, usize)> = set.patches().iter().map(|p| p.degree()).collect();
    degrees.sort_unstable();
    degrees.dedup();
    let (lo, hi) = set.bounding_box();
    let rows: Vec<(&str, String)> = vec![
        ("file", path.display().to_string()),
        (
            "format",
            if set.is_rational() {
                "rational Bézier patches"
            } else {
                "Bézier patches"
            }
            .into(),
        ),
        ("patches", set.patches().len().to_string()),
        (
            "degrees",
            degrees
                .iter()
                .map(|(m, n)| format!("{m}x{n}"))
                .collect::<Vec<_>>()
                .join(", "),
        ),
        ("boundary edges", boundary.to_string()),
        ("shared edge pairs", shared.to_string()),
        ("collapsed edges", degenerate.to_string()),
        ("closed", yes(boundary == 0).to_string()),
        ("bbox min", format!("{lo:?}")),
        ("bbox max", format!("{hi:?}")),
    ];
    aligned(&rows)
}

/// The text block `gwn info` prints for an oriented point cloud.
fn cloud_report(path: &std::path::Path, cloud: &gwn::mesh::PointCloud) -> String {
    let mut rows: Vec<(&str, String)> = vec![
        ("file", path.display().to_string()),
        ("format", "oriented point cloud".into()),
        ("points", cloud.len().to_string()),
        (
            "areas",
            match cloud.areas() {
                Some(_) => "given".into(),
                None => "none (estimated from the 20 nearest neighbours when evaluated)".into(),
            },
        ),
    ];
    if let Some(b) = gwn::BoundingBox::of_points(cloud.positions()) {
        rows.push(("bbox min", format!("{:?}", b.min)));
        rows.push(("bbox max", format!("{:?}", b.max)));
        rows.push(("diagonal", format!("{:?}", b.diagonal())));
    }
    let mut out = aligned(&rows);
    out.push_str("a point cloud: w is the fast (Barnes-Hut) method's estimate\n");
    out
}

/// `rows` as `key  value` lines, the values aligned.
fn aligned(rows: &[(&str, String)]) -> String {
    let width = rows
        .iter()
        .map(|(k, _)| k.chars().count())
        .max()
        .unwrap_or(0);
    let mut out = String::new();
    for (k, v) in rows {
        out.push_str(&format!("{k:<width$}  {v}\n"));
    }
    out
}

fn yes(b: bool) -> &'static str {
    if b { "yes" } else { "no" }
}

/// The aligned text block `gwn info` prints.
fn report(path: &std::path::Path, l: &gwn::io::LoadedMesh, s: &MeshStats) -> String {
    let mut rows: Vec<(&str, String)> = vec![
        ("file", path.display().to_string()),
        ("format", l.format.to_string()),
        ("triangles", s.faces.to_string()),
        ("vertices", s.vertices.to_string()),
    ];
    if l.welded_vertices > 0 || l.format == gwn::io::Format::Stl {
        rows.push(("welded vertices", l.welded_vertices.to_string()));
    }
    if l.polygons_triangulated > 0 {
        rows.push(("polygons fanned", l.polygons_triangulated.to_string()));
    }
    rows.extend([
        ("unreferenced vertices", s.unreferenced_vertices.to_string()),
        ("components", s.components.to_string()),
        ("boundary edges", s.boundary_edges.to_string()),
        ("non-manifold edges", s.nonmanifold_edges.to_string()),
        (
            "signed boundary edges",
            format!(
                "{} ({} with weight > 1)",
                s.signed_boundary_edges, s.signed_boundary_heavy_edges
            ),
        ),
        (
            "signed boundary by position",
            s.geometric_boundary_edges.to_string(),
        ),
        ("degenerate faces", s.degenerate_faces.to_string()),
        ("duplicate faces", s.duplicate_faces.to_string()),
        ("closed", yes(s.closed).to_string()),
        ("oriented closed", yes(s.oriented_closed).to_string()),
    ]);
    if let Some(b) = s.bounding_box {
        rows.push(("bbox min", format!("{:?}", b.min)));
        rows.push(("bbox max", format!("{:?}", b.max)));
        // `{:?}`, as the box corners: `{}` would print 1e-300 as 301 digits.
        rows.push(("diagonal", format!("{:?}", s.diagonal)));
    }
    if let Some(snap) = gwn::eval::antipodal::Snapping::of_mesh(&l.mesh) {
        // The exact evaluator computes on the input bits either way; this says whether the
        // 60-bit lattice holds them (its fast path) or how far the snapped vertices moved.
        let value = if snap.lossless() {
            format!("lossless (cell {:e})", snap.cell)
        } else {
            format!(
                "{} vertices off the lattice, largest displacement {:e} (cell {:e}; values use the exact input)",
                snap.off_lattice, snap.max_displacement, snap.cell
            )
        };
        rows.push(("60-bit snapping", value));
    }
    let mut out = aligned(&rows);
    if s.oriented_closed {
        out.push_str("signed boundary is empty: w is an integer off the surface\n");
    } else if s.geometric_boundary_edges == 0 {
        out.push_str(
            "signed boundary by position is empty: w is an integer off the surface (the index \
             boundary cancels geometrically: split vertices)\n",
        );
    } else {
        out.push_str("signed boundary is not empty: w varies continuously near the boundary\n");
        let census = gwn::eval::parity::EdgeCensus::of(&l.mesh, Default::default());
        if census.closed_but_not_oriented() {
            out.push_str(
                "closed but not consistently oriented (every edge has an even number of faces): \
                 --method parity gives the solid it encloses\n",
            );
        }
    }
    out
}
