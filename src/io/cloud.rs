//! Oriented point clouds for the fast winding number of points.
//!
//! - Text (`.xyz`, `.xyzn`, `.csv`, `.txt`, `.pts`, anything not starting with `ply`): one point
//!   per line, `x y z nx ny nz [area]`, separated by whitespace, commas or semicolons. Blank lines
//!   and lines starting with `#` or `//` are skipped, and so is one header line before the first
//!   point if it does not parse as numbers. Every point must have the column count of the first
//!   (6 or 7).
//! - PLY (ascii or binary, read by the mesh loader's PLY reader): the `vertex` element with
//!   `x y z nx ny nz` and an optional `area` property (any scalar types); faces are not read.
//!
//! Errors name the file and the line (text), or the vertex (PLY values).

use std::path::Path;

use super::{COLUMN_SEPARATORS, parse_num, show, text_lines, tokens_separated_by};
use crate::error::{LoadError, LoadErrorKind, LoadWarning, Location};
use crate::mesh::PointCloud;

/// A point-cloud file format.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum CloudFormat {
    /// Columns of numbers: `x y z nx ny nz [area]`.
    Text,
    /// Stanford PLY with normals.
    Ply,
}

/// The format implied by the extension (`.ply` → PLY; `.xyz`, `.xyzn`, `.csv`, `.txt`, `.pts`
/// → text), case-insensitive.
pub fn cloud_format_from_extension(path: impl AsRef<Path>) -> Option<CloudFormat> {
    let ext = path.as_ref().extension()?.to_str()?.to_ascii_lowercase();
    match ext.as_str() {
        "ply" => Some(CloudFormat::Ply),
        "xyz" | "xyzn" | "csv" | "txt" | "pts" => Some(CloudFormat::Text),
        _ => None,
    }
}

/// Loads an oriented point cloud (format from the extension, else from the content).
pub fn load_point_cloud(path: impl AsRef<Path>) -> Result<PointCloud, LoadError> {
    load_point_cloud_with_warnings(path).map(|(cloud, _)| cloud)
}

/// [`load_point_cloud`], also returning what the reader ignored (e.g. unknown PLY header lines).
pub fn load_point_cloud_with_warnings(
    path: impl AsRef<Path>,
) -> Result<(PointCloud, Vec<LoadWarning>), LoadError> {
    let path = path.as_ref();
    let bytes = super::read_input(path)?;
    parse_cloud(&bytes, path, cloud_format_from_extension(path))
}

/// Parses an oriented point cloud from bytes; `format: None` detects PLY by its `ply` magic
/// and reads anything else as text.
pub fn load_point_cloud_from_bytes(
    bytes: &[u8],
    name_for_errors: impl AsRef<Path>,
    format: Option<CloudFormat>,
) -> Result<PointCloud, LoadError> {
    parse_cloud(bytes, name_for_errors.as_ref(), format).map(|(cloud, _)| cloud)
}

fn parse_cloud(
    bytes: &[u8],
    name: &Path,
    format: Option<CloudFormat>,
) -> Result<(PointCloud, Vec<LoadWarning>), LoadError> {
    let format = format.unwrap_or(if bytes.starts_with(b"ply") {
        CloudFormat::Ply
    } else {
        CloudFormat::Text
    });
    let parsed = match format {
        CloudFormat::Text => parse_text(bytes).map(|c| (c, Vec::new())),
        CloudFormat::Ply => parse_ply(bytes),
    };
    finish_cloud(parsed, name)
}

/// The cloud of what a reader returned (an empty one is an error).
fn finish_cloud(
    parsed: Result<(Columns, Vec<LoadWarning>), Fail>,
    name: &Path,
) -> Result<(PointCloud, Vec<LoadWarning>), LoadError> {
    let ((positions, normals, areas), warnings) =
        parsed.map_err(|(location, kind)| LoadError::new(name, location, kind))?;
    if positions.is_empty() {
        return Err(LoadError::new(
            name,
            Location::File,
            LoadErrorKind::NoPoints,
        ));
    }
    let cloud = PointCloud::new(positions, normals, areas)
        .map_err(|e| LoadError::new(name, Location::File, LoadErrorKind::Syntax(e.to_string())))?;
    Ok((cloud, warnings))
}

type Columns = (Vec<[f64; 3]>, Vec<[f64; 3]>, Option<Vec<f64>>);
type Fail = (Location, LoadErrorKind);

fn syntax(location: Location, msg: String) -> Fail {
    (location, LoadErrorKind::Syntax(msg))
}

fn parse_text(bytes: &[u8]) -> Result<Columns, Fail> {
    let mut positions = Vec::new();
    let mut normals = Vec::new();
    let mut areas = Vec::new();
    let mut columns: Option<usize> = None;
    let mut header_skipped = false;
    for (line_no, line) in text_lines(bytes) {
        let trimmed = line.trim_ascii();
        if trimmed.is_empty() || trimmed.starts_with(b"#") || trimmed.starts_with(b"//") {
            continue;
        }
        let toks: Vec<&[u8]> = tokens_separated_by(trimmed, COLUMN_SEPARATORS).collect();
        let values: Option<Vec<f64>> = toks.iter().map(|t| parse_num::<f64>(t)).collect();
        let at = Location::Line(line_no);
        let values = match values {
            Some(v) => v,
            None if columns.is_none() && !header_skipped => {
                header_skipped = true;
                continue;
            }
            None => {
                let bad = toks
                    .iter()
                    .find(|t| parse_num::<f64>(t).is_none())
                    .map_or_else(String::new, |t| show(t));
                return Err(syntax(at, format!("expected a number, found `{bad}`")));
            }
        };
        let expected = *columns.get_or_insert(values.len());
        if values.len() != expected || !(expected == 6 || expected == 7) {
            return Err(syntax(
                at,
                format!(
                    "expected {} numbers (x y z nx ny nz [area]), found {}",
                    if expected == 6 || expected == 7 {
                        expected.to_string()
                    } else {
                        "6 or 7".to_string()
                    },
                    values.len()
                ),
            ));
        }
        if let Some(v) = values.iter().find(|v| !v.is_finite()) {
            return Err(syntax(at, format!("non-finite value {v}")));
        }
        positions.push([values[0], values[1], values[2]]);
        normals.push([values[3], values[4], values[5]]);
        if expected == 7 {
            if values[6] < 0.0 {
                return Err(syntax(at, format!("negative area {}", values[6])));
            }
            areas.push(values[6]);
        }
    }
    let areas = (columns == Some(7)).then_some(areas);
    Ok((positions, normals, areas))
}

/// The vertex properties of a point-cloud PLY, in the order [`ply_columns`] reads them.
const NAMES: [&str; 7] = ["x", "y", "z", "nx", "ny", "nz", "area"];

fn parse_ply(bytes: &[u8]) -> Result<(Columns, Vec<LoadWarning>), Fail> {
    let data = super::ply::read(
        bytes,
        &super::ply::Request {
            vertex: &NAMES.map(|c| (c, c != "area")),
            faces: false,
        },
    )?;
    ply_columns(data)
}

/// What [`super::load_mesh_or_cloud`] reads from a PLY: positions (required), normals and areas
/// (optional: a mesh needs none), and the faces.
pub(super) const PLY_MESH_OR_CLOUD: super::ply::Request<'static> = super::ply::Request {
    vertex: &[
        ("x", true),
        ("y", true),
        ("z", true),
        ("nx", false),
        ("ny", false),
        ("nz", false),
        ("area", false),
    ],
    faces: true,
};

/// The point cloud of a PLY read with [`PLY_MESH_OR_CLOUD`] that turned out to have no faces.
pub(super) fn cloud_from_ply(
    data: super::ply::PlyData,
    name: &Path,
) -> Result<(PointCloud, Vec<LoadWarning>), LoadError> {
    if let Some(k) = (3..6).find(|&k| data.columns[k].is_none()) {
        return Err(LoadError::new(
            name,
            Location::File,
            // Said whole: a PLY meant as a mesh but without faces lands here too.
            LoadErrorKind::Syntax(format!(
                "no faces (not a mesh), and as a point cloud: PLY `vertex` element has no \
                 scalar property `{}`",
                NAMES[k]
            )),
        ));
    }
    finish_cloud(ply_columns(data), name)
}

/// Checks the columns `x y z nx ny nz [area]` of a PLY read and makes them points and normals.
fn ply_columns(data: super::ply::PlyData) -> Result<(Columns, Vec<LoadWarning>), Fail> {
    let mut columns = data.columns.into_iter();
    let mut next = || columns.next().flatten().unwrap_or_default();
    let [x, y, z, nx, ny, nz]: [Vec<f64>; 6] = std::array::from_fn(|_| next());
    let area = columns.next().flatten();
    let all: Vec<&Vec<f64>> = [&x, &y, &z, &nx, &ny, &nz]
        .into_iter()
        .chain(area.as_ref())
        .collect();
    for i in 0..x.len() {
        for (name, col) in NAMES.iter().zip(&all) {
            let v = col[i];
            if !v.is_finite() {
                return Err(syntax(
                    Location::Vertex(i),
                    format!("property `{name}` is {v}"),
                ));
            }
            if *name == "area" && v < 0.0 {
                return Err(syntax(Location::Vertex(i), format!("negative area {v}")));
            }
        }
    }
    let positions = (0..x.len()).map(|i| [x[i], y[i], z[i]]).collect();
    let normals = (0..x.len()).map(|i| [nx[i], ny[i], nz[i]]).collect();
    Ok(((positions, normals, area), data.warnings))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn text_with_header_comments_and_areas() {
        let src = b"# comment\nx,y,z,nx,ny,nz,area\n0,0,0, 0,0,1, 0.5\n\n1;2;3;0;1;0;0.25\r\n";
        let c = load_point_cloud_from_bytes(src, "a.csv", None).unwrap();
        assert_eq!(c.len(), 2);
        assert_eq!(c.positions()[1], [1.0, 2.0, 3.0]);
        assert_eq!(c.areas(), Some(&[0.5, 0.25][..]));
    }

    #[test]
    fn text_without_areas() {
        let c = load_point_cloud_from_bytes(b"0 0 0 0 0 2\n1 1 1 1 0 0\n", "a.xyz", None).unwrap();
        assert_eq!(c.areas(), None);
        assert_eq!(c.normals()[0], [0.0, 0.0, 1.0]);
    }

    #[test]
    fn text_errors_name_file_and_line() {
        let e =
            load_point_cloud_from_bytes(b"0 0 0 0 0 1\n0 0 0 0 1\n", "p.xyz", None).unwrap_err();
        assert_eq!(e.location, Location::Line(2));
        let msg = e.to_string();
        assert!(msg.contains("p.xyz") && msg.contains("line 2"), "{msg}");
        let e = load_point_cloud_from_bytes(b"0 0 0 0 0 1\n0 0 zero 0 0 1\n", "p.xyz", None)
            .unwrap_err();
        assert_eq!(e.location, Location::Line(2));
        assert!(e.to_string().contains("zero"));
        let e = load_point_cloud_from_bytes(b"1 2 3\n", "p.xyz", None).unwrap_err();
        assert_eq!(e.location, Location::Line(1));
        let e = load_point_cloud_from_bytes(b"# nothing\n", "p.xyz", None).unwrap_err();
        assert!(matches!(e.kind, LoadErrorKind::NoPoints));
        assert!(e.to_string().ends_with("contains no points"), "{e}");
    }

    #[test]
    fn ply_ascii_with_and_without_area() {
        let src = b"ply\nformat ascii 1.0\nelement vertex 2\nproperty float x\nproperty float y\n\
property float z\nproperty float nx\nproperty float ny\nproperty float nz\nproperty double area\n\
end_header\n0 0 0 0 0 1 0.5\n1 0 0 0 0 1 0.25\n";
        let c = load_point_cloud_from_bytes(src, "c.ply", None).unwrap();
        assert_eq!(c.len(), 2);
        assert_eq!(c.areas(), Some(&[0.5, 0.25][..]));
        let src = b"ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\nproperty float y\n\
property float z\nend_header\n0 0 0\n";
        let e = load_point_cloud_from_bytes(src, "c.ply", None).unwrap_err();
        assert!(e.to_string().contains("nx"), "{e}");
    }

    #[test]
    fn ply_binary_little_endian() {
        let mut src = b"ply\nformat binary_little_endian 1.0\nelement vertex 1\nproperty float x\n\
property float y\nproperty float z\nproperty float nx\nproperty float ny\nproperty float nz\n\
end_header\n"
            .to_vec();
        for v in [1.0f32, 2.0, 3.0, 0.0, 0.0, -1.0] {
            src.extend_from_slice(&v.to_le_bytes());
        }
        let c = load_point_cloud_from_bytes(&src, "b.ply", None).unwrap();
        assert_eq!(c.positions()[0], [1.0, 2.0, 3.0]);
        assert_eq!(c.normals()[0], [0.0, 0.0, -1.0]);
        assert_eq!(c.areas(), None);
    }
}
