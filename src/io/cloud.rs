//! Oriented point clouds for the fast winding number of points.
//!
//! - Text (`.xyz`, `.xyzn`, `.csv`, `.txt`, `.pts`, anything not starting with `ply`): one point
//!   per line, `x y z nx ny nz [area]`, separated by whitespace, commas or semicolons. Blank lines
//!   and lines starting with `#` or `//` are skipped, and so is one header line before the first
//!   point if it does not parse as numbers. Every point must have the column count of the first
//!   (6 or 7).
//! - PLY (ascii or binary, via `ply-rs-bw`): the `vertex` element with `x y z nx ny nz` and an
//!   optional `area` property (any scalar types).
//!
//! Errors name the file and the line (text), or the vertex (PLY values).

use std::path::Path;

use ply_rs_bw::parser::Parser;
use ply_rs_bw::ply::{DefaultElement, Property};

use super::{parse_num, show, text_lines};
use crate::error::{LoadError, LoadErrorKind, Location};
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
    let path = path.as_ref();
    let bytes = std::fs::read(path)
        .map_err(|e| LoadError::new(path, Location::File, LoadErrorKind::Io(e)))?;
    load_point_cloud_from_bytes(&bytes, path, cloud_format_from_extension(path))
}

/// Parses an oriented point cloud from bytes; `format: None` detects PLY by its `ply` magic
/// and reads anything else as text.
pub fn load_point_cloud_from_bytes(
    bytes: &[u8],
    name_for_errors: impl AsRef<Path>,
    format: Option<CloudFormat>,
) -> Result<PointCloud, LoadError> {
    let name = name_for_errors.as_ref();
    let format = format.unwrap_or(if bytes.starts_with(b"ply") {
        CloudFormat::Ply
    } else {
        CloudFormat::Text
    });
    let parsed = match format {
        CloudFormat::Text => parse_text(bytes),
        CloudFormat::Ply => parse_ply(bytes),
    };
    let (positions, normals, areas) =
        parsed.map_err(|(location, kind)| LoadError::new(name, location, kind))?;
    if positions.is_empty() {
        return Err(LoadError::new(name, Location::File, LoadErrorKind::Empty));
    }
    PointCloud::new(positions, normals, areas)
        .map_err(|e| LoadError::new(name, Location::File, LoadErrorKind::Syntax(e.to_string())))
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
        let toks: Vec<&[u8]> = trimmed
            .split(|&b| b.is_ascii_whitespace() || b == b',' || b == b';')
            .filter(|t| !t.is_empty())
            .collect();
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

fn scalar(p: &Property) -> Option<f64> {
    Some(match *p {
        Property::Char(v) => f64::from(v),
        Property::UChar(v) => f64::from(v),
        Property::Short(v) => f64::from(v),
        Property::UShort(v) => f64::from(v),
        Property::Int(v) => f64::from(v),
        Property::UInt(v) => f64::from(v),
        Property::Float(v) => f64::from(v),
        Property::Double(v) => v,
        _ => return None,
    })
}

fn parse_ply(bytes: &[u8]) -> Result<Columns, Fail> {
    let parser = Parser::<DefaultElement>::new();
    let mut src = bytes;
    let ply = parser.read_ply(&mut src).map_err(|e| {
        let at = e.line().map_or(Location::File, Location::Line);
        syntax(at, format!("invalid PLY: {e}"))
    })?;
    let Some(vertices) = ply.payload.get("vertex") else {
        return Err(syntax(Location::File, "PLY has no `vertex` element".into()));
    };
    let def = &ply.header.elements["vertex"];
    for key in ["x", "y", "z", "nx", "ny", "nz"] {
        if !def.properties.contains_key(key) {
            return Err(syntax(
                Location::File,
                format!(
                    "PLY `vertex` element has no `{key}` property (a point cloud needs x y z nx ny nz)"
                ),
            ));
        }
    }
    let has_area = def.properties.contains_key("area");
    let mut positions = Vec::with_capacity(vertices.len());
    let mut normals = Vec::with_capacity(vertices.len());
    let mut areas = Vec::with_capacity(if has_area { vertices.len() } else { 0 });
    for (i, v) in vertices.iter().enumerate() {
        let at = || Location::Vertex(i);
        let get = |key: &str| -> Result<f64, Fail> {
            let x = v
                .get(key)
                .and_then(scalar)
                .ok_or_else(|| syntax(at(), format!("property `{key}` is not a scalar")))?;
            if x.is_finite() {
                Ok(x)
            } else {
                Err(syntax(at(), format!("property `{key}` is {x}")))
            }
        };
        positions.push([get("x")?, get("y")?, get("z")?]);
        normals.push([get("nx")?, get("ny")?, get("nz")?]);
        if has_area {
            let a = get("area")?;
            if a < 0.0 {
                return Err(syntax(at(), format!("negative area {a}")));
            }
            areas.push(a);
        }
    }
    Ok((positions, normals, has_area.then_some(areas)))
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
        assert!(matches!(e.kind, LoadErrorKind::Empty));
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
