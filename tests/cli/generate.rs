//! `gwn gen`: the testing kit's cases written to files reload as the same meshes, with the
//! oracle's certified values, bit for bit across runs.

use gwn::RayAxis;
use gwn::testing::{Decision, Kind, Oracle};

fn temp_dir(tag: &str) -> std::path::PathBuf {
    let nanos = std::time::SystemTime::now()
        .duration_since(std::time::UNIX_EPOCH)
        .unwrap()
        .as_nanos();
    let d = std::env::temp_dir().join(format!("gwn-kit-{tag}-{}-{nanos}", std::process::id()));
    std::fs::create_dir_all(&d).unwrap();
    d
}

fn run_gen(out: &std::path::Path, extra: &[&str]) {
    let status = std::process::Command::new(env!("CARGO_BIN_EXE_gwn"))
        .args([
            "gen", "--kind", "all", "--seed", "7", "--count", "4", "--out",
        ])
        .arg(out)
        .args(extra)
        .status()
        .unwrap();
    assert!(status.success());
}

fn read_dir_sorted(d: &std::path::Path) -> Vec<(String, Vec<u8>)> {
    let mut v: Vec<(String, Vec<u8>)> = std::fs::read_dir(d)
        .unwrap()
        .map(|e| {
            let e = e.unwrap();
            (
                e.file_name().to_string_lossy().into_owned(),
                std::fs::read(e.path()).unwrap(),
            )
        })
        .collect();
    v.sort();
    v
}

#[test]
fn gen_output_reloads_and_reproduces_bit_for_bit() {
    let (a, b) = (temp_dir("a"), temp_dir("b"));
    run_gen(&a, &[]);
    run_gen(&b, &[]);
    let (fa, fb) = (read_dir_sorted(&a), read_dir_sorted(&b));
    assert_eq!(fa.len(), 8 * 4 * 4 + 1);
    assert_eq!(fa, fb, "two runs with the same seed differ");
    for kind in Kind::ALL {
        for seed in 7..11u64 {
            let case = kind.generate(seed);
            let stem = format!("{}-{seed}", kind.name());
            for ext in ["obj", "off"] {
                let m = gwn::io::load_mesh(a.join(format!("{stem}.{ext}")))
                    .unwrap()
                    .mesh;
                assert_eq!(m, case.mesh, "{stem}.{ext}");
            }
            // STL stores corners per face; the loader welds them back: same triangles.
            let m = gwn::io::load_mesh(a.join(format!("{stem}.stl")))
                .unwrap()
                .mesh;
            assert_eq!(m.triangles().len(), case.mesh.triangles().len());
            for f in 0..m.triangles().len() {
                assert_eq!(
                    m.triangle_positions(f),
                    case.mesh.triangle_positions(f),
                    "{stem}.stl"
                );
            }
            // The query file: the case's queries with the oracle's certified values.
            let csv = std::fs::read_to_string(a.join(format!("{stem}.queries.csv"))).unwrap();
            let mut lines = csv.lines();
            assert_eq!(lines.next(), Some("x,y,z,lo,hi,inside"));
            let oracle = Oracle::new(&case.mesh, RayAxis::PosZ);
            let rows: Vec<&str> = lines.collect();
            assert_eq!(rows.len(), case.queries.len());
            for (row, &q) in rows.iter().zip(&case.queries) {
                let f: Vec<&str> = row.split(',').collect();
                let x: Vec<f64> = f[..5].iter().map(|s| s.parse().unwrap()).collect();
                assert_eq!(&x[..3], &q[..]);
                let c = oracle.eval(q);
                assert_eq!((x[3], x[4]), (c.lo, c.hi));
                let want = match c.decide(0.5) {
                    Decision::Inside => "1",
                    Decision::Outside => "0",
                    Decision::Undecided => "?",
                };
                assert_eq!(f[5], want);
            }
        }
    }
    // Another ray changes the on-surface values only; an unknown kind is an error.
    let c = temp_dir("c");
    run_gen(&c, &["--ray", "-x"]);
    assert_eq!(read_dir_sorted(&c).len(), fa.len());
    let st = std::process::Command::new(env!("CARGO_BIN_EXE_gwn"))
        .args(["gen", "--kind", "nope", "--out"])
        .arg(&c)
        .output()
        .unwrap();
    assert!(!st.status.success());
    assert!(String::from_utf8_lossy(&st.stderr).contains("unknown kind"));
    // An absurd count is refused before anything is written, in one line.
    let d = temp_dir("d");
    let st = std::process::Command::new(env!("CARGO_BIN_EXE_gwn"))
        .args(["gen", "--kind", "all", "--count", "100000000000", "--out"])
        .arg(&d)
        .output()
        .unwrap();
    assert!(!st.status.success());
    let stderr = String::from_utf8_lossy(&st.stderr);
    assert_eq!(
        stderr.trim(),
        "gwn: --count: 100000000000 cases per kind is above the limit 1000000"
    );
    assert!(read_dir_sorted(&d).is_empty());
    for d in [a, b, c, d] {
        std::fs::remove_dir_all(d).unwrap();
    }
}
