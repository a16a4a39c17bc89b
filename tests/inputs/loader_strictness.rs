//! The loaders' strictness guarantees (issue 11 section 6, `docs/formats.md`): every ascii PLY
//! line holds exactly its element's values, integer values fit their declared type, numbers
//! after OBJ/STL coordinates are checked, unknown PLY header lines are warned about, point
//! clouds are read by the same PLY reader as meshes, and grids refuse overflowing bounds.

use gwn::error::{LoadErrorKind, Location};
use gwn::io::cloud::{CloudFormat, load_point_cloud_from_bytes, load_point_cloud_with_warnings};
use gwn::io::{Format, load_mesh_from_bytes, load_points_from_bytes};

const PLY_HEAD: &str = "ply\nformat ascii 1.0\nelement vertex 4\nproperty float x\n\
property float y\nproperty float z\nelement face 2\nproperty list uchar int vertex_indices\n\
end_header\n";
const PLY_VERTICES: &str = "0 0 0\n1 0 0\n0 1 0\n0 0 1\n";

fn ply(body: &str) -> Result<gwn::io::LoadedMesh, gwn::error::LoadError> {
    let text = format!("{PLY_HEAD}{body}");
    load_mesh_from_bytes(text.as_bytes(), "m.ply", Some(Format::Ply))
}

#[test]
fn ascii_ply_lines_hold_exactly_their_values() {
    let good = ply(&format!("{PLY_VERTICES}3 0 1 2\n3 0 2 3\n")).unwrap();
    assert_eq!(good.mesh.triangles(), &[[0, 1, 2], [0, 2, 3]]);
    // Blank lines between elements shift nothing and are allowed; CRLF too.
    let crlf = ply(&format!("{PLY_VERTICES}\n3 0 1 2\r\n\r\n3 0 2 3\r\n")).unwrap();
    assert_eq!(crlf.mesh, good.mesh);
    // Face 0 says 2 corners but lists 3: rejected at its line (line 14), not read as 2 of 4.
    for (body, line, what) in [
        (
            "0 0 0\n1 0 0\n0 1 0\n0 0 1\n2 0 1 3\n3 0 2 3\n",
            14,
            "after the end",
        ),
        (
            "0 0 0 9\n1 0 0\n0 1 0\n0 0 1\n3 0 1 2\n3 0 2 3\n",
            10,
            "after the end",
        ),
        (
            "0 0 0\n1 0 0\n0 1 0\n0 0 1\n3 0 1 2\n3 0 2 3 1\n",
            15,
            "after the end",
        ),
        (
            "0 0 0\n1 0\n0 1 0\n0 0 1\n3 0 1 2\n3 0 2 3\n",
            11,
            "line ends too early",
        ),
        (
            "0 0 0\n1 0 0\n0 1 0\n0 0 1\n3 0 1\n3 0 2 3\n",
            14,
            "line ends too early",
        ),
        (
            "0 0 0 1 0 0\n0 1 0\n0 0 1\n3 0 1 2\n3 0 2 3\n",
            10,
            "after the end",
        ),
    ] {
        let e = ply(body).unwrap_err();
        assert!(matches!(e.kind, LoadErrorKind::Syntax(_)), "{e}");
        assert_eq!(e.location, Location::Line(line), "{e}");
        assert!(e.to_string().contains(what), "{e}");
    }
    // Too few lines is still truncation.
    let e = ply("0 0 0\n1 0 0\n0 1 0\n0 0 1\n3 0 1 2\n").unwrap_err();
    assert!(matches!(e.kind, LoadErrorKind::Truncated(_)), "{e}");
}

#[test]
fn ascii_ply_integers_fit_their_type() {
    for (ty, ok, bad) in [
        ("uchar", "255", "256"),
        ("uchar", "0", "-1"),
        ("char", "-128", "-129"),
        ("ushort", "65535", "65536"),
        ("short", "32767", "32768"),
        ("uint", "4294967295", "4294967296"),
        ("int", "-2147483648", "-2147483649"),
        ("int", "7", "7.5"),
    ] {
        let text = |v: &str| {
            format!(
                "ply\nformat ascii 1.0\nelement tag 1\nproperty {ty} t\nelement vertex 3\n\
                 property float x\nproperty float y\nproperty float z\nelement face 1\n\
                 property list uchar int vertex_indices\nend_header\n{v}\n0 0 0\n1 0 0\n0 1 0\n\
                 3 0 1 2\n"
            )
        };
        load_mesh_from_bytes(text(ok).as_bytes(), "t.ply", None)
            .unwrap_or_else(|e| panic!("{ty} {ok}: {e}"));
        let e = load_mesh_from_bytes(text(bad).as_bytes(), "t.ply", None).unwrap_err();
        assert_eq!(e.location, Location::Line(12), "{ty} {bad}: {e}");
        assert!(
            e.to_string()
                .contains(&format!("invalid {ty} value `{bad}`")),
            "{e}"
        );
    }
    // The list count is checked against its type too.
    let e = ply(&format!("{PLY_VERTICES}300 0 1 2\n3 0 2 3\n")).unwrap_err();
    assert!(e.to_string().contains("invalid uchar value `300`"), "{e}");
}

#[test]
fn unknown_ply_header_lines_are_warnings() {
    let text = PLY_HEAD.replace(
        "format ascii 1.0\n",
        "format ascii 1.0\nCreated by Blender3D 247 - www.blender.org, source file: a.blend\n",
    ) + PLY_VERTICES
        + "3 0 1 2\n3 0 2 3\n";
    let l = load_mesh_from_bytes(text.as_bytes(), "b.ply", None).unwrap();
    assert_eq!(l.mesh.triangles().len(), 2);
    assert_eq!(l.warnings.len(), 1);
    assert_eq!(l.warnings[0].location, Location::Line(3));
    assert!(
        l.warnings[0]
            .to_string()
            .starts_with("line 3: unknown PLY header line")
    );
    // Malformed lines of the keywords that shape the body stay errors.
    for (from, to) in [
        ("element face 2", "element face"),
        ("property float y", "property float"),
        ("property float y", "property quad y"),
        ("format ascii 1.0", "format text 1.0"),
    ] {
        let text = PLY_HEAD.replace(from, to) + PLY_VERTICES + "3 0 1 2\n3 0 2 3\n";
        let e = load_mesh_from_bytes(text.as_bytes(), "b.ply", None).unwrap_err();
        assert!(matches!(e.kind, LoadErrorKind::Syntax(_)), "{to}: {e}");
    }
    // Clean files have no warnings.
    assert!(
        ply(&format!("{PLY_VERTICES}3 0 1 2\n3 0 2 3\n"))
            .unwrap()
            .warnings
            .is_empty()
    );
}

#[test]
fn obj_stl_and_off_lines_are_checked_to_the_end() {
    let obj = |v0: &str| format!("{v0}\nv 0 1 0\nv 0 0 1\nf 1 2 3\n");
    for good in [
        "v 1 0 0",
        "v 1 0 0 1",
        "v 1 0 0 0.5 0.5 0.5",
        "v 1 0 0 # note",
    ] {
        load_mesh_from_bytes(obj(good).as_bytes(), "a.obj", None)
            .unwrap_or_else(|e| panic!("{good}: {e}"));
    }
    for bad in ["v 1 0 0 abc", "v 1 0 0 1 x"] {
        let e = load_mesh_from_bytes(obj(bad).as_bytes(), "a.obj", None).unwrap_err();
        assert_eq!(e.location, Location::Line(1), "{bad}: {e}");
    }
    let stl = |v0: &str| {
        format!(
            "solid a\nfacet normal 0 0 1\nouter loop\n{v0}\nvertex 0 1 0\nvertex 0 0 1\n\
             endloop\nendfacet\nendsolid a\n"
        )
    };
    load_mesh_from_bytes(stl("vertex 1 0 0").as_bytes(), "a.stl", None).unwrap();
    for facet in [
        "facet normal 0 0 x",
        "facet normal 0 0",
        "facet normal 0 0 1 2",
        "facet x",
    ] {
        let text = stl("vertex 1 0 0").replace("facet normal 0 0 1", facet);
        let e = load_mesh_from_bytes(text.as_bytes(), "a.stl", None).unwrap_err();
        assert_eq!(e.location, Location::Line(2), "{facet}: {e}");
    }
    let bare = stl("vertex 1 0 0").replace("facet normal 0 0 1", "facet");
    load_mesh_from_bytes(bare.as_bytes(), "a.stl", None).unwrap();
    // OFF: colours after coordinates or indices are fine, words are not.
    let off = |v0: &str, f0: &str| format!("OFF\n3 1 0\n{v0}\n0 1 0\n0 0 1\n{f0}\n");
    load_mesh_from_bytes(
        off("1 0 0 255 0 0 255", "3 0 1 2 0.5 0.5 0.5").as_bytes(),
        "a.off",
        None,
    )
    .unwrap();
    for (v0, f0, line) in [("1 0 0 red", "3 0 1 2", 3), ("1 0 0", "3 0 1 2 red", 6)] {
        let e = load_mesh_from_bytes(off(v0, f0).as_bytes(), "a.off", None).unwrap_err();
        assert_eq!(e.location, Location::Line(line), "{e}");
        assert!(e.to_string().contains("invalid value `red`"), "{e}");
    }
    let e = load_mesh_from_bytes(stl("vertex 1 0 0 7").as_bytes(), "a.stl", None).unwrap_err();
    assert_eq!(e.location, Location::Line(4), "{e}");
    assert!(e.to_string().contains("more than three coordinates"), "{e}");
}

#[test]
fn points_files_without_points_say_so() {
    for text in ["", "\n\n", "# only a comment\n", "x,y,z\n", "x y z\n# c\n"] {
        let e = load_points_from_bytes(text.as_bytes(), "q.csv").unwrap_err();
        assert!(matches!(e.kind, LoadErrorKind::NoPoints), "{text:?}: {e}");
        assert_eq!(e.to_string(), "q.csv: contains no points");
    }
    // Semicolons separate values as in point-cloud files.
    assert_eq!(
        load_points_from_bytes(b"1;2;3\n", "q.csv").unwrap(),
        vec![[1.0, 2.0, 3.0]]
    );
}

const CLOUD_HEAD: &str = "ply\nformat ascii 1.0\nelement vertex 2\nproperty double x\n\
property float y\nproperty int z\nproperty float nx\nproperty float ny\nproperty float nz\n\
property uchar red\nproperty list uchar int extra\nelement face 1\n\
property list uchar int vertex_indices\nend_header\n";

#[test]
fn ply_point_clouds_use_the_mesh_reader() {
    // Any scalar types, extra scalar and list properties, and a face element (not read).
    let text = format!("{CLOUD_HEAD}0.5 1 2 0 0 1 255 2 7 8\n1 0 0 0 1 0 0 0\n3 0 1 1\n");
    let c = load_point_cloud_from_bytes(text.as_bytes(), "c.ply", None).unwrap();
    assert_eq!(c.positions(), &[[0.5, 1.0, 2.0], [1.0, 0.0, 0.0]]);
    assert_eq!(c.normals(), &[[0.0, 0.0, 1.0], [0.0, 1.0, 0.0]]);
    assert_eq!(c.areas(), None);
    // Line-strict like meshes: an extra value on vertex 0 is an error at its line.
    let text = format!("{CLOUD_HEAD}0.5 1 2 0 0 1 255 2 7 8 9\n1 0 0 0 1 0 0 0\n3 0 1 1\n");
    let e = load_point_cloud_from_bytes(text.as_bytes(), "c.ply", None).unwrap_err();
    assert_eq!(e.location, Location::Line(15), "{e}");
    // Binary big-endian with a double area.
    let mut bin = b"ply\nformat binary_big_endian 1.0\nelement vertex 1\nproperty float x\n\
property float y\nproperty float z\nproperty float nx\nproperty float ny\nproperty float nz\n\
property double area\nend_header\n"
        .to_vec();
    for v in [1.0f32, 2.0, 3.0, 0.0, 0.0, -1.0] {
        bin.extend_from_slice(&v.to_be_bytes());
    }
    bin.extend_from_slice(&0.25f64.to_be_bytes());
    let c = load_point_cloud_from_bytes(&bin, "b.ply", Some(CloudFormat::Ply)).unwrap();
    assert_eq!(c.areas(), Some(&[0.25][..]));
    bin.truncate(bin.len() - 1);
    let e = load_point_cloud_from_bytes(&bin, "b.ply", None).unwrap_err();
    assert!(matches!(e.kind, LoadErrorKind::Truncated(_)), "{e}");
    // No vertex element, or no vertices: no points.
    let none = "ply\nformat ascii 1.0\nelement vertex 0\nproperty float x\nproperty float y\n\
property float z\nproperty float nx\nproperty float ny\nproperty float nz\nend_header\n";
    let e = load_point_cloud_from_bytes(none.as_bytes(), "n.ply", None).unwrap_err();
    assert_eq!(e.to_string(), "n.ply: contains no points");
    // Non-finite values and negative areas name the vertex.
    let text = "ply\nformat ascii 1.0\nelement vertex 2\nproperty float x\nproperty float y\n\
property float z\nproperty float nx\nproperty float ny\nproperty float nz\n\
property float area\nend_header\n0 0 0 0 0 1 1\n0 0 0 0 0 1 -1\n";
    let e = load_point_cloud_from_bytes(text.as_bytes(), "a.ply", None).unwrap_err();
    assert_eq!(e.location, Location::Vertex(1), "{e}");
    let text = text
        .replace("-1\n", "1\n")
        .replace("0 0 0 0 0 1 1\n0", "0 nan 0 0 0 1 1\n0");
    let e = load_point_cloud_from_bytes(text.as_bytes(), "a.ply", None).unwrap_err();
    assert_eq!(e.location, Location::Vertex(0), "{e}");
}

#[test]
fn ply_point_cloud_warnings_reach_the_caller() {
    let dir = std::env::temp_dir().join(format!("gwn-strict-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let path = dir.join("w.ply");
    let text = "ply\nformat ascii 1.0\nexported by some tool\nelement vertex 1\n\
property float x\nproperty float y\nproperty float z\nproperty float nx\nproperty float ny\n\
property float nz\nend_header\n0 0 0 0 0 1\n";
    std::fs::write(&path, text).unwrap();
    let (cloud, warnings) = load_point_cloud_with_warnings(&path).unwrap();
    std::fs::remove_dir_all(&dir).unwrap();
    assert_eq!(cloud.len(), 1);
    assert_eq!(warnings.len(), 1);
    assert_eq!(warnings[0].location, Location::Line(3));
}

#[test]
fn grid_bounds_whose_extent_overflows_are_refused() {
    use gwn::BoundingBox;
    use gwn::grid::GridSpec;
    let b = |min: [f64; 3], max: [f64; 3]| BoundingBox { min, max };
    assert!(GridSpec::new(b([0.0; 3], [1.0; 3]), [2, 2, 2]).is_ok());
    assert!(GridSpec::new(b([-1e308, 0.0, 0.0], [1e308, 1.0, 1.0]), [2, 2, 2]).is_err());
    assert!(GridSpec::new(b([0.0, f64::NAN, 0.0], [1.0; 3]), [2, 2, 2]).is_err());
    assert!(GridSpec::with_resolution(b([0.0; 3], [f64::MAX, 1.0, 1.0]), 4).is_ok());
}

#[test]
fn tet_file_errors_say_line() {
    use gwn::io::tets::load_tets;
    let dir = std::env::temp_dir().join(format!("gwn-strict-tets-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    std::fs::write(dir.join("t.node"), "2 3 0 0\n1 0 0 0\n2 0 x 0\n").unwrap();
    std::fs::write(dir.join("t.ele"), "0 4 0\n").unwrap();
    let e = load_tets(dir.join("t.ele")).unwrap_err();
    std::fs::remove_dir_all(&dir).unwrap();
    let msg = e.to_string();
    assert!(
        msg.ends_with("t.node: line 3: expected a coordinate, found `x`"),
        "{msg}"
    );
}
