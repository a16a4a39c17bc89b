//! Dataset labelling: labels against closed forms and the direct sum, byte-for-byte
//! reproducibility (across runs, thread counts and list order), resumption, failures and time
//! limits as manifest rows, and the `gwn label` command.

use crate::common;

use std::path::{Path, PathBuf};
use std::process::Command;
use std::time::Duration;

use gwn::eval::direct::winding_number_direct;
use gwn::products::dataset::Status;
use gwn::products::label::{
    JobOptions, Labels, SamplingOptions, label_dataset, label_mesh, sample_points,
};

fn fixture(name: &str) -> PathBuf {
    crate::common::repo().join("tests/fixtures").join(name)
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
    assert_eq!(rows[4].stats.count("faces"), Some(24));
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

/// Runs `work` on another thread and fails the test after 60 s instead of hanging it.
fn within_a_minute<T: Send + 'static>(what: &str, work: impl FnOnce() -> T + Send + 'static) -> T {
    let (tx, rx) = std::sync::mpsc::channel();
    std::thread::spawn(move || {
        let _ = tx.send(work());
    });
    rx.recv_timeout(Duration::from_secs(60))
        .unwrap_or_else(|_| panic!("{what} did not finish within 60 s"))
}

fn mkfifo(path: &Path) -> bool {
    Command::new("mkfifo")
        .arg(path)
        .status()
        .is_ok_and(|s| s.success())
}

#[cfg(unix)]
#[test]
fn fifo_in_a_dataset_is_a_failed_row_not_a_hang() {
    let dir = scratch("fifo");
    dataset(&dir);
    if !mkfifo(&dir.join("in/b/pipe.obj")) {
        println!("skipping: mkfifo is not available");
        return;
    }
    let (inp, out) = (dir.join("in"), dir.join("out"));
    let run = within_a_minute("gwn label on a folder with a FIFO", move || {
        Command::new(env!("CARGO_BIN_EXE_gwn"))
            .arg("label")
            .arg(&inp)
            .arg("--out")
            .arg(&out)
            .args(["--uniform", "50", "--near", "50"])
            .output()
            .unwrap()
    });
    assert!(run.status.success(), "{run:?}");
    let manifest = std::fs::read_to_string(dir.join("out/manifest.jsonl")).unwrap();
    let row = manifest
        .lines()
        .find(|l| l.contains("pipe.obj"))
        .unwrap_or_else(|| panic!("no row for the FIFO: {manifest}"));
    assert!(
        row.contains("\"status\":\"failed\"") && row.contains("not a regular file"),
        "{row}"
    );
    // The library, given the FIFO by name, does the same.
    let fifo = dir.join("in/b/pipe.obj");
    let out2 = dir.join("out2");
    let rows = within_a_minute("label_dataset on a FIFO", move || {
        label_dataset(&[fifo], &out2, None, &JobOptions::default(), |_| {}).unwrap()
    });
    assert_eq!(rows[0].status, Status::Failed);
    assert!(
        rows[0]
            .error
            .as_deref()
            .unwrap()
            .contains("not a regular file")
    );
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn two_inputs_never_share_an_output() {
    let dir = scratch("collide");
    let a = dir.join("in/a/d/m.off");
    let d = dir.join("in/d/m.off");
    std::fs::create_dir_all(a.parent().unwrap()).unwrap();
    std::fs::create_dir_all(d.parent().unwrap()).unwrap();
    std::fs::copy(fixture("cube.off"), &a).unwrap();
    std::fs::copy(fixture("broken_index.off"), &d).unwrap();
    let opts = JobOptions {
        sampling: small(1),
        ..Default::default()
    };
    // `a/../d/m.off` is `d/m.off`, another file: it gets its own output.
    let dotdot = dir.join("in/a/../d/m.off");
    let rows = label_dataset(&[a.clone(), dotdot], &dir.join("out"), None, &opts, |_| {}).unwrap();
    assert_ne!(rows[0].output, rows[1].output, "{rows:?}");
    assert_eq!(rows[0].status, Status::Ok);
    assert_eq!(rows[1].status, Status::Failed, "{rows:?}");
    // One file twice (or two names for one output) is refused before anything is written.
    let e = label_dataset(
        &[a.clone(), a.clone()],
        &dir.join("out3"),
        None,
        &opts,
        |_| {},
    )
    .unwrap_err()
    .to_string();
    assert!(e.contains("m.off.npz") && !e.contains('\n'), "{e}");
    assert!(!dir.join("out3/manifest.jsonl").exists());
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn resume_redoes_outputs_whose_options_or_input_changed_and_keeps_statistics() {
    let dir = scratch("options");
    let meshes = dataset(&dir);
    let out = dir.join("out");
    let with = |seed: u64| JobOptions {
        sampling: small(seed),
        ..Default::default()
    };
    let first = label_dataset(&meshes, &out, None, &with(1), |_| {}).unwrap();
    assert_eq!(first[0].status, Status::Ok);
    // Same options: done, with the statistics of the run that made the file.
    let again = label_dataset(&meshes, &out, None, &with(1), |_| {}).unwrap();
    for (a, b) in first.iter().zip(&again) {
        if a.status == Status::Ok {
            assert_eq!(b.status, Status::Done, "{b:?}");
            assert_eq!(&b.stats, &a.stats, "{b:?}");
            assert!(b.redone.is_none());
        }
    }
    // Another seed: every output is redone, says so, and equals a fresh run's.
    let other = label_dataset(&meshes, &out, None, &with(2), |_| {}).unwrap();
    assert_eq!(other[0].status, Status::Ok);
    let why = other[0].redone.as_deref().unwrap_or_default();
    assert!(why.contains("options"), "{why:?}");
    assert!(
        other[0].to_json().contains("\"redone\":"),
        "{}",
        other[0].to_json()
    );
    let fresh = dir.join("fresh");
    label_dataset(&meshes, &fresh, None, &with(2), |_| {}).unwrap();
    assert_eq!(outputs(&out), outputs(&fresh));
    // A changed input (here one more trailing newline) is redone too.
    let mut bytes = std::fs::read(&meshes[0]).unwrap();
    bytes.push(b'\n');
    std::fs::write(&meshes[0], bytes).unwrap();
    let changed = label_dataset(&meshes, &out, None, &with(2), |_| {}).unwrap();
    assert_eq!(changed[0].status, Status::Ok);
    assert!(
        changed[0]
            .redone
            .as_deref()
            .unwrap_or_default()
            .contains("input"),
        "{:?}",
        changed[0]
    );
    assert_eq!(changed[1].status, Status::Done);
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn partial_files_of_a_killed_run_are_removed() {
    let dir = scratch("partial");
    let meshes = dataset(&dir);
    let out = dir.join("out");
    std::fs::create_dir_all(out.join("a")).unwrap();
    let leftovers = [
        out.join("a/.cube.off.npz.partial-999999-3"),
        out.join(".manifest.jsonl.partial-999999-0"),
        out.join("a/.gone.obj.npz.partial-1-0"),
    ];
    for p in &leftovers {
        std::fs::write(p, b"half a file").unwrap();
    }
    // Files that merely look alike are the user's.
    let keep = out.join("a/notes.partial-1-0");
    std::fs::write(&keep, b"mine").unwrap();
    let opts = JobOptions {
        sampling: small(0),
        ..Default::default()
    };
    label_dataset(&meshes, &out, None, &opts, |_| {}).unwrap();
    for p in &leftovers {
        assert!(!p.exists(), "{} left behind", p.display());
    }
    assert!(keep.exists());
    let _ = std::fs::remove_dir_all(&dir);
}

#[cfg(unix)]
#[test]
fn directory_symlink_loops_list_each_file_once() {
    let dir = scratch("loop");
    dataset(&dir);
    std::os::unix::fs::symlink("..", dir.join("in/a/up")).unwrap();
    std::os::unix::fs::symlink("../b", dir.join("in/a/b_again")).unwrap();
    let (inp, out) = (dir.join("in"), dir.join("out"));
    let run = within_a_minute("gwn label on a symlink loop", move || {
        Command::new(env!("CARGO_BIN_EXE_gwn"))
            .arg("label")
            .arg(&inp)
            .arg("--out")
            .arg(&out)
            .args(["--uniform", "20", "--near", "20"])
            .output()
            .unwrap()
    });
    assert!(run.status.success(), "{run:?}");
    let manifest = std::fs::read_to_string(dir.join("out/manifest.jsonl")).unwrap();
    assert_eq!(manifest.lines().count(), 5, "{manifest}");
    // Files are named by their real paths, not through the links.
    assert!(
        !manifest.contains("b_again") && !manifest.contains("up/"),
        "{manifest}"
    );
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn sample_box_must_be_finite() {
    let cube = common::unit_cube();
    for opts in [
        SamplingOptions {
            padding: 1e308,
            ..small(0)
        },
        SamplingOptions {
            sigmas: vec![0.01, 1e308],
            ..small(0)
        },
        SamplingOptions {
            sigmas: vec![1e307],
            ..small(0)
        },
    ] {
        let e = label_mesh(&cube, "c", &opts, None).expect_err("must refuse");
        assert!(e.to_string().contains("not finite"), "{e}");
    }
    // The CLI's row says so, too.
    let dir = scratch("hugepad");
    let meshes = dataset(&dir);
    let opts = JobOptions {
        sampling: SamplingOptions {
            padding: 1e308,
            ..small(0)
        },
        ..Default::default()
    };
    let rows = label_dataset(&meshes[..1], &dir.join("out"), None, &opts, |_| {}).unwrap();
    assert_eq!(rows[0].status, Status::Failed, "{rows:?}");
    assert!(outputs(&dir.join("out")).is_empty());
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn full_stdout_is_a_one_line_error() {
    let Ok(full) = std::fs::File::options().write(true).open("/dev/full") else {
        println!("skipping: /dev/full is not available");
        return;
    };
    let dir = scratch("devfull");
    dataset(&dir);
    let out = Command::new(env!("CARGO_BIN_EXE_gwn"))
        .arg("label")
        .arg(dir.join("in"))
        .arg("--out")
        .arg(dir.join("out"))
        .args(["--uniform", "20", "--near", "20"])
        .stdout(full)
        .output()
        .unwrap();
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(1), "{err}");
    assert!(
        err.lines()
            .any(|l| l.starts_with("gwn: ") && l.contains("stdout")),
        "{err}"
    );
    assert!(!err.contains("panicked"), "{err}");
    let _ = std::fs::remove_dir_all(&dir);
}
