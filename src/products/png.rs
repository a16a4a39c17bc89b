//! Slice images: the winding number on an axis-aligned plane as an RGB PNG, with the diverging
//! colour map of [`super::colormap`], an optional outline of the mesh's cross-section and a
//! colour bar.
//!
//! # Geometry
//! A [`Slice`] is the plane `x[axis] = coord` restricted to a rectangle of the two other axes
//! `(u, v)`: for `axis` = x, y, z the image axes `(u, v)` are `(y, z)`, `(x, z)`, `(x, y)`.
//! `u` runs left to right, `v` bottom to top. The longer side of the rectangle has `res` pixels,
//! the other side proportionally many; each pixel shows `w` at its **centre**, so the slice is a
//! [`GridSpec`] with one cell along `axis` (bounds `[coord, coord]`) whose samples are the pixel
//! centres, and it is evaluated with ray reuse ([`crate::grid::evaluate`]) when the evaluator's
//! ray lies in the plane ([`Slice::ray`] picks such a ray).
//!
//! # Picture
//! Rows `0..height` are the slice (row 0 is the top, largest `v`). Below it a legend strip of
//! [`Slice::legend_height`] rows holds a colour bar over `w ∈ [−1, 2]`, tick marks at −1, 0, 0.5,
//! 1, 2 (the ones at 0, 0.5 and 1 longer) and their labels.

use std::io::{self, Write};
use std::path::Path;

use crate::base::bounding_box::BoundingBox;
use crate::eval::Evaluator;
use crate::grid::GridSpec;
use crate::kernel::frame::RayAxis;
use crate::mesh::Mesh;

use super::colormap;

/// Outline colour (near black).
pub const OUTLINE_COLOR: [u8; 3] = [20, 20, 20];
/// Legend background (white).
pub const LEGEND_BACKGROUND: [u8; 3] = [255, 255, 255];

/// An axis-aligned slice rectangle and its pixel raster.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Slice {
    /// Normal axis (0 = x, 1 = y, 2 = z).
    pub axis: usize,
    /// Coordinate of the plane along `axis`.
    pub coord: f64,
    /// `[min, max]` along the image's horizontal axis `u`.
    pub u_range: [f64; 2],
    /// `[min, max]` along the image's vertical axis `v`.
    pub v_range: [f64; 2],
    /// Image width in pixels (slice part).
    pub width: usize,
    /// Image height in pixels (slice part, without the legend).
    pub height: usize,
}

/// The in-plane axes `(u, v)` of a slice with normal `axis`.
pub fn plane_axes(axis: usize) -> (usize, usize) {
    match axis {
        0 => (1, 2),
        1 => (0, 2),
        _ => (0, 1),
    }
}

impl Slice {
    /// The slice of `region` (only its in-plane extents matter) at `x[axis] = coord` whose longer
    /// side has `res` pixels.
    pub fn new(region: &BoundingBox, axis: usize, coord: f64, res: usize) -> Slice {
        let (u, v) = plane_axes(axis);
        let eu = region.max[u] - region.min[u];
        let ev = region.max[v] - region.min[v];
        let longest = eu.max(ev);
        let px = |e: f64| {
            if longest > 0.0 {
                ((e / longest * res as f64).round() as usize).max(1)
            } else {
                res.max(1)
            }
        };
        Slice {
            axis,
            coord,
            u_range: [region.min[u], region.max[u]],
            v_range: [region.min[v], region.max[v]],
            width: px(eu),
            height: px(ev),
        }
    }

    /// The grid whose samples are the pixel centres (one cell along `axis`). Grid index
    /// `(i along u, j along v)` is pixel `(i, height − 1 − j)`.
    pub fn grid(&self) -> GridSpec {
        let (u, v) = plane_axes(self.axis);
        let mut min = [0.0; 3];
        let mut max = [0.0; 3];
        let mut dims = [1; 3];
        min[self.axis] = self.coord;
        max[self.axis] = self.coord;
        (min[u], max[u], dims[u]) = (self.u_range[0], self.u_range[1], self.width);
        (min[v], max[v], dims[v]) = (self.v_range[0], self.v_range[1], self.height);
        GridSpec {
            bounds: BoundingBox { min, max },
            dims,
        }
    }

    /// A ray direction in the slice plane (`+z` for x- and y-slices, `+y` for z-slices), so that
    /// an evaluator built with it reuses one ray per image column or row.
    pub fn ray(&self) -> RayAxis {
        if self.axis == 2 {
            RayAxis::PosY
        } else {
            RayAxis::PosZ
        }
    }

    /// The world point at the centre of pixel `(px, py)` (row 0 at the top).
    pub fn pixel_point(&self, px: usize, py: usize) -> [f64; 3] {
        let g = self.grid();
        let (u, v) = plane_axes(self.axis);
        let mut idx = [0usize; 3];
        idx[u] = px;
        idx[v] = self.height - 1 - py;
        g.point(idx[0], idx[1], idx[2])
    }

    /// The pixel `(px, py)` containing the world point `p` (its `axis` coordinate is ignored), or
    /// `None` outside the rectangle.
    pub fn pixel_of(&self, p: [f64; 3]) -> Option<(usize, usize)> {
        let (u, v) = plane_axes(self.axis);
        let fu = (p[u] - self.u_range[0]) / (self.u_range[1] - self.u_range[0]) * self.width as f64;
        let fv =
            (p[v] - self.v_range[0]) / (self.v_range[1] - self.v_range[0]) * self.height as f64;
        if !(fu >= 0.0 && fu < self.width as f64 && fv >= 0.0 && fv < self.height as f64) {
            return None;
        }
        Some((fu as usize, self.height - 1 - fv as usize))
    }

    /// Rows of the legend strip below the slice.
    pub fn legend_height(&self) -> usize {
        (self.width / 12).clamp(36, 120)
    }

    /// Winding numbers at the pixel centres, row-major from the top row (`width·height`).
    pub fn evaluate<E: Evaluator + ?Sized>(&self, evaluator: &E) -> Vec<f64> {
        self.evaluate_with_progress(evaluator, |_| {})
    }

    /// [`Slice::evaluate`] with a progress callback (see
    /// [`crate::grid::evaluate_with_progress`]).
    pub fn evaluate_with_progress<E: Evaluator + ?Sized>(
        &self,
        evaluator: &E,
        progress: impl Fn(usize) + Sync,
    ) -> Vec<f64> {
        let g = self.grid();
        let values = crate::grid::evaluate_with_progress(evaluator, &g, progress);
        let (u, v) = plane_axes(self.axis);
        let mut out = vec![0.0; self.width * self.height];
        for py in 0..self.height {
            for px in 0..self.width {
                let mut idx = [0usize; 3];
                idx[u] = px;
                idx[v] = self.height - 1 - py;
                out[py * self.width + px] = values[g.index(idx[0], idx[1], idx[2])];
            }
        }
        out
    }

    /// The cross-section of `mesh` with the plane as segments in pixel coordinates
    /// (continuous: pixel `(px, py)` covers `[px, px+1) × [py, py+1)`). Triangles lying in the
    /// plane contribute their three edges.
    pub fn outline_segments(&self, mesh: &Mesh) -> Vec<[[f64; 2]; 2]> {
        let (u, v) = plane_axes(self.axis);
        let to_px = |p: [f64; 3]| -> [f64; 2] {
            let fu =
                (p[u] - self.u_range[0]) / (self.u_range[1] - self.u_range[0]) * self.width as f64;
            let fv =
                (p[v] - self.v_range[0]) / (self.v_range[1] - self.v_range[0]) * self.height as f64;
            [fu, self.height as f64 - fv]
        };
        let mut segs = Vec::new();
        for f in 0..mesh.triangles().len() {
            let p = mesh.triangle_positions(f);
            let d = p.map(|q| q[self.axis] - self.coord);
            if d.iter().all(|&x| x == 0.0) {
                for e in 0..3 {
                    segs.push([to_px(p[e]), to_px(p[(e + 1) % 3])]);
                }
                continue;
            }
            let mut pts: Vec<[f64; 3]> = Vec::with_capacity(3);
            for e in 0..3 {
                let (a, b) = (e, (e + 1) % 3);
                if d[a] == 0.0 {
                    pts.push(p[a]);
                } else if (d[a] < 0.0) != (d[b] < 0.0) && d[b] != 0.0 {
                    let t = d[a] / (d[a] - d[b]);
                    let mut x: [f64; 3] =
                        std::array::from_fn(|k| p[a][k] + t * (p[b][k] - p[a][k]));
                    x[self.axis] = self.coord;
                    pts.push(x);
                }
            }
            if pts.len() == 2 {
                segs.push([to_px(pts[0]), to_px(pts[1])]);
            }
        }
        segs
    }

    /// The picture: slice colours from `values` (as returned by [`Slice::evaluate`]), the
    /// outline of `outline` if given, then the legend strip.
    pub fn render(&self, values: &[f64], outline: Option<&Mesh>) -> RgbImage {
        let legend = self.legend_height();
        let mut img = RgbImage::new(self.width, self.height + legend, LEGEND_BACKGROUND);
        for py in 0..self.height {
            for px in 0..self.width {
                img.set(px, py, colormap::color(values[py * self.width + px]));
            }
        }
        if let Some(mesh) = outline {
            for [a, b] in self.outline_segments(mesh) {
                img.draw_segment(a, b, OUTLINE_COLOR, self.height);
            }
        }
        draw_legend(&mut img, self.height, legend);
        img
    }
}

/// An 8-bit RGB raster, rows top to bottom.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct RgbImage {
    /// Width in pixels.
    pub width: usize,
    /// Height in pixels.
    pub height: usize,
    /// `3·width·height` bytes, row-major.
    pub data: Vec<u8>,
}

impl RgbImage {
    /// An image filled with `fill`.
    pub fn new(width: usize, height: usize, fill: [u8; 3]) -> Self {
        let mut data = Vec::with_capacity(3 * width * height);
        for _ in 0..width * height {
            data.extend_from_slice(&fill);
        }
        RgbImage {
            width,
            height,
            data,
        }
    }

    /// The colour of pixel `(x, y)`.
    pub fn get(&self, x: usize, y: usize) -> [u8; 3] {
        let i = 3 * (y * self.width + x);
        [self.data[i], self.data[i + 1], self.data[i + 2]]
    }

    /// Sets pixel `(x, y)`; ignored outside the image.
    pub fn set(&mut self, x: usize, y: usize, c: [u8; 3]) {
        if x < self.width && y < self.height {
            let i = 3 * (y * self.width + x);
            self.data[i..i + 3].copy_from_slice(&c);
        }
    }

    fn fill_rect(&mut self, x0: usize, y0: usize, w: usize, h: usize, c: [u8; 3]) {
        for y in y0..y0 + h {
            for x in x0..x0 + w {
                self.set(x, y, c);
            }
        }
    }

    /// Draws a segment between continuous pixel coordinates, stepping at most half a pixel, on
    /// rows `0..max_row` only.
    fn draw_segment(&mut self, a: [f64; 2], b: [f64; 2], c: [u8; 3], max_row: usize) {
        let len = (b[0] - a[0]).abs().max((b[1] - a[1]).abs());
        if !len.is_finite() {
            return;
        }
        let steps = (2.0 * len).ceil().max(1.0) as usize;
        for s in 0..=steps {
            let t = s as f64 / steps as f64;
            let x = a[0] + t * (b[0] - a[0]);
            let y = a[1] + t * (b[1] - a[1]);
            if x >= 0.0 && y >= 0.0 && (y as usize) < max_row {
                self.set(x as usize, y as usize, c);
            }
        }
    }

    /// Encodes as an 8-bit RGB PNG.
    pub fn write_png(&self, w: impl Write) -> io::Result<()> {
        let to_io = |e: png::EncodingError| io::Error::other(e.to_string());
        let (Ok(width), Ok(height)) = (u32::try_from(self.width), u32::try_from(self.height))
        else {
            return Err(io::Error::new(
                io::ErrorKind::InvalidInput,
                "image too large for PNG",
            ));
        };
        let mut enc = png::Encoder::new(w, width, height);
        enc.set_color(png::ColorType::Rgb);
        enc.set_depth(png::BitDepth::Eight);
        let mut writer = enc.write_header().map_err(to_io)?;
        writer.write_image_data(&self.data).map_err(to_io)?;
        writer.finish().map_err(to_io)
    }

    /// [`RgbImage::write_png`] to a new file.
    pub fn save_png(&self, path: impl AsRef<Path>) -> io::Result<()> {
        let mut f = io::BufWriter::new(std::fs::File::create(path)?);
        self.write_png(&mut f)?;
        // Dropping a BufWriter discards its flush error: a full disk would go unnoticed.
        f.flush()
    }
}

/// 3×5 glyphs (rows top to bottom, 3 bits each, high bit left) for the tick labels.
fn glyph(c: char) -> [u8; 5] {
    match c {
        '0' => [0b111, 0b101, 0b101, 0b101, 0b111],
        '1' => [0b010, 0b110, 0b010, 0b010, 0b111],
        '2' => [0b111, 0b001, 0b111, 0b100, 0b111],
        '5' => [0b111, 0b100, 0b111, 0b001, 0b111],
        '.' => [0b000, 0b000, 0b000, 0b000, 0b010],
        '-' => [0b000, 0b000, 0b111, 0b000, 0b000],
        _ => [0; 5],
    }
}

fn draw_text(img: &mut RgbImage, text: &str, cx: usize, y0: usize, scale: usize, c: [u8; 3]) {
    let n = text.chars().count();
    let w = n * 4 * scale - scale;
    let x0 = cx.saturating_sub(w / 2);
    for (k, ch) in text.chars().enumerate() {
        let g = glyph(ch);
        for (row, bits) in g.iter().enumerate() {
            for col in 0..3 {
                if bits >> (2 - col) & 1 == 1 {
                    img.fill_rect(
                        x0 + (k * 4 + col) * scale,
                        y0 + row * scale,
                        scale,
                        scale,
                        c,
                    );
                }
            }
        }
    }
}

/// The colour bar over `w ∈ [−1, 2]` in rows `top..top+h` (see the module documentation).
fn draw_legend(img: &mut RgbImage, top: usize, h: usize) {
    let width = img.width;
    let x0 = width / 12;
    let x1 = width - width / 12;
    if x1 <= x0 + 1 {
        return;
    }
    let bar_top = top + h / 10;
    let bar_h = (h * 3 / 10).max(4);
    let (lo, hi) = colormap::RANGE;
    let x_of = |w: f64| x0 as f64 + (w - lo) / (hi - lo) * (x1 - x0) as f64;
    for x in x0..x1 {
        let w = lo + (x as f64 + 0.5 - x0 as f64) / (x1 - x0) as f64 * (hi - lo);
        img.fill_rect(x, bar_top, 1, bar_h, colormap::color(w));
    }
    let black = [0, 0, 0];
    let scale = (h / 20).max(1);
    let tick_top = bar_top + bar_h;
    for (w, label, long) in [
        (-1.0, "-1", false),
        (0.0, "0", true),
        (0.5, "0.5", true),
        (1.0, "1", true),
        (2.0, "2", false),
    ] {
        let x = (x_of(w).round() as usize).min(x1 - 1);
        let len = if long { h / 8 } else { h / 12 }.max(2);
        img.fill_rect(x, bar_top, 1, bar_h + len, black);
        draw_text(img, label, x, tick_top + len + scale, scale, black);
    }
    draw_text(
        img,
        "w",
        x0 / 2,
        bar_top + bar_h / 2 - 2 * scale,
        scale,
        black,
    );
}
