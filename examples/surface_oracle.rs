//! Each ray's value at query points that lie exactly on a mesh's surface, against the rational
//! oracle (docs/benchmarks.md, "On the surface, against the narrow oracle"). There `w` is the
//! value at each ray's own perturbed point, so the six rays may differ and their agreement
//! checks nothing; the oracle (`gwn::testing::Oracle`, big integers, no predicate shared with
//! the kernel) certifies an interval per ray. Points off the surface are skipped: the six-ray
//! sweep checks those (`benches/rays/ulp_rays.sh`). Prints the points on the surface, the
//! oracle's widest interval, and every point where a ray leaves its interval by more than
//! `1e-10` (`point|ray|value|lo|hi`).
//!
//! ```text
//! python3 benches/rays/ulp_points.py MESH.off q.csv 3000 11
//! cargo run --release --features examples --example surface_oracle -- MESH.off q.csv
//! ```

use gwn::RayAxis;
use gwn::eval::antipodal::{Options, WindingNumber};
use gwn::testing::{Oracle, on_surface};
use rayon::prelude::*;

fn main() {
    let mut args = std::env::args().skip(1);
    let (Some(mesh_path), Some(points_path)) = (args.next(), args.next()) else {
        eprintln!("usage: surface_oracle MESH POINTS.csv");
        std::process::exit(2);
    };
    let mesh = match gwn::io::load_mesh(&mesh_path) {
        Ok(loaded) => loaded.mesh,
        Err(e) => {
            eprintln!("{mesh_path}: {e}");
            std::process::exit(1);
        }
    };
    let text = std::fs::read_to_string(&points_path).unwrap_or_else(|e| {
        eprintln!("{points_path}: {e}");
        std::process::exit(1);
    });
    let points: Vec<[f64; 3]> = text
        .lines()
        .filter(|l| !l.trim().is_empty())
        .map(|l| {
            let c: Vec<f64> = l.split(',').map(|x| x.trim().parse().unwrap()).collect();
            [c[0], c[1], c[2]]
        })
        .collect();
    let start = std::time::Instant::now();
    let on: Vec<[f64; 3]> = points
        .par_iter()
        .copied()
        .filter(|&q| on_surface(&mesh, q))
        .collect();
    let rays: Vec<(RayAxis, WindingNumber, Oracle)> = RayAxis::ALL
        .iter()
        .map(|&ray| {
            let options = Options {
                ray,
                ..Default::default()
            };
            let wn = WindingNumber::with_options(&mesh, options).expect("the mesh builds");
            (ray, wn, Oracle::new(&mesh, ray))
        })
        .collect();
    let results: Vec<(f64, Vec<String>)> = on
        .par_iter()
        .map(|&q| {
            let mut widest = 0.0_f64;
            let mut bad = Vec::new();
            for (ray, wn, oracle) in &rays {
                let w = wn.eval(q);
                let c = oracle.eval(q);
                widest = widest.max(c.width());
                if !(c.is_narrow() && c.contains(w, 1e-10)) {
                    bad.push(format!("{q:?}|{ray:?}|{w}|{}|{}", c.lo, c.hi));
                }
            }
            (widest, bad)
        })
        .collect();
    let widest = results.iter().fold(0.0_f64, |m, r| m.max(r.0));
    let bad: Vec<&String> = results.iter().flat_map(|r| &r.1).collect();
    for line in &bad {
        println!("{line}");
    }
    println!(
        "{mesh_path}: {} points, {} on the surface, widest oracle interval {widest:.1e}, {} ray values outside it ({:.1} s)",
        points.len(),
        on.len(),
        bad.len(),
        start.elapsed().as_secs_f64()
    );
}
