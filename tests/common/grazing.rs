//! Degenerate meshes on a small integer grid, decoded from bytes so that proptest, the cargo-fuzz
//! target and the corpus replay share one generator. Coordinates lie in −4..=4, so coincident
//! vertices, collinear and vertical triangles, duplicated and flipped faces are certain to occur.
#![allow(dead_code)]

use gwn::Mesh;

/// A decoded case: a mesh, queries on grid points and on dyadic points of edges and faces.
#[derive(Clone, Debug)]
pub struct Case {
    pub mesh: Mesh,
    pub queries: Vec<[f64; 3]>,
}

fn coord(b: u8) -> f64 {
    f64::from(b % 9) - 4.0
}

/// Decodes bytes into a case. Never fails: missing bytes read as zero.
pub fn decode(bytes: &[u8]) -> Case {
    let mut it = bytes.iter().copied().chain(std::iter::repeat(0));
    let mut next = || it.next().unwrap_or(0);
    let nv = 3 + (next() % 6) as usize;
    let positions: Vec<[f64; 3]> = (0..nv)
        .map(|_| [coord(next()), coord(next()), coord(next())])
        .collect();
    let nf = 1 + (next() % 8) as usize;
    let mut triangles = Vec::new();
    for _ in 0..nf {
        let t = [
            next() as u32 % nv as u32,
            next() as u32 % nv as u32,
            next() as u32 % nv as u32,
        ];
        match next() % 4 {
            // duplicate, flipped duplicate, or plain
            0 => {
                triangles.push(t);
                triangles.push(t);
            }
            1 => {
                triangles.push(t);
                triangles.push([t[0], t[2], t[1]]);
            }
            _ => triangles.push(t),
        }
    }
    let mesh = Mesh::new(positions.clone(), triangles.clone()).unwrap();
    let nq = 1 + (next() % 6) as usize;
    let mut queries = Vec::new();
    for _ in 0..nq {
        let kind = next() % 4;
        let q = match kind {
            // a vertex
            0 => positions[next() as usize % nv],
            // an edge midpoint (half-integers: exact on the grid)
            1 => {
                let t = triangles[next() as usize % triangles.len()];
                let (a, b) = (positions[t[0] as usize], positions[t[1] as usize]);
                std::array::from_fn(|k| 0.5 * (a[k] + b[k]))
            }
            // a point inside a face, barycentric (1/4, 1/2, 1/4)
            2 => {
                let t = triangles[next() as usize % triangles.len()];
                let p = t.map(|i| positions[i as usize]);
                std::array::from_fn(|k| 0.25 * p[0][k] + 0.5 * p[1][k] + 0.25 * p[2][k])
            }
            // any grid point (in line with edges along the axes, often)
            _ => [coord(next()), coord(next()), coord(next())],
        };
        queries.push(q);
    }
    Case { mesh, queries }
}

/// Exactly: does `q` (dyadic, small) lie on a triangle of `mesh` (closed triangle, including
/// degenerate ones)? Scaled by 4 to integers, then exact integer predicates.
pub fn on_surface(mesh: &Mesh, q: [f64; 3]) -> bool {
    let s = |v: f64| (v * 4.0) as i64;
    let qi = q.map(s);
    mesh.triangles().iter().any(|t| {
        let p = t.map(|i| mesh.positions()[i as usize].map(s));
        point_on_triangle(qi, p)
    })
}

fn sub(a: [i64; 3], b: [i64; 3]) -> [i64; 3] {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}
fn cross(a: [i64; 3], b: [i64; 3]) -> [i64; 3] {
    [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ]
}
fn dot(a: [i64; 3], b: [i64; 3]) -> i64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

fn on_segment(q: [i64; 3], a: [i64; 3], b: [i64; 3]) -> bool {
    let (ab, aq) = (sub(b, a), sub(q, a));
    cross(ab, aq) == [0; 3] && dot(aq, ab) >= 0 && dot(aq, ab) <= dot(ab, ab)
}

fn point_on_triangle(q: [i64; 3], p: [[i64; 3]; 3]) -> bool {
    let n = cross(sub(p[1], p[0]), sub(p[2], p[0]));
    if n == [0; 3] {
        return on_segment(q, p[0], p[1]) || on_segment(q, p[1], p[2]) || on_segment(q, p[2], p[0]);
    }
    if dot(sub(q, p[0]), n) != 0 {
        return false;
    }
    (0..3).all(|i| dot(cross(sub(p[(i + 1) % 3], p[i]), sub(q, p[i])), n) >= 0)
}

/// Union of axis-aligned boxes with integer corners (closed, outward, self-intersecting where they
/// overlap): the exact winding number is the number of boxes containing the point.
pub fn boxes(bytes: &[u8]) -> (Mesh, Vec<([f64; 3], [f64; 3])>) {
    let mut it = bytes.iter().copied().chain(std::iter::repeat(0));
    let mut next = || it.next().unwrap_or(0);
    let n = 1 + (next() % 3) as usize;
    let mut positions = Vec::new();
    let mut triangles = Vec::new();
    let mut bs = Vec::new();
    for _ in 0..n {
        let lo = [coord(next()), coord(next()), coord(next())];
        let hi: [f64; 3] = std::array::from_fn(|k| (lo[k] + 1.0 + f64::from(next() % 4)).min(5.0));
        let base = positions.len() as u32;
        for c in 0..8 {
            positions.push([
                if c & 1 == 0 { lo[0] } else { hi[0] },
                if c & 2 == 0 { lo[1] } else { hi[1] },
                if c & 4 == 0 { lo[2] } else { hi[2] },
            ]);
        }
        // Outward faces of the box with corner code (x | y<<1 | z<<2).
        for f in [
            [0, 2, 3, 1],
            [4, 5, 7, 6],
            [0, 1, 5, 4],
            [2, 6, 7, 3],
            [0, 4, 6, 2],
            [1, 3, 7, 5],
        ] {
            triangles.push([base + f[0], base + f[1], base + f[2]]);
            triangles.push([base + f[0], base + f[2], base + f[3]]);
        }
        bs.push((lo, hi));
    }
    (Mesh::new(positions, triangles).unwrap(), bs)
}
