//! STL reader (own code): binary and ascii.
//!
//! Binary or ascii is decided by size, not by the word `solid`: a file of exactly `84 + 50·n`
//! bytes, where `n` is the little-endian count at byte 80, is binary (exporters often begin the
//! binary header with `solid`). Otherwise a file beginning with `solid` whose first KiB holds no
//! NUL byte is ascii; anything else is binary and then must match its header count exactly:
//! fewer bytes is [`LoadErrorKind::Truncated`], more bytes is a [`LoadErrorKind::Syntax`] error
//! (we do not guess which of header and body is wrong; dropping or inventing triangles would
//! silently change winding numbers).
//!
//! Ascii: any number of `solid … endsolid` blocks; facets with more than three vertices are
//! fan-triangulated; a facet with fewer than three is an error; the file must end after a
//! complete `endsolid` (anything else is truncated). Keywords are case-insensitive; the facet
//! normal is ignored (but `facet normal` must carry three numbers). A `vertex` line holds
//! exactly three numbers. Every triangle gets its own three vertices (weld afterwards).

use super::{Fail, RawMesh, capped_capacity, parse_num, show, text_lines, tokens};
use crate::error::{LoadErrorKind, Location};

pub(crate) fn parse(bytes: &[u8]) -> Result<RawMesh, Fail> {
    if bytes.len() >= 84 {
        let n = header_count(bytes);
        if 84 + 50 * n == bytes.len() as u64 {
            return parse_binary(bytes);
        }
    }
    let head = &bytes[..bytes.len().min(1024)];
    if bytes.trim_ascii_start().starts_with(b"solid") && !head.contains(&0) {
        parse_ascii(bytes)
    } else {
        parse_binary(bytes)
    }
}

fn header_count(bytes: &[u8]) -> u64 {
    u64::from(u32::from_le_bytes([
        bytes[80], bytes[81], bytes[82], bytes[83],
    ]))
}

fn parse_binary(bytes: &[u8]) -> Result<RawMesh, Fail> {
    let len = bytes.len() as u64;
    if len < 84 {
        return Err((
            Location::Byte(len),
            LoadErrorKind::Truncated(format!(
                "binary STL needs an 84-byte header, the file has {len} bytes"
            )),
        ));
    }
    let n = header_count(bytes);
    let expected = 84 + 50 * n;
    if len < expected {
        let complete = (len - 84) / 50;
        return Err((
            Location::Byte(84 + 50 * complete),
            LoadErrorKind::Truncated(format!(
                "binary STL header promises {n} triangles ({expected} bytes) but the file has \
                 {len} bytes; triangle {complete} is incomplete"
            )),
        ));
    }
    if len > expected {
        return Err((
            Location::Byte(expected),
            LoadErrorKind::Syntax(format!(
                "binary STL header says {n} triangles ({expected} bytes) but the file has {len} \
                 bytes ({} extra); wrong triangle count or trailing data",
                len - expected
            )),
        ));
    }
    let n = n as usize;
    let mut positions = Vec::with_capacity(3 * n);
    let mut triangles = Vec::with_capacity(n);
    for rec in bytes[84..].chunks_exact(50) {
        for k in 0..3 {
            let at = 12 + 12 * k;
            let c = |j: usize| {
                let o = at + 4 * j;
                f64::from(f32::from_le_bytes([
                    rec[o],
                    rec[o + 1],
                    rec[o + 2],
                    rec[o + 3],
                ]))
            };
            positions.push([c(0), c(1), c(2)]);
        }
        let b = (positions.len() - 3) as u32;
        triangles.push([b, b + 1, b + 2]);
    }
    Ok(RawMesh {
        positions,
        triangles,
        ..RawMesh::default()
    })
}

#[derive(Clone, Copy, PartialEq, Eq, Debug)]
enum State {
    /// Before `solid` or after `endsolid`.
    Outside,
    /// Inside a solid, between facets.
    Solid,
    /// After `facet`, before `outer loop`.
    Facet,
    /// Inside `outer loop`.
    Loop,
    /// After `endloop`, before `endfacet`.
    EndLoop,
}

fn parse_ascii(bytes: &[u8]) -> Result<RawMesh, Fail> {
    let mut out = RawMesh {
        // "vertex 0 0 0\n" is at least 13 bytes.
        positions: Vec::with_capacity(capped_capacity(u64::MAX, bytes.len(), 13 * 4)),
        ..RawMesh::default()
    };
    let mut state = State::Outside;
    let mut corners: Vec<[f64; 3]> = Vec::new();
    let mut last_line = 0;
    let syntax = |line: usize, msg: String| (Location::Line(line), LoadErrorKind::Syntax(msg));
    for (ln, line) in text_lines(bytes) {
        last_line = ln;
        let mut toks = tokens(line);
        let Some(kw) = toks.next() else { continue };
        let kw_l = kw.to_ascii_lowercase();
        let expect = |want: &str| syntax(ln, format!("expected {want}, found `{}`", show(kw)));
        match (state, kw_l.as_slice()) {
            (State::Outside, b"solid") => state = State::Solid,
            (State::Outside, _) => return Err(expect("`solid`")),
            (State::Solid, b"facet") => {
                // The normal is ignored, but `facet normal` must carry exactly three numbers:
                // anything else is not a facet line this reader understands.
                let rest: Vec<&[u8]> = toks.collect();
                let numbers = rest.iter().skip(1).all(|t| parse_num::<f64>(t).is_some());
                let ok = rest.is_empty()
                    || rest[0].eq_ignore_ascii_case(b"normal") && rest.len() == 4 && numbers;
                if !ok {
                    return Err(syntax(
                        ln,
                        "expected `facet normal NX NY NZ` with three numbers".into(),
                    ));
                }
                state = State::Facet;
            }
            (State::Solid, b"endsolid") => state = State::Outside,
            (State::Solid, _) => return Err(expect("`facet` or `endsolid`")),
            (State::Facet, b"outer") => {
                state = State::Loop;
                corners.clear();
            }
            (State::Facet, _) => return Err(expect("`outer loop`")),
            (State::Loop, b"vertex") => {
                let mut p = [0.0; 3];
                for c in &mut p {
                    let tok = toks
                        .next()
                        .ok_or_else(|| syntax(ln, "vertex needs three coordinates".into()))?;
                    *c = parse_num(tok)
                        .ok_or_else(|| syntax(ln, format!("invalid coordinate `{}`", show(tok))))?;
                }
                if let Some(extra) = toks.next() {
                    return Err(syntax(
                        ln,
                        format!("vertex has more than three coordinates (`{}`)", show(extra)),
                    ));
                }
                corners.push(p);
            }
            (State::Loop, b"endloop") => {
                if corners.len() < 3 {
                    return Err(syntax(
                        ln,
                        format!("facet has {} vertices, needs at least 3", corners.len()),
                    ));
                }
                let base = out.positions.len() as u64;
                if base + corners.len() as u64 > u64::from(u32::MAX) {
                    return Err((
                        Location::Line(ln),
                        LoadErrorKind::Syntax("too many vertices for 32-bit indices".into()),
                    ));
                }
                let base = base as u32;
                out.positions.extend_from_slice(&corners);
                for i in 1..corners.len() as u32 - 1 {
                    out.triangles.push([base, base + i, base + i + 1]);
                }
                if corners.len() > 3 {
                    out.polygons += 1;
                }
                state = State::EndLoop;
            }
            (State::Loop, _) => return Err(expect("`vertex` or `endloop`")),
            (State::EndLoop, b"endfacet") => state = State::Solid,
            (State::EndLoop, _) => return Err(expect("`endfacet`")),
        }
    }
    if state != State::Outside {
        return Err((
            Location::Line(last_line),
            LoadErrorKind::Truncated(format!(
                "ascii STL ends inside a {}",
                match state {
                    State::Solid => "solid (no `endsolid`)",
                    _ => "facet",
                }
            )),
        ));
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn ascii_quad_facet_and_two_solids() {
        let s = b"solid a\nfacet normal 0 0 1\nouter loop\nvertex 0 0 0\nvertex 1 0 0\nvertex 1 1 0\nvertex 0 1 0\nendloop\nendfacet\nendsolid a\nSOLID b\nendsolid\n";
        let m = parse(s).unwrap();
        assert_eq!(m.triangles.len(), 2);
        assert_eq!(m.polygons, 1);
    }

    #[test]
    fn ascii_truncated() {
        let s = b"solid a\nfacet normal 0 0 1\nouter loop\nvertex 0 0 0\n";
        let e = parse(s).unwrap_err();
        assert!(matches!(e.1, LoadErrorKind::Truncated(_)));
        assert_eq!(e.0, Location::Line(5));
    }
}
