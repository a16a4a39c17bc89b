//! `gwn curve field|untangle|offset` on a text polygon, and a bad input as a one-line error
//! naming the file and line.

use std::f64::consts::PI;
use std::process::Command;

use gwn::curve2d::Polygon;

fn circle(r: f64, n: usize) -> Polygon {
    let pts = (0..n)
        .map(|i| {
            let t = 2.0 * PI * i as f64 / n as f64;
            [r * t.cos(), r * t.sin()]
        })
        .collect();
    Polygon::new(vec![pts]).unwrap()
}

fn temp_dir(name: &str) -> std::path::PathBuf {
    let d = std::env::temp_dir().join(format!("gwn-curve2d-{name}-{}", std::process::id()));
    std::fs::create_dir_all(&d).unwrap();
    d
}

fn write_text(p: &Polygon) -> String {
    let mut s = String::from("# test polygon\n");
    for k in 0..p.num_loops() {
        for v in p.loop_points(k) {
            s.push_str(&format!("{} {}\n", v[0], v[1]));
        }
        s.push('\n');
    }
    s
}

#[test]
fn cli_smoke() {
    let exe = env!("CARGO_BIN_EXE_gwn");
    let dir = temp_dir("cli");
    let input = dir.join("circle.txt");
    std::fs::write(&input, write_text(&circle(1.0, 64))).unwrap();
    let png = dir.join("field.png");
    let st = Command::new(exe)
        .args(["curve", "field"])
        .arg(&input)
        .args(["--sigma", "0.05", "--res", "48", "--out"])
        .arg(&png)
        .output()
        .unwrap();
    assert!(
        st.status.success(),
        "{}",
        String::from_utf8_lossy(&st.stderr)
    );
    let bytes = std::fs::read(&png).unwrap();
    assert_eq!(&bytes[1..4], b"PNG");
    for (sub, extra) in [("untangle", vec![]), ("offset", vec!["--distance", "0.1"])] {
        let out = dir.join(format!("{sub}.svg"));
        let st = Command::new(exe)
            .args(["curve", sub])
            .arg(&input)
            .args(extra)
            .arg("--out")
            .arg(&out)
            .output()
            .unwrap();
        assert!(
            st.status.success(),
            "{}",
            String::from_utf8_lossy(&st.stderr)
        );
        let svg = gwn::curve2d::io::read_polygon(&out).unwrap();
        assert_eq!(svg.num_loops(), 2); // input and result layers
    }
    // A bad input: non-zero exit and a single line naming the file and line.
    let bad = dir.join("bad.txt");
    std::fs::write(&bad, "0 0\n1 0\n1 oops\n").unwrap();
    let st = Command::new(exe)
        .args(["curve", "field"])
        .arg(&bad)
        .arg("--out")
        .arg(dir.join("x.png"))
        .output()
        .unwrap();
    assert!(!st.status.success());
    let err = String::from_utf8_lossy(&st.stderr);
    assert_eq!(err.trim_end().lines().count(), 1, "{err}");
    assert!(err.contains("bad.txt:3"), "{err}");
    let _ = std::fs::remove_dir_all(&dir);
}
