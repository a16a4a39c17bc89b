//! OBJ reader (own code).
//!
//! We do not use `tobj` (the crate the foundation issue suggested), because for this crate's purpose it
//! changes the mesh (checked against tobj 4.0.5):
//! - it splits the file into one model per `o`/`g`/`usemtl` and re-indexes each model, so a
//!   vertex shared by two groups becomes two vertices (new boundary edges and components), and
//!   unreferenced vertices disappear;
//! - a file mixing `v x y z` and `v x y z r g b` lines fails (`FaceColorOutOfBounds`);
//! - `v x y z w` divides by `w`, and its errors carry no line number.
//!
//! This reader keeps one global vertex list exactly as stored. `v` lines use their first three
//! numbers (a `w` or colour values after them are ignored, but must be numbers). `f` corners
//! may be `i`, `i/t`, `i//n` or `i/t/n`; negative indices are relative to the vertices read so
//! far; indices may refer to vertices defined later in the file (checked at the end). Faces are
//! fan-triangulated; faces with fewer than three corners, `l`, `p` and every other statement are
//! ignored. A trailing `\` continues a line.

use super::{Fail, RawMesh, fan, index_error, parse_num, show, text_lines, tokens};
use crate::error::{LoadErrorKind, Location};

pub(crate) fn parse(bytes: &[u8]) -> Result<RawMesh, Fail> {
    let mut out = RawMesh::default();
    let syntax = |line: usize, msg: String| (Location::Line(line), LoadErrorKind::Syntax(msg));
    let mut poly: Vec<u32> = Vec::new();
    let mut faces = 0usize;
    // Largest index seen and the first face that used it (forward references are checked at
    // the end, when the vertex count is known).
    let mut worst: Option<(u64, usize)> = None;
    let mut joined: Vec<u8> = Vec::new();
    let mut lines = text_lines(bytes);
    while let Some((ln, first)) = lines.next() {
        let mut line = first;
        if line.ends_with(b"\\") {
            joined.clear();
            joined.extend_from_slice(&line[..line.len() - 1]);
            for (_, next) in lines.by_ref() {
                joined.push(b' ');
                match next.strip_suffix(b"\\") {
                    Some(n) => joined.extend_from_slice(n),
                    None => {
                        joined.extend_from_slice(next);
                        break;
                    }
                }
            }
            line = &joined;
        }
        let line = line.split(|&b| b == b'#').next().unwrap_or(&[]);
        let mut toks = tokens(line);
        match toks.next() {
            Some(b"v") => {
                let mut p = [0.0; 3];
                for c in &mut p {
                    let tok = toks
                        .next()
                        .ok_or_else(|| syntax(ln, "`v` needs three coordinates".into()))?;
                    *c = parse_num(tok)
                        .ok_or_else(|| syntax(ln, format!("invalid coordinate `{}`", show(tok))))?;
                }
                // A `w` or colours may follow, but only numbers: `v 1 0 0 abc` is a broken line,
                // not a vertex with a comment.
                if let Some(bad) = toks.find(|t| parse_num::<f64>(t).is_none()) {
                    return Err(syntax(
                        ln,
                        format!("invalid value `{}` after the coordinates", show(bad)),
                    ));
                }
                out.positions.push(p);
            }
            Some(b"f") | Some(b"fo") => {
                let face = faces;
                faces += 1;
                poly.clear();
                let nv = out.positions.len() as i64;
                for tok in toks {
                    let v = tok.split(|&b| b == b'/').next().unwrap_or(&[]);
                    let i: i64 = parse_num(v).ok_or_else(|| {
                        syntax(ln, format!("invalid face corner `{}`", show(tok)))
                    })?;
                    let abs = match i {
                        0 => return Err(syntax(ln, "vertex index 0 (OBJ counts from 1)".into())),
                        i if i > 0 => i - 1,
                        i => {
                            let a = nv + i;
                            if a < 0 {
                                return Err((
                                    Location::Face(face),
                                    LoadErrorKind::Syntax(format!(
                                        "relative vertex index {i} reaches before the first \
                                         vertex ({nv} vertices read so far, line {ln})"
                                    )),
                                ));
                            }
                            a
                        }
                    } as u64;
                    if worst.is_none_or(|(w, _)| abs > w) {
                        worst = Some((abs, face));
                    }
                    if abs > u64::from(u32::MAX) {
                        return Err(index_error(face, abs, out.positions.len()));
                    }
                    poly.push(abs as u32);
                }
                if fan(&poly, &mut out.triangles) {
                    out.polygons += 1;
                }
            }
            _ => {}
        }
    }
    if let Some((w, face)) = worst {
        if w >= out.positions.len() as u64 {
            return Err(index_error(face, w, out.positions.len()));
        }
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn negative_and_slash_indices_colours_and_continuation() {
        let s = b"v 0 0 0 1 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0 0.5 0.5 0.5\nf -4/1 -3/2 -2/3 \\\n -1/4\nl 1 2\np 3\nf 1//1 2//1 3//1\n";
        let m = parse(s).unwrap();
        assert_eq!(m.triangles, vec![[0, 1, 2], [0, 2, 3], [0, 1, 2]]);
        assert_eq!(m.polygons, 1);
        assert_eq!(m.positions.len(), 4);
    }

    #[test]
    fn out_of_range() {
        let e = parse(b"v 0 0 0\nf 1 2 3\nf 1 1 1\n").unwrap_err();
        assert_eq!(e.0, Location::Face(0));
    }
}
