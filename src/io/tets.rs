//! TetGen `.node`/`.ele` and MEDIT `.mesh` tetrahedral meshes: small own parsers whose errors
//! name the file and line, never panic, and whose header counts never size an allocation beyond
//! what the file can hold. (`products::tets` filters the tets by a winding number.)
//!
//! Formats accepted:
//! - **TetGen**: `.node` header `<#points> 3 <#attributes> <0|1 markers>`, then
//!   `<index> x y z [attributes] [marker]`; `.ele` header `<#tets> <4|10> <#attributes>`, then
//!   `<index> n1 n2 n3 n4 [n5..n10] [attributes]`. `#` starts a comment. Indices start at 0 or 1
//!   (the first point's index decides, as in TetGen). For 10-node tets only the four corners are
//!   kept; attributes and markers are dropped. Written files are 1-based without attributes.
//! - **MEDIT** (`.mesh`, ascii): free-format keywords `MeshVersionFormatted`, `Dimension 3`,
//!   `Vertices`, `Tetrahedra` (1-based, with a reference that is kept), and `Triangles`, `Edges`,
//!   `Quadrilaterals`, `Hexahedra`, `Corners`, `Ridges`, `Required*`, `Normals`, `Tangents`,
//!   `NormalAtVertices` which are skipped; `End` stops reading. Other keywords are errors, and
//!   so is a file without a `Tetrahedra` section (an empty file).

use std::fmt;
use std::io::{self, Write};
use std::path::{Path, PathBuf};

use crate::mesh::TetMesh;

/// A tet-file error: file, 1-based line (0 when not tied to a line) and message.
#[derive(Debug)]
pub struct TetError {
    /// The file.
    pub path: PathBuf,
    /// 1-based line, 0 for file-level errors.
    pub line: usize,
    /// What is wrong.
    pub message: String,
}

impl fmt::Display for TetError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        if self.line > 0 {
            write!(
                f,
                "{}: line {}: {}",
                self.path.display(),
                self.line,
                self.message
            )
        } else {
            write!(f, "{}: {}", self.path.display(), self.message)
        }
    }
}

impl std::error::Error for TetError {}

/// A parse error before the file name is attached: 1-based line (0: whole file) and message.
pub type Fail = (usize, String);

/// Whitespace tokens with their 1-based line numbers; `#` comments removed.
fn tokens(bytes: &[u8]) -> Vec<(usize, &[u8])> {
    token_lines(bytes)
        .flat_map(|(n, toks)| toks.into_iter().map(move |t| (n, t)))
        .collect()
}

/// Non-empty lines (comments stripped) as token lists with their line numbers.
fn token_lines(bytes: &[u8]) -> impl Iterator<Item = (usize, Vec<&[u8]>)> {
    crate::io::text_lines(bytes).filter_map(|(n, line)| {
        let line = line.split(|&b| b == b'#').next().unwrap_or(&[]);
        let toks: Vec<&[u8]> = crate::io::tokens(line).collect();
        (!toks.is_empty()).then_some((n, toks))
    })
}

fn show(t: &[u8]) -> String {
    let s = String::from_utf8_lossy(t);
    s.chars().take(40).collect()
}

fn num<T: std::str::FromStr>(line: usize, t: &[u8], what: &str) -> Result<T, Fail> {
    std::str::from_utf8(t)
        .ok()
        .and_then(|s| s.parse().ok())
        .ok_or_else(|| (line, format!("expected {what}, found `{}`", show(t))))
}

fn finite(line: usize, t: &[u8]) -> Result<f64, Fail> {
    let v: f64 = num(line, t, "a coordinate")?;
    if v.is_finite() {
        Ok(v)
    } else {
        Err((line, format!("coordinate `{}` is not finite", show(t))))
    }
}

fn capped(count: usize, len: usize, min_bytes: usize) -> usize {
    count.min(len / min_bytes)
}

/// Parses a TetGen `.node` file: points and the index base (0 or 1).
pub fn parse_node(bytes: &[u8]) -> Result<(Vec<[f64; 3]>, u64), Fail> {
    let mut lines = token_lines(bytes);
    let (hl, head) = lines.next().ok_or((0, "empty .node file".to_string()))?;
    if head.len() < 2 {
        return Err((hl, "header needs `<#points> <dimension> ...`".into()));
    }
    let n: usize = num(hl, head[0], "the number of points")?;
    let dim: usize = num(hl, head[1], "the dimension")?;
    if dim != 3 {
        return Err((hl, format!("dimension {dim} is not supported (only 3)")));
    }
    let mut pts = Vec::with_capacity(capped(n, bytes.len(), 8));
    let mut base = 0u64;
    for i in 0..n {
        let (l, toks) = lines.next().ok_or((
            0,
            format!("file ends after {i} of {n} points announced by the header"),
        ))?;
        if toks.len() < 4 {
            return Err((l, "point line needs `<index> x y z`".into()));
        }
        let idx: u64 = num(l, toks[0], "a point index")?;
        if i == 0 {
            if idx > 1 {
                return Err((l, format!("first point index must be 0 or 1, found {idx}")));
            }
            base = idx;
        } else if idx != base + i as u64 {
            return Err((
                l,
                format!(
                    "point index {idx} out of sequence (expected {})",
                    base + i as u64
                ),
            ));
        }
        pts.push([
            finite(l, toks[1])?,
            finite(l, toks[2])?,
            finite(l, toks[3])?,
        ]);
    }
    if pts.len() > u32::MAX as usize {
        return Err((hl, "too many points".into()));
    }
    Ok((pts, base))
}

/// Parses a TetGen `.ele` file against `points` points whose indices start at `base`.
pub fn parse_ele(bytes: &[u8], points: usize, base: u64) -> Result<Vec<[u32; 4]>, Fail> {
    let mut lines = token_lines(bytes);
    let (hl, head) = lines.next().ok_or((0, "empty .ele file".to_string()))?;
    if head.len() < 2 {
        return Err((hl, "header needs `<#tets> <nodes per tet> ...`".into()));
    }
    let n: usize = num(hl, head[0], "the number of tets")?;
    let per: usize = num(hl, head[1], "the nodes per tet")?;
    if per != 4 && per != 10 {
        return Err((
            hl,
            format!("{per} nodes per tet is not supported (4 or 10)"),
        ));
    }
    let mut tets = Vec::with_capacity(capped(n, bytes.len(), 10));
    for i in 0..n {
        let (l, toks) = lines.next().ok_or((
            0,
            format!("file ends after {i} of {n} tets announced by the header"),
        ))?;
        if toks.len() < 1 + per {
            return Err((l, format!("tet line needs an index and {per} corners")));
        }
        let mut t = [0u32; 4];
        for k in 0..4 {
            let v: u64 = num(l, toks[1 + k], "a point index")?;
            let i0 = v.checked_sub(base).filter(|&i| i < points as u64).ok_or((
                l,
                format!("corner index {v} outside the {points} points (first index {base})"),
            ))?;
            t[k] = i0 as u32;
        }
        tets.push(t);
    }
    Ok(tets)
}

/// Parses an ascii MEDIT `.mesh` file.
pub fn parse_medit(bytes: &[u8]) -> Result<TetMesh, Fail> {
    let toks = tokens(bytes);
    let mut it = toks.iter().copied().peekable();
    let mut mesh = TetMesh::default();
    let mut raw_tets: Vec<([u64; 4], usize)> = Vec::new();
    let mut has_tets = false;
    let mut next = |what: &str, last: usize| -> Result<(usize, &[u8]), Fail> {
        it.next()
            .ok_or_else(|| (last, format!("file ends where {what} was expected")))
    };
    let mut last = 0usize;
    while let Ok((l, kw)) = next("a keyword or `End`", last) {
        last = l;
        let kw = String::from_utf8_lossy(kw).to_string();
        let skip = |k: &str| -> Option<usize> {
            Some(match k {
                "Triangles" => 4,
                "Edges" => 3,
                "Quadrilaterals" => 5,
                "Hexahedra" => 9,
                "Corners"
                | "Ridges"
                | "RequiredVertices"
                | "RequiredEdges"
                | "RequiredTriangles"
                | "RequiredQuadrilaterals"
                | "RequiredTetrahedra" => 1,
                "Normals" | "Tangents" => 3,
                "NormalAtVertices" | "TangentAtVertices" => 2,
                _ => return None,
            })
        };
        match kw.as_str() {
            "End" => break,
            "MeshVersionFormatted" => {
                let (l, v) = next("a version", last)?;
                let _: u32 = num(l, v, "a version number")?;
            }
            "Dimension" => {
                let (l, v) = next("a dimension", last)?;
                let d: u32 = num(l, v, "a dimension")?;
                if d != 3 {
                    return Err((l, format!("dimension {d} is not supported (only 3)")));
                }
            }
            "Vertices" => {
                let (l, v) = next("a vertex count", last)?;
                let n: usize = num(l, v, "a vertex count")?;
                mesh.points.reserve(capped(n, bytes.len(), 8));
                for _ in 0..n {
                    let mut p = [0.0; 3];
                    for c in &mut p {
                        let (l, v) = next("a coordinate", last)?;
                        last = l;
                        *c = finite(l, v)?;
                    }
                    let (l, v) = next("a vertex reference", last)?;
                    last = l;
                    let _: i64 = num(l, v, "a vertex reference")?;
                    mesh.points.push(p);
                }
            }
            "Tetrahedra" => {
                has_tets = true;
                let (l, v) = next("a tet count", last)?;
                let n: usize = num(l, v, "a tet count")?;
                raw_tets.reserve(capped(n, bytes.len(), 10));
                mesh.refs.reserve(capped(n, bytes.len(), 10));
                for _ in 0..n {
                    let mut t = [0u64; 4];
                    let mut line = 0;
                    for c in &mut t {
                        let (l, v) = next("a tet corner", last)?;
                        last = l;
                        line = l;
                        *c = num(l, v, "a tet corner index")?;
                    }
                    let (l, v) = next("a tet reference", last)?;
                    last = l;
                    mesh.refs.push(num(l, v, "a tet reference")?);
                    raw_tets.push((t, line));
                }
            }
            k => {
                let Some(per) = skip(k) else {
                    return Err((l, format!("unsupported keyword `{}`", show(kw.as_bytes()))));
                };
                let (l, v) = next("a count", last)?;
                let n: usize = num(l, v, "a count")?;
                for _ in 0..n.saturating_mul(per) {
                    let (l, _) = next("an entry", last)?;
                    last = l;
                }
            }
        }
    }
    if !has_tets {
        // An empty or header-only file is a mistake, not an empty mesh: `gwn filter-tets`
        // exited 0 having done nothing. (`Tetrahedra 0`, as written for an empty result, reads.)
        return Err((last, "no `Tetrahedra` section (empty file?)".into()));
    }
    let np = mesh.points.len() as u64;
    if np > u64::from(u32::MAX) {
        return Err((0, "too many vertices".into()));
    }
    for (t, line) in raw_tets {
        let mut out = [0u32; 4];
        for k in 0..4 {
            if t[k] == 0 || t[k] > np {
                return Err((
                    line,
                    format!("tet corner {} outside the {np} vertices (1-based)", t[k]),
                ));
            }
            out[k] = (t[k] - 1) as u32;
        }
        mesh.tets.push(out);
    }
    Ok(mesh)
}

fn read(path: &Path) -> Result<Vec<u8>, TetError> {
    crate::io::read_input(path).map_err(|e| TetError {
        path: path.to_path_buf(),
        line: 0,
        message: e.kind.to_string(),
    })
}

fn at(path: &Path) -> impl Fn(Fail) -> TetError + '_ {
    move |(line, message)| TetError {
        path: path.to_path_buf(),
        line,
        message,
    }
}

fn ext(path: &Path) -> String {
    path.extension()
        .and_then(|e| e.to_str())
        .unwrap_or("")
        .to_ascii_lowercase()
}

/// Loads a tet mesh: `.mesh` (MEDIT), or `.node`/`.ele` (TetGen: the other file of the pair is
/// the same path with the other extension).
pub fn load_tets(path: impl AsRef<Path>) -> Result<TetMesh, TetError> {
    let path = path.as_ref();
    match ext(path).as_str() {
        "mesh" => parse_medit(&read(path)?).map_err(at(path)),
        "node" | "ele" => {
            let node = path.with_extension("node");
            let ele = path.with_extension("ele");
            let (points, base) = parse_node(&read(&node)?).map_err(at(&node))?;
            let tets = parse_ele(&read(&ele)?, points.len(), base).map_err(at(&ele))?;
            let refs = vec![0; tets.len()];
            Ok(TetMesh { points, tets, refs })
        }
        _ => Err(TetError {
            path: path.to_path_buf(),
            line: 0,
            message: "unknown tet mesh format (expected .mesh, .node or .ele)".into(),
        }),
    }
}

/// Writes MEDIT ascii (`MeshVersionFormatted 2`, 1-based, references kept).
pub fn write_medit(mut w: impl Write, mesh: &TetMesh) -> io::Result<()> {
    writeln!(
        w,
        "MeshVersionFormatted 2\nDimension 3\nVertices\n{}",
        mesh.points.len()
    )?;
    for p in &mesh.points {
        writeln!(w, "{:?} {:?} {:?} 0", p[0], p[1], p[2])?;
    }
    writeln!(w, "Tetrahedra\n{}", mesh.tets.len())?;
    for (i, t) in mesh.tets.iter().enumerate() {
        let r = mesh.refs.get(i).copied().unwrap_or(0);
        writeln!(w, "{} {} {} {} {r}", t[0] + 1, t[1] + 1, t[2] + 1, t[3] + 1)?;
    }
    writeln!(w, "End")?;
    w.flush()
}

/// Writes a TetGen `.node` (1-based, no attributes or markers).
pub fn write_node(mut w: impl Write, points: &[[f64; 3]]) -> io::Result<()> {
    writeln!(w, "{} 3 0 0", points.len())?;
    for (i, p) in points.iter().enumerate() {
        writeln!(w, "{} {:?} {:?} {:?}", i + 1, p[0], p[1], p[2])?;
    }
    w.flush()
}

/// Writes a TetGen `.ele` (1-based, 4 nodes, no attributes).
pub fn write_ele(mut w: impl Write, tets: &[[u32; 4]]) -> io::Result<()> {
    writeln!(w, "{} 4 0", tets.len())?;
    for (i, t) in tets.iter().enumerate() {
        writeln!(
            w,
            "{} {} {} {} {}",
            i + 1,
            t[0] + 1,
            t[1] + 1,
            t[2] + 1,
            t[3] + 1
        )?;
    }
    w.flush()
}

/// Saves by extension: `.mesh` → MEDIT; `.node` or `.ele` → the TetGen pair. Returns the
/// files written. Error messages start with the name of the file concerned.
pub fn save_tets(path: impl AsRef<Path>, mesh: &TetMesh) -> io::Result<Vec<PathBuf>> {
    let path = path.as_ref();
    // Every error names the file it concerns (with `.node`/`.ele` pairs that is not always
    // `path`), so callers need not and must not add it again.
    let named = |p: &Path| {
        let p = p.to_path_buf();
        move |e: io::Error| io::Error::new(e.kind(), format!("{}: {e}", p.display()))
    };
    let create = |p: &Path| {
        std::fs::File::create(p)
            .map(io::BufWriter::new)
            .map_err(named(p))
    };
    match ext(path).as_str() {
        "mesh" => {
            write_medit(create(path)?, mesh).map_err(named(path))?;
            Ok(vec![path.to_path_buf()])
        }
        "node" | "ele" => {
            let node = path.with_extension("node");
            let ele = path.with_extension("ele");
            write_node(create(&node)?, &mesh.points).map_err(named(&node))?;
            write_ele(create(&ele)?, &mesh.tets).map_err(named(&ele))?;
            Ok(vec![node, ele])
        }
        _ => Err(io::Error::new(
            io::ErrorKind::InvalidInput,
            format!(
                "{}: unknown tet mesh format (expected .mesh, .node or .ele)",
                path.display()
            ),
        )),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn tetgen_and_medit_round_trip() {
        let m = TetMesh {
            points: vec![[0.0; 3], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.5]],
            tets: vec![[0, 1, 2, 3]],
            refs: vec![7],
        };
        let mut node = Vec::new();
        let mut ele = Vec::new();
        write_node(&mut node, &m.points).unwrap();
        write_ele(&mut ele, &m.tets).unwrap();
        let (p, base) = parse_node(&node).unwrap();
        assert_eq!((p.clone(), base), (m.points.clone(), 1));
        assert_eq!(parse_ele(&ele, p.len(), base).unwrap(), m.tets);
        let mut med = Vec::new();
        write_medit(&mut med, &m).unwrap();
        assert_eq!(parse_medit(&med).unwrap(), m);
    }

    #[test]
    fn malformed_inputs_are_line_numbered_errors() {
        assert_eq!(parse_node(b"3 3 0 0\n1 0 0 0\n2 1 0 0\n").unwrap_err().0, 0);
        assert_eq!(
            parse_node(b"# c\n2 3 0 0\n0 0 0 0\n1 x 0 0\n")
                .unwrap_err()
                .0,
            4
        );
        assert_eq!(parse_node(b"2 2 0 0\n").unwrap_err().0, 1);
        // A lying header does not allocate.
        assert!(parse_node(b"999999999999 3 0 0\n").is_err());
        let e = parse_ele(b"1 4 0\n1 1 2 3 9\n", 4, 1).unwrap_err();
        assert_eq!(e.0, 2);
        assert!(e.1.contains('9'));
        let e = parse_medit(b"MeshVersionFormatted 2\nDimension 3\nFoo 1\n").unwrap_err();
        assert_eq!(e.0, 3);
        let e = parse_medit(b"Vertices\n1\n0 0 0 0\nTetrahedra\n1\n1 1 1 2 0\nEnd\n").unwrap_err();
        assert_eq!(e.0, 6);
    }
}
