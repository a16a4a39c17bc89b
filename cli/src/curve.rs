//! `gwn curve`: 2D curves and GauWN, the Gaussian-smoothed winding number (values at points,
//! field pictures and grids, untangling, offsetting).

use crate::common::{CliError, outln, progress};
use clap::{Parser, Subcommand};
use gwn::curve2d::apps::{
    OffsetParams, OffsetStop, UntangleParams, UntangleStop, offset, untangle_with_progress,
};
use gwn::curve2d::io::{Drawing, SvgLayer, read_drawing, read_points, svg_string, text_string};
use gwn::curve2d::{BvnMethod, Curves, CurvesField, GauWn, Point, Polygon};
use gwn::products::npy;
use gwn::products::png::Slice;
use rayon::prelude::*;
use std::io::Write;
use std::path::{Path, PathBuf};

/// Arguments of `gwn curve`.
#[derive(Parser)]
pub struct Args {
    #[command(subcommand)]
    cmd: CurveCmd,
}

#[derive(Subcommand)]
enum CurveCmd {
    /// Winding numbers at query points: the generalized winding number without --sigma, W_σ
    /// with it (and its gradient with --gradient). Open polylines are supported.
    Eval {
        /// Input curves (.svg, or text: one loop per block of `x y` lines, `open` blocks).
        input: PathBuf,
        /// Query points: text `x y` per line, or .npy float64 of shape (N, 2).
        #[arg(long)]
        points: PathBuf,
        /// Kernel standard deviation σ (absolute units); without it, the plain (unsmoothed)
        /// generalized winding number.
        #[arg(long, allow_negative_numbers = true)]
        sigma: Option<f64>,
        /// Also output ∇W_σ (needs --sigma): columns w, dw/dx, dw/dy.
        #[arg(long, requires = "sigma")]
        gradient: bool,
        /// Use the fast (Tsay–Ke, ~1e-3) bivariate normal CDF for closed loops.
        #[arg(long)]
        fast: bool,
        /// Output file (.npy or .csv); default: text on stdout, one point per line.
        #[arg(long)]
        out: Option<PathBuf>,
    },
    /// Render W_σ of curves as a PNG (the palette and colour bar of `gwn slice`: blue 0, white
    /// 0.5, red 1) and/or write the grid of values as .npy.
    Field {
        /// Input curves (.svg, or text: one loop per block of `x y` lines, `open` blocks).
        input: PathBuf,
        /// Kernel standard deviation σ (absolute units; default 1% of the size).
        #[arg(long, allow_negative_numbers = true)]
        sigma: Option<f64>,
        /// Pixels along the longer side.
        #[arg(long, default_value_t = 512)]
        res: usize,
        /// Use the fast (Tsay–Ke, ~1e-3) bivariate normal CDF.
        #[arg(long)]
        fast: bool,
        /// Show the plain generalized winding number instead of W_σ.
        #[arg(long, conflicts_with = "sigma")]
        plain: bool,
        /// Output PNG.
        #[arg(long)]
        out: Option<PathBuf>,
        /// Output .npy of shape (rows, columns): element [j, i] is the value at
        /// (origin_x + i·spacing, origin_y + j·spacing), rows in increasing y; origin and
        /// spacing are printed.
        #[arg(long)]
        npy: Option<PathBuf>,
    },
    /// Resolve self-intersections / local flips of closed loops (GauWN energy, σ schedule).
    /// Never returns a curve with more intersecting edge pairs than the input.
    Untangle {
        /// Input polygon (closed loops).
        input: PathBuf,
        /// Initial σ relative to the size.
        #[arg(long, default_value_t = 0.01, allow_negative_numbers = true)]
        sigma0: f64,
        /// Test-point distance ε relative to the size.
        #[arg(long, default_value_t = 0.004, allow_negative_numbers = true)]
        eps: f64,
        /// Regularisation weight λ (>= 0).
        #[arg(long, default_value_t = 1.0, allow_negative_numbers = true)]
        lambda: f64,
        /// σ factor per step, in (0, 1].
        #[arg(long, default_value_t = 0.95, allow_negative_numbers = true)]
        decay: f64,
        /// Maximum σ steps.
        #[arg(long, default_value_t = 80)]
        max_iters: usize,
        /// L-BFGS iterations per σ step.
        #[arg(long, default_value_t = 30)]
        inner_iters: u64,
        /// Stop after this many σ steps without a better iterate.
        #[arg(long, default_value_t = 8)]
        patience: usize,
        /// Exit with status 3 when the result still has intersections or misplaced test points.
        #[arg(long)]
        strict: bool,
        /// Output .svg (input in grey, result in black) or text (the result only).
        #[arg(long)]
        out: PathBuf,
    },
    /// Offset closed loops by the GauWN flow (positive distance: outwards).
    Offset {
        /// Input polygon (closed loops).
        input: PathBuf,
        /// Offset distance (absolute units; negative = inwards).
        #[arg(long, allow_hyphen_values = true)]
        distance: f64,
        /// σ (absolute; default min(|D|/5, 2% of the size)).
        #[arg(long, allow_negative_numbers = true)]
        sigma: Option<f64>,
        /// GauWN change requested per step, in (0, 0.5].
        #[arg(long, default_value_t = 0.1, allow_negative_numbers = true)]
        step: f64,
        /// Weight of the displacement term (units of 1/σ²).
        #[arg(long, default_value_t = 0.1, allow_negative_numbers = true)]
        lambda: f64,
        /// Maximum flow steps.
        #[arg(long, default_value_t = 2000)]
        max_steps: usize,
        /// Exit with status 3 when the mean displacement did not reach |distance|.
        #[arg(long)]
        strict: bool,
        /// Output .svg (input in grey, result in black) or text (the result only).
        #[arg(long)]
        out: PathBuf,
    },
}

fn load(p: &Path) -> Result<Drawing, CliError> {
    read_drawing(p).map_err(|e| CliError::msg(e.to_string()))
}

/// The closed loops of a drawing, or an error naming the first open one.
fn closed_only(d: &Drawing, input: &Path, what: &str) -> Result<Polygon, CliError> {
    if let Some(k) = d.curves.open.iter().position(|&o| o) {
        return Err(CliError::msg(format!(
            "{}: loop {k} is an open polyline; {what} needs closed loops",
            input.display()
        )));
    }
    Ok(d.curves.polygon.clone())
}

fn size_of(poly: &Polygon) -> f64 {
    let b = poly.bbox();
    (b[2] - b[0]).max(b[3] - b[1]).max(f64::MIN_POSITIVE)
}

fn check_sigma(sigma: f64) -> Result<(), CliError> {
    if sigma > 0.0 && sigma.is_finite() {
        Ok(())
    } else {
        Err(CliError::msg(format!(
            "--sigma {sigma}: expected a finite number > 0"
        )))
    }
}

fn is_svg(p: &Path) -> bool {
    p.extension().is_some_and(|e| e.eq_ignore_ascii_case("svg"))
}

/// Writes the result: SVG with the input in grey and the result in black, or the text format.
fn write_result(out: &Path, d: &Drawing, result: &Polygon) -> Result<(), CliError> {
    let result = Curves::closed(result.clone());
    let text = if is_svg(out) {
        svg_string(
            &[
                SvgLayer {
                    curves: &d.curves,
                    stroke: "#aaaaaa",
                    width: 0.004,
                },
                SvgLayer {
                    curves: &result,
                    stroke: "black",
                    width: 0.003,
                },
            ],
            !d.y_down,
        )
    } else {
        text_string(&result)
    };
    std::fs::write(out, text)
        .map_err(|e| CliError::msg(format!("{}: cannot write: {e}", out.display())))
}

fn gauwn(sigma: f64, fast: bool) -> GauWn {
    GauWn::new(sigma).with_bvn(if fast {
        BvnMethod::Fast
    } else {
        BvnMethod::Precise
    })
}

fn eval(
    input: &Path,
    points: &Path,
    sigma: Option<f64>,
    gradient: bool,
    fast: bool,
    out: Option<&Path>,
) -> Result<(), CliError> {
    let d = load(input)?;
    if let Some(s) = sigma {
        check_sigma(s)?;
    }
    let q = read_points(points).map_err(|e| CliError::msg(e.to_string()))?;
    let field = CurvesField::new(&d.curves);
    let cols = if gradient { 3 } else { 1 };
    let rows: Vec<[f64; 3]> = q
        .par_iter()
        .map(|&p| match sigma {
            None => [d.curves.winding_number(p), 0.0, 0.0],
            Some(s) => {
                let g = gauwn(s, fast);
                let w = field.value(&g, p);
                if gradient {
                    let gr = field.gradient(&g, p);
                    [w, gr[0], gr[1]]
                } else {
                    [w, 0.0, 0.0]
                }
            }
        })
        .collect();
    let write_err = |e: std::io::Error, what: &str| CliError::msg(format!("{what}: {e}"));
    match out {
        Some(o) if o.extension().is_some_and(|e| e.eq_ignore_ascii_case("npy")) => {
            let flat: Vec<f64> = rows.iter().flat_map(|r| r[..cols].to_vec()).collect();
            let shape: Vec<usize> = if cols == 1 {
                vec![rows.len()]
            } else {
                vec![rows.len(), cols]
            };
            npy::save(o, &shape, &flat)
                .map_err(|e| write_err(e, &format!("{}: cannot write", o.display())))?;
        }
        Some(o) => {
            let f = std::fs::File::create(o)
                .map_err(|e| write_err(e, &format!("{}: cannot create", o.display())))?;
            write_rows(std::io::BufWriter::new(f), &rows, cols, ",")
                .map_err(|e| write_err(e, &format!("{}: cannot write", o.display())))?;
        }
        None => {
            write_rows(std::io::stdout().lock(), &rows, cols, " ")
                .map_err(|e| write_err(e, "stdout: cannot write"))?;
        }
    }
    Ok(())
}

/// One line per point, values in full (`{}` prints the shortest form that reads back exactly).
fn write_rows(mut w: impl Write, rows: &[[f64; 3]], cols: usize, sep: &str) -> std::io::Result<()> {
    for r in rows {
        let line: Vec<String> = r[..cols].iter().map(|v| v.to_string()).collect();
        writeln!(w, "{}", line.join(sep))?;
    }
    w.flush()
}

/// The sampling grid of `curve field`: sample `(i, j)` is `origin + (i, j)·spacing`.
struct FieldGrid {
    origin: Point,
    spacing: f64,
    nx: usize,
    ny: usize,
}

impl FieldGrid {
    fn point(&self, i: usize, j: usize) -> Point {
        [
            self.origin[0] + i as f64 * self.spacing,
            self.origin[1] + j as f64 * self.spacing,
        ]
    }
}

#[allow(clippy::too_many_arguments)]
fn field(
    input: &Path,
    sigma: Option<f64>,
    res: usize,
    fast: bool,
    plain: bool,
    out: Option<&Path>,
    npy_out: Option<&Path>,
) -> Result<(), CliError> {
    if out.is_none() && npy_out.is_none() {
        return Err(CliError::msg("give --out PNG and/or --npy FILE"));
    }
    if !(2..=8192).contains(&res) {
        return Err(CliError::msg(format!("--res {res}: expected 2..=8192")));
    }
    let d = load(input)?;
    let poly = &d.curves.polygon;
    let size = size_of(poly);
    let sigma = sigma.unwrap_or(0.01 * size);
    check_sigma(sigma)?;
    let g = gauwn(sigma, fast);
    let field = CurvesField::new(&d.curves);
    let b = poly.bbox();
    let margin = 0.05 * size + if plain { 0.0 } else { 3.0 * sigma };
    let (x0, y0) = (b[0] - margin, b[1] - margin);
    let (wx, wy) = (b[2] - b[0] + 2.0 * margin, b[3] - b[1] + 2.0 * margin);
    let spacing = wx.max(wy) / res as f64;
    if !(spacing > 0.0 && spacing.is_finite()) {
        return Err(CliError::msg(format!(
            "{}: the drawing's extent {size:e} gives no usable pixel size",
            input.display()
        )));
    }
    let grid = FieldGrid {
        origin: [x0 + 0.5 * spacing, y0 + 0.5 * spacing],
        spacing,
        nx: ((wx / spacing).ceil() as usize).clamp(1, 8192),
        ny: ((wy / spacing).ceil() as usize).clamp(1, 8192),
    };
    // Row-major, row j = y increasing.
    let values: Vec<f64> = (0..grid.ny)
        .into_par_iter()
        .flat_map_iter(|j| {
            let (grid, field, d, g) = (&grid, &field, &d, &g);
            (0..grid.nx).map(move |i| {
                let p = grid.point(i, j);
                if plain {
                    d.curves.winding_number(p)
                } else {
                    field.value(g, p)
                }
            })
        })
        .collect();
    let (lo, hi) = values
        .iter()
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), &v| {
            (a.min(v), b.max(v))
        });
    if let Some(path) = npy_out {
        npy::save(path, &[grid.ny, grid.nx], &values)
            .map_err(|e| CliError::msg(format!("{}: cannot write: {e}", path.display())))?;
        outln!(
            "wrote {} (shape ({}, {}); value [j, i] at origin + (i, j)·spacing)",
            path.display(),
            grid.ny,
            grid.nx
        )?;
        outln!(
            "grid origin {} {} spacing {} shape {} {}",
            grid.origin[0],
            grid.origin[1],
            grid.spacing,
            grid.ny,
            grid.nx
        )?;
    }
    if let Some(path) = out {
        render_png(path, &grid, &values, &d)?;
        outln!(
            "wrote {} ({}×{} pixels, {}, {}; W in [{lo:.3}, {hi:.3}])",
            path.display(),
            grid.nx,
            grid.ny,
            if plain {
                "plain winding number".to_string()
            } else {
                format!("σ = {sigma}")
            },
            if d.y_down {
                "y axis down as in the SVG"
            } else {
                "y axis up"
            }
        )?;
    }
    Ok(())
}

/// The picture: `gwn slice`'s palette and colour bar, the curves in near black. SVG input is
/// shown as drawn (y down), text input with y up.
fn render_png(path: &Path, grid: &FieldGrid, values: &[f64], d: &Drawing) -> Result<(), CliError> {
    let (nx, ny, h) = (grid.nx, grid.ny, grid.spacing);
    // Image row r shows grid row j(r).
    let row_of = |r: usize| if d.y_down { r } else { ny - 1 - r };
    let mut top_first = Vec::with_capacity(values.len());
    for r in 0..ny {
        let j = row_of(r);
        top_first.extend_from_slice(&values[j * nx..(j + 1) * nx]);
    }
    let (x0, y0) = (grid.origin[0] - 0.5 * h, grid.origin[1] - 0.5 * h);
    let slice = Slice {
        axis: 2,
        coord: 0.0,
        u_range: [x0, x0 + nx as f64 * h],
        v_range: [y0, y0 + ny as f64 * h],
        width: nx,
        height: ny,
    };
    let mut img = slice.render(&top_first, None);
    let pts = d.curves.polygon.points();
    for k in 0..d.curves.polygon.num_loops() {
        let (s, e) = (
            d.curves.polygon.starts()[k],
            d.curves.polygon.starts()[k + 1],
        );
        let last = if d.curves.open[k] { e - 1 } else { e };
        for i in s..last {
            let (a, b) = (pts[i], pts[if i + 1 == e { s } else { i + 1 }]);
            let len = (b[0] - a[0]).hypot(b[1] - a[1]);
            let steps = ((len / (0.5 * h)).ceil() as usize).clamp(1, 1 << 20);
            for t in 0..=steps {
                let t = t as f64 / steps as f64;
                let x = a[0] + t * (b[0] - a[0]);
                let y = a[1] + t * (b[1] - a[1]);
                let (fi, fj) = ((x - x0) / h, (y - y0) / h);
                if fi >= 0.0 && fj >= 0.0 && (fi as usize) < nx && (fj as usize) < ny {
                    let j = fj as usize;
                    let r = if d.y_down { j } else { ny - 1 - j };
                    img.set(fi as usize, r, gwn::products::png::OUTLINE_COLOR);
                }
            }
        }
    }
    img.save_png(path)
        .map_err(|e| CliError::msg(format!("{}: cannot write: {e}", path.display())))
}

/// Exit status when `--strict` is given and the target was not reached.
const NOT_REACHED_STATUS: i32 = 3;

fn finish(strict: bool, reached: bool) -> Result<(), CliError> {
    if strict && !reached {
        eprintln!("gwn: target not reached (--strict)");
        std::process::exit(NOT_REACHED_STATUS);
    }
    Ok(())
}

/// Runs `gwn curve …`.
pub fn run(args: Args) -> Result<(), CliError> {
    match args.cmd {
        CurveCmd::Eval {
            input,
            points,
            sigma,
            gradient,
            fast,
            out,
        } => eval(&input, &points, sigma, gradient, fast, out.as_deref()),
        CurveCmd::Field {
            input,
            sigma,
            res,
            fast,
            plain,
            out,
            npy,
        } => field(
            &input,
            sigma,
            res,
            fast,
            plain,
            out.as_deref(),
            npy.as_deref(),
        ),
        CurveCmd::Untangle {
            input,
            sigma0,
            eps,
            lambda,
            decay,
            max_iters,
            inner_iters,
            patience,
            strict,
            out,
        } => {
            let params = UntangleParams {
                sigma0,
                eps,
                lambda,
                decay,
                max_outer: max_iters,
                inner_iters,
                patience,
                unsmoothed: false,
            };
            params.validate()?;
            let d = load(&input)?;
            let poly = closed_only(&d, &input, "untangle")?;
            let pb = progress(params.max_outer as u64, "untangle");
            let rep = untangle_with_progress(&poly, &params, &mut |p| {
                pb.set_position(p.outer as u64);
                pb.set_message(format!(
                    "untangle: {} crossings (best {}), σ {:.2e}",
                    p.crossings, p.best_crossings, p.sigma
                ));
            })?;
            pb.finish_and_clear();
            write_result(&out, &d, &rep.polygon)?;
            let why = match rep.stop {
                UntangleStop::Resolved => "resolved",
                UntangleStop::Stalled => "stalled: no better iterate in --patience steps",
                UntangleStop::MaxIterations => "--max-iters reached",
                UntangleStop::NonFinite => "stopped: non-finite energy",
            };
            let verdict = if rep.converged {
                "resolved".to_string()
            } else {
                format!("TARGET NOT REACHED, {why}")
            };
            outln!(
                "{}: {} → {} intersecting edge pairs ({verdict}); {} σ steps, best at step {}, max displacement {:.3e}",
                out.display(),
                rep.crossings_before,
                rep.crossings_after,
                rep.outer_iterations,
                rep.best_iteration,
                rep.max_displacement,
            )?;
            finish(strict, rep.converged)
        }
        CurveCmd::Offset {
            input,
            distance,
            sigma,
            step,
            lambda,
            max_steps,
            strict,
            out,
        } => {
            let params = OffsetParams {
                distance,
                sigma,
                step,
                lambda,
                max_steps,
            };
            params.validate()?;
            let d = load(&input)?;
            let poly = closed_only(&d, &input, "offset")?;
            let rep = offset(&poly, &params)?;
            write_result(&out, &d, &rep.polygon)?;
            let reached = rep.stop == OffsetStop::Reached;
            let verdict = match rep.stop {
                OffsetStop::Reached => "reached".to_string(),
                OffsetStop::Stalled => "TARGET NOT REACHED, the flow stalled".to_string(),
                OffsetStop::MaxSteps => "TARGET NOT REACHED, --max-steps reached".to_string(),
                OffsetStop::NonFinite => "TARGET NOT REACHED, non-finite energy".to_string(),
                OffsetStop::SelfIntersecting => {
                    "TARGET NOT REACHED, the next step would self-intersect".to_string()
                }
            };
            outln!(
                "{}: offset {distance}: mean displacement {:.4e} ({verdict}) in {} steps, σ {:.3e}",
                out.display(),
                rep.mean_displacement,
                rep.steps,
                rep.sigma
            )?;
            finish(strict, reached)
        }
    }
}
