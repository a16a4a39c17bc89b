//! Trimmed B-rep STEP models against the shared reference winding numbers
//! (`../shared/parametric/step/<model>_ref/`). Skips, with a message, when the shared data is
//! absent. Every query of every model must be within the accuracy: closed models the
//! exact integer within 1e-9, open ones within max(1e-7, 3·err) of the reference.

use std::path::{Path, PathBuf};

use gwn::patch::step::{StepWindingNumber, load_step};

fn shared() -> Option<PathBuf> {
    // `../shared` beside the clone (CI); `GWN_SHARED_DIR` points elsewhere (a worktree).
    let base = std::env::var_os("GWN_SHARED_DIR")
        .map(PathBuf::from)
        .unwrap_or_else(|| Path::new(env!("CARGO_MANIFEST_DIR")).join("../shared"));
    let p = base.join("parametric/step");
    if p.join("tet.step").exists() {
        Some(p)
    } else {
        eprintln!(
            "skipping: {} not found (shared STEP models absent)",
            p.display()
        );
        None
    }
}

/// Minimal `.npy` reader for the reference arrays: little-endian `<f8` or `|i1`, C order.
fn npy(path: &Path) -> (Vec<f64>, Vec<usize>) {
    let b = std::fs::read(path).unwrap();
    assert_eq!(&b[..6], b"\x93NUMPY");
    let (hlen, start) = if b[6] == 1 {
        (u16::from_le_bytes([b[8], b[9]]) as usize, 10)
    } else {
        (u32::from_le_bytes([b[8], b[9], b[10], b[11]]) as usize, 12)
    };
    let header = std::str::from_utf8(&b[start..start + hlen]).unwrap();
    assert!(header.contains("'fortran_order': False"));
    let shape_txt = header
        .split("'shape': (")
        .nth(1)
        .unwrap()
        .split(')')
        .next()
        .unwrap();
    let shape: Vec<usize> = shape_txt
        .split(',')
        .filter(|s| !s.trim().is_empty())
        .map(|s| s.trim().parse().unwrap())
        .collect();
    let data = &b[start + hlen..];
    let vals = if header.contains("<f8") {
        data.chunks_exact(8)
            .map(|c| f64::from_le_bytes(c.try_into().unwrap()))
            .collect()
    } else if header.contains("|i1") {
        data.iter().map(|&x| x as i8 as f64).collect()
    } else {
        panic!("unsupported dtype in {header}")
    };
    (vals, shape)
}

struct Refs {
    queries: Vec<[f64; 3]>,
    w: Vec<f64>,
    err: Vec<f64>,
    kind: Vec<i64>,
}

fn refs(dir: &Path, model: &str) -> Refs {
    let d = dir.join(format!("{model}_ref"));
    let (q, shape) = npy(&d.join("queries.npy"));
    assert_eq!(shape[1], 3);
    Refs {
        queries: q.chunks_exact(3).map(|c| [c[0], c[1], c[2]]).collect(),
        w: npy(&d.join("ref.npy")).0,
        err: npy(&d.join("err.npy")).0,
        kind: npy(&d.join("kind.npy"))
            .0
            .into_iter()
            .map(|k| k as i64)
            .collect(),
    }
}

/// Evaluates every query; reports per kind (max error, failures, count) and fails on any query
/// outside the allowed error.
fn check(model: &str, closed: bool) {
    let Some(dir) = shared() else { return };
    let m = load_step(&dir.join(format!("{model}.step"))).unwrap();
    let wn = StepWindingNumber::new(&m);
    let r = refs(&dir, model);
    let picked: Vec<usize> = (0..r.queries.len()).collect();
    let pts: Vec<[f64; 3]> = picked.iter().map(|&i| r.queries[i]).collect();
    let t = std::time::Instant::now();
    let got = wn.eval_batch(&pts);
    let secs = t.elapsed().as_secs_f64();
    let mut worst = [(0.0f64, 0usize, 0usize); 3];
    let mut failures = Vec::new();
    for (j, &i) in picked.iter().enumerate() {
        let k = r.kind[i] as usize;
        let e = (got[j] - r.w[i]).abs();
        let allowed = if closed {
            1e-9
        } else {
            (3.0 * r.err[i]).max(1e-7)
        };
        worst[k].0 = worst[k].0.max(e);
        worst[k].2 += 1;
        if e.is_nan() || e > allowed {
            worst[k].1 += 1;
            if failures.len() < 10 {
                failures.push(format!(
                    "#{i} kind {k} q {:?}: got {} ref {} err {}",
                    r.queries[i], got[j], r.w[i], r.err[i]
                ));
            }
        }
    }
    eprintln!(
        "{model}: {} queries in {secs:.2}s; per kind (max |Δw|, failures, n): {worst:?}",
        pts.len()
    );
    assert!(failures.is_empty(), "{model}: {failures:#?}");
}

#[test]
fn tet_is_exact() {
    check("tet", true);
}

#[test]
fn sliced_cylinder_is_exact() {
    check("sliced_cylinder", true);
}

#[test]
fn boxed_sphere_is_exact() {
    check("boxed_sphere", true);
}

#[test]
fn open_cylinder_matches_reference() {
    check("open_cylinder", false);
}

#[test]
fn spring_matches_reference() {
    check("spring", false);
}
