//! Prints, for one query, the value along every candidate direction of the STEP evaluator.
//! `cargo run --release --features examples --example step_debug -- MODEL.step x y z`
fn main() {
    let a: Vec<String> = std::env::args().collect();
    let m = gwn::patch::step::load_step(std::path::Path::new(&a[1])).unwrap();
    let q = [
        a[2].parse().unwrap(),
        a[3].parse().unwrap(),
        a[4].parse().unwrap(),
    ];
    let wn = gwn::patch::step::StepWindingNumber::new(&m);
    println!("{:?}", wn.evaluate(q));
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
