//! Prints, for one query, the value along every candidate direction of the STEP evaluator, the
//! grid-column value along `z` and the `+z` hits.
//! `cargo run --release --features examples --example step_debug -- MODEL.step x y z`
//! `cargo run --release --features examples --example step_debug -- MODEL.step index` compares the indexed trimming
//! test with the scan on random points of every face.
fn main() {
    let a: Vec<String> = std::env::args().collect();
    let m = gwn::patch::step::load_step(std::path::Path::new(&a[1])).unwrap();
    if a.get(2).map(String::as_str) == Some("index") {
        // Indexed trimming test against the scan on random points of every face.
        let mut state = 7u64;
        let mut rnd = || {
            state = state
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            (state >> 11) as f64 / (1u64 << 53) as f64
        };
        let mut bad = 0;
        for f in m.faces() {
            let b = f.trim.bbox;
            for _ in 0..20000 {
                let p = f.trim.period_u.unwrap_or(0.0);
                let uv = [
                    b[0] - p + (1.4 * rnd() - 0.2) * (b[1] - b[0] + 2.0 * p),
                    b[2] + (1.4 * rnd() - 0.2) * (b[3] - b[2]),
                ];
                let su = [1.0 + rnd(), rnd(), rnd()];
                let sv = [rnd(), 1.0 + rnd(), rnd()];
                let margin = 1e-3 * rnd() * (b[1] - b[0]);
                let x = f.trim.classify(uv, su, sv, margin);
                let y = f.trim.classify_by_scan(uv, su, sv, margin);
                if x != y {
                    bad += 1;
                    if bad < 5 {
                        println!("face {}: {uv:?} index {x:?} scan {y:?}", f.id);
                    }
                }
            }
        }
        println!("{bad} disagreements");
        return;
    }
    let q = [
        a[2].parse().unwrap(),
        a[3].parse().unwrap(),
        a[4].parse().unwrap(),
    ];
    let wn = gwn::patch::step::StepWindingNumber::new(&m);
    println!("{:?}", wn.evaluate(q));
    println!(
        "column along z: {:?}",
        wn.evaluate_column(q, 2, &[q[2], q[2]])[0]
    );
    for h in wn.hits_along(q, [0.0, 0.0, 1.0]) {
        println!("  +z hit {h:?}");
    }
    if let Some(id) = a.get(5).and_then(|s| s.parse::<u64>().ok()) {
        let f = m.faces().iter().find(|f| f.id == id).unwrap();
        let segs = &f.trim.segments;
        println!(
            "face {id}: {} segments, bbox {:?}, sense {}, period {:?}",
            segs.len(),
            f.trim.bbox,
            f.sense,
            f.trim.period_u
        );
        for (k, s) in segs.iter().enumerate() {
            if k < 4
                || k + 4 > segs.len()
                || (s.a[0] - s.b[0]).abs() + (s.a[1] - s.b[1]).abs()
                    > 1e-2 * (f.trim.bbox[1] - f.trim.bbox[0])
            {
                println!("  {k}: {:?}", s);
            }
        }
        for p in &f.patches {
            println!("  patch u {:?} v {:?}", p.u, p.v);
        }
    }
    for &d in wn.directions() {
        println!("{d:?}: {:?}", wn.evaluate_along(q, d));
        for h in wn.hits_along(q, d) {
            println!("    {h:?}");
        }
    }
}
