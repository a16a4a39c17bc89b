//! Loads STEP models and times the trimmed-model evaluator on the paper's 32³ grid over the
//! bounding box (one thread): point by point ([`StepWindingNumber::evaluate`], one ray per
//! point) and column by column ([`StepWindingNumber::evaluate_column`], one ray per grid
//! column along `z`: the paper's ray reuse, Sec. 4.3.1). For models whose faces are untrimmed
//! (spring), also the exact mesh kernel on tessellations of the faces' patches, with their
//! error against the evaluator on the reference queries `<model>_ref/queries.npy`.
//!
//! Times are the thread's CPU time (`/proc/thread-self/schedstat`, wall-clock elsewhere), so
//! other processes on a shared machine disturb them far less than wall-clock time.
//!
//! `cargo run --release --features examples --example step_bench -- ../shared/parametric/step/*.step`
//!
//! Environment: `GWN_GRID` (default 32), `GWN_BENCH=points|columns` (only one of the two).

use std::path::Path;
use std::time::Instant;

use gwn::eval::antipodal::WindingNumber;
use gwn::patch::model::{Patch, PatchSet};
use gwn::patch::step::{StepModel, StepWindingNumber, load_step};
use gwn::patch::tessellate::tessellate;

/// CPU time of this thread in seconds (Linux), or wall-clock time since `start`.
fn cpu_seconds(start: Instant) -> f64 {
    std::fs::read_to_string("/proc/thread-self/schedstat")
        .ok()
        .and_then(|s| s.split_whitespace().next()?.parse::<f64>().ok())
        .map(|ns| ns * 1e-9)
        .unwrap_or_else(|| start.elapsed().as_secs_f64())
}

/// Milliseconds per item of `f` over `n` items, in CPU time.
fn timed<T>(n: usize, f: impl FnOnce() -> T) -> (f64, T) {
    let start = Instant::now();
    let t0 = cpu_seconds(start);
    let out = f();
    (1e3 * (cpu_seconds(start) - t0) / n as f64, out)
}

/// The faces' patches as one patch set with outward normals (`None` if some face is trimmed:
/// its loops' area is not its parameter box's).
fn untrimmed_patches(model: &StepModel) -> Option<PatchSet> {
    let mut out = Vec::new();
    for face in model.faces() {
        let t = &face.trim;
        let area: f64 = t
            .segments
            .iter()
            .map(|s| 0.5 * (s.a[0] * s.b[1] - s.b[0] * s.a[1]))
            .sum();
        let box_area = (t.bbox[1] - t.bbox[0]) * (t.bbox[3] - t.bbox[2]);
        if t.period_u.is_some() || (area.abs() - box_area).abs() > 1e-9 * box_area {
            return None;
        }
        for fp in &face.patches {
            let p = &fp.patch;
            // The mesh's triangles face `S_t × S_s`; the face's outward normal is
            // `sense · S_s × S_t`: swap s and t when the sense is positive.
            if face.sense > 0.0 {
                let (m, n) = p.degree();
                let idx = |i: usize, j: usize| i * (n + 1) + j;
                let mut pts = Vec::new();
                let mut ws = Vec::new();
                for j in 0..=n {
                    for i in 0..=m {
                        pts.push(p.points()[idx(i, j)]);
                        ws.push(p.weights()[idx(i, j)]);
                    }
                }
                out.push(Patch::rational(n, m, pts, ws).ok()?);
            } else {
                out.push(p.clone());
            }
        }
    }
    PatchSet::new(out).ok()
}

fn reference_queries(step: &Path) -> Option<Vec<[f64; 3]>> {
    let stem = step.file_stem()?.to_str()?;
    let q = step
        .with_file_name(format!("{stem}_ref"))
        .join("queries.npy");
    gwn::io::load_points(q).ok()
}

fn main() {
    let n = std::env::var("GWN_GRID")
        .ok()
        .and_then(|s| s.parse().ok())
        .unwrap_or(32usize);
    let only = std::env::var("GWN_BENCH").unwrap_or_default();
    for path in std::env::args().skip(1) {
        let t = Instant::now();
        let model = match load_step(Path::new(&path)) {
            Ok(m) => m,
            Err(e) => {
                println!("{path}: {e}");
                continue;
            }
        };
        let load = t.elapsed().as_secs_f64();
        let info = model.info();
        let (lo, hi) = model.bounding_box();
        // The reference grids use the B-rep's bounding box; the patch control boxes contain it.
        let wn = StepWindingNumber::new(&model);
        let lin = |k: usize, a: f64, b: f64| a + (b - a) * k as f64 / (n - 1) as f64;
        let zs: Vec<f64> = (0..n).map(|k| lin(k, lo[2], hi[2])).collect();
        let mut pts = Vec::with_capacity(n * n * n);
        for i in 0..n {
            for j in 0..n {
                for &z in &zs {
                    pts.push([lin(i, lo[0], hi[0]), lin(j, lo[1], hi[1]), z]);
                }
            }
        }
        println!(
            "{path}: load {load:.2} s; {} faces, {} patches, {} trim segments, {} boundary edges",
            info.faces, info.patches, info.trim_segments, info.boundary_edges
        );
        let mut per_point = Vec::new();
        if only != "columns" {
            let (ms, evals) = timed(pts.len(), || {
                pts.iter().map(|&q| wn.evaluate(q)).collect::<Vec<_>>()
            });
            let uncertified = evals.iter().filter(|e| e.uncertified).count();
            let rays: usize = evals.iter().map(|e| e.rays).sum();
            println!(
                "  {n}^3 grid, point by point: {ms:.4} ms/query (1 thread, CPU), {:.2} rays/query, \
                 {uncertified} uncertified",
                rays as f64 / pts.len() as f64
            );
            // The share of the points on the surface (within the margins; every direction is
            // tried before the relaxed pass): timed again on their own.
            let on_surface: Vec<[f64; 3]> = pts
                .iter()
                .zip(&evals)
                .filter(|(_, e)| e.uncertified)
                .map(|(&q, _)| q)
                .collect();
            if !on_surface.is_empty() {
                let (ms_on, _) = timed(on_surface.len(), || {
                    on_surface.iter().map(|&q| wn.eval(q)).sum::<f64>()
                });
                let rest = (ms * pts.len() as f64 - ms_on * on_surface.len() as f64)
                    / (pts.len() - on_surface.len()).max(1) as f64;
                println!(
                    "    the {} uncertified points: {ms_on:.3} ms each ({:.0} % of the time); \
                     the other points: {rest:.4} ms/query",
                    on_surface.len(),
                    100.0 * ms_on * on_surface.len() as f64 / (ms * pts.len() as f64)
                );
            }
            per_point = evals;
        }
        if only != "points" {
            let (ms, evals) = timed(pts.len(), || {
                pts.chunks_exact(n)
                    .flat_map(|col| wn.evaluate_column(col[0], 2, &zs))
                    .collect::<Vec<_>>()
            });
            let own = evals.iter().filter(|e| e.rays != 1).count();
            let uncertified = evals.iter().filter(|e| e.uncertified).count();
            let mut diff = 0.0f64;
            let mut differ = 0;
            for ((a, b), q) in per_point.iter().zip(&evals).zip(&pts) {
                if !a.uncertified && !b.uncertified {
                    let d = (a.value - b.value).abs();
                    diff = diff.max(d);
                    differ += usize::from(d > 1e-9);
                    if d > 1e-9 && differ <= 3 {
                        println!("  differs at {q:?}: point {a:?}, column {b:?}");
                    }
                }
            }
            println!(
                "  {n}^3 grid, columns along z: {ms:.4} ms/query (1 thread, CPU), {own} points \
                 evaluated on their own, {uncertified} uncertified; max |Δ| to point by point \
                 (both certified) {diff:.1e}, {differ} differ by more than 1e-9"
            );
        }
        let Some(set) = untrimmed_patches(&model) else {
            println!("  (trimmed faces: no tessellation baseline)");
            continue;
        };
        let Some(refq) = reference_queries(Path::new(&path)) else {
            continue;
        };
        // The evaluator at its default tolerance (1e-10) as the reference of the tessellations.
        let exact: Vec<f64> = refq.iter().map(|&q| wn.eval(q)).collect();
        for k in [4, 8, 16, 32, 64] {
            let Ok(mesh) = tessellate(&set, k) else {
                continue;
            };
            let Ok(mw) = WindingNumber::new(&mesh) else {
                continue;
            };
            let (ms, _) = timed(pts.len(), || pts.iter().map(|&q| mw.eval(q)).sum::<f64>());
            let mut errs: Vec<f64> = refq
                .iter()
                .zip(&exact)
                .map(|(&q, &w)| (mw.eval(q) - w).abs())
                .collect();
            errs.sort_by(f64::total_cmp);
            println!(
                "  tessellation k = {k} ({} triangles), exact mesh kernel: {ms:.4} ms/query on the \
                 grid; |w − evaluator| on the {} reference queries: median {:.1e}, max {:.1e}",
                mesh.triangles().len(),
                refq.len(),
                errs[errs.len() / 2],
                errs[errs.len() - 1]
            );
        }
    }
}
