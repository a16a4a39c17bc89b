//! Issue 12, part 1, through the CLI: `--weld` / `--no-weld` on every subcommand that reads a
//! mesh, and `gwn info`'s boundary by position beside the index topology.

use std::path::PathBuf;

use crate::cli;
use cli::gwn;

/// The unit cube as an OBJ soup: each of the 12 triangles has its own three vertices.
fn cube_soup(dir: &std::path::Path) -> PathBuf {
    let cube = gwn::testing::unit_cube(false);
    let mut s = String::new();
    for t in cube.triangles() {
        for &i in t {
            let p = cube.positions()[i as usize];
            s.push_str(&format!("v {} {} {}\n", p[0], p[1], p[2]));
        }
    }
    for f in 0..cube.triangles().len() {
        s.push_str(&format!("f {} {} {}\n", 3 * f + 1, 3 * f + 2, 3 * f + 3));
    }
    let p = dir.join("cube-soup.obj");
    std::fs::write(&p, s).unwrap();
    p
}

#[test]
fn weld_flags_change_the_boundary_not_the_values() {
    let dir = std::env::temp_dir().join(format!("gwn-cli-weld-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let soup = cube_soup(&dir);
    let soup = soup.to_str().unwrap();
    let q = dir.join("q.csv");
    std::fs::write(&q, "0.5 0.5 0.5\n2 0.5 0.5\n0.25 0.75 0.1\n").unwrap();
    let q = q.to_str().unwrap();

    let (ok, info, err) = gwn(&["info", soup]);
    assert!(ok, "{err}");
    let row = |name: &str| {
        info.lines()
            .find(|l| l.starts_with(name))
            .unwrap_or_else(|| panic!("no {name} row in\n{info}"))
            .split_whitespace()
            .last()
            .unwrap()
            .to_string()
    };
    assert_eq!(row("signed boundary by position"), "0");
    assert!(
        info.contains("signed boundary by position is empty"),
        "{info}"
    );
    let (ok, welded, _) = gwn(&["info", soup, "--weld"]);
    assert!(
        ok && welded.contains("signed boundary is empty"),
        "{welded}"
    );

    let mut outputs = Vec::new();
    for flags in [&[][..], &["--weld"], &["--no-weld"]] {
        let (ok, out, err) = gwn(&[&["eval", soup, "--points", q][..], flags].concat());
        assert!(ok, "{flags:?}: {err}");
        outputs.push(out);
    }
    assert_eq!(outputs[0], "1.0\n0.0\n1.0\n");
    assert_eq!(outputs[0], outputs[1]);
    // Matched by index, the 36 soup edges cancel term by term: equal up to rounding.
    let parse = |o: &str| -> Vec<f64> { o.lines().map(|l| l.parse().unwrap()).collect() };
    for (a, b) in parse(&outputs[0]).iter().zip(parse(&outputs[2])) {
        assert!((a - b).abs() < 1e-12, "{a} vs {b}");
    }
    // Every other mesh subcommand accepts both flags.
    for sub in [
        vec!["voxelize", soup, "--res", "4", "--out"],
        vec!["sdf", soup, "--res", "4", "--out"],
        vec!["slice", soup, "--res", "8", "--out"],
    ] {
        for flag in ["--weld", "--no-weld"] {
            let ext = if sub[0] == "slice" { "png" } else { "npy" };
            let out = dir.join(format!("{}{flag}.{ext}", sub[0]));
            let (ok, _, err) = gwn(&[&sub[..], &[out.to_str().unwrap(), flag]].concat());
            assert!(ok, "{sub:?} {flag}: {err}");
        }
    }
    let (ok, _, err) = gwn(&["eval", soup, "--points", q, "--weld", "--no-weld"]);
    assert!(!ok && err.contains("cannot be used with"), "{err}");
    std::fs::remove_dir_all(&dir).ok();
}
