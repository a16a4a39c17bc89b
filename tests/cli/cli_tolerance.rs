//! Issue 12, part 2, through the CLI: `--tolerance` on `eval` and the products. Bad values are a
//! one-line error; `--tolerance 0` is the flat loop; far queries on a mesh with a large boundary
//! move by at most the tolerance.

use crate::cli;
use cli::gwn;

/// An open wavy sheet of `n × n` quads with every seventh triangle removed: ~n²/3.5 boundary edges.
fn holey_sheet(dir: &std::path::Path, n: usize) -> std::path::PathBuf {
    let mut s = String::new();
    for j in 0..=n {
        for i in 0..=n {
            let (x, y) = (i as f64 / n as f64, j as f64 / n as f64);
            s.push_str(&format!(
                "v {x} {y} {}\n",
                0.1 * (6.0 * x).sin() * (5.0 * y).cos()
            ));
        }
    }
    let mut k = 0;
    for j in 0..n {
        for i in 0..n {
            let a = j * (n + 1) + i + 1;
            let (b, c, d) = (a + 1, a + n + 1, a + n + 2);
            for t in [[a, b, d], [a, d, c]] {
                k += 1;
                if k % 7 != 0 {
                    s.push_str(&format!("f {} {} {}\n", t[0], t[1], t[2]));
                }
            }
        }
    }
    let p = dir.join("sheet.obj");
    std::fs::write(&p, s).unwrap();
    p
}

#[test]
fn tolerance_flag() {
    let dir = std::env::temp_dir().join(format!("gwn-cli-tolerance-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let sheet = holey_sheet(&dir, 40);
    let sheet = sheet.to_str().unwrap();
    let q = dir.join("q.csv");
    // Far queries (where the hierarchy expands) and near ones.
    std::fs::write(
        &q,
        "5 5 5\n-4 0.5 3\n0.5 0.5 -6\n0.3 0.4 0.2\n0.5 0.5 0.01\n",
    )
    .unwrap();
    let q = q.to_str().unwrap();
    let values = |tol: &str| -> Vec<f64> {
        let (ok, out, err) = gwn(&["eval", sheet, "--points", q, "--tolerance", tol]);
        assert!(ok, "--tolerance {tol}: {err}");
        out.lines().map(|l| l.trim().parse().unwrap()).collect()
    };
    let flat = values("0");
    for tol in ["1e-3", "1e-10"] {
        let t: f64 = tol.parse().unwrap();
        for (a, b) in values(tol).iter().zip(&flat) {
            assert!((a - b).abs() <= t + 1e-13, "--tolerance {tol}: {a} vs {b}");
        }
    }
    // The default is 1e-10.
    let (ok, out, _) = gwn(&["eval", sheet, "--points", q]);
    assert!(ok);
    for (line, b) in out.lines().zip(&flat) {
        assert!((line.trim().parse::<f64>().unwrap() - b).abs() <= 1e-10 + 1e-13);
    }
    for bad in ["-1", "nan", "inf"] {
        let flag = format!("--tolerance={bad}");
        let (ok, _, err) = gwn(&["eval", sheet, "--points", q, &flag]);
        assert!(!ok, "--tolerance {bad} accepted");
        assert!(
            err.contains("tolerance must be a finite number >= 0"),
            "{err}"
        );
        assert_eq!(err.trim().lines().count(), 1, "{err}");
        let out = dir.join("v.npy");
        let (ok, _, err) = gwn(&[
            "voxelize",
            sheet,
            "--res",
            "4",
            "--out",
            out.to_str().unwrap(),
            &flag,
        ]);
        assert!(
            !ok && err.contains("tolerance must be a finite number >= 0"),
            "voxelize --tolerance {bad}: {err}"
        );
        let (ok, _, err) = gwn(&["bench", sheet, "--grid", "2", &flag]);
        assert!(
            !ok && err.contains("tolerance must be a finite number >= 0")
                && err.trim().lines().count() == 1,
            "bench --tolerance {bad}: {err}"
        );
    }
    // `gwn bench` measures the flat loop with --tolerance 0 and the default otherwise.
    for tol in ["0", "1e-10"] {
        let (ok, out, err) = gwn(&[
            "bench",
            sheet,
            "--grid",
            "4",
            "--threads-list",
            "1",
            "--tolerance",
            tol,
        ]);
        assert!(ok, "bench --tolerance {tol}: {err}");
        assert_eq!(out.lines().count(), 2, "{out}");
    }
    let _ = std::fs::remove_dir_all(&dir);
}
