//! OFF reader (own code, `f64` throughout).
//!
//! Header keyword `OFF` with optional prefixes (`COFF`, `NOFF`, `CNOFF`, `STOFF`, `4OFF`; only the
//! first three coordinates of a vertex are used, colours/normals/texture coordinates after them
//! are ignored). The counts `V F E` may follow the keyword on the same line or come on the next
//! line. `#` starts a comment anywhere; blank lines are skipped. One vertex per line, one face
//! per line (`n i0 … i(n-1)` followed by optional colour values, ignored; values after the
//! coordinates or indices must be numbers). Polygons are
//! fan-triangulated; faces with fewer than 3 corners add no triangle. Binary OFF and `nOFF`
//! are rejected. Content after the last face is ignored.

use super::detect::is_off_keyword;
use super::{
    Fail, RawMesh, capped_capacity, fan, index_error, parse_num, show, text_lines, tokens,
};
use crate::error::{LoadErrorKind, Location};

pub(crate) fn parse(bytes: &[u8]) -> Result<RawMesh, Fail> {
    // Lines with comments removed and blank lines skipped.
    let mut lines = text_lines(bytes)
        .map(|(n, l)| (n, l.split(|&b| b == b'#').next().unwrap_or(&[])))
        .filter(|(_, l)| !l.trim_ascii().is_empty());
    let mut last_line = 0;
    let syntax = |line: usize, msg: String| (Location::Line(line), LoadErrorKind::Syntax(msg));

    let (hl, header) = lines.next().ok_or((Location::File, LoadErrorKind::Empty))?;
    let mut toks = tokens(header);
    let kw = toks.next().unwrap_or(&[]);
    if !is_off_keyword(kw) {
        return Err(syntax(
            hl,
            format!("expected an OFF header keyword, found `{}`", show(kw)),
        ));
    }
    let mut counts: Vec<&[u8]> = toks.collect();
    if counts
        .first()
        .is_some_and(|t| t.eq_ignore_ascii_case(b"BINARY"))
    {
        return Err(syntax(hl, "binary OFF is not supported".into()));
    }
    let mut count_line = hl;
    if counts.is_empty() {
        let (cl, l) = lines.next().ok_or_else(|| {
            (
                Location::Line(hl),
                LoadErrorKind::Truncated("no vertex/face counts after the header".into()),
            )
        })?;
        count_line = cl;
        counts = tokens(l).collect();
    }
    if counts.len() < 2 {
        return Err(syntax(
            count_line,
            "expected vertex and face counts `V F [E]`".into(),
        ));
    }
    let count = |t: &[u8]| {
        parse_num::<u64>(t)
            .ok_or_else(|| syntax(count_line, format!("invalid count `{}`", show(t))))
    };
    let nv = count(counts[0])?;
    let nf = count(counts[1])?;
    last_line = last_line.max(count_line);

    // "0 0 0\n" is the shortest vertex line, "3 0 1 2\n" the shortest face line.
    let mut positions = Vec::with_capacity(capped_capacity(nv, bytes.len(), 6));
    for v in 0..nv {
        let Some((ln, l)) = lines.next() else {
            return Err((
                Location::Line(last_line),
                LoadErrorKind::Truncated(format!("expected {nv} vertices, found {v}")),
            ));
        };
        last_line = ln;
        let mut p = [0.0; 3];
        let mut t = tokens(l);
        for c in &mut p {
            let tok = t
                .next()
                .ok_or_else(|| syntax(ln, "vertex needs three coordinates".into()))?;
            *c = parse_num(tok)
                .ok_or_else(|| syntax(ln, format!("invalid coordinate `{}`", show(tok))))?;
        }
        trailing_numbers(&mut t, ln)?;
        positions.push(p);
    }
    if nv > u64::from(u32::MAX) {
        return Err((
            Location::File,
            LoadErrorKind::Syntax(format!("{nv} vertices do not fit 32-bit indices")),
        ));
    }
    let mut out = RawMesh {
        triangles: Vec::with_capacity(capped_capacity(nf, bytes.len(), 8)),
        ..RawMesh::default()
    };
    let mut poly: Vec<u32> = Vec::new();
    for f in 0..nf as usize {
        let Some((ln, l)) = lines.next() else {
            return Err((
                Location::Line(last_line),
                LoadErrorKind::Truncated(format!("expected {nf} faces, found {f}")),
            ));
        };
        last_line = ln;
        let mut t = tokens(l);
        let first = t.next().unwrap_or(&[]);
        let n: usize = parse_num(first)
            .ok_or_else(|| syntax(ln, format!("invalid corner count `{}`", show(first))))?;
        poly.clear();
        for k in 0..n {
            let tok = t
                .next()
                .ok_or_else(|| syntax(ln, format!("face has {k} of its {n} vertex indices")))?;
            let i: u64 = parse_num(tok)
                .ok_or_else(|| syntax(ln, format!("invalid vertex index `{}`", show(tok))))?;
            if i >= nv {
                return Err(index_error(f, i, nv as usize));
            }
            poly.push(i as u32);
        }
        trailing_numbers(&mut t, ln)?;
        if fan(&poly, &mut out.triangles) {
            out.polygons += 1;
        }
    }
    out.positions = positions;
    Ok(out)
}

/// Colours, normals and texture coordinates may follow a vertex or face, but only as numbers:
/// anything else means the line is not what the counts say it is.
fn trailing_numbers<'a>(
    rest: &mut impl Iterator<Item = &'a [u8]>,
    line: usize,
) -> Result<(), Fail> {
    match rest.find(|t| parse_num::<f64>(t).is_none()) {
        Some(bad) => Err((
            Location::Line(line),
            LoadErrorKind::Syntax(format!("invalid value `{}` after the data", show(bad))),
        )),
        None => Ok(()),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn counts_on_header_line_comments_colours() {
        let s =
            b"# c\nCOFF 4 1 0 # counts\n0 0 0 1 1 1 1\n1 0 0\n1 1 0\n0 1 0\n4 0 1 2 3 255 0 0\n";
        let m = parse(s).unwrap();
        assert_eq!(m.triangles, vec![[0, 1, 2], [0, 2, 3]]);
        assert_eq!(m.polygons, 1);
    }

    #[test]
    fn huge_count_is_truncated_not_oom() {
        let e = parse(b"OFF\n4000000000 4000000000 0\n0 0 0\n").unwrap_err();
        assert!(matches!(e.1, LoadErrorKind::Truncated(_)));
    }
}
