//! `gwn remesh` through the CLI: output formats, the JSON report, and one-line errors.

use crate::cli::gwn;

/// Writes `mesh` as OBJ at `path`.
fn write_obj_file(path: &std::path::Path, mesh: &gwn::Mesh) {
    gwn::mesh::write_obj(std::fs::File::create(path).unwrap(), mesh).unwrap();
}

/// `gwn remesh INPUT --res RES --out OUT [--report REPORT] --samples SAMPLES EXTRA...`: whether
/// it succeeded, its stdout and its stderr.
fn remesh(
    input: &std::path::Path,
    res: &str,
    out: &std::path::Path,
    report: Option<&std::path::Path>,
    samples: &str,
    extra: &[&str],
) -> (bool, String, String) {
    let mut args = vec!["remesh", input.to_str().unwrap(), "--res", res];
    args.extend(["--out", out.to_str().unwrap()]);
    if let Some(report) = report {
        args.extend(["--report", report.to_str().unwrap()]);
    }
    args.extend(["--samples", samples]);
    args.extend(extra);
    gwn(&args)
}

#[test]
fn remesh_writes_every_format_and_a_report() {
    let dir = std::env::temp_dir().join(format!("gwn-cli-remesh-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let input = dir.join("cube.obj");
    let cube = gwn::testing::unit_cube(false);
    write_obj_file(&input, &cube);
    for ext in ["obj", "ply", "stl", "glb"] {
        let out = dir.join(format!("out.{ext}"));
        let report = dir.join(format!("report-{ext}.json"));
        // The cube already is its own answer (below): the remesher's path here.
        let (ok, stdout, stderr) = remesh(
            &input,
            "20",
            &out,
            Some(&report),
            "2000",
            &["--always-remesh"],
        );
        assert!(ok, "{stderr}");
        assert!(stdout.contains("closed: yes") && stdout.contains("Euler characteristic 2"));
        assert!(stdout.contains("to the input where it bounds the solid (w > 1/2 on one side only: 100.0 % of its samples)"), "{stdout}");
        let json = std::fs::read_to_string(&report).unwrap();
        for member in [
            "\"closed\": true",
            "\"edge_manifold\": true",
            "\"vertex_manifold\": true",
            "\"oriented\": true",
            "\"euler_characteristic\": 2",
            "\"components\": 1",
            "\"occupancy_agreement\": ",
            "\"self_intersections\": 0",
            "\"collinear_faces\": 0",
            "\"hausdorff_cells\": ",
            // A clean cube bounds its solid everywhere.
            "\"hausdorff_boundary_fraction\": 1.0",
            "\"hausdorff_boundary_cells\": ",
            "\"simplified\": true",
            "\"marching_tetrahedra_faces\": ",
            "\"marching_cubes_faces\": ",
            "\"collapses\": ",
            "\"phase_seconds\": {\"probes\": ",
        ] {
            assert!(json.contains(member), "{member} not in {json}");
        }
        assert!(stdout.contains("seconds by phase: probes "), "{stdout}");
        // STL has no shared vertices: weld when reading back (the loader does for STL).
        let back = gwn::io::load_mesh(&out).unwrap().mesh;
        let r =
            gwn::products::remesh::report::TopologyReport::of(back.positions(), back.triangles());
        assert!(r.closed && r.edge_manifold && r.oriented, "{ext}: {r}");
        assert_eq!(r.euler_characteristic, 2, "{ext}: {r}");
        assert!(json.contains("\"input\": \"remeshed\"") || !json.contains("\"input\""));
    }
    // Without --always-remesh the clean cube is written as it is, and the report says so.
    let out = dir.join("kept.obj");
    let report = dir.join("kept.json");
    let (ok, stdout, stderr) = remesh(&input, "20", &out, Some(&report), "2000", &[]);
    assert!(ok, "{stderr}");
    assert!(stdout.contains("the input as it is (12 faces"), "{stdout}");
    assert!(
        stdout.contains("self-intersections (exact): 0 face pairs"),
        "{stdout}"
    );
    assert!(stdout.contains("occupancy agreement 100.000 %"), "{stdout}");
    let json = std::fs::read_to_string(&report).unwrap();
    assert!(json.contains("\"input\": \"kept\""), "{json}");
    assert!(json.contains("\"hausdorff_boundary_cells\": 0.0"), "{json}");
    let back = gwn::io::load_mesh(&out).unwrap().mesh;
    assert_eq!(back.triangles(), cube.triangles());
    assert_eq!(back.positions(), cube.positions());
    assert!(json.contains("\"input_zero_area_faces\": 0"), "{json}");
    // A cube with a zero-area cap over a T-junction (as OpenSCAD exports write them): the cap
    // goes, the face across the junction is split, no vertex moves.
    let capped = dir.join("capped.obj");
    let mut p = cube.positions().to_vec();
    let mut t = cube.triangles().to_vec();
    let [a, b, c] = t[1];
    let (pa, pb) = (p[a as usize], p[b as usize]);
    p.push(std::array::from_fn(|k| (pa[k] + pb[k]) / 2.0));
    t[1] = [a, 8, c];
    t.extend([[8, b, c], [a, b, 8]]);
    let with_cap = gwn::Mesh::new(p.clone(), t).unwrap();
    write_obj_file(&capped, &with_cap);
    let (ok, stdout, stderr) = remesh(&capped, "20", &out, Some(&report), "2000", &[]);
    assert!(ok, "{stderr}");
    assert!(
        stdout.contains(
            "the input as it is (14 faces, 1 zero-area face left out, 1 face split at vertices \
             on their edges"
        ),
        "{stdout}"
    );
    let json = std::fs::read_to_string(&report).unwrap();
    assert!(json.contains("\"input_zero_area_faces\": 1"), "{json}");
    assert!(json.contains("\"input_split_faces\": 1"), "{json}");
    let back = gwn::io::load_mesh(&out).unwrap().mesh;
    assert_eq!(back.positions(), p.as_slice());
    // With --no-weld the exact method's boundary is by index: not tried.
    let (ok, stdout, stderr) = remesh(&input, "12", &out, None, "0", &["--no-weld"]);
    assert!(ok, "{stderr}");
    assert!(
        !stdout.contains("the input as it is") && !stdout.contains("not kept"),
        "{stdout}"
    );
    // An open box is remeshed, and the report names why.
    let open = dir.join("open.obj");
    write_obj_file(&open, &gwn::testing::unit_cube(true));
    let (ok, stdout, stderr) = remesh(&open, "12", &out, Some(&report), "0", &[]);
    assert!(ok, "{stderr}");
    assert!(
        stdout.contains("remeshed: the input is not kept as it is: it is open (4 boundary edges)"),
        "{stdout}"
    );
    let json = std::fs::read_to_string(&report).unwrap();
    assert!(
        json.contains("\"input_not_kept\": \"it is open (4 boundary edges)\""),
        "{json}"
    );
    std::fs::remove_dir_all(&dir).unwrap();
}

/// `--no-simplify` writes the marching-tetrahedra surface: the face count the simplified run
/// reports as before simplification, and more faces than the simplified run.
#[test]
fn no_simplify_writes_the_marching_tetrahedra_surface() {
    let dir = std::env::temp_dir().join(format!("gwn-cli-remesh-raw-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let input = dir.join("cube.obj");
    write_obj_file(&input, &gwn::testing::unit_cube(false));
    let faces = |extra: &[&str]| -> (usize, usize) {
        let out = dir.join("o.ply");
        let report = dir.join("r.json");
        let mut args = vec![
            "remesh",
            input.to_str().unwrap(),
            "--res",
            "12",
            "--samples",
            "0",
            "--out",
            out.to_str().unwrap(),
            "--report",
            report.to_str().unwrap(),
            "--always-remesh",
        ];
        args.extend_from_slice(extra);
        let (ok, _, stderr) = gwn(&args);
        assert!(ok, "{stderr}");
        let json = std::fs::read_to_string(&report).unwrap();
        let member = |key: &str| -> usize {
            let at = json.find(&format!("\"{key}\": ")).unwrap() + key.len() + 4;
            json[at..]
                .split(|c: char| !c.is_ascii_digit())
                .next()
                .unwrap()
                .parse()
                .unwrap()
        };
        (member("faces"), member("marching_tetrahedra_faces"))
    };
    let (simplified, before) = faces(&[]);
    let (raw, raw_before) = faces(&["--no-simplify"]);
    assert_eq!((raw, raw_before), (before, before));
    assert!(simplified < raw, "{simplified} vs {raw}");
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn remesh_errors_are_one_line() {
    let dir = std::env::temp_dir().join(format!("gwn-cli-remesh-err-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let input = dir.join("cube.obj");
    write_obj_file(&input, &gwn::testing::unit_cube(false));
    let input = input.to_str().unwrap();
    let out = dir.join("o.obj");
    let out = out.to_str().unwrap();
    let cases: [(&[&str], &str); 6] = [
        (
            &["remesh", input, "--out", "x.vtk"],
            "unknown output extension",
        ),
        (
            &["remesh", input, "--res", "0", "--out", out],
            "resolution 0",
        ),
        (
            &["remesh", input, "--bisect", "99", "--out", out],
            "bisection steps",
        ),
        (&["remesh", "/nonexistent/m.obj", "--out", out], "m.obj"),
        (
            &["remesh", input, "--simplify-distance=-1", "--out", out],
            "simplification option",
        ),
        // Refused before the remesh: 10^11 samples would be terabytes (an abort, once).
        (
            &["remesh", input, "--samples", "100000000000", "--out", out],
            "--samples: 100000000000 report samples is above the limit 10000000",
        ),
    ];
    for (args, needle) in cases {
        let (ok, _, stderr) = gwn(args);
        assert!(!ok, "{args:?}");
        assert_eq!(stderr.trim_end().lines().count(), 1, "{stderr}");
        assert!(stderr.contains(needle), "{needle}: {stderr}");
    }
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn remesh_thickens_an_open_sheet_on_request() {
    let dir = std::env::temp_dir().join(format!("gwn-cli-remesh-thick-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let input = dir.join("sheet.obj");
    std::fs::write(
        &input,
        "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nf 1 2 3\nf 1 3 4\n",
    )
    .unwrap();
    let (input, out, report) = (
        input.to_str().unwrap().to_owned(),
        dir.join("o.obj").to_str().unwrap().to_owned(),
        dir.join("r.json").to_str().unwrap().to_owned(),
    );
    let args = |extra: &[&'static str]| {
        let mut a = vec![
            "remesh",
            &input,
            "--res",
            "24",
            "--out",
            &out,
            "--samples",
            "500",
        ];
        a.extend_from_slice(extra);
        a.iter().map(|s| s.to_string()).collect::<Vec<_>>()
    };
    let call = |a: Vec<String>| gwn(&a.iter().map(String::as_str).collect::<Vec<_>>());
    // Without --thicken the sheet has no volume (|w| < ½ everywhere off it): the output is
    // empty, and the report says that empty agrees with the input at every sample.
    let mut plain = args(&["--report"]);
    plain.push(report.clone());
    let (ok, stdout, stderr) = call(plain);
    assert!(ok, "{stderr}");
    let json = std::fs::read_to_string(&report).unwrap();
    assert!(json.contains("\"faces\": 0,"), "{json}");
    assert!(json.contains("\"occupancy_agreement\": 1.0"), "{json}");
    // ... and the printed report says why it may be empty, and what to do.
    assert!(
        stdout.contains("the output is empty") && stdout.contains("--thicken EPS"),
        "{stdout}"
    );
    let mut with_report = args(&["--thicken", "0.08", "--report"]);
    with_report.push(report.clone());
    let (ok, stdout, stderr) = call(with_report);
    assert!(ok, "{stderr}");
    assert!(stdout.contains("closed: yes"), "{stdout}");
    assert!(stdout.contains("thickened open sheets"), "{stdout}");
    let json = std::fs::read_to_string(&report).unwrap();
    for member in [
        "\"thicken\": 0.08",
        "\"closed\": true",
        "\"self_intersections\": 0",
    ] {
        assert!(json.contains(member), "{member} not in {json}");
    }
    // Thickened sheets bound nothing of the input's solid: no distance to its boundary.
    assert!(!json.contains("hausdorff_boundary"), "{json}");
    // Below one finest cell (1/24) the slab could fall between lattice points: refused.
    for (eps, needle) in [
        ("0.01", "below one finest cell"),
        ("nan", "below one finest cell"),
    ] {
        let (ok, _, stderr) = call(args(&["--thicken", eps]));
        assert!(!ok);
        assert_eq!(stderr.trim_end().lines().count(), 1, "{stderr}");
        assert!(
            stderr.contains(needle) && stderr.contains("sheet.obj"),
            "{stderr}"
        );
    }
    std::fs::remove_dir_all(&dir).unwrap();
}

/// A closed tetrahedron with its faces turned inward has `w = -1` inside: `{w > ½}` is empty,
/// and so is the output, with a line that says the input winds inward and that the parity
/// method remeshes the solid it encloses (which it then does).
#[test]
fn remesh_of_an_inward_input_is_empty_and_says_why() {
    let dir = std::env::temp_dir().join(format!("gwn-cli-remesh-inward-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let input = dir.join("inward.obj");
    std::fs::write(
        &input,
        "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\nf 1 2 3\nf 1 4 2\nf 2 4 3\nf 1 3 4\n",
    )
    .unwrap();
    let (input, out) = (
        input.to_str().unwrap().to_owned(),
        dir.join("o.obj").to_str().unwrap().to_owned(),
    );
    let run_with = |method: &str, extra: &[&str]| {
        let mut args = vec![
            "remesh",
            &input,
            "--res",
            "16",
            "--out",
            &out,
            "--samples",
            "200",
            "--method",
            method,
        ];
        args.extend_from_slice(extra);
        let (ok, stdout, stderr) = gwn(&args);
        assert!(ok, "{stderr}");
        stdout
    };
    let run = |method: &str| run_with(method, &[]);
    // Remeshed all the same: the lattice finds w > 1/2 nowhere, and the reason is still told.
    let always = run_with("exact", &["--always-remesh"]);
    assert!(
        always.contains("the output is empty: w > 1/2 at no point of the lattice")
            && always.contains("winds inward"),
        "{always}"
    );
    let exact = run("exact");
    assert!(exact.contains("0 faces, 0 vertices"), "{exact}");
    assert!(
        exact.contains("the output is empty") && exact.contains("winds inward"),
        "{exact}"
    );
    // Proved (closed, embedded, w <= 0 on both sides): no lattice.
    assert!(
        exact.contains("no lattice needed") && !exact.contains("points classified"),
        "{exact}"
    );
    let parity = run("parity");
    assert!(parity.contains("closed: yes"), "{parity}");
    assert!(!parity.contains("0 faces, 0 vertices"), "{parity}");
    assert!(!parity.contains("the output is empty"), "{parity}");
    std::fs::remove_dir_all(&dir).unwrap();
}

/// Trimmed B-rep STEP models (the paper's dataset in `../shared/parametric/step`) remesh like
/// meshes: closed, manifold, oriented, genus 0, no exact self-intersection, agreeing with the
/// model's own `w > ½` at the seeded samples, with vertices placed at the model's surface
/// hits, and within a cell of the model (its trimmed tessellation at half-cell segments).
#[test]
fn remesh_reads_step_models() {
    let Some(dir) = crate::common::shared_file("parametric/step") else {
        return;
    };
    for (model, min_agreement) in [("tet.step", 0.995), ("sliced_cylinder.step", 0.98)] {
        let json = remesh_report(
            &dir.join(model),
            "16",
            "2000",
            &["\"euler_characteristic\": 2"],
        );
        let agreement = report_number(&json, "occupancy_agreement");
        assert!(agreement >= min_agreement, "{model}: agreement {agreement}");
        // Measured to the trimmed tessellation (0.69 and 0.60 cells when written).
        let distance = report_number(&json, "hausdorff_boundary_cells");
        assert!(distance <= 1.0, "{model}: {distance} cells");
        assert_eq!(
            report_number(&json, "hausdorff_reference_segment_cells"),
            0.5
        );
        // Placed at the model's own surface hits: about two evaluations per vertex (eight for
        // the field search).
        let guided = report_number(&json, "guided_vertices");
        let evaluations = report_number(&json, "placement_evaluations");
        assert!(
            guided > 0.0 && evaluations < 3.0 * guided,
            "{model}: {guided} guided vertices, {evaluations} evaluations"
        );
    }
}

/// A Bézier patch set (the Utah teapot of the shared data) through the CLI: closed, manifold,
/// oriented, one component, its vertices placed at the patches' own segment hits (about two
/// evaluations per vertex), and a Hausdorff distance in the report, measured to a
/// tessellation of the patches: within a cell where the teapot bounds the solid at res 32.
#[test]
fn remesh_reads_patch_sets_and_reports_their_distance() {
    let Some(teapot) = crate::common::shared_file("parametric/teapot.bpt") else {
        return;
    };
    let json = remesh_report(&teapot, "32", "4000", &[]);
    let guided = report_number(&json, "guided_vertices");
    let evaluations = report_number(&json, "placement_evaluations");
    assert!(
        guided > 0.0 && evaluations < 3.0 * guided,
        "{guided} guided vertices, {evaluations} evaluations"
    );
    let distance = report_number(&json, "hausdorff_boundary_cells");
    assert!(distance <= 1.0, "{distance} cells");
    assert!(report_number(&json, "hausdorff_cells") >= distance);
}

/// A printer part thinner than a cube cell of `extent / res` (`prusa-helper_disk.stl` of the
/// shared corpus: a disk 15 mm across and 0.2 mm thick, cubes of 0.47 mm at res 32) was empty;
/// with cells sized for the thin axis it is a closed, manifold disk that agrees with the input.
#[test]
fn remesh_keeps_a_printer_plate_thinner_than_a_cube_cell() {
    let Some(input) = crate::common::shared_file("meshes/prusa-helper_disk.stl") else {
        return;
    };
    let json = remesh_report(&input, "32", "20000", &[]);
    assert!(report_number(&json, "faces") > 0.0, "{json}");
    let agreement = report_number(&json, "occupancy_agreement");
    assert!(agreement >= 0.99, "agreement {agreement}");
}

/// Closed inputs whose parts pass through each other are cut along their intersections, not
/// remeshed (the shared corpus: `cgal-bull.off`, 3 pairs of faces folded through each other at a
/// shared vertex; `cgal-camel.off`, 20 pairs, two of whose patches are pieces of cut faces
/// only). The output is the input's solid exactly (every sample agrees), and its faces the
/// input's but for the cut ones.
#[test]
fn remesh_cuts_closed_inputs_along_their_self_intersections() {
    for (name, pairs, faces) in [
        ("cgal-bull.off", 3.0, 12396.0),
        ("cgal-camel.off", 20.0, 19536.0),
    ] {
        let Some(input) = crate::common::shared_file(&format!("meshes/{name}")) else {
            return;
        };
        let json = remesh_report(&input, "256", "20000", &["\"input\": \"cut\""]);
        assert_eq!(
            report_number(&json, "input_intersecting_pairs"),
            pairs,
            "{json}"
        );
        assert_eq!(report_number(&json, "occupancy_agreement"), 1.0, "{json}");
        let kept = report_number(&json, "input_kept_faces");
        assert!(kept > faces - 100.0 && kept < faces, "{json}");
    }
}

/// Solids touching at a vertex or along an edge are pulled apart and kept (the shared corpus:
/// `cgal-kingroon_kp3.stl`, a bed whose parts share 18 edges; `cgal-cow.off`, a leg touching
/// the body at one vertex and self-intersecting elsewhere, pulled apart then cut; `cgal-man.off`,
/// whose cut leaves four pinched vertices, cut then pulled apart; `npm-dragon_vrip_res4.ply`, a
/// scan whose faces are written up to five times, whose pinches need the pull into the wedges
/// and one edge pinched flat split at its midpoint). Every sample agrees with the input's solid.
#[test]
fn remesh_pulls_apart_solids_that_touch() {
    for (name, input_kind, components, edges, vertices, midpoints) in [
        ("cura-kingroon_kp3.stl", "kept", 2, 18.0, 18.0, None),
        ("cgal-cow.off", "cut", 1, 0.0, 1.0, None),
        ("cgal-man.off", "cut", 2, 0.0, 4.0, None),
        ("npm-dragon_vrip_res4.ply", "cut", 7, 29.0, 35.0, Some(1.0)),
    ] {
        let Some(input) = crate::common::shared_file(&format!("meshes/{name}")) else {
            return;
        };
        let kind = format!("\"input\": \"{input_kind}\"");
        let json = remesh_report_of(&input, "256", "20000", components, &[&kind]);
        assert_eq!(
            report_number(&json, "input_separated_edges"),
            edges,
            "{json}"
        );
        assert_eq!(
            report_number(&json, "input_separated_vertices"),
            vertices,
            "{json}"
        );
        assert_eq!(
            report_number(&json, "input_separated_midpoints"),
            midpoints.unwrap_or(0.0),
            "{json}"
        );
        assert_eq!(report_number(&json, "occupancy_agreement"), 1.0, "{json}");
        let cell = report_number(&json, "cell_size");
        assert!(
            report_number(&json, "input_largest_move") <= cell / 32.0,
            "{json}"
        );
    }
}

/// Printer beds whose parts stand on their plates (faces overlapping in one plane) are kept
/// with those faces replaced by their sum, agreeing with the input's solid at every sample.
#[test]
fn remesh_keeps_parts_standing_on_plates() {
    for (name, input_kind, components, planes) in [
        ("prusa-A350_bed.stl", "kept", 1, 2.0),
        ("cura-ultimaker2_platform.obj", "kept", 2, 4.0),
        ("openscad-bad-stl-pcbvicebar.stl", "kept", 1, 1.0),
        ("cura-voron0_120_bed.stl", "cut", 10, 15.0),
    ] {
        let Some(input) = crate::common::shared_file(&format!("meshes/{name}")) else {
            return;
        };
        let kind = format!("\"input\": \"{input_kind}\"");
        let json = remesh_report_of(&input, "256", "20000", components, &[&kind]);
        assert_eq!(
            report_number(&json, "input_coplanar_planes"),
            planes,
            "{json}"
        );
        assert!(report_number(&json, "input_coplanar_faces") > 0.0, "{json}");
        assert_eq!(report_number(&json, "occupancy_agreement"), 1.0, "{json}");
    }
}

/// Parts pushed into each other whose faces meet in the degenerate ways the cut takes: edges
/// crossing edges exactly (pyvista-ant's mirror-symmetric legs) and corners exactly inside
/// faces (cura-ultimaker3_platform, after its faces overlapping in a plane are replaced).
#[test]
fn remesh_cuts_parts_meeting_at_edges_and_corners() {
    for (name, components) in [("pyvista-ant.ply", 9), ("cura-ultimaker3_platform.obj", 9)] {
        let Some(input) = crate::common::shared_file(&format!("meshes/{name}")) else {
            return;
        };
        let json = remesh_report_of(&input, "256", "20000", components, &["\"input\": \"cut\""]);
        assert!(report_number(&json, "input_new_vertices") > 0.0, "{json}");
        assert_eq!(report_number(&json, "occupancy_agreement"), 1.0, "{json}");
    }
}

/// Runs `gwn remesh INPUT --res RES --samples SAMPLES` and returns its JSON report, after
/// checking that the run succeeded and that the report says closed, manifold, oriented, one
/// component, no self-intersection, and every member of `also`.
fn remesh_report(input: &std::path::Path, res: &str, samples: &str, also: &[&str]) -> String {
    remesh_report_of(input, res, samples, 1, also)
}

/// [`remesh_report`] with this many components.
fn remesh_report_of(
    input: &std::path::Path,
    res: &str,
    samples: &str,
    components: usize,
    also: &[&str],
) -> String {
    let name = input.file_name().unwrap().to_string_lossy().into_owned();
    let dir = std::env::temp_dir().join(format!("gwn-cli-remesh-{name}-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let (out, report) = (dir.join("o.ply"), dir.join("r.json"));
    let (ok, stdout, stderr) = gwn(&[
        "remesh",
        input.to_str().unwrap(),
        "--res",
        res,
        "--samples",
        samples,
        "--out",
        out.to_str().unwrap(),
        "--report",
        report.to_str().unwrap(),
    ]);
    assert!(ok, "{name}: {stderr}");
    assert!(stdout.contains("closed: yes"), "{name}: {stdout}");
    let json = std::fs::read_to_string(&report).unwrap();
    std::fs::remove_dir_all(&dir).unwrap();
    // The comma keeps 1 from matching 10.
    let components = format!("\"components\": {components},");
    for member in [
        "\"closed\": true",
        "\"edge_manifold\": true",
        "\"vertex_manifold\": true",
        "\"oriented\": true",
        components.as_str(),
        "\"self_intersections\": 0",
    ]
    .into_iter()
    .chain(also.iter().copied())
    {
        assert!(json.contains(member), "{name}: {member} not in {json}");
    }
    json
}

/// The number after `"key": ` in a JSON report.
fn report_number(json: &str, key: &str) -> f64 {
    json.split(&format!("\"{key}\": "))
        .nth(1)
        .and_then(|s| s.split([',', '\n', '}']).next())
        .and_then(|s| s.trim().parse().ok())
        .unwrap_or_else(|| panic!("no {key} in {json}"))
}

/// A 1.5-thick plate on a 40-high pedestal at res 32 (cubes of 3.125, the plate between two
/// lattice planes): the report says the cells got 4 times finer along z and the plate is kept
/// (agreement); `--no-plate-refinement` keeps the cubes and loses the plate.
#[test]
fn remesh_reports_the_plate_refinement_and_can_turn_it_off() {
    let dir = std::env::temp_dir().join(format!("gwn-cli-remesh-plate-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let input = dir.join("pedestal_plate.obj");
    let cube = gwn::testing::unit_cube(false);
    let block = |lo: [f64; 3], hi: [f64; 3]| {
        let positions = cube
            .positions()
            .iter()
            .map(|p| std::array::from_fn(|a| lo[a] + p[a] * (hi[a] - lo[a])))
            .collect();
        gwn::Mesh::new(positions, cube.triangles().to_vec()).unwrap()
    };
    // The lattice of the box [0, 100]² × [0, 40] at res 32 has planes at z = 24.6875, 27.8125.
    let mesh = block([40.0, 40.0, 0.0], [60.0, 60.0, 40.0])
        .concatenated(&block([0.0, 0.0, 25.8], [100.0, 100.0, 27.3]))
        .unwrap();
    write_obj_file(&input, &mesh);
    let run = |extra: &[&str]| {
        let (out, report) = (dir.join("o.ply"), dir.join("r.json"));
        let mut args = vec![
            "remesh",
            input.to_str().unwrap(),
            "--res",
            "32",
            "--samples",
            "20000",
            "--out",
            out.to_str().unwrap(),
            "--report",
            report.to_str().unwrap(),
            "--always-remesh",
        ];
        args.extend_from_slice(extra);
        let (ok, stdout, stderr) = gwn(&args);
        assert!(ok, "{stderr}");
        assert!(stdout.contains("closed: yes"), "{stdout}");
        (stdout, std::fs::read_to_string(&report).unwrap())
    };
    let (stdout, json) = run(&[]);
    assert!(
        stdout.contains(
            "cells made finer for plates of the input thinner than a cell: 4.00x along z"
        ),
        "{stdout}"
    );
    assert!(
        json.contains("\"plate_refinement\": [1.0, 1.0, 4.0]"),
        "{json}"
    );
    assert!(
        json.contains("\"cell_sizes\": [3.125, 3.125, 0.78125]"),
        "{json}"
    );
    assert!(json.contains("\"cell_size\": 3.125"), "{json}");
    let thickness = json
        .split("\"plate_thickness\": [null, null, ")
        .nth(1)
        .unwrap();
    let thickness: f64 = thickness.split(']').next().unwrap().parse().unwrap();
    assert!((thickness - 1.5).abs() < 1e-9, "{json}");
    assert!(
        report_number(&json, "occupancy_agreement") > 0.999,
        "{json}"
    );
    // Without sub-cell levels too: one level finds most of the plate on its own (99.6 %).
    let (stdout, json) = run(&["--no-plate-refinement", "--sub-cell-levels", "0"]);
    assert!(!stdout.contains("cells made finer"), "{stdout}");
    assert!(
        json.contains("\"plate_refinement\": [1.0, 1.0, 1.0]"),
        "{json}"
    );
    // The plate is 3.6 % of the box; most of it is lost.
    assert!(report_number(&json, "occupancy_agreement") < 0.98, "{json}");
    std::fs::remove_dir_all(&dir).unwrap();
}

/// A closed cube with half its faces flipped: the exact method's `w` is fractional inside, and
/// the remesh says so and names `--method parity`, whose output is the cube with those faces
/// turned back (or, with `--always-remesh`, its lattice remesh: one component within a cell of
/// the input, which it bounds everywhere); an open box is refused by parity.
#[test]
fn remesh_points_closed_unoriented_inputs_to_the_parity_method() {
    let dir = std::env::temp_dir().join(format!("gwn-cli-parity-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let cube = gwn::testing::unit_cube(false);
    let flipped: Vec<[u32; 3]> = cube
        .triangles()
        .iter()
        .enumerate()
        .map(|(f, &[a, b, c])| if f % 2 == 1 { [a, c, b] } else { [a, b, c] })
        .collect();
    let flipped = gwn::Mesh::new(cube.positions().to_vec(), flipped).unwrap();
    let input = dir.join("flipped.obj");
    write_obj_file(&input, &flipped);
    let out = dir.join("out.ply");
    let run = |also: &[&str]| {
        let mut args = vec![
            "remesh",
            input.to_str().unwrap(),
            "--res",
            "16",
            "--samples",
            "2000",
            "--out",
            out.to_str().unwrap(),
        ];
        args.extend_from_slice(also);
        gwn(&args)
    };
    let (ok, stdout, stderr) = run(&[]);
    assert!(ok, "{stderr}");
    assert!(
        stdout.contains("the input is closed but not consistently oriented")
            && stdout.contains("--method parity keeps it with 6 of its faces turned"),
        "{stdout}"
    );
    // Kept with its six flipped faces turned back (no lattice), or remeshed on request.
    let report = dir.join("report.json");
    let (ok, stdout, stderr) = run(&["--method", "parity", "--report", report.to_str().unwrap()]);
    assert!(ok, "{stderr}");
    assert!(!stdout.contains("not consistently oriented"), "{stdout}");
    assert!(
        stdout.contains("the input with 6 of its faces turned (12 faces")
            && stdout.contains("the boundary of the parity method's solid")
            && !stdout.contains("points classified"),
        "{stdout}"
    );
    let json = std::fs::read_to_string(&report).unwrap();
    assert!(
        json.contains("\"input\": \"reoriented\"") && json.contains("\"input_turned_faces\": 6"),
        "{json}"
    );
    for also in [
        &["--method", "parity"][..],
        &["--method", "parity", "--always-remesh"],
    ] {
        let (ok, stdout, stderr) = run(also);
        assert!(ok, "{stderr}");
        assert!(
            stdout.contains("Euler characteristic 2; 1 component(s)")
                && stdout.contains("w > 1/2 on one side only: 100.0 % of its samples"),
            "{also:?}: {stdout}"
        );
        assert_eq!(
            stdout.contains("points classified"),
            also.len() == 3,
            "{stdout}"
        );
    }
    let open = dir.join("open.obj");
    write_obj_file(&open, &gwn::testing::unit_cube(true));
    let (ok, _, stderr) = gwn(&[
        "remesh",
        open.to_str().unwrap(),
        "--method",
        "parity",
        "--out",
        out.to_str().unwrap(),
    ]);
    assert!(!ok);
    assert!(
        stderr.contains("the parity method needs a closed mesh, but 4 edges have an odd number")
            && stderr.trim().lines().count() == 1,
        "{stderr}"
    );
    std::fs::remove_dir_all(&dir).ok();
}
