//! Per-point area estimation for oriented point clouds (Barill et al. 2018, Section 3.1): the
//! `k` nearest neighbours of each point (neighbours whose normal faces the opposite way
//! dropped), projected to the point's tangent plane, and the area of the point's 2D Voronoi cell
//! among them, obtained by clipping a square with one bisector half-plane per neighbour.

use rayon::prelude::*;

use super::soup::dist2;
use super::tree::{STACK, Tree, box_dist2};

/// Estimated area of every point (same order as the input), with `k` neighbours (Barill et al.
/// use `k = 20`).
///
/// - The projection plane is the tangent plane given by the point's own normal (the normals are
///   part of the input and define the orientation anyway).
/// - A cell left open by the neighbours (a point on the rim of an open scan) is closed by the
///   square of half-width equal to the distance to the farthest kept neighbour.
/// - Points at exactly the same position share one cell (its area is divided among them).
/// - A point with a zero normal, or without a usable neighbour, gets area 0.
pub fn estimate_areas(positions: &[[f64; 3]], normals: &[[f64; 3]], k: usize) -> Vec<f64> {
    assert_eq!(positions.len(), normals.len());
    if positions.is_empty() || k == 0 {
        return vec![0.0; positions.len()];
    }
    let boxes: Vec<_> = positions.iter().map(|&p| (p, p)).collect();
    let tree = Tree::build(positions, &boxes, 8);
    (0..positions.len())
        .into_par_iter()
        .map(|i| {
            let nbrs = k_nearest(&tree, positions, i, k);
            voronoi_area(positions, normals, i, &nbrs)
        })
        .collect()
}

/// The `k` nearest other points of point `i` (ids), nearest first.
pub(crate) fn k_nearest(tree: &Tree, positions: &[[f64; 3]], i: usize, k: usize) -> Vec<usize> {
    let q = positions[i];
    // Sorted by distance, at most k entries.
    let mut best: Vec<(f64, usize)> = Vec::with_capacity(k + 1);
    let mut stack = [0u32; STACK];
    let mut top = 1usize;
    while top > 0 {
        top -= 1;
        let node = &tree.nodes[stack[top] as usize];
        let worst = if best.len() == k {
            best[k - 1].0
        } else {
            f64::INFINITY
        };
        if box_dist2(q, node.min, node.max) > worst {
            continue;
        }
        if node.is_leaf() {
            for &e in &tree.order[node.range()] {
                let e = e as usize;
                if e == i {
                    continue;
                }
                let d = dist2(positions[e], q);
                if best.len() == k && d >= best[k - 1].0 {
                    continue;
                }
                let at = best.partition_point(|&(bd, _)| bd <= d);
                best.insert(at, (d, e));
                best.truncate(k);
            }
        } else {
            let (l, r) = (node.left, node.left + 1);
            let dl = {
                let n = &tree.nodes[l as usize];
                box_dist2(q, n.min, n.max)
            };
            let dr = {
                let n = &tree.nodes[r as usize];
                box_dist2(q, n.min, n.max)
            };
            // Visit the nearer child first (pushed last).
            let (near, far) = if dl <= dr { (l, r) } else { (r, l) };
            stack[top] = far;
            stack[top + 1] = near;
            top += 2;
        }
    }
    best.into_iter().map(|(_, e)| e).collect()
}

/// Area of the Voronoi cell of point `i` among `nbrs`, in the tangent plane of its normal.
pub(crate) fn voronoi_area(
    positions: &[[f64; 3]],
    normals: &[[f64; 3]],
    i: usize,
    nbrs: &[usize],
) -> f64 {
    let n = normals[i];
    if n == [0.0; 3] {
        return 0.0;
    }
    let (u, v) = tangent_basis(n);
    let p = positions[i];
    let mut sites: Vec<[f64; 2]> = Vec::with_capacity(nbrs.len());
    let mut duplicates = 0usize;
    for &j in nbrs {
        // Opposite-facing neighbours belong to another sheet of the surface.
        let nj = normals[j];
        if n[0] * nj[0] + n[1] * nj[1] + n[2] * nj[2] < 0.0 {
            continue;
        }
        let d = [
            positions[j][0] - p[0],
            positions[j][1] - p[1],
            positions[j][2] - p[2],
        ];
        if d == [0.0; 3] {
            duplicates += 1;
            continue;
        }
        let s = [
            d[0] * u[0] + d[1] * u[1] + d[2] * u[2],
            d[0] * v[0] + d[1] * v[1] + d[2] * v[2],
        ];
        if s[0] * s[0] + s[1] * s[1] > 0.0 {
            sites.push(s);
        }
    }
    let half = sites
        .iter()
        .map(|s| (s[0] * s[0] + s[1] * s[1]).sqrt())
        .fold(0.0_f64, f64::max);
    if half == 0.0 {
        return 0.0;
    }
    let mut cell = vec![[-half, -half], [half, -half], [half, half], [-half, half]];
    for s in &sites {
        // Points closer to the origin than to s: x·s ≤ |s|²/2.
        let h = 0.5 * (s[0] * s[0] + s[1] * s[1]);
        cell = clip_half_plane(&cell, *s, h);
        if cell.len() < 3 {
            return 0.0;
        }
    }
    polygon_area(&cell) / (1 + duplicates) as f64
}

/// Sutherland–Hodgman clipping of a convex polygon against `{x : x·s ≤ h}`.
pub(crate) fn clip_half_plane(poly: &[[f64; 2]], s: [f64; 2], h: f64) -> Vec<[f64; 2]> {
    let f = |p: [f64; 2]| p[0] * s[0] + p[1] * s[1] - h;
    let mut out = Vec::with_capacity(poly.len() + 1);
    for (idx, &a) in poly.iter().enumerate() {
        let b = poly[(idx + 1) % poly.len()];
        let (fa, fb) = (f(a), f(b));
        if fa <= 0.0 {
            out.push(a);
        }
        if (fa < 0.0 && fb > 0.0) || (fa > 0.0 && fb < 0.0) {
            let t = fa / (fa - fb);
            out.push([a[0] + t * (b[0] - a[0]), a[1] + t * (b[1] - a[1])]);
        }
    }
    out
}

/// Shoelace area (counter-clockwise positive; the clipped square stays counter-clockwise).
pub(crate) fn polygon_area(poly: &[[f64; 2]]) -> f64 {
    let mut twice = 0.0;
    for (idx, &a) in poly.iter().enumerate() {
        let b = poly[(idx + 1) % poly.len()];
        twice += a[0] * b[1] - a[1] * b[0];
    }
    0.5 * twice
}

/// Two unit vectors spanning the plane orthogonal to the unit vector `n`.
fn tangent_basis(n: [f64; 3]) -> ([f64; 3], [f64; 3]) {
    // Cross with the coordinate axis least aligned with n.
    let a = if n[0].abs() <= n[1].abs() && n[0].abs() <= n[2].abs() {
        [1.0, 0.0, 0.0]
    } else if n[1].abs() <= n[2].abs() {
        [0.0, 1.0, 0.0]
    } else {
        [0.0, 0.0, 1.0]
    };
    let u = crate::base::vec3::cross(n, a);
    let l = (u[0] * u[0] + u[1] * u[1] + u[2] * u[2]).sqrt();
    let u = u.map(|x| x / l);
    let v = crate::base::vec3::cross(n, u);
    (u, v)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn clipping_a_square_by_a_diagonal_halves_it() {
        let sq = vec![[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]];
        let c = clip_half_plane(&sq, [1.0, 1.0], 1.0);
        assert!((polygon_area(&c) - 0.5).abs() < 1e-15);
        assert!((polygon_area(&clip_half_plane(&sq, [1.0, 0.0], 5.0)) - 1.0).abs() < 1e-15);
        assert!(clip_half_plane(&sq, [1.0, 0.0], -1.0).is_empty());
    }

    #[test]
    fn knn_matches_brute_force() {
        let pts: Vec<[f64; 3]> = (0..700)
            .map(|i| {
                let t = f64::from(i);
                [(t * 0.731).sin(), (t * 0.377).cos(), (t * 0.0917).sin()]
            })
            .collect();
        let boxes: Vec<_> = pts.iter().map(|&p| (p, p)).collect();
        let tree = Tree::build(&pts, &boxes, 8);
        for i in [0, 17, 350, 699] {
            let got = k_nearest(&tree, &pts, i, 20);
            let mut all: Vec<(f64, usize)> = (0..pts.len())
                .filter(|&j| j != i)
                .map(|j| (dist2(pts[j], pts[i]), j))
                .collect();
            all.sort_by(|a, b| a.0.total_cmp(&b.0));
            let want: Vec<f64> = all[..20].iter().map(|x| x.0).collect();
            let got_d: Vec<f64> = got.iter().map(|&j| dist2(pts[j], pts[i])).collect();
            assert_eq!(got_d, want);
        }
    }

    #[test]
    fn planar_grid_cells_have_the_grid_area() {
        // A 21×21 grid with spacing h in z = 0: interior cells are h×h squares.
        let h = 0.1;
        let mut pts = Vec::new();
        for i in 0..21 {
            for j in 0..21 {
                pts.push([f64::from(i) * h, f64::from(j) * h, 0.0]);
            }
        }
        let normals = vec![[0.0, 0.0, 1.0]; pts.len()];
        let areas = estimate_areas(&pts, &normals, 20);
        for i in 3..18 {
            for j in 3..18 {
                let a = areas[i * 21 + j];
                assert!((a - h * h).abs() < 1e-12, "cell ({i},{j}): {a}");
            }
        }
        // Opposite-facing neighbours are ignored: a second sheet just below changes nothing.
        let mut two = pts.clone();
        two.extend(pts.iter().map(|p| [p[0] + 0.5 * h, p[1] + 0.5 * h, -1e-3]));
        let mut n2 = normals.clone();
        n2.extend(std::iter::repeat_n([0.0, 0.0, -1.0], pts.len()));
        let areas2 = estimate_areas(&two, &n2, 20);
        let a = areas2[10 * 21 + 10];
        assert!((a - h * h).abs() < 1e-12, "{a}");
    }
}
