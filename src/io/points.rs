//! Query points in and results out.
//!
//! Input: text with one point `x y z`, `x,y,z` or `x;y;z` per line (`#` comments and blank lines skipped,
//! one header line before the first point skipped if it does not parse as numbers), or NumPy
//! `.npy` (`float64` or `float32`, either byte order, C or Fortran order, shape `(N, 3)`).
//!
//! Output: CSV (one value or one `x,y,z` row per line, printed with Rust's shortest round-trip
//! formatting, so reading the text back gives the identical `f64`), and `.npy` `float64` of shape
//! `(N,)` or `(N, 3)` (NPY format version 1.0, written here without any extra crate).

use std::io::{self, Write};
use std::path::Path;

use super::{COLUMN_SEPARATORS, parse_num, show, text_lines, tokens_separated_by};
use crate::error::{LoadError, LoadErrorKind, Location};

const NPY_MAGIC: &[u8] = b"\x93NUMPY";

/// Loads query points from a text file or a `.npy` file (detected by the magic bytes).
pub fn load_points(path: impl AsRef<Path>) -> Result<Vec<[f64; 3]>, LoadError> {
    let path = path.as_ref();
    let bytes = super::read_input(path)?;
    load_points_from_bytes(&bytes, path)
}

/// Parses query points from bytes (`.npy` if they start with the NPY magic, text otherwise).
pub fn load_points_from_bytes(
    bytes: &[u8],
    name_for_errors: impl AsRef<Path>,
) -> Result<Vec<[f64; 3]>, LoadError> {
    let name = name_for_errors.as_ref();
    let r = if bytes.starts_with(NPY_MAGIC) {
        parse_npy(bytes)
    } else {
        parse_text(bytes)
    };
    match r {
        Ok(p) if p.is_empty() => Err(LoadError::new(
            name,
            Location::File,
            LoadErrorKind::NoPoints,
        )),
        Ok(p) => Ok(p),
        Err((location, kind)) => Err(LoadError::new(name, location, kind)),
    }
}

fn parse_text(bytes: &[u8]) -> Result<Vec<[f64; 3]>, super::Fail> {
    let mut out = Vec::new();
    let mut header_allowed = true;
    for (ln, line) in text_lines(bytes) {
        let line = line.split(|&b| b == b'#').next().unwrap_or(&[]);
        let toks: Vec<&[u8]> = tokens_separated_by(line, COLUMN_SEPARATORS).collect();
        if toks.is_empty() {
            continue;
        }
        let vals: Option<Vec<f64>> = toks.iter().map(|t| parse_num(t)).collect();
        let first = header_allowed;
        header_allowed = false;
        match vals {
            Some(v) if v.len() == 3 => {
                if let Some(bad) = v.iter().find(|c| !c.is_finite()) {
                    return Err((
                        Location::Line(ln),
                        LoadErrorKind::Syntax(format!("non-finite coordinate {bad}")),
                    ));
                }
                out.push([v[0], v[1], v[2]]);
            }
            None if first => {} // a header line such as `x,y,z`
            Some(v) => {
                return Err((
                    Location::Line(ln),
                    LoadErrorKind::Syntax(format!("expected 3 values, found {}", v.len())),
                ));
            }
            None => {
                let bad = toks.iter().find(|t| parse_num::<f64>(t).is_none());
                return Err((
                    Location::Line(ln),
                    LoadErrorKind::Syntax(format!(
                        "invalid number `{}`",
                        show(bad.copied().unwrap_or(&[]))
                    )),
                ));
            }
        }
    }
    Ok(out)
}

fn npy_err(at: usize, msg: impl Into<String>) -> super::Fail {
    (Location::Byte(at as u64), LoadErrorKind::Syntax(msg.into()))
}

/// The text after `'key':` in an NPY header dictionary.
fn dict_value<'a>(dict: &'a str, key: &str) -> Option<&'a str> {
    let k = dict.find(&format!("'{key}'"))?;
    let rest = &dict[k + key.len() + 2..];
    Some(rest.trim_start().strip_prefix(':')?.trim_start())
}

fn parse_npy(bytes: &[u8]) -> Result<Vec<[f64; 3]>, super::Fail> {
    let trunc = |at: usize, msg: String| (Location::Byte(at as u64), LoadErrorKind::Truncated(msg));
    if bytes.len() < 10 {
        return Err(trunc(bytes.len(), "NPY header incomplete".into()));
    }
    let (hlen, start): (usize, usize) = match bytes[6] {
        1 => (usize::from(u16::from_le_bytes([bytes[8], bytes[9]])), 10),
        2 | 3 => {
            if bytes.len() < 12 {
                return Err(trunc(bytes.len(), "NPY header incomplete".into()));
            }
            let n = u32::from_le_bytes([bytes[8], bytes[9], bytes[10], bytes[11]]);
            (n as usize, 12)
        }
        v => return Err(npy_err(6, format!("unsupported NPY version {v}"))),
    };
    let data = start.saturating_add(hlen);
    if bytes.len() < data {
        return Err(trunc(bytes.len(), "NPY header incomplete".into()));
    }
    let dict = std::str::from_utf8(&bytes[start..data])
        .map_err(|_| npy_err(start, "NPY header is not text"))?;
    let descr = dict_value(dict, "descr")
        .and_then(|v| v.strip_prefix('\''))
        .and_then(|v| v.split('\'').next())
        .ok_or_else(|| npy_err(start, "NPY header has no 'descr'"))?;
    let (big, size) = match descr {
        "<f8" | "=f8" => (false, 8),
        ">f8" => (true, 8),
        "<f4" | "=f4" => (false, 4),
        ">f4" => (true, 4),
        d => {
            return Err(npy_err(
                start,
                format!("NPY dtype `{d}` not supported (need float64 or float32)"),
            ));
        }
    };
    let fortran = match dict_value(dict, "fortran_order") {
        Some(v) if v.starts_with("True") => true,
        Some(v) if v.starts_with("False") => false,
        _ => return Err(npy_err(start, "NPY header has no 'fortran_order'")),
    };
    let shape = dict_value(dict, "shape")
        .and_then(|v| v.strip_prefix('('))
        .and_then(|v| v.split(')').next())
        .ok_or_else(|| npy_err(start, "NPY header has no 'shape'"))?;
    let dims: Option<Vec<u64>> = shape
        .split(',')
        .map(str::trim)
        .filter(|s| !s.is_empty())
        .map(|s| s.parse().ok())
        .collect();
    let n = match dims.as_deref() {
        Some([n, 3]) => *n,
        _ => {
            return Err(npy_err(start, format!("NPY shape ({shape}) is not (N, 3)")));
        }
    };
    let need = n.saturating_mul(3 * size as u64);
    let have = (bytes.len() - data) as u64;
    if have < need {
        return Err(trunc(
            bytes.len(),
            format!("NPY shape ({n}, 3) needs {need} data bytes, the file has {have}"),
        ));
    }
    if have > need {
        // Trailing bytes mean the header does not describe the file (a wrong shape or dtype, or
        // two arrays concatenated): reading the first `need` bytes would silently mix them up.
        return Err(npy_err(
            data + need as usize,
            format!(
                "{} bytes after the {need} data bytes of shape ({n}, 3)",
                have - need
            ),
        ));
    }
    let n = n as usize;
    let body = &bytes[data..];
    let value = |k: usize| -> f64 {
        let b = &body[k * size..(k + 1) * size];
        let mut a = [0u8; 8];
        a[..size].copy_from_slice(b);
        if big {
            a[..size].reverse();
        }
        if size == 8 {
            f64::from_le_bytes(a)
        } else {
            f64::from(f32::from_le_bytes([a[0], a[1], a[2], a[3]]))
        }
    };
    let mut out = Vec::with_capacity(n);
    for i in 0..n {
        let mut p = [0.0; 3];
        for (k, c) in p.iter_mut().enumerate() {
            *c = value(if fortran { k * n + i } else { 3 * i + k });
            if !c.is_finite() {
                let at = if fortran { k * n + i } else { 3 * i + k };
                return Err(npy_err(
                    data + at * size,
                    format!("point {i} has a non-finite coordinate {c}"),
                ));
            }
        }
        out.push(p);
    }
    Ok(out)
}

/// Writes one value per line, round-trippable (`0.1`, `1e-300`, `NaN`, `inf`).
pub fn write_values_csv(mut w: impl Write, values: &[f64]) -> io::Result<()> {
    for v in values {
        writeln!(w, "{v:?}")?;
    }
    w.flush()
}

/// Writes one `x,y,z` row per line, round-trippable.
pub fn write_points_csv(mut w: impl Write, points: &[[f64; 3]]) -> io::Result<()> {
    for p in points {
        writeln!(w, "{:?},{:?},{:?}", p[0], p[1], p[2])?;
    }
    w.flush()
}

fn write_npy(mut w: impl Write, shape: &str, data: impl Iterator<Item = f64>) -> io::Result<()> {
    let dict = format!("{{'descr': '<f8', 'fortran_order': False, 'shape': {shape}, }}");
    // magic (6) + version (2) + length (2) + dict + padding + '\n' is a multiple of 64.
    let unpadded = 10 + dict.len() + 1;
    let pad = (64 - unpadded % 64) % 64;
    let hlen = dict.len() + pad + 1;
    let hlen16 = u16::try_from(hlen)
        .map_err(|_| io::Error::new(io::ErrorKind::InvalidInput, "NPY header too long"))?;
    let mut head = Vec::with_capacity(10 + hlen);
    head.extend_from_slice(NPY_MAGIC);
    head.extend_from_slice(&[1, 0]);
    head.extend_from_slice(&hlen16.to_le_bytes());
    head.extend_from_slice(dict.as_bytes());
    head.resize(head.len() + pad, b' ');
    head.push(b'\n');
    w.write_all(&head)?;
    let mut buf = Vec::with_capacity(8 * 4096);
    for v in data {
        buf.extend_from_slice(&v.to_le_bytes());
        if buf.len() >= 8 * 4096 {
            w.write_all(&buf)?;
            buf.clear();
        }
    }
    w.write_all(&buf)?;
    w.flush()
}

/// Writes values as `.npy` `float64`, shape `(N,)`.
pub fn write_values_npy(w: impl Write, values: &[f64]) -> io::Result<()> {
    write_npy(w, &format!("({},)", values.len()), values.iter().copied())
}

/// Writes points as `.npy` `float64`, shape `(N, 3)`, C order.
pub fn write_points_npy(w: impl Write, points: &[[f64; 3]]) -> io::Result<()> {
    write_npy(
        w,
        &format!("({}, 3)", points.len()),
        points.iter().flat_map(|p| p.iter().copied()),
    )
}

/// Saves values to `path`: `.npy` when the extension is `npy` (any case), CSV otherwise.
pub fn save_values(path: impl AsRef<Path>, values: &[f64]) -> io::Result<()> {
    let path = path.as_ref();
    let f = io::BufWriter::new(std::fs::File::create(path)?);
    if is_npy(path) {
        write_values_npy(f, values)
    } else {
        write_values_csv(f, values)
    }
}

/// Saves points to `path`: `.npy` when the extension is `npy` (any case), CSV otherwise.
pub fn save_points(path: impl AsRef<Path>, points: &[[f64; 3]]) -> io::Result<()> {
    let path = path.as_ref();
    let f = io::BufWriter::new(std::fs::File::create(path)?);
    if is_npy(path) {
        write_points_npy(f, points)
    } else {
        write_points_csv(f, points)
    }
}

fn is_npy(path: &Path) -> bool {
    path.extension()
        .and_then(|e| e.to_str())
        .is_some_and(|e| e.eq_ignore_ascii_case("npy"))
}

/// Parses a values file written by [`write_values_csv`] or [`write_values_npy`] (shape `(N,)`);
/// used to read results back.
pub fn load_values_from_bytes(
    bytes: &[u8],
    name_for_errors: impl AsRef<Path>,
) -> Result<Vec<f64>, LoadError> {
    let name = name_for_errors.as_ref();
    let err = |(location, kind): super::Fail| LoadError::new(name, location, kind);
    if bytes.starts_with(NPY_MAGIC) {
        // Reuse the (N, 3) reader by checking the shape ourselves: simplest is a small parser.
        let (hlen, start) = match bytes.get(6) {
            Some(1) if bytes.len() >= 10 => {
                (usize::from(u16::from_le_bytes([bytes[8], bytes[9]])), 10)
            }
            _ => return Err(err(npy_err(6, "unsupported NPY version"))),
        };
        let data = start + hlen;
        let dict = bytes
            .get(start..data)
            .and_then(|d| std::str::from_utf8(d).ok())
            .ok_or_else(|| err(npy_err(start, "NPY header incomplete")))?;
        if !dict.contains("'<f8'") {
            return Err(err(npy_err(start, "values NPY must be '<f8'")));
        }
        let body = &bytes[data..];
        return Ok(body
            .chunks_exact(8)
            .map(|c| f64::from_le_bytes([c[0], c[1], c[2], c[3], c[4], c[5], c[6], c[7]]))
            .collect());
    }
    let mut out = Vec::new();
    for (ln, line) in text_lines(bytes) {
        let t = line.trim_ascii();
        if t.is_empty() || t.starts_with(b"#") {
            continue;
        }
        out.push(parse_num(t).ok_or_else(|| {
            err((
                Location::Line(ln),
                LoadErrorKind::Syntax(format!("invalid number `{}`", show(t))),
            ))
        })?);
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn text_with_header_and_commas() {
        let p = load_points_from_bytes(b"x,y,z\n# c\n1,2,3\n 4 5 6 \n\n", "p.csv").unwrap();
        assert_eq!(p, vec![[1.0, 2.0, 3.0], [4.0, 5.0, 6.0]]);
        let e = load_points_from_bytes(b"1 2 3\n1 2\n", "p.txt").unwrap_err();
        assert_eq!(e.location, Location::Line(2));
    }

    #[test]
    fn npy_round_trip() {
        let pts = vec![[0.1, -2.5, 1e-300], [3.0, 4.0, 5.0]];
        let mut buf = Vec::new();
        write_points_npy(&mut buf, &pts).unwrap();
        assert_eq!((buf[8] as usize + 10) % 64, 0);
        assert_eq!(load_points_from_bytes(&buf, "p.npy").unwrap(), pts);
        buf.truncate(buf.len() - 1);
        let e = load_points_from_bytes(&buf, "p.npy").unwrap_err();
        assert!(matches!(e.kind, LoadErrorKind::Truncated(_)));
    }
}
