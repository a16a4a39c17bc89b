//! `gwn bench`: throughput of the evaluators, measured side by side in one run.

use std::path::PathBuf;
use std::time::Instant;

use clap::Args as ClapArgs;
use gwn::Mesh;
use gwn::eval::antipodal::WindingNumber;
use gwn::eval::direct::winding_number_direct;
use gwn::eval::fast::{FastParams, FastWindingNumber};
use rayon::prelude::*;

use crate::common::{CliError, checked_threads, load_mesh_for_cli, outln};

/// Benchmark the evaluators on meshes: per mesh, faces, boundary edges, precompute time of
/// `exact` (with its boundary hierarchy, see --tolerance), tree build time of `fast`, and queries/s of `exact`, `direct` and `fast`
/// (Barnes–Hut, `--beta`, `--order`) on an N³ grid over the bounding box enlarged by 10 % per
/// side, with each thread count. `direct` is timed on an evenly spaced subset of the grid
/// (`--direct-sample`) because it costs O(faces) per query; the last column is the largest
/// |fast − direct| on that subset.
///
/// Example: gwn bench ../shared/meshes --grid 32 --threads-list 1,2 --markdown
#[derive(ClapArgs, Debug)]
#[command(verbatim_doc_comment)]
pub struct Args {
    /// Mesh files or folders (every .obj/.stl/.off/.ply/.gltf/.glb inside, sorted).
    #[arg(required = true)]
    pub paths: Vec<PathBuf>,
    /// Grid resolution per axis (1 to 256: the grid has N³ points).
    #[arg(long, default_value_t = 32)]
    pub grid: usize,
    /// Thread counts to measure.
    #[arg(long, value_delimiter = ',', default_value = "1,2")]
    pub threads_list: Vec<usize>,
    /// Number of grid points on which the direct sum is timed.
    #[arg(long, default_value_t = 256)]
    pub direct_sample: usize,
    /// Accuracy of the fast method (Barill et al.'s β: a node is approximated beyond β times
    /// its radius; positive, finite).
    #[arg(long, default_value_t = 2.0, allow_negative_numbers = true)]
    pub beta: f64,
    /// Expansion order of the fast method (0, 1 or 2).
    #[arg(long, default_value_t = 2)]
    pub order: u8,
    /// Which node size beta multiplies in the fast method (as in `gwn eval --rule`).
    #[arg(long, value_parser = crate::method::parse_option::<gwn::eval::fast::Admissibility>, default_value = "radius")]
    pub rule: gwn::eval::fast::Admissibility,
    /// Leave out the `exact` columns (for timing `fast` alone, e.g. on soups, where the exact
    /// method costs O(faces) per query).
    #[arg(long)]
    pub skip_exact: bool,
    /// Print a Markdown table.
    #[arg(long)]
    pub markdown: bool,
    #[command(flatten)]
    pub tolerance: crate::method::ToleranceArgs,
}

impl Args {
    /// The exact method's options (`--tolerance`).
    fn method_spec(&self) -> gwn::spec::EvaluatorSpec {
        gwn::spec::EvaluatorSpec {
            tolerance: self.tolerance.tolerance,
            ..Default::default()
        }
    }
}

/// Largest `--grid`: the N³ query points and two value arrays take 40 bytes per point, so 256
/// (16.8 million points) needs about 640 MiB; `--grid 1000` would need 40 GB.
pub const MAX_GRID: usize = 256;

/// Runs `gwn bench`.
pub fn run(mut args: Args) -> Result<(), CliError> {
    if !(1..=MAX_GRID).contains(&args.grid) {
        return Err(CliError(format!(
            "--grid {}: expected 1 to {MAX_GRID} (the grid has N³ points; {MAX_GRID}³ = {} \
             points take about {} MB)",
            args.grid,
            MAX_GRID.pow(3),
            (MAX_GRID.pow(3) * 40) >> 20
        )));
    }
    if args.direct_sample == 0 {
        return Err(CliError::msg(
            "--direct-sample 0: expected at least 1 point",
        ));
    }
    // The values' rules (bench runs both methods, so no method is named).
    gwn::spec::EvaluatorSpec {
        beta: Some(args.beta),
        order: Some(args.order),
        rule: Some(args.rule),
        ..args.method_spec()
    }
    .validate()?;
    for t in &mut args.threads_list {
        *t = checked_threads(*t, "--threads-list")?;
    }
    let mut files = Vec::new();
    for p in &args.paths {
        if p.is_dir() {
            let mut v: Vec<PathBuf> = std::fs::read_dir(p)
                .map_err(|e| CliError(format!("{}: {e}", p.display())))?
                .filter_map(|e| e.ok().map(|e| e.path()))
                .filter(|p| {
                    p.extension().and_then(|e| e.to_str()).is_some_and(|e| {
                        ["obj", "stl", "off", "ply", "gltf", "glb"]
                            .contains(&e.to_ascii_lowercase().as_str())
                    })
                })
                .collect();
            v.sort();
            files.extend(v);
        } else {
            files.push(p.clone());
        }
    }
    let mut header = String::from("mesh | faces | boundary | precompute ms | fast build ms");
    for t in &args.threads_list {
        if !args.skip_exact {
            header += &format!(" | exact q/s ({t}t)");
        }
        header += &format!(" | direct q/s ({t}t) | fast q/s ({t}t)");
    }
    if !args.skip_exact {
        header += " | exact/direct";
    }
    header += " | fast/direct | fast max err";
    if !args.skip_exact {
        // Issue 21's cost: how many vertices the 60-bit lattice does not hold, and how often an
        // exact query needed big-integer arithmetic on the input values.
        header += " | off-lattice vertices | exact fallbacks";
    }
    if args.markdown {
        outln!("| {header} |")?;
        outln!("|{}", "---|".repeat(header.matches('|').count() + 1))?;
    } else {
        outln!("{}", header.replace(" | ", "\t"))?;
    }
    for f in files {
        let mesh = load_mesh_for_cli(&f, Default::default())?;
        let Some(row) = bench_mesh(&mesh, &args)? else {
            continue;
        };
        let name = f
            .file_name()
            .map(|n| n.to_string_lossy().into_owned())
            .unwrap_or_default();
        let line = format!("{name} | {row}");
        if args.markdown {
            outln!("| {line} |")?;
        } else {
            outln!("{}", line.replace(" | ", "\t"))?;
        }
    }
    Ok(())
}

fn bench_mesh(mesh: &Mesh, args: &Args) -> Result<Option<String>, CliError> {
    let Some(bbox) = mesh.bounding_box() else {
        return Ok(None);
    };
    let b = bbox.enlarged(0.1);
    let n = args.grid;
    let points: Vec<[f64; 3]> = (0..n * n * n)
        .map(|i| {
            let idx = [i % n, (i / n) % n, i / (n * n)];
            std::array::from_fn(|k| {
                b.min[k] + (b.max[k] - b.min[k]) * (idx[k] as f64 + 0.5) / n as f64
            })
        })
        .collect();
    let step = (points.len() / args.direct_sample).max(1);
    let sample: Vec<[f64; 3]> = points.iter().step_by(step).copied().collect();
    let options = args.method_spec().exact_options();
    let t0 = Instant::now();
    let wn = WindingNumber::with_options(mesh, options).map_err(|e| CliError(e.to_string()))?;
    // The boundary hierarchy is built on first use: one query outside the box builds it here, so
    // that it counts as precomputation and not in the first thread count's throughput.
    let outside: [f64; 3] = std::array::from_fn(|k| b.max[k] + (b.max[k] - b.min[k]));
    std::hint::black_box(wn.eval(outside));
    let pre = t0.elapsed().as_secs_f64() * 1e3;
    let t0 = Instant::now();
    let params = FastParams {
        beta: args.beta,
        order: args.order,
        admissibility: args.rule,
    };
    let fast = FastWindingNumber::with_params(mesh, params);
    let build = t0.elapsed().as_secs_f64() * 1e3;
    let mut row = format!(
        "{} | {} | {pre:.1} | {build:.1}",
        mesh.triangles().len(),
        wn.boundary_edge_count()
    );
    let mut ratio = 0.0;
    let mut fast_ratio = 0.0;
    let mut max_err = 0.0_f64;
    let fallbacks_before = gwn::eval::exact_fallbacks();
    let mut exact_queries = 0usize;
    for &t in &args.threads_list {
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(t)
            .build()
            .map_err(|e| CliError(e.to_string()))?;
        let (exact_qps, direct_qps, fast_qps) = pool.install(|| {
            let exact = if args.skip_exact {
                f64::NAN
            } else {
                exact_queries += points.len();
                let t0 = Instant::now();
                let w = wn.eval_batch(&points);
                std::hint::black_box(w);
                points.len() as f64 / t0.elapsed().as_secs_f64()
            };
            let t0 = Instant::now();
            let d: Vec<f64> = sample
                .par_iter()
                .map(|&q| winding_number_direct(mesh, q))
                .collect();
            let direct = sample.len() as f64 / t0.elapsed().as_secs_f64();
            let t0 = Instant::now();
            let w = fast.eval_batch(&points);
            let fast_qps = points.len() as f64 / t0.elapsed().as_secs_f64();
            // The fast values on the direct sample: the same grid points, same order. A NaN
            // error is kept (f64::max would drop it).
            for (&wf, &wd) in w.iter().step_by(step).zip(&d) {
                let e = (wf - wd).abs();
                if e > max_err || e.is_nan() {
                    max_err = e;
                }
            }
            std::hint::black_box(w);
            (exact, direct, fast_qps)
        });
        ratio = exact_qps / direct_qps;
        fast_ratio = fast_qps / direct_qps;
        if !args.skip_exact {
            row += &format!(" | {exact_qps:.0}");
        }
        row += &format!(" | {direct_qps:.0} | {fast_qps:.0}");
    }
    if !args.skip_exact {
        row += &format!(" | {ratio:.1}×");
    }
    row += &format!(" | {fast_ratio:.1}× | {max_err:.1e}");
    if !args.skip_exact {
        let fallbacks = gwn::eval::exact_fallbacks() - fallbacks_before;
        row += &format!(
            " | {} | {fallbacks} in {exact_queries} queries",
            wn.snapping().off_lattice
        );
    }
    Ok(Some(row))
}
