//! The six-ray search over mixed-magnitude soups (docs/benchmarks.md, "Mixed magnitudes, six
//! rays"): one or two triangles over coordinates that are 0, `O(1)`, or `O(1)·2^-k` for any
//! `k < 1000` (the not-quite-zeros of rotated meshes), queried on an edge (at an end, the
//! middle, any point or beyond an end) moved along each axis by nothing or by any power of two
//! down to the subnormals. Off the surface `w` does not depend on the ray, so every query
//! whose six values spread by more than `1e-9` is a kernel error; each is printed as
//! `case|positions|triangles|query|values` (for an independent check, e.g. mpmath).
//!
//! With `oracle`, every query — on the surface too, where each ray has its own perturbed point
//! and agreement checks nothing — is also compared, ray by ray, with the rational oracle's
//! narrow interval (`gwn::testing::oracle_disagreements`, tolerance `1e-10`); those lines start
//! with `oracle|`. With `direct`, the direct sum (`--method direct`) is compared with the
//! oracle instead, off the surface (on it the direct sum returns the principal value, not a
//! ray's perturbed limit); those lines start with `direct|`.
//!
//! ```text
//! cargo run --release --features examples --example mixed_magnitude_rays -- [CASES] [SEED] [oracle|direct]
//! ```

use gwn::Mesh;
use gwn::testing::SplitMix64;

/// `2^-e` for `0 ≤ e ≤ 1074` (two exact steps into the subnormals).
fn power_of_two(e: u64) -> f64 {
    let e = e as i32;
    2f64.powi(-e / 2) * 2f64.powi(-(e - e / 2))
}

fn coordinate(rng: &mut SplitMix64) -> f64 {
    let r = rng.next_u64();
    let m = (1.0 + (r % 16) as f64 / 16.0) * if (r >> 8) & 1 == 1 { -1.0 } else { 1.0 };
    match (r >> 9) % 4 {
        0 => 0.0,
        1 => m,
        2 => m * power_of_two((r >> 12) % 1000),
        _ => ((r >> 20) % 8) as f64 - 4.0,
    }
}

fn main() {
    let mut args = std::env::args().skip(1);
    let cases: u64 = args.next().map_or(200_000, |s| s.parse().expect("CASES"));
    let seed: u64 = args.next().map_or(1, |s| s.parse().expect("SEED"));
    let mode = args.next().unwrap_or_default();
    let (with_oracle, direct) = (mode == "oracle", mode == "direct");
    let mut oracle_disagreements = 0u64;
    let mut rng = SplitMix64(seed);
    let (mut checked, mut disagreements) = (0u64, 0u64);
    for case in 0..cases {
        let p: Vec<[f64; 3]> = (0..4)
            .map(|_| std::array::from_fn(|_| coordinate(&mut rng)))
            .collect();
        let two = rng.next_u64().is_multiple_of(2);
        let faces: &[[u32; 3]] = if two {
            &[[0, 1, 2], [0, 2, 3]]
        } else {
            &[[0, 1, 2]]
        };
        let mesh = Mesh::from_slices(&p, faces).expect("finite coordinates");
        let r = rng.next_u64();
        let (a, b) = (p[(r % 4) as usize], p[((r >> 2) % 4) as usize]);
        let t = [0.0, 0.5, ((r >> 8) % 1000) as f64 / 1000.0, -0.5][((r >> 4) % 4) as usize];
        let q: [f64; 3] = std::array::from_fn(|k| {
            let r = rng.next_u64();
            let offset = if r.is_multiple_of(3) {
                0.0
            } else {
                let m = 1.0 + ((r >> 3) % 8) as f64 / 8.0;
                m * power_of_two((r >> 8) % 1075) * if (r >> 2) & 1 == 1 { -1.0 } else { 1.0 }
            };
            a[k] + t * (b[k] - a[k]) + offset
        });
        if !q.iter().all(|c| c.is_finite()) {
            continue;
        }
        checked += 1;
        if direct {
            if !gwn::testing::on_surface(&mesh, q) {
                let w = gwn::eval::direct::winding_number_direct(&mesh, q);
                let oracle =
                    gwn::testing::exact_winding_number_rational(&mesh, q, gwn::RayAxis::PosZ);
                if !oracle.contains(w, 1e-10) {
                    oracle_disagreements += 1;
                    println!("direct|{case}|{p:?}|{faces:?}|{q:?}|{w:?}|{oracle:?}");
                }
            }
            continue;
        }
        for (q, w) in gwn::testing::ray_disagreements(&mesh, &[q], 1e-9) {
            disagreements += 1;
            println!("{case}|{p:?}|{faces:?}|{q:?}|{w:?}");
        }
        if with_oracle {
            for (q, w) in gwn::testing::oracle_disagreements(&mesh, &[q], 1e-10) {
                oracle_disagreements += 1;
                println!("oracle|{case}|{p:?}|{faces:?}|{q:?}|{w:?}");
            }
        }
    }
    if direct {
        eprintln!(
            "seed {seed}: {checked} queries, {oracle_disagreements} direct sums off the surface leave the oracle's interval"
        );
        return;
    }
    eprintln!("seed {seed}: {checked} queries, {disagreements} off the surface depend on the ray");
    if with_oracle {
        eprintln!("seed {seed}: {oracle_disagreements} leave the oracle's interval on some ray");
    }
}
