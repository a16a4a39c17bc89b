//! SVG read as drawn (usvg: shapes, transforms, viewBox user units, y down) and written in the
//! same convention: every test drawing reads back identically after a write.

use gwn::curve2d::Curves;
use gwn::curve2d::io::{SvgLayer, parse_svg, svg_string};

fn svg(body: &str) -> String {
    format!("<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"200\" height=\"200\">{body}</svg>")
}

/// The test drawings: every shape element, nested and composed transforms, viewBoxes that
/// scale and shift, `<use>`, open and closed subpaths, curves and arcs.
fn drawings() -> Vec<(&'static str, String)> {
    vec![
        ("rect", svg("<rect x='10' y='20' width='30' height='40'/>")),
        (
            "rounded rect + rotate",
            svg("<rect x='10' y='20' width='30' height='40' rx='5' transform='rotate(30 25 40)'/>"),
        ),
        ("circle", svg("<circle cx='50' cy='60' r='10'/>")),
        ("ellipse", svg("<ellipse cx='50' cy='60' rx='30' ry='10' fill='blue'/>")),
        ("polygon", svg("<polygon points='0,0 10,0 10,10 0,10'/>")),
        (
            "open polyline",
            svg("<polyline points='0,0 10,5 20,0 30,5' fill='none' stroke='black'/>"),
        ),
        (
            "nested groups",
            svg("<g transform='translate(100 50)'><g transform='scale(2 3)'>\
                 <path d='M0 0 L10 0 L5 8 Z'/></g></g>"),
        ),
        (
            "matrix + skew",
            svg("<path transform='matrix(1 0.2 -0.3 1 7 9) skewX(10)' d='M0 0 h10 v10 h-10 z'/>"),
        ),
        (
            "viewBox shift and scale",
            "<svg xmlns=\"http://www.w3.org/2000/svg\" viewBox=\"-50 -50 100 100\" width=\"400\" height=\"300\">\
             <path d='M-10 -10 L10 -10 L0 10 Z'/></svg>"
                .to_string(),
        ),
        (
            "use",
            svg("<defs><path id='t' d='M0 0 L4 0 L0 4 Z'/></defs>\
                 <use href='#t' x='10' y='10'/><use href='#t' transform='rotate(90)'/>"),
        ),
        (
            "curves, arcs, open stroke",
            svg("<path d='M10 10 C 20 0 30 20 40 10 S 60 0 70 10 Q 80 30 60 40 A 10 15 20 0 1 30 40 Z'/>\
                 <path d='M100 100 q 10 -20 20 0 t 20 0' fill='none' stroke='red'/>"),
        ),
        (
            "filled unclosed path",
            svg("<path d='M0 0 L10 0 L10 10' fill='green'/>"),
        ),
    ]
}

fn max_diff(a: &Curves, b: &Curves) -> f64 {
    assert_eq!(a.polygon.starts(), b.polygon.starts());
    assert_eq!(a.open, b.open);
    a.polygon
        .points()
        .iter()
        .zip(b.polygon.points())
        .map(|(p, q)| (p[0] - q[0]).abs().max((p[1] - q[1]).abs()))
        .fold(0.0, f64::max)
}

#[test]
fn every_drawing_round_trips_to_1e9() {
    for (name, text) in drawings() {
        let a = parse_svg(&text, name).unwrap_or_else(|e| panic!("{name}: {e}"));
        let out = svg_string(
            &[SvgLayer {
                curves: &a,
                stroke: "black",
                width: 0.01,
            }],
            false,
        );
        let b = parse_svg(&out, "written").unwrap_or_else(|e| panic!("{name}: {e}\n{out}"));
        let d = max_diff(&a, &b);
        assert!(d <= 1e-9, "{name}: round trip moved a vertex by {d}");
    }
}

fn close(p: [f64; 2], q: [f64; 2]) -> bool {
    (p[0] - q[0]).abs() < 1e-4 && (p[1] - q[1]).abs() < 1e-4
}

#[test]
fn shapes_are_read_as_drawn() {
    // A rect: its four corners in document order, y down as in the file.
    let r = parse_svg(&svg("<rect x='10' y='20' width='30' height='40'/>"), "r").unwrap();
    let p = r.polygon.points();
    assert_eq!(p.len(), 4);
    for c in [[10.0, 20.0], [40.0, 20.0], [40.0, 60.0], [10.0, 60.0]] {
        assert!(p.iter().any(|&v| close(v, c)), "{c:?} missing in {p:?}");
    }
    assert_eq!(r.open, vec![false]);
    // SVG's y axis points down: this rect is drawn clockwise on screen, which is a positive
    // (counter-clockwise) loop in its own coordinates.
    assert!(r.polygon.signed_area() > 0.0);

    // Nested transforms: translate(100 50) scale(2 3) applied to (10, 0) and (5, 8).
    let n = parse_svg(
        &svg("<g transform='translate(100 50)'><g transform='scale(2 3)'><path d='M0 0 L10 0 L5 8 Z'/></g></g>"),
        "n",
    )
    .unwrap();
    let p = n.polygon.points();
    for c in [[100.0, 50.0], [120.0, 50.0], [110.0, 74.0]] {
        assert!(p.iter().any(|&v| close(v, c)), "{c:?} missing in {p:?}");
    }
    // rotate(90) maps (4, 0) to (0, 4) and (0, 4) to (−4, 0).
    let u = parse_svg(
        &svg("<path transform='rotate(90)' d='M0 0 L4 0 L0 4 Z'/>"),
        "u",
    )
    .unwrap();
    let p = u.polygon.points();
    for c in [[0.0, 0.0], [0.0, 4.0], [-4.0, 0.0]] {
        assert!(p.iter().any(|&v| close(v, c)), "{c:?} missing in {p:?}");
    }
    // A viewBox changes the viewport, not the user coordinates.
    let v = parse_svg(
        "<svg xmlns=\"http://www.w3.org/2000/svg\" viewBox=\"-50 -50 100 100\" width=\"400\" height=\"300\"><path d='M-10 -10 L10 -10 L0 10 Z'/></svg>",
        "v",
    )
    .unwrap();
    let p = v.polygon.points();
    for c in [[-10.0, -10.0], [10.0, -10.0], [0.0, 10.0]] {
        assert!(p.iter().any(|&v| close(v, c)), "{c:?} missing in {p:?}");
    }
    // A circle: every vertex within the flattening tolerance of the circle, centred right.
    let c = parse_svg(&svg("<circle cx='50' cy='60' r='10'/>"), "c").unwrap();
    let p = c.polygon.points();
    assert!(p.len() >= 8);
    for v in p {
        let r = (v[0] - 50.0).hypot(v[1] - 60.0);
        assert!((r - 10.0).abs() < 0.03, "{v:?} at radius {r}");
    }
    assert_eq!(c.polygon.winding_number([50.0, 60.0]).abs(), 1);
    // Open and closed subpaths.
    let o = parse_svg(
        &svg("<polyline points='0,0 10,5 20,0' fill='none' stroke='black'/><polyline points='0,20 10,25 20,20'/>"),
        "o",
    )
    .unwrap();
    assert_eq!(o.open, vec![true, false]);
    // Hidden elements are not drawn, so not read.
    let h = parse_svg(
        &svg("<rect width='5' height='5'/><rect width='9' height='9' display='none'/>"),
        "h",
    )
    .unwrap();
    assert_eq!(h.polygon.num_loops(), 1);
}

#[test]
fn unreadable_svg_is_one_line_error() {
    for (text, what) in [
        ("<svg", "not a readable SVG"),
        (&svg("") as &str, "no visible shape"),
        (
            &svg("<text x='0' y='0'>hi</text>") as &str,
            "no visible shape",
        ),
    ] {
        let e = parse_svg(text, "bad.svg").unwrap_err().to_string();
        assert!(e.starts_with("bad.svg: ") && e.contains(what), "{e}");
        assert_eq!(e.lines().count(), 1);
    }
}

/// `<image href>` names a file on the document's say-so; the paths are all we read, so no file is
/// opened at all. The old reader opened the href (usvg's default resolver): a FIFO hung it, and
/// `/dev/zero` read until memory ran out.
#[cfg(unix)]
#[test]
fn image_hrefs_are_never_opened() {
    let dir = std::env::temp_dir().join(format!("gwn-svg-{}-href", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    let fifo = dir.join("pipe.png");
    let made = std::process::Command::new("mkfifo")
        .arg(&fifo)
        .status()
        .is_ok_and(|s| s.success());
    if !made {
        println!("skipping: mkfifo is not available");
        return;
    }
    let text = svg(&format!(
        "<image href='{}' width='10' height='10'/><polygon points='0,0 10,0 10,10'/>",
        fifo.display()
    ));
    let (tx, rx) = std::sync::mpsc::channel();
    std::thread::spawn(move || {
        let _ = tx.send(parse_svg(&text, "img.svg"));
    });
    let curves = rx
        .recv_timeout(std::time::Duration::from_secs(20))
        .expect("parsing an SVG whose <image> names a FIFO hangs")
        .unwrap();
    let without = parse_svg(&svg("<polygon points='0,0 10,0 10,10'/>"), "p.svg").unwrap();
    assert_eq!(curves, without);
    let _ = std::fs::remove_dir_all(&dir);
}
