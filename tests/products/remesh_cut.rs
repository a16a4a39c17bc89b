//! `products::remesh::cut_intersections`: a closed input whose shells overlap is cut along its
//! self-intersections into the boundary of its `w > ½` solid (their union, or a solid minus a
//! cavity), proved exactly, instead of being remeshed.

use proptest::prelude::*;

use crate::common::{self, Rng};
use crate::remesh::sphere;
use crate::remesh_keep::assert_valid;

use gwn::Mesh;
use gwn::eval::antipodal::WindingNumber;
use gwn::products::remesh::cut_intersections::{NotCut, cut_intersections};
use gwn::products::remesh::keep_input::{InputCheck, NotKept, keep_input};
use gwn::products::remesh::simplify::point_triangle_distance2;
use gwn::products::remesh::{RemeshOptions, Remeshed};

fn kept(mesh: &Mesh) -> Result<Remeshed, NotKept> {
    keep_input(
        mesh,
        mesh.bounding_box().unwrap(),
        &RemeshOptions::with_resolution(64),
    )
}

pub(crate) fn join(parts: &[Mesh]) -> Mesh {
    parts[1..]
        .iter()
        .fold(parts[0].clone(), |m, p| m.concatenated(p).unwrap())
}

/// `mesh` turned by the rotation of unit quaternion `(w, x, y, z)` (normalised here) about the
/// origin, then moved by `offset`.
pub(crate) fn placed(mesh: &Mesh, q: [f64; 4], offset: [f64; 3]) -> Mesh {
    let n = q.iter().map(|c| c * c).sum::<f64>().sqrt();
    let [w, x, y, z] = q.map(|c| c / n);
    let r = [
        [
            1.0 - 2.0 * (y * y + z * z),
            2.0 * (x * y - w * z),
            2.0 * (x * z + w * y),
        ],
        [
            2.0 * (x * y + w * z),
            1.0 - 2.0 * (x * x + z * z),
            2.0 * (y * z - w * x),
        ],
        [
            2.0 * (x * z - w * y),
            2.0 * (y * z + w * x),
            1.0 - 2.0 * (x * x + y * y),
        ],
    ];
    let p = mesh
        .positions()
        .iter()
        .map(|p| std::array::from_fn(|i| (0..3).map(|j| r[i][j] * p[j]).sum::<f64>() + offset[i]))
        .collect();
    Mesh::new(p, mesh.triangles().to_vec()).unwrap()
}

/// A cube of side 1 centred at the origin.
fn centred_cube() -> Mesh {
    common::unit_cube().translated([-0.5; 3])
}

/// A regular tetrahedron around the origin, outward, with circumradius `r`.
fn tetrahedron(r: f64) -> Mesh {
    let s = r / 3f64.sqrt();
    Mesh::new(
        vec![[s, s, s], [s, -s, -s], [-s, s, -s], [-s, -s, s]],
        vec![[0, 1, 2], [0, 3, 1], [0, 2, 3], [1, 3, 2]],
    )
    .unwrap()
}

/// An octahedron with vertices at distance `r` on the axes, outward.
fn octahedron(r: f64) -> Mesh {
    let p = vec![
        [r, 0.0, 0.0],
        [-r, 0.0, 0.0],
        [0.0, r, 0.0],
        [0.0, -r, 0.0],
        [0.0, 0.0, r],
        [0.0, 0.0, -r],
    ];
    Mesh::new(p, gwn::testing::OCTAHEDRON_FACES.to_vec()).unwrap()
}

/// The input cut, with its counts; panics with the reason otherwise.
fn cut(
    mesh: &Mesh,
) -> (
    Remeshed,
    gwn::products::remesh::cut_intersections::CutCounts,
) {
    let out = match kept(mesh) {
        Ok(out) => out,
        Err(e) => panic!("not cut: {e}"),
    };
    let Some(InputCheck::Cut { cut, .. }) = out.stats.input else {
        panic!("not cut: {:?}", out.stats.input);
    };
    (out, cut)
}

/// Closed, manifold, oriented, without self-intersections on its `f64` vertices, and with
/// `w > ½` where the input has it at `samples` random points of the input's box.
/// Points within `skip_within` of the input's surface are not compared (where a separation
/// moved it).
pub(crate) fn assert_same_solid(
    input: &Mesh,
    out: &Remeshed,
    samples: usize,
    seed: u64,
    skip_within: f64,
) {
    assert_valid(out);
    let output = Mesh::from_slices(&out.positions, &out.triangles).unwrap();
    let (w_in, w_out) = (
        WindingNumber::new(input).unwrap(),
        WindingNumber::new(&output).unwrap(),
    );
    let b = input.bounding_box().unwrap();
    let mut rng = Rng(seed);
    let mut inside = 0;
    for _ in 0..samples {
        // The output differs from the input's solid only within rounding of the intersection
        // curves: a random point is never there.
        let q: [f64; 3] = std::array::from_fn(|k| rng.range(b.min[k], b.max[k]));
        if skip_within > 0.0 && distance_to_surface(input, q) <= skip_within {
            continue;
        }
        let (a, o) = (w_in.eval(q), w_out.eval(q));
        assert_eq!(a > 0.5, o > 0.5, "at {q:?}: input w {a}, output w {o}");
        assert!(o == 0.0 || o == 1.0, "output w {o} at {q:?}");
        inside += usize::from(a > 0.5);
    }
    assert!(inside > 0, "no sample inside the solid");
}

/// The distance from `q` to the nearest face of `mesh`.
pub(crate) fn distance_to_surface(mesh: &Mesh, q: [f64; 3]) -> f64 {
    let p = mesh.positions();
    mesh.triangles()
        .iter()
        .map(|t| point_triangle_distance2(q, &t.map(|v| p[v as usize])))
        .fold(f64::INFINITY, f64::min)
        .sqrt()
}

#[test]
fn overlapping_shells_are_cut_into_their_union() {
    // A cube and a turned copy pushed into it: every piercing in general position.
    let turned = placed(
        &centred_cube(),
        [0.8813, 0.3377, 0.2291, 0.1517],
        [0.6113, 0.3529, 0.2071],
    );
    let two_cubes = join(&[centred_cube(), turned]);
    let (out, counts) = cut(&two_cubes);
    assert_same_solid(&two_cubes, &out, 4000, 1, 0.0);
    assert!(counts.intersecting_pairs > 0 && counts.new_vertices > 0);
    // Faces no other face meets are written as they were.
    let Some(InputCheck::Cut { uncut_faces, .. }) = out.stats.input else {
        unreachable!()
    };
    assert!(uncut_faces > 0);
    let input_faces: std::collections::HashSet<[[u64; 3]; 3]> = (0..two_cubes.triangles().len())
        .map(|f| two_cubes.triangle_positions(f).map(|p| p.map(f64::to_bits)))
        .collect();
    let verbatim = out
        .triangles
        .iter()
        .filter(|t| input_faces.contains(&t.map(|v| out.positions[v as usize].map(f64::to_bits))))
        .count();
    assert_eq!(verbatim, uncut_faces);

    // A tetrahedron poking one corner through a cube's face: the corner inside the cube and the
    // part of the face inside the tetrahedron are patches made only of pieces of cut faces,
    // which take their values across the intersection curve.
    let tip = placed(
        &tetrahedron(0.5),
        [0.7919, -0.2143, 0.5087, 0.2963],
        [0.0; 3],
    );
    let top = tip
        .positions()
        .iter()
        .map(|p| p[2])
        .fold(f64::MIN, f64::max);
    let poking = join(&[
        centred_cube(),
        tip.translated([0.0531, -0.0327, -0.5 - top + 0.1093]),
    ]);
    let (out, counts) = cut(&poking);
    assert_same_solid(&poking, &out, 4000, 2, 0.0);
    assert!(counts.removed_faces > 0);

    // A ball overlapping a cavity's wall: the solid minus the cavity.
    let carved = join(&[
        sphere([0.0; 3], 1.0, 10, false),
        placed(
            &sphere([0.0; 3], 0.5, 8, true),
            [0.9087, 0.2213, 0.1171, 0.2939],
            [0.8123, 0.1037, -0.0519],
        ),
    ]);
    let (out, _) = cut(&carved);
    assert_same_solid(&carved, &out, 4000, 4, 0.0);
}

/// Two cubes offset along their diagonal by half a side: each edge of one that pierces the
/// other does so at a face's centre, on its diagonal. The crossing point is a vertex of the
/// four faces through the two edges, found the same from each pair.
#[test]
fn edges_crossing_edges_are_cut_there() {
    let cube = centred_cube();
    let diagonal = join(&[cube.clone(), cube.translated([0.5, 0.5, 0.5])]);
    let (out, counts) = cut(&diagonal);
    assert_same_solid(&diagonal, &out, 4000, 3, 0.0);
    // The six face centres where an edge crosses a diagonal are among the new vertices.
    let centres = [
        [0.5, 0.0, 0.0],
        [0.0, 0.5, 0.0],
        [0.0, 0.0, 0.5],
        [0.5, 0.5, 0.0],
        [0.5, 0.0, 0.5],
        [0.0, 0.5, 0.5],
    ];
    for c in centres {
        assert!(out.positions.contains(&c), "{c:?} not a vertex: {counts:?}");
    }
    // An octahedron and its mirror image across x = 0, pushed into each other: every edge that
    // crosses the mirror plane crosses its image there (mirror-symmetric parts, as a model's
    // legs), and the solid is their union.
    let half = placed(&octahedron(0.5), [0.9, 0.2, 0.3, 0.1], [0.125, 0.0, 0.0]);
    let both = join(&[half.clone(), mirrored(&half)]);
    let (out, _) = cut(&both);
    assert_same_solid(&both, &out, 4000, 6, 0.0);
}

/// An octahedron `centre ± x, ± y, ± z` (its corners in that order: any three independent
/// vectors give a convex one), outward.
fn affine_octahedron(centre: [f64; 3], x: [f64; 3], y: [f64; 3], z: [f64; 3]) -> Mesh {
    let at = |d: [f64; 3], s: f64| std::array::from_fn(|k| centre[k] + s * d[k]);
    let p = vec![
        at(x, 1.0),
        at(x, -1.0),
        at(y, 1.0),
        at(y, -1.0),
        at(z, 1.0),
        at(z, -1.0),
    ];
    let mesh = Mesh::new(p, gwn::testing::OCTAHEDRON_FACES.to_vec()).unwrap();
    let det = x[0] * (y[1] * z[2] - y[2] * z[1]) - x[1] * (y[0] * z[2] - y[2] * z[0])
        + x[2] * (y[0] * z[1] - y[1] * z[0]);
    if det > 0.0 { mesh } else { mesh.flipped() }
}

/// An octahedron with a corner exactly inside a cube's top face (`z = ½`, off its diagonal):
/// crossing the face there (faces around that corner on both sides of its plane), touching it
/// from inside the cube, or from outside. The corner becomes a vertex of the face, the two
/// surfaces are cut along their curves from it, and where they only touch, the kept pieces
/// meeting at that vertex are pulled apart.
#[test]
fn a_corner_inside_a_face_is_a_vertex_of_the_cut() {
    let cube = centred_cube();
    let corner = [0.125, 0.0625, 0.5];
    let below = |d: [f64; 3]| std::array::from_fn(|k| corner[k] - d[k]);
    let cases = [
        // Crossing: the ring corners `+x` above the plane, the others below.
        ([0.125, 0.0625, 0.25], [0.25, 0.0, 0.375]),
        // Touching from inside (the whole octahedron below the plane but its corner).
        ([0.125, 0.0625, 0.25], [0.25, 0.0, 0.0625]),
        // Touching from outside (above it).
        ([0.125, 0.0625, -0.25], [0.25, 0.0, -0.0625]),
    ];
    for (i, (to_centre, x)) in cases.into_iter().enumerate() {
        let centre = below(to_centre);
        let z = std::array::from_fn(|k| corner[k] - centre[k]);
        let y = [0.0, 0.25, 0.125 * to_centre[2].signum()];
        let octahedron = affine_octahedron(centre, x, y, z);
        assert!(octahedron.positions().contains(&corner));
        let input = join(&[cube.clone(), octahedron]);
        let (out, _) = cut(&input);
        assert_same_solid(&input, &out, 4000, 10 + i as u64, 0.0);
        // A vertex of the face's pieces (pulled apart by at most a 64th of a cell where the
        // two kept surfaces only touch there).
        let near = out
            .positions
            .iter()
            .any(|p| (0..3).all(|k| (p[k] - corner[k]).abs() < 1e-3));
        assert!(near, "case {i}: the corner is not a vertex of the output");
    }
}

/// An octahedron with an edge exactly in a cube's top plane (`z = ½`), from outside the cube to
/// inside its top face, its two poles above and below: the faces through that edge meet the
/// cube along it (from where it crosses the cube's edge to its end inside the face); the
/// union is cut.
#[test]
fn an_edge_in_a_face_plane_is_cut_along_it() {
    let cube = centred_cube();
    let octahedron = affine_octahedron(
        [0.375, 0.125, 0.375],
        [0.25, 0.0, 0.125],
        [0.0, 0.1875, 0.125],
        [-0.0625, 0.0625, 0.25],
    );
    let p = octahedron.positions();
    assert_eq!((p[0][2], p[2][2]), (0.5, 0.5), "the edge from +x to +y");
    let input = join(&[cube, octahedron]);
    let (out, counts) = cut(&input);
    assert_same_solid(&input, &out, 4000, 20, 0.0);
    // Where the edge crosses the cube's edge `x = ½, z = ½`.
    let crossing = [0.5, 0.125 + 0.1875 / 2.0, 0.5];
    assert!(
        out.positions
            .iter()
            .any(|q| (0..3).all(|k| (q[k] - crossing[k]).abs() < 1e-12)),
        "{counts:?}"
    );
}

/// `mesh` reflected across the plane `x = 0` (exactly: a sign), still outward.
fn mirrored(mesh: &Mesh) -> Mesh {
    Mesh::new(
        mesh.positions()
            .iter()
            .map(|&[x, y, z]| [-x, y, z])
            .collect(),
        mesh.triangles().to_vec(),
    )
    .unwrap()
    .flipped()
}

#[test]
fn contacts_in_a_face_plane_are_cut_or_replaced() {
    let cube = centred_cube();
    // An octahedron whose four equator edges lie inside a cube's top face: each face through
    // one meets the cube along it (two corners inside the top face).
    let on_plane = join(&[
        cube.clone(),
        octahedron(0.25).translated([0.125, 0.0625, 0.5]),
    ]);
    let (out, counts) = cut(&on_plane);
    assert_eq!(counts.intersecting_pairs, 12, "{counts:?}");
    assert_same_solid(&on_plane, &out, 4000, 8, 0.0);
    // Touching along a face: not cut, but the faces of that plane are replaced by what they
    // add up to there (`coplanar_overlaps`), and the two are kept as one solid.
    let touching = join(&[cube.clone(), cube.translated([1.0, 0.25, 0.25])]);
    let out = kept(&touching).unwrap_or_else(|e| panic!("{e}"));
    let Some(InputCheck::Kept { repairs, .. }) = out.stats.input else {
        panic!("not kept: {:?}", out.stats.input);
    };
    assert_eq!(repairs.coplanar.planes, 1, "{repairs:?}");
    assert_same_solid(&touching, &out, 2000, 9, 0.0);
}

/// Three cubes through one region: where three faces meet in a point, two intersection
/// segments cross inside each of them; they are split there, the same way in all three.
#[test]
fn three_shells_meeting_in_points_are_cut_there() {
    let cube = centred_cube();
    let three = join(&[
        cube.clone(),
        placed(
            &cube,
            [0.8813, 0.3377, 0.2291, 0.1517],
            [0.4127, 0.3019, 0.2203],
        ),
        placed(
            &cube,
            [0.8171, -0.1093, 0.4129, 0.2207],
            [0.3011, -0.2137, 0.4519],
        ),
    ]);
    let (out, counts) = cut(&three);
    assert_same_solid(&three, &out, 4000, 5, 0.0);
    assert!(counts.triple_points > 0, "{counts:?}");
}

/// Without intersections the cut is the input as it is, every face labelled `w = 0` in front;
/// turned inward, every face is left out.
#[test]
fn an_input_without_intersections_is_its_own_cut() {
    let cube = centred_cube();
    let (positions, triangles) = (cube.positions(), cube.triangles());
    // Integers in one scale (twice the coordinates, which are ±½).
    let fixed: Vec<[i128; 3]> = positions
        .iter()
        .map(|p| p.map(|x| (x * 2.0) as i128))
        .collect();
    let out = cut_intersections(positions, &fixed, triangles, 0.0).unwrap();
    assert_eq!(
        (out.positions.as_slice(), out.triangles.as_slice()),
        (positions, triangles)
    );
    assert_eq!((out.uncut_faces, out.counts.removed_faces), (12, 0));
    let inward = cube.flipped();
    assert_eq!(
        cut_intersections(positions, &fixed, inward.triangles(), 0.0).err(),
        Some(NotCut::Proof("empty"))
    );
}

/// A tetrahedron inside a cube, sharing one of the cube's edges: around that edge `w` runs
/// 0, 1, 2, 1 (the cube's face, the tetrahedron's two, the cube's other), four faces that are
/// not two solid wedges, so no pull takes them apart. Every edge is used as often each way
/// (`w` is an integer off the surface), and the cut's labels keep the faces with `w = 0` in
/// front: the cube, the tetrahedron left out, no face cut. Outside the cube, sharing the edge
/// (0, 1, 0, 1 around it: solid wedges), the two are pulled apart instead.
#[test]
fn a_solid_inside_another_sharing_its_edge_is_left_out() {
    let cube = common::unit_cube();
    // Outward (`w = 2` inside it, checked below).
    let inside = Mesh::new(
        vec![
            [0.0, 0.0, 0.0],
            [0.0, 0.0, 1.0],
            [0.5, 0.2, 0.5],
            [0.2, 0.5, 0.5],
        ],
        vec![[0, 2, 1], [0, 1, 3], [0, 3, 2], [1, 2, 3]],
    )
    .unwrap();
    let nested = join(&[cube.clone(), inside.clone()]);
    let wn = WindingNumber::new(&nested).unwrap();
    assert_eq!(
        wn.eval([0.2, 0.2, 0.5]),
        2.0,
        "the tetrahedron is inside the cube"
    );
    let (out, counts) = cut(&nested);
    assert_eq!(
        (
            counts.intersecting_pairs,
            counts.cut_faces,
            counts.removed_faces
        ),
        (0, 0, 4),
        "{counts:?}"
    );
    assert_eq!(out.triangles.len(), 12);
    assert_same_solid(&nested, &out, 2_000, 11, 0.0);
    // Turned half a turn about the edge, out of the cube: it and the cube touch along the edge
    // only, and are kept both, pulled apart.
    let outside = Mesh::new(
        inside
            .positions()
            .iter()
            .map(|p| [-p[0], -p[1], p[2]])
            .collect(),
        inside.triangles().to_vec(),
    )
    .unwrap();
    let touching = join(&[cube, outside]);
    let out = kept(&touching).unwrap_or_else(|e| panic!("{e}"));
    let Some(InputCheck::Kept { separated, .. }) = out.stats.input else {
        panic!("not kept: {:?}", out.stats.input);
    };
    assert!(
        separated.vertices + separated.added_vertices > 0,
        "{separated:?}"
    );
    assert_eq!(out.triangles.len(), 16);
    assert_same_solid(&touching, &out, 2_000, 12, 0.01);
}

/// The input kept (whole, or cut) with the same solid, or refused whole for its winding (apart,
/// or nested without touching: nothing to cut).
fn cut_or_refused(input: &Mesh, seed: u64) -> Result<(), TestCaseError> {
    match kept(input) {
        Ok(out) => {
            prop_assert!(out.stats.input.is_some_and(|i| i.is_input_surface()));
            assert_same_solid(input, &out, 600, seed, 0.0);
        }
        Err(NotKept::Winding { .. }) => {}
        Err(e) => prop_assert!(false, "{e}"),
    }
    Ok(())
}

proptest! {
    #![proptest_config(ProptestConfig {
        cases: 24,
        failure_persistence: None,
        ..ProptestConfig::default()
    })]

    /// Two shells (cube, tetrahedron, octahedron or ball; either may be a cavity's wall, turned
    /// inward) in general position, overlapping: the cut always succeeds and bounds the input's
    /// solid. Two shells have no triple points, so nothing here may fall back.
    #[test]
    fn two_overlapping_shells_are_cut_exactly(
        shapes in (0usize..4, 0usize..4),
        q1 in prop::array::uniform4(-1.0f64..1.0),
        q2 in prop::array::uniform4(-1.0f64..1.0),
        offset in prop::array::uniform3(-0.45f64..0.45),
        inward in any::<bool>(),
        seed in any::<u64>(),
    ) {
        // Away from the special rotations and offsets, whose coincidences (an edge through
        // another, a corner on a face) are not in general position.
        prop_assume!(q1.iter().chain(&q2).chain(&offset).all(|c| c.abs() > 0.01));
        let shape = |k: usize| match k {
            0 => centred_cube(),
            1 => tetrahedron(0.9),
            2 => octahedron(0.7),
            _ => sphere([0.0; 3], 0.6, 6, false),
        };
        let a = placed(&shape(shapes.0), q1, [0.0; 3]);
        let mut b = placed(&shape(shapes.1), q2, offset);
        if inward {
            // A cavity's wall, smaller, inside-out: the solid minus it where they overlap.
            b = Mesh::new(
                b.positions().iter().map(|p| std::array::from_fn(|k| 0.6 * p[k] + 0.4 * offset[k])).collect(),
                b.triangles().to_vec(),
            ).unwrap().flipped();
        }
        let input = join(&[a, b]);
        cut_or_refused(&input, seed)?;
    }

    /// A shell and its mirror image across `x = 0`, overlapping: their faces meet on the mirror
    /// plane where edges cross edges (and elsewhere in general position). Cut, or refused
    /// only for the winding, and the same solid.
    #[test]
    fn mirrored_shells_are_cut_where_their_edges_cross(
        shape in 0usize..4,
        q in prop::array::uniform4(-1.0f64..1.0),
        offset in prop::array::uniform3(-0.3f64..0.3),
        seed in any::<u64>(),
    ) {
        prop_assume!(q.iter().all(|c| c.abs() > 0.01) && offset[0].abs() > 0.01);
        let shape = match shape {
            0 => centred_cube(),
            1 => tetrahedron(0.9),
            2 => octahedron(0.7),
            _ => sphere([0.0; 3], 0.6, 6, false),
        };
        let half = placed(&shape, q, offset);
        // A corner on the mirror plane is another contact (a vertex on a face).
        prop_assume!(half.positions().iter().all(|p| p[0] != 0.0));
        let input = join(&[half.clone(), mirrored(&half)]);
        cut_or_refused(&input, seed)?;
    }

    /// Three shells through one region, in general position: cut at their triple points too,
    /// and the same solid.
    #[test]
    fn three_overlapping_shells_are_cut_exactly(
        q in prop::array::uniform12(-1.0f64..1.0),
        offsets in prop::array::uniform6(-0.4f64..0.4),
        seed in any::<u64>(),
    ) {
        prop_assume!(q.iter().chain(&offsets).all(|c| c.abs() > 0.01));
        let input = join(&[
            placed(&centred_cube(), [q[0], q[1], q[2], q[3]], [0.0; 3]),
            placed(&octahedron(0.7), [q[4], q[5], q[6], q[7]], [offsets[0], offsets[1], offsets[2]]),
            placed(&tetrahedron(0.9), [q[8], q[9], q[10], q[11]], [offsets[3], offsets[4], offsets[5]]),
        ]);
        cut_or_refused(&input, seed)?;
    }
}
