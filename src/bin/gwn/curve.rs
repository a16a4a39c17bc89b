//! `gwn curve`: 2D polygons and GauWN, the Gaussian-smoothed winding number (field pictures,
//! untangling, offsetting).

use crate::common::CliError;
use clap::{Parser, Subcommand};
use gwn::curve2d::apps::{OffsetParams, UntangleParams, offset, untangle};
use gwn::curve2d::io::{SvgLayer, read_polygon, write_svg};
use gwn::curve2d::{BvnMethod, CurveBvh, GauWn, Polygon};
use rayon::prelude::*;
use std::path::{Path, PathBuf};

/// Arguments of `gwn curve`.
#[derive(Parser)]
pub struct Args {
    #[command(subcommand)]
    cmd: CurveCmd,
}

#[derive(Subcommand)]
enum CurveCmd {
    /// Render W_σ of a polygon (text `x y` blocks or SVG paths) as a PNG, with the curve drawn.
    /// Colours: white at 0.5, red above (1 = full red), blue below (0 = full blue).
    Field {
        /// Input polygon (.svg, or text: one loop per block of `x y` lines).
        input: PathBuf,
        /// Kernel standard deviation σ (absolute units; default 1% of the size).
        #[arg(long)]
        sigma: Option<f64>,
        /// Pixels along the longer side.
        #[arg(long, default_value_t = 512)]
        res: usize,
        /// Use the fast (Tsay–Ke, ~1e-3) bivariate normal CDF.
        #[arg(long)]
        fast: bool,
        /// Output PNG.
        #[arg(long)]
        out: PathBuf,
    },
    /// Resolve self-intersections / local flips of a polygon (GauWN energy, σ schedule).
    Untangle {
        /// Input polygon.
        input: PathBuf,
        /// Initial σ relative to the size.
        #[arg(long, default_value_t = 0.01)]
        sigma0: f64,
        /// Test-point distance ε relative to the size.
        #[arg(long, default_value_t = 0.004)]
        eps: f64,
        /// Regularisation weight λ.
        #[arg(long, default_value_t = 1.0)]
        lambda: f64,
        /// Maximum σ steps.
        #[arg(long, default_value_t = 80)]
        max_iters: usize,
        /// Output SVG (input in grey, result in black).
        #[arg(long)]
        out: PathBuf,
    },
    /// Offset a polygon by the GauWN flow (positive distance: outwards).
    Offset {
        /// Input polygon.
        input: PathBuf,
        /// Offset distance (absolute units; negative = inwards).
        #[arg(long, allow_hyphen_values = true)]
        distance: f64,
        /// σ (absolute; default min(|D|/5, 2% of the size)).
        #[arg(long)]
        sigma: Option<f64>,
        /// Output SVG (input in grey, result in black).
        #[arg(long)]
        out: PathBuf,
    },
}

fn load(p: &Path) -> Result<Polygon, CliError> {
    read_polygon(p).map_err(|e| CliError::msg(e.to_string()))
}

fn size_of(poly: &Polygon) -> f64 {
    let b = poly.bbox();
    (b[2] - b[0]).max(b[3] - b[1]).max(f64::MIN_POSITIVE)
}

fn write_layers(out: &Path, input: &Polygon, result: &Polygon) -> Result<(), CliError> {
    write_svg(
        out,
        &[
            SvgLayer {
                polygon: input,
                stroke: "#aaaaaa",
                width: 0.004,
            },
            SvgLayer {
                polygon: result,
                stroke: "black",
                width: 0.003,
            },
        ],
    )
    .map_err(|e| CliError::msg(format!("{}: cannot write: {e}", out.display())))
}

/// Diverging map: blue (≤ 0) – white (0.5) – red (≥ 1), darkening beyond.
fn colour(w: f64) -> [u8; 3] {
    let t = ((w - 0.5) * 2.0).clamp(-2.0, 2.0);
    let lerp = |a: [f64; 3], b: [f64; 3], s: f64| {
        [
            a[0] + (b[0] - a[0]) * s,
            a[1] + (b[1] - a[1]) * s,
            a[2] + (b[2] - a[2]) * s,
        ]
    };
    let white = [247.0, 247.0, 247.0];
    let red = [178.0, 24.0, 43.0];
    let dark_red = [80.0, 0.0, 20.0];
    let blue = [33.0, 102.0, 172.0];
    let dark_blue = [5.0, 30.0, 80.0];
    let c = if t >= 0.0 {
        if t <= 1.0 {
            lerp(white, red, t)
        } else {
            lerp(red, dark_red, t - 1.0)
        }
    } else if t >= -1.0 {
        lerp(white, blue, -t)
    } else {
        lerp(blue, dark_blue, -t - 1.0)
    };
    [c[0] as u8, c[1] as u8, c[2] as u8]
}

fn field(
    input: &Path,
    sigma: Option<f64>,
    res: usize,
    fast: bool,
    out: &Path,
) -> Result<(), CliError> {
    let poly = load(input)?;
    if !(2..=8192).contains(&res) {
        return Err(CliError::msg(format!("--res {res}: expected 2..=8192")));
    }
    let size = size_of(&poly);
    let sigma = sigma.unwrap_or(0.01 * size);
    if !(sigma > 0.0 && sigma.is_finite()) {
        return Err(CliError::msg(format!(
            "--sigma {sigma}: expected a positive number"
        )));
    }
    let g = GauWn::new(sigma).with_bvn(if fast {
        BvnMethod::Fast
    } else {
        BvnMethod::Precise
    });
    let bvh = CurveBvh::new(&poly);
    let b = poly.bbox();
    let margin = 0.05 * size + 3.0 * sigma;
    let (x0, y0) = (b[0] - margin, b[1] - margin);
    let (wx, wy) = (b[2] - b[0] + 2.0 * margin, b[3] - b[1] + 2.0 * margin);
    let px = wx.max(wy) / res as f64;
    let (w, h) = (
        ((wx / px).ceil() as usize).max(1),
        ((wy / px).ceil() as usize).max(1),
    );
    // Row 0 is the top (largest y).
    let mut img: Vec<u8> = (0..h)
        .into_par_iter()
        .flat_map_iter(|r| {
            let y = y0 + (h - 1 - r) as f64 * px + 0.5 * px;
            let bvh = &bvh;
            let g = &g;
            (0..w).flat_map(move |c| colour(bvh.value(g, [x0 + (c as f64 + 0.5) * px, y])))
        })
        .collect();
    // Draw the curve in black.
    let pts = poly.points();
    for (i, j) in poly.edges() {
        let (a, bb) = (pts[i], pts[j]);
        let len = (bb[0] - a[0]).hypot(bb[1] - a[1]);
        let steps = ((len / (0.5 * px)).ceil() as usize).max(1);
        for s in 0..=steps {
            let t = s as f64 / steps as f64;
            let x = a[0] + t * (bb[0] - a[0]);
            let y = a[1] + t * (bb[1] - a[1]);
            let c = ((x - x0) / px).floor();
            let r = (h as f64 - 1.0 - ((y - y0) / px).floor()).round();
            if c >= 0.0 && r >= 0.0 && (c as usize) < w && (r as usize) < h {
                let k = 3 * (r as usize * w + c as usize);
                img[k..k + 3].copy_from_slice(&[0, 0, 0]);
            }
        }
    }
    let file = std::fs::File::create(out)
        .map_err(|e| CliError::msg(format!("{}: cannot create: {e}", out.display())))?;
    let mut buffered = std::io::BufWriter::new(file);
    let mut enc = png::Encoder::new(&mut buffered, w as u32, h as u32);
    enc.set_color(png::ColorType::Rgb);
    enc.set_depth(png::BitDepth::Eight);
    enc.write_header()
        .and_then(|mut wr| wr.write_image_data(&img).and_then(|()| wr.finish()))
        .map_err(|e| CliError::msg(format!("{}: cannot write PNG: {e}", out.display())))?;
    // Dropping a BufWriter discards its flush error: a full disk would go unnoticed.
    std::io::Write::flush(&mut buffered)
        .map_err(|e| CliError::msg(format!("{}: cannot write PNG: {e}", out.display())))?;
    eprintln!("wrote {} ({w}×{h}, σ = {sigma})", out.display());
    Ok(())
}

/// Runs `gwn curve …`.
pub fn run(args: Args) -> Result<(), CliError> {
    match args.cmd {
        CurveCmd::Field {
            input,
            sigma,
            res,
            fast,
            out,
        } => field(&input, sigma, res, fast, &out),
        CurveCmd::Untangle {
            input,
            sigma0,
            eps,
            lambda,
            max_iters,
            out,
        } => {
            let poly = load(&input)?;
            let params = UntangleParams {
                sigma0,
                eps,
                lambda,
                max_outer: max_iters,
                ..UntangleParams::default()
            };
            let before = poly.self_intersections(usize::MAX).len();
            let rep = untangle(&poly, &params);
            let after = rep.polygon.self_intersections(usize::MAX).len();
            write_layers(&out, &poly, &rep.polygon)?;
            eprintln!(
                "{}: {before} → {after} intersecting edge pairs in {} σ steps (final σ {:.3e}, max displacement {:.3e}){}",
                out.display(),
                rep.outer_iterations,
                rep.final_sigma,
                rep.max_displacement,
                if rep.converged {
                    ""
                } else {
                    "; not fully resolved"
                }
            );
            Ok(())
        }
        CurveCmd::Offset {
            input,
            distance,
            sigma,
            out,
        } => {
            let poly = load(&input)?;
            if !distance.is_finite() {
                return Err(CliError::msg("--distance must be finite"));
            }
            let mut params = OffsetParams::new(distance);
            params.sigma = sigma;
            let rep = offset(&poly, &params);
            write_layers(&out, &poly, &rep.polygon)?;
            eprintln!(
                "{}: offset by {distance} in {} steps (σ {:.3e}, mean displacement {:.4e})",
                out.display(),
                rep.steps,
                rep.sigma,
                rep.mean_displacement
            );
            Ok(())
        }
    }
}
