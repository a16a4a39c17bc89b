//! The STEP reader and trimmed-model evaluator on small hand-written fixtures
//! (`tests/fixtures/step/`, CC0), independent of the shared data; malformed input.

use std::f64::consts::{FRAC_PI_2, PI, TAU};
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

/// The crossings of the segment `a → b` with the capped cylinder (radius 1, `0 ≤ z ≤ 2`) in
/// closed form, as `(t, unit normal)`; `None` when one lies within `margin` of a rim, grazes,
/// or an end lies within `margin` of the surface (where a proposal may rightly differ).
fn capped_cylinder_crossings(
    a: [f64; 3],
    b: [f64; 3],
    margin: f64,
) -> Option<Vec<(f64, [f64; 3])>> {
    let d = [b[0] - a[0], b[1] - a[1], b[2] - a[2]];
    let at = |t: f64| [a[0] + t * d[0], a[1] + t * d[1], a[2] + t * d[2]];
    let mut out = Vec::new();
    let (qa, qb, qc) = (
        d[0] * d[0] + d[1] * d[1],
        2.0 * (a[0] * d[0] + a[1] * d[1]),
        a[0] * a[0] + a[1] * a[1] - 1.0,
    );
    if qa > 0.0 && qb * qb - 4.0 * qa * qc > 0.0 {
        let root = (qb * qb - 4.0 * qa * qc).sqrt();
        for t in [(-qb - root) / (2.0 * qa), (-qb + root) / (2.0 * qa)] {
            let p = at(t);
            if (0.0..=1.0).contains(&t) && (-margin..=2.0 + margin).contains(&p[2]) {
                if p[2].abs() < margin || (p[2] - 2.0).abs() < margin {
                    return None;
                }
                let n = [p[0], p[1], 0.0];
                let cosine =
                    (n[0] * d[0] + n[1] * d[1]) / (d.iter().map(|x| x * x).sum::<f64>()).sqrt();
                if cosine.abs() < 0.05 {
                    return None;
                }
                out.push((t, n));
            }
        }
    }
    for cap in [0.0, 2.0] {
        if d[2] != 0.0 {
            let t = (cap - a[2]) / d[2];
            let p = at(t);
            let r = p[0].hypot(p[1]);
            if (0.0..=1.0).contains(&t) && r <= 1.0 + margin {
                if (r - 1.0).abs() < margin {
                    return None;
                }
                out.push((t, [0.0, 0.0, 1.0]));
            }
        }
    }
    let off_surface = |p: [f64; 3]| {
        let r = p[0].hypot(p[1]);
        (r - 1.0).abs() > margin && p[2].abs() > margin && (p[2] - 2.0).abs() > margin
    };
    if !off_surface(a) || !off_surface(b) {
        return None;
    }
    out.sort_by(|x, y| x.0.total_cmp(&y.0));
    Some(out)
}

/// A STEP model's segment crossings, which the remesher verifies in place of searching the
/// field: on the capped cylinder, short segments along the axes, the face diagonals and
/// oblique directions (the remesher's lattice edges, and others) get exactly the closed-form
/// crossings, normals included, and none past their end although the ray goes on to the
/// surface.
/// Directions of the segment-crossing tests: the axes, face and body diagonals, and an oblique
/// one.
pub(crate) const SEGMENT_DIRECTIONS: [[f64; 3]; 7] = [
    [1.0, 0.0, 0.0],
    [0.0, 1.0, 0.0],
    [0.0, 0.0, 1.0],
    [1.0, 1.0, 0.0],
    [0.0, 1.0, -1.0],
    [1.0, -1.0, 1.0],
    [0.3, 0.7, -0.2],
];

/// `found`, the segment `a → b`'s crossings, are `expected` (`t` and the unit normal, either
/// sign): `t` within 1e-9, normals parallel within 1e-9.
pub(crate) fn assert_crossings_are(
    a: [f64; 3],
    b: [f64; 3],
    found: &[gwn::eval::SurfaceCrossing],
    expected: &[(f64, [f64; 3])],
) {
    assert_eq!(
        found.len(),
        expected.len(),
        "{a:?} → {b:?}: {found:?} vs {expected:?}"
    );
    for (f, (t, n)) in found.iter().zip(expected) {
        assert!((f.t - t).abs() < 1e-9, "{a:?} → {b:?}: t {} vs {t}", f.t);
        let along = f.normal.iter().zip(n).map(|(x, y)| x * y).sum::<f64>();
        assert!(
            (along.abs() - 1.0).abs() < 1e-9,
            "{a:?} → {b:?}: normal {:?} vs {n:?}",
            f.normal
        );
    }
}

#[test]
fn segment_crossings_are_the_closed_form_ones() {
    let m = load_step(&fixture("capped_cylinder.step")).unwrap();
    let wn = StepWindingNumber::new(&m);
    let mut state = 0x2545_f491_4f6c_dd1du64;
    let mut next = move || {
        state ^= state << 13;
        state ^= state >> 7;
        state ^= state << 17;
        (state >> 11) as f64 / (1u64 << 53) as f64
    };
    let directions = SEGMENT_DIRECTIONS;
    let (mut checked, mut crossings) = (0, 0);
    for k in 0..5000 {
        let a = [3.0 * next() - 1.5, 3.0 * next() - 1.5, 3.0 * next() - 0.5];
        let d = directions[k % directions.len()];
        let length = 0.05 + 0.4 * next();
        let scale = length / d.iter().map(|x| x * x).sum::<f64>().sqrt();
        let b = [
            a[0] + scale * d[0],
            a[1] + scale * d[1],
            a[2] + scale * d[2],
        ];
        let Some(expected) = capped_cylinder_crossings(a, b, 1e-3) else {
            continue;
        };
        assert_crossings_are(a, b, &wn.segment_crossings(a, b), &expected);
        checked += 1;
        crossings += expected.len();
    }
    assert!(
        checked > 2500 && crossings > 300,
        "{checked} segments, {crossings} crossings"
    );
    // Inside the cylinder, towards the wall: nothing before it, one crossing once it reaches.
    assert!(
        wn.segment_crossings([0.0, 0.0, 1.0], [0.5, 0.0, 1.0])
            .is_empty()
    );
    let through = wn.segment_crossings([0.0, 0.0, 1.0], [1.5, 0.0, 1.0]);
    assert_eq!(through.len(), 1, "{through:?}");
    assert!((through[0].t - 2.0 / 3.0).abs() < 1e-9);
    // Degenerate and non-finite segments have none.
    assert!(wn.segment_crossings([0.5; 3], [0.5; 3]).is_empty());
    assert!(
        wn.segment_crossings([f64::NAN, 0.0, 1.0], [1.5, 0.0, 1.0])
            .is_empty()
    );
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

/// Grid columns share one ray per column (`evaluate_column`, the paper's ray reuse) and give
/// the closed-form values: the capped cylinder's integers along every axis (lines parallel to
/// the wall, through the seam plane, across the caps), the open plate's solid angle on its
/// axis, and `grid::evaluate` goes through the column path.
#[test]
fn grid_columns_share_a_ray_and_give_the_points_values() {
    let m = load_step(&fixture("capped_cylinder.step")).unwrap();
    let wn = StepWindingNumber::new(&m);
    let ts: Vec<f64> = (0..23).map(|k| -1.55 + 0.17 * k as f64).collect();
    let (mut shared, mut total) = (0, 0);
    for axis in 0..3 {
        for a in 0..9 {
            for b in 0..9 {
                let (u, v) = (-1.6 + 0.4 * a as f64 + 0.013, -1.6 + 0.4 * b as f64 + 0.007);
                let mut q = [0.0; 3];
                q[(axis + 1) % 3] = u;
                q[(axis + 2) % 3] = v;
                // Heights along the axis, shifted so that z spans the cylinder [0, 2].
                let heights: Vec<f64> = ts.iter().map(|t| t + 1.0).collect();
                let col = wn.evaluate_column(q, axis, &heights);
                for (e, &t) in col.iter().zip(&heights) {
                    let mut p = q;
                    p[axis] = t;
                    let r = p[0].hypot(p[1]);
                    if (r - 1.0).abs() < 1e-3 || p[2].abs() < 1e-3 || (p[2] - 2.0).abs() < 1e-3 {
                        continue;
                    }
                    let inside = r < 1.0 && p[2] > 0.0 && p[2] < 2.0;
                    assert_eq!(e.value, if inside { 1.0 } else { 0.0 }, "{p:?} {e:?}");
                    assert!(!e.uncertified, "{p:?}");
                    total += 1;
                    shared += usize::from(e.rays == 1);
                }
            }
        }
    }
    // Most points use the column's line (the rest are evaluated on their own).
    assert!(
        total > 4000 && shared * 10 > total * 9,
        "{shared} of {total}"
    );

    let m = load_step(&fixture("plate_with_hole.stp")).unwrap();
    let wn = StepWindingNumber::new(&m);
    let hs = [-3.0, -0.4, -1e-3, 1e-3, 0.1, 0.7, 2.0];
    for (e, &h) in wn.evaluate_column([0.0, 0.0, 0.0], 2, &hs).iter().zip(&hs) {
        assert!((e.value - plate_on_axis(h)).abs() < 1e-9, "h {h}: {e:?}");
        assert_eq!(e.rays, 1, "h {h}: {e:?}");
    }

    let spec = gwn::grid::GridSpec::new(
        gwn::BoundingBox {
            min: [-1.5, -1.5, -0.5],
            max: [1.5, 1.5, 0.5],
        },
        [6, 7, 8],
    )
    .unwrap();
    let by_columns = gwn::grid::evaluate(&wn, &spec);
    let by_points = gwn::grid::evaluate_per_point(&wn, &spec);
    for (a, b) in by_columns.iter().zip(&by_points) {
        assert!((a - b).abs() < 1e-9, "{a} {b}");
    }
}

/// A column reaching far beyond the model (1e12 and 1e300 away) keeps the values of the points
/// near it and gives the far points' (0 for the closed cylinder, ~0 for the plate).
#[test]
fn far_reaching_columns_keep_their_near_values() {
    let m = load_step(&fixture("capped_cylinder.step")).unwrap();
    let wn = StepWindingNumber::new(&m);
    let ts = [-1e300, -1e12, -0.5, 0.3, 1.0, 1.7, 2.5, 1e12, 1e300];
    let want = [0.0, 0.0, 0.0, 1.0, 1.0, 1.0, 0.0, 0.0, 0.0];
    let col = wn.evaluate_column([0.2, -0.3, 0.0], 2, &ts);
    for ((e, &w), &t) in col.iter().zip(&want).zip(&ts) {
        assert_eq!(e.value, w, "z = {t}: {e:?}");
    }
    let m = load_step(&fixture("plate_with_hole.stp")).unwrap();
    let wn = StepWindingNumber::new(&m);
    let ts = [-1e300, -1e12, -0.4, 0.7, 1e12, 1e300];
    for (e, &h) in wn.evaluate_column([0.0, 0.0, 0.0], 2, &ts).iter().zip(&ts) {
        // (The closed form itself overflows at 1e300, where w is below 1e-300.)
        let want = if h.abs() > 1e100 {
            0.0
        } else {
            plate_on_axis(h)
        };
        assert!((e.value - want).abs() < 1e-9, "h {h}: {e:?}");
    }
}

/// The fixture torus (`tests/fixtures/step/torus_*.step`): major radius 2, minor 0.5, axis z.
fn torus_point(u: f64, v: f64) -> [f64; 3] {
    let rr = 2.0 + 0.5 * v.cos();
    [rr * u.cos(), rr * u.sin(), 0.5 * v.sin()]
}

/// The outward unit normal of the fixture torus.
fn torus_normal(u: f64, v: f64) -> [f64; 3] {
    [v.cos() * u.cos(), v.cos() * u.sin(), v.sin()]
}

/// The winding number of the torus patch `[u0, u1] × [v0, v1]` (normal outward) by the
/// direct solid-angle sum over an `n × n` grid of triangles, Richardson-extrapolated from `n`
/// and `2n` (the tessellation error is O(h²)); returns the value and the change.
fn torus_patch_by_tessellation(
    u: [f64; 2],
    v: [f64; 2],
    n: usize,
    q: &[[f64; 3]],
) -> Vec<(f64, f64)> {
    let mesh = |n: usize| {
        let mut pos = Vec::new();
        for i in 0..=n {
            for j in 0..=n {
                let (s, t) = (i as f64 / n as f64, j as f64 / n as f64);
                pos.push(torus_point(
                    u[0] + s * (u[1] - u[0]),
                    v[0] + t * (v[1] - v[0]),
                ));
            }
        }
        let id = |i: usize, j: usize| (i * (n + 1) + j) as u32;
        let mut tris = Vec::new();
        for i in 0..n {
            for j in 0..n {
                // (u, v) counter-clockwise: the normal is S_u × S_v, outward.
                tris.push([id(i, j), id(i + 1, j), id(i + 1, j + 1)]);
                tris.push([id(i, j), id(i + 1, j + 1), id(i, j + 1)]);
            }
        }
        gwn::Mesh::new(pos, tris).unwrap()
    };
    let coarse = gwn::eval::direct::winding_number_direct_batch(&mesh(n), q);
    let fine = gwn::eval::direct::winding_number_direct_batch(&mesh(2 * n), q);
    coarse
        .iter()
        .zip(&fine)
        .map(|(&c, &f)| ((4.0 * f - c) / 3.0, (f - c).abs()))
        .collect()
}

#[test]
fn full_torus_is_an_exact_solid() {
    // One face bounded only by its two seams (each used twice): a doubly periodic domain
    // whose loops carry no boundary at all.
    let m = load_step(&fixture("torus_full.step")).unwrap();
    let info = m.info();
    assert_eq!((info.faces, info.boundary_edges), (1, 0), "{info:?}");
    let wn = StepWindingNumber::new(&m);
    let mut inside = 0;
    for i in 0..11 {
        for j in 0..11 {
            for k in 0..5 {
                let q = [
                    -2.9 + 0.58 * i as f64 + 0.0123,
                    -2.9 + 0.58 * j as f64 + 0.0071,
                    -0.7 + 0.35 * k as f64 + 0.0037,
                ];
                let d = ((q[0].hypot(q[1]) - 2.0).powi(2) + q[2] * q[2]).sqrt();
                if (d - 0.5).abs() < 1e-3 {
                    continue;
                }
                let e = wn.evaluate(q);
                assert!(!e.uncertified, "{q:?}");
                let expected = if d < 0.5 { 1.0 } else { 0.0 };
                assert_eq!(e.value, expected, "{q:?} {e:?}");
                inside += usize::from(d < 0.5);
            }
        }
    }
    assert!(inside > 20, "{inside}");
    // Just inside and outside the surface all around both seams and across v = ±π.
    for (u, v) in [
        (0.0, 0.0),
        (0.0, 3.0),
        (3.1, PI + 1e-5),
        (-1.0, -PI - 1e-5),
        (4.0, 0.0),
    ] {
        let (p, n) = (torus_point(u, v), torus_normal(u, v));
        for d in [1e-3, 1e-5] {
            let at = |s: f64| [p[0] + s * n[0], p[1] + s * n[1], p[2] + s * n[2]];
            assert_eq!(wn.eval(at(-d)), 1.0, "({u}, {v}) {d}");
            assert_eq!(wn.eval(at(d)), 0.0, "({u}, {v}) {d}");
        }
    }
}

/// Checks a torus face against the direct sum over a fine tessellation of the same trimmed
/// domain, and the unit jump across the face where it is and only there.
fn check_torus_face(name: &str, u: [f64; 2], v: [f64; 2], boundary_edges: usize) {
    let m = load_step(&fixture(name)).unwrap();
    assert_eq!(m.info().boundary_edges, boundary_edges, "{:?}", m.info());
    let wn = StepWindingNumber::new(&m);
    let mut q = Vec::new();
    for i in 0..4 {
        for j in 0..4 {
            for k in 0..3 {
                q.push([
                    -2.7 + 1.8 * i as f64 + 0.011,
                    -2.7 + 1.8 * j as f64 + 0.023,
                    -0.9 + 0.9 * k as f64 + 0.017,
                ]);
            }
        }
    }
    // Near the face: inside the tube and off it, at the inner equator (v = π).
    for (a, b, s) in [
        (0.7, 3.1, -0.2),
        (0.7, 3.1, 0.2),
        (1.2, 1.0, -0.1),
        (2.0, 3.0, 0.3),
    ] {
        let (p, n) = (torus_point(a, b), torus_normal(a, b));
        q.push([p[0] + s * n[0], p[1] + s * n[1], p[2] + s * n[2]]);
    }
    let reference = torus_patch_by_tessellation(u, v, 160, &q);
    for (k, &p) in q.iter().enumerate() {
        let e = wn.evaluate(p);
        let (r, change) = reference[k];
        assert!(
            !e.uncertified && (e.value - r).abs() < 1e-6 + change,
            "{name} {p:?}: {} vs tessellation {r} (±{change}) {e:?}",
            e.value
        );
    }
    // The jump across the surface: 1 inside the face's domain, 0 outside (u and v wrapped).
    let in_face = |a: f64, b: f64| {
        let wrap = |x: f64, lo: f64| lo + (x - lo).rem_euclid(TAU);
        wrap(a, u[0]) < u[1] && wrap(b, v[0]) < v[1]
    };
    for (a, b) in [
        (0.3, PI),
        (1.2, PI + 0.01),
        (0.8, -PI + 0.2),
        (0.2, 2.0),
        (0.8, 0.3),
        (1.4, -0.2),
        (2.5, PI),
        (-0.4, 3.0),
        (4.0, 0.1),
        (0.05, 1.6),
        (1.5, 4.7),
    ] {
        let (p, n) = (torus_point(a, b), torus_normal(a, b));
        let at = |s: f64| [p[0] + s * n[0], p[1] + s * n[1], p[2] + s * n[2]];
        let jump = wn.eval(at(-1e-6)) - wn.eval(at(1e-6));
        let expected = if in_face(a, b) { 1.0 } else { 0.0 };
        assert!(
            (jump - expected).abs() < 1e-4,
            "{name} ({a}, {b}): jump {jump}, expected {expected}"
        );
    }
}

#[test]
fn torus_patch_across_the_v_seam_is_trimmed() {
    // u ∈ [0, π/2], v ∈ [π/2, 3π/2]: its loop runs across v = π, where the inversion's atan2
    // wraps; the loop is unwrapped along its edges.
    check_torus_face(
        "torus_patch.step",
        [0.0, FRAC_PI_2],
        [FRAC_PI_2, 1.5 * PI],
        4,
    );
}

#[test]
fn torus_band_wrapping_in_v_is_trimmed() {
    // u ∈ [0, π/2], every v: two loops running once around v, crossed by no column of the
    // parameter plane (the row decides).
    check_torus_face("torus_band.step", [0.0, FRAC_PI_2], [-PI, PI], 2);
}

#[test]
fn oblique_trim_on_rational_arcs() {
    // A cylinder face cut by an ellipse that crosses its rational quarter-arc patches
    // obliquely. A hit's u must be the cylinder's angle, not the arc's patch parameter read
    // linearly (off by up to ~1°, which moves the top curve by up to 8e-3 here and made
    // boxed_sphere.step count a fillet hit twice): the jump across the face is 1 just below the
    // curve and 0 just above it, all around.
    let m = load_step(&fixture("sliced_tube.step")).unwrap();
    assert_eq!(m.info().boundary_edges, 2, "{:?}", m.info());
    let wn = StepWindingNumber::new(&m);
    for deg in [
        7.0, 20.0, 33.0, 67.0, 110.0, 160.0, 200.0, 250.0, 290.0, 315.0, 350.0,
    ] {
        let u: f64 = deg * PI / 180.0;
        let top = 1.0 + 0.5 * u.cos();
        for (dz, expected) in [(-3e-3, 1.0), (3e-3, 0.0), (-0.3, 1.0), (0.1, 0.0)] {
            let z = top + dz;
            let at = |r: f64| [r * u.cos(), r * u.sin(), z];
            // 2e-5 off the surface: beyond the hit margin, close enough that the boundary term
            // changes by < 1e-2 between the two points. (3e-3 from the top curve no ray passes
            // the strict boundary certificate; the relaxed pass decides the hits the same way.)
            let jump = wn.eval(at(1.0 - 2e-5)) - wn.eval(at(1.0 + 2e-5));
            assert!(
                (jump - expected).abs() < 1e-2,
                "u {deg}°, z = top {dz:+}: jump {jump}, expected {expected}"
            );
        }
    }
}

/// `capped_cylinder_pcurves.step`: the capped cylinder whose 3D edges lie 1e-3 outside its
/// faces (circles of radius 1.001) while the pcurves give the true circles. Mapped from 3D,
/// the disks overhang the side by 1e-3 and a ray from just outside the wall through that ring
/// counts a crossing; trimmed by the pcurves, the solid is closed and every ray agrees.
#[test]
fn pcurves_trim_the_faces_where_the_3d_edges_stray() {
    let text = std::fs::read_to_string(fixture("capped_cylinder_pcurves.step")).unwrap();
    let with = parse_step(&text).unwrap();
    let info = with.info();
    // Top and bottom disks 1 use each, the side 4 (two circles, the seam twice).
    assert_eq!(info.pcurve_uses, 6, "{info:?}");
    assert_eq!((info.pcurves_rejected, info.pcurves_unreadable), (0, 0));
    // The same file with its pcurves hidden: every use mapped from 3D.
    let without = parse_step(&text.replace("PCURVE(", "NOT_A_PCURVE(")).unwrap();
    assert_eq!(without.info().pcurve_uses, 0);
    let (a, b) = (
        StepWindingNumber::new(&with),
        StepWindingNumber::new(&without),
    );
    // Just outside the wall, below the top rim's overhang and above the bottom's.
    for q in [
        [1.0005, 0.0, 1.9999],
        [0.0, -1.0004, 1.9998],
        [-0.7075, 0.7075, 1e-4],
    ] {
        let mut overhang = 0;
        for &d in a.directions() {
            let ea = a.evaluate_along(q, d).map(|e| e.value);
            assert!(ea.is_none() || ea == Some(0.0), "{q:?} {d:?} {ea:?}");
            overhang += usize::from(b.evaluate_along(q, d).map(|e| e.value) == Some(1.0));
        }
        assert!(overhang >= 4, "{q:?}: {overhang} rays through the overhang");
        let e = a.evaluate(q);
        assert_eq!((e.value, e.uncertified), (0.0, false), "{q:?} {e:?}");
    }
    // Mapped from 3D, the first certified ray at the first two points passes through the
    // overhang and counts 1. It passes within `CLEAR_MARGIN` of the rim's loops, so the
    // evaluator takes it only if a second ray agrees: it does not, and the answer is 0 even
    // for the mis-trimmed model.
    for q in [[1.0005, 0.0, 1.9999], [0.0, -1.0004, 1.9998]] {
        let first = b.directions().iter().find_map(|&d| b.evaluate_along(q, d));
        assert_eq!(first.map(|e| e.value), Some(1.0), "{q:?}");
        let e = b.evaluate(q);
        assert_eq!((e.value, e.uncertified), (0.0, false), "{q:?} {e:?}");
    }
    // Inside the wall and on a lattice, the pcurve-trimmed model is the exact solid.
    for q in [
        [0.9995, 0.0, 1.9999],
        [0.0, 0.9996, 1e-4],
        [-0.9995, 1e-9, 1.0],
    ] {
        assert_eq!(a.eval(q), 1.0, "{q:?}");
    }
    for i in 0..6 {
        for k in 0..5 {
            let q = [
                -1.5 + 0.6 * i as f64 + 0.013,
                0.011,
                -0.45 + 0.6 * k as f64 + 0.017,
            ];
            let r = q[0].hypot(q[1]);
            let inside = r < 1.0 && q[2] > 0.0 && q[2] < 2.0;
            assert_eq!(a.eval(q), if inside { 1.0 } else { 0.0 }, "{q:?}");
        }
    }
    // A pcurve in the wrong place (the disks' circle of radius 2: 1 from the 3D edge) is
    // refused, and those uses are mapped from 3D.
    let wrong =
        parse_step(&text.replace("#104=CIRCLE('',#103,1.)", "#104=CIRCLE('',#103,2.)")).unwrap();
    let info = wrong.info();
    assert_eq!(
        (info.pcurve_uses, info.pcurves_rejected),
        (4, 2),
        "{info:?}"
    );
}

/// `load_step` keeps the kind of every error (`StepError::cause`) and names the file in its one
/// line: I/O, syntax, dangling reference, unsupported entity, invalid parameters, geometry, no
/// faces. (`TooLarge` needs a 256 MiB file or 4·10⁶ instances: not written here.)
#[test]
fn load_errors_keep_their_kind_and_name_the_file() {
    let dir = std::env::temp_dir().join(format!("gwn-step-errors-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let good = std::fs::read_to_string(fixture("capped_cylinder.step")).unwrap();
    let load = |name: &str, text: &str| {
        let path = dir.join(name);
        std::fs::write(&path, text).unwrap();
        let e = load_step(&path).unwrap_err();
        let line = e.to_string();
        assert!(!line.contains('\n'), "{line}");
        assert!(line.starts_with(&format!("{}: ", path.display())), "{line}");
        assert_eq!(e.path(), Some(path.as_path()));
        e
    };
    let missing = dir.join("missing.step");
    let e = load_step(&missing).unwrap_err();
    assert!(
        matches!(&e, StepError::Io { kind: std::io::ErrorKind::NotFound, path, .. } if path == &missing),
        "{e:?}"
    );
    assert!(
        e.to_string()
            .starts_with(&format!("{}: ", missing.display()))
    );
    let e = load("truncated.step", &good[..good.len() / 2]);
    assert!(matches!(e.cause(), StepError::Syntax { .. }), "{e:?}");
    let e = load(
        "dangling.step",
        &good.replace(
            "#12=CYLINDRICAL_SURFACE('',#10,1.);",
            "#12=CYLINDRICAL_SURFACE('',#99,1.);",
        ),
    );
    assert_eq!(e.cause(), &StepError::Dangling { id: 12, target: 99 });
    let e = load(
        "offset.step",
        &good.replace("#14=PLANE('',#10);", "#14=OFFSET_SURFACE('',#12,0.1,.F.);"),
    );
    assert!(
        matches!(e.cause(), StepError::Unsupported { id: 14, entity, .. } if entity == "OFFSET_SURFACE"),
        "{e:?}"
    );
    assert!(
        e.to_string()
            .ends_with("#14 OFFSET_SURFACE: not supported as a face surface"),
        "{e}"
    );
    let e = load(
        "invalid.step",
        &good.replace(
            "#12=CYLINDRICAL_SURFACE('',#10,1.);",
            "#12=CYLINDRICAL_SURFACE('',#10,-1.);",
        ),
    );
    assert!(
        matches!(e.cause(), StepError::Invalid { id: 12, .. }),
        "{e:?}"
    );
    // A line edge from a vertex back to itself: well-formed parameters, no edge.
    let e = load(
        "geometry.step",
        &good.replace(
            "#42=EDGE_CURVE('',#22,#23,#32,.T.);",
            "#42=EDGE_CURVE('',#22,#22,#32,.T.);",
        ),
    );
    assert!(
        matches!(e.cause(), StepError::Geometry { id: 42, entity, .. } if entity == "EDGE_CURVE"),
        "{e:?}"
    );
    let e = load("empty.step", &minimal("#1=CARTESIAN_POINT('',(0.,0.,0.));"));
    assert_eq!(e.cause(), &StepError::NoFaces);
    std::fs::remove_dir_all(&dir).ok();
}

/// A tolerance that is not a finite positive number is refused, not replaced by the default.
#[test]
fn evaluator_refuses_a_bad_tolerance() {
    use gwn::patch::ToleranceError;
    use gwn::patch::step::StepOptions;
    let m = load_step(&fixture("capped_cylinder.step")).unwrap();
    for t in [f64::NAN, -1e-8, 0.0, f64::INFINITY] {
        let e = StepWindingNumber::with_options(&m, StepOptions { tolerance: t }).unwrap_err();
        assert_eq!(e.to_string(), ToleranceError(t).to_string());
        assert!(e.to_string().contains(&t.to_string()), "{e}");
    }
    let wn = StepWindingNumber::with_options(&m, StepOptions { tolerance: 1e-6 }).unwrap();
    assert_eq!(wn.eval([0.1, 0.2, 1.0]), 1.0);
}

/// On the plate's boundary (its outer square, corners included, and the hole's circle) the
/// principal value is 0 exactly: the plate is flat, and a flat region seen from a point in its
/// plane subtends no solid angle. Every qualifying ray gives it; the value is certified.
#[test]
fn plate_boundary_gets_the_principal_value() {
    let m = load_step(&fixture("plate_with_hole.stp")).unwrap();
    let wn = StepWindingNumber::new(&m);
    let a = 1.1_f64;
    for c in [
        [1.0, 0.3, 0.0],
        [-0.2, -1.0, 0.0],
        [-1.0, 0.9, 0.0],
        [1.0, 1.0, 0.0],
        [-1.0, -1.0, 0.0],
        [0.5 * a.cos(), 0.5 * a.sin(), 0.0],
        [-0.5, 0.0, 0.0],
    ] {
        let e = wn.evaluate(c);
        assert!(!e.uncertified && e.value.abs() < 1e-9, "{c:?} {e:?}");
        let mut rays = 0;
        for &d in wn.directions() {
            if let Some(f) = wn.evaluate_on_boundary_along(c, d) {
                assert!(f.value.abs() < 1e-9, "{c:?} {d:?} {f:?}");
                rays += 1;
            }
        }
        assert!(rays >= 6, "{c:?}: {rays}");
        // Just off the boundary the rule does not apply.
        assert!(
            wn.evaluate_on_boundary_along([c[0], c[1], 1e-9], wn.directions()[0])
                .is_none()
        );
    }
}
