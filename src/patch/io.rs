//! Text formats for patch sets.
//!
//! - `.bpt` (Bézier patch text, the Utah teapot's format): first line the number of patches; per
//!   patch a line `m n` (degrees) and `(m+1)(n+1)` lines `x y z`, row-major (`m+1` rows of `n+1`).
//! - `.rbpt` (rational Bézier patch text, this crate's): the same layout with `x y z w` on every
//!   control-point line, `w > 0` the weight of the (Euclidean) point `(x, y, z)`.
//!
//! Blank lines and lines starting with `#` are skipped. Errors name the 1-based line.

use std::path::Path;

use super::model::{MAX_DEGREE, Patch, PatchError, PatchSet};

/// Which patch format a file has.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum PatchFormat {
    /// `.bpt`: polynomial, `x y z` per control point.
    Bpt,
    /// `.rbpt`: rational, `x y z w` per control point.
    Rbpt,
}

impl PatchFormat {
    /// The format named by a path's extension (case-insensitive), if it is a patch format.
    pub fn from_path(path: &Path) -> Option<PatchFormat> {
        let ext = path.extension()?.to_str()?.to_ascii_lowercase();
        match ext.as_str() {
            "bpt" => Some(PatchFormat::Bpt),
            "rbpt" => Some(PatchFormat::Rbpt),
            _ => None,
        }
    }
}

/// Whether `path` names a patch file (`.bpt` or `.rbpt`).
pub fn is_patch_path(path: &Path) -> bool {
    PatchFormat::from_path(path).is_some()
}

/// Reads a `.bpt` or `.rbpt` file (by extension). Errors are one line naming the file.
pub fn load_patches(path: &Path) -> Result<PatchSet, PatchError> {
    let format =
        PatchFormat::from_path(path).ok_or_else(|| PatchError::NotPatchFile(path.into()))?;
    // Opened without blocking (a FIFO without a writer reads as empty); a pipe or device is read
    // up to 256 MiB.
    let text =
        crate::base::file::read_text_nonblocking(path, 1 << 28).map_err(|e| PatchError::Io {
            path: path.into(),
            kind: e.kind(),
            message: e.to_string(),
        })?;
    parse_patches(&text, format).map_err(|e| PatchError::InFile {
        path: path.into(),
        error: Box::new(e),
    })
}

/// Parses patch text in the given format.
pub fn parse_patches(text: &str, format: PatchFormat) -> Result<PatchSet, PatchError> {
    let mut lines = text
        .lines()
        .enumerate()
        .map(|(i, l)| (i + 1, l.trim()))
        .filter(|(_, l)| !l.is_empty() && !l.starts_with('#'));
    let mut last_line = 0;
    let mut next = |what: &str| -> Result<(usize, &str), PatchError> {
        match lines.next() {
            Some((n, l)) => {
                last_line = n;
                Ok((n, l))
            }
            None => Err(PatchError::Parse {
                line: last_line + 1,
                message: format!("unexpected end of file, expected {what}"),
            }),
        }
    };
    let (n0, first) = next("the number of patches")?;
    let count: usize = first.parse().map_err(|_| PatchError::Parse {
        line: n0,
        message: format!("expected the number of patches, found {first:?}"),
    })?;
    if count == 0 {
        return Err(PatchError::Empty);
    }
    let per_point = match format {
        PatchFormat::Bpt => 3,
        PatchFormat::Rbpt => 4,
    };
    // The header is not trusted for allocation: patches are pushed as they are read.
    let mut patches = Vec::new();
    for index in 0..count {
        let (nl, header) = next("a patch header `m n`")?;
        let degrees = numbers::<usize>(header, 2, nl, "patch degrees `m n`")?;
        let (m, n) = (degrees[0], degrees[1]);
        if m > MAX_DEGREE || n > MAX_DEGREE {
            return Err(PatchError::DegreeTooHigh {
                patch: index,
                degrees: (m, n),
            });
        }
        let size = (m + 1) * (n + 1);
        let mut points = Vec::with_capacity(size);
        let mut weights = Vec::with_capacity(size);
        for _ in 0..size {
            let what = if per_point == 3 {
                "`x y z`"
            } else {
                "`x y z w`"
            };
            let (pl, row) = next(what)?;
            let v = numbers::<f64>(row, per_point, pl, what)?;
            points.push([v[0], v[1], v[2]]);
            weights.push(if per_point == 4 { v[3] } else { 1.0 });
        }
        patches.push(Patch::checked(index, m, n, points, weights)?);
    }
    if let Some((line, _)) = lines.next() {
        return Err(PatchError::Parse {
            line,
            message: format!("text after the {count} patches the header announced"),
        });
    }
    PatchSet::new(patches)
}

fn numbers<T: std::str::FromStr>(
    line: &str,
    count: usize,
    line_no: usize,
    what: &str,
) -> Result<Vec<T>, PatchError> {
    let fields: Vec<&str> = line.split_whitespace().collect();
    let bad = || PatchError::Parse {
        line: line_no,
        message: format!("expected {what}, found {line:?}"),
    };
    if fields.len() != count {
        return Err(bad());
    }
    fields
        .iter()
        .map(|f| f.parse::<T>().map_err(|_| bad()))
        .collect()
}

/// The `.rbpt` text of a patch set (round-trips through [`parse_patches`] bit for bit: `{:?}`
/// prints the shortest decimal that parses back to the same `f64`).
pub fn to_rbpt(set: &PatchSet) -> String {
    let mut out = format!("{}\n", set.patches().len());
    for p in set.patches() {
        let (m, n) = p.degree();
        out.push_str(&format!("{m} {n}\n"));
        for (q, w) in p.points().iter().zip(p.weights()) {
            out.push_str(&format!("{:?} {:?} {:?} {:?}\n", q[0], q[1], q[2], w));
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn parses_both_formats_and_round_trips() {
        let bpt = "1\n1 1\n0 0 0\n1 0 0\n0 1 0\n1 1 0.5\n";
        let set = parse_patches(bpt, PatchFormat::Bpt).unwrap();
        assert_eq!(set.patches()[0].points()[3], [1.0, 1.0, 0.5]);
        assert!(!set.is_rational());
        let text = "# comment\n1\n0 1\n0 0 0 1\n1 0 0 0.7071067811865476\n";
        let r = parse_patches(text, PatchFormat::Rbpt).unwrap();
        assert!(r.is_rational());
        let again = parse_patches(&to_rbpt(&r), PatchFormat::Rbpt).unwrap();
        assert_eq!(again, r);
    }

    #[test]
    fn errors_name_the_line() {
        let e = parse_patches("2\n1 1\n0 0 0\n1 0 0\n0 1 0\n1 1 0\n", PatchFormat::Bpt);
        assert!(matches!(e, Err(PatchError::Parse { line: 7, .. })), "{e:?}");
        let e = parse_patches("1\n1 1\n0 0 0\n1 0\n", PatchFormat::Bpt);
        assert!(matches!(e, Err(PatchError::Parse { line: 4, .. })), "{e:?}");
        let e = parse_patches(
            "1\n1 1\n0 0 0 1\n1 0 0 1\n0 1 0 -1\n1 1 0 1\n",
            PatchFormat::Rbpt,
        );
        assert!(
            matches!(e, Err(PatchError::BadWeight { point: 2, .. })),
            "{e:?}"
        );
        let e = parse_patches("99999999999\n", PatchFormat::Bpt);
        assert!(matches!(e, Err(PatchError::Parse { line: 2, .. })), "{e:?}");
        let e = parse_patches("1\n1000 1000\n", PatchFormat::Bpt);
        assert!(matches!(e, Err(PatchError::DegreeTooHigh { .. })), "{e:?}");
        let e = parse_patches("1\n0 0\n1 2 3\nextra\n", PatchFormat::Bpt);
        assert!(matches!(e, Err(PatchError::Parse { line: 4, .. })), "{e:?}");
    }

    /// Files name themselves in every error; an unreadable one keeps the system's error kind
    /// (Python raises `FileNotFoundError` for it), a readable invalid one is `InFile`.
    #[test]
    fn file_errors_keep_the_path_and_the_kind() {
        let dir = std::env::temp_dir().join(format!("gwn-patch-io-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let missing = dir.join("missing.bpt");
        let e = load_patches(&missing).unwrap_err();
        assert!(
            matches!(
                &e,
                PatchError::Io {
                    kind: std::io::ErrorKind::NotFound,
                    ..
                }
            ),
            "{e:?}"
        );
        assert!(
            e.to_string().starts_with(&missing.display().to_string()),
            "{e}"
        );
        let bad = dir.join("bad.bpt");
        std::fs::write(&bad, "1\n1 1\n0 0 0\n").unwrap();
        let e = load_patches(&bad).unwrap_err();
        assert!(
            matches!(&e, PatchError::InFile { error, .. } if matches!(**error, PatchError::Parse { .. })),
            "{e:?}"
        );
        assert!(
            e.to_string()
                .starts_with(&format!("{}: line", bad.display())),
            "{e}"
        );
        let e = load_patches(&dir.join("x.obj")).unwrap_err();
        assert_eq!(e, PatchError::NotPatchFile(dir.join("x.obj")));
        assert!(
            e.to_string()
                .ends_with("not a patch file (expected .bpt or .rbpt)")
        );
        std::fs::remove_dir_all(&dir).unwrap();
    }
}
