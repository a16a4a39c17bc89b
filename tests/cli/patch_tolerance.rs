//! `--tolerance` reaches the patch evaluator from the products (issue 24: `gwn voxelize` and
//! `gwn slice` used to drop it for patch sets): the voxel grid of a patch set equals, bit for
//! bit, the library's grid of `PatchWindingNumber` at the tolerance given — and differs from the
//! default tolerance's, so a dropped flag would fail here.

use gwn::BoundingBox;
use gwn::grid::GridSpec;
use gwn::patch::{Options, PatchWindingNumber, load_patches};

use crate::cli::gwn;

/// One bicubic patch over the unit square, bulging in z: an open surface, so `w` is the boundary
/// quadrature's (its tolerance matters).
fn bulge(dir: &std::path::Path) -> std::path::PathBuf {
    let mut s = String::from("1\n3 3\n");
    for i in 0..4 {
        for j in 0..4 {
            let z = if (1..3).contains(&i) && (1..3).contains(&j) {
                0.8
            } else {
                0.0
            };
            s.push_str(&format!("{} {} {z}\n", i as f64 / 3.0, j as f64 / 3.0));
        }
    }
    let p = dir.join("bulge.bpt");
    std::fs::write(&p, s).unwrap();
    p
}

/// The float64 values of an `.npy` file written by `gwn voxelize --dtype f64`.
fn npy_f64(path: &std::path::Path) -> Vec<f64> {
    let bytes = std::fs::read(path).unwrap();
    assert_eq!(&bytes[..6], b"\x93NUMPY");
    let header = u16::from_le_bytes([bytes[8], bytes[9]]) as usize;
    bytes[10 + header..]
        .chunks_exact(8)
        .map(|c| f64::from_le_bytes(c.try_into().unwrap()))
        .collect()
}

#[test]
fn voxelize_and_slice_pass_the_tolerance_to_patch_sets() {
    let dir = std::env::temp_dir().join(format!("gwn-patch-tolerance-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let set_path = bulge(&dir);
    let set = load_patches(&set_path).unwrap();
    let spec = GridSpec::new(
        BoundingBox {
            min: [-0.2, -0.2, -0.3],
            max: [1.2, 1.2, 0.9],
        },
        [5, 4, 6],
    )
    .unwrap();
    let voxelize = |tolerance: &str| -> Vec<f64> {
        let out = dir.join(format!("w{tolerance}.npy"));
        let (ok, _, err) = gwn(&[
            "voxelize",
            set_path.to_str().unwrap(),
            "--bounds",
            "-0.2",
            "-0.2",
            "-0.3",
            "1.2",
            "1.2",
            "0.9",
            "--dims",
            "5",
            "4",
            "6",
            "--dtype",
            "f64",
            "--tolerance",
            tolerance,
            "--out",
            out.to_str().unwrap(),
        ]);
        assert!(ok, "voxelize --tolerance {tolerance}: {err}");
        npy_f64(&out)
    };
    let library = |tolerance: f64| {
        let wn = PatchWindingNumber::with_options(
            &set,
            Options {
                tolerance,
                ..Options::default()
            },
        )
        .unwrap();
        gwn::grid::evaluate(&wn, &spec)
    };
    let coarse = voxelize("1e-2");
    let bits = |v: &[f64]| v.iter().map(|x| x.to_bits()).collect::<Vec<_>>();
    assert_eq!(bits(&coarse), bits(&library(1e-2)));
    let fine = library(1e-10);
    assert_eq!(bits(&voxelize("1e-10")), bits(&fine));
    assert_ne!(
        bits(&coarse),
        bits(&fine),
        "the tolerance changes no value: this test cannot see a dropped --tolerance"
    );
    // `gwn slice` reaches the same rules: a zero tolerance is refused for a patch set (its
    // quadrature needs a target) instead of being dropped.
    let png = dir.join("s.png");
    let (ok, _, err) = gwn(&[
        "slice",
        set_path.to_str().unwrap(),
        "--res",
        "8",
        "--tolerance",
        "0",
        "--out",
        png.to_str().unwrap(),
    ]);
    assert!(!ok, "slice --tolerance 0 accepted for a patch set");
    assert!(
        err.contains("tolerance must be positive for a patch set"),
        "{err}"
    );
    let (ok, _, err) = gwn(&[
        "slice",
        set_path.to_str().unwrap(),
        "--res",
        "8",
        "--tolerance",
        "1e-3",
        "--out",
        png.to_str().unwrap(),
    ]);
    assert!(ok, "{err}");
    std::fs::remove_dir_all(&dir).ok();
}
