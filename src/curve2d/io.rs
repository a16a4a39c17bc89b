//! Reading and writing 2D polygons.
//!
//! - **Text** (any extension but `.svg`): one loop per block of `x y` lines; blocks are separated
//!   by blank lines; `#` starts a comment (whole line or trailing). Each loop is implicitly closed
//!   (a repeated first vertex at the end is dropped).
//! - **SVG** (`.svg`): the `d` attribute of every `<path>` element (found by a simple scan; no
//!   `transform`s are applied), parsed and flattened by `kurbo` (M/L/H/V/C/S/Q/T/A/Z, absolute and
//!   relative). Every subpath becomes one loop, closed implicitly as SVG fills do.
//! - **SVG output** ([`write_svg`]): each polygon as one `<path>` with `M … L … Z` per loop.
//!
//! Errors name the file and the line.

use super::polygon::{Point, Polygon};
use std::fmt;
use std::path::Path;

/// A file that cannot be read as a polygon.
#[derive(Clone, Debug, PartialEq)]
pub struct CurveIoError {
    /// File name as given.
    pub file: String,
    /// 1-based line (0 if not tied to a line).
    pub line: usize,
    /// What is wrong.
    pub message: String,
}

impl fmt::Display for CurveIoError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        if self.line > 0 {
            write!(f, "{}:{}: {}", self.file, self.line, self.message)
        } else {
            write!(f, "{}: {}", self.file, self.message)
        }
    }
}

impl std::error::Error for CurveIoError {}

fn err(file: &str, line: usize, message: impl Into<String>) -> CurveIoError {
    CurveIoError {
        file: file.to_string(),
        line,
        message: message.into(),
    }
}

/// Reads a polygon from a text or SVG file (by extension).
pub fn read_polygon(path: &Path) -> Result<Polygon, CurveIoError> {
    let name = path.display().to_string();
    let text =
        std::fs::read_to_string(path).map_err(|e| err(&name, 0, format!("cannot read: {e}")))?;
    let is_svg = path
        .extension()
        .is_some_and(|e| e.eq_ignore_ascii_case("svg"));
    if is_svg {
        parse_svg(&text, &name)
    } else {
        parse_text(&text, &name)
    }
}

/// Turns loops (with the line of their first vertex) into a polygon, mapping validation errors
/// to the line of the offending loop.
fn build(loops: Vec<(usize, Vec<Point>)>, name: &str) -> Result<Polygon, CurveIoError> {
    if loops.is_empty() {
        return Err(err(name, 0, "no loop found"));
    }
    let lines: Vec<usize> = loops.iter().map(|l| l.0).collect();
    let pts: Vec<Vec<Point>> = loops
        .into_iter()
        .map(|(_, mut l)| {
            if l.len() > 1 && l.first() == l.last() {
                l.pop();
            }
            l
        })
        .collect();
    Polygon::new(pts).map_err(|e| {
        let line = match &e {
            super::polygon::PolygonError::BadCoordinate { loop_index, .. }
            | super::polygon::PolygonError::DegenerateLoop { loop_index, .. } => {
                lines.get(*loop_index).copied().unwrap_or(0)
            }
            super::polygon::PolygonError::Empty => 0,
        };
        err(name, line, e.to_string())
    })
}

/// Parses the text format; `name` is used in errors.
pub fn parse_text(text: &str, name: &str) -> Result<Polygon, CurveIoError> {
    let mut loops: Vec<(usize, Vec<Point>)> = Vec::new();
    let mut current: Option<(usize, Vec<Point>)> = None;
    for (i, raw) in text.lines().enumerate() {
        let line_no = i + 1;
        let is_blank = raw.trim().is_empty();
        let content = raw.split('#').next().unwrap_or("").trim();
        if is_blank {
            if let Some(l) = current.take() {
                loops.push(l);
            }
            continue;
        }
        if content.is_empty() {
            continue; // comment line: does not end a block
        }
        let fields: Vec<&str> = content
            .split(|c: char| c.is_whitespace() || c == ',')
            .filter(|s| !s.is_empty())
            .collect();
        if fields.len() != 2 {
            return Err(err(
                name,
                line_no,
                format!(
                    "expected two numbers `x y`, found {} field(s)",
                    fields.len()
                ),
            ));
        }
        let mut p = [0.0; 2];
        for (k, f) in fields.iter().enumerate() {
            p[k] = f
                .parse::<f64>()
                .map_err(|_| err(name, line_no, format!("`{f}` is not a number")))?;
            if !p[k].is_finite() {
                return Err(err(name, line_no, format!("`{f}` is not finite")));
            }
        }
        current
            .get_or_insert_with(|| (line_no, Vec::new()))
            .1
            .push(p);
    }
    if let Some(l) = current.take() {
        loops.push(l);
    }
    build(loops, name)
}

/// Flattening tolerance for SVG curves, relative to the size of the path's bounding box.
pub const SVG_FLATTEN_TOLERANCE: f64 = 1e-3;

/// Parses the `d` attributes of the `<path>` elements of an SVG document.
pub fn parse_svg(text: &str, name: &str) -> Result<Polygon, CurveIoError> {
    let mut loops: Vec<(usize, Vec<Point>)> = Vec::new();
    let mut search = 0;
    while let Some(off) = text[search..].find("<path") {
        let start = search + off;
        let end = text[start..]
            .find('>')
            .map(|e| start + e)
            .ok_or_else(|| err(name, line_of(text, start), "unterminated <path> element"))?;
        let tag = &text[start..end];
        search = end;
        let Some(d) = attribute(tag, "d") else {
            continue;
        };
        let line = line_of(text, start);
        let path = kurbo::BezPath::from_svg(d)
            .map_err(|e| err(name, line, format!("bad path data: {e}")))?;
        let bb = kurbo::Shape::bounding_box(&path);
        let size = bb.width().max(bb.height());
        let tol = if size > 0.0 {
            size * SVG_FLATTEN_TOLERANCE
        } else {
            1e-9
        };
        let mut cur: Vec<Point> = Vec::new();
        let mut parts: Vec<Vec<Point>> = Vec::new();
        kurbo::flatten(path.iter(), tol, |el| match el {
            kurbo::PathEl::MoveTo(p) => {
                if !cur.is_empty() {
                    parts.push(std::mem::take(&mut cur));
                }
                cur.push([p.x, p.y]);
            }
            kurbo::PathEl::LineTo(p) if cur.last() != Some(&[p.x, p.y]) => {
                cur.push([p.x, p.y]);
            }
            kurbo::PathEl::ClosePath if !cur.is_empty() => {
                parts.push(std::mem::take(&mut cur));
            }
            // `flatten` emits only lines; repeated points and empty closes are skipped.
            _ => {}
        });
        if !cur.is_empty() {
            parts.push(cur);
        }
        for p in parts {
            if p.len() >= 2 {
                loops.push((line, p));
            }
        }
    }
    if loops.is_empty() {
        return Err(err(name, 0, "no <path> with a non-empty `d` attribute"));
    }
    build(loops, name)
}

fn line_of(text: &str, byte: usize) -> usize {
    text[..byte].bytes().filter(|&b| b == b'\n').count() + 1
}

/// The value of attribute `key` in a tag's text (`key="…"` or `key='…'`, preceded by whitespace).
fn attribute<'a>(tag: &'a str, key: &str) -> Option<&'a str> {
    let bytes = tag.as_bytes();
    let mut from = 0;
    while let Some(off) = tag[from..].find(key) {
        let at = from + off;
        from = at + key.len();
        if at == 0 || !bytes[at - 1].is_ascii_whitespace() {
            continue;
        }
        let rest = tag[at + key.len()..].trim_start();
        let Some(rest) = rest.strip_prefix('=') else {
            continue;
        };
        let rest = rest.trim_start();
        let quote = rest.chars().next()?;
        if quote != '"' && quote != '\'' {
            continue;
        }
        let body = &rest[1..];
        let close = body.find(quote)?;
        return Some(&body[..close]);
    }
    None
}

/// One polygon to draw in [`write_svg`].
pub struct SvgLayer<'a> {
    /// The curve.
    pub polygon: &'a Polygon,
    /// Stroke colour (any SVG colour).
    pub stroke: &'a str,
    /// Stroke width relative to the drawing size.
    pub width: f64,
}

/// An SVG document drawing the layers (coordinates unchanged; viewBox fitted with a margin).
pub fn svg_string(layers: &[SvgLayer]) -> String {
    let mut b = [f64::INFINITY, f64::INFINITY, -f64::INFINITY, -f64::INFINITY];
    for l in layers {
        let lb = l.polygon.bbox();
        b = [
            b[0].min(lb[0]),
            b[1].min(lb[1]),
            b[2].max(lb[2]),
            b[3].max(lb[3]),
        ];
    }
    let size = (b[2] - b[0]).max(b[3] - b[1]).max(1e-12);
    let m = 0.05 * size;
    let mut s = format!(
        "<svg xmlns=\"http://www.w3.org/2000/svg\" viewBox=\"{} {} {} {}\" width=\"800\" height=\"{}\">\n",
        b[0] - m,
        b[1] - m,
        b[2] - b[0] + 2.0 * m,
        b[3] - b[1] + 2.0 * m,
        (800.0 * (b[3] - b[1] + 2.0 * m) / (b[2] - b[0] + 2.0 * m)).round()
    );
    for l in layers {
        let mut d = String::new();
        for k in 0..l.polygon.num_loops() {
            for (i, p) in l.polygon.loop_points(k).iter().enumerate() {
                d.push_str(if i == 0 { "M" } else { " L" });
                d.push_str(&format!("{} {}", p[0], p[1]));
            }
            d.push_str(" Z ");
        }
        s.push_str(&format!(
            "  <path d=\"{}\" fill=\"none\" stroke=\"{}\" stroke-width=\"{}\" stroke-linejoin=\"round\"/>\n",
            d.trim_end(),
            l.stroke,
            l.width * size
        ));
    }
    s.push_str("</svg>\n");
    s
}

/// Writes [`svg_string`] to `path`.
pub fn write_svg(path: &Path, layers: &[SvgLayer]) -> std::io::Result<()> {
    std::fs::write(path, svg_string(layers))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn text_format() {
        let p = parse_text(
            "# square\n0 0\n1 0\n1 1\n0 1\n0 0\n\n\n2 2 # tri\n3 2\n2 3\n",
            "t",
        )
        .unwrap();
        assert_eq!(p.num_loops(), 2);
        assert_eq!(p.loop_points(0).len(), 4);
        let e = parse_text("0 0\n1 x\n", "f.txt").unwrap_err();
        assert_eq!(e.to_string(), "f.txt:2: `x` is not a number");
        let e = parse_text("0 0\n0 0\n\n1 1\n2 2\n", "f.txt").unwrap_err();
        assert_eq!(e.line, 1);
    }

    #[test]
    fn svg_round_trip() {
        let svg = "<svg>\n<path fill='red' d=\"M0 0 H10 V10 h-10 Z M20 20 L30 20 L25 30 z\"/>\n\
                   <path id=\"c\"\n d=\"M0 0 C 10 0 10 10 0 10 Z\"/></svg>";
        let p = parse_svg(svg, "x.svg").unwrap();
        assert_eq!(p.num_loops(), 3);
        assert_eq!(p.loop_points(0).len(), 4);
        assert!(p.loop_points(2).len() > 4);
        let out = svg_string(&[SvgLayer {
            polygon: &p,
            stroke: "black",
            width: 0.01,
        }]);
        let q = parse_svg(&out, "y.svg").unwrap();
        assert_eq!(q.points(), p.points());
        let e = parse_svg("<svg>\n\n<path d=\"M 0 0 L\"/></svg>", "bad.svg").unwrap_err();
        assert_eq!(e.line, 3);
    }
}
