//! Random open triangles whose edge `a → b` runs through the origin (`b = −r·a`, exact with
//! dyadic coordinates), seen from `d·n` at `d = 1e-6 … 1e-300` from that edge: queries that close
//! exist in `f64` only next to such an edge. Shared by the gradient's and the direct sum's
//! property tests.

use gwn::Mesh;
use proptest::prelude::*;

/// A triangle and a query direction beside its edge through the origin.
#[derive(Debug, Clone)]
pub struct BesideEdge {
    pub mesh: Mesh,
    /// The query is `n·d`.
    pub n: [f64; 3],
    pub d: f64,
    /// `|n·N̂|/|n|` for the triangle's unit normal `N̂`: how far `n` leaves the triangle's plane.
    pub off_plane: f64,
}

/// A dyadic `±(1 + k/16)·2^j`: exact, so `−r·a` is exact too.
fn dyadic() -> impl Strategy<Value = f64> {
    (0u32..16, -3i32..=3, any::<bool>()).prop_map(|(k, j, neg)| {
        (1.0 + f64::from(k) / 16.0) * 2f64.powi(j) * if neg { -1.0 } else { 1.0 }
    })
}

fn cross(u: [f64; 3], v: [f64; 3]) -> [f64; 3] {
    [
        u[1] * v[2] - u[2] * v[1],
        u[2] * v[0] - u[0] * v[2],
        u[0] * v[1] - u[1] * v[0],
    ]
}

fn dot(u: [f64; 3], v: [f64; 3]) -> f64 {
    u[0] * v[0] + u[1] * v[1] + u[2] * v[2]
}

/// Triangles that are not slivers (normal above `1e-3` of the sides' product) and directions
/// `n` at least `0.3` (sine) from the edge's.
pub fn beside_edge() -> impl Strategy<Value = BesideEdge> {
    (
        proptest::array::uniform3(dyadic()),
        proptest::array::uniform3(dyadic()),
        proptest::array::uniform3(-1.0f64..1.0),
        proptest::sample::select(vec![0.25, 0.5, 1.0, 1.5, 3.0]),
        proptest::sample::select(vec![1e-6, 1e-12, 1e-40, 1e-150, 1e-300]),
    )
        .prop_filter_map("a sliver, or n along the edge", |(a, c, n, r, d)| {
            let b = a.map(|x| -r * x);
            let e = [b[0] - a[0], b[1] - a[1], b[2] - a[2]];
            let ca = [c[0] - a[0], c[1] - a[1], c[2] - a[2]];
            let normal = cross(e, ca);
            let (ln, le, lnn) = (
                dot(normal, normal).sqrt(),
                dot(e, e).sqrt(),
                dot(n, n).sqrt(),
            );
            let ne = cross(n, e);
            let ok = ln > 1e-3 * le * dot(ca, ca).sqrt()
                && lnn > 0.1
                && dot(ne, ne).sqrt() > 0.3 * lnn * le;
            ok.then(|| BesideEdge {
                mesh: Mesh::from_slices(&[a, b, c], &[[0, 1, 2]]).unwrap(),
                n,
                d,
                off_plane: dot(n, normal).abs() / (lnn * ln),
            })
        })
}
