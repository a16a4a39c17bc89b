//! Issue 22, "No crash, no unbounded work": hostile or extreme inputs end with a one-line error
//! (or a right answer), never a stack overflow, an unbounded read, a NaN, an infinity or a zero
//! where the evaluators are right. Each test reproduces one reported defect.

use crate::cli;

use std::path::PathBuf;

use gwn::BoundingBox;
use gwn::Mesh;
use gwn::curve2d::io::{parse_points_text, parse_svg, read_drawing};
use gwn::products::sdf::SignedDistance;

/// A scratch directory, removed when dropped.
struct Scratch(PathBuf);

impl Scratch {
    fn new(name: &str) -> Scratch {
        let d = std::env::temp_dir().join(format!("gwn-bounded-{name}-{}", std::process::id()));
        std::fs::create_dir_all(&d).unwrap();
        Scratch(d)
    }
    fn file(&self, name: &str, bytes: &[u8]) -> String {
        let p = self.0.join(name);
        std::fs::write(&p, bytes).unwrap();
        p.display().to_string()
    }
}

impl Drop for Scratch {
    fn drop(&mut self) {
        let _ = std::fs::remove_dir_all(&self.0);
    }
}

fn nested_svg(depth: usize) -> String {
    format!(
        "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"10\" height=\"10\">{}\
         <rect x=\"1\" y=\"1\" width=\"2\" height=\"2\"/>{}</svg>",
        "<g>".repeat(depth),
        "</g>".repeat(depth)
    )
}

#[test]
fn svg_nested_20000_groups_is_an_error_not_a_stack_overflow() {
    // Before: usvg's recursive conversion overflowed the stack (CLI rc 134, Python SIGSEGV).
    let e = parse_svg(&nested_svg(20_000), "deep.svg").unwrap_err();
    assert!(e.to_string().contains("nest"), "{e}");
    assert!(!e.to_string().contains('\n'), "{e}");
    // Ordinary nesting still reads, on a test thread's small stack.
    let c = parse_svg(&nested_svg(100), "ok.svg").unwrap();
    assert_eq!(c.polygon.num_loops(), 1);
}

#[test]
fn svg_nested_20000_groups_via_the_cli_is_a_one_line_error() {
    let dir = Scratch::new("svg");
    let svg = dir.file("deep.svg", nested_svg(20_000).as_bytes());
    let q = dir.file("q.txt", b"0 0\n");
    let (ok, _, err) = cli::gwn(&["curve", "eval", &svg, "--points", &q, "--sigma", "0.1"]);
    assert!(!ok);
    assert_eq!(err.trim().lines().count(), 1, "{err}");
    assert!(err.contains("nest"), "{err}");
}

#[test]
fn a_drawing_that_never_ends_is_refused_after_a_bounded_read() {
    // Before: `read_to_string` on a device read until memory ran out.
    let e = read_drawing(std::path::Path::new("/dev/zero")).unwrap_err();
    assert!(e.to_string().contains("MiB"), "{e}");
}

#[test]
fn curve_queries_beyond_1e100_are_refused() {
    // Before: accepted, and evaluated as NaN.
    let e = parse_points_text("0 0\n1e101 0\n", "q.txt").unwrap_err();
    assert_eq!(e.line, 2, "{e}");
    assert!(e.to_string().contains("1e100"), "{e}");
    let dir = Scratch::new("curve-far");
    let poly = dir.file("sq.txt", b"0 0\n1 0\n1 1\n0 1\n");
    let q = dir.file("q.txt", b"0.5 0.5\n-3e150 2\n");
    let (ok, out, err) = cli::gwn(&["curve", "eval", &poly, "--points", &q, "--sigma", "0.1"]);
    assert!(!ok, "{out}");
    assert!(err.contains("1e100"), "{err}");
}

fn cube_scaled(s: f64) -> Mesh {
    let mut m = gwn::testing::unit_cube(false);
    let p: Vec<[f64; 3]> = m.positions().iter().map(|v| v.map(|c| c * s)).collect();
    m = Mesh::new(p, m.triangles().to_vec()).unwrap();
    m
}

#[test]
fn signed_distance_is_right_on_huge_and_tiny_meshes() {
    // Before: ±inf above ~1e160 (squared distances overflow) and 0 below ~1e-170 (underflow),
    // while the winding numbers were right.
    for s in [1.0, 1e160, 1e200, 1e300, 1e-170, 1e-200, 1e-300] {
        let sdf = SignedDistance::new(&cube_scaled(s)).unwrap();
        let inside = sdf.eval([0.5 * s, 0.5 * s, 0.25 * s]);
        let outside = sdf.eval([0.5 * s, 0.5 * s, 3.0 * s]);
        assert!(
            (inside / s + 0.25).abs() < 1e-12,
            "scale {s:e}: inside {inside:e}"
        );
        assert!(
            (outside / s - 2.0).abs() < 1e-12,
            "scale {s:e}: outside {outside:e}"
        );
        let c = sdf.closest([0.5 * s, 0.5 * s, 3.0 * s]).unwrap();
        assert!((c.point[2] / s - 1.0).abs() < 1e-12, "{:?}", c.point);
    }
}

#[test]
fn sdf_refuses_a_float32_output_that_cannot_hold_the_values() {
    let dir = Scratch::new("sdf32");
    let mut obj = String::new();
    for v in cube_scaled(1e60).positions() {
        obj.push_str(&format!("v {:e} {:e} {:e}\n", v[0], v[1], v[2]));
    }
    for t in cube_scaled(1.0).triangles() {
        obj.push_str(&format!("f {} {} {}\n", t[0] + 1, t[1] + 1, t[2] + 1));
    }
    let mesh = dir.file("big.obj", obj.as_bytes());
    let out = dir.0.join("sdf.npy").display().to_string();
    let (ok, _, err) = cli::gwn(&["sdf", &mesh, "--res", "4", "--out", &out]);
    assert!(!ok, "float32 cannot hold 1e60");
    assert!(
        err.contains("float32") && err.contains("--dtype f64"),
        "{err}"
    );
    assert_eq!(err.trim().lines().count(), 1, "{err}");
    let (ok, _, err) = cli::gwn(&["sdf", &mesh, "--res", "4", "--out", &out, "--dtype", "f64"]);
    assert!(ok, "{err}");
}

#[test]
fn the_grid_memory_check_is_the_librarys() {
    let b = BoundingBox {
        min: [0.0; 3],
        max: [1.0; 3],
    };
    let spec = gwn::grid::GridSpec::new(b, [1024, 1024, 1024]).unwrap();
    assert!(spec.check_memory(8, Some(16 << 30)).is_ok());
    let e = spec.check_memory(21, Some(8 << 30)).unwrap_err();
    assert!(e.to_string().contains("GiB"), "{e}");
    let huge = gwn::grid::GridSpec::new(b, [2048, 2048, 1024]).unwrap();
    assert!(huge.check_memory(1, None).is_err(), "beyond 2^31 cells");
}

#[test]
fn an_empty_medit_file_is_an_error() {
    // Before: `gwn filter-tets` exited 0 with nothing to do.
    assert!(gwn::io::tets::parse_medit(b"").is_err());
    assert!(gwn::io::tets::parse_medit(b"MeshVersionFormatted 2\nDimension 3\nEnd\n").is_err());
    let dir = Scratch::new("medit");
    let tets = dir.file("empty.mesh", b"");
    let mesh = crate::common::repo().join("data/lion-head.off");
    let out = dir.0.join("kept").display().to_string();
    let (ok, _, err) = cli::gwn(&["filter-tets", mesh.to_str().unwrap(), &tets, "--out", &out]);
    assert!(!ok);
    assert!(err.contains("empty.mesh"), "{err}");
}

#[test]
fn npy_points_with_trailing_bytes_are_refused() {
    let mut npy = Vec::new();
    gwn::products::npy::write(&mut npy, &[1, 3], &[0.5f64, 0.5, 0.5]).unwrap();
    assert!(gwn::io::load_points_from_bytes(&npy, "q.npy").is_ok());
    npy.extend_from_slice(&[0u8; 8]);
    let e = gwn::io::load_points_from_bytes(&npy, "q.npy").unwrap_err();
    assert!(e.to_string().contains("8 bytes after"), "{e}");
}

#[test]
fn obj_with_cr_only_line_ends_loads() {
    // Classic Mac line ends: before, the whole file was one line ("too many values").
    let obj = b"v 0 0 0\rv 1 0 0\rv 0 1 0\rv 0 0 1\rf 1 3 2\rf 1 2 4\rf 2 3 4\rf 3 1 4\r";
    let m = gwn::io::load_mesh_from_bytes(obj, "mac.obj", None).unwrap();
    assert_eq!(m.mesh.triangles().len(), 4);
    assert_eq!(m.mesh.positions().len(), 4);
    // Errors still name the right line.
    let bad = b"v 0 0 0\rv 1 0 0\rv 0 1 x\rf 1 2 3\r";
    let e = gwn::io::load_mesh_from_bytes(bad, "mac.obj", None).unwrap_err();
    assert!(e.to_string().contains("line 3"), "{e}");
}

#[test]
fn info_prints_the_diagonal_of_a_tiny_mesh() {
    // Before: `diagonal 0` for a cube scaled by 1e-300 (the squared lengths underflowed).
    let b = BoundingBox {
        min: [0.0; 3],
        max: [1e-300; 3],
    };
    let d = b.diagonal();
    assert!((d / 1e-300 - 3f64.sqrt()).abs() < 1e-12, "{d:e}");
    let big = BoundingBox {
        min: [-1e300; 3],
        max: [1e300; 3],
    };
    assert!((big.diagonal() / 2e300 - 3f64.sqrt()).abs() < 1e-12);
    let dir = Scratch::new("info");
    let mut obj = String::new();
    for v in cube_scaled(1e-300).positions() {
        obj.push_str(&format!("v {:e} {:e} {:e}\n", v[0], v[1], v[2]));
    }
    for t in cube_scaled(1.0).triangles() {
        obj.push_str(&format!("f {} {} {}\n", t[0] + 1, t[1] + 1, t[2] + 1));
    }
    let f = dir.file("tiny.obj", obj.as_bytes());
    let (ok, out, err) = cli::gwn(&["info", &f]);
    assert!(ok, "{err}");
    let line = out.lines().find(|l| l.contains("diagonal")).unwrap();
    assert!(line.contains("e-300"), "{line}");
}

#[test]
fn grids_stop_when_asked() {
    // What the Python package's Ctrl-C handling relies on: a set flag ends the grid early.
    use std::sync::atomic::AtomicBool;
    let cube = gwn::testing::unit_cube(false);
    let wn = gwn::eval::antipodal::WindingNumber::new(&cube).unwrap();
    let spec = gwn::grid::GridSpec::with_resolution(cube.bounding_box().unwrap(), 8).unwrap();
    let go = AtomicBool::new(false);
    let all = gwn::grid::evaluate_until(&wn, &spec, |_| {}, &go).unwrap();
    assert_eq!(all, gwn::grid::evaluate(&wn, &spec));
    let stop = AtomicBool::new(true);
    assert!(gwn::grid::evaluate_until(&wn, &spec, |_| {}, &stop).is_none());
    let sdf = SignedDistance::new(&cube).unwrap();
    assert!(sdf.eval_grid_until(&spec, |_| {}, &stop).is_none());
    assert_eq!(
        sdf.eval_grid_until(&spec, |_| {}, &go).unwrap(),
        sdf.eval_grid(&spec)
    );
}
