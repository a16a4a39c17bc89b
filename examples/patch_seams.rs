//! The queries of issue 23 that used to hang, with the work and time each now takes: points
//! `1e-3 … 1e-12 × diagonal` from every seam, boundary curve and corner of the teapot (along the
//! normal, both sides, and straight below the boundary curves), exactly at its poles, near the
//! rim of a rational hemisphere, and on a closed sphere; six rays each. Reports per group the
//! largest evaluation count and time of one query, the uncertified count and the largest
//! spread of the six rays' values among certified queries.
//!
//! ```text
//! cargo run --release --features examples --example patch_seams -- ../shared/parametric/teapot.bpt
//! ```

#[path = "../tests/common/patch_points.rs"]
mod patch_points;

use std::collections::BTreeMap;
use std::time::Instant;

use gwn::RayAxis;
use gwn::patch::{Options, Patch, PatchSet, PatchWindingNumber, load_patches};
use patch_points::{Query, near_feature_queries, poles};

/// The unit sphere as 8 rational biquadratic patches (as `tests/common`).
fn sphere() -> PatchSet {
    let w = std::f64::consts::FRAC_1_SQRT_2;
    let south = [(0.0, -1.0, 1.0), (1.0, -1.0, w), (1.0, 0.0, 1.0)];
    let north = [(1.0, 0.0, 1.0), (1.0, 1.0, w), (0.0, 1.0, 1.0)];
    let quarters = [
        [(1.0, 0.0), (1.0, 1.0), (0.0, 1.0)],
        [(0.0, 1.0), (-1.0, 1.0), (-1.0, 0.0)],
        [(-1.0, 0.0), (-1.0, -1.0), (0.0, -1.0)],
        [(0.0, -1.0), (1.0, -1.0), (1.0, 0.0)],
    ];
    let cw = [1.0, w, 1.0];
    let mut patches = Vec::new();
    for profile in [south, north] {
        for quarter in quarters {
            let mut pts = Vec::new();
            let mut ws = Vec::new();
            for &(r, z, wp) in &profile {
                for (j, &(x, y)) in quarter.iter().enumerate() {
                    pts.push([r * x, r * y, z]);
                    ws.push(wp * cw[j]);
                }
            }
            patches.push(Patch::rational(2, 2, pts, ws).unwrap());
        }
    }
    PatchSet::new(patches).unwrap()
}

#[derive(Default)]
struct Row {
    count: usize,
    max_evaluations: usize,
    max_ms: f64,
    uncertified: usize,
    capped: usize,
    spread: f64,
    max_error_estimate: f64,
}

fn run(name: &str, set: &PatchSet, queries: &[Query], tolerance: f64) {
    let evaluators: Vec<PatchWindingNumber> = RayAxis::ALL
        .iter()
        .map(|&ray| PatchWindingNumber::with_options(set, Options { ray, tolerance }).unwrap())
        .collect();
    let mut rows: BTreeMap<(String, String), Row> = BTreeMap::new();
    let total = Instant::now();
    for q in queries {
        let row = rows
            .entry((q.kind.to_string(), format!("{:.0e}", q.offset)))
            .or_default();
        let mut values = Vec::new();
        let mut all_certified = true;
        for e in &evaluators {
            let t = Instant::now();
            let ev = e.evaluate(q.q);
            let ms = t.elapsed().as_secs_f64() * 1e3;
            row.count += 1;
            row.max_evaluations = row.max_evaluations.max(ev.evaluations);
            row.max_ms = row.max_ms.max(ms);
            row.uncertified += usize::from(!ev.certified);
            row.capped += usize::from(ev.capped);
            row.max_error_estimate = row.max_error_estimate.max(ev.error_estimate);
            all_certified &= ev.certified;
            values.push(ev.value);
        }
        if all_certified {
            let hi = values.iter().cloned().fold(f64::NEG_INFINITY, f64::max);
            let lo = values.iter().cloned().fold(f64::INFINITY, f64::min);
            row.spread = row.spread.max(hi - lo);
        }
    }
    println!(
        "{name}: {} queries × 6 rays, tolerance {tolerance:e}, {:.2} s",
        queries.len(),
        total.elapsed().as_secs_f64()
    );
    println!(
        "  {:<15} {:>6} {:>6} {:>9} {:>8} {:>6} {:>6} {:>9} {:>9}",
        "kind", "offset", "evals", "max evals", "max ms", "uncert", "capped", "max est", "spread"
    );
    for ((kind, off), r) in rows {
        println!(
            "  {kind:<15} {off:>6} {:>6} {:>9} {:>8.3} {:>6} {:>6} {:>9.1e} {:>9.1e}",
            r.count,
            r.max_evaluations,
            r.max_ms,
            r.uncertified,
            r.capped,
            r.max_error_estimate,
            r.spread
        );
    }
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let path = std::env::args()
        .nth(1)
        .unwrap_or_else(|| "../shared/parametric/teapot.bpt".into());
    let offsets = [1e-3, 1e-6, 1e-9, 1e-12];
    let teapot = load_patches(std::path::Path::new(&path))?;
    let mut queries = near_feature_queries(&teapot, &offsets, true);
    queries.extend(poles(&teapot));
    run("teapot", &teapot, &queries, 1e-10);

    // The rational hemisphere (upper half of the sphere): 150 points near its rim, at the
    // offsets above, inside and outside, above and below.
    let sphere = sphere();
    let hemisphere = PatchSet::new(sphere.patches()[4..].to_vec())?;
    let mut rim = Vec::new();
    for k in 0..150 {
        let phi = 2.0 * std::f64::consts::PI * (k as f64 + 0.37) / 150.0;
        let off = offsets[k % 4];
        let (dr, dz) = [
            (1.0, 0.0),
            (-1.0, 0.0),
            (0.0, 1.0),
            (0.0, -1.0),
            (0.7, -0.7),
        ][k % 5];
        let r = 1.0 + dr * off;
        rim.push(Query {
            kind: "rim",
            offset: off,
            q: [r * phi.cos(), r * phi.sin(), dz * off],
        });
    }
    run("rational hemisphere", &hemisphere, &rim, 1e-10);

    // The closed sphere: on the surface to rounding (seams, poles, patch interiors).
    let mut on = Vec::new();
    for k in 0..40 {
        let (theta, phi) = (
            std::f64::consts::PI * (k as f64 * 0.618).fract(),
            2.0 * std::f64::consts::PI * (k as f64 * 0.377).fract(),
        );
        let p = [
            theta.sin() * phi.cos(),
            theta.sin() * phi.sin(),
            theta.cos(),
        ];
        on.push(Query {
            kind: "on-surface",
            offset: 0.0,
            q: p,
        });
        on.push(Query {
            kind: "1e-30 off",
            offset: 1e-30,
            q: p.map(|c| c * (1.0 + 1e-30)),
        });
    }
    for q in [
        [1.0, 0.0, 0.0],
        [0.0, 0.0, 1.0],
        [0.0, 0.0, -1.0],
        [0.0, -1.0, 0.0],
    ] {
        on.push(Query {
            kind: "on-seam/pole",
            offset: 0.0,
            q,
        });
    }
    run("closed sphere", &sphere, &on, 1e-10);
    let mut worst: f64 = 0.0;
    for q in &on {
        for ray in RayAxis::ALL {
            let w = PatchWindingNumber::with_options(
                &sphere,
                Options {
                    ray,
                    tolerance: 1e-10,
                },
            )
            .unwrap()
            .eval(q.q);
            worst = worst.max((w - 0.5).abs());
        }
    }
    println!("  closed sphere on the surface: max |w − 0.5| over six rays = {worst:.2e}");
    Ok(())
}
