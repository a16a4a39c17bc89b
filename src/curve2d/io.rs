//! Reading and writing 2D curves.
//!
//! - **Text** (any extension but `.svg`): one loop per block of `x y` lines; blocks are separated
//!   by blank lines; `#` starts a comment (whole line or trailing). Each loop is implicitly closed
//!   (a repeated first vertex at the end is dropped), unless the block starts with the line
//!   `open`: then it is an open polyline from its first to its last vertex. The y axis points up.
//! - **SVG** (`.svg`): read as a viewer draws it, by `usvg`: `<path>`, `<rect>` (with rounded
//!   corners), `<circle>`, `<ellipse>`, `<line>`, `<polygon>`, `<polyline>`, `<use>`, nested
//!   `<svg>`, `transform` attributes on every element and CSS styles are resolved; hidden
//!   elements are skipped. Coordinates are the root's user units (the `viewBox` coordinates of the
//!   outermost `<svg>`), so the y axis points **down**, as in the file. Curves are flattened by
//!   `kurbo` to within [`SVG_FLATTEN_TOLERANCE`] of the path size. A subpath closed by `Z` is a
//!   closed loop; an unclosed subpath is closed if the path is filled (as the fill is drawn) and
//!   an open polyline if it is only stroked. usvg stores coordinates as `f32`, so every vertex is
//!   rounded to `f32` (relative error ≤ 6e-8), which makes a write → read round trip exact.
//! - **SVG output** ([`svg_string`]): each layer as one `<path>`, `M … L … [Z]` per loop (`Z` for
//!   closed loops only), coordinates printed in full (shortest round-trip form) and unchanged; a
//!   drawing read from text (y up) is wrapped in `<g transform="scale(1 -1)">` so it shows
//!   upright. Reading the output back gives the same vertices (tested on a set of drawings).
//! - **Text output** ([`text_string`]): the text format, `open` blocks for open loops.
//!
//! Errors name the file and, where known, the line.
//!
//! Bounded work on hostile files: a drawing file is read up to [`MAX_DRAWING_BYTES`] and a
//! query-point file up to [`MAX_POINTS_BYTES`] (a device such as `/dev/zero` is refused after
//! that many bytes instead of filling memory), and SVG elements nested deeper than
//! [`MAX_SVG_NESTING`] are refused before usvg, whose conversion recurses once per level, sees
//! them (20,000 nested `<g>` overflowed the stack).

use super::open::Curves;
use super::polygon::{MAX_COORD, Point, Polygon, PolygonError, query_in_range};
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

/// Curves as read from a file, with the file's y-axis convention.
#[derive(Clone, Debug, PartialEq)]
pub struct Drawing {
    /// The loops (closed and open).
    pub curves: Curves,
    /// True for SVG input (y axis down, as drawn), false for text (y axis up).
    pub y_down: bool,
}

/// Reads a polygon from a text or SVG file (by extension); open polylines are closed.
pub fn read_polygon(path: &Path) -> Result<Polygon, CurveIoError> {
    Ok(read_drawing(path)?.curves.polygon)
}

/// Largest drawing file (text or SVG) [`read_drawing`] reads: 256 MiB.
pub const MAX_DRAWING_BYTES: u64 = 1 << 28;

/// Largest query-point file [`read_points`] reads: 2 GiB, more than [`MAX_POINTS`] points as
/// `.npy` (16 bytes each) need.
pub const MAX_POINTS_BYTES: u64 = 1 << 31;

/// Deepest element nesting [`parse_svg`] accepts. usvg converts nested elements by recursion
/// (several kB of stack per level); 256 levels fit in a 2 MiB thread stack with room to spare
/// (tested), and drawings nest a few tens of levels at most.
pub const MAX_SVG_NESTING: usize = 256;

/// The bytes of `path`, at most `limit` of them: a longer file (or a device that never ends) is
/// an error, never an unbounded allocation or a blocking read.
fn read_capped(path: &Path, limit: u64, what: &str) -> Result<Vec<u8>, CurveIoError> {
    let name = path.display().to_string();
    let cannot = |e: std::io::Error| err(&name, 0, format!("cannot read: {e}"));
    let longer = || {
        err(
            &name,
            0,
            format!("longer than {} MiB, the limit for {what}", limit >> 20),
        )
    };
    // A regular file is read whole: refuse a long one before allocating. Anything else (a pipe,
    // a device) is opened without blocking and read up to the limit.
    if std::fs::metadata(path).is_ok_and(|m| m.is_file() && m.len() > limit) {
        return Err(longer());
    }
    // Beyond `limit` a stream is an `InvalidData` error of `read_nonblocking`.
    let bytes = crate::base::file::read_nonblocking(path, limit).map_err(|e| {
        if e.kind() == std::io::ErrorKind::InvalidData {
            longer()
        } else {
            cannot(e)
        }
    })?;
    if bytes.len() as u64 > limit {
        return Err(longer());
    }
    Ok(bytes)
}

/// Reads curves from a text or SVG file (by extension).
pub fn read_drawing(path: &Path) -> Result<Drawing, CurveIoError> {
    let name = path.display().to_string();
    let bytes = read_capped(path, MAX_DRAWING_BYTES, "drawings")?;
    let text = String::from_utf8(bytes).map_err(|_| err(&name, 0, "not UTF-8 text"))?;
    let is_svg = path
        .extension()
        .is_some_and(|e| e.eq_ignore_ascii_case("svg"));
    Ok(if is_svg {
        Drawing {
            curves: parse_svg(&text, &name)?,
            y_down: true,
        }
    } else {
        Drawing {
            curves: parse_text_curves(&text, &name)?,
            y_down: false,
        }
    })
}

/// One loop as found in a file: the line of its first vertex, its vertices, whether it is open.
struct RawLoop {
    line: usize,
    points: Vec<Point>,
    open: bool,
}

/// Turns loops into curves, mapping validation errors to the line of the offending loop. A loop
/// whose last vertex repeats its first is closed (the repeat dropped), even if marked open.
fn build(loops: Vec<RawLoop>, name: &str) -> Result<Curves, CurveIoError> {
    if loops.is_empty() {
        return Err(err(name, 0, "no loop found"));
    }
    let lines: Vec<usize> = loops.iter().map(|l| l.line).collect();
    let mut open = Vec::with_capacity(loops.len());
    let pts: Vec<Vec<Point>> = loops
        .into_iter()
        .map(|mut l| {
            if l.points.len() > 1 && l.points.first() == l.points.last() {
                l.points.pop();
                l.open = false;
            }
            open.push(l.open);
            l.points
        })
        .collect();
    let polygon = Polygon::new(pts).map_err(|e| {
        let line = match &e {
            PolygonError::BadCoordinate { loop_index, .. }
            | PolygonError::DegenerateLoop { loop_index, .. } => {
                lines.get(*loop_index).copied().unwrap_or(0)
            }
            PolygonError::Empty => 0,
        };
        err(name, line, e.to_string())
    })?;
    Ok(Curves { polygon, open })
}

/// Parses the text format (open blocks closed); `name` is used in errors.
pub fn parse_text(text: &str, name: &str) -> Result<Polygon, CurveIoError> {
    Ok(parse_text_curves(text, name)?.polygon)
}

/// Parses the text format, keeping open blocks open; `name` is used in errors.
pub fn parse_text_curves(text: &str, name: &str) -> Result<Curves, CurveIoError> {
    let mut loops: Vec<RawLoop> = Vec::new();
    let mut current: Option<RawLoop> = None;
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
        if content.eq_ignore_ascii_case("open") {
            match &current {
                None => {
                    current = Some(RawLoop {
                        line: line_no,
                        points: Vec::new(),
                        open: true,
                    })
                }
                Some(_) => {
                    return Err(err(
                        name,
                        line_no,
                        "`open` must be the first line of a block",
                    ));
                }
            }
            continue;
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
                    "expected two numbers `x y` (or `open` before a block), found {} field(s)",
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
            .get_or_insert_with(|| RawLoop {
                line: line_no,
                points: Vec::new(),
                open: false,
            })
            .points
            .push(p);
    }
    if let Some(l) = current.take() {
        loops.push(l);
    }
    build(loops, name)
}

/// Flattening tolerance for SVG curves, relative to the size of the path's bounding box.
pub const SVG_FLATTEN_TOLERANCE: f64 = 1e-3;

/// An affine map `(x, y) ↦ (a·x + c·y + e, b·x + d·y + f)` (SVG's `matrix(a b c d e f)`), in f64.
#[derive(Clone, Copy, Debug)]
struct Affine([f64; 6]);

impl Affine {
    const IDENTITY: Affine = Affine([1.0, 0.0, 0.0, 1.0, 0.0, 0.0]);

    fn from_usvg(t: usvg::Transform) -> Affine {
        Affine([
            f64::from(t.sx),
            f64::from(t.ky),
            f64::from(t.kx),
            f64::from(t.sy),
            f64::from(t.tx),
            f64::from(t.ty),
        ])
    }

    /// `self ∘ other` (apply `other` first).
    fn then_inner(self, other: Affine) -> Affine {
        let [a, b, c, d, e, f] = self.0;
        let [a2, b2, c2, d2, e2, f2] = other.0;
        Affine([
            a * a2 + c * b2,
            b * a2 + d * b2,
            a * c2 + c * d2,
            b * c2 + d * d2,
            a * e2 + c * f2 + e,
            b * e2 + d * f2 + f,
        ])
    }

    fn apply(self, x: f32, y: f32) -> kurbo::Point {
        let [a, b, c, d, e, f] = self.0;
        let (x, y) = (f64::from(x), f64::from(y));
        kurbo::Point::new(a * x + c * y + e, b * x + d * y + f)
    }
}

/// Whether usvg wrapped the document in a group carrying the `viewBox` → viewport map: it does
/// exactly when the root has a valid `viewBox` that is not `0 0 width height`.
fn has_viewbox_wrapper(doc: &usvg::roxmltree::Document<'_>, tree: &usvg::Tree) -> bool {
    let Some(vb) = doc.root_element().attribute("viewBox") else {
        return false;
    };
    let nums: Vec<f32> = vb
        .split(|c: char| c.is_whitespace() || c == ',')
        .filter(|s| !s.is_empty())
        .filter_map(|s| s.parse::<f64>().ok().map(|v| v as f32))
        .collect();
    let [x, y, w, h] = nums[..] else {
        return false;
    };
    if !(w > 0.0 && h > 0.0) {
        return false;
    }
    let size = tree.size();
    !(x == 0.0 && y == 0.0 && w == size.width() && h == size.height())
}

/// Parses an SVG document as drawn (see the module docs); `name` is used in errors.
pub fn parse_svg(text: &str, name: &str) -> Result<Curves, CurveIoError> {
    let unreadable = |e: usvg::Error| err(name, 0, format!("not a readable SVG: {e}"));
    // Both roxmltree's parser and usvg's conversion recurse once per nesting level: the raw text
    // is scanned first, and the parsed tree (which may nest deeper through entities) is checked
    // again before usvg sees it.
    prescan_nesting(text, name)?;
    let doc = usvg::roxmltree::Document::parse_with_options(
        text,
        usvg::roxmltree::ParsingOptions {
            allow_dtd: true,
            ..Default::default()
        },
    )
    .map_err(|e| unreadable(usvg::Error::ParsingFailed(e)))?;
    check_nesting(&doc, name)?;
    // `<image>` elements are never drawn into curves, and usvg's default resolver would open
    // whatever path an untrusted document names (a FIFO blocks, `/dev/zero` never ends): no
    // image is resolved at all.
    let options = usvg::Options {
        image_href_resolver: usvg::ImageHrefResolver {
            resolve_data: Box::new(|_, _, _| None),
            resolve_string: Box::new(|_, _| None),
        },
        ..usvg::Options::default()
    };
    let tree = usvg::Tree::from_xmltree(&doc, &options).map_err(unreadable)?;
    let mut loops: Vec<RawLoop> = Vec::new();
    let root = tree.root();
    if has_viewbox_wrapper(&doc, &tree) {
        // Skip the viewBox → viewport map: coordinates stay in the root's user units.
        for child in root.children() {
            match child {
                usvg::Node::Group(g) => {
                    for c in g.children() {
                        collect_node(c, Affine::IDENTITY, &mut loops);
                    }
                }
                other => collect_node(other, Affine::IDENTITY, &mut loops),
            }
        }
    } else {
        collect_group(root, Affine::IDENTITY, &mut loops);
    }
    if loops.is_empty() {
        return Err(err(name, 0, "no visible shape or path found"));
    }
    build(loops, name)
}

/// Refuses text whose tags nest deeper than [`MAX_SVG_NESTING`], before any recursive parser
/// sees it. A conservative scan of the raw text: comments, CDATA and processing instructions are
/// skipped; every other `<name …>` opens a level (also inside a DTD's entity values, which
/// only overestimates), `</…>` closes one, `<…/>` none.
fn prescan_nesting(text: &str, name: &str) -> Result<(), CurveIoError> {
    let b = text.as_bytes();
    let skip_past = |from: usize, end: &str| {
        text[from..]
            .find(end)
            .map_or(b.len(), |k| from + k + end.len())
    };
    let (mut i, mut depth) = (0usize, 0usize);
    while let Some(k) = text[i..].find('<') {
        i += k;
        let rest = &text[i..];
        if rest.starts_with("<!--") {
            i = skip_past(i + 4, "-->");
        } else if rest.starts_with("<![CDATA[") {
            i = skip_past(i + 9, "]]>");
        } else if rest.starts_with("<?") {
            i = skip_past(i + 2, "?>");
        } else if rest.starts_with("<!") {
            i += 2; // a declaration: its content is scanned as text
        } else if rest.starts_with("</") {
            depth = depth.saturating_sub(1);
            i = skip_past(i + 2, ">");
        } else {
            // A start tag: up to its `>` outside quoted attribute values.
            let mut j = i + 1;
            let mut quote = None;
            while j < b.len() {
                match (quote, b[j]) {
                    (Some(q), c) if c == q => quote = None,
                    (None, c @ (b'"' | b'\'')) => quote = Some(c),
                    (None, b'>') => break,
                    _ => {}
                }
                j += 1;
            }
            if b.get(j.wrapping_sub(1)) != Some(&b'/') {
                depth += 1;
                if depth > MAX_SVG_NESTING {
                    let line = 1 + b[..i].iter().filter(|&&c| c == b'\n').count();
                    return Err(err(
                        name,
                        line,
                        format!("elements nested more than {MAX_SVG_NESTING} levels deep"),
                    ));
                }
            }
            i = (j + 1).min(b.len());
        }
    }
    Ok(())
}

/// Refuses elements nested deeper than [`MAX_SVG_NESTING`]. Iterative (document order, each
/// node's depth from its parent's, which comes first), so the check itself cannot overflow the
/// stack.
fn check_nesting(doc: &usvg::roxmltree::Document<'_>, name: &str) -> Result<(), CurveIoError> {
    let mut depth: Vec<u32> = Vec::new();
    for node in doc.descendants() {
        let id = node.id().get_usize();
        let parent = node.parent().map_or(0, |p| depth[p.id().get_usize()]);
        let d = parent + u32::from(node.is_element());
        if d as usize > MAX_SVG_NESTING {
            let line = doc.text_pos_at(node.range().start).row as usize;
            return Err(err(
                name,
                line,
                format!("elements nested more than {MAX_SVG_NESTING} levels deep"),
            ));
        }
        if depth.len() <= id {
            depth.resize(id + 1, 0);
        }
        depth[id] = d;
    }
    Ok(())
}

fn collect_group(g: &usvg::Group, parent: Affine, out: &mut Vec<RawLoop>) {
    let ts = parent.then_inner(Affine::from_usvg(g.transform()));
    for child in g.children() {
        collect_node(child, ts, out);
    }
}

fn collect_node(node: &usvg::Node, ts: Affine, out: &mut Vec<RawLoop>) {
    match node {
        usvg::Node::Group(g) => collect_group(g, ts, out),
        usvg::Node::Path(p) => collect_path(p, ts, out),
        _ => {}
    }
}

/// Rounds to the nearest `f32`: the precision usvg reads, so written values read back exactly.
fn to_f32_grid(p: kurbo::Point) -> Point {
    [p.x as f32 as f64, p.y as f32 as f64]
}

fn collect_path(path: &usvg::Path, ts: Affine, out: &mut Vec<RawLoop>) {
    use usvg::tiny_skia_path::PathSegment;
    let filled = path.fill().is_some();
    // Subpaths in final coordinates as kurbo paths, with their closed flag.
    let mut subpaths: Vec<(kurbo::BezPath, bool)> = Vec::new();
    let mut cur = kurbo::BezPath::new();
    for seg in path.data().segments() {
        match seg {
            PathSegment::MoveTo(p) => {
                if !cur.elements().is_empty() {
                    subpaths.push((std::mem::take(&mut cur), false));
                }
                cur.move_to(ts.apply(p.x, p.y));
            }
            PathSegment::LineTo(p) => cur.line_to(ts.apply(p.x, p.y)),
            PathSegment::QuadTo(c, p) => cur.quad_to(ts.apply(c.x, c.y), ts.apply(p.x, p.y)),
            PathSegment::CubicTo(c1, c2, p) => cur.curve_to(
                ts.apply(c1.x, c1.y),
                ts.apply(c2.x, c2.y),
                ts.apply(p.x, p.y),
            ),
            PathSegment::Close => {
                if !cur.elements().is_empty() {
                    subpaths.push((std::mem::take(&mut cur), true));
                }
            }
        }
    }
    if !cur.elements().is_empty() {
        subpaths.push((cur, false));
    }
    for (bez, closed) in subpaths {
        let bb = kurbo::Shape::bounding_box(&bez);
        let size = bb.width().max(bb.height());
        let tol = if size > 0.0 {
            size * SVG_FLATTEN_TOLERANCE
        } else {
            1e-9
        };
        let mut pts: Vec<Point> = Vec::new();
        kurbo::flatten(bez.iter(), tol, |el| {
            if let kurbo::PathEl::MoveTo(p) | kurbo::PathEl::LineTo(p) = el {
                let q = to_f32_grid(p);
                if pts.last() != Some(&q) {
                    pts.push(q);
                }
            }
        });
        if pts.len() >= 2 {
            out.push(RawLoop {
                line: 0,
                points: pts,
                open: !closed && !filled,
            });
        }
    }
}

/// One set of curves to draw in [`svg_string`].
pub struct SvgLayer<'a> {
    /// The curves.
    pub curves: &'a Curves,
    /// Stroke colour (any SVG colour).
    pub stroke: &'a str,
    /// Stroke width relative to the drawing size.
    pub width: f64,
}

/// An SVG document drawing the layers (coordinates unchanged; viewBox fitted with a margin). With
/// `y_up` (text input) the drawing is wrapped in a `scale(1 -1)` group so it shows upright.
pub fn svg_string(layers: &[SvgLayer], y_up: bool) -> String {
    let mut b = [f64::INFINITY, f64::INFINITY, -f64::INFINITY, -f64::INFINITY];
    for l in layers {
        let lb = l.curves.polygon.bbox();
        b = [
            b[0].min(lb[0]),
            b[1].min(lb[1]),
            b[2].max(lb[2]),
            b[3].max(lb[3]),
        ];
    }
    if y_up {
        b = [b[0], -b[3], b[2], -b[1]];
    }
    let size = (b[2] - b[0]).max(b[3] - b[1]).max(1e-12);
    let m = 0.05 * size;
    let mut s = format!(
        "<svg xmlns=\"http://www.w3.org/2000/svg\" viewBox=\"{} {} {} {}\" width=\"800\" height=\"{}\">\n",
        b[0] - m,
        b[1] - m,
        b[2] - b[0] + 2.0 * m,
        b[3] - b[1] + 2.0 * m,
        (800.0 * (b[3] - b[1] + 2.0 * m) / (b[2] - b[0] + 2.0 * m))
            .round()
            .max(1.0)
    );
    if y_up {
        s.push_str("<g transform=\"scale(1 -1)\">\n");
    }
    for l in layers {
        let poly = &l.curves.polygon;
        let mut d = String::new();
        for k in 0..poly.num_loops() {
            for (i, p) in poly.loop_points(k).iter().enumerate() {
                d.push_str(if i == 0 { "M" } else { " L" });
                d.push_str(&format!("{} {}", p[0], p[1]));
            }
            d.push_str(if l.curves.open[k] { " " } else { " Z " });
        }
        s.push_str(&format!(
            "  <path d=\"{}\" fill=\"none\" stroke=\"{}\" stroke-width=\"{}\" stroke-linejoin=\"round\"/>\n",
            d.trim_end(),
            l.stroke,
            l.width * size
        ));
    }
    if y_up {
        s.push_str("</g>\n");
    }
    s.push_str("</svg>\n");
    s
}

/// Writes [`svg_string`] to `path`.
pub fn write_svg(path: &Path, layers: &[SvgLayer], y_up: bool) -> std::io::Result<()> {
    std::fs::write(path, svg_string(layers, y_up))
}

/// The text format of `curves` (coordinates in full; `open` blocks for open loops).
pub fn text_string(curves: &Curves) -> String {
    let poly = &curves.polygon;
    let mut s = String::new();
    for k in 0..poly.num_loops() {
        if k > 0 {
            s.push('\n');
        }
        if curves.open[k] {
            s.push_str("open\n");
        }
        for p in poly.loop_points(k) {
            s.push_str(&format!("{} {}\n", p[0], p[1]));
        }
    }
    s
}

/// Most query points read by [`read_points`] (a `.npy` header claiming more is refused before
/// allocating).
pub const MAX_POINTS: usize = 100_000_000;

/// Reads 2D query points: `.npy` (`<f8`, C order, shape `(N, 2)`) or text (`x y` or `x,y` per
/// line, `#` comments, blank lines ignored).
pub fn read_points(path: &Path) -> Result<Vec<Point>, CurveIoError> {
    let name = path.display().to_string();
    let bytes = read_capped(path, MAX_POINTS_BYTES, "query-point files")?;
    let pts = if bytes.starts_with(b"\x93NUMPY") {
        parse_points_npy(&bytes, &name)?
    } else {
        let text = std::str::from_utf8(&bytes)
            .map_err(|_| err(&name, 0, "neither a .npy file nor UTF-8 text"))?;
        parse_points_text(text, &name)?
    };
    if pts.is_empty() {
        return Err(err(&name, 0, "contains no points"));
    }
    Ok(pts)
}

/// Parses text query points (see [`read_points`]).
pub fn parse_points_text(text: &str, name: &str) -> Result<Vec<Point>, CurveIoError> {
    let mut out = Vec::new();
    for (i, raw) in text.lines().enumerate() {
        let content = raw.split('#').next().unwrap_or("").trim();
        if content.is_empty() {
            continue;
        }
        let fields: Vec<&str> = content
            .split(|c: char| c.is_whitespace() || c == ',')
            .filter(|s| !s.is_empty())
            .collect();
        if fields.len() != 2 {
            return Err(err(
                name,
                i + 1,
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
                .ok()
                .filter(|&v| query_in_range([v, 0.0]))
                .ok_or_else(|| {
                    err(
                        name,
                        i + 1,
                        format!("`{f}` is not a number of magnitude at most {MAX_COORD:e}"),
                    )
                })?;
        }
        out.push(p);
    }
    Ok(out)
}

fn parse_points_npy(bytes: &[u8], name: &str) -> Result<Vec<Point>, CurveIoError> {
    let bad = |m: &str| err(name, 0, format!("NPY: {m}"));
    let (hlen, start) = match bytes.get(6) {
        Some(1) if bytes.len() >= 10 => {
            (u16::from_le_bytes([bytes[8], bytes[9]]) as usize, 10usize)
        }
        Some(2) | Some(3) if bytes.len() >= 12 => (
            u32::from_le_bytes([bytes[8], bytes[9], bytes[10], bytes[11]]) as usize,
            12usize,
        ),
        _ => return Err(bad("unsupported version or truncated header")),
    };
    let header = bytes
        .get(start..start + hlen)
        .and_then(|h| std::str::from_utf8(h).ok())
        .ok_or_else(|| bad("truncated or non-text header"))?;
    let compact: String = header.chars().filter(|c| !c.is_whitespace()).collect();
    if !compact.contains("'descr':'<f8'") {
        return Err(bad("only little-endian float64 ('<f8') is supported"));
    }
    if !compact.contains("'fortran_order':False") {
        return Err(bad("only C order is supported"));
    }
    let shape = compact
        .split("'shape':(")
        .nth(1)
        .and_then(|r| r.split(')').next())
        .ok_or_else(|| bad("header has no shape"))?;
    let dims: Vec<usize> = shape
        .split(',')
        .filter(|s| !s.is_empty())
        .map(|s| s.parse::<usize>().map_err(|_| bad("bad shape")))
        .collect::<Result<_, _>>()?;
    let [n, 2] = dims[..] else {
        return Err(bad(&format!("shape ({shape}) is not (N, 2)")));
    };
    if n > MAX_POINTS {
        return Err(bad(&format!("{n} points exceed the limit of {MAX_POINTS}")));
    }
    let data = &bytes[start + hlen..];
    if data.len() != 16 * n {
        return Err(bad(&format!(
            "{} data bytes for shape ({n}, 2), expected {}",
            data.len(),
            16 * n
        )));
    }
    let vals: Vec<f64> = data
        .chunks_exact(8)
        .map(|c| f64::from_le_bytes([c[0], c[1], c[2], c[3], c[4], c[5], c[6], c[7]]))
        .collect();
    if let Some(k) = vals.iter().position(|&v| !query_in_range([v, 0.0])) {
        return Err(bad(&format!(
            "point {} has a coordinate that is not finite or exceeds {MAX_COORD:e} in magnitude",
            k / 2
        )));
    }
    Ok(vals.chunks_exact(2).map(|c| [c[0], c[1]]).collect())
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
        let svg = "<svg xmlns='http://www.w3.org/2000/svg'>\n<path fill='red' d=\"M0 0 H10 V10 h-10 Z M20 20 L30 20 L25 30 z\"/>\n\
                   <path id=\"c\"\n d=\"M0 0 C 10 0 10 10 0 10 Z\"/></svg>";
        let p = parse_svg(svg, "x.svg").unwrap();
        assert_eq!(p.polygon.num_loops(), 3);
        assert_eq!(p.polygon.loop_points(0).len(), 4);
        assert!(p.polygon.loop_points(2).len() > 4);
        for y_up in [false, true] {
            let out = svg_string(
                &[SvgLayer {
                    curves: &p,
                    stroke: "black",
                    width: 0.01,
                }],
                y_up,
            );
            let q = parse_svg(&out, "y.svg").unwrap();
            let expect: Vec<Point> = p
                .polygon
                .points()
                .iter()
                .map(|v| if y_up { [v[0], -v[1]] } else { *v })
                .collect();
            assert_eq!(q.polygon.points(), &expect[..]);
            assert_eq!(q.open, p.open);
        }
        let e = parse_svg("<svg>\n\n<path d=\"M 0 0 L\"/></svg>", "bad.svg").unwrap_err();
        assert!(e.to_string().starts_with("bad.svg: "), "{e}");
    }
}
