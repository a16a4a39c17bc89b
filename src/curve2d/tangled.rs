//! A reproducible set of tangled closed curves for testing and benchmarking [`super::apps::untangle`]:
//! figure-eights, circles with small figure-eight lobes, circles with local flips (swapped
//! neighbouring vertices) and noisy circles, 20–2000 vertices, 1–50 intersecting edge pairs. Every
//! curve is a function of its parameters only (a fixed linear congruential generator).

use super::polygon::{Point, Polygon};
use std::f64::consts::PI;

/// A named test curve.
#[derive(Clone, Debug)]
pub struct TangledCurve {
    /// Short description with its parameters.
    pub name: String,
    /// The curve (one closed loop).
    pub polygon: Polygon,
}

/// A small deterministic generator (Knuth's MMIX LCG, top 53 bits).
#[derive(Clone, Debug)]
pub struct Lcg(u64);

impl Lcg {
    /// A generator from a seed.
    pub fn new(seed: u64) -> Self {
        Lcg(seed
            .wrapping_mul(6_364_136_223_846_793_005)
            .wrapping_add(1_442_695_040_888_963_407))
    }

    /// Uniform in `[0, 1)`.
    pub fn next_f64(&mut self) -> f64 {
        self.0 = self
            .0
            .wrapping_mul(6_364_136_223_846_793_005)
            .wrapping_add(1_442_695_040_888_963_407);
        (self.0 >> 11) as f64 / (1u64 << 53) as f64
    }
}

/// One closed loop. The generators clamp `n ≥ 3` and place distinct finite vertices, which is
/// all [`Polygon::new`] checks, so this cannot fail.
fn closed(pts: Vec<Point>) -> Polygon {
    Polygon::new(vec![pts]).expect("generated loops have distinct finite vertices")
}

/// The lemniscate of Gerono `(sin t, sin t cos t)` with `n` vertices: one crossing at the
/// origin between two large lobes (not a local defect; untangling cannot resolve it locally).
pub fn figure_eight(n: usize) -> Polygon {
    let n = n.max(3);
    let pts = (0..n)
        .map(|i| {
            // Offset t so that no vertex lands exactly on the crossing.
            let t = 2.0 * PI * (i as f64 + 0.25) / n as f64;
            [t.sin(), t.sin() * t.cos()]
        })
        .collect();
    closed(pts)
}

/// A unit circle of `n` vertices in which `lobes` evenly spaced edges are replaced by a small
/// twisted (figure-eight) lobe of size `size` (relative to the radius).
pub fn circle_with_lobes(n: usize, lobes: usize, size: f64) -> Polygon {
    let n = n.max(3);
    let mut pts = Vec::new();
    let every = (n / lobes.max(1)).max(2);
    for i in 0..n {
        let t = 2.0 * PI * i as f64 / n as f64;
        let (c, s) = (t.cos(), t.sin());
        pts.push([c, s]);
        if i % every == every / 2 && pts.len() < 10 * n {
            // Local frame: tangent (−s, c), outward normal (c, s).
            let step = 2.0 * PI / n as f64;
            let lobe = [
                (0.25, 0.0),
                (0.75, 0.5),
                (0.75, -0.3),
                (0.4, 0.4),
                (0.9, 0.0),
            ];
            for (u, v) in lobe {
                let along = u * step.min(3.0 * size);
                let out = v * size;
                pts.push([c - s * along + c * out, s + c * along + s * out]);
            }
        }
    }
    closed(pts)
}

/// A unit circle of `n` vertices with radial noise of ±`noise` (relative) in which `flips`
/// random pairs of neighbouring vertices are swapped (each swap makes a small bow tie).
pub fn circle_with_flips(n: usize, flips: usize, noise: f64, seed: u64) -> Polygon {
    let n = n.max(3);
    let mut rng = Lcg::new(seed);
    let mut pts: Vec<Point> = (0..n)
        .map(|i| {
            let t = 2.0 * PI * i as f64 / n as f64;
            let r = 1.0 + noise * (2.0 * rng.next_f64() - 1.0);
            [r * t.cos(), r * t.sin()]
        })
        .collect();
    let mut used = vec![false; n];
    let mut done = 0;
    let mut tries = 0;
    while done < flips && tries < 100 * flips + 100 {
        tries += 1;
        let i = ((rng.next_f64() * n as f64) as usize).min(n - 1);
        let j = (i + 1) % n;
        let (prev, next) = ((i + n - 1) % n, (j + 1) % n);
        if used[i] || used[j] || used[prev] || used[next] {
            continue;
        }
        pts.swap(i, j);
        used[i] = true;
        used[j] = true;
        done += 1;
    }
    closed(pts)
}

/// A unit circle of `n` vertices whose vertices are moved by uniform noise of ±`amplitude`
/// edge lengths in both coordinates (crossings appear where neighbours overtake each other).
pub fn noisy_circle(n: usize, amplitude: f64, seed: u64) -> Polygon {
    let n = n.max(3);
    let mut rng = Lcg::new(seed);
    let edge = 2.0 * PI / n as f64;
    let pts = (0..n)
        .map(|i| {
            let t = 2.0 * PI * i as f64 / n as f64;
            let dx = amplitude * edge * (2.0 * rng.next_f64() - 1.0);
            let dy = amplitude * edge * (2.0 * rng.next_f64() - 1.0);
            [t.cos() + dx, t.sin() + dy]
        })
        .collect();
    closed(pts)
}

/// The benchmark set: 15 curves, 25–2060 vertices.
pub fn benchmark_set() -> Vec<TangledCurve> {
    let mut v = Vec::new();
    let mut push = |name: String, polygon: Polygon| v.push(TangledCurve { name, polygon });
    for (n, lobes) in [(20, 1), (100, 2), (200, 5), (1000, 10), (2000, 12)] {
        push(
            format!("circle+{lobes} lobes n={n}"),
            circle_with_lobes(n, lobes, 0.04),
        );
    }
    for (n, flips, seed) in [(50, 2, 1), (200, 8, 2), (500, 20, 3), (2000, 50, 4)] {
        push(
            format!("circle+{flips} flips n={n}"),
            circle_with_flips(n, flips, 0.0, seed),
        );
    }
    for (n, amp, seed) in [(100, 1.3, 5), (300, 1.2, 6), (1000, 1.0, 7), (1500, 0.9, 8)] {
        push(
            format!("noisy circle ±{amp} n={n}"),
            noisy_circle(n, amp, seed),
        );
    }
    // Last: global defects, which local untangling is not meant to resolve (the slowest rows).
    push("figure-eight n=40".into(), figure_eight(40));
    push("figure-eight n=200".into(), figure_eight(200));
    v
}
