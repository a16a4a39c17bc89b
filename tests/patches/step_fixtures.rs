//! The STEP reader and trimmed-model evaluator on small hand-written fixtures
//! (`tests/fixtures/step/`, CC0), independent of the shared data; malformed input.

use std::f64::consts::PI;
use std::path::Path;

use gwn::patch::step::{StepError, StepWindingNumber, load_step, parse_step};

fn fixture(name: &str) -> std::path::PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("tests/fixtures/step")
        .join(name)
}

#[test]
fn capped_cylinder_is_an_exact_solid() {
    let m = load_step(&fixture("capped_cylinder.step")).unwrap();
    let info = m.info();
    assert_eq!(info.faces, 3);
    assert_eq!(info.boundary_edges, 0, "{info:?}");
    assert_eq!(info.cancelled_exact, 3);
    assert_eq!(info.topology.solids, 1);
    assert_eq!(info.topology.length_unit, "millimetre");
    let wn = StepWindingNumber::new(&m);
    let mut n = 0;
    // Points on a lattice around the cylinder, avoiding the surface itself.
    for i in 0..9 {
        for j in 0..9 {
            for k in 0..7 {
                let q = [
                    -1.6 + 0.4 * i as f64 + 0.013,
                    -1.6 + 0.4 * j as f64 + 0.007,
                    -0.45 + 0.5 * k as f64 + 0.011,
                ];
                let r = q[0].hypot(q[1]);
                if (r - 1.0).abs() < 1e-3 || q[2].abs() < 1e-3 || (q[2] - 2.0).abs() < 1e-3 {
                    continue;
                }
                let inside = r < 1.0 && q[2] > 0.0 && q[2] < 2.0;
                let e = wn.evaluate(q);
                assert!(!e.uncertified, "{q:?}");
                assert_eq!(e.value, if inside { 1.0 } else { 0.0 }, "{q:?} {e:?}");
                n += 1;
            }
        }
    }
    assert!(n > 400);
    // Near the seam line (x = 1, y = 0) and the rims, inside and outside.
    for d in [1e-3, 1e-5, 1e-7] {
        assert_eq!(wn.eval([1.0 - d, 0.0, 1.0]), 1.0);
        assert_eq!(wn.eval([1.0 + d, 0.0, 1.0]), 0.0);
        assert_eq!(wn.eval([1.0 - d, 1e-9, 2.0 - d]), 1.0);
        assert_eq!(wn.eval([0.3, 0.2, -d]), 0.0);
    }
}

/// `w` on the axis of the plate: `−sign(h) (Ω_square − Ω_disk) / 4π`, the normal being `+z`.
fn plate_on_axis(h: f64) -> f64 {
    let a = h.abs();
    let square = 4.0 * (1.0 / (1.0 + a * a)).asin();
    let disk = 2.0 * PI * (1.0 - a / (a * a + 0.25).sqrt());
    -h.signum() * (square - disk) / (4.0 * PI)
}

#[test]
fn plate_with_hole_is_trimmed_and_open() {
    let m = load_step(&fixture("plate_with_hole.stp")).unwrap();
    let info = m.info();
    assert_eq!(info.faces, 1);
    assert_eq!(info.boundary_edges, 5, "{info:?}");
    assert_eq!(info.topology.length_unit, "metre");
    let wn = StepWindingNumber::new(&m);
    for h in [2.0, 0.7, 0.1, 1e-3, -1e-3, -0.4, -3.0] {
        let q = [0.0, 0.0, h];
        let e = wn.evaluate(q);
        assert!(
            (e.value - plate_on_axis(h)).abs() < 1e-9,
            "h {h}: {} vs {} ({e:?})",
            e.value,
            plate_on_axis(h)
        );
    }
    // Crossing the plate: the jump is 1 where the plate is, 0 in the hole and outside.
    for (x, y, jump) in [
        (0.75, 0.1, 1.0),
        (0.1, -0.2, 0.0),
        (1.3, 0.0, 0.0),
        (-0.8, 0.8, 1.0),
    ] {
        let below = wn.eval([x, y, -1e-6]);
        let above = wn.eval([x, y, 1e-6]);
        assert!(
            (below - above - jump).abs() < 1e-5,
            "({x},{y}): {below} {above}"
        );
    }
}

fn minimal(data: &str) -> String {
    format!("ISO-10303-21;\nHEADER;\nENDSEC;\nDATA;\n{data}\nENDSEC;\nEND-ISO-10303-21;\n")
}

fn one_line(e: StepError) -> String {
    let s = e.to_string();
    assert!(!s.contains('\n') && !s.is_empty(), "{s}");
    s
}

#[test]
fn malformed_files_are_one_line_errors() {
    let good = std::fs::read_to_string(fixture("capped_cylinder.step")).unwrap();
    // Truncated at every tenth byte: never a panic, always one line.
    for cut in (0..good.len()).step_by(10) {
        if let Err(e) = parse_step(&good[..cut]) {
            one_line(e);
        }
    }
    let truncated = one_line(parse_step(&good[..good.len() / 2]).unwrap_err());
    assert!(truncated.starts_with("line "), "{truncated}");
    // Unknown surface entity, named with its #id.
    let unknown = good.replace("#14=PLANE('',#10);", "#14=OFFSET_SURFACE('',#12,0.1,.F.);");
    let e = one_line(parse_step(&unknown).unwrap_err());
    assert!(e.contains("#14") && e.contains("OFFSET_SURFACE"), "{e}");
    // Dangling reference.
    let dangling = good.replace(
        "#12=CYLINDRICAL_SURFACE('',#10,1.);",
        "#12=CYLINDRICAL_SURFACE('',#99,1.);",
    );
    let e = one_line(parse_step(&dangling).unwrap_err());
    assert!(e.contains("#12") && e.contains("#99"), "{e}");
    // Wrong parameter type.
    let bad = good.replace(
        "#12=CYLINDRICAL_SURFACE('',#10,1.);",
        "#12=CYLINDRICAL_SURFACE('',#10,'one');",
    );
    let e = one_line(parse_step(&bad).unwrap_err());
    assert!(e.contains("#12 CYLINDRICAL_SURFACE"), "{e}");
    // Absurd B-spline counts: degree, multiplicities, knot count.
    for (deg, mults, knots) in [
        ("99", "(100,100)", "(0.,1.)"),
        ("3", "(4000000000,4)", "(0.,1.)"),
        ("3", "(4,4)", "(0.,1.,2.)"),
        ("-2", "(4,4)", "(0.,1.)"),
    ] {
        let curve = format!(
            "#30=B_SPLINE_CURVE_WITH_KNOTS('',{deg},(#20,#20,#21,#21),.UNSPECIFIED.,.F.,.F.,{mults},{knots},.UNSPECIFIED.);"
        );
        let text = good.replace("#30=CIRCLE('',#10,1.);", &curve);
        let e = one_line(parse_step(&text).unwrap_err());
        assert!(e.contains("#30"), "{e}");
    }
    // No faces; nesting too deep; duplicate id.
    one_line(parse_step(&minimal("#1=CARTESIAN_POINT('',(0.,0.,0.));")).unwrap_err());
    one_line(
        parse_step(&minimal(&format!(
            "#1=A({}1{});",
            "(".repeat(40),
            ")".repeat(40)
        )))
        .unwrap_err(),
    );
    one_line(parse_step(&minimal("#1=A(1);\n#1=A(2);")).unwrap_err());
    // A huge count in the text is not an allocation: a list of a million references to
    // nothing fails on the first dangling one.
    let many = format!(
        "#1=CLOSED_SHELL('',({}));\n#2=MANIFOLD_SOLID_BREP('',#1);",
        vec!["#5"; 100_000].join(",")
    );
    let e = one_line(parse_step(&minimal(&many)).unwrap_err());
    assert!(e.contains("#5"), "{e}");
    // Missing file.
    one_line(load_step(Path::new("/nonexistent/x.step")).unwrap_err());
}
