//! Every reference query of the shared STEP models (`<dir>/<model>_ref/{queries,ref,err}.npy`):
//! max |Δw|, failures against the bound (closed models: the exact integer within 1e-9;
//! open models: max(1e-7, 3·err)), uncertified evaluations and ms per query (one thread).
//!
//! `cargo run --release --features examples --example step_accuracy -- ../shared/parametric/step`

use std::path::{Path, PathBuf};
use std::time::Instant;

use gwn::patch::step::{StepWindingNumber, load_step};

/// `<f8` (any shape, flattened) from a little-endian, C-order `.npy` file.
fn npy_f64(path: &Path) -> Result<Vec<f64>, String> {
    let b = std::fs::read(path).map_err(|e| format!("{}: {e}", path.display()))?;
    if b.len() < 12 || &b[..6] != b"\x93NUMPY" {
        return Err(format!("{}: not a .npy file", path.display()));
    }
    let (hlen, start) = if b[6] == 1 {
        (u16::from_le_bytes([b[8], b[9]]) as usize, 10)
    } else {
        (u32::from_le_bytes([b[8], b[9], b[10], b[11]]) as usize, 12)
    };
    let header = b
        .get(start..start + hlen)
        .and_then(|h| std::str::from_utf8(h).ok())
        .ok_or_else(|| format!("{}: bad header", path.display()))?;
    if !header.contains("<f8") || !header.contains("'fortran_order': False") {
        return Err(format!("{}: not C-order float64", path.display()));
    }
    Ok(b[start + hlen..]
        .chunks_exact(8)
        .map(|c| f64::from_le_bytes(c.try_into().unwrap()))
        .collect())
}

fn main() -> Result<(), String> {
    let dir = PathBuf::from(
        std::env::args()
            .nth(1)
            .unwrap_or_else(|| "../shared/parametric/step".into()),
    );
    println!("| model | queries | max abs Δw | failures | uncertified | ms/query |");
    println!("|---|---|---|---|---|---|");
    for (model, closed) in [
        ("tet", true),
        ("sliced_cylinder", true),
        ("boxed_sphere", true),
        ("open_cylinder", false),
        ("spring", false),
    ] {
        let m = load_step(&dir.join(format!("{model}.step"))).map_err(|e| e.to_string())?;
        let wn = StepWindingNumber::new(&m);
        let r = dir.join(format!("{model}_ref"));
        let q = npy_f64(&r.join("queries.npy"))?;
        let reference = npy_f64(&r.join("ref.npy"))?;
        let err = npy_f64(&r.join("err.npy"))?;
        let points: Vec<[f64; 3]> = q.chunks_exact(3).map(|c| [c[0], c[1], c[2]]).collect();
        let t = Instant::now();
        let evaluations: Vec<_> = points.iter().map(|&p| wn.evaluate(p)).collect();
        let secs = t.elapsed().as_secs_f64();
        let (mut worst, mut failures, mut uncertified) = (0.0f64, Vec::new(), 0);
        for (i, e) in evaluations.iter().enumerate() {
            let dw = (e.value - reference[i]).abs();
            let allowed = if closed {
                1e-9
            } else {
                (3.0 * err[i]).max(1e-7)
            };
            worst = worst.max(dw);
            uncertified += usize::from(e.uncertified);
            if dw.is_nan() || dw > allowed {
                failures.push(i);
            }
        }
        println!(
            "| {model} | {} | {worst:.2e} | {} {:?} | {uncertified} | {:.3} |",
            points.len(),
            failures.len(),
            &failures[..failures.len().min(8)],
            1e3 * secs / points.len() as f64
        );
    }
    Ok(())
}
