//! `gwn remesh-dataset` and `products::remesh::dataset::RemeshJob`: one closed surface per mesh,
//! the same bytes `gwn remesh` writes, a manifest, resuming, failures as rows.

use std::path::{Path, PathBuf};

use gwn::products::dataset::{DatasetError, Status, run_dataset};
use gwn::products::remesh::dataset::RemeshJob;

use crate::cli::gwn;
use crate::common::fixture;

/// A fresh scratch directory for one test, removed by `Drop`.
struct Scratch(PathBuf);

impl Scratch {
    fn new(name: &str) -> Scratch {
        let d =
            std::env::temp_dir().join(format!("gwn-remesh-dataset-{}-{name}", std::process::id()));
        let _ = std::fs::remove_dir_all(&d);
        std::fs::create_dir_all(&d).unwrap();
        Scratch(d)
    }
}

impl Drop for Scratch {
    fn drop(&mut self) {
        let _ = std::fs::remove_dir_all(&self.0);
    }
}

/// The inputs below `dir/in`: the cube, two cubes (glb), a sub-folder with a lone open triangle
/// (no solid: an empty surface) and a file with a NaN coordinate.
fn inputs(dir: &Path) -> Vec<PathBuf> {
    let input = dir.join("in");
    std::fs::create_dir_all(input.join("sub")).unwrap();
    for name in ["cube.off", "two_cubes.glb", "broken_nan.off"] {
        std::fs::copy(fixture(name), input.join(name)).unwrap();
    }
    std::fs::write(
        input.join("sub/triangle.obj"),
        "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n",
    )
    .unwrap();
    [
        "cube.off",
        "two_cubes.glb",
        "sub/triangle.obj",
        "broken_nan.off",
    ]
    .iter()
    .map(|n| input.join(n))
    .collect()
}

/// The PLY bytes `gwn remesh INPUT --res RES --samples 0` writes (to a file in `scratch`).
fn remeshed_by_the_cli(input: &Path, res: usize, scratch: &Path, extra: &[&str]) -> Vec<u8> {
    let single = scratch.join("single.ply");
    let res = res.to_string();
    let mut args = vec![
        "remesh",
        input.to_str().unwrap(),
        "--res",
        &res,
        "--samples",
        "0",
        "--out",
        single.to_str().unwrap(),
    ];
    args.extend_from_slice(extra);
    let (ok, _, err) = gwn(&args);
    assert!(ok, "{err}");
    std::fs::read(&single).unwrap()
}

#[test]
fn remesh_dataset_writes_what_gwn_remesh_writes_and_resumes() {
    let scratch = Scratch::new("library");
    let dir = &scratch.0;
    let meshes = inputs(dir);
    let out = dir.join("out");
    // The remesher's own path (the clean cubes would be kept as they are: below).
    let job = RemeshJob {
        samples: 2000,
        keep_input: false,
        ..RemeshJob::new(32)
    };
    let rows = run_dataset(&job, &meshes, &out, None, |_| {}).unwrap();
    let status: Vec<Status> = rows.iter().map(|r| r.status).collect();
    assert_eq!(
        status,
        [Status::Ok, Status::Ok, Status::Ok, Status::Failed],
        "{rows:?}"
    );
    let stat = |i: usize, name: &str| rows[i].stats.get(name).unwrap().to_string();
    // The cube: one closed component; two cubes: two; the lone triangle bounds nothing.
    assert_eq!(stat(0, "faces"), "12");
    assert_eq!(stat(0, "valid"), "true");
    assert_eq!(stat(0, "components"), "1");
    assert_eq!(stat(0, "self_intersections"), "0");
    assert!(stat(0, "hausdorff_cells").parse::<f64>().unwrap() < 1.0);
    assert!(stat(0, "occupancy_agreement").parse::<f64>().unwrap() > 0.99);
    assert_eq!(stat(1, "components"), "2");
    assert_eq!(stat(2, "output_faces"), "0");
    assert_eq!(stat(2, "valid"), "true");
    // How each output was made, and why an empty one is empty (nothing kept: remeshed).
    assert_eq!(stat(0, "outcome"), "\"remeshed\"");
    assert_eq!(stat(0, "empty"), "null");
    assert_eq!(stat(2, "empty"), "\"no volume\"");
    // A failure keeps nothing it did not learn, and says why in one line.
    assert_eq!(stat(3, "faces"), "null");
    let error = rows[3].error.as_deref().unwrap();
    assert!(
        error.contains("broken_nan.off") && error.contains("NaN"),
        "{error}"
    );
    // The outputs mirror the inputs, and are the bytes `gwn remesh` writes at the same options
    // (the job's defaults are the CLI's).
    assert_eq!(
        std::fs::read(out.join("cube.off.ply")).unwrap(),
        remeshed_by_the_cli(&fixture("cube.off"), 32, dir, &["--always-remesh"])
    );
    assert!(out.join("sub/triangle.obj.ply").is_file());
    assert!(!out.join("broken_nan.off.ply").exists());
    let manifest = std::fs::read_to_string(out.join("manifest.jsonl")).unwrap();
    assert_eq!(manifest.lines().count(), 4);
    assert!(manifest.lines().next().unwrap().contains("\"valid\":true"));

    // Again: done, with the statistics of the run that made each file.
    let again = run_dataset(&job, &meshes, &out, None, |_| {}).unwrap();
    for (a, b) in rows.iter().zip(&again) {
        if a.status == Status::Ok {
            assert_eq!(b.status, Status::Done, "{b:?}");
            assert_eq!(a.stats, b.stats);
        } else {
            assert_eq!(b.status, Status::Failed);
        }
    }
    // Another resolution redoes them, and says so.
    let coarser = RemeshJob {
        samples: 2000,
        keep_input: false,
        ..RemeshJob::new(24)
    };
    let redone = run_dataset(&coarser, &meshes[..1], &out, None, |_| {}).unwrap();
    assert_eq!(redone[0].status, Status::Ok);
    assert_eq!(
        redone[0].redone.as_deref(),
        Some("options changed: res 32 -> 24")
    );
    assert_ne!(
        std::fs::read(out.join("cube.off.ply")).unwrap(),
        remeshed_by_the_cli(&fixture("cube.off"), 32, dir, &["--always-remesh"])
    );
    // Keeping clean inputs is an option of the job: the cubes are written as they are (the
    // bytes of `gwn remesh` without --always-remesh), the lone triangle is still remeshed.
    let keeping = RemeshJob {
        samples: 2000,
        ..RemeshJob::new(24)
    };
    let kept = run_dataset(&keeping, &meshes, &out, None, |_| {}).unwrap();
    assert_eq!(
        kept[0].redone.as_deref(),
        Some("options changed: keep_input false -> true")
    );
    let kept_stat = |i: usize| kept[i].stats.get("kept").unwrap().to_string();
    assert_eq!(
        [kept_stat(0), kept_stat(1), kept_stat(2)],
        ["true", "true", "false"]
    );
    assert_eq!(kept[0].stats.get("output_faces").unwrap().to_string(), "12");
    let kept_faces = |i: usize| kept[i].stats.get("kept_faces").unwrap().to_string();
    assert_eq!([kept_faces(0), kept_faces(2)], ["12", "0"]);
    let outcome = |i: usize| kept[i].stats.get("outcome").unwrap().to_string();
    // The lone triangle: a sheet in one plane, proved to bound nothing.
    assert_eq!([outcome(0), outcome(2)], ["\"kept\"", "\"planar\""]);
    assert_eq!(kept[2].stats.get("empty"), Some("\"no volume\""));
    // An inward tetrahedron: proved to bound nothing, and the row says it winds inward.
    let inward = dir.join("in/inward.obj");
    std::fs::write(
        &inward,
        "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\nf 1 2 3\nf 1 4 2\nf 2 4 3\nf 1 3 4\n",
    )
    .unwrap();
    let rows = run_dataset(&keeping, &[inward], &dir.join("inward"), None, |_| {}).unwrap();
    let stat = |name: &str| rows[0].stats.get(name).unwrap().to_string();
    assert_eq!(
        [stat("outcome"), stat("empty"), stat("output_faces")],
        ["\"bounds nothing\"", "\"winds inward\"", "0"]
    );
    assert_eq!(
        std::fs::read(out.join("cube.off.ply")).unwrap(),
        remeshed_by_the_cli(&fixture("cube.off"), 24, dir, &[])
    );

    // One file twice: refused before anything is written.
    let twice = [meshes[0].clone(), meshes[0].clone()];
    let fresh = dir.join("twice");
    let err = run_dataset(&job, &twice, &fresh, None, |_| {}).unwrap_err();
    assert!(matches!(err, DatasetError::Collision { .. }), "{err}");
    assert!(!fresh.exists());
    // Thickened: the lone triangle becomes a closed slab (it bounded nothing before).
    let thick = RemeshJob {
        samples: 2000,
        thicken_cells: Some(2.0),
        ..RemeshJob::new(32)
    };
    let slab = run_dataset(&thick, &meshes[2..3], &dir.join("thick"), None, |_| {}).unwrap();
    assert_eq!(slab[0].status, Status::Ok, "{slab:?}");
    assert_eq!(slab[0].stats.get("valid"), Some("true"));
    assert_eq!(slab[0].stats.get("components"), Some("1"));
    assert!(slab[0].stats.count("output_faces").unwrap() > 0);
    // Unusable options: refused up front.
    let bad = RemeshJob {
        thicken_cells: Some(0.5),
        ..RemeshJob::new(32)
    };
    let err = run_dataset(&bad, &meshes, &fresh, None, |_| {}).unwrap_err();
    assert!(
        err.to_string().contains("at least one finest cell"),
        "{err}"
    );
}

#[test]
fn remesh_dataset_cli() {
    let scratch = Scratch::new("cli");
    let dir = &scratch.0;
    inputs(dir);
    let out = dir.join("out");
    let args = |extra: &[&str]| -> Vec<String> {
        let mut a: Vec<String> = [
            "remesh-dataset",
            dir.join("in").to_str().unwrap(),
            "--out",
            out.to_str().unwrap(),
            "--res",
            "24",
            "--samples",
            "0",
        ]
        .iter()
        .map(|s| s.to_string())
        .collect();
        a.extend(extra.iter().map(|s| s.to_string()));
        a
    };
    let run = |extra: &[&str]| {
        let a = args(extra);
        gwn(&a.iter().map(String::as_str).collect::<Vec<_>>())
    };
    // A failed mesh is a row and a stderr line; the job itself succeeds.
    let (ok, stdout, stderr) = run(&["--format", "obj"]);
    assert!(ok, "{stderr}");
    assert!(
        stdout.contains("remeshed 3 inputs (0 done before, 0 redone, 1 failed, 0 timed out)"),
        "{stdout}"
    );
    assert!(stdout.contains("3 outputs valid"), "{stdout}");
    // The lone triangle bounds nothing: counted.
    assert!(
        stdout.contains("1 outputs empty (0 wound inward, 1 without volume"),
        "{stdout}"
    );
    assert!(
        stderr.contains("gwn remesh-dataset: failed") && stderr.contains("broken_nan.off"),
        "{stderr}"
    );
    let cube = gwn::io::load_mesh(out.join("cube.off.obj")).unwrap().mesh;
    assert!(!cube.triangles().is_empty());
    // The same run again: nothing to do; a knob changed: redone, and named.
    let (ok, stdout, _) = run(&["--format", "obj"]);
    assert!(
        ok && stdout.contains("remeshed 0 inputs (3 done before"),
        "{stdout}"
    );
    let (ok, _, stderr) = run(&["--format", "obj", "--no-relocate"]);
    assert!(ok);
    assert!(
        stderr.contains("options changed: simplify_relocate true -> false"),
        "{stderr}"
    );
    // Bad options: one line, non-zero.
    let (ok, _, stderr) = run(&["--format", "step"]);
    assert!(!ok);
    assert_eq!(
        stderr.trim(),
        "gwn: --format step: expected obj, ply, stl or glb"
    );
    // A time limit no mesh can meet: timeout rows, the job still succeeds.
    let (ok, stdout, _) = run(&["--time-limit", "0.000001", "--format", "stl"]);
    assert!(ok);
    assert!(stdout.contains("1 failed, 3 timed out"), "{stdout}");
    // `gwn remesh --time-limit`: one line naming the mesh and the phase, exit 1, no output.
    let single = dir.join("single.ply");
    let cube = fixture("cube.off");
    let (ok, _, stderr) = gwn(&[
        "remesh",
        cube.to_str().unwrap(),
        "--res",
        "64",
        "--time-limit",
        "0.000001",
        "--out",
        single.to_str().unwrap(),
    ]);
    assert!(!ok);
    assert_eq!(stderr.trim().lines().count(), 1, "{stderr}");
    assert!(
        stderr.contains("cube.off: the time limit ran out while "),
        "{stderr}"
    );
    assert!(!single.exists());
    let (ok, _, stderr) = run(&["--thicken-cells", "0"]);
    assert!(!ok);
    assert_eq!(stderr.trim().lines().count(), 1, "{stderr}");
    assert!(stderr.contains("at least one finest cell"), "{stderr}");
}

#[test]
fn remesh_stops_at_its_deadline_without_an_output() {
    use gwn::products::remesh::{RemeshError, RemeshOptions, RemeshPhase, remesh_guided};
    let mesh = gwn::io::load_mesh(crate::common::repo().join("data/lion-head.off"))
        .unwrap()
        .mesh;
    let wn = gwn::eval::antipodal::WindingNumber::new(&mesh).unwrap();
    let guide = gwn::products::remesh::crossings::SegmentBvh::of_field_mesh(&mesh);
    let bounds = mesh.bounding_box().unwrap();
    let options = RemeshOptions::with_resolution(64);
    let run = |options: &RemeshOptions| remesh_guided(&wn, Some(&guide), bounds, options, &|_| {});
    let start = std::time::Instant::now();
    let full = run(&options).unwrap();
    let took = start.elapsed();
    // Past already: stopped before classifying.
    let past = RemeshOptions {
        deadline: Some(std::time::Instant::now()),
        ..options
    };
    assert_eq!(
        run(&past).unwrap_err(),
        RemeshError::TimeLimit {
            phase: RemeshPhase::Classify
        }
    );
    // A third of the time a run takes: stopped in some later phase, with no surface.
    let early = RemeshOptions {
        deadline: Some(std::time::Instant::now() + took / 3),
        ..options
    };
    assert!(
        matches!(run(&early), Err(RemeshError::TimeLimit { .. })),
        "a third of {took:?}"
    );
    // A deadline far ahead changes nothing.
    let later = RemeshOptions {
        deadline: Some(std::time::Instant::now() + std::time::Duration::from_secs(3600)),
        ..options
    };
    let again = run(&later).unwrap();
    assert_eq!(again.triangles, full.triangles);
    assert_eq!(again.positions, full.positions);
    // Extraction looks at the clock between its batches of cubes (seconds of serial work on a
    // large band), and a deadline it does not reach changes nothing.
    {
        use gwn::products::remesh::{extract::extract, lattice::Lattice, octree::classify};
        let lattice = Lattice::new(bounds, 64).unwrap();
        let before = std::time::Instant::now();
        let classified = classify(&wn, &lattice, Some(&guide), usize::MAX, None).unwrap();
        assert!(extract(&lattice, &classified, Some(before)).is_none());
        let now = std::time::Instant::now();
        let far = now + std::time::Duration::from_secs(3600);
        let (a, b) = (
            extract(&lattice, &classified, Some(far)).unwrap(),
            extract(&lattice, &classified, None).unwrap(),
        );
        assert!(!a.triangles.is_empty());
        // Placement too: nothing past the deadline, the same vertices before it.
        use gwn::products::remesh::place::{CrossingSource, place_vertices};
        let corner_w = classified.edge_values(&a.edges);
        let place = |deadline| {
            let source = CrossingSource::Triangles(&guide);
            place_vertices(&wn, &lattice, &a.edges, &corner_w, 8, source, deadline)
        };
        assert!(place(Some(before)).is_none());
        assert_eq!(place(Some(far)).unwrap().fixed, place(None).unwrap().fixed);
        assert_eq!((a.triangles, a.edges), (b.triangles, b.edges));
    }

    // In a dataset: a `timeout` row that names the limit, and no output.
    let scratch = Scratch::new("deadline");
    let dir = &scratch.0;
    let meshes = inputs(dir);
    let job = RemeshJob {
        time_limit: Some(std::time::Duration::from_micros(1)),
        ..RemeshJob::new(32)
    };
    let rows = run_dataset(&job, &meshes[..2], &dir.join("out"), None, |_| {}).unwrap();
    for row in &rows {
        assert_eq!(row.status, Status::Timeout, "{row:?}");
        let error = row.error.as_deref().unwrap();
        assert!(
            error.starts_with("time limit of 0.000 s exceeded while "),
            "{error}"
        );
        assert!(!dir.join("out").join(&row.output).exists());
    }
}

/// A field whose evaluations are slow (as next to a long signed boundary), and that counts
/// those that begin after a deadline.
struct SlowField {
    deadline: std::time::Instant,
    after: std::sync::atomic::AtomicUsize,
    before: std::sync::atomic::AtomicUsize,
}

impl gwn::eval::Evaluator for SlowField {
    fn eval(&self, q: [f64; 3]) -> f64 {
        use std::sync::atomic::Ordering::Relaxed;
        if std::time::Instant::now() > self.deadline {
            self.after.fetch_add(1, Relaxed);
        } else {
            self.before.fetch_add(1, Relaxed);
        }
        std::thread::sleep(std::time::Duration::from_micros(20));
        // A ball of radius 0.3.
        let r2: f64 = q.iter().map(|c| (c - 0.5) * (c - 0.5)).sum();
        if r2 < 0.09 { 1.0 } else { 0.0 }
    }
}

#[test]
fn remesh_evaluates_little_past_its_deadline() {
    use gwn::products::remesh::{RemeshError, RemeshOptions, remesh_guided};
    // The coarse grid alone is 33³ points, ~0.4 s of this field on two threads: one batch that
    // used to run to its end whatever the deadline.
    let deadline = std::time::Instant::now() + std::time::Duration::from_millis(50);
    let field = SlowField {
        deadline,
        after: Default::default(),
        before: Default::default(),
    };
    let bounds = gwn::BoundingBox {
        min: [0.0; 3],
        max: [1.0; 3],
    };
    let options = RemeshOptions {
        deadline: Some(deadline),
        ..RemeshOptions::with_resolution(128)
    };
    let out = remesh_guided(&field, None, bounds, &options, &|_| {});
    assert!(
        matches!(out, Err(RemeshError::TimeLimit { .. })),
        "{:?}",
        out.map(|r| r.triangles.len())
    );
    let (before, after) = (
        field.before.load(std::sync::atomic::Ordering::Relaxed),
        field.after.load(std::sync::atomic::Ordering::Relaxed),
    );
    // At most the chunk under way when the deadline passed (4096 points) went on.
    assert!(
        after <= 4096,
        "{before} evaluations before the deadline, {after} after"
    );
}

/// An oriented point cloud of the unit sphere (Fibonacci points, outward normals) as ASCII PLY
/// without faces: a point cloud to `gwn::input`.
fn sphere_cloud(path: &Path, n: usize) {
    let mut ply = format!(
        "ply\nformat ascii 1.0\nelement vertex {n}\nproperty float x\nproperty float y\n\
         property float z\nproperty float nx\nproperty float ny\nproperty float nz\nend_header\n"
    );
    let golden = std::f64::consts::PI * (3.0 - 5f64.sqrt());
    for i in 0..n {
        let z = 1.0 - 2.0 * (i as f64 + 0.5) / n as f64;
        let r = (1.0 - z * z).sqrt();
        let (x, y) = (r * (golden * i as f64).cos(), r * (golden * i as f64).sin());
        ply.push_str(&format!("{x} {y} {z} {x} {y} {z}\n"));
    }
    std::fs::write(path, ply).unwrap();
}

/// STEP models, patch sets and oriented point clouds are inputs of the dataset job as of
/// `gwn remesh`: walked from folders by their extensions (`.step`, `.stp`, `.bpt`), set up with
/// their own evaluators, written as the same bytes, the manifest naming each input's kind.
#[test]
fn remesh_dataset_takes_step_models_patch_sets_and_point_clouds() {
    let scratch = Scratch::new("inputs");
    let dir = &scratch.0;
    let input = dir.join("in");
    std::fs::create_dir_all(&input).unwrap();
    for name in [
        "torus_full.step",
        "capped_cylinder.step",
        "plate_with_hole.stp",
    ] {
        std::fs::copy(fixture(&format!("step/{name}")), input.join(name)).unwrap();
    }
    std::fs::copy(fixture("cube.off"), input.join("cube.off")).unwrap();
    sphere_cloud(&input.join("sphere.ply"), 3000);
    // Not an input: a folder walk skips it.
    std::fs::write(input.join("notes.txt"), "not a mesh\n").unwrap();
    let teapot = crate::common::shared_file("parametric/teapot.bpt");
    if let Some(teapot) = &teapot {
        std::fs::copy(teapot, input.join("teapot.bpt")).unwrap();
    }
    let out = dir.join("out");
    let (ok, stdout, err) = gwn(&[
        "remesh-dataset",
        input.to_str().unwrap(),
        "--out",
        out.to_str().unwrap(),
        "--res",
        "24",
        "--samples",
        "2000",
    ]);
    assert!(ok, "{err}");
    let inputs = 5 + usize::from(teapot.is_some());
    assert!(
        stdout.contains(&format!(
            "remeshed {inputs} inputs (0 done before, 0 redone, 0 failed"
        )),
        "{stdout}"
    );
    let manifest = std::fs::read_to_string(out.join("manifest.jsonl")).unwrap();
    let row = |name: &str| -> String {
        manifest
            .lines()
            .find(|l| l.contains(&format!("\"mesh\":\"{}", input.join(name).display())))
            .unwrap_or_else(|| panic!("no row for {name} in {manifest}"))
            .to_string()
    };
    for (name, kind, faces) in [
        ("cube.off", "mesh", "12"),
        ("torus_full.step", "STEP model", "1"),
        ("capped_cylinder.step", "STEP model", "3"),
        ("sphere.ply", "point cloud", "null"),
    ] {
        let r = row(name);
        assert!(r.contains(&format!("\"input\":\"{kind}\"")), "{r}");
        assert!(r.contains(&format!("\"faces\":{faces},")), "{r}");
        assert!(
            r.contains("\"valid\":true") && r.contains("\"components\":1"),
            "{r}"
        );
        assert!(r.contains("\"status\":\"ok\""), "{r}");
    }
    // The cloud's points are its vertices; it has no distance (nothing to measure it to), a
    // curved input's is to its tessellation.
    assert!(row("sphere.ply").contains("\"vertices\":3000,"));
    assert!(row("sphere.ply").contains("\"hausdorff_cells\":null"));
    assert!(!row("torus_full.step").contains("\"hausdorff_cells\":null"));
    assert!(!manifest.contains("notes.txt"));
    // An open plate (`.stp`) bounds nothing: an empty, valid surface.
    let plate = row("plate_with_hole.stp");
    assert!(
        plate.contains("\"input\":\"STEP model\",\"faces\":1,"),
        "{plate}"
    );
    assert!(plate.contains("\"output_faces\":0,") && plate.contains("\"valid\":true"));
    if teapot.is_some() {
        assert!(row("teapot.bpt").contains("\"input\":\"patch set\",\"faces\":32,"));
    } else {
        crate::common::report_skip("../shared/parametric/teapot.bpt (the patch-set row)");
    }
    // The bytes `gwn remesh` writes for each.
    for name in ["torus_full.step", "sphere.ply"] {
        assert_eq!(
            std::fs::read(out.join(format!("{name}.ply"))).unwrap(),
            remeshed_by_the_cli(&input.join(name), 24, dir, &[]),
            "{name}"
        );
    }
    // Thickening needs triangles: a failed row that says so, the mesh remeshed.
    let job = RemeshJob {
        thicken_cells: Some(1.0),
        samples: 0,
        ..RemeshJob::new(16)
    };
    let rows = run_dataset(
        &job,
        &[input.join("torus_full.step"), input.join("cube.off")],
        &dir.join("thick"),
        None,
        |_| {},
    )
    .unwrap();
    assert_eq!(rows[0].status, Status::Failed);
    let error = rows[0].error.as_deref().unwrap();
    assert!(
        error.contains("thicken: needs triangles (a mesh or soup), not a STEP model"),
        "{error}"
    );
    assert_eq!(rows[0].stats.get("input"), Some("\"STEP model\""));
    assert_eq!(rows[1].status, Status::Ok);
}

/// `parity_where_flipped` (`--parity-where-flipped`): a closed mesh with flipped faces is
/// remeshed by parity, kept with its faces turned (the bytes `gwn remesh --method parity`
/// writes), while a clean cube and an open box go the exact method's way; the manifest's
/// `method` says which, and the CLI counts them. Off: the flipped cube's fractional `w` is
/// remeshed.
#[test]
fn parity_where_flipped_remeshes_closed_flipped_meshes_by_their_parity() {
    let scratch = Scratch::new("parity");
    let dir = &scratch.0;
    let input = dir.join("in");
    std::fs::create_dir_all(&input).unwrap();
    let cube = gwn::testing::unit_cube(false);
    let flipped: Vec<[u32; 3]> = (cube.triangles().iter().enumerate())
        .map(|(f, &[a, b, c])| if f % 2 == 1 { [a, c, b] } else { [a, b, c] })
        .collect();
    let flipped = gwn::Mesh::new(cube.positions().to_vec(), flipped).unwrap();
    gwn::mesh::write_obj(
        std::fs::File::create(input.join("flipped.obj")).unwrap(),
        &flipped,
    )
    .unwrap();
    gwn::mesh::write_obj(
        std::fs::File::create(input.join("open.obj")).unwrap(),
        &gwn::testing::unit_cube(true),
    )
    .unwrap();
    std::fs::copy(fixture("cube.off"), input.join("cube.off")).unwrap();
    let meshes: Vec<PathBuf> = ["cube.off", "flipped.obj", "open.obj"]
        .iter()
        .map(|n| input.join(n))
        .collect();
    let out = dir.join("out");
    let job = RemeshJob {
        samples: 0,
        parity_where_flipped: true,
        ..RemeshJob::new(16)
    };
    let rows = run_dataset(&job, &meshes, &out, None, |_| {}).unwrap();
    let stat = |i: usize, name: &str| rows[i].stats.get(name).unwrap().to_string();
    let column = |name: &str| (0..3).map(|i| stat(i, name)).collect::<Vec<_>>();
    assert_eq!(column("method"), ["\"exact\"", "\"parity\"", "\"exact\""]);
    assert_eq!(
        column("outcome"),
        ["\"kept\"", "\"reoriented\"", "\"remeshed\""]
    );
    assert_eq!(column("valid"), ["true", "true", "true"]);
    // Six of the flipped cube's faces turned back, the other six written as they are.
    assert_eq!(stat(1, "kept_faces"), "6");
    assert_eq!(stat(1, "output_faces"), "12");
    assert_eq!(
        std::fs::read(out.join("flipped.obj.ply")).unwrap(),
        remeshed_by_the_cli(&meshes[1], 16, dir, &["--method", "parity"])
    );
    // Off, as before: the exact method remeshes the flipped cube's fractional `w`, and the
    // option's change redoes every output.
    let off = RemeshJob {
        parity_where_flipped: false,
        ..job
    };
    let rows_off = run_dataset(&off, &meshes, &out, None, |_| {}).unwrap();
    assert_eq!(rows_off[1].stats.get("method"), Some("\"exact\""));
    assert_eq!(rows_off[1].stats.get("outcome"), Some("\"remeshed\""));
    assert!(rows_off.iter().all(|r| r.redone.is_some()), "{rows_off:?}");
    // The CLI: the same files, the parity inputs counted.
    let (ok, stdout, stderr) = gwn(&[
        "remesh-dataset",
        input.to_str().unwrap(),
        "--out",
        dir.join("cli").to_str().unwrap(),
        "--res",
        "16",
        "--samples",
        "0",
        "--parity-where-flipped",
    ]);
    assert!(ok, "{stderr}");
    assert!(
        stdout.contains("; 1 by parity (closed, faces flipped"),
        "{stdout}"
    );
    assert_eq!(
        std::fs::read(dir.join("cli/flipped.obj.ply")).unwrap(),
        remeshed_by_the_cli(&meshes[1], 16, dir, &["--method", "parity"])
    );
}
