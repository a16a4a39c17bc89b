//! Throughput of the testing kit: cases per second of each generator, queries per second of the
//! exact oracle and of the fast exact evaluator on those cases (one thread).
//!
//! Run: `cargo run --release --features examples --example testing_kit_rates`

use std::hint::black_box;
use std::time::Instant;

use gwn::RayAxis;
use gwn::testing::{Kind, Oracle, exact_evaluator};

fn main() {
    println!(
        "{:<13} {:>12} {:>10} {:>16} {:>16} {:>18}",
        "kind", "cases/s", "queries", "oracle q/s", "oracle cases/s", "fast exact q/s"
    );
    let (mut all_gen, mut all_or, mut all_fast) = (0.0, 0.0, 0.0);
    for kind in Kind::ALL {
        // Generators: as many cases as fit in 0.3 s.
        let t = Instant::now();
        let mut n = 0u64;
        let mut queries = 0usize;
        while t.elapsed().as_secs_f64() < 0.3 {
            queries += black_box(kind.generate(n)).queries.len();
            n += 1;
        }
        let gen_rate = n as f64 / t.elapsed().as_secs_f64();
        let per_case = queries as f64 / n as f64;
        // Oracle: build + every query, for 200 cases.
        let cases: Vec<_> = (0..200).map(|s| kind.generate(s)).collect();
        let t = Instant::now();
        let mut evals = 0usize;
        for c in &cases {
            let o = Oracle::new(&c.mesh, RayAxis::PosZ);
            for &q in &c.queries {
                black_box(o.eval(q));
                evals += 1;
            }
        }
        let dt = t.elapsed().as_secs_f64();
        let oracle_rate = evals as f64 / dt;
        // Fast exact evaluator: build + every query.
        let t = Instant::now();
        for c in &cases {
            let wn = exact_evaluator(&c.mesh, RayAxis::PosZ).expect("small meshes grid");
            for &q in &c.queries {
                black_box(wn.eval(q));
            }
        }
        let fast_rate = evals as f64 / t.elapsed().as_secs_f64();
        println!(
            "{:<13} {:>12.0} {:>10.1} {:>16.0} {:>16.0} {:>18.0}",
            kind.name(),
            gen_rate,
            per_case,
            oracle_rate,
            cases.len() as f64 / dt,
            fast_rate
        );
        all_gen += 1.0 / gen_rate;
        all_or += 1.0 / oracle_rate;
        all_fast += 1.0 / fast_rate;
    }
    let k = Kind::ALL.len() as f64;
    println!(
        "mix (equal share of kinds): {:.0} cases/s generated, {:.0} oracle queries/s, {:.0} fast exact queries/s",
        k / all_gen,
        k / all_or,
        k / all_fast
    );
}
