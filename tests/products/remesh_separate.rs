//! `products::remesh::separate_pinches`: solids that touch at a vertex or along an edge are
//! pulled apart by a fraction of a cell and kept, proved like any kept input, instead of being
//! remeshed; where an edge's wedges are one fan at each end (cavities touching along it), it is
//! split at its midpoint and pulled apart there.

use std::collections::HashSet;

use proptest::prelude::*;

use crate::common;
use crate::remesh_cut::{assert_same_solid, join, placed};
use crate::remesh_keep::cuboid;

use gwn::Mesh;
use gwn::products::remesh::keep_input::{InputCheck, NotKept, keep_input};
use gwn::products::remesh::separate_pinches::{
    LARGEST_MOVE_IN_CELLS, SeparatedCounts, split_at_midpoints,
};
use gwn::products::remesh::{RemeshOptions, Remeshed};

fn kept(mesh: &Mesh) -> Result<Remeshed, NotKept> {
    keep_input(
        mesh,
        mesh.bounding_box().unwrap(),
        &RemeshOptions::with_resolution(64),
    )
}

/// The input kept with its pinches pulled apart, checked: a valid surface with the input's
/// solid at random points, every vertex either an input position bit for bit or one of the
/// moved ones, each within the largest move of an input vertex (or of an edge's midpoint, for
/// edges pinched flat), and that move within its cap.
fn separated(mesh: &Mesh) -> (Remeshed, SeparatedCounts) {
    let out = kept(mesh).unwrap_or_else(|e| panic!("not kept: {e}"));
    let Some(InputCheck::Kept { separated, .. }) = out.stats.input else {
        panic!("not kept: {:?}", out.stats.input);
    };
    // The faces around a moved vertex sweep a sliver no thicker than its move.
    assert_same_solid(mesh, &out, 4000, 3, separated.largest_move);
    let finest = out.cell_sizes.into_iter().fold(f64::INFINITY, f64::min);
    assert!(separated.largest_move > 0.0);
    // Two passes where edges were split at their midpoints (a midpoint rounded to `f32` first
    // leaves its edge by far less than a pass's cap).
    let passes = if separated.midpoints > 0 { 2.0 } else { 1.0 };
    assert!(separated.largest_move <= passes * finest * LARGEST_MOVE_IN_CELLS * (1.0 + 1e-12));
    let bits = |p: &[f64; 3]| p.map(f64::to_bits);
    let input: HashSet<[u64; 3]> = mesh.positions().iter().map(bits).collect();
    let moved: Vec<&[f64; 3]> = out
        .positions
        .iter()
        .filter(|p| !input.contains(&bits(p)))
        .collect();
    assert_eq!(moved.len(), separated.vertices + separated.added_vertices);
    let midpoints = mesh.triangles().iter().flat_map(|t| {
        (0..3).map(|k| {
            let (a, b) = (
                mesh.positions()[t[k] as usize],
                mesh.positions()[t[(k + 1) % 3] as usize],
            );
            std::array::from_fn::<f64, 3, _>(|c| 0.5 * (a[c] + b[c]))
        })
    });
    let origins: Vec<[f64; 3]> = mesh.positions().iter().copied().chain(midpoints).collect();
    for p in moved {
        let nearest = origins
            .iter()
            .map(|q| (0..3).map(|k| (p[k] - q[k]).powi(2)).sum::<f64>().sqrt())
            .fold(f64::INFINITY, f64::min);
        assert!(nearest <= separated.largest_move, "{p:?} moved {nearest}");
    }
    (out, separated)
}

fn counts(s: SeparatedCounts) -> [usize; 3] {
    assert_eq!(s.midpoints, 0, "{s:?}");
    [s.edges, s.vertices, s.added_vertices]
}

#[test]
fn cubes_touching_at_a_corner_or_along_an_edge_are_pulled_apart() {
    let cube = common::unit_cube();
    let corner = join(&[cube.clone(), cube.translated([1.0, 1.0, 1.0])]);
    assert_eq!(counts(separated(&corner).1), [0, 1, 1]);
    let edge = join(&[cube.clone(), cube.translated([1.0, 1.0, 0.0])]);
    assert_eq!(counts(separated(&edge).1), [1, 2, 2]);
    // Four cubes in alternate octants around the origin: every two share a half-axis.
    let octant = |s: [f64; 3]| cuboid(s.map(|c| c.min(0.0)), s.map(|c| c.max(0.0)), false);
    let four = join(&[
        octant([1.0, 1.0, 1.0]),
        octant([-1.0, -1.0, 1.0]),
        octant([-1.0, 1.0, -1.0]),
        octant([1.0, -1.0, -1.0]),
    ]);
    assert_eq!(counts(separated(&four).1), [6, 7, 9]);
}

/// A block whose edge touches part of another's: the vertices of each inside the other's edge
/// are in no face of the other, so the contact is a self-intersection, and a degenerate one the
/// cut refuses. The faces along those edges split at them (`exact_repair::split_at_contacts`)
/// share the edge, and the pull takes it apart.
#[test]
fn a_block_touching_part_of_an_edge_is_split_there_then_pulled_apart() {
    let block = cuboid([0.0; 3], [2.0; 3], false);
    for (lo, hi, split) in [(0.5, 1.5, 2), (1.0, 3.0, 4)] {
        let small = cuboid([2.0, 2.0, lo], [3.0, 3.0, hi], false);
        let pair = join(&[block.clone(), small]);
        let (out, s) = separated(&pair);
        let Some(InputCheck::Kept { repairs, .. }) = out.stats.input else {
            unreachable!()
        };
        // The blocks' faces in the planes `x = 2` and `y = 2` also touch along the edge: the
        // faces of those planes replaced by their sum (`coplanar_overlaps`) put the same
        // vertices in the faces; without them, the split does.
        assert!(
            repairs.split_faces == split || repairs.coplanar.planes == 2,
            "{lo}..{hi}: {repairs:?}"
        );
        assert_eq!(counts(s), [1, 2, 2], "{lo}..{hi}");
    }
    // A tetrahedron's corner on the middle of the block's edge: the block's two faces there
    // split at it, and it becomes a vertex of both.
    let tip = Mesh::new(
        vec![
            [2.0, 2.0, 1.0],
            [3.0, 2.2, 0.5],
            [2.2, 3.0, 0.5],
            [2.6, 2.6, 1.8],
        ],
        vec![[0, 2, 1], [0, 1, 3], [0, 3, 2], [1, 2, 3]],
    )
    .unwrap();
    let tip = if kept(&tip).is_ok() {
        tip
    } else {
        tip.flipped()
    };
    let (out, s) = separated(&join(&[block, tip]));
    let Some(InputCheck::Kept { repairs, .. }) = out.stats.input else {
        unreachable!()
    };
    assert_eq!(repairs.split_faces, 2);
    assert_eq!(counts(s), [0, 1, 1]);
}

#[test]
fn cavities_touching_at_a_corner_or_along_an_edge_are_pulled_apart() {
    let solid = cuboid([-3.0; 3], [3.0; 3], false);
    let corner = join(&[
        solid.clone(),
        cuboid([-1.0; 3], [0.0; 3], true),
        cuboid([0.0; 3], [1.0; 3], true),
    ]);
    assert_eq!(counts(separated(&corner).1), [0, 1, 1]);
    // Along an edge, the solid wedges on both sides join the two cavities' faces into one fan
    // at each end: no vertex to split, so the edge is split at its midpoint, which has one fan
    // per wedge, and pulled apart there (the cavities become one, through a gap along the edge).
    for (lo, hi) in [(0.0, 1.0), (-2.0, 2.0)] {
        let edge = join(&[
            solid.clone(),
            cuboid([-1.0, -1.0, lo], [0.0, 0.0, hi], true),
            cuboid([0.0, 0.0, lo], [1.0, 1.0, hi], true),
        ]);
        let (out, s) = separated(&edge);
        assert_eq!(
            [s.edges, s.midpoints, s.vertices, s.added_vertices],
            [1, 1, 1, 1]
        );
        // The midpoint and its copy, each in its wedge: `x > 0 > y` or `x < 0 < y`.
        let middle = (lo + hi) / 2.0;
        let split: Vec<&[f64; 3]> = out.positions.iter().filter(|p| p[2] == middle).collect();
        assert_eq!(split.len(), 2, "{split:?}");
        assert!(split.iter().all(|p| p[0] * p[1] < 0.0), "{split:?}");
        assert!(split[0][0] * split[1][0] < 0.0, "{split:?}");
    }
}

/// A face with one, two or three of its edges in more than two faces is split at their
/// midpoints into pieces that tile it with its orientation (their area vectors add up to its
/// own, each a positive part of it: none degenerate, none turned), and every face on a split
/// edge is split the same way, so no edge runs past a midpoint.
#[test]
fn split_at_midpoints_tiles_each_face_with_its_orientation() {
    let positions = vec![
        [0.0, 0.0, 0.0],
        [4.0, 0.0, 0.0],
        [1.0, 3.0, 0.0],
        [2.0, -1.0, 1.0],
        [3.0, 2.0, 2.0],
        [0.0, 2.0, -2.0],
        [2.0, -1.0, -1.5],
        [3.0, 2.0, -1.0],
        [0.0, 2.0, 1.0],
    ];
    // Twice the area vector of face `t`, and vector helpers.
    let cross = |t: [u32; 3], p: &[[f64; 3]]| -> [f64; 3] {
        let [a, b, c] = t.map(|v| p[v as usize]);
        let (u, w): ([f64; 3], [f64; 3]) = (
            std::array::from_fn(|k| b[k] - a[k]),
            std::array::from_fn(|k| c[k] - a[k]),
        );
        [
            u[1] * w[2] - u[2] * w[1],
            u[2] * w[0] - u[0] * w[2],
            u[0] * w[1] - u[1] * w[0],
        ]
    };
    let dot = |a: [f64; 3], b: [f64; 3]| (0..3).map(|k| a[k] * b[k]).sum::<f64>();
    let length = |a: [f64; 3]| dot(a, a).sqrt();
    // Extra faces on edges (0, 1), (1, 2), (2, 0), two each (one each way, apexes apart):
    // crowded edges.
    let extra = [(0, 1, 3, 6), (1, 2, 4, 7), (2, 0, 5, 8)];
    for crowded in 1..=3usize {
        let mut triangles = vec![[0u32, 1, 2]];
        for &(a, b, c, d) in extra.iter().take(crowded) {
            triangles.extend([[a, b, c], [b, a, d]]);
        }
        let split = split_at_midpoints(&positions, &triangles).unwrap();
        assert_eq!(split.counts.midpoints, crowded);
        assert_eq!(split.positions.len(), positions.len() + crowded);
        let whole = cross([0, 1, 2], &positions);
        let pieces: Vec<[u32; 3]> = split
            .triangles
            .iter()
            .copied()
            .filter(|&t| {
                let c = cross(t, &split.positions);
                dot(c, whole) > (1.0 - 1e-12) * length(c) * length(whole)
            })
            .collect();
        assert_eq!(pieces.len(), 1 + crowded, "{:?}", split.triangles);
        let sum = pieces.iter().fold([0.0; 3], |s, &t| {
            let c = cross(t, &split.positions);
            std::array::from_fn(|k| s[k] + c[k])
        });
        let gap: [f64; 3] = std::array::from_fn(|k| sum[k] - whole[k]);
        assert!(length(gap) < 1e-12, "{sum:?} {whole:?}");
        assert!(
            pieces
                .iter()
                .all(|&t| length(cross(t, &split.positions)) > 1e-9)
        );
        // No face runs along a whole crowded edge past its midpoint: the most faces on an
        // edge is the three of each half of one.
        let mut edges: Vec<(u32, u32)> = split
            .triangles
            .iter()
            .flat_map(|t| (0..3).map(move |k| (t[k].min(t[(k + 1) % 3]), t[k].max(t[(k + 1) % 3]))))
            .collect();
        edges.sort_unstable();
        let most = edges
            .chunk_by(|x, y| x == y)
            .map(|g| g.len())
            .max()
            .unwrap();
        assert_eq!(most, 3, "each half of a crowded edge keeps its three faces");
        assert_eq!(split.triangles.len(), triangles.len() + 3 * crowded);
    }
    // Nothing crowded: nothing to split.
    assert!(split_at_midpoints(&positions, &[[0, 1, 2], [0, 2, 3]]).is_none());
}

#[test]
fn single_precision_inputs_stay_single_precision() {
    let tenth = f64::from(0.1f32);
    let cube = cuboid([0.0; 3], [tenth; 3], false);
    let pair = join(&[cube.clone(), cube.translated([tenth, tenth, tenth])]);
    assert!(
        pair.positions()
            .iter()
            .flatten()
            .all(|&x| f64::from(x as f32) == x)
    );
    let single = |p: &[[f64; 3]]| p.iter().flatten().all(|&x| f64::from(x as f32) == x);
    let (out, _) = separated(&pair);
    assert!(single(&out.positions));
    // Cavities touching along an edge whose midpoint is no `f32`: rounded to one, then pulled.
    let (a, b) = (f64::from(0.1f32), f64::from(0.7f32));
    assert_ne!(f64::from((0.5 * (a + b)) as f32), 0.5 * (a + b));
    let edge = join(&[
        cuboid([-1.0; 3], [1.0; 3], false),
        cuboid([-tenth, -tenth, a], [0.0, 0.0, b], true),
        cuboid([0.0, 0.0, a], [tenth, tenth, b], true),
    ]);
    assert!(single(edge.positions()));
    let (out, s) = separated(&edge);
    assert_eq!(s.midpoints, 1);
    assert!(single(&out.positions));
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(48))]

    /// A cube, an octahedron or a tetrahedron turned about the origin (its vertex there), in
    /// the octant opposite a cube's corner there: they touch at that point only, and are kept
    /// with one vertex split.
    #[test]
    fn turned_solids_touching_at_a_corner_are_kept(
        shape in 0usize..3,
        q in [-0.25f64..0.25, -0.25f64..0.25, -0.25f64..0.25],
        scale in 0.3f64..3.0,
    ) {
        let other = match shape {
            0 => cuboid([-scale; 3], [0.0; 3], false),
            1 => {
                // Its vertex on the x axis moved to the origin, pointing into x < 0.
                let p: Vec<[f64; 3]> = [[0.0, 0.0, 0.0], [-2.0, 0.0, 0.0], [-1.0, 0.5, 0.0],
                    [-1.0, -0.5, 0.0], [-1.0, 0.0, 0.5], [-1.0, 0.0, -0.5]]
                    .iter().map(|v: &[f64; 3]| v.map(|c| c * scale)).collect();
                Mesh::new(p, common::OCTAHEDRON_FACES.to_vec()).unwrap()
            }
            _ => {
                let s = scale;
                Mesh::new(
                    vec![[0.0; 3], [-s, -0.2 * s, -0.1 * s], [-0.3 * s, -s, -0.2 * s], [-0.2 * s, -0.3 * s, -s]],
                    vec![[0, 1, 2], [0, 2, 3], [0, 3, 1], [1, 3, 2]],
                ).unwrap()
            }
        };
        let turned = placed(&other, [1.0, q[0], q[1], q[2]], [0.0; 3]);
        let pair = join(&[common::unit_cube(), turned.clone()]);
        // The orientation of the shapes above, checked: each alone is kept as it is.
        prop_assert!(kept(&turned).is_ok());
        let (_, s) = separated(&pair);
        prop_assert_eq!(counts(s), [0, 1, 1]);
    }

    /// A box turned about the z axis, sharing the cube's edge there (or part of it), in the
    /// quadrant across: one edge separated, at both of its ends.
    #[test]
    fn boxes_sharing_an_edge_at_any_angle_are_kept(
        angle in -1.4f64..1.4,
        height in prop::sample::select(vec![0.5, 1.0, 1.5]),
        width in 0.3f64..2.0,
    ) {
        let across = cuboid([-width, -width, 0.0], [0.0, 0.0, height], false);
        let (s, c) = (0.5 * angle).sin_cos();
        let turned = placed(&across, [c, 0.0, 0.0, s], [0.0; 3]);
        // Points on the axis stay there exactly.
        prop_assert!(turned.positions().iter().any(|p| p[0] == 0.0 && p[1] == 0.0));
        let pair = join(&[common::unit_cube(), turned]);
        let (_, s) = separated(&pair);
        // Edges of different lengths share the origin only: its split pulls the shorter
        // edge's end, which lay on the longer edge, off it (the proof says whether it did).
        let expected = if height == 1.0 { [1, 2, 2] } else { [0, 1, 1] };
        prop_assert_eq!(counts(s), expected);
    }

    /// Two cavities touching along a whole edge (a unit cube and a box turned about the edge,
    /// in the quadrant across), in a solid, all of it turned and moved anywhere: the edge's
    /// wedges are one fan at each end, so it is split at its midpoint (off the edge's line by
    /// the rounding, once turned: the proof decides) and pulled apart there.
    #[test]
    fn cavities_touching_along_a_turned_edge_are_split_at_its_midpoint(
        angle in -1.4f64..1.4,
        width in 0.3f64..2.0,
        q in [-1.0f64..1.0, -1.0f64..1.0, -1.0f64..1.0, -1.0f64..1.0],
        offset in [-10.0f64..10.0, -10.0f64..10.0, -10.0f64..10.0],
    ) {
        prop_assume!(q.iter().map(|c| c * c).sum::<f64>() > 0.01);
        let across = cuboid([-width, -width, 0.0], [0.0, 0.0, 1.0], true);
        let (s, c) = (0.5 * angle).sin_cos();
        let across = placed(&across, [c, 0.0, 0.0, s], [0.0; 3]);
        let cavities = join(&[
            cuboid([-3.0; 3], [3.0; 3], false),
            cuboid([0.0; 3], [1.0; 3], true),
            across,
        ]);
        let turned = placed(&cavities, q, offset);
        let (_, s) = separated(&turned);
        prop_assert_eq!([s.edges, s.midpoints, s.vertices, s.added_vertices], [1, 1, 1, 1]);
    }
}

/// Pinched and crossing: two cubes sharing a corner, and a turned cube through one of them.
/// The corner is pulled apart first, then the crossing cut.
#[test]
fn a_pinch_is_pulled_apart_before_a_cut() {
    let centred = common::unit_cube().translated([-0.5; 3]);
    let turned = placed(
        &centred,
        [0.8813, 0.3377, 0.2291, 0.1517],
        [0.6113, 0.3529, 0.2071],
    );
    let touching = cuboid([-1.5; 3], [-0.5; 3], false);
    let input = join(&[centred, turned, touching]);
    let out = kept(&input).unwrap_or_else(|e| panic!("not kept: {e}"));
    let Some(InputCheck::Cut { separated, cut, .. }) = out.stats.input else {
        panic!("not cut: {:?}", out.stats.input);
    };
    assert_eq!(counts(separated), [0, 1, 1]);
    assert!(cut.intersecting_pairs > 0);
    assert_same_solid(&input, &out, 4000, 5, separated.largest_move);
}
