//! Issue 12: two synthetic large-boundary meshes for the boundary hierarchy, generated
//! reproducibly. The base surface is a closed, consistently oriented "scan": a bumpy ellipsoid (a
//! deterministic low-frequency radial displacement) triangulated as an indexed UV sphere of about
//! `FACES` (default 200000) triangles, every vertex shared. Writes two OBJ files into `OUT_DIR`
//! (created if missing):
//!
//! - `scan-holes.obj`: 5 % of the faces removed at random (seed 1);
//! - `scan-flipped.obj`: 5 % of the faces flipped at random (seed 2), none removed.
//!
//! The faces are picked by a partial Fisher–Yates shuffle driven by an inline splitmix64, so the
//! files are identical on every run. Prints V, F and the signed boundary of each file: `B` is the
//! sum over unordered vertex pairs of |net| (u→v counts +1, v→u −1), `edges` the number of pairs
//! with net ≠ 0 (what the exact evaluator's `boundary_edge_count` reports for an indexed mesh).
//!
//! ```text
//! cargo run --release --features examples --example synthetic_boundary -- OUT_DIR [FACES]
//! ```

use std::collections::HashMap;
use std::f64::consts::{PI, TAU};
use std::io::Write;
use std::path::Path;

struct SplitMix64(u64);

impl SplitMix64 {
    fn next(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9e37_79b9_7f4a_7c15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
        z ^ (z >> 31)
    }

    /// Uniform in `0..n` (the modulo bias is irrelevant here).
    fn below(&mut self, n: usize) -> usize {
        (self.next() % n as u64) as usize
    }
}

/// A bumpy ellipsoid as an indexed UV sphere with `2 m (n − 1)` outward-facing triangles.
fn bumpy_sphere(faces: usize) -> (Vec<[f64; 3]>, Vec<[u32; 3]>) {
    let n = ((faces as f64 / 4.0).sqrt().round() as usize).max(2); // stacks
    let m = (faces as f64 / (2.0 * (n - 1) as f64)).round().max(3.0) as usize; // slices
    let point = |theta: f64, phi: f64| {
        let (s, z) = theta.sin_cos();
        let (x, y) = (s * phi.cos(), s * phi.sin());
        let r = 1.0 + 0.08 * (3.0 * x + 1.0).sin() * (2.0 * y).cos() + 0.05 * (4.0 * z + x).sin();
        [r * x, 0.8 * r * y, 0.6 * r * z]
    };
    let mut verts = vec![point(0.0, 0.0)];
    for i in 1..n {
        let theta = PI * i as f64 / n as f64;
        for j in 0..m {
            verts.push(point(theta, TAU * j as f64 / m as f64));
        }
    }
    verts.push(point(PI, 0.0));
    let south = (verts.len() - 1) as u32;
    let ring = |i: usize, j: usize| (1 + (i - 1) * m + j % m) as u32;
    let mut tris = Vec::with_capacity(2 * m * (n - 1));
    for j in 0..m {
        tris.push([0, ring(1, j), ring(1, j + 1)]);
        for i in 1..n - 1 {
            let (a, c) = (ring(i, j), ring(i + 1, j + 1));
            tris.extend([[a, ring(i + 1, j), c], [a, c, ring(i, j + 1)]]);
        }
        tris.push([ring(n - 1, j), south, ring(n - 1, j + 1)]);
    }
    (verts, tris)
}

/// `count` distinct face indices, picked by a partial Fisher–Yates shuffle.
fn pick(faces: usize, count: usize, seed: u64) -> Vec<usize> {
    let mut rng = SplitMix64(seed);
    let mut order: Vec<usize> = (0..faces).collect();
    for k in 0..count {
        let r = k + rng.below(faces - k);
        order.swap(k, r);
    }
    order.truncate(count);
    order
}

/// (B = Σ |net| over unordered pairs, number of pairs with net ≠ 0).
fn signed_boundary(tris: &[[u32; 3]]) -> (i64, usize) {
    let mut net: HashMap<(u32, u32), i64> = HashMap::new();
    for t in tris {
        for k in 0..3 {
            let (u, v) = (t[k], t[(k + 1) % 3]);
            *net.entry((u.min(v), u.max(v))).or_default() += if u < v { 1 } else { -1 };
        }
    }
    let b = net.values().map(|w| w.abs()).sum();
    (b, net.values().filter(|&&w| w != 0).count())
}

fn write_obj(path: &Path, verts: &[[f64; 3]], tris: &[[u32; 3]]) -> std::io::Result<()> {
    let mut out = std::io::BufWriter::new(std::fs::File::create(path)?);
    for [x, y, z] in verts {
        writeln!(out, "v {x} {y} {z}")?;
    }
    for [i, j, k] in tris {
        writeln!(out, "f {} {} {}", i + 1, j + 1, k + 1)?;
    }
    out.flush()
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let args: Vec<String> = std::env::args().collect();
    let dir = Path::new(
        args.get(1)
            .ok_or("usage: synthetic_boundary OUT_DIR [FACES]")?,
    );
    let faces: usize = args.get(2).map_or(Ok(200_000), |s| s.parse())?;
    std::fs::create_dir_all(dir)?;
    let (verts, tris) = bumpy_sphere(faces);
    assert_eq!(signed_boundary(&tris), (0, 0), "the base must be closed");
    let count = (tris.len() as f64 * 0.05).round() as usize;

    let mut keep = vec![true; tris.len()];
    for f in pick(tris.len(), count, 1) {
        keep[f] = false;
    }
    let holes: Vec<_> = tris
        .iter()
        .zip(&keep)
        .filter_map(|(t, &k)| k.then_some(*t))
        .collect();
    let mut flipped = tris.clone();
    for f in pick(tris.len(), count, 2) {
        flipped[f].swap(1, 2);
    }

    for (name, mesh) in [("scan-holes.obj", &holes), ("scan-flipped.obj", &flipped)] {
        let path = dir.join(name);
        write_obj(&path, &verts, mesh)?;
        let (b, edges) = signed_boundary(mesh);
        println!(
            "{}: V = {}, F = {}, B = {b} (Σ|net|), {edges} edges with net ≠ 0",
            path.display(),
            verts.len(),
            mesh.len()
        );
    }
    Ok(())
}
