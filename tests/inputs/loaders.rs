//! Loader fixtures: every good file gives the unit cube, every broken file its specific error.

use std::path::{Path, PathBuf};

use gwn::error::{LoadError, LoadErrorKind, Location, MeshError};
use gwn::io::points::{
    load_values_from_bytes, save_points, save_values, write_points_csv, write_values_csv,
    write_values_npy,
};
use gwn::io::{Format, LoadOptions, load_mesh, load_mesh_from_bytes, load_mesh_with, load_points};
use gwn::mesh::stats::MeshStats;

fn fixture(name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("tests/fixtures")
        .join(name)
}

fn load_err(name: &str) -> LoadError {
    let e = load_mesh(fixture(name)).expect_err(name);
    let msg = e.to_string();
    assert!(msg.contains(name), "{msg}");
    assert!(!msg.contains('\n'), "{msg}");
    e
}

#[test]
fn cubes_load_as_closed_cubes() {
    for (name, format, polys, welded) in [
        ("cube.obj", Format::Obj, 6, 0),
        ("cube.off", Format::Off, 6, 0),
        ("cube_ascii.stl", Format::Stl, 0, 28),
        ("cube_binary.stl", Format::Stl, 0, 28),
        ("cube_ascii.ply", Format::Ply, 6, 0),
        ("cube_binary_le.ply", Format::Ply, 6, 0),
        ("cube_binary_be.ply", Format::Ply, 6, 0),
    ] {
        let l = load_mesh(fixture(name)).unwrap_or_else(|e| panic!("{e}"));
        assert_eq!(l.format, format, "{name}");
        assert_eq!(l.polygons_triangulated, polys, "{name}");
        assert_eq!(l.welded_vertices, welded, "{name}");
        let s = MeshStats::compute(&l.mesh);
        assert_eq!((s.faces, s.vertices), (12, 8), "{name}");
        assert!(s.closed && s.oriented_closed, "{name}");
        assert_eq!(s.components, 1, "{name}");
        assert_eq!(s.bounding_box.unwrap().max, [1.0; 3], "{name}");
        // Same result when the format comes from the content only.
        let bytes = std::fs::read(fixture(name)).unwrap();
        let l2 = load_mesh_from_bytes(&bytes, "no_extension", None).unwrap();
        assert_eq!(l2.format, format, "{name} by content");
        assert_eq!(l2.mesh, l.mesh, "{name} by content");
    }
}

#[test]
fn stl_without_weld_keeps_corners() {
    let l = load_mesh_with(
        fixture("cube_binary.stl"),
        &LoadOptions { weld: Some(false) },
    )
    .unwrap();
    assert_eq!(l.mesh.positions().len(), 36);
    assert_eq!(l.welded_vertices, 0);
    let l = load_mesh_with(fixture("cube.obj"), &LoadOptions { weld: Some(true) }).unwrap();
    assert_eq!(l.welded_vertices, 0);
}

#[test]
fn truncated_binary_stl() {
    let e = load_err("broken_truncated_binary.stl");
    assert!(matches!(e.kind, LoadErrorKind::Truncated(_)), "{e}");
    assert_eq!(e.location, Location::Byte(84 + 50 * 5));
}

#[test]
fn stl_with_wrong_count() {
    let e = load_err("broken_wrong_count.stl");
    assert!(matches!(e.kind, LoadErrorKind::Syntax(_)), "{e}");
    assert_eq!(e.location, Location::Byte(84 + 50 * 11));
}

#[test]
fn off_bad_counts() {
    let e = load_err("broken_bad_counts.off");
    assert!(matches!(e.kind, LoadErrorKind::Syntax(_)), "{e}");
    assert_eq!(e.location, Location::Line(2));
    assert!(e.to_string().contains("line 2"));
}

#[test]
fn off_index_out_of_range() {
    let e = load_err("broken_index.off");
    assert!(
        matches!(
            e.kind,
            LoadErrorKind::Mesh(MeshError::IndexOutOfRange {
                face: 1,
                index: 3,
                vertex_count: 3
            })
        ),
        "{e}"
    );
    assert_eq!(e.location, Location::Face(1));
}

#[test]
fn off_nan_coordinate() {
    let e = load_err("broken_nan.off");
    assert!(
        matches!(
            e.kind,
            LoadErrorKind::Mesh(MeshError::NonFiniteCoordinate {
                vertex: 1,
                axis: 1,
                ..
            })
        ),
        "{e}"
    );
    assert_eq!(e.location, Location::Vertex(1));
    // The file, the vertex, the axis, once each.
    assert_eq!(
        e.to_string().rsplit('/').next().unwrap(),
        "broken_nan.off: vertex 1 has a non-finite coordinate NaN on axis y"
    );
}

#[test]
fn off_truncated() {
    let e = load_err("broken_truncated.off");
    assert!(matches!(e.kind, LoadErrorKind::Truncated(_)), "{e}");
    assert_eq!(e.location, Location::Line(7));
}

#[test]
fn obj_index_out_of_range() {
    let e = load_err("broken_index.obj");
    assert!(
        matches!(
            e.kind,
            LoadErrorKind::Mesh(MeshError::IndexOutOfRange { index: 3, .. })
        ),
        "{e}"
    );
    assert_eq!(e.location, Location::Face(1));
}

#[test]
fn ply_truncated() {
    let e = load_err("broken_truncated.ply");
    assert!(matches!(e.kind, LoadErrorKind::Truncated(_)), "{e}");
    let len = std::fs::metadata(fixture("broken_truncated.ply"))
        .unwrap()
        .len();
    // Face 5 is `4 a b c d` (1 + 4·4 bytes); 10 of them are present, so the third index
    // starts one byte before the end: the location is the value that does not fit.
    assert_eq!(e.location, Location::Byte(len - 1));
}

#[test]
fn empty_files() {
    for name in ["broken_empty.stl", "broken_empty.obj", "broken_empty.ply"] {
        let e = load_err(name);
        assert!(matches!(e.kind, LoadErrorKind::Empty), "{name}: {e}");
    }
}

#[test]
fn missing_file_and_unknown_format() {
    let e = load_mesh(fixture("does_not_exist.obj")).unwrap_err();
    assert!(matches!(e.kind, LoadErrorKind::Io(_)));
    assert!(e.to_string().contains("does_not_exist.obj"));
    let e = load_mesh_from_bytes(b"hello world", "x.bin", None).unwrap_err();
    assert!(matches!(e.kind, LoadErrorKind::UnknownFormat));
}

#[test]
fn points_text_and_npy_round_trip() {
    let p = load_points(fixture("points.csv")).unwrap();
    assert_eq!(p, vec![[0.5, 0.5, 0.5], [2.0, 2.0, 2.0], [0.1, 0.2, 0.3]]);

    let dir = std::env::temp_dir().join(format!("gwn-loaders-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let pts = vec![[0.1, 1.0 / 3.0, -1e-310], [f64::MAX, 5e-324, -0.0]];
    for name in ["p.csv", "p.NPY"] {
        let path = dir.join(name);
        save_points(&path, &pts).unwrap();
        let back = load_points(&path).unwrap();
        assert_eq!(
            back.iter()
                .flatten()
                .map(|v| v.to_bits())
                .collect::<Vec<_>>(),
            pts.iter()
                .flatten()
                .map(|v| v.to_bits())
                .collect::<Vec<_>>(),
            "{name}"
        );
    }
    let vals = vec![0.1, 1.0 / 3.0, -2.5e-300, 7.0];
    for name in ["w.csv", "w.npy"] {
        let path = dir.join(name);
        save_values(&path, &vals).unwrap();
        let back = load_values_from_bytes(&std::fs::read(&path).unwrap(), &path).unwrap();
        assert_eq!(back, vals, "{name}");
    }
    std::fs::remove_dir_all(&dir).ok();

    let mut csv = Vec::new();
    write_values_csv(&mut csv, &[0.1, 2.0]).unwrap();
    assert_eq!(csv, b"0.1\n2.0\n");
    let mut csv = Vec::new();
    write_points_csv(&mut csv, &[[1.0, 2.5, -3.0]]).unwrap();
    assert_eq!(csv, b"1.0,2.5,-3.0\n");
    let mut npy = Vec::new();
    write_values_npy(&mut npy, &[1.0, 2.0]).unwrap();
    assert_eq!(&npy[..6], b"\x93NUMPY");
    let data = npy.len() - 16;
    assert_eq!(data % 64, 0);
    assert_eq!(usize::from(u16::from_le_bytes([npy[8], npy[9]])) + 10, data);
    let header = std::str::from_utf8(&npy[10..data]).unwrap();
    assert!(header.starts_with("{'descr': '<f8', 'fortran_order': False, 'shape': (2,), }"));
    assert!(header.ends_with('\n'));
}

#[test]
fn npy_float32_fortran_points() {
    // Hand-made float32 Fortran-order (2, 3) array: columns x, y, z.
    let dict = "{'descr': '<f4', 'fortran_order': True, 'shape': (2, 3), }";
    let mut b = b"\x93NUMPY\x01\x00".to_vec();
    let hlen = 128 - 10;
    b.extend_from_slice(&(hlen as u16).to_le_bytes());
    b.extend_from_slice(dict.as_bytes());
    b.resize(127, b' ');
    b.push(b'\n');
    for v in [1.0f32, 4.0, 2.0, 5.0, 3.0, 6.0] {
        b.extend_from_slice(&v.to_le_bytes());
    }
    let p = gwn::io::load_points_from_bytes(&b, "f.npy").unwrap();
    assert_eq!(p, vec![[1.0, 2.0, 3.0], [4.0, 5.0, 6.0]]);
}
