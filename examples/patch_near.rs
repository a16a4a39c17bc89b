//! The patch evaluator against the direct surface quadrature at points 1e-3 from the teapot's
//! boundary curves (lid gap, tube ends), with timings.
//!
//! ```text
//! cargo run --release --features examples --example patch_near -- ../shared/parametric/teapot.bpt 1e-10
//! ```

use std::time::Instant;

use gwn::patch::boundary::{EdgeLink, link_edges};
use gwn::patch::surface_quadrature::winding_number_surface_quadrature;
use gwn::patch::{Options, PatchWindingNumber, load_patches};

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let mut args = std::env::args().skip(1);
    let path = args
        .next()
        .unwrap_or_else(|| "../shared/parametric/teapot.bpt".into());
    let tol: f64 = args.next().and_then(|s| s.parse().ok()).unwrap_or(1e-9);
    let set = load_patches(std::path::Path::new(&path))?;
    let links = link_edges(&set);
    let wn = PatchWindingNumber::with_options(
        &set,
        Options {
            tolerance: 1e-12,
            ..Options::default()
        },
    )
    .unwrap();
    let mut worst = 0.0f64;
    for (p, patch) in set.patches().iter().enumerate() {
        for (e, link) in links[p].iter().enumerate() {
            if *link != EdgeLink::Boundary {
                continue;
            }
            let (s, t) = [(0.0, 0.37), (0.37, 1.0), (1.0, 0.37), (0.37, 0.0)][e];
            for axis in 0..3 {
                for sign in [1.0, -1.0] {
                    let mut q = patch.eval(s, t);
                    q[axis] += sign * 1e-3;
                    let t0 = Instant::now();
                    let ev = wn.evaluate(q);
                    let t1 = t0.elapsed();
                    let t0 = Instant::now();
                    let (r, err) = winding_number_surface_quadrature(&set, q, tol);
                    let t2 = t0.elapsed();
                    worst = worst.max((ev.value - r).abs());
                    println!(
                        "patch {p:2} edge {e} axis {axis} {sign:+}: w = {:.12} (±{:.1e}, {t1:?}), quadrature {r:.12} (±{err:.1e}, {t2:?}), diff {:.1e}",
                        ev.value,
                        ev.error_estimate,
                        (ev.value - r).abs()
                    );
                }
            }
        }
    }
    println!("worst difference {worst:.2e}");
    Ok(())
}
