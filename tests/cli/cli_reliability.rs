//! The command line under misuse (issue 11, sections 2, 3 and 6): full stdout, unwritable
//! outputs, nonsense option values, oversized requests and unusual input files. Every case must
//! end with a one-line `gwn: …` error and a non-zero exit (or, where the input is acceptable,
//! succeed), never with a panic, an abort or a hang.

use std::fs::File;
use std::path::{Path, PathBuf};
use std::process::{Command, Output, Stdio};

const GWN: &str = env!("CARGO_BIN_EXE_gwn");

fn fixture(name: &str) -> PathBuf {
    crate::common::repo().join("tests/fixtures").join(name)
}

/// A scratch directory, removed when dropped.
struct Scratch(PathBuf);

impl std::ops::Deref for Scratch {
    type Target = Path;
    fn deref(&self) -> &Path {
        &self.0
    }
}

impl Drop for Scratch {
    fn drop(&mut self) {
        let _ = std::fs::remove_dir_all(&self.0);
    }
}

/// A fresh scratch directory for one test, with a query file, a tet mesh and a polygon.
fn scratch(test: &str) -> Scratch {
    let dir = std::env::temp_dir().join(format!("gwn-cli-{}-{test}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    std::fs::write(dir.join("q.csv"), "0.5 0.5 0.5\n2 2 2\n").unwrap();
    std::fs::write(
        dir.join("t.node"),
        "4 3 0 0\n1 0.2 0.2 0.2\n2 0.8 0.2 0.2\n3 0.2 0.8 0.2\n4 0.2 0.2 0.8\n",
    )
    .unwrap();
    std::fs::write(dir.join("t.ele"), "1 4 0\n1 1 2 3 4\n").unwrap();
    std::fs::write(dir.join("poly.txt"), "0 0\n1 0\n1 1\n0 1\n").unwrap();
    Scratch(dir)
}

/// Runs `gwn ARGS` in `dir` with stdout sent to `stdout` (captured when `None`).
fn run_in(dir: &Path, args: &[&str], stdout: Option<File>) -> Output {
    let mut cmd = Command::new(GWN);
    cmd.current_dir(dir).args(args).stdin(Stdio::null());
    if let Some(f) = stdout {
        cmd.stdout(f);
    }
    cmd.output().unwrap()
}

/// Asserts a failure with exactly one stderr line `gwn: …` containing every string of `want`.
#[track_caller]
fn assert_one_line_error(out: &Output, want: &[&str]) -> String {
    let err = String::from_utf8_lossy(&out.stderr).into_owned();
    assert!(!out.status.success(), "exit 0; stderr: {err}");
    assert_ne!(out.status.code(), Some(101), "panicked: {err}");
    assert_eq!(err.lines().count(), 1, "not one line: {err}");
    assert!(err.starts_with("gwn: "), "{err}");
    for w in want {
        assert!(err.contains(w), "`{w}` missing from: {err}");
    }
    err
}

/// The subcommands that print to stdout, each with arguments that succeed on a normal stdout.
fn printing_subcommands() -> Vec<Vec<String>> {
    let cube = fixture("cube.obj").display().to_string();
    let s = |v: &[&str]| v.iter().map(|a| a.to_string()).collect::<Vec<_>>();
    vec![
        s(&["eval", &cube, "--points", "q.csv"]),
        s(&["eval", &cube, "--points", "q.csv", "--gradient"]),
        s(&["info", &cube]),
        s(&["voxelize", &cube, "--res", "4", "--out", "v.npy"]),
        s(&["sdf", &cube, "--res", "4", "--out", "s.npy"]),
        s(&["remesh", &cube, "--res", "4", "--out", "r.obj"]),
        s(&["slice", &cube, "--res", "8", "--out", "s.png"]),
        s(&["classify", &cube, &cube, "--out", "c.csv"]),
        s(&["filter-tets", &cube, "t.node", "--out", "k.mesh"]),
        s(&["bench", &cube, "--grid", "2", "--threads-list", "1"]),
        s(&["curve", "field", "poly.txt", "--res", "8", "--out", "f.png"]),
    ]
}

#[test]
fn every_subcommand_fails_cleanly_on_a_full_stdout() {
    let Ok(full) = File::options().write(true).open("/dev/full") else {
        println!("skipping: /dev/full is not available on this system");
        return;
    };
    let dir = scratch("full-stdout");
    for args in printing_subcommands() {
        let args: Vec<&str> = args.iter().map(String::as_str).collect();
        let ok = run_in(&dir, &args, None);
        assert!(ok.status.success(), "{args:?}: {ok:?}");
        assert!(!ok.stdout.is_empty(), "{args:?} prints nothing");
        let out = run_in(&dir, &args, Some(full.try_clone().unwrap()));
        let err = assert_one_line_error(&out, &["stdout: cannot write"]);
        assert!(err.contains("No space left"), "{args:?}: {err}");
    }
    // `gen` prints nothing on stdout: a full stdout loses nothing.
    let args = ["gen", "--kind", "boxes", "--count", "1", "--out", "g"];
    let out = run_in(&dir, &args, Some(full.try_clone().unwrap()));
    assert!(out.status.success(), "{args:?}: {out:?}");
}

#[test]
fn every_output_file_error_names_the_file() {
    let dir = scratch("bad-out");
    let cube = fixture("cube.obj").display().to_string();
    // A path below a regular file cannot be created, even by root.
    let bad = format!("{cube}/x");
    let bad_mesh = format!("{cube}/x.mesh");
    let bad_obj = format!("{cube}/x.obj");
    let cases: Vec<(Vec<&str>, &str)> = vec![
        (
            vec!["eval", &cube, "--points", "q.csv", "--out", &bad],
            &bad,
        ),
        (
            vec![
                "eval",
                &cube,
                "--points",
                "q.csv",
                "--gradient",
                "--gradient-out",
                &bad,
            ],
            &bad,
        ),
        (vec!["voxelize", &cube, "--res", "4", "--out", &bad], &bad),
        (
            vec![
                "voxelize", &cube, "--res", "4", "--out", "v.npy", "--vti", &bad,
            ],
            &bad,
        ),
        (
            vec![
                "voxelize",
                &cube,
                "--res",
                "4",
                "--out",
                "v.npy",
                "--occupancy",
                "0.5",
                "--occupancy-out",
                &bad,
            ],
            &bad,
        ),
        (vec!["sdf", &cube, "--res", "4", "--out", &bad], &bad),
        (
            vec!["remesh", &cube, "--res", "4", "--out", &bad_obj],
            &bad_obj,
        ),
        (
            vec![
                "remesh", &cube, "--res", "4", "--out", "r.obj", "--report", &bad,
            ],
            &bad,
        ),
        (vec!["slice", &cube, "--res", "8", "--out", &bad], &bad),
        (vec!["classify", &cube, &cube, "--out", &bad], &bad),
        (
            vec![
                "classify",
                &cube,
                &cube,
                "--out",
                "c.csv",
                "--mesh-out",
                &bad_obj,
            ],
            &bad_obj,
        ),
        (
            vec!["filter-tets", &cube, "t.node", "--out", &bad_mesh],
            &bad_mesh,
        ),
        (
            vec!["curve", "field", "poly.txt", "--res", "8", "--out", &bad],
            &bad,
        ),
        (
            vec!["gen", "--kind", "boxes", "--count", "1", "--out", &bad],
            &bad,
        ),
    ];
    for (args, name) in cases {
        let out = run_in(&dir, &args, None);
        assert_one_line_error(&out, &[name]);
    }
    // A full device as the output file: the write (or the final flush) fails.
    if Path::new("/dev/full").exists() {
        for args in [
            &["eval", &cube, "--points", "q.csv", "--out", "/dev/full"][..],
            &["voxelize", &cube, "--res", "4", "--out", "/dev/full"],
            &["sdf", &cube, "--res", "4", "--out", "/dev/full"],
            &["slice", &cube, "--res", "8", "--out", "/dev/full"],
            &["classify", &cube, &cube, "--out", "/dev/full"],
            &[
                "curve",
                "field",
                "poly.txt",
                "--res",
                "8",
                "--out",
                "/dev/full",
            ],
        ] {
            let out = run_in(&dir, args, None);
            assert_one_line_error(&out, &["/dev/full", "No space left"]);
        }
    } else {
        println!("skipping the /dev/full output files: /dev/full is not available");
    }
}

#[test]
fn oversized_requests_are_refused_or_capped() {
    let dir = scratch("sizes");
    let cube = fixture("cube.obj").display().to_string();
    let out = run_in(&dir, &["bench", &cube, "--grid", "1000"], None);
    assert_one_line_error(&out, &["--grid 1000", "256"]);
    let out = run_in(&dir, &["bench", &cube, "--grid", "0"], None);
    assert_one_line_error(&out, &["--grid 0"]);
    let out = run_in(&dir, &["bench", &cube, "--direct-sample", "0"], None);
    assert_one_line_error(&out, &["--direct-sample 0"]);
    let out = run_in(&dir, &["--threads", "0", "info", &cube], None);
    assert_one_line_error(&out, &["--threads 0"]);
    // Capped with a one-line warning, and the result is still printed.
    let out = run_in(
        &dir,
        &["--threads", "5000", "eval", &cube, "--points", "q.csv"],
        None,
    );
    assert!(out.status.success(), "{out:?}");
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(err.lines().count(), 1, "{err}");
    assert!(err.contains("--threads 5000 capped at"), "{err}");
    assert_eq!(String::from_utf8_lossy(&out.stdout), "1.0\n0.0\n");
    let out = run_in(
        &dir,
        &["bench", &cube, "--grid", "2", "--threads-list", "1,5000"],
        None,
    );
    assert!(out.status.success(), "{out:?}");
    assert!(String::from_utf8_lossy(&out.stderr).contains("--threads-list 5000 capped at"));
}

#[test]
fn nonsense_option_values_are_refused() {
    let dir = scratch("values");
    let cube = fixture("cube.obj").display().to_string();
    let eval = ["eval", &cube, "--points", "q.csv", "--method", "fast"];
    for beta in ["nan", "0", "-1", "inf", "-0"] {
        let arg = format!("--beta={beta}");
        let out = run_in(&dir, &[&eval[..], &[&arg]].concat(), None);
        // The library's message (gwn::spec), the one Python shows.
        assert_one_line_error(&out, &["beta must be a positive finite number"]);
        let out = run_in(&dir, &["bench", &cube, "--grid", "2", &arg], None);
        assert_one_line_error(&out, &["beta must be a positive finite number"]);
    }
    let out = run_in(
        &dir,
        &["eval", &cube, "--points", "q.csv", "--beta", "-1"],
        None,
    );
    assert_one_line_error(&out, &["beta must be a positive finite number, got -1"]);
    let out = run_in(
        &dir,
        &["voxelize", &cube, "--res", "4", "--occupancy", "nan"],
        None,
    );
    assert_one_line_error(&out, &["--occupancy NaN"]);
    let out = run_in(
        &dir,
        &["voxelize", &cube, "--res", "4", "--occupancy-out", "o.npy"],
        None,
    );
    assert_one_line_error(&out, &["--occupancy-out needs --occupancy"]);
    let out = run_in(
        &dir,
        &[
            "classify",
            &cube,
            &cube,
            "--out",
            "c.csv",
            "--threshold",
            "nan",
        ],
        None,
    );
    assert_one_line_error(&out, &["--threshold NaN"]);
    let out = run_in(
        &dir,
        &[
            "filter-tets",
            &cube,
            "t.node",
            "--out",
            "k.mesh",
            "--threshold",
            "nan",
        ],
        None,
    );
    assert_one_line_error(&out, &["--threshold NaN"]);
    for cmd in ["voxelize", "sdf"] {
        let out = run_in(
            &dir,
            &[
                cmd, &cube, "--res", "4", "--bounds", "-1e308", "0", "0", "1e308", "1", "1",
            ],
            None,
        );
        assert_one_line_error(&out, &["--bounds", "overflows"]);
        let out = run_in(
            &dir,
            &[
                cmd, &cube, "--res", "4", "--bounds", "0", "0", "0", "nan", "1", "1",
            ],
            None,
        );
        assert_one_line_error(&out, &["--bounds", "NaN"]);
        let out = run_in(
            &dir,
            &[
                cmd, &cube, "--res", "4", "--bounds", "1", "0", "0", "0", "1", "1",
            ],
            None,
        );
        assert_one_line_error(&out, &["--bounds", "below"]);
    }
    let out = run_in(
        &dir,
        &[
            "eval",
            &cube,
            "--points",
            "q.csv",
            "--gradient-out",
            "g.csv",
        ],
        None,
    );
    assert_one_line_error(&out, &["--gradient-out needs --gradient"]);
    assert!(!dir.join("g.csv").exists());
}

#[test]
fn input_file_messages() {
    let dir = scratch("messages");
    let cube = fixture("cube.obj").display().to_string();
    // Points files without points do not talk about triangles.
    std::fs::write(dir.join("empty.csv"), "").unwrap();
    std::fs::write(dir.join("header.csv"), "x,y,z\n").unwrap();
    for f in ["empty.csv", "header.csv"] {
        let out = run_in(&dir, &["eval", &cube, "--points", f], None);
        let err = assert_one_line_error(&out, &[f, "contains no points"]);
        assert!(!err.contains("triangles"), "{err}");
    }
    // Tet readers say `file: line N:`.
    std::fs::write(
        dir.join("bad.node"),
        "4 3 0 0\n1 0 0 0\n2 1 0 0\n3 x 0 0\n4 0 0 1\n",
    )
    .unwrap();
    std::fs::write(dir.join("bad.ele"), "1 4 0\n1 1 2 3 4\n").unwrap();
    let out = run_in(
        &dir,
        &["filter-tets", &cube, "bad.node", "--out", "k.mesh"],
        None,
    );
    assert_one_line_error(&out, &["bad.node: line 4: "]);
    // An unknown output extension names the file once.
    let out = run_in(
        &dir,
        &["filter-tets", &cube, "t.node", "--out", "o.vtk"],
        None,
    );
    let err = assert_one_line_error(&out, &["o.vtk: unknown tet mesh format"]);
    assert_eq!(err.matches("o.vtk").count(), 1, "{err}");
}

#[test]
fn endless_device_is_refused_not_read_until_memory_runs_out() {
    if !Path::new("/dev/zero").exists() {
        println!("skipping: /dev/zero is not available on this system");
        return;
    }
    let dir = scratch("dev-zero");
    let out = run_in(&dir, &["info", "/dev/zero"], None);
    assert_one_line_error(&out, &["/dev/zero: not a regular file and longer than"]);
    let cube = fixture("cube.obj").display().to_string();
    let out = run_in(&dir, &["eval", &cube, "--points", "/dev/zero"], None);
    assert_one_line_error(&out, &["/dev/zero: not a regular file"]);
    // A short pipe-like input (`/dev/null`) is read normally: empty.
    let out = run_in(&dir, &["info", "/dev/null"], None);
    assert_one_line_error(&out, &["/dev/null: contains no triangles"]);
}

#[test]
fn blender_247_ply_loads_with_a_warning() {
    let dir = scratch("blender");
    let ply = "ply\nformat ascii 1.0\n\
Created by Blender3D 247 - www.blender.org, source file: untitled.blend\n\
element vertex 4\nproperty float x\nproperty float y\nproperty float z\n\
element face 4\nproperty list uchar uint vertex_indices\nend_header\n\
0 0 0\n1 0 0\n0 1 0\n0 0 1\n3 0 2 1\n3 0 1 3\n3 0 3 2\n3 1 2 3\n";
    std::fs::write(dir.join("b.ply"), ply).unwrap();
    let out = run_in(&dir, &["info", "b.ply"], None);
    assert!(out.status.success(), "{out:?}");
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(err.lines().count(), 1, "{err}");
    assert!(
        err.starts_with("gwn: warning: b.ply: line 3: unknown PLY header line `Created by"),
        "{err}"
    );
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert!(
        stdout
            .lines()
            .any(|l| l.starts_with("oriented closed") && l.ends_with("yes")),
        "{stdout}"
    );
}

#[cfg(unix)]
#[test]
fn fifo_given_as_input_does_not_hang() {
    let dir = scratch("fifo-input");
    let fifo = dir.join("pipe.obj");
    let made = Command::new("mkfifo")
        .arg(&fifo)
        .status()
        .is_ok_and(|s| s.success());
    if !made {
        println!("skipping: mkfifo is not available");
        return;
    }
    let cube = fixture("cube.obj").display().to_string();
    for args in [
        vec!["info", "pipe.obj"],
        vec!["eval", cube.as_str(), "--points", "pipe.obj"],
        vec!["curve", "field", "pipe.obj", "--res", "8", "--out", "f.png"],
    ] {
        // No writer ever opens the FIFO: the old blocking open waited for one forever.
        let mut child = Command::new(GWN)
            .current_dir(&*dir)
            .args(&args)
            .stdin(Stdio::null())
            .stdout(Stdio::piped())
            .stderr(Stdio::piped())
            .spawn()
            .unwrap();
        let start = std::time::Instant::now();
        while child.try_wait().unwrap().is_none() {
            if start.elapsed() > std::time::Duration::from_secs(30) {
                let _ = child.kill();
                panic!("gwn {args:?} hangs on a FIFO without a writer");
            }
            std::thread::sleep(std::time::Duration::from_millis(20));
        }
        let out = child.wait_with_output().unwrap();
        assert_one_line_error(&out, &["pipe.obj"]);
    }
}
