//! Dataset labelling: labels against closed forms and the direct sum, byte-for-byte
//! reproducibility (across runs, thread counts and list order), resumption, failures and time
//! limits as manifest rows, and the `gwn label` command.

mod common;

use std::path::{Path, PathBuf};
use std::process::Command;
use std::time::Duration;

use gwn::eval::direct::winding_number_direct;
use gwn::products::label::{
    JobOptions, Labels, SamplingOptions, Status, label_dataset, label_mesh, sample_points,
};

fn fixture(name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("tests/fixtures")
        .join(name)
}

/// A fresh scratch directory for one test.
fn scratch(name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("gwn-label-{}-{name}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).unwrap();
    d
}

fn small(seed: u64) -> SamplingOptions {
    SamplingOptions {
        uniform: 300,
        near: 300,
        sigmas: vec![0.01, 0.1],
        padding: 0.1,
        seed,
    }
}

/// Distance from `q` to the surface of the unit cube, negative inside.
fn cube_sdf(q: [f64; 3]) -> f64 {
    let d: Vec<f64> = q.iter().map(|&c| (c - 0.5).abs() - 0.5).collect();
    let outside: f64 = d.iter().map(|v| v.max(0.0).powi(2)).sum::<f64>().sqrt();
    let inside = d.iter().copied().fold(f64::NEG_INFINITY, f64::max).min(0.0);
    outside + inside
}

#[test]
fn cube_labels_match_closed_forms() {
    let cube = common::unit_cube();
    let l = label_mesh(&cube, "cube", &small(1), None).unwrap();
    assert_eq!(l.points.len(), 600);
    assert_eq!(l.source.iter().filter(|&&s| s == 0).count(), 300);
    assert_eq!(l.source.iter().filter(|&&s| s == 1).count(), 150);
    assert_eq!(l.source.iter().filter(|&&s| s == 2).count(), 150);
    // Uniform points lie in the box grown by 0.1 · √3 on each side.
    let pad = 0.1 * 3f64.sqrt();
    for (p, _) in l.points.iter().zip(&l.source).filter(|(_, s)| **s == 0) {
        assert!(p.iter().all(|&c| c >= -pad && c < 1.0 + pad), "{p:?}");
    }
    let mut inside = 0;
    for i in 0..l.points.len() {
        let q = l.points[i];
        let exact = cube_sdf(q);
        assert!(
            (l.sdf[i] - exact).abs() < 1e-12,
            "{q:?}: {} vs {exact}",
            l.sdf[i]
        );
        // Closed cube: w is 1 inside, 0 outside (no sample lands exactly on a face).
        let want = if exact < 0.0 { 1.0 } else { 0.0 };
        assert_eq!(l.w[i], want, "{q:?}");
        assert_eq!(l.occupancy[i], exact < 0.0);
        inside += usize::from(l.occupancy[i]);
    }
    // Near-surface points straddle the surface: both labels occur in quantity.
    assert!(inside > 100 && inside < 500, "{inside}");
}

#[test]
fn open_box_labels_match_the_direct_sum() {
    let open = common::open_cube();
    let l = label_mesh(&open, "open", &small(2), None).unwrap();
    for i in 0..l.points.len() {
        let direct = winding_number_direct(&open, l.points[i]);
        assert!((l.w[i] - direct).abs() < 1e-9, "{:?}", l.points[i]);
        assert_eq!(l.occupancy[i], l.w[i] > 0.5);
        assert_eq!(l.sdf[i] < 0.0, l.w[i] > 0.5 && l.sdf[i] != 0.0);
    }
    // Some points of the open box have fractional w (near the hole).
    assert!(l.w.iter().any(|&w| w > 0.01 && w < 0.99));
}

#[test]
fn reproducible_and_keyed() {
    let cube = common::unit_cube();
    let a = label_mesh(&cube, "a/cube.off", &small(5), None).unwrap();
    let b = label_mesh(&cube, "a/cube.off", &small(5), None).unwrap();
    assert_eq!(a.to_npz().unwrap(), b.to_npz().unwrap());
    let other_key = sample_points(&cube, "b/cube.off", &small(5)).unwrap().0;
    let other_seed = sample_points(&cube, "a/cube.off", &small(6)).unwrap().0;
    assert_ne!(a.points, other_key);
    assert_ne!(a.points, other_seed);
    // The labels do not depend on the thread count.
    let one = rayon::ThreadPoolBuilder::new()
        .num_threads(1)
        .build()
        .unwrap()
        .install(|| label_mesh(&cube, "a/cube.off", &small(5), None).unwrap());
    assert_eq!(one, a);
}

#[test]
fn bad_options_and_degenerate_meshes() {
    let cube = common::unit_cube();
    for opts in [
        SamplingOptions {
            sigmas: vec![],
            ..small(0)
        },
        SamplingOptions {
            sigmas: vec![f64::NAN],
            ..small(0)
        },
        SamplingOptions {
            padding: -1.0,
            ..small(0)
        },
        SamplingOptions {
            uniform: usize::MAX,
            ..small(0)
        },
    ] {
        assert!(label_mesh(&cube, "c", &opts, None).is_err(), "{opts:?}");
    }
    // A mesh of degenerate triangles only: points still come (uniform faces), w = 0 up to the
    // rounding of the boundary sum.
    let flat = gwn::Mesh::from_slices(&[[0.0; 3], [1.0, 0.0, 0.0], [2.0, 0.0, 0.0]], &[[0, 1, 2]])
        .unwrap();
    let l = label_mesh(&flat, "flat", &small(0), None).unwrap();
    let bad: Vec<_> =
        l.w.iter()
            .zip(&l.points)
            .filter(|(w, _)| w.abs() > 1e-12)
            .take(5)
            .collect();
    assert!(bad.is_empty(), "{bad:?}");
    assert!(l.points.iter().flatten().all(|c| c.is_finite()));
}

/// The arrays of our stored `.npz`, parsed back from the zip's central directory.
fn npz_member<'a>(bytes: &'a [u8], name: &str) -> &'a [u8] {
    let eocd = bytes.len() - 22;
    let cd = u32::from_le_bytes(bytes[eocd + 16..eocd + 20].try_into().unwrap()) as usize;
    let entries = u16::from_le_bytes(bytes[eocd + 10..eocd + 12].try_into().unwrap());
    let mut at = cd;
    for _ in 0..entries {
        let size = u32::from_le_bytes(bytes[at + 24..at + 28].try_into().unwrap()) as usize;
        let nlen = u16::from_le_bytes(bytes[at + 28..at + 30].try_into().unwrap()) as usize;
        let off = u32::from_le_bytes(bytes[at + 42..at + 46].try_into().unwrap()) as usize;
        let n = &bytes[at + 46..at + 46 + nlen];
        if n == name.as_bytes() {
            let lnlen = u16::from_le_bytes(bytes[off + 26..off + 28].try_into().unwrap()) as usize;
            let start = off + 30 + lnlen;
            let member = &bytes[start..start + size];
            let crc = u32::from_le_bytes(bytes[at + 16..at + 20].try_into().unwrap());
            assert_eq!(crc, crc32fast::hash(member));
            let hlen = u16::from_le_bytes([member[8], member[9]]) as usize;
            return &member[10 + hlen..];
        }
        at += 46 + nlen;
    }
    panic!("{name} not in archive");
}

fn f64s(b: &[u8]) -> Vec<f64> {
    b.chunks_exact(8)
        .map(|c| f64::from_le_bytes(c.try_into().unwrap()))
        .collect()
}

#[test]
fn npz_holds_the_labels() {
    let l: Labels = label_mesh(&common::open_cube(), "o", &small(3), None).unwrap();
    let z = l.to_npz().unwrap();
    assert_eq!(f64s(npz_member(&z, "w.npy")), l.w);
    assert_eq!(f64s(npz_member(&z, "sdf.npy")), l.sdf);
    let pts = f64s(npz_member(&z, "points.npy"));
    assert_eq!(pts, l.points.iter().flatten().copied().collect::<Vec<_>>());
    let occ: Vec<bool> = npz_member(&z, "occupancy.npy")
        .iter()
        .map(|&b| b == 1)
        .collect();
    assert_eq!(occ, l.occupancy);
    assert_eq!(npz_member(&z, "source.npy"), &l.source[..]);
}

/// A small dataset: three good meshes in two folders, a broken one, a glTF scene.
fn dataset(dir: &Path) -> Vec<PathBuf> {
    let files = [
        ("a/cube.off", "cube.off"),
        ("a/cube.obj", "cube.obj"),
        ("b/c/cube.ply", "cube_binary_le.ply"),
        ("b/broken.off", "broken_index.off"),
        ("b/scene.glb", "two_cubes.glb"),
    ];
    files
        .iter()
        .map(|(to, from)| {
            let p = dir.join("in").join(to);
            std::fs::create_dir_all(p.parent().unwrap()).unwrap();
            std::fs::copy(fixture(from), &p).unwrap();
            p
        })
        .collect()
}

fn outputs(dir: &Path) -> Vec<(PathBuf, Vec<u8>)> {
    let mut v = Vec::new();
    let mut stack = vec![dir.to_path_buf()];
    while let Some(d) = stack.pop() {
        for e in std::fs::read_dir(&d).unwrap() {
            let p = e.unwrap().path();
            if p.is_dir() {
                stack.push(p);
            } else if p.extension().is_some_and(|e| e == "npz") {
                v.push((
                    p.strip_prefix(dir).unwrap().to_path_buf(),
                    std::fs::read(&p).unwrap(),
                ));
            }
        }
    }
    v.sort();
    v
}

#[test]
fn dataset_job_failures_resume_and_thread_independence() {
    let dir = scratch("job");
    let meshes = dataset(&dir);
    let opts = JobOptions {
        sampling: small(9),
        ..Default::default()
    };
    let run = |out: &Path, threads: usize, list: &[PathBuf]| {
        rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .unwrap()
            .install(|| label_dataset(list, out, None, &opts, |_| {}).unwrap())
    };
    let rows = run(&dir.join("out1"), 2, &meshes);
    let status: Vec<Status> = rows.iter().map(|r| r.status).collect();
    assert_eq!(
        status,
        [
            Status::Ok,
            Status::Ok,
            Status::Ok,
            Status::Failed,
            Status::Ok
        ]
    );
    let err = rows[3].error.as_deref().unwrap();
    assert!(
        err.contains("broken.off") && err.contains("face 1"),
        "{err}"
    );
    assert_eq!(rows[4].faces, Some(24));
    assert_eq!(rows[0].output, PathBuf::from("a/cube.off.npz"));
    let manifest = std::fs::read_to_string(dir.join("out1/manifest.jsonl")).unwrap();
    assert_eq!(manifest.lines().count(), 5);
    assert!(
        manifest
            .lines()
            .nth(3)
            .unwrap()
            .contains("\"status\":\"failed\"")
    );

    let first = outputs(&dir.join("out1"));
    assert_eq!(first.len(), 4);
    // Same bytes with one thread and the list reversed.
    let mut reversed = meshes.clone();
    reversed.reverse();
    run(&dir.join("out2"), 1, &reversed);
    assert_eq!(outputs(&dir.join("out2")), first);

    // Resume: finished meshes are skipped, the broken one is retried (and fails again).
    let again = run(&dir.join("out1"), 2, &meshes);
    let status: Vec<Status> = again.iter().map(|r| r.status).collect();
    assert_eq!(
        status,
        [
            Status::Done,
            Status::Done,
            Status::Done,
            Status::Failed,
            Status::Done
        ]
    );
    // A lost output is redone, identically.
    std::fs::remove_file(dir.join("out1/b/c/cube.ply.npz")).unwrap();
    let third = run(&dir.join("out1"), 2, &meshes);
    assert_eq!(third[2].status, Status::Ok);
    assert_eq!(outputs(&dir.join("out1")), first);
    // No temporary files are left behind.
    let leftovers = std::fs::read_dir(dir.join("out1/a"))
        .unwrap()
        .filter(|e| {
            e.as_ref()
                .unwrap()
                .file_name()
                .to_string_lossy()
                .contains("partial")
        })
        .count();
    assert_eq!(leftovers, 0);
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn time_limit_is_a_manifest_row() {
    let dir = scratch("timeout");
    let meshes = dataset(&dir);
    let opts = JobOptions {
        sampling: small(0),
        time_limit: Some(Duration::from_nanos(1)),
        ..Default::default()
    };
    let rows = label_dataset(&meshes[..1], &dir.join("out"), None, &opts, |_| {}).unwrap();
    assert_eq!(rows[0].status, Status::Timeout);
    assert!(rows[0].error.as_deref().unwrap().contains("time limit"));
    assert!(outputs(&dir.join("out")).is_empty());
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn cli_label() {
    let dir = scratch("cli");
    dataset(&dir);
    let out = Command::new(env!("CARGO_BIN_EXE_gwn"))
        .args(["--threads", "2", "label"])
        .arg(dir.join("in"))
        .arg("--out")
        .arg(dir.join("out"))
        .args(["--uniform", "100", "--near", "100", "--seed", "4"])
        .output()
        .unwrap();
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert!(
        stdout.contains("labelled 4 meshes") && stdout.contains("1 failed"),
        "{stdout}"
    );
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(stderr.contains("broken.off"), "{stderr}");
    assert_eq!(outputs(&dir.join("out")).len(), 4);
    // The library with the same options writes the same bytes.
    let lib = dir.join("lib");
    let mut meshes = Vec::new();
    for name in [
        "a/cube.obj",
        "a/cube.off",
        "b/broken.off",
        "b/c/cube.ply",
        "b/scene.glb",
    ] {
        meshes.push(dir.join("in").join(name));
    }
    let opts = JobOptions {
        sampling: SamplingOptions {
            uniform: 100,
            near: 100,
            seed: 4,
            ..Default::default()
        },
        ..Default::default()
    };
    label_dataset(&meshes, &lib, None, &opts, |_| {}).unwrap();
    assert_eq!(outputs(&lib), outputs(&dir.join("out")));

    let bad = Command::new(env!("CARGO_BIN_EXE_gwn"))
        .args(["label", "x.off", "--sigma=-1", "--out"])
        .arg(dir.join("bad"))
        .output()
        .unwrap();
    assert!(!bad.status.success());
    let err = String::from_utf8_lossy(&bad.stderr);
    assert_eq!(err.trim_end().lines().count(), 1, "{err}");
    assert!(err.contains("sigma"), "{err}");
    let _ = std::fs::remove_dir_all(&dir);
}
