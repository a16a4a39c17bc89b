//! The fast evaluators' build runs on the current rayon pool (subtrees in parallel): it must
//! give the same tree, the same moments and the same values bit for bit at any thread count,
//! i.e. the values of the single-threaded build (`src/eval/fast/tree.rs` also checks the tree
//! against the serial build it replaced).

use gwn::Mesh;
use gwn::eval::fast::{FastParams, FastWindingNumber, Moments, PointCloudWindingNumber};
use gwn::mesh::PointCloud;

use crate::common::Rng;

fn pool(threads: usize) -> rayon::ThreadPool {
    rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build()
        .expect("thread pool")
}

/// A bumpy latitude–longitude sphere with `2·n·(n−1)`-ish triangles, plus a few thousand loose
/// random triangles (a soup part: overlapping, some degenerate), so that the tree has
/// subtrees above the parallel grain and near-duplicate centroids.
fn bumpy_sphere_and_soup(n: usize, loose: usize) -> Mesh {
    let mut rng = Rng(7);
    let mut positions = Vec::new();
    for i in 0..=n {
        let theta = std::f64::consts::PI * i as f64 / n as f64;
        for j in 0..n {
            let phi = std::f64::consts::TAU * j as f64 / n as f64;
            let r = 1.0 + 0.05 * (5.0 * phi).sin() * (3.0 * theta).cos();
            positions.push([
                r * theta.sin() * phi.cos(),
                r * theta.sin() * phi.sin(),
                r * theta.cos(),
            ]);
        }
    }
    let id = |i: usize, j: usize| (i * n + j % n) as u32;
    let mut triangles = Vec::new();
    for i in 0..n {
        for j in 0..n {
            let (a, b, c, d) = (id(i, j), id(i, j + 1), id(i + 1, j), id(i + 1, j + 1));
            triangles.push([a, c, d]);
            triangles.push([a, d, b]);
        }
    }
    for k in 0..loose {
        let base = positions.len() as u32;
        let centre = [
            rng.range(-1.5, 1.5),
            rng.range(-1.5, 1.5),
            rng.range(-1.5, 1.5),
        ];
        for _ in 0..3 {
            let s = if k % 50 == 0 { 0.0 } else { 0.05 };
            positions.push(centre.map(|c| c + s * rng.range(-1.0, 1.0)));
        }
        triangles.push([base, base + 1, base + 2]);
    }
    Mesh::new(positions, triangles).expect("valid mesh")
}

fn moment_bits(m: &Moments) -> Vec<u64> {
    let mut v: Vec<f64> = Vec::new();
    v.extend(m.center);
    v.push(m.radius);
    v.push(m.area);
    v.extend(m.n);
    v.extend(m.m1.iter().flatten());
    v.extend(m.m2.iter().flatten());
    v.iter().map(|x| x.to_bits()).collect()
}

fn queries(n: usize) -> Vec<[f64; 3]> {
    let mut rng = Rng(11);
    (0..n)
        .map(|_| [0; 3].map(|_| rng.range(-1.8, 1.8)))
        .collect()
}

#[test]
fn mesh_build_is_the_same_at_any_thread_count() {
    let mesh = bumpy_sphere_and_soup(90, 3000);
    assert!(
        mesh.triangles().len() > 3 * 4096,
        "subtrees above the parallel grain"
    );
    let params = FastParams::barill(2.0, 2);
    let qs = queries(1500);
    let reference = pool(1).install(|| FastWindingNumber::with_params(&mesh, params));
    let values: Vec<u64> = qs.iter().map(|&q| reference.eval(q).to_bits()).collect();
    for threads in [2, 3] {
        let fast = pool(threads).install(|| FastWindingNumber::with_params(&mesh, params));
        assert_eq!(
            fast.node_count(),
            reference.node_count(),
            "{threads} threads"
        );
        for id in 0..fast.node_count() {
            assert_eq!(
                moment_bits(fast.node_moments(id)),
                moment_bits(reference.node_moments(id)),
                "node {id}'s moments, built on {threads} threads"
            );
            let (a, b) = (fast.node_box(id), reference.node_box(id));
            assert_eq!((a.min, a.max), (b.min, b.max), "node {id}'s box");
        }
        for (&q, &v) in qs.iter().zip(&values) {
            assert_eq!(
                fast.eval(q).to_bits(),
                v,
                "value at {q:?}: the build on {threads} threads differs from the one on 1"
            );
        }
    }
}

#[test]
fn point_cloud_build_is_the_same_at_any_thread_count() {
    let mut rng = Rng(3);
    let n = 15_000;
    let positions: Vec<[f64; 3]> = (0..n)
        .map(|_| {
            let z = rng.range(-1.0, 1.0);
            let phi = rng.range(0.0, std::f64::consts::TAU);
            let s = (1.0 - z * z).sqrt();
            [s * phi.cos(), s * phi.sin(), z]
        })
        .collect();
    let areas = vec![4.0 * std::f64::consts::PI / n as f64; n];
    let cloud = PointCloud::new(positions.clone(), positions, Some(areas)).expect("valid cloud");
    let qs = queries(1500);
    let reference = pool(1).install(|| PointCloudWindingNumber::new(&cloud));
    let values: Vec<u64> = qs.iter().map(|&q| reference.eval(q).to_bits()).collect();
    for threads in [2, 3] {
        let fast = pool(threads).install(|| PointCloudWindingNumber::new(&cloud));
        for (&q, &v) in qs.iter().zip(&values) {
            assert_eq!(
                fast.eval(q).to_bits(),
                v,
                "value at {q:?}: the build on {threads} threads differs from the one on 1"
            );
        }
    }
    // The values are the winding numbers of the sphere (a test that they are values at all).
    assert!((reference.eval([0.1, 0.2, 0.0]) - 1.0).abs() < 1e-2);
    assert!(reference.eval([1.5, 0.0, 0.3]).abs() < 1e-2);
}
