//! Degenerate meshes on small integer grids, and query sets that hit them exactly.
//!
//! Every generator reads its choices from a [`Source`], so each [`Kind`] is available as a seeded
//! function ([`Kind::generate`], e.g. [`polycube`]), as a byte decoder for cargo-fuzz/arbitrary
//! ([`Kind::from_bytes`], e.g. [`polycube_from_bytes`]) and, with the `testing` feature, as a
//! proptest strategy (`gwn::testing::strategies`). All coordinates are small dyadic rationals
//! (integers, halves, quarters, eighths), so they are exact in `f64`, `f32` (STL) and decimal text,
//! every degeneracy survives any exact pipeline, and the exact oracle
//! ([`super::oracle::exact_winding_number_rational`]) applies.
//!
//! The guarantee of each kind is stated on its variant and checked by `tests/exact/testing_kit.rs`
//! (with the measured frequency of each promised degeneracy).

use std::collections::HashMap;

use super::source::Source;
use crate::mesh::Mesh;

/// An axis-aligned box `(lo, hi)`.
pub type Aabb = ([f64; 3], [f64; 3]);

/// One generated test case.
#[derive(Clone, Debug, PartialEq)]
pub struct Case {
    /// The generator that produced it.
    pub kind: Kind,
    /// The mesh.
    pub mesh: Mesh,
    /// Query points: vertices, edge midpoints, face points, points in line with edges along the
    /// axes and points near the surface (all dyadic, exactly representable).
    pub queries: Vec<[f64; 3]>,
    /// Closed-form truth when non-empty ([`Kind::Boxes`], [`Kind::Polycube`],
    /// [`Kind::TJunction`]): the winding number at the perturbed query `q_ε` is the number of
    /// these boxes whose interior contains `q_ε`.
    pub boxes: Vec<Aabb>,
}

impl Case {
    /// The closed-form truth at `q_ε` from [`Case::boxes`]: the number of boxes containing the
    /// perturbed point `q + R·(ε1, ε2, ε3)` for the ray frame `ray` (`None` when the case has no
    /// boxes). On a box face the perturbation decides: the first frame axis that moves `q`
    /// strictly inside or outside.
    pub fn box_truth(&self, q: [f64; 3], ray: crate::kernel::frame::RayAxis) -> Option<u32> {
        if self.boxes.is_empty() {
            return None;
        }
        // Perturbation direction along each world axis: (frame axis order, sign). The first frame
        // axis dominates, so a coordinate on a face moves by the sign of its frame axis.
        let mut dir = [0.0f64; 3];
        for (axis, neg) in ray.map() {
            dir[axis] = if neg { -1.0 } else { 1.0 };
        }
        let inside = |lo: f64, hi: f64, x: f64, d: f64| {
            (lo < x && x < hi) || (x == lo && d > 0.0) || (x == hi && d < 0.0)
        };
        Some(
            self.boxes
                .iter()
                .filter(|(lo, hi)| (0..3).all(|k| inside(lo[k], hi[k], q[k], dir[k])))
                .count() as u32,
        )
    }
}

/// The generator families. Each variant documents what every case it produces guarantees.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum Kind {
    /// Triangle soup on the integer grid −4..=4: 3–8 vertices, 1–8 faces, each face plain,
    /// duplicated or duplicated flipped. Coincident vertices (distinct indices, same position),
    /// collinear and zero-area triangles, repeated indices, vertical (ray-parallel) faces,
    /// duplicated and flipped faces all occur often; no topological guarantee. Queries: vertices,
    /// edge midpoints, face points `(1/4, 1/2, 1/4)` and grid points. This is the byte decoder of
    /// the `kernel_grazing` fuzz corpus (its behaviour is frozen).
    Soup,
    /// Union of 1–3 axis-aligned boxes with integer corners in −4..=5 (the later ones within ±2
    /// of the first), each triangulated with 12 outward triangles and its own 8 vertices (corners
    /// shared by two boxes are coincident vertices). Closed (every edge balanced), consistently
    /// oriented, self-intersecting where boxes overlap: `w(q_ε)` = number of boxes containing
    /// `q_ε` ∈ {0, 1, 2, 3}.
    Boxes,
    /// Polycube: the boundary of a union of unit cubes in a 3×3×3 grid (coordinates −1..=2),
    /// shared faces removed, vertices welded. Closed, consistently oriented, `w(q_ε)` ∈ {0, 1}
    /// (1 iff `q_ε` is in an occupied cell); every face is parallel to two of the three axes
    /// (ray-parallel for four of the six rays); cubes touching along an edge or a corner only
    /// make non-manifold edges (4 faces) and vertices.
    Polycube,
    /// A polycube whose square faces are split at the midpoint of one side with probability 1/2,
    /// leaving T-junctions against the neighbouring face, and whose faces get their own
    /// (coincident, unwelded) vertices with probability 1/4. Geometrically closed and
    /// consistently oriented (the faces tile the boundary of the union), `w(q_ε)` ∈ {0, 1} off
    /// and on the surface, but the index boundary is non-empty: zero-area collinear loops along
    /// T-junctions and cancelling pairs along unwelded seams, whose terms cancel only up to
    /// rounding in floating point (the oracle merges coincident vertices, and returns a tight
    /// non-point interval around the integer for the T-junction loops).
    TJunction,
    /// A polycube with 1/8 of its triangles removed (at least one, never all): consistently
    /// oriented (every boundary edge has weight 1, or 2 at a non-manifold edge that lost both
    /// faces of one orientation), open: the signed boundary is non-empty and `w` takes
    /// fractional values.
    Open,
    /// A polycube with about 1/4 of its triangles flipped (at least one, never all): closed as an
    /// unoriented surface (every undirected edge used an even number of times), inconsistently
    /// oriented; the signed boundary has weight-2 edges unless the flipped set is a union of
    /// whole components.
    Inconsistent,
    /// Non-manifold fan ("book"): 3–6 triangles on one shared edge, each with a random
    /// orientation, apexes on the grid −3..=3 or (1/4 of the pages) on the edge's line: its
    /// midpoint or beyond its end (zero-area, collinear triangles), plus 0–2 triangles sharing only
    /// the edge's first vertex (a bow tie). Open; the shared edge is used by ≥ 3 triangles.
    Fan,
    /// 2–4 tetrahedra sharing one edge, corners on the grid −3..=3, each positively oriented or
    /// flat (zero volume). Closed, consistently oriented, self-intersecting where tetrahedra
    /// overlap; the shared edge is used by 2k ≥ 4 faces; `w(q_ε)` ∈ {0, …, k}.
    Tets,
}

impl Kind {
    /// Every kind.
    pub const ALL: [Kind; 8] = [
        Kind::Soup,
        Kind::Boxes,
        Kind::Polycube,
        Kind::TJunction,
        Kind::Open,
        Kind::Inconsistent,
        Kind::Fan,
        Kind::Tets,
    ];

    /// The name used by `gwn gen --kind`.
    pub fn name(self) -> &'static str {
        match self {
            Kind::Soup => "soup",
            Kind::Boxes => "boxes",
            Kind::Polycube => "polycube",
            Kind::TJunction => "t-junction",
            Kind::Open => "open",
            Kind::Inconsistent => "inconsistent",
            Kind::Fan => "fan",
            Kind::Tets => "tets",
        }
    }

    /// The kind called `name` ([`Kind::name`]).
    pub fn from_name(name: &str) -> Option<Kind> {
        Kind::ALL.into_iter().find(|k| k.name() == name)
    }

    /// Whether every case is closed with consistent orientation as an index mesh (empty signed
    /// boundary): the oracle then returns a point interval (an integer).
    pub fn is_closed(self) -> bool {
        matches!(self, Kind::Boxes | Kind::Polycube | Kind::Tets)
    }

    /// Whether every case is closed and consistently oriented *geometrically* (possibly with
    /// T-junctions): the winding number at `q_ε` is an integer for every query.
    pub fn is_geometrically_closed(self) -> bool {
        self.is_closed() || self == Kind::TJunction
    }

    /// The case for `seed` (SplitMix64; identical on every platform).
    pub fn generate(self, seed: u64) -> Case {
        self.from_source(&mut Source::from_seed(seed))
    }

    /// The case decoded from `bytes` (never fails; missing bytes read as zero). For cargo-fuzz
    /// targets and committed corpora.
    pub fn from_bytes(self, bytes: &[u8]) -> Case {
        self.from_source(&mut Source::from_bytes(bytes))
    }

    /// The case built from an arbitrary byte source.
    pub fn from_source(self, src: &mut Source<'_>) -> Case {
        match self {
            Kind::Soup => gen_soup(src),
            Kind::Boxes => gen_boxes(src),
            Kind::Polycube => gen_polycube(src, Variant::Plain),
            Kind::TJunction => gen_polycube(src, Variant::TJunction),
            Kind::Open => gen_polycube(src, Variant::Open),
            Kind::Inconsistent => gen_polycube(src, Variant::Inconsistent),
            Kind::Fan => gen_fan(src),
            Kind::Tets => gen_tets(src),
        }
    }
}

impl std::fmt::Display for Kind {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.name())
    }
}

macro_rules! front_ends {
    ($($kind:ident, $seeded:ident, $bytes:ident;)*) => {$(
        #[doc = concat!("The seeded [`Kind::", stringify!($kind), "`] case (see its guarantee).")]
        pub fn $seeded(seed: u64) -> Case {
            Kind::$kind.generate(seed)
        }
        #[doc = concat!("The [`Kind::", stringify!($kind), "`] case decoded from bytes (cargo-fuzz).")]
        pub fn $bytes(bytes: &[u8]) -> Case {
            Kind::$kind.from_bytes(bytes)
        }
    )*};
}

front_ends! {
    Soup, soup, soup_from_bytes;
    Boxes, boxes, boxes_from_bytes;
    Polycube, polycube, polycube_from_bytes;
    TJunction, t_junction, t_junction_from_bytes;
    Open, open, open_from_bytes;
    Inconsistent, inconsistent, inconsistent_from_bytes;
    Fan, fan, fan_from_bytes;
    Tets, tets, tets_from_bytes;
}

fn coord(b: u8) -> f64 {
    f64::from(b % 9) - 4.0
}

fn mesh(positions: Vec<[f64; 3]>, triangles: Vec<[u32; 3]>) -> Mesh {
    Mesh::new(positions, triangles).expect("generated meshes are valid by construction")
}

/// The `kernel_tiny_offsets` fuzz decoder: the first six bytes move every query of a
/// [`soup_from_bytes`] case (decoded from the rest) by `±2^-e`, `e` in `30..=1074`, along each
/// axis. Next to 0 that is as close to the grid's faces and edges as the subnormals get (edges on
/// coordinate planes are common on the grid −4..4); elsewhere the move rounds away. `None` for
/// fewer than six bytes.
pub fn soup_with_tiny_offsets_from_bytes(data: &[u8]) -> Option<Case> {
    if data.len() < 6 {
        return None;
    }
    let (moves, rest) = data.split_at(6);
    let offset = |k: usize| {
        let e = 30 + (i32::from(moves[k]) * 256 + i32::from(moves[(k + 3) % 6])) % 1045;
        // 2^-e in two exact steps (2^-1074 is below the normal range).
        let magnitude = 2f64.powi(-(e / 2)) * 2f64.powi(-(e - e / 2));
        if moves[k] & 1 == 0 {
            magnitude
        } else {
            -magnitude
        }
    };
    let mut case = soup_from_bytes(rest);
    for q in &mut case.queries {
        *q = std::array::from_fn(|k| q[k] + offset(k));
    }
    Some(case)
}

/// The `kernel_grazing` decoder, byte for byte (do not change: the fuzz corpus depends on it).
fn gen_soup(src: &mut Source<'_>) -> Case {
    let mut next = || src.byte();
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
    Case {
        kind: Kind::Soup,
        mesh: mesh(positions, triangles),
        queries,
        boxes: Vec::new(),
    }
}

/// Outward faces of a box with corner code `x | y<<1 | z<<2`, in the order −z, +z, −y, +y, −x, +x.
const BOX_FACES: [[usize; 4]; 6] = [
    [0, 2, 3, 1],
    [4, 5, 7, 6],
    [0, 1, 5, 4],
    [2, 6, 7, 3],
    [0, 4, 6, 2],
    [1, 3, 7, 5],
];
/// The outward direction of each of [`BOX_FACES`].
const FACE_DIRS: [[i32; 3]; 6] = [
    [0, 0, -1],
    [0, 0, 1],
    [0, -1, 0],
    [0, 1, 0],
    [-1, 0, 0],
    [1, 0, 0],
];

fn corner(lo: [f64; 3], hi: [f64; 3], c: usize) -> [f64; 3] {
    [
        if c & 1 == 0 { lo[0] } else { hi[0] },
        if c & 2 == 0 { lo[1] } else { hi[1] },
        if c & 4 == 0 { lo[2] } else { hi[2] },
    ]
}

/// Union of boxes (also used by the kernel's tests), followed by queries.
fn gen_boxes(src: &mut Source<'_>) -> Case {
    let n = 1 + (src.byte() % 3) as usize;
    let mut positions = Vec::new();
    let mut triangles = Vec::new();
    let mut bs = Vec::new();
    for i in 0..n {
        let mut lo = [coord(src.byte()), coord(src.byte()), coord(src.byte())];
        if i > 0 {
            // Near the first box, so that boxes overlap often: offset −2..=2 per axis.
            let first: [f64; 3] = bs.first().map_or([0.0; 3], |b: &Aabb| b.0);
            lo = std::array::from_fn(|k| (first[k] + (lo[k] + 4.0) % 5.0 - 2.0).clamp(-4.0, 4.0));
        }
        let hi: [f64; 3] =
            std::array::from_fn(|k| (lo[k] + 1.0 + f64::from(src.byte() % 4)).min(5.0));
        let base = positions.len() as u32;
        for c in 0..8 {
            positions.push(corner(lo, hi, c));
        }
        for f in BOX_FACES {
            let f = f.map(|c| base + c as u32);
            triangles.push([f[0], f[1], f[2]]);
            triangles.push([f[0], f[2], f[3]]);
        }
        bs.push((lo, hi));
    }
    let mesh = mesh(positions, triangles);
    let queries = queries(&mesh, src);
    Case {
        kind: Kind::Boxes,
        mesh,
        queries,
        boxes: bs,
    }
}

/// Welds vertices by exact position as they are added.
#[derive(Default)]
struct Builder {
    positions: Vec<[f64; 3]>,
    triangles: Vec<[u32; 3]>,
    index: HashMap<[u64; 3], u32>,
}

impl Builder {
    fn vertex(&mut self, p: [f64; 3]) -> u32 {
        let key = p.map(|c| (c + 0.0).to_bits());
        let n = self.positions.len() as u32;
        *self.index.entry(key).or_insert_with(|| {
            self.positions.push(p);
            n
        })
    }

    /// A vertex that is not welded (its own index even if the position repeats).
    fn fresh_vertex(&mut self, p: [f64; 3]) -> u32 {
        self.positions.push(p);
        (self.positions.len() - 1) as u32
    }
}

#[derive(Clone, Copy, PartialEq, Eq)]
enum Variant {
    Plain,
    TJunction,
    Open,
    Inconsistent,
}

fn gen_polycube(src: &mut Source<'_>, variant: Variant) -> Case {
    const N: i32 = 3;
    let mut occupied = [[[false; 3]; 3]; 3];
    let mut any = false;
    for plane in occupied.iter_mut() {
        for row in plane.iter_mut() {
            for cell in row.iter_mut() {
                *cell = src.byte() < 128;
                any |= *cell;
            }
        }
    }
    if !any {
        occupied[1][1][1] = true;
    }
    let occ = |c: [i32; 3]| {
        c.iter().all(|&v| (0..N).contains(&v))
            && occupied[c[0] as usize][c[1] as usize][c[2] as usize]
    };
    let mut b = Builder::default();
    let mut cells = Vec::new();
    for i in 0..N {
        for j in 0..N {
            for k in 0..N {
                if !occ([i, j, k]) {
                    continue;
                }
                let lo = [i, j, k].map(|v| f64::from(v - 1));
                let hi = lo.map(|v| v + 1.0);
                cells.push((lo, hi));
                for (f, d) in BOX_FACES.iter().zip(FACE_DIRS) {
                    if occ([i + d[0], j + d[1], k + d[2]]) {
                        continue;
                    }
                    let quad = f.map(|c| corner(lo, hi, c));
                    let choice = src.byte();
                    // T-junction cubes: 1/4 of the faces get their own (coincident) vertices.
                    let unwelded = variant == Variant::TJunction && src.byte() >= 192;
                    let vertex = |b: &mut Builder, p: [f64; 3]| {
                        if unwelded {
                            b.fresh_vertex(p)
                        } else {
                            b.vertex(p)
                        }
                    };
                    if variant == Variant::TJunction && choice & 1 == 1 {
                        // Split the side (s, s+1) at its midpoint: (s, m, s+3), (m, s+1, s+2),
                        // (m, s+2, s+3) tile the quad with the quad's orientation.
                        let s = usize::from(choice >> 1) % 4;
                        let c = |o: usize| quad[(s + o) % 4];
                        let (p0, p1) = (c(0), c(1));
                        let m: [f64; 3] = std::array::from_fn(|a| 0.5 * (p0[a] + p1[a]));
                        let [v0, v1, v2, v3] = [0, 1, 2, 3].map(|o| vertex(&mut b, c(o)));
                        let vm = vertex(&mut b, m);
                        b.triangles.push([v0, vm, v3]);
                        b.triangles.push([vm, v1, v2]);
                        b.triangles.push([vm, v2, v3]);
                    } else {
                        // Either diagonal.
                        let s = usize::from(choice >> 1) % 2;
                        let v = [0, 1, 2, 3].map(|o| vertex(&mut b, quad[(s + o) % 4]));
                        b.triangles.push([v[0], v[1], v[2]]);
                        b.triangles.push([v[0], v[2], v[3]]);
                    }
                }
            }
        }
    }
    let n = b.triangles.len();
    let mut truth = cells;
    let kind = match variant {
        Variant::Plain => Kind::Polycube,
        Variant::TJunction => Kind::TJunction,
        Variant::Open => {
            let keep: Vec<bool> = (0..n).map(|_| src.byte() < 224).collect();
            let mut tris: Vec<[u32; 3]> = (0..n)
                .filter(|&i| keep[i])
                .map(|i| b.triangles[i])
                .collect();
            if tris.len() == n {
                tris.remove(src.below(n));
            }
            if tris.is_empty() {
                tris.push(b.triangles[0]);
            }
            b.triangles = tris;
            truth.clear();
            Kind::Open
        }
        Variant::Inconsistent => {
            let mut flip: Vec<bool> = (0..n).map(|_| src.byte() >= 192).collect();
            if flip.iter().all(|&f| !f) {
                flip[src.below(n)] = true;
            }
            if flip.iter().all(|&f| f) {
                flip[src.below(n)] = false;
            }
            for (t, f) in b.triangles.iter_mut().zip(flip) {
                if f {
                    *t = [t[0], t[2], t[1]];
                }
            }
            truth.clear();
            Kind::Inconsistent
        }
    };
    let mesh = mesh(b.positions, b.triangles);
    let queries = queries(&mesh, src);
    Case {
        kind,
        mesh,
        queries,
        boxes: truth,
    }
}

/// A grid point in −3..=3.
fn point3(src: &mut Source<'_>) -> [f64; 3] {
    [0, 0, 0].map(|_: i32| src.below(7) as f64 - 3.0)
}

/// Two distinct grid points (the shared edge of fans and tetrahedra).
fn shared_edge(src: &mut Source<'_>) -> ([f64; 3], [f64; 3]) {
    let p = point3(src);
    let mut d = [0, 0, 0].map(|_: i32| src.below(5) as f64 - 2.0);
    if d == [0.0; 3] {
        d = [1.0, 0.0, 0.0];
    }
    (p, [p[0] + d[0], p[1] + d[1], p[2] + d[2]])
}

fn gen_fan(src: &mut Source<'_>) -> Case {
    let mut b = Builder::default();
    let (p, q) = shared_edge(src);
    let (vp, vq) = (b.vertex(p), b.vertex(q));
    let pages = 3 + src.below(4);
    for _ in 0..pages {
        let apex = match src.byte() % 8 {
            // On the line of the shared edge: a zero-area page.
            0 => std::array::from_fn(|k| 0.5 * (p[k] + q[k])),
            1 => std::array::from_fn(|k| 2.0 * q[k] - p[k]),
            _ => point3(src),
        };
        let a = b.vertex(apex);
        if src.byte() & 1 == 0 {
            b.triangles.push([vp, vq, a]);
        } else {
            b.triangles.push([vq, vp, a]);
        }
    }
    for _ in 0..src.below(3) {
        let (c, d) = (b.vertex(point3(src)), b.vertex(point3(src)));
        b.triangles.push([vp, c, d]);
    }
    let mesh = mesh(b.positions, b.triangles);
    let queries = queries(&mesh, src);
    Case {
        kind: Kind::Fan,
        mesh,
        queries,
        boxes: Vec::new(),
    }
}

fn orient3d(p: [[f64; 3]; 4]) -> f64 {
    // Exact for the small integers used here (products < 2^12).
    let d = |i: usize| [p[i][0] - p[0][0], p[i][1] - p[0][1], p[i][2] - p[0][2]];
    let (a, b, c) = (d(1), d(2), d(3));
    a[0] * (b[1] * c[2] - b[2] * c[1]) - a[1] * (b[0] * c[2] - b[2] * c[0])
        + a[2] * (b[0] * c[1] - b[1] * c[0])
}

fn gen_tets(src: &mut Source<'_>) -> Case {
    let mut b = Builder::default();
    let (p, q) = shared_edge(src);
    let (vp, vq) = (b.vertex(p), b.vertex(q));
    let k = 2 + src.below(3);
    for _ in 0..k {
        let (mut x, mut y) = (point3(src), point3(src));
        if orient3d([p, q, x, y]) < 0.0 {
            std::mem::swap(&mut x, &mut y);
        }
        // Own indices for the apexes, so each tetrahedron is closed by index even when an apex
        // coincides with another vertex.
        let (a, c) = (b.fresh_vertex(x), b.fresh_vertex(y));
        // Positively oriented (p, q, a, c): outward faces.
        b.triangles.push([vp, a, vq]);
        b.triangles.push([vp, vq, c]);
        b.triangles.push([vq, a, c]);
        b.triangles.push([a, vp, c]);
    }
    let mesh = mesh(b.positions, b.triangles);
    let queries = queries(&mesh, src);
    Case {
        kind: Kind::Tets,
        mesh,
        queries,
        boxes: Vec::new(),
    }
}

/// 8–15 queries that hit `mesh` exactly or graze it: vertices, edge midpoints, face points
/// `(1/4, 1/2, 1/4)`, points on an edge's line beyond its end, vertices and edge midpoints
/// shifted along one axis (so that the rays along that axis pass exactly through them), and
/// points at eighth-grid offsets from a vertex. All dyadic.
pub fn queries(mesh: &Mesh, src: &mut Source<'_>) -> Vec<[f64; 3]> {
    let n = 8 + src.below(8);
    let tris = mesh.triangles();
    let pos = mesh.positions();
    if tris.is_empty() {
        return vec![[0.0; 3]; n];
    }
    let mut out = Vec::with_capacity(n);
    for _ in 0..n {
        let t = tris[src.below(tris.len())].map(|i| pos[i as usize]);
        let r = src.below(3);
        let (a, b, c) = (t[r], t[(r + 1) % 3], t[(r + 2) % 3]);
        let mid: [f64; 3] = std::array::from_fn(|k| 0.5 * (a[k] + b[k]));
        let q = match src.below(6) {
            0 => a,
            1 => mid,
            2 => std::array::from_fn(|k| 0.25 * a[k] + 0.5 * b[k] + 0.25 * c[k]),
            // On the edge's line, beyond b.
            3 => std::array::from_fn(|k| 2.0 * b[k] - a[k]),
            // A vertex or an edge midpoint shifted along one axis by ±1..3.
            4 => {
                let mut p = if src.byte() & 1 == 0 { a } else { mid };
                let axis = src.below(3);
                let m = 1.0 + src.below(3) as f64;
                p[axis] += if src.byte() & 1 == 0 { m } else { -m };
                p
            }
            // Eighth-grid offsets from a vertex.
            _ => std::array::from_fn(|k| a[k] + (src.below(17) as f64 - 8.0) / 8.0),
        };
        out.push(q);
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn kinds_round_trip_their_names_and_are_deterministic() {
        for k in Kind::ALL {
            assert_eq!(Kind::from_name(k.name()), Some(k));
            assert_eq!(k.generate(3), k.generate(3));
            assert_eq!(k.from_bytes(&[1, 2, 3]), k.from_bytes(&[1, 2, 3]));
            let c = k.generate(11);
            assert!(!c.mesh.triangles().is_empty(), "{k}");
            assert!(!c.queries.is_empty());
        }
    }
}
