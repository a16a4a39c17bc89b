//! Format detection: by extension first (case-insensitive), by content when the extension is
//! unknown or missing.

use std::path::Path;

use super::Format;

/// The format an extension names (`.obj`, `.stl`, `.off`, `.ply`, `.gltf`, `.glb`, any case).
pub fn format_from_extension(path: &Path) -> Option<Format> {
    let ext = path.extension()?.to_str()?.to_ascii_lowercase();
    match ext.as_str() {
        "obj" => Some(Format::Obj),
        "stl" => Some(Format::Stl),
        "off" => Some(Format::Off),
        "ply" => Some(Format::Ply),
        "gltf" | "glb" => Some(Format::Gltf),
        _ => None,
    }
}

/// True for an OFF header keyword: `OFF` with optional prefixes `C`, `N`, `ST`, `4`
/// (`COFF`, `NOFF`, `CNOFF`, `STOFF`, `STCNOFF`, `4OFF`, …).
pub(crate) fn is_off_keyword(tok: &[u8]) -> bool {
    tok.len() <= 8
        && tok.ends_with(b"OFF")
        && tok[..tok.len() - 3]
            .iter()
            .all(|b| matches!(b, b'C' | b'N' | b'S' | b'T' | b'4'))
}

/// Guesses the format from the bytes, in this order: `glTF` magic (GLB); a JSON object whose first
/// 64 KiB mention `"asset"` (glTF JSON); `ply` magic line; an OFF keyword as the first
/// token after `#` comment lines; a binary STL whose size is exactly `84 + 50·n` for the count `n`
/// in its header; a file starting with `solid` (ascii STL); a line starting with `v ` or `f `
/// within the first 64 KiB (OBJ).
pub fn format_from_content(bytes: &[u8]) -> Option<Format> {
    if bytes.starts_with(b"glTF") {
        return Some(Format::Gltf);
    }
    let head = &bytes[..bytes.len().min(1 << 16)];
    if head.trim_ascii_start().starts_with(b"{") && head.windows(7).any(|w| w == b"\"asset\"") {
        return Some(Format::Gltf);
    }
    if bytes.starts_with(b"ply\n") || bytes.starts_with(b"ply\r\n") {
        return Some(Format::Ply);
    }
    for (_, line) in super::text_lines(head) {
        let t = line.trim_ascii_start();
        if t.is_empty() || t.starts_with(b"#") {
            continue;
        }
        if super::tokens(t).next().is_some_and(is_off_keyword) {
            return Some(Format::Off);
        }
        break;
    }
    if bytes.len() >= 84 {
        let n = u32::from_le_bytes([bytes[80], bytes[81], bytes[82], bytes[83]]) as u64;
        if 84 + 50 * n == bytes.len() as u64 {
            return Some(Format::Stl);
        }
    }
    if bytes.trim_ascii_start().starts_with(b"solid") {
        return Some(Format::Stl);
    }
    for (_, line) in super::text_lines(head) {
        let t = line.trim_ascii_start();
        if t.starts_with(b"v ") || t.starts_with(b"f ") || t.starts_with(b"v\t") {
            return Some(Format::Obj);
        }
    }
    None
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn extensions() {
        assert_eq!(
            format_from_extension(Path::new("a/B.STL")),
            Some(Format::Stl)
        );
        assert_eq!(format_from_extension(Path::new("x.Obj")), Some(Format::Obj));
        assert_eq!(format_from_extension(Path::new("x")), None);
        assert_eq!(
            format_from_extension(Path::new("s.GLB")),
            Some(Format::Gltf)
        );
        assert_eq!(
            format_from_extension(Path::new("s.gltf")),
            Some(Format::Gltf)
        );
        assert_eq!(format_from_extension(Path::new("x.txt")), None);
    }

    #[test]
    fn content() {
        assert_eq!(
            format_from_content(b"ply\nformat ascii 1.0\n"),
            Some(Format::Ply)
        );
        assert_eq!(format_from_content(b"# c\nCOFF 3 1 0\n"), Some(Format::Off));
        assert_eq!(format_from_content(b"OFF\n"), Some(Format::Off));
        assert_eq!(format_from_content(b"  solid x\n"), Some(Format::Stl));
        assert_eq!(format_from_content(b"# hi\nv 1 2 3\n"), Some(Format::Obj));
        let mut bin = vec![0u8; 84 + 50];
        bin[..5].copy_from_slice(b"solid");
        bin[80] = 1;
        assert_eq!(format_from_content(&bin), Some(Format::Stl));
        assert_eq!(format_from_content(b"hello"), None);
        assert_eq!(format_from_content(b"glTF\x02\0\0\0"), Some(Format::Gltf));
        assert_eq!(
            format_from_content(b" {\"asset\": {\"version\": \"2.0\"}}"),
            Some(Format::Gltf)
        );
        assert_eq!(format_from_content(b"{\"a\": 1}"), None);
    }
}
