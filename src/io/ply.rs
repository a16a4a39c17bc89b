//! PLY reader (own code): ascii, binary little-endian and binary big-endian.
//!
//! We do not use `ply-rs-bw`, although it is a dependency: it builds a hash map per element
//! (slow and memory-hungry for 200k-face meshes), its errors carry no byte offset or line, and
//! making it panic-free on untrusted input would need a full header validation of our own
//! anyway — which is most of a reader. This one validates the header completely, then streams
//! the body without allocating from untrusted counts.
//!
//! Accepted: any elements in any order (e.g. `camera` before `vertex`; unknown elements and
//! properties are skipped, lists included); `vertex` needs scalar `x`, `y`, `z` of any numeric
//! type; `face` needs a list `vertex_indices` or `vertex_index` with any integer count and item
//! type. Polygons are fan-triangulated; faces with fewer than 3 corners add no triangle. A body
//! that ends early is [`LoadErrorKind::Truncated`] (byte offset for binary, line for ascii);
//! data after the last element is ignored.

use super::{Fail, RawMesh, capped_capacity, fan, index_error, show};
use crate::error::{LoadErrorKind, Location};

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

    fn is_int(self) -> bool {
        !matches!(self, Scalar::F32 | Scalar::F64)
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
    body: usize,
}

fn syntax(line: usize, msg: String) -> Fail {
    (Location::Line(line), LoadErrorKind::Syntax(msg))
}

fn parse_header(bytes: &[u8]) -> Result<Header, Fail> {
    let mut pos = 0;
    let mut ln = 0;
    let mut encoding = None;
    let mut elements: Vec<Element> = Vec::new();
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
            Some(other) => {
                return Err(syntax(
                    ln,
                    format!("unknown header keyword `{}`", show(other.as_bytes())),
                ));
            }
        }
    }
    let encoding = encoding.ok_or_else(|| syntax(ln, "PLY header has no `format` line".into()))?;
    Ok(Header {
        encoding,
        elements,
        body: pos,
    })
}

/// A stream of scalar values from the body.
trait Source {
    /// The next value of type `t` (integers are exact in `f64`), or a truncation/syntax error
    /// whose message is completed with `what`.
    fn next(&mut self, t: Scalar, what: &dyn Fn() -> String) -> Result<f64, Fail>;
    /// Skips `n` values of type `t`.
    fn skip(&mut self, t: Scalar, n: u64, what: &dyn Fn() -> String) -> Result<(), Fail>;
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

    fn remaining(&self) -> usize {
        self.bytes.len() - self.pos
    }
}

struct Ascii<'a> {
    bytes: &'a [u8],
    pos: usize,
    line: usize,
}

impl Source for Ascii<'_> {
    fn next(&mut self, t: Scalar, what: &dyn Fn() -> String) -> Result<f64, Fail> {
        while let Some(&b) = self.bytes.get(self.pos) {
            if !b.is_ascii_whitespace() {
                break;
            }
            if b == b'\n' {
                self.line += 1;
            }
            self.pos += 1;
        }
        let start = self.pos;
        while self
            .bytes
            .get(self.pos)
            .is_some_and(|b| !b.is_ascii_whitespace())
        {
            self.pos += 1;
        }
        let tok = &self.bytes[start..self.pos];
        if tok.is_empty() {
            return Err((
                Location::Line(self.line),
                LoadErrorKind::Truncated(format!("file ends in {}", what())),
            ));
        }
        let bad = || {
            syntax(
                self.line,
                format!("invalid value `{}` in {}", show(tok), what()),
            )
        };
        let v: f64 = super::parse_num(tok).ok_or_else(bad)?;
        if t.is_int() && v.fract() != 0.0 {
            return Err(bad());
        }
        Ok(v)
    }

    fn skip(&mut self, t: Scalar, n: u64, what: &dyn Fn() -> String) -> Result<(), Fail> {
        for _ in 0..n {
            self.next(t, what)?;
        }
        Ok(())
    }

    fn remaining(&self) -> usize {
        self.bytes.len() - self.pos
    }
}

pub(crate) fn parse(bytes: &[u8]) -> Result<RawMesh, Fail> {
    let h = parse_header(bytes)?;
    let vertex = h.elements.iter().find(|e| e.name == "vertex");
    let nv = vertex.map_or(0, |e| e.count);
    let mut xyz = [usize::MAX; 3];
    if let Some(v) = vertex {
        for (k, axis) in ["x", "y", "z"].iter().enumerate() {
            match v.props.iter().position(|(n, _)| n == axis) {
                Some(i) if matches!(v.props[i].1, Prop::Scalar(_)) => xyz[k] = i,
                _ => {
                    return Err((
                        Location::File,
                        LoadErrorKind::Syntax(format!(
                            "PLY `vertex` element has no scalar property `{axis}`"
                        )),
                    ));
                }
            }
        }
    }
    if nv > u64::from(u32::MAX) {
        return Err((
            Location::File,
            LoadErrorKind::Syntax(format!("{nv} vertices do not fit 32-bit indices")),
        ));
    }
    let mut face_list = None;
    if let Some(f) = h.elements.iter().find(|e| e.name == "face") {
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
    match h.encoding {
        Encoding::Ascii => {
            let header_lines = bytes[..h.body].iter().filter(|&&b| b == b'\n').count();
            let mut src = Ascii {
                bytes: body,
                pos: 0,
                line: header_lines + 1,
            };
            read_body(&h, &mut src, nv, xyz, face_list, 2)
        }
        e => {
            let mut src = Binary {
                bytes: body,
                pos: 0,
                big: e == Encoding::Big,
            };
            read_body(&h, &mut src, nv, xyz, face_list, 0).map_err(|(loc, kind)| match loc {
                Location::Byte(b) => (Location::Byte(b + h.body as u64), kind),
                l => (l, kind),
            })
        }
    }
}

/// Reads all elements. `ascii_min` is the minimum bytes per value in ascii (0 for binary, where
/// the type sizes are used).
fn read_body(
    h: &Header,
    src: &mut dyn Source,
    nv: u64,
    xyz: [usize; 3],
    face_list: Option<usize>,
    ascii_min: usize,
) -> Result<RawMesh, Fail> {
    let mut out = RawMesh::default();
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
        let is_face = el.name == "face" && !seen_face;
        if is_vertex {
            seen_vertex = true;
            out.positions.reserve(cap);
        }
        if is_face {
            seen_face = true;
            out.triangles.reserve(cap);
        }
        for i in 0..el.count {
            let what = || format!("element `{}` {i} of {}", el.name, el.count);
            let mut p = [0.0; 3];
            for (k, (_, prop)) in el.props.iter().enumerate() {
                match *prop {
                    Prop::Scalar(t) => {
                        let v = src.next(t, &what)?;
                        if is_vertex {
                            if let Some(axis) = xyz.iter().position(|&j| j == k) {
                                p[axis] = v;
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
                        if is_face && face_list == Some(k) {
                            poly.clear();
                            for _ in 0..n {
                                let v = src.next(it, &what)?;
                                if v < 0.0 || !it.is_int() && v.fract() != 0.0 {
                                    return Err((
                                        Location::Face(i as usize),
                                        LoadErrorKind::Syntax(format!("invalid vertex index {v}")),
                                    ));
                                }
                                if v >= nv as f64 {
                                    return Err(index_error(i as usize, v as u64, nv as usize));
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
            if is_vertex {
                out.positions.push(p);
            }
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
