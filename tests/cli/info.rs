//! `gwn info` on fixtures, on a mesh off the 60-bit lattice, and on missing and broken files.

use std::process::Command;

use crate::common::fixture;

#[test]
fn cli_info_on_fixture_missing_and_broken_files() {
    let exe = env!("CARGO_BIN_EXE_gwn");
    let out = Command::new(exe)
        .args(["info"])
        .arg(fixture("cube_binary.stl"))
        .output()
        .unwrap();
    assert!(out.status.success());
    let stdout = String::from_utf8(out.stdout).unwrap();
    assert!(stdout.contains("STL"), "{stdout}");
    assert!(
        stdout
            .lines()
            .any(|l| l.starts_with("welded vertices") && l.split_whitespace().last() == Some("28")),
        "{stdout}"
    );
    assert!(
        stdout.contains("w is an integer off the surface"),
        "{stdout}"
    );

    // Issue 21: whether the 60-bit lattice holds the mesh. The cube's integer corners do; a
    // triangle with a coordinate far below the extent does not, and the displacement is shown.
    assert!(stdout.contains("60-bit snapping"), "{stdout}");
    assert!(stdout.contains("lossless"), "{stdout}");
    let dir = std::env::temp_dir().join(format!("gwn-info-snap-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let off = dir.join("tiny.off");
    std::fs::write(&off, "OFF\n3 1 0\n0 0 0\n10 0 1e-20\n0 10 0.01\n3 0 1 2\n").unwrap();
    let out = Command::new(exe).args(["info"]).arg(&off).output().unwrap();
    let stdout = String::from_utf8(out.stdout).unwrap();
    let line = stdout
        .lines()
        .find(|l| l.starts_with("60-bit snapping"))
        .unwrap_or_else(|| panic!("{stdout}"));
    assert!(line.contains("2 vertices off the lattice"), "{line}");
    assert!(line.contains("largest displacement"), "{line}");
    std::fs::remove_dir_all(&dir).ok();

    for name in ["does_not_exist.off", "broken_index.off"] {
        let out = Command::new(exe)
            .args(["info"])
            .arg(fixture(name))
            .output()
            .unwrap();
        assert!(!out.status.success(), "{name}");
        let stderr = String::from_utf8(out.stderr).unwrap();
        assert_eq!(stderr.lines().count(), 1, "{stderr}");
        assert!(stderr.contains(name), "{stderr}");
    }
}

/// A broken STEP file is one line on stderr naming the file and the entity with its `#id`, for
/// `gwn info` and `gwn eval` alike; `gwn info` counts the edge uses trimmed by pcurves.
#[test]
fn cli_step_errors_are_one_line_naming_the_file() {
    let dir = std::env::temp_dir().join(format!("gwn-cli-step-errors-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let good = std::fs::read_to_string(fixture("step/capped_cylinder.step")).unwrap();
    let bad = dir.join("offset.step");
    std::fs::write(
        &bad,
        good.replace("#14=PLANE('',#10);", "#14=OFFSET_SURFACE('',#12,0.1,.F.);"),
    )
    .unwrap();
    let points = dir.join("q.csv");
    std::fs::write(&points, "0 0 1\n").unwrap();
    let bad_s = bad.to_str().unwrap();
    for args in [
        vec!["info", bad_s],
        vec!["eval", bad_s, "--points", points.to_str().unwrap()],
    ] {
        let (ok, _, err) = crate::cli::gwn(&args);
        assert!(!ok, "{args:?}");
        let lines: Vec<&str> = err.lines().collect();
        assert_eq!(lines.len(), 1, "{err}");
        assert!(
            lines[0].contains(bad_s) && lines[0].contains("#14 OFFSET_SURFACE: not supported"),
            "{err}"
        );
    }
    let (ok, out, err) = crate::cli::gwn(&[
        "info",
        fixture("step/capped_cylinder_pcurves.step")
            .to_str()
            .unwrap(),
    ]);
    assert!(ok, "{err}");
    assert!(
        out.lines()
            .any(|l| l.starts_with("edge uses trimmed by pcurves")
                && l.contains(" 6 (0 pcurves off")),
        "{out}"
    );
    std::fs::remove_dir_all(&dir).ok();
}

/// `gwn info` reads what every other subcommand reads: an oriented point cloud (text, or a PLY
/// with normals and no faces) gets its own report instead of "unknown format", and a PLY with
/// neither faces nor normals gets `gwn eval`'s message.
#[test]
fn cli_info_on_point_clouds_and_faceless_ply() {
    let exe = env!("CARGO_BIN_EXE_gwn");
    let dir = std::env::temp_dir().join(format!("gwn-info-cloud-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let xyz = dir.join("c.xyz");
    std::fs::write(&xyz, "0 0 0 0 0 1 0.5\n1 0 0 0 0 1 0.5\n0 1 0 0 0 2 0.5\n").unwrap();
    let ply = dir.join("c.ply");
    std::fs::write(
        &ply,
        "ply\nformat ascii 1.0\nelement vertex 2\nproperty float x\nproperty float y\n\
         property float z\nproperty float nx\nproperty float ny\nproperty float nz\nend_header\n\
         0 0 0 1 0 0\n2 3 4 0 1 0\n",
    )
    .unwrap();
    for (path, points, areas, max) in [
        (&xyz, "3", "given", "[1.0, 1.0, 0.0]"),
        (&ply, "2", "none", "[2.0, 3.0, 4.0]"),
    ] {
        let out = Command::new(exe).arg("info").arg(path).output().unwrap();
        let stdout = String::from_utf8_lossy(&out.stdout);
        assert!(
            out.status.success(),
            "{}",
            String::from_utf8_lossy(&out.stderr)
        );
        let row = |key: &str| {
            stdout
                .lines()
                .find(|l| l.starts_with(key))
                .map(|l| l[key.len()..].trim().to_string())
                .unwrap_or_else(|| panic!("no {key} in {stdout}"))
        };
        assert_eq!(row("format"), "oriented point cloud");
        assert_eq!(row("points"), points);
        assert!(row("areas").starts_with(areas), "{stdout}");
        assert_eq!(row("bbox max"), max);
    }
    let empty = fixture("broken_empty.ply");
    let info = Command::new(exe).arg("info").arg(&empty).output().unwrap();
    let eval = Command::new(exe)
        .args(["eval", "--points"])
        .arg(&xyz)
        .arg(&empty)
        .output()
        .unwrap();
    assert!(!info.status.success() && !eval.status.success());
    let message = String::from_utf8_lossy(&info.stderr);
    assert!(message.contains("broken_empty.ply: no faces"), "{message}");
    assert_eq!(message, String::from_utf8_lossy(&eval.stderr));
    std::fs::remove_dir_all(&dir).ok();
}

/// A closed tetrahedron with one face flipped: `gwn info` says the parity method applies; an
/// open mesh (one triangle), whose signed boundary is not empty either, does not get the line.
#[test]
fn cli_info_names_the_parity_method_for_closed_unoriented_meshes() {
    let exe = env!("CARGO_BIN_EXE_gwn");
    let dir = std::env::temp_dir().join(format!("gwn-info-parity-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let flipped = dir.join("flipped_tet.off");
    std::fs::write(
        &flipped,
        "OFF\n4 4 0\n0 0 0\n1 0 0\n0 1 0\n0 0 1\n3 0 1 2\n3 0 1 3\n3 1 2 3\n3 2 0 3\n",
    )
    .unwrap();
    let open = dir.join("triangle.off");
    std::fs::write(&open, "OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n").unwrap();
    let line = "--method parity gives the solid it encloses";
    let out = Command::new(exe)
        .args(["info"])
        .arg(&flipped)
        .output()
        .unwrap();
    let stdout = String::from_utf8(out.stdout).unwrap();
    assert!(stdout.contains(line), "{stdout}");
    let out = Command::new(exe)
        .args(["info"])
        .arg(&open)
        .output()
        .unwrap();
    let stdout = String::from_utf8(out.stdout).unwrap();
    assert!(
        stdout.contains("signed boundary is not empty") && !stdout.contains(line),
        "{stdout}"
    );
    std::fs::remove_dir_all(&dir).ok();
}
