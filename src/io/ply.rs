//! PLY reader (own code): ascii, binary little-endian and binary big-endian. The one PLY reader
//! of the crate: meshes ([`parse`]) and point clouds ([`read_vertices`], used by `io::cloud`)
//! both go through [`read`].
//!
//! We do not use `ply-rs-bw`: it builds a hash map per element (slow and memory-hungry for
//! 200k-face meshes), its errors carry no byte offset or line, and making it panic-free on
//! untrusted input would need a full header validation of our own anyway — which is most of a
//! reader. This one validates the header completely, then streams the body without allocating
//! from untrusted counts.
//!
//! Accepted: any elements in any order (e.g. `camera` before `vertex`; unknown elements and
//! properties are skipped, lists included); `vertex` needs scalar `x`, `y`, `z` of any numeric
//! type; `face` needs a list `vertex_indices` or `vertex_index` with any integer count and item
//! type. Polygons are fan-triangulated; faces with fewer than 3 corners add no triangle. A body
//! that ends early is [`LoadErrorKind::Truncated`] (byte offset for binary, line for ascii);
//! data after the last element is ignored. In ascii, every element instance is one line holding
//! exactly its values (blank lines are skipped), and every integer value must fit its declared
//! type. Header lines that are not `format`/`element`/`property`/`comment`/`obj_info` (such as
//! Blender 2.47's `Created by Blender3D 247 …`) are ignored with a warning.

use super::{Fail, RawMesh, capped_capacity, fan, index_error, show, text_lines, tokens};
use crate::error::{LoadErrorKind, LoadWarning, Location};

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Scalar {
    I8,
    U8,
    I16,
    U16,
    I32,
    U32,
    F32,
    F64,
}

impl Scalar {
    fn parse(s: &str) -> Option<Scalar> {
        Some(match s {
            "char" | "int8" => Scalar::I8,
            "uchar" | "uint8" => Scalar::U8,
            "short" | "int16" => Scalar::I16,
            "ushort" | "uint16" => Scalar::U16,
            "int" | "int32" => Scalar::I32,
            "uint" | "uint32" => Scalar::U32,
            "float" | "float32" => Scalar::F32,
            "double" | "float64" => Scalar::F64,
            _ => return None,
        })
    }

    fn size(self) -> usize {
        match self {
            Scalar::I8 | Scalar::U8 => 1,
            Scalar::I16 | Scalar::U16 => 2,
            Scalar::I32 | Scalar::U32 | Scalar::F32 => 4,
            Scalar::F64 => 8,
        }
    }

    /// The inclusive value range of an integer type; `None` for floating-point types.
    fn int_range(self) -> Option<(f64, f64)> {
        Some(match self {
            Scalar::I8 => (i8::MIN.into(), i8::MAX.into()),
            Scalar::U8 => (0.0, u8::MAX.into()),
            Scalar::I16 => (i16::MIN.into(), i16::MAX.into()),
            Scalar::U16 => (0.0, u16::MAX.into()),
            Scalar::I32 => (i32::MIN.into(), i32::MAX.into()),
            Scalar::U32 => (0.0, u32::MAX.into()),
            Scalar::F32 | Scalar::F64 => return None,
        })
    }

    fn is_int(self) -> bool {
        self.int_range().is_some()
    }

    fn name(self) -> &'static str {
        match self {
            Scalar::I8 => "char",
            Scalar::U8 => "uchar",
            Scalar::I16 => "short",
            Scalar::U16 => "ushort",
            Scalar::I32 => "int",
            Scalar::U32 => "uint",
            Scalar::F32 => "float",
            Scalar::F64 => "double",
        }
    }
}

#[derive(Clone, Copy, Debug)]
enum Prop {
    Scalar(Scalar),
    List(Scalar, Scalar),
}

#[derive(Debug)]
struct Element {
    name: String,
    count: u64,
    props: Vec<(String, Prop)>,
}

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Encoding {
    Ascii,
    Little,
    Big,
}

struct Header {
    encoding: Encoding,
    elements: Vec<Element>,
    /// Byte offset of the body.
    body: usize,
    /// Number of header lines (the body starts on the next line).
    lines: usize,
    warnings: Vec<LoadWarning>,
}

fn syntax(line: usize, msg: String) -> Fail {
    (Location::Line(line), LoadErrorKind::Syntax(msg))
}

fn parse_header(bytes: &[u8]) -> Result<Header, Fail> {
    let mut pos = 0;
    let mut ln = 0;
    let mut encoding = None;
    let mut elements: Vec<Element> = Vec::new();
    let mut warnings = Vec::new();
    loop {
        ln += 1;
        let Some(nl) = bytes[pos..].iter().position(|&b| b == b'\n') else {
            return Err((
                Location::Line(ln),
                LoadErrorKind::Truncated("PLY header has no `end_header` line".into()),
            ));
        };
        let raw = &bytes[pos..pos + nl];
        pos += nl + 1;
        let raw = raw.strip_suffix(b"\r").unwrap_or(raw);
        let line = std::str::from_utf8(raw)
            .map_err(|_| syntax(ln, "PLY header line is not text".into()))?;
        let w: Vec<&str> = line.split_ascii_whitespace().collect();
        if ln == 1 {
            if w != ["ply"] {
                return Err(syntax(ln, "missing `ply` magic line".into()));
            }
            continue;
        }
        match w.first().copied() {
            None | Some("comment") | Some("obj_info") => {}
            Some("format") => {
                encoding = Some(match w.get(1).copied() {
                    Some("ascii") => Encoding::Ascii,
                    Some("binary_little_endian") => Encoding::Little,
                    Some("binary_big_endian") => Encoding::Big,
                    other => {
                        return Err(syntax(
                            ln,
                            format!("unknown PLY format `{}`", other.unwrap_or("")),
                        ));
                    }
                });
            }
            Some("element") => {
                let (Some(name), Some(count), None) = (w.get(1), w.get(2), w.get(3)) else {
                    return Err(syntax(ln, "expected `element NAME COUNT`".into()));
                };
                let count = count
                    .parse()
                    .map_err(|_| syntax(ln, format!("invalid element count `{count}`")))?;
                elements.push(Element {
                    name: name.to_string(),
                    count,
                    props: Vec::new(),
                });
            }
            Some("property") => {
                let el = elements
                    .last_mut()
                    .ok_or_else(|| syntax(ln, "`property` before any `element`".into()))?;
                let ty = |s: &str| {
                    Scalar::parse(s).ok_or_else(|| syntax(ln, format!("unknown type `{s}`")))
                };
                let (prop, name) = match w.as_slice() {
                    ["property", "list", c, i, name] => {
                        let c = ty(c)?;
                        if !c.is_int() {
                            return Err(syntax(ln, "list count type must be an integer".into()));
                        }
                        (Prop::List(c, ty(i)?), name)
                    }
                    ["property", t, name] => (Prop::Scalar(ty(t)?), name),
                    _ => return Err(syntax(ln, format!("malformed property `{}`", show(raw)))),
                };
                el.props.push((name.to_string(), prop));
            }
            Some("end_header") => break,
            // Not a keyword that shapes the body, so ignoring it cannot misread the data (Blender
            // 2.47 writes `Created by Blender3D 247 - www.blender.org, source file: …` here).
            Some(_) => warnings.push(LoadWarning {
                location: Location::Line(ln),
                message: format!("unknown PLY header line `{}` ignored", show(raw)),
            }),
        }
    }
    let encoding = encoding.ok_or_else(|| syntax(ln, "PLY header has no `format` line".into()))?;
    Ok(Header {
        encoding,
        elements,
        body: pos,
        lines: ln,
        warnings,
    })
}

/// A stream of scalar values from the body, read one element instance at a time.
trait Source {
    /// Starts element instance `what()`. In ascii this takes the instance's line.
    fn begin(&mut self, what: &dyn Fn() -> String) -> Result<(), Fail>;
    /// The next value of type `t` (integers are exact in `f64`), or a truncation/syntax error
    /// whose message is completed with `what`.
    fn next(&mut self, t: Scalar, what: &dyn Fn() -> String) -> Result<f64, Fail>;
    /// Skips `n` values of type `t`.
    fn skip(&mut self, t: Scalar, n: u64, what: &dyn Fn() -> String) -> Result<(), Fail>;
    /// Ends the instance. In ascii the line must hold nothing more.
    fn end(&mut self, what: &dyn Fn() -> String) -> Result<(), Fail>;
    /// Bytes left (a bound for capacities).
    fn remaining(&self) -> usize;
}

struct Binary<'a> {
    bytes: &'a [u8],
    pos: usize,
    big: bool,
}

impl Binary<'_> {
    fn truncated(&self, what: &dyn Fn() -> String) -> Fail {
        (
            Location::Byte(self.pos as u64),
            LoadErrorKind::Truncated(format!("file ends in {}", what())),
        )
    }
}

impl Source for Binary<'_> {
    fn begin(&mut self, _: &dyn Fn() -> String) -> Result<(), Fail> {
        Ok(())
    }

    fn next(&mut self, t: Scalar, what: &dyn Fn() -> String) -> Result<f64, Fail> {
        let n = t.size();
        let Some(b) = self.bytes.get(self.pos..self.pos + n) else {
            return Err(self.truncated(what));
        };
        let mut a = [0u8; 8];
        a[..n].copy_from_slice(b);
        if self.big {
            a[..n].reverse();
        }
        self.pos += n;
        Ok(match t {
            Scalar::I8 => f64::from(a[0] as i8),
            Scalar::U8 => f64::from(a[0]),
            Scalar::I16 => f64::from(i16::from_le_bytes([a[0], a[1]])),
            Scalar::U16 => f64::from(u16::from_le_bytes([a[0], a[1]])),
            Scalar::I32 => f64::from(i32::from_le_bytes([a[0], a[1], a[2], a[3]])),
            Scalar::U32 => f64::from(u32::from_le_bytes([a[0], a[1], a[2], a[3]])),
            Scalar::F32 => f64::from(f32::from_le_bytes([a[0], a[1], a[2], a[3]])),
            Scalar::F64 => f64::from_le_bytes(a),
        })
    }

    fn skip(&mut self, t: Scalar, n: u64, what: &dyn Fn() -> String) -> Result<(), Fail> {
        let len = n.saturating_mul(t.size() as u64);
        if len > self.remaining() as u64 {
            self.pos = self.bytes.len();
            return Err(self.truncated(what));
        }
        self.pos += len as usize;
        Ok(())
    }

    fn end(&mut self, _: &dyn Fn() -> String) -> Result<(), Fail> {
        Ok(())
    }

    fn remaining(&self) -> usize {
        self.bytes.len() - self.pos
    }
}

/// The ascii body: one element instance per line, values separated by whitespace.
struct Ascii<'a, L: Iterator<Item = (usize, &'a [u8])>> {
    lines: L,
    /// The current instance's line number and the tokens not consumed yet.
    line: usize,
    toks: Vec<&'a [u8]>,
    next_tok: usize,
    /// Bytes of the body not yet reached (a capacity bound).
    remaining: usize,
}

impl<'a, L: Iterator<Item = (usize, &'a [u8])>> Source for Ascii<'a, L> {
    fn begin(&mut self, what: &dyn Fn() -> String) -> Result<(), Fail> {
        for (ln, l) in self.lines.by_ref() {
            self.remaining = self.remaining.saturating_sub(l.len() + 1);
            self.toks.clear();
            self.toks.extend(tokens(l));
            if !self.toks.is_empty() {
                self.line = ln;
                self.next_tok = 0;
                return Ok(());
            }
        }
        Err((
            Location::Line(self.line),
            LoadErrorKind::Truncated(format!("file ends before {}", what())),
        ))
    }

    fn next(&mut self, t: Scalar, what: &dyn Fn() -> String) -> Result<f64, Fail> {
        let Some(&tok) = self.toks.get(self.next_tok) else {
            return Err(syntax(
                self.line,
                format!("line ends too early in {}", what()),
            ));
        };
        self.next_tok += 1;
        let bad = || {
            syntax(
                self.line,
                format!("invalid {} value `{}` in {}", t.name(), show(tok), what()),
            )
        };
        let v: f64 = super::parse_num(tok).ok_or_else(bad)?;
        if let Some((lo, hi)) = t.int_range() {
            if v.fract() != 0.0 || v < lo || v > hi {
                return Err(bad());
            }
        }
        Ok(v)
    }

    fn skip(&mut self, t: Scalar, n: u64, what: &dyn Fn() -> String) -> Result<(), Fail> {
        for _ in 0..n {
            self.next(t, what)?;
        }
        Ok(())
    }

    fn end(&mut self, what: &dyn Fn() -> String) -> Result<(), Fail> {
        let extra = self.toks.len() - self.next_tok;
        if extra > 0 {
            return Err(syntax(
                self.line,
                format!(
                    "{extra} value(s) after the end of {} (first `{}`)",
                    what(),
                    show(self.toks[self.next_tok])
                ),
            ));
        }
        Ok(())
    }

    fn remaining(&self) -> usize {
        self.remaining
    }
}

/// What to read from a PLY file.
pub(crate) struct Request<'r> {
    /// Scalar properties of the `vertex` element to return, in this order; a name with `true`
    /// is required, one with `false` is returned as `None` when absent.
    pub vertex: &'r [(&'r str, bool)],
    /// Whether to read the `face` element's vertex index lists.
    pub faces: bool,
}

/// What [`read`] returns.
#[derive(Debug, Default)]
pub(crate) struct PlyData {
    /// One column per requested vertex property (`None`: optional and absent).
    pub columns: Vec<Option<Vec<f64>>>,
    /// Fan-triangulated faces (empty unless requested).
    pub triangles: Vec<[u32; 3]>,
    /// Faces with more than three corners.
    pub polygons: usize,
    /// Header lines that were ignored.
    pub warnings: Vec<LoadWarning>,
}

/// Reads a PLY mesh: vertex positions and triangles.
pub(crate) fn parse(bytes: &[u8]) -> Result<RawMesh, Fail> {
    let data = read(
        bytes,
        &Request {
            vertex: &[("x", true), ("y", true), ("z", true)],
            faces: true,
        },
    )?;
    let column = |k: usize| data.columns[k].as_deref().unwrap_or(&[]);
    let (x, y, z) = (column(0), column(1), column(2));
    Ok(RawMesh {
        positions: (0..x.len()).map(|i| [x[i], y[i], z[i]]).collect(),
        triangles: data.triangles,
        polygons: data.polygons,
        warnings: data.warnings,
    })
}

/// Reads the requested vertex properties and (optionally) the faces of a PLY file.
pub(crate) fn read(bytes: &[u8], request: &Request) -> Result<PlyData, Fail> {
    let h = parse_header(bytes)?;
    let vertex = h.elements.iter().find(|e| e.name == "vertex");
    let nv = vertex.map_or(0, |e| e.count);
    // For each requested property, its position among the vertex element's properties.
    let mut wanted: Vec<Option<usize>> = Vec::with_capacity(request.vertex.len());
    for &(name, required) in request.vertex {
        let found = vertex.and_then(|v| {
            v.props
                .iter()
                .position(|(n, p)| n == name && matches!(p, Prop::Scalar(_)))
        });
        if found.is_none() && required && vertex.is_some() {
            return Err((
                Location::File,
                LoadErrorKind::Syntax(format!(
                    "PLY `vertex` element has no scalar property `{name}`"
                )),
            ));
        }
        wanted.push(if vertex.is_some() { found } else { None });
    }
    if nv > u64::from(u32::MAX) {
        return Err((
            Location::File,
            LoadErrorKind::Syntax(format!("{nv} vertices do not fit 32-bit indices")),
        ));
    }
    let mut face_list = None;
    if let Some(f) = h
        .elements
        .iter()
        .find(|e| e.name == "face")
        .filter(|_| request.faces)
    {
        face_list = f.props.iter().position(|(n, p)| {
            (n == "vertex_indices" || n == "vertex_index") && matches!(p, Prop::List(..))
        });
        if face_list.is_none() {
            return Err((
                Location::File,
                LoadErrorKind::Syntax(
                    "PLY `face` element has no list property `vertex_indices`".into(),
                ),
            ));
        }
    }
    let body = &bytes[h.body..];
    let plan = Plan {
        nv,
        wanted: &wanted,
        face_list,
    };
    let mut data = match h.encoding {
        Encoding::Ascii => {
            let mut src = Ascii {
                lines: text_lines(body).map(|(n, l)| (n + h.lines, l)),
                line: h.lines,
                toks: Vec::new(),
                next_tok: 0,
                remaining: body.len(),
            };
            read_body(&h, &mut src, &plan, 2)
        }
        e => {
            let mut src = Binary {
                bytes: body,
                pos: 0,
                big: e == Encoding::Big,
            };
            read_body(&h, &mut src, &plan, 0).map_err(|(loc, kind)| match loc {
                Location::Byte(b) => (Location::Byte(b + h.body as u64), kind),
                l => (l, kind),
            })
        }
    }?;
    data.warnings = h.warnings;
    Ok(data)
}

/// Which values of the body are kept.
struct Plan<'p> {
    nv: u64,
    wanted: &'p [Option<usize>],
    face_list: Option<usize>,
}

/// Reads all elements. `ascii_min` is the minimum bytes per value in ascii (0 for binary, where
/// the type sizes are used).
fn read_body(
    h: &Header,
    src: &mut dyn Source,
    plan: &Plan,
    ascii_min: usize,
) -> Result<PlyData, Fail> {
    let mut out = PlyData {
        columns: plan.wanted.iter().map(|w| w.map(|_| Vec::new())).collect(),
        ..PlyData::default()
    };
    let mut poly: Vec<u32> = Vec::new();
    let mut seen_vertex = false;
    let mut seen_face = false;
    for el in &h.elements {
        let min_bytes: usize = el
            .props
            .iter()
            .map(|(_, p)| match (ascii_min, p) {
                (0, Prop::Scalar(t)) | (0, Prop::List(t, _)) => t.size(),
                (m, _) => m,
            })
            .sum();
        let cap = capped_capacity(el.count, src.remaining(), min_bytes);
        let is_vertex = el.name == "vertex" && !seen_vertex;
        let is_face = el.name == "face" && !seen_face && plan.face_list.is_some();
        if is_vertex {
            seen_vertex = true;
            for c in out.columns.iter_mut().flatten() {
                c.reserve(cap);
            }
        }
        if is_face {
            seen_face = true;
            out.triangles.reserve(cap);
        }
        if el.props.is_empty() {
            // No values, so no bytes and (in ascii) no lines: nothing to read, however large
            // the count.
            continue;
        }
        for i in 0..el.count {
            let what = || format!("element `{}` {i} of {}", el.name, el.count);
            src.begin(&what)?;
            for (k, (_, prop)) in el.props.iter().enumerate() {
                match *prop {
                    Prop::Scalar(t) => {
                        let v = src.next(t, &what)?;
                        if is_vertex {
                            for (col, w) in out.columns.iter_mut().zip(plan.wanted) {
                                if let (Some(col), Some(j)) = (col, w) {
                                    if *j == k {
                                        col.push(v);
                                    }
                                }
                            }
                        }
                    }
                    Prop::List(ct, it) => {
                        let n = src.next(ct, &what)?;
                        if n < 0.0 {
                            return Err((
                                Location::Face(i as usize),
                                LoadErrorKind::Syntax(format!(
                                    "negative list length {n} in {}",
                                    what()
                                )),
                            ));
                        }
                        let n = n as u64;
                        if is_face && plan.face_list == Some(k) {
                            poly.clear();
                            for _ in 0..n {
                                let v = src.next(it, &what)?;
                                if v < 0.0 || !it.is_int() && v.fract() != 0.0 {
                                    return Err((
                                        Location::Face(i as usize),
                                        LoadErrorKind::Syntax(format!("invalid vertex index {v}")),
                                    ));
                                }
                                if v >= plan.nv as f64 {
                                    return Err(index_error(
                                        i as usize,
                                        v as u64,
                                        plan.nv as usize,
                                    ));
                                }
                                poly.push(v as u32);
                            }
                            if fan(&poly, &mut out.triangles) {
                                out.polygons += 1;
                            }
                        } else {
                            src.skip(it, n, &what)?;
                        }
                    }
                }
            }
            src.end(&what)?;
        }
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn ascii_with_camera_and_int_coords() {
        let s = b"ply\nformat ascii 1.0\ncomment x\nelement camera 1\nproperty float a\nproperty list uchar int l\nelement vertex 3\nproperty int x\nproperty int y\nproperty short z\nelement face 1\nproperty list uchar uint vertex_index\nend_header\n1.5 2 7 8\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n";
        let m = parse(s).unwrap();
        assert_eq!(m.positions[1], [1.0, 0.0, 0.0]);
        assert_eq!(m.triangles, vec![[0, 1, 2]]);
    }

    #[test]
    fn binary_truncated_reports_byte() {
        let mut s = b"ply\nformat binary_big_endian 1.0\nelement vertex 2\nproperty double x\nproperty double y\nproperty double z\nend_header\n".to_vec();
        let body = s.len() as u64;
        s.extend_from_slice(&[0u8; 30]);
        let e = parse(&s).unwrap_err();
        assert_eq!(e.0, Location::Byte(body + 24));
        assert!(matches!(e.1, LoadErrorKind::Truncated(_)));
    }
}
