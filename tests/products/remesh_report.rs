//! `TopologyReport::of` against a plain recount (ordered maps, one triangle at a time) on
//! random triangle lists over a few vertices, which make every case the report names: boundary,
//! non-manifold and flipped edges, degenerate faces, pinched vertices, several components.

use gwn::products::remesh::report::TopologyReport;
use proptest::prelude::*;
use std::collections::{BTreeMap, BTreeSet};

/// The report recounted: every edge in an ordered map, every vertex's link walked from one
/// node.
fn recount(n: usize, triangles: &[[u32; 3]]) -> TopologyReport {
    // Undirected edge -> its triangles' directions (true: lower to higher vertex).
    let mut edges: BTreeMap<(u32, u32), Vec<bool>> = BTreeMap::new();
    let mut used = BTreeSet::new();
    for t in triangles {
        for k in 0..3 {
            let (a, b) = (t[k], t[(k + 1) % 3]);
            edges.entry((a.min(b), a.max(b))).or_default().push(a < b);
            used.insert(a);
        }
    }
    let with = |len: usize| edges.values().filter(|d| d.len() == len).count();
    let misoriented = edges
        .values()
        .filter(|d| d.len() == 2 && d[0] == d[1])
        .count();
    // Components: flood over the edges.
    let mut seen = BTreeSet::new();
    let mut components = 0;
    for &start in &used {
        if seen.insert(start) {
            components += 1;
            let mut stack = vec![start];
            while let Some(v) = stack.pop() {
                for &(a, b) in edges.keys() {
                    for (x, y) in [(a, b), (b, a)] {
                        if x == v && seen.insert(y) {
                            stack.push(y);
                        }
                    }
                }
            }
        }
    }
    // A vertex is manifold when the edges opposite it (one per corner it is) form one path or
    // one cycle: connected, no node of degree above 2.
    let nonmanifold_vertices = (0..n as u32)
        .filter(|&v| {
            let link: Vec<(u32, u32)> = triangles
                .iter()
                .flat_map(|t| {
                    (0..3)
                        .filter(move |&k| t[k] == v)
                        .map(move |k| (t[(k + 1) % 3], t[(k + 2) % 3]))
                })
                .collect();
            if link.is_empty() {
                return false;
            }
            let mut degree: BTreeMap<u32, usize> = BTreeMap::new();
            for &(a, b) in &link {
                *degree.entry(a).or_default() += 1;
                *degree.entry(b).or_default() += 1;
            }
            let first = *degree.keys().next().unwrap();
            let mut reached = BTreeSet::from([first]);
            let mut grew = true;
            while grew {
                grew = false;
                for &(a, b) in &link {
                    if reached.contains(&a) != reached.contains(&b) {
                        reached.insert(a);
                        reached.insert(b);
                        grew = true;
                    }
                }
            }
            reached.len() != degree.len() || degree.values().any(|&d| d > 2)
        })
        .count();
    let r = TopologyReport {
        vertices: used.len(),
        faces: triangles.len(),
        edges: edges.len(),
        boundary_edges: with(1),
        nonmanifold_edges: edges.values().filter(|d| d.len() > 2).count(),
        nonmanifold_vertices,
        misoriented_edges: misoriented,
        degenerate_faces: triangles
            .iter()
            .filter(|t| t[0] == t[1] || t[1] == t[2] || t[0] == t[2])
            .count(),
        components,
        euler_characteristic: used.len() as i64 - edges.len() as i64 + triangles.len() as i64,
        ..TopologyReport::default()
    };
    TopologyReport {
        closed: r.boundary_edges == 0,
        edge_manifold: r.nonmanifold_edges == 0,
        vertex_manifold: r.nonmanifold_vertices == 0,
        oriented: r.misoriented_edges == 0,
        ..r
    }
}

fn report(n: usize, triangles: &[[u32; 3]]) -> TopologyReport {
    TopologyReport::of(&vec![[0.0; 3]; n], triangles)
}

const TETRAHEDRON: [[u32; 3]; 4] = [[0, 2, 1], [0, 1, 3], [1, 2, 3], [0, 3, 2]];

#[test]
fn closed_forms() {
    let tet = report(4, &TETRAHEDRON);
    assert!(tet.closed && tet.edge_manifold && tet.vertex_manifold && tet.oriented);
    assert_eq!(
        (tet.euler_characteristic, tet.components, tet.edges),
        (2, 1, 6)
    );
    // Two tetrahedra sharing vertex 0: a pinched vertex, edges still manifold.
    let mut bowtie: Vec<[u32; 3]> = TETRAHEDRON.to_vec();
    bowtie.extend(
        TETRAHEDRON
            .iter()
            .map(|t| t.map(|v| if v == 0 { 0 } else { v + 3 })),
    );
    let b = report(7, &bowtie);
    assert_eq!(
        (b.nonmanifold_vertices, b.components, b.euler_characteristic),
        (1, 1, 3)
    );
    assert!(b.edge_manifold && b.closed && b.oriented);
    // One face flipped: its three edges are traversed the same way by both of their faces.
    let mut flipped = TETRAHEDRON;
    flipped[0].swap(1, 2);
    assert_eq!(report(4, &flipped).misoriented_edges, 3);
    // A fin: three triangles on one edge; and a degenerate face.
    let fin = report(5, &[[0, 1, 2], [1, 0, 3], [0, 1, 4], [2, 2, 3]]);
    assert_eq!((fin.nonmanifold_edges, fin.degenerate_faces), (1, 1));
    assert_eq!(report(3, &[]), recount(3, &[]));
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(2000))]

    #[test]
    fn report_matches_a_plain_recount(
        n in 1usize..8,
        raw in prop::collection::vec([0u32..8, 0u32..8, 0u32..8], 0..14),
    ) {
        let triangles: Vec<[u32; 3]> = raw.iter().map(|t| t.map(|v| v % n as u32)).collect();
        prop_assert_eq!(report(n, &triangles), recount(n, &triangles));
    }
}
