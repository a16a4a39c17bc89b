//! Marching tetrahedra on the Freudenthal (Kuhn) split of the band's finest cells.
//!
//! Every cube is cut into the six tetrahedra `0 → e_a → e_a + e_b → e_a + e_b + e_c` over the
//! permutations `(a, b, c)` of the axes. The split is the same in every cube, so the face
//! diagonals of neighbouring cubes match and the tetrahedra triangulate space. Give each lattice
//! corner its class (inside `w > ½`, outside) and the value `+1` / `−1`; the zero set of the
//! piecewise-linear interpolant is a closed 2-manifold (0 is a regular value: no vertex has value
//! 0), made of one triangle in a tetrahedron with one corner apart from the other three, and one
//! quadrilateral (two triangles, diagonal chosen inside the tetrahedron) in a tetrahedron with
//! two and two. There is no ambiguous case, and no rule to keep consistent between cells.
//!
//! Output vertices are identified by their lattice edge (inside corner, outside corner), so
//! neighbouring cells share them. Each triangle is oriented with exact integer arithmetic on the
//! edge midpoints: its normal points from the inside corner to the outside corner of its first
//! edge, so the surface faces outward everywhere.

use super::lattice::{Corner, KeyHash, Lattice, pack};
use super::octree::{Classified, offset};
use rayon::prelude::*;

/// The six tetrahedra of the Freudenthal split, as cube-corner bits (x: 1, y: 2, z: 4).
pub const FREUDENTHAL: [[usize; 4]; 6] = [
    [0, 1, 3, 7],
    [0, 1, 5, 7],
    [0, 2, 3, 7],
    [0, 2, 6, 7],
    [0, 4, 5, 7],
    [0, 4, 6, 7],
];

/// The extracted surface before vertex placement.
#[derive(Debug, Default)]
pub struct Band {
    /// One lattice edge per output vertex: (inside corner, outside corner).
    pub edges: Vec<(Corner, Corner)>,
    /// Triangles over `edges`, oriented outward.
    pub triangles: Vec<[u32; 3]>,
    /// Finest cells in the band.
    pub band_cells: usize,
    /// Triangles a dense marching cubes would give on the same corner classes
    /// ([`marching_cubes_triangles`] summed over the band: only band cells have any).
    pub marching_cubes_triangles: usize,
}

/// Extracts the separating surface of the band of `classified`: the regular cells'
/// Freudenthal split, and with sub-levels the refined cells' finer one and the transition
/// split between them ([`super::transition`]). `None` once `deadline` has passed (checked
/// between batches of cubes: the extraction of a large band is seconds of serial numbering).
pub fn extract(
    lattice: &Lattice,
    classified: &Classified,
    deadline: Option<std::time::Instant>,
) -> Option<Band> {
    let past = || deadline.is_some_and(|at| std::time::Instant::now() > at);
    let mut band = Band {
        band_cells: classified.band.len()
            + classified.fine_band.len()
            + classified.transition.len(),
        ..Band::default()
    };
    let mc_table = marching_cubes_table();
    // A dense marching cubes at the resolution: exact in the resolution's cells, estimated in
    // larger ones (which stay whole where the input is flat: its faces there grow with the
    // area, 4 per level), none for what only the finer levels see.
    let resolution = lattice.resolution_level();
    let marching_cubes = |level: u32, inside: [bool; 8]| -> usize {
        if level < resolution {
            return 0;
        }
        let case = (0..8).filter(|&b| inside[b]).fold(0, |c, b| c | (1 << b));
        usize::from(mc_table[case]) << (2 * (level - resolution))
    };
    // Output vertices numbered by first use, keyed by the packed corners (hashing two u64
    // costs a third of hashing six u32). A part arrives numbered by first use within itself
    // (`Part::of`, in parallel), so only its own vertices are looked up here, in their order
    // of first use: the vertices new to the surface get the numbers the serial first-use
    // numbering of every triangle would give them.
    let mut vertex_of: std::collections::HashMap<(u64, u64), u32, KeyHash> = Default::default();
    let mut number = |part: Part, band: &mut Band| {
        let global: Vec<u32> = part
            .keys
            .iter()
            .zip(&part.edges)
            .map(|(&key, &edge)| {
                *vertex_of.entry(key).or_insert_with(|| {
                    band.edges.push(edge);
                    (band.edges.len() - 1) as u32
                })
            })
            .collect();
        band.triangles
            .extend(part.triangles.iter().map(|t| t.map(|i| global[i as usize])));
    };
    // The cubes of one Freudenthal split (the regular band and the finer one): their eight
    // corners looked up once (not once per tetrahedron: 8 lookups instead of 32), in parallel
    // chunks whose triangles are numbered in the cubes' order, so the output does not depend
    // on the thread count; a batch of chunks at a time, so that the triangles waiting to be
    // numbered stay a small part of the surface.
    let cubes = |cells: &[(u32, Corner)], band: &mut Band, number: &mut dyn FnMut(_, &mut Band)| {
        for batch in cells.chunks(CUBES_PER_CHUNK * CHUNKS_PER_BATCH) {
            if past() {
                return None;
            }
            let parts: Vec<(Part, usize)> = batch
                .par_chunks(CUBES_PER_CHUNK)
                .map(|chunk| {
                    let mut triangles = Vec::new();
                    let mut marching = 0;
                    for &(level, m) in chunk {
                        let corners: [Corner; 8] =
                            std::array::from_fn(|b| offset(m, b, 1 << level));
                        let inside = corners.map(|c| classified.label(c));
                        marching += marching_cubes(level, inside);
                        for tet in FREUDENTHAL {
                            march(tet.map(|b| (corners[b], inside[b])), &mut triangles);
                        }
                    }
                    (Part::of(triangles), marching)
                })
                .collect();
            for (part, marching) in parts {
                band.marching_cubes_triangles += marching;
                number(part, band);
            }
        }
        Some(())
    };
    // The regular cells' edge is `1 << sub_levels` finest cells (`Lattice::regular_cell`).
    let regular = lattice.sub_levels;
    let regular_cells: Vec<(u32, Corner)> = classified.band.iter().map(|&m| (regular, m)).collect();
    cubes(&regular_cells, &mut band, &mut number)?;
    if past() {
        return None;
    }
    for &(level, m) in &classified.transition {
        let corners: [Corner; 8] = std::array::from_fn(|b| offset(m, b, 1 << level));
        band.marching_cubes_triangles +=
            marching_cubes(level, corners.map(|c| classified.label(c)));
        let refined = |c: Corner| classified.split.contains(&(level, pack(c)));
        let mut triangles = Vec::new();
        for tet in super::transition::tetrahedra(m, 1 << level, refined) {
            march(tet.map(|c| (c, classified.label(c))), &mut triangles);
        }
        number(Part::of(triangles), &mut band);
    }
    // The resolution's cells split below it count as in any band cell if their corners differ.
    for &m in &classified.refined {
        if classified.corners_mixed(resolution, m) {
            let corners: [Corner; 8] = std::array::from_fn(|b| offset(m, b, 1 << resolution));
            band.marching_cubes_triangles +=
                marching_cubes(resolution, corners.map(|c| classified.label(c)));
        }
    }
    cubes(&classified.fine_band, &mut band, &mut number)?;
    Some(band)
}

/// A triangle of the extracted surface as its three lattice edges (inside corner, outside
/// corner), before its vertices are numbered.
type EdgeTriangle = [(Corner, Corner); 3];

/// Triangles of one task of [`extract`] with their vertices numbered by first use within
/// them: the lattice edges and their packed keys in that order, and the triangles as indices
/// into them.
struct Part {
    keys: Vec<(u64, u64)>,
    edges: Vec<(Corner, Corner)>,
    triangles: Vec<[u32; 3]>,
}

impl Part {
    fn of(triangles: Vec<EdgeTriangle>) -> Part {
        let mut index: std::collections::HashMap<(u64, u64), u32, KeyHash> =
            std::collections::HashMap::with_capacity_and_hasher(
                triangles.len(),
                Default::default(),
            );
        let (mut keys, mut edges) = (Vec::new(), Vec::new());
        let triangles = triangles
            .into_iter()
            .map(|t| {
                t.map(|edge| {
                    let key = (pack(edge.0), pack(edge.1));
                    *index.entry(key).or_insert_with(|| {
                        keys.push(key);
                        edges.push(edge);
                        (keys.len() - 1) as u32
                    })
                })
            })
            .collect();
        Part {
            keys,
            edges,
            triangles,
        }
    }
}

/// Cubes per parallel task of [`extract`] (a few hundred microseconds of work each).
const CUBES_PER_CHUNK: usize = 1024;

/// Parallel tasks of [`extract`] whose triangles are numbered together.
const CHUNKS_PER_BATCH: usize = 16;

/// The outward triangles of the separating surface in the tetrahedron `v` (corners with their
/// class), as lattice edges (inside corner, outside corner): one where one corner is apart
/// from the other three, two (a quadrilateral) where two and two.
fn march(v: [(Corner, bool); 4], triangles: &mut Vec<EdgeTriangle>) {
    let mut in_idx = [0usize; 4];
    let mut out_idx = [0usize; 4];
    let (mut n_in, mut n_out) = (0, 0);
    for (i, &(_, inside)) in v.iter().enumerate() {
        if inside {
            in_idx[n_in] = i;
            n_in += 1;
        } else {
            out_idx[n_out] = i;
            n_out += 1;
        }
    }
    let quad;
    let tris: &[[(usize, usize); 3]] = match n_in {
        1 => {
            let i = in_idx[0];
            quad = [[(i, out_idx[0]), (i, out_idx[1]), (i, out_idx[2])]; 2];
            &quad[..1]
        }
        3 => {
            let o = out_idx[0];
            quad = [[(in_idx[0], o), (in_idx[1], o), (in_idx[2], o)]; 2];
            &quad[..1]
        }
        2 => {
            let (a, b) = (in_idx[0], in_idx[1]);
            let (c, d) = (out_idx[0], out_idx[1]);
            quad = [[(a, c), (a, d), (b, d)], [(a, c), (b, d), (b, c)]];
            &quad[..]
        }
        _ => return,
    };
    for tri in tris {
        let mut e = tri.map(|(i, o)| (v[i].0, v[o].0));
        if !outward(&e) {
            e.swap(1, 2);
        }
        triangles.push(e);
    }
}

/// Triangles of marching cubes in a cube whose inside corners are the set bits of `case`
/// (corner bits x: 1, y: 2, z: 4): the surface crosses the `k` edges whose corners differ and
/// is cut into polygons, one per cycle of the crossing points joined across the cube's faces,
/// and a polygon of `n` points is `n − 2` triangles, so the count is `k − 2·cycles`. A face with
/// four crossings (two diagonal inside corners: the ambiguous case) is resolved by separating
/// the inside corners. This is the count of the classic table (Lorensen & Cline) for every
/// unambiguous case; in the ambiguous ones any resolution gives `k − 2·cycles` for its own
/// cycles, and differs from this one by at most 2 triangles per cube.
pub fn marching_cubes_triangles(case: u8) -> u8 {
    let inside = |b: usize| case & (1 << b) != 0;
    // The 12 cube edges as corner pairs, and their index.
    let mut edges: Vec<(usize, usize)> = Vec::new();
    for a in 0..8usize {
        for bit in [1, 2, 4] {
            if a & bit == 0 {
                edges.push((a, a | bit));
            }
        }
    }
    let edge_index = |a: usize, b: usize| {
        edges
            .iter()
            .position(|&e| e == (a.min(b), a.max(b)))
            .unwrap_or(0)
    };
    let cut: Vec<bool> = edges.iter().map(|&(a, b)| inside(a) != inside(b)).collect();
    let mut parent: Vec<usize> = (0..12).collect();
    fn root(parent: &mut [usize], mut x: usize) -> usize {
        while parent[x] != x {
            x = parent[x];
        }
        x
    }
    let mut join = |a: usize, b: usize| {
        let (ra, rb) = (root(&mut parent, a), root(&mut parent, b));
        parent[ra] = rb;
    };
    for axis in [1usize, 2, 4] {
        let (p, q) = match axis {
            1 => (2, 4),
            2 => (4, 1),
            _ => (1, 2),
        };
        for side in [0, axis] {
            // The face's corners in cyclic order, and its edges e_i = (c_i, c_i+1).
            let c = [side, side | p, side | p | q, side | q];
            let e: [usize; 4] = std::array::from_fn(|i| edge_index(c[i], c[(i + 1) % 4]));
            let crossed: Vec<usize> = (0..4).filter(|&i| cut[e[i]]).collect();
            match crossed.len() {
                2 => join(e[crossed[0]], e[crossed[1]]),
                4 => {
                    // Separate the inside corners: pair the two edges around each of them.
                    for i in 0..4 {
                        if inside(c[i]) {
                            join(e[(i + 3) % 4], e[i]);
                        }
                    }
                }
                _ => {}
            }
        }
    }
    let k = cut.iter().filter(|&&x| x).count();
    let cycles = (0..12)
        .filter(|&i| cut[i] && root(&mut parent, i) == i)
        .count();
    (k - 2 * cycles) as u8
}

/// [`marching_cubes_triangles`] for every case.
pub fn marching_cubes_table() -> [u8; 256] {
    std::array::from_fn(|case| marching_cubes_triangles(case as u8))
}

/// Whether the triangle through the midpoints of `edges` (inside, outside corners) has its
/// normal pointing from the inside corner to the outside corner of `edges[0]` (exact: twice the
/// midpoints are integers; the product is nonzero because the midpoint plane of a tetrahedron
/// never holds a whole edge).
fn outward(edges: &EdgeTriangle) -> bool {
    let mid = |(i, o): (Corner, Corner)| -> [i64; 3] {
        [0, 1, 2].map(|a| i64::from(i[a]) + i64::from(o[a]))
    };
    let [p, q, r] = edges.map(mid);
    let u = [0, 1, 2].map(|a| q[a] - p[a]);
    let v = [0, 1, 2].map(|a| r[a] - p[a]);
    let n = [
        u[1] * v[2] - u[2] * v[1],
        u[2] * v[0] - u[0] * v[2],
        u[0] * v[1] - u[1] * v[0],
    ];
    let (i, o) = edges[0];
    let d = [0, 1, 2].map(|a| i64::from(o[a]) - i64::from(i[a]));
    n[0] * d[0] + n[1] * d[1] + n[2] * d[2] > 0
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn marching_cubes_counts_of_the_classic_cases() {
        let case = |corners: &[usize]| corners.iter().fold(0u8, |c, &b| c | (1 << b));
        // Nothing, one corner, an edge, a face, two corners across a face (ambiguous: two
        // triangles), across the cube, three corners of a face, a corner and its three
        // neighbours (a hexagon: four triangles).
        assert_eq!(marching_cubes_triangles(0), 0);
        assert_eq!(marching_cubes_triangles(0xff), 0);
        assert_eq!(marching_cubes_triangles(case(&[0])), 1);
        assert_eq!(marching_cubes_triangles(case(&[0, 1])), 2);
        assert_eq!(marching_cubes_triangles(case(&[0, 1, 2, 3])), 2);
        assert_eq!(marching_cubes_triangles(case(&[0, 3])), 2);
        assert_eq!(marching_cubes_triangles(case(&[0, 7])), 2);
        assert_eq!(marching_cubes_triangles(case(&[0, 1, 2])), 3);
        assert_eq!(marching_cubes_triangles(case(&[0, 1, 2, 4])), 4);
        let table = marching_cubes_table();
        // Every unambiguous case (no face with its inside corners on a diagonal) counts the
        // same as its complement; at most 5 triangles per cube, as in the classic table.
        let ambiguous = |c: u8| {
            [
                (0, 3, 1, 2),
                (4, 7, 5, 6),
                (0, 5, 1, 4),
                (2, 7, 3, 6),
                (0, 6, 2, 4),
                (1, 7, 3, 5),
            ]
            .iter()
            .any(|&(a, b, p, q)| {
                let i = |k: usize| c & (1 << k) != 0;
                i(a) == i(b) && i(p) == i(q) && i(a) != i(p)
            })
        };
        for c in 0..=255u8 {
            assert!(table[c as usize] <= 5, "{c:#010b}");
            if !ambiguous(c) {
                assert_eq!(table[c as usize], table[!c as usize], "{c:#010b}");
            }
        }
    }
}
