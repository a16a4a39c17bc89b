//! Every evaluation method through every CLI job, and misuse of the method options as one-line
//! errors (moved from the library's `Evaluator` tests, `tests/exact/evaluator.rs`).

use crate::common::sphere_cloud;

fn gwn(args: &[&str]) -> std::process::Output {
    std::process::Command::new(env!("CARGO_BIN_EXE_gwn"))
        .args(args)
        .output()
        .unwrap()
}

fn one_line_error(args: &[&str]) -> String {
    let out = gwn(args);
    assert!(!out.status.success(), "{args:?} should fail");
    let err = String::from_utf8_lossy(&out.stderr).into_owned();
    assert_eq!(err.trim_end().lines().count(), 1, "{err}");
    err
}

#[test]
fn cli_methods_apply_to_every_product_and_misuse_is_an_error() {
    let dir = std::env::temp_dir().join(format!("gwn-evaluator-cli-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let cloud = dir.join("sphere.xyz");
    let c = sphere_cloud(400);
    let text: String = c
        .positions()
        .iter()
        .map(|p| format!("{} {} {} {} {} {}\n", p[0], p[1], p[2], p[0], p[1], p[2]))
        .collect();
    std::fs::write(&cloud, text).unwrap();
    let queries = dir.join("q.csv");
    std::fs::write(&queries, "0 0 0.1\n0 0 3\n").unwrap();
    let mesh = crate::common::fixture("cube.off");
    let mesh = mesh.to_str().unwrap();
    let (cloud, queries) = (cloud.to_str().unwrap(), queries.to_str().unwrap());
    let d = |name: &str| dir.join(name).to_str().unwrap().to_owned();

    let out = gwn(&[
        "eval",
        mesh,
        "--points",
        queries,
        "--method",
        "fast",
        "--gradient",
    ]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let stdout = String::from_utf8_lossy(&out.stdout).into_owned();
    assert_eq!(
        stdout.lines().next().unwrap().split(',').count(),
        4,
        "{stdout}"
    );
    let out = gwn(&["eval", cloud, "--points", queries, "--gradient"]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );

    for (cmd, extra) in [
        ("voxelize", vec!["--res", "6", "--out", &d("v.npy")]),
        ("sdf", vec!["--res", "6", "--out", &d("s.npy")]),
        ("slice", vec!["--res", "16", "--out", &d("s.png")]),
    ] {
        for input in [mesh, cloud] {
            for method in [&["--method", "fast", "--beta", "3"][..], &[]] {
                let mut args = vec![cmd, input];
                args.extend(&extra);
                args.extend(method);
                let out = gwn(&args);
                assert!(
                    out.status.success(),
                    "{args:?}: {}",
                    String::from_utf8_lossy(&out.stderr)
                );
            }
        }
        let mut direct = vec![cmd, mesh, "--method", "direct"];
        direct.extend(&extra);
        assert!(gwn(&direct).status.success(), "{direct:?}");
    }
    let out = gwn(&["classify", mesh, cloud, "--out", &d("c.csv")]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );

    let err = one_line_error(&["eval", cloud, "--points", queries, "--method", "exact"]);
    assert!(
        err.contains("sphere.xyz: the exact method does not apply to a point cloud (use fast)"),
        "{err}"
    );
    let err = one_line_error(&[
        "voxelize",
        cloud,
        "--method",
        "direct",
        "--out",
        &d("x.npy"),
    ]);
    assert!(
        err.contains("the direct method does not apply to a point cloud"),
        "{err}"
    );
    let err = one_line_error(&["eval", mesh, "--points", queries, "--beta", "3"]);
    assert!(
        err.contains(
            "beta does not apply to the exact method (it is an option of the fast method)"
        ),
        "{err}"
    );
    let err = one_line_error(&[
        "eval", mesh, "--points", queries, "--method", "fast", "--ray", "-x",
    ]);
    assert!(
        err.contains("ray does not apply to the fast method (it is an option of the exact and parity methods)"),
        "{err}"
    );
    let err = one_line_error(&["slice", cloud, "--outline", "--out", &d("o.png")]);
    assert!(err.contains("needs a triangle mesh"), "{err}");
    let err = one_line_error(&["classify", cloud, mesh, "--out", &d("c2.csv")]);
    assert!(err.contains("needs a triangle mesh"), "{err}");
    std::fs::remove_dir_all(&dir).ok();
}
