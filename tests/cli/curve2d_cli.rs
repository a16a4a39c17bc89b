//! `gwn curve` end to end: field .npy equals `curve eval` at the same points, parameter
//! validation, bounded runs on degenerate input, summary lines and `--strict`.

use gwn::curve2d::apps::{OffsetParams, OffsetStop, UntangleParams, offset, untangle};
use gwn::curve2d::tangled::{circle_with_flips, circle_with_lobes, figure_eight};
use gwn::curve2d::{Point, Polygon};
use std::path::{Path, PathBuf};
use std::process::{Command, Output};
use std::time::{Duration, Instant};

fn temp_dir(name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("gwn-curve-cli-{name}-{}", std::process::id()));
    std::fs::create_dir_all(&d).unwrap();
    d
}

/// Runs `gwn` with a time limit (a hang fails the test instead of blocking it).
fn gwn(args: &[&str], limit: Duration) -> Output {
    let mut child = Command::new(env!("CARGO_BIN_EXE_gwn"))
        .args(args)
        .stdout(std::process::Stdio::piped())
        .stderr(std::process::Stdio::piped())
        .spawn()
        .unwrap();
    let start = Instant::now();
    loop {
        if child.try_wait().unwrap().is_some() {
            return child.wait_with_output().unwrap();
        }
        if start.elapsed() > limit {
            let _ = child.kill();
            panic!("gwn {args:?} did not finish within {limit:?}");
        }
        std::thread::sleep(Duration::from_millis(20));
    }
}

fn text(o: &Output) -> (String, String) {
    (
        String::from_utf8_lossy(&o.stdout).into_owned(),
        String::from_utf8_lossy(&o.stderr).into_owned(),
    )
}

fn circle_text(r: f64, n: usize) -> String {
    (0..n)
        .map(|i| {
            let t = std::f64::consts::TAU * i as f64 / n as f64;
            format!("{} {}\n", r * t.cos(), r * t.sin())
        })
        .collect()
}

fn read_npy_f64(path: &Path) -> (Vec<usize>, Vec<f64>) {
    let b = std::fs::read(path).unwrap();
    let hlen = u16::from_le_bytes([b[8], b[9]]) as usize;
    let header = std::str::from_utf8(&b[10..10 + hlen]).unwrap();
    let shape: Vec<usize> = header
        .split("'shape': (")
        .nth(1)
        .unwrap()
        .split(')')
        .next()
        .unwrap()
        .split(',')
        .filter_map(|s| s.trim().parse().ok())
        .collect();
    let data = b[10 + hlen..]
        .chunks_exact(8)
        .map(|c| f64::from_le_bytes(c.try_into().unwrap()))
        .collect();
    (shape, data)
}

const MINUTE: Duration = Duration::from_secs(60);

#[test]
fn field_npy_equals_eval_at_the_same_points() {
    let dir = temp_dir("field");
    let input = dir.join("shape.txt");
    // A closed square and an open arc-like polyline.
    std::fs::write(&input, "0 0\n1 0\n1 1\n0 1\n\nopen\n1.5 0\n2 0.5\n1.5 1\n").unwrap();
    let npy = dir.join("w.npy");
    let png = dir.join("w.png");
    for extra in [vec!["--sigma", "0.05"], vec!["--plain"]] {
        let mut args = vec!["curve", "field", input.to_str().unwrap(), "--res", "40"];
        args.extend(&extra);
        args.extend([
            "--npy",
            npy.to_str().unwrap(),
            "--out",
            png.to_str().unwrap(),
        ]);
        let o = gwn(&args, MINUTE);
        let (out, err) = text(&o);
        assert!(o.status.success(), "{err}");
        let grid_line = out.lines().find(|l| l.starts_with("grid origin")).unwrap();
        let f: Vec<&str> = grid_line.split_whitespace().collect();
        let (ox, oy, h): (f64, f64, f64) = (
            f[2].parse().unwrap(),
            f[3].parse().unwrap(),
            f[5].parse().unwrap(),
        );
        let (ny, nx): (usize, usize) = (f[7].parse().unwrap(), f[8].parse().unwrap());
        let (shape, values) = read_npy_f64(&npy);
        assert_eq!(shape, vec![ny, nx]);
        // The same points through `curve eval`.
        let mut pts = String::new();
        for j in 0..ny {
            for i in 0..nx {
                pts.push_str(&format!("{} {}\n", ox + i as f64 * h, oy + j as f64 * h));
            }
        }
        let qfile = dir.join("q.txt");
        std::fs::write(&qfile, pts).unwrap();
        let mut args = vec!["curve", "eval", input.to_str().unwrap(), "--points"];
        args.push(qfile.to_str().unwrap());
        if extra[0] == "--sigma" {
            args.extend(["--sigma", "0.05"]);
        }
        let o = gwn(&args, MINUTE);
        let (out, err) = text(&o);
        assert!(o.status.success(), "{err}");
        let evals: Vec<f64> = out.lines().map(|l| l.parse().unwrap()).collect();
        assert_eq!(evals.len(), values.len());
        for (a, b) in evals.iter().zip(&values) {
            assert_eq!(a, b, "{extra:?}");
        }
        // The plain field takes the open curve's fractional values.
        if extra[0] == "--plain" {
            assert!(values.iter().any(|v| v.fract().abs() > 0.05));
        }
        let bytes = std::fs::read(&png).unwrap();
        assert_eq!(&bytes[1..4], b"PNG");
    }
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn eval_gradient_columns_match_finite_differences() {
    let dir = temp_dir("grad");
    let input = dir.join("c.txt");
    std::fs::write(&input, format!("open\n{}", circle_text(1.0, 50))).unwrap();
    let q = dir.join("q.txt");
    let h = 1e-6;
    std::fs::write(
        &q,
        format!(
            "0.9 0.1\n{} 0.1\n{} 0.1\n0.9 {}\n0.9 {}\n",
            0.9 + h,
            0.9 - h,
            0.1 + h,
            0.1 - h
        ),
    )
    .unwrap();
    let o = gwn(
        &[
            "curve",
            "eval",
            input.to_str().unwrap(),
            "--points",
            q.to_str().unwrap(),
            "--sigma",
            "0.1",
            "--gradient",
        ],
        MINUTE,
    );
    let (out, err) = text(&o);
    assert!(o.status.success(), "{err}");
    let rows: Vec<Vec<f64>> = out
        .lines()
        .map(|l| l.split_whitespace().map(|v| v.parse().unwrap()).collect())
        .collect();
    assert_eq!(rows[0].len(), 3);
    let fd = [
        (rows[1][0] - rows[2][0]) / (2.0 * h),
        (rows[3][0] - rows[4][0]) / (2.0 * h),
    ];
    for c in 0..2 {
        assert!(
            (fd[c] - rows[0][1 + c]).abs() < 1e-6,
            "{fd:?} vs {:?}",
            rows[0]
        );
    }
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn bad_parameters_are_one_line_errors() {
    let dir = temp_dir("params");
    let input = dir.join("c.txt");
    std::fs::write(&input, circle_text(1.0, 16)).unwrap();
    let out = dir.join("o.svg");
    let (i, o) = (input.to_str().unwrap(), out.to_str().unwrap());
    let cases: Vec<(Vec<&str>, &str)> = vec![
        (
            vec!["curve", "untangle", i, "--out", o, "--sigma0", "nan"],
            "--sigma0",
        ),
        (
            vec!["curve", "untangle", i, "--out", o, "--lambda", "nan"],
            "--lambda",
        ),
        (
            vec!["curve", "untangle", i, "--out", o, "--lambda", "-1"],
            "--lambda",
        ),
        (
            vec!["curve", "untangle", i, "--out", o, "--eps", "0"],
            "--eps",
        ),
        (
            vec!["curve", "untangle", i, "--out", o, "--sigma0", "inf"],
            "--sigma0",
        ),
        (
            vec!["curve", "untangle", i, "--out", o, "--decay", "1.5"],
            "--decay",
        ),
        (
            vec!["curve", "untangle", i, "--out", o, "--max-iters", "0"],
            "--max-iters",
        ),
        (
            vec!["curve", "untangle", i, "--out", o, "--patience", "0"],
            "--patience",
        ),
        (
            vec!["curve", "offset", i, "--out", o, "--distance", "nan"],
            "--distance",
        ),
        (
            vec![
                "curve",
                "offset",
                i,
                "--out",
                o,
                "--distance",
                "0.1",
                "--sigma",
                "nan",
            ],
            "--sigma",
        ),
        (
            vec![
                "curve",
                "offset",
                i,
                "--out",
                o,
                "--distance",
                "0.1",
                "--sigma",
                "0",
            ],
            "--sigma",
        ),
        (
            vec![
                "curve",
                "offset",
                i,
                "--out",
                o,
                "--distance",
                "0.1",
                "--step",
                "0",
            ],
            "--step",
        ),
        (
            vec![
                "curve",
                "offset",
                i,
                "--out",
                o,
                "--distance",
                "0.1",
                "--lambda",
                "-2",
            ],
            "--lambda",
        ),
        (
            vec![
                "curve",
                "offset",
                i,
                "--out",
                o,
                "--distance",
                "0.1",
                "--max-steps",
                "0",
            ],
            "--max-steps",
        ),
        (
            vec!["curve", "field", i, "--out", o, "--sigma", "-1"],
            "--sigma",
        ),
        (vec!["curve", "field", i, "--out", o, "--res", "0"], "--res"),
        (
            vec!["curve", "eval", i, "--points", i, "--sigma", "nan"],
            "--sigma",
        ),
    ];
    for (args, flag) in cases {
        let r = gwn(&args, MINUTE);
        let (_, err) = text(&r);
        assert!(!r.status.success(), "{args:?} succeeded");
        assert_eq!(err.trim_end().lines().count(), 1, "{args:?}: {err}");
        assert!(
            err.starts_with("gwn: ") && err.contains(flag),
            "{args:?}: {err}"
        );
    }
    // An open polyline cannot be untangled or offset.
    let open = dir.join("open.txt");
    std::fs::write(&open, "open\n0 0\n1 0\n1 1\n").unwrap();
    let r = gwn(
        &["curve", "untangle", open.to_str().unwrap(), "--out", o],
        MINUTE,
    );
    let (_, err) = text(&r);
    assert!(
        !r.status.success() && err.contains("open polyline"),
        "{err}"
    );
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn tiny_and_huge_extents_finish_with_the_scaled_result() {
    // Issue 11: a polygon of extent ≤ 1e-19 used to hang `curve offset` (NaN in the line search).
    let unit: Vec<Point> = (0..40)
        .map(|i| {
            let t = std::f64::consts::TAU * i as f64 / 40.0;
            [t.cos(), t.sin()]
        })
        .collect();
    let reference = offset(
        &Polygon::new(vec![unit.clone()]).unwrap(),
        &OffsetParams::new(0.1),
    )
    .unwrap();
    for s in [1e-20, 1e-150, 1e-300, 1e90] {
        let p = Polygon::new(vec![unit.iter().map(|v| [v[0] * s, v[1] * s]).collect()]).unwrap();
        let t = Instant::now();
        let rep = offset(&p, &OffsetParams::new(0.1 * s)).unwrap();
        assert!(t.elapsed() < MINUTE);
        assert_eq!(rep.stop, OffsetStop::Reached, "scale {s}");
        assert!(
            ((rep.mean_displacement / s) - 0.1).abs() < 1e-6,
            "scale {s}: {}",
            rep.mean_displacement
        );
        // Same flow as at unit size, up to the power-of-two scaling (exact) and s's rounding.
        for (a, b) in rep.polygon.points().iter().zip(reference.polygon.points()) {
            assert!((a[0] / s - b[0]).abs() < 1e-9 && (a[1] / s - b[1]).abs() < 1e-9);
        }
    }
    // The CLI on the 1e-20 polygon: finishes, says the target was reached.
    let dir = temp_dir("tiny");
    let input = dir.join("tiny.txt");
    std::fs::write(&input, circle_text(1e-20, 40)).unwrap();
    let o = dir.join("o.txt");
    let r = gwn(
        &[
            "curve",
            "offset",
            input.to_str().unwrap(),
            "--distance",
            "1e-21",
            "--out",
            o.to_str().unwrap(),
            "--strict",
        ],
        MINUTE,
    );
    let (out, err) = text(&r);
    assert!(r.status.success(), "{out}{err}");
    assert!(out.contains("(reached)"), "{out}");
    let r = gwn(
        &[
            "curve",
            "untangle",
            input.to_str().unwrap(),
            "--out",
            o.to_str().unwrap(),
            "--strict",
        ],
        MINUTE,
    );
    assert!(r.status.success(), "{:?}", text(&r));
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn strict_fails_when_the_target_is_not_reached() {
    let dir = temp_dir("strict");
    let input = dir.join("c.txt");
    std::fs::write(&input, circle_text(1.0, 40)).unwrap();
    let o = dir.join("o.svg");
    // Inwards by more than the radius: the flow stalls.
    let args = [
        "curve",
        "offset",
        input.to_str().unwrap(),
        "--distance",
        "-3",
        "--out",
        o.to_str().unwrap(),
    ];
    let r = gwn(&args, MINUTE);
    let (out, _) = text(&r);
    assert!(r.status.success());
    assert!(out.contains("TARGET NOT REACHED"), "{out}");
    let mut strict = args.to_vec();
    strict.push("--strict");
    let r = gwn(&strict, MINUTE);
    assert_eq!(r.status.code(), Some(3), "{:?}", text(&r));
    // A figure-eight with large lobes cannot be untangled locally in 2 σ steps.
    let fig = dir.join("fig.txt");
    let p = figure_eight(60);
    let s: String = p
        .points()
        .iter()
        .map(|v| format!("{} {}\n", v[0], v[1]))
        .collect();
    std::fs::write(&fig, s).unwrap();
    let args = [
        "curve",
        "untangle",
        fig.to_str().unwrap(),
        "--max-iters",
        "2",
        "--inner-iters",
        "10",
        "--out",
        o.to_str().unwrap(),
        "--strict",
    ];
    let r = gwn(&args, MINUTE);
    let (out, err) = text(&r);
    assert_eq!(r.status.code(), Some(3), "{out}{err}");
    assert!(
        out.contains("TARGET NOT REACHED") && out.contains("1 → 1"),
        "{out}"
    );
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn untangling_is_never_worse_than_its_input() {
    // Cases it resolves, and one it cannot (a large figure-eight): the result never has more
    // intersecting edge pairs than the input, and the input comes back when nothing is better.
    let params = UntangleParams {
        max_outer: 3,
        inner_iters: 10,
        ..UntangleParams::default()
    };
    for p in [
        circle_with_flips(50, 2, 0.0, 1),
        circle_with_lobes(40, 1, 0.04),
        figure_eight(60),
    ] {
        let rep = untangle(&p, &params).unwrap();
        let before = p.self_intersections(usize::MAX).len();
        let after = rep.polygon.self_intersections(usize::MAX).len();
        assert_eq!(before, rep.crossings_before);
        assert_eq!(after, rep.crossings_after);
        assert!(after <= before, "{before} → {after}");
        if rep.best_iteration == 0 {
            assert_eq!(rep.polygon, p);
        }
        if rep.converged {
            assert_eq!(after, 0);
        }
    }
}
